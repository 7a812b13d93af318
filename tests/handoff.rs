//! The prepared job handed from the page's job worker to the others (src/pipeline/handoff.rs):
//! a job read back from its bytes writes the same G-code as the job itself (a plain STL, a
//! 3MF build, an OBJ, a build job with a unit-1 part and support on), has the same info and
//! settings, and damaged bytes are refused with a message, never a panic. A draft (the job as
//! merged, before the repairs: `Job::prepare_drafted`) confirmed by the finished job is that
//! job, byte for byte, whenever the preparation says the job is the draft's, and it says so
//! exactly when no repair changed the mesh.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::Rng;
use dropslice::model::models::Model;
use dropslice::model::spec::JobSpec;
use dropslice::{Job, Settings};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;

fn gcode(job: &Job) -> Vec<u8> {
    let mut out = Vec::new();
    dropslice::pipeline::write_gcode(job, &mut out, |_, _| {}).unwrap();
    out
}

/// `job` and the job read back from its bytes agree in everything the page uses.
fn assert_same(job: &Job, what: &str) {
    let bytes = job.to_bytes();
    let back = Job::from_bytes(&bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(back.settings(), job.settings(), "{what}: settings");
    assert_eq!(back.info(), job.info(), "{what}: info");
    assert_eq!(back.layer_count(), job.layer_count(), "{what}: layers");
    assert_eq!(
        back.mesh().vertices,
        job.mesh().vertices,
        "{what}: vertices"
    );
    assert_eq!(back.mesh().facets, job.mesh().facets, "{what}: facets");
    assert_eq!(back.header(None), job.header(None), "{what}: header");
    assert!(gcode(&back) == gcode(job), "{what}: the G-code differs");
    // Written again, the same bytes.
    assert!(
        back.to_bytes() == bytes,
        "{what}: written again, other bytes"
    );
}

#[test]
fn a_job_read_back_from_its_bytes_slices_as_the_job_itself() {
    for (file, sets) in [
        ("3DBenchy.stl", vec![]),
        (
            "3DBenchy.stl",
            vec![("support", "unit1"), ("stagger", "true")],
        ),
        ("M3x10_screw.stl", vec![("layer_height", "0.1")]),
    ] {
        let mut s = Settings::default();
        for (k, v) in &sets {
            s.set(k, v).unwrap();
        }
        let job = Job::new(&common::model_bytes(file), file, s).unwrap();
        assert_same(&job, &format!("{file} {sets:?}"));
    }
    for (name, bytes) in common::model_files(&[".3mf", ".obj"]) {
        if let Ok(job) = Job::new(&bytes, &name, Settings::default()) {
            assert_same(&job, &name);
        }
    }
}

#[test]
fn a_build_job_with_a_unit_1_part_and_support_reads_back_alike() {
    let benchy = Model::read(&common::model_bytes("3DBenchy.stl"), "boat.stl").unwrap();
    let screw = Model::read(&common::model_bytes("M3x10_screw.stl"), "screw.stl").unwrap();
    let spec = JobSpec::from_json(
        r#"{"settings": {"support": "unit1", "unit1_droplet_aspect": 1.6},
            "parts": [{"file": "boat.stl"}, {"file": "screw.stl", "unit": 1, "copies": 2}]}"#,
    )
    .unwrap();
    let job = Job::from_models(&[benchy, screw], &spec).unwrap();
    assert!(!job.part_units().is_empty());
    assert!(!job.info().groups.is_empty());
    assert_same(&job, "boat and two unit-1 screws");
}

fn small_job() -> Job {
    Job::new(
        &common::model_bytes("M3x10_screw.stl"),
        "screw.stl",
        Settings::default(),
    )
    .unwrap()
}

#[test]
fn damaged_bytes_are_refused_with_a_message() {
    let bytes = small_job().to_bytes();
    let refused = |b: &[u8], what: &str| {
        let e = Job::from_bytes(b)
            .err()
            .unwrap_or_else(|| panic!("{what}: taken"));
        assert_eq!(e.kind(), "internal", "{what}");
        assert!(e.to_string().contains("prepared job"), "{what}: {e}");
    };
    // Every length cut short (steps of 7 bytes, and the last few).
    for n in (0..bytes.len())
        .step_by(7)
        .chain(bytes.len() - 9..bytes.len())
    {
        refused(&bytes[..n], &format!("cut to {n} bytes"));
    }
    let mut longer = bytes.clone();
    longer.push(0);
    refused(&longer, "a byte more");
    let mut other = bytes.clone();
    other[7] = 2;
    refused(&other, "another version");
    // A length that claims more than there is (the settings' JSON length, first after the
    // 8-byte header): refused before anything is allocated.
    let mut huge = bytes.clone();
    huge[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
    refused(&huge, "a huge length");
    // The layout after the settings: vertices, facets, planes, offsets, listed facets.
    let meta = u64::from_le_bytes(bytes[8..16].try_into().unwrap()) as usize;
    let at_vertices = 16 + meta;
    let nv = u64::from_le_bytes(bytes[at_vertices..at_vertices + 8].try_into().unwrap()) as usize;
    let at_facets = at_vertices + 8 + 24 * nv;
    let nf = u64::from_le_bytes(bytes[at_facets..at_facets + 8].try_into().unwrap()) as usize;
    let mut nan = bytes.clone();
    nan[at_vertices + 8..at_vertices + 16].copy_from_slice(&f64::NAN.to_le_bytes());
    refused(&nan, "a NaN vertex");
    let mut past = bytes.clone();
    past[at_facets + 8..at_facets + 12].copy_from_slice(&(nv as u32).to_le_bytes());
    refused(&past, "a facet past the last vertex");
    let at_planes = at_facets + 8 + 12 * nf;
    let nz = u64::from_le_bytes(bytes[at_planes..at_planes + 8].try_into().unwrap()) as usize;
    let mut falling = bytes.clone();
    let z1 = bytes[at_planes + 16..at_planes + 24].to_vec();
    falling[at_planes + 8..at_planes + 16].copy_from_slice(&z1);
    refused(&falling, "two planes at one height");
    let at_offsets = at_planes + 8 + 8 * nz;
    let mut shifted = bytes.clone();
    shifted[at_offsets + 8..at_offsets + 12].copy_from_slice(&1u32.to_le_bytes());
    refused(&shifted, "offsets not from 0");
    let at_listed = at_offsets + 8 + 4 * (nz + 1);
    let mut stray = bytes.clone();
    stray[at_listed + 8..at_listed + 12].copy_from_slice(&(nf as u32).to_le_bytes());
    refused(&stray, "a listed facet past the last");
    let mut settings = bytes.clone();
    let text = String::from_utf8(bytes[16..at_vertices].to_vec()).unwrap();
    let at = 16 + text.find("\"layer_height\":").unwrap() + "\"layer_height\":".len();
    settings[at] = b'-';
    refused(&settings, "a negative layer height");
}

#[test]
fn random_damage_never_panics() {
    taken_or_refused(&small_job().to_bytes(), 25, 300, Job::from_bytes);
}

/// `tries` copies of `bytes`, each with one to four bytes changed at random (from `seed`):
/// each is taken or refused by `read`, never a panic, and a job taken plans its layers.
fn taken_or_refused(
    bytes: &[u8],
    seed: u64,
    tries: usize,
    read: impl Fn(&[u8]) -> Result<Job, dropslice::Error>,
) {
    let mut rng = Rng::new(seed);
    for _ in 0..tries {
        let mut b = bytes.to_vec();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(b.len() as u64) as usize;
            b[at] = rng.below(256) as u8;
        }
        if let Ok(job) = read(&b) {
            let _ = gcode(&job);
        }
    }
}

type Tri = [[f32; 3]; 3];

/// The job of `spec` prepared in steps with a draft: the job (or the refusal), the draft's
/// bytes (if one was made) and whether the job is the draft's.
fn drafted(
    models: &[Model],
    spec: &JobSpec,
) -> (Result<Job, String>, Option<Vec<u8>>, Option<bool>) {
    let draft: Rc<RefCell<Option<Vec<u8>>>> = Rc::default();
    let d = draft.clone();
    let hook: dropslice::pipeline::DraftHook = Box::new(move |draft| {
        let (size, write) = draft.bytes_writer();
        let mut out = vec![0u8; size];
        write(&mut out);
        *d.borrow_mut() = Some(out);
    });
    let mut prep = Job::prepare_drafted(Arc::new(models.to_vec()), spec, Some(hook));
    let job = loop {
        match prep.step(20_000) {
            Ok(Some(job)) => break Ok(job),
            Ok(None) => {}
            Err(e) => break Err(e.to_string()),
        }
    };
    let bytes = draft.borrow_mut().take();
    (job, bytes, prep.as_drafted())
}

/// Prepares `spec` with a draft; when the preparation says the job is the draft's, the draft
/// confirmed is the job (the same bytes, so the same layers); else the draft's mesh, planes
/// or units differ from the job's. Returns whether the job was the draft's.
fn assert_draft(models: &[Model], spec: &str, what: &str) -> Option<bool> {
    let spec = JobSpec::from_json(spec).unwrap();
    let whole = Job::from_models(models, &spec).map_err(|e| e.to_string());
    let (job, draft, as_drafted) = drafted(models, &spec);
    let job = match (job, whole) {
        (Ok(job), Ok(whole)) => {
            assert!(job.to_bytes() == whole.to_bytes(), "{what}: another job");
            job
        }
        (Err(a), Err(b)) => {
            assert_eq!(a, b, "{what}: another refusal");
            assert_eq!(as_drafted, None, "{what}: a refused job is no draft's");
            return None;
        }
        (a, b) => panic!("{what}: {:?} against {:?}", a.err(), b.err()),
    };
    let draft = draft.unwrap_or_else(|| panic!("{what}: no draft"));
    let mut from_draft =
        Job::from_draft(&draft.as_slice()).unwrap_or_else(|e| panic!("{what}: {e}"));
    let confirmed = from_draft.confirm(&job.confirmation().as_slice());
    match as_drafted {
        Some(true) => {
            confirmed.unwrap_or_else(|e| panic!("{what}: {e}"));
            assert!(
                from_draft.to_bytes() == job.to_bytes(),
                "{what}: the confirmed draft is not the job"
            );
            assert_eq!(from_draft.header(None), job.header(None), "{what}: header");
        }
        Some(false) => {
            let differs = from_draft.mesh().facets != job.mesh().facets
                || from_draft.mesh().vertices != job.mesh().vertices
                || from_draft.layer_count() != job.layer_count()
                || from_draft.info().groups != job.info().groups;
            assert!(
                differs,
                "{what}: said to differ from its draft, but is the same"
            );
        }
        None => panic!("{what}: a draft was made, but not told whether the job is its"),
    }
    as_drafted
}

#[test]
fn a_draft_confirmed_is_the_job_when_no_repair_changed_the_mesh() {
    for (name, m) in common::readable_models() {
        let spec = format!(
            r#"{{"settings": {{"allow_off_plate": true}}, "parts": [{{"file": "{name}"}}]}}"#
        );
        assert_draft(&[m], &spec, &name);
    }
    let benchy = Model::read(&common::model_bytes("3DBenchy.stl"), "boat.stl").unwrap();
    let screw = Model::read(&common::model_bytes("M3x10_screw.stl"), "screw.stl").unwrap();
    let two = r#"{"settings": {"support": "unit1"},
        "parts": [{"file": "boat.stl"}, {"file": "screw.stl", "unit": 1, "copies": 2}]}"#;
    assert_eq!(assert_draft(&[benchy, screw], two, "two units"), Some(true));
    let model = |tris: &[Tri], name: &str| Model::read(&common::stl_bytes(tris), name).unwrap();
    let cube = common::cuboid([0.; 3], [10., 10., 10.]);
    let one = |name: &str| format!(r#"{{"parts": [{{"file": "{name}"}}]}}"#);
    assert_eq!(
        assert_draft(&[model(&cube, "a.stl")], &one("a.stl"), "a cube"),
        Some(true)
    );
    // repeated facets dropped
    let mut repeated = cube.clone();
    repeated.extend_from_slice(&cube[..3]);
    assert_eq!(
        assert_draft(&[model(&repeated, "r.stl")], &one("r.stl"), "repeats"),
        Some(false)
    );
    // an inside-out box: its shell turned
    let inside_out: Vec<Tri> = cube.iter().map(|&[a, b, c]| [a, c, b]).collect();
    assert_eq!(
        assert_draft(&[model(&inside_out, "i.stl")], &one("i.stl"), "inside out"),
        Some(false)
    );
    // a crack closed (a corner moved by 0.05 µm, within the tolerance weld)
    let mut cracked = cube.clone();
    cracked[4][1][0] += 0.00005;
    assert_eq!(
        assert_draft(&[model(&cracked, "k.stl")], &one("k.stl"), "a crack"),
        Some(false)
    );
    // an open box: nothing to repair
    let open: Vec<Tri> = (cube.iter().enumerate())
        .filter(|(i, _)| *i / 2 != 1)
        .map(|(_, t)| *t)
        .collect();
    assert_eq!(
        assert_draft(&[model(&open, "o.stl")], &one("o.stl"), "open"),
        Some(true)
    );
    // refused after the draft (taller than the chamber)
    let tall = r#"{"settings": {"plate_z": 5}, "parts": [{"file": "t.stl"}]}"#;
    assert_eq!(
        assert_draft(&[model(&cube, "t.stl")], tall, "too tall"),
        None
    );
}

#[test]
fn a_damaged_draft_or_confirmation_is_refused() {
    let m = Model::read(&common::model_bytes("M3x10_screw.stl"), "s.stl").unwrap();
    let spec = JobSpec::from_json(r#"{"parts": [{"file": "s.stl"}]}"#).unwrap();
    let (job, draft, as_drafted) = drafted(&[m], &spec);
    let (job, draft) = (job.unwrap(), draft.unwrap());
    assert_eq!(as_drafted, Some(true));
    let refused = |e: dropslice::Error, what: &str| {
        assert_eq!(e.kind(), "internal", "{what}");
        assert!(e.to_string().contains("prepared job"), "{what}: {e}");
    };
    // a draft is not a prepared job, nor the other way round
    refused(Job::from_bytes(&draft).err().unwrap(), "a draft as a job");
    refused(
        Job::from_draft(&job.to_bytes().as_slice()).err().unwrap(),
        "a job as a draft",
    );
    for n in (0..draft.len()).step_by(11) {
        refused(
            Job::from_draft(&&draft[..n]).err().unwrap(),
            &format!("a draft cut to {n}"),
        );
    }
    let table = job.confirmation();
    let mut from_draft = Job::from_draft(&draft.as_slice()).unwrap();
    let before = from_draft.to_bytes();
    for n in 0..table.len() {
        refused(
            from_draft.confirm(&&table[..n]).err().unwrap(),
            &format!("cut to {n}"),
        );
    }
    let mut longer = table.clone();
    longer.push(b' ');
    refused(
        from_draft.confirm(&longer.as_slice()).err().unwrap(),
        "a byte more",
    );
    // another job's confirmation: other settings, other layers
    let mut s = Settings::default();
    s.set("layer_height", "0.1").unwrap();
    let other = Job::new(&common::model_bytes("M3x10_screw.stl"), "s.stl", s).unwrap();
    refused(
        from_draft
            .confirm(&other.confirmation().as_slice())
            .err()
            .unwrap(),
        "another job's",
    );
    let benchy = Job::new(
        &common::model_bytes("3DBenchy.stl"),
        "s.stl",
        Settings::default(),
    )
    .unwrap();
    refused(
        from_draft
            .confirm(&benchy.confirmation().as_slice())
            .err()
            .unwrap(),
        "another model's",
    );
    assert!(
        from_draft.to_bytes() == before,
        "a refused confirmation changed the draft"
    );
    from_draft.confirm(&table.as_slice()).unwrap();
    assert!(from_draft.to_bytes() == job.to_bytes());
    // random damage to a draft: taken or refused, never a panic
    taken_or_refused(&draft, 26, 200, |b| Job::from_draft(&b));
}
