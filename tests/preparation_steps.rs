//! The job's preparation in steps (`Job::prepare_in_steps`, `Preparation::step`: the page's
//! short calls, each of a budget of items) makes exactly the job of `Job::from_models`,
//! whatever the budget (one run of items a step, a few runs, more than the whole job): the
//! same bytes handed to the page's other workers (mesh, facet index, plane heights,
//! settings, info) and the same G-code, on the shared models and on meshes that take every
//! branch of the preparation (repeated facets, an inside-out shell, a crack closed, an open
//! part); a refusal is the same refusal, and a step after the end is an error, never a panic.
//! The file's import in steps (`Model::read_in_steps`) reads what `Model::read` reads, or
//! refuses alike; a job (or a draft) taken from its bytes in steps (`Job::take_in_steps`) is
//! the job read at once.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::Job;
use dropslice::model::models::Model;
use dropslice::model::spec::JobSpec;
use std::sync::Arc;

/// The budgets every preparation is stepped with: one item (a run a step), a few runs, all.
const BUDGETS: [usize; 3] = [1, 20_000, usize::MAX];

type Tri = [[f32; 3]; 3];

fn gcode(job: &Job) -> Vec<u8> {
    let mut out = Vec::new();
    dropslice::pipeline::write_gcode(job, &mut out, |_, _| {}).unwrap();
    out
}

/// Steps the preparation to its end with `budget` items a step; the number of steps beside
/// the job (or the refusal).
fn in_steps(models: &[Model], spec: &JobSpec, budget: usize) -> (Result<Job, String>, usize) {
    let mut prep = Job::prepare_in_steps(Arc::new(models.to_vec()), spec);
    for n in 1..=1_000_000 {
        match prep.step(budget) {
            Ok(Some(job)) => {
                // nothing is left once the job was handed out
                let after = prep.step(budget).map(|_| ()).unwrap_err().to_string();
                assert!(after.contains("already ended"), "{after}");
                return (Ok(job), n);
            }
            Ok(None) => {}
            Err(e) => {
                assert!(prep.step(budget).is_err(), "a step after a refusal");
                return (Err(e.to_string()), n);
            }
        }
    }
    panic!("the preparation did not end in a million steps");
}

/// The stepped preparation of `spec` is the one-call preparation, with every budget of
/// [`BUDGETS`] (the G-code compared once); returns the step counts.
fn assert_same(models: &[Model], spec: &str, what: &str) -> Vec<usize> {
    let spec = JobSpec::from_json(spec).unwrap();
    let whole = Job::from_models(models, &spec).map_err(|e| e.to_string());
    let whole_code = whole.as_ref().ok().map(gcode);
    let mut counts = Vec::new();
    for budget in BUDGETS {
        let (stepped, steps) = in_steps(models, &spec, budget);
        counts.push(steps);
        match (&whole, stepped) {
            (Ok(a), Ok(b)) => {
                assert!(
                    a.to_bytes() == b.to_bytes(),
                    "{what}, {budget}: other bytes"
                );
                assert_eq!(a.info(), b.info(), "{what}, {budget}: info");
                if budget == BUDGETS[1] {
                    assert!(
                        whole_code.as_ref() == Some(&gcode(&b)),
                        "{what}: the G-code differs"
                    );
                }
            }
            (Err(a), Err(b)) => assert_eq!(*a, b, "{what}, {budget}: another refusal"),
            (a, b) => panic!(
                "{what}, {budget}: one call {:?}, in steps {:?}",
                a.as_ref().map(|_| "a job"),
                b.map(|_| "a job")
            ),
        }
    }
    // a smaller budget never takes fewer steps; all of it, one
    assert!(
        counts.windows(2).all(|w| w[0] >= w[1]),
        "{what}: {counts:?}"
    );
    assert_eq!(counts[2], 1, "{what}: an unlimited budget is one step");
    counts
}

fn model(tris: &[Tri], name: &str) -> Model {
    Model::read(&common::stl_bytes(tris), name).unwrap()
}

#[test]
fn the_shared_models_prepare_alike_in_steps() {
    for (name, m) in common::readable_models() {
        let spec = format!(r#"{{"parts": [{{"file": {name:?}}}]}}"#);
        let steps = assert_same(&[m], &spec, &name);
        if name == "3DBenchy.stl" {
            // 225,154 facets: a budget of one item pauses after every run of 4,096 items
            // (the weld alone takes 55 runs), a budget of 20,000 after every fifth
            assert!(steps[0] > 200 && steps[1] > 40, "{name}: {steps:?}");
        }
    }
}

/// Imports `bytes` as `name` in steps of `budget` triangles (`Model::read_in_steps`, the
/// page's short calls of a file's import); the model (or refusal) and the number of steps.
fn read_in_steps(bytes: &[u8], name: &str, budget: usize) -> (Result<Model, String>, usize) {
    use dropslice::base::steps::{Budget, Stepped};
    use std::rc::Rc;
    let b = Rc::new(Budget::new(0));
    let (bytes, name, bb) = (bytes.to_vec(), name.to_string(), b.clone());
    let mut pass = Stepped::new(async move { Model::read_in_steps(&bytes, &name, &bb).await });
    for n in 1.. {
        b.refill(budget);
        if let Some(read) = pass.step() {
            return (read.map_err(|e| e.to_string()), n);
        }
    }
    unreachable!()
}

/// The import in steps reads what `Model::read` reads (every part's name, triangles and
/// transform) or refuses as it does, with every budget of [`BUDGETS`].
fn assert_same_import(bytes: &[u8], name: &str) -> Vec<usize> {
    let whole = Model::read(bytes, name).map_err(|e| e.to_string());
    let mut counts = Vec::new();
    for budget in BUDGETS {
        let (stepped, steps) = read_in_steps(bytes, name, budget);
        counts.push(steps);
        match (&whole, &stepped) {
            (Ok(a), Ok(b)) => {
                assert_eq!((&a.name, a.format), (&b.name, b.format), "{name}, {budget}");
                assert_eq!(a.parts.len(), b.parts.len(), "{name}, {budget}: parts");
                for (p, q) in a.parts.iter().zip(&b.parts) {
                    assert_eq!(p.name, q.name, "{name}, {budget}");
                    assert!(p.triangles == q.triangles, "{name}, {budget}: triangles");
                    assert_eq!(p.transform_applied, q.transform_applied, "{name}, {budget}");
                    assert_eq!(p.source_object, q.source_object, "{name}, {budget}");
                }
            }
            (Err(a), Err(b)) => assert_eq!(a, b, "{name}, {budget}: another refusal"),
            (a, b) => panic!(
                "{name}, {budget}: one call {:?}, in steps {:?}",
                a.is_ok(),
                b.is_ok()
            ),
        }
    }
    assert_eq!(counts[2], 1, "{name}: an unlimited budget is one step");
    counts
}

#[test]
fn files_import_alike_in_steps() {
    for (name, bytes) in common::model_files(&[".stl", ".obj", ".3mf"]) {
        let steps = assert_same_import(&bytes, &name);
        if name == "3DBenchy.stl" {
            // 225,154 binary records and their check, a run of 4,096 a step
            assert!(steps[0] > 100 && steps[1] > 20, "{name}: {steps:?}");
        }
    }
    // damaged files: a coordinate that is no number deep in a binary file, a truncated
    // binary file, an empty file, a facet of two corners in ASCII
    let cube = common::cuboid([0.; 3], [10., 10., 10.]);
    let mut many = Vec::new();
    for k in 0..1000 {
        many.extend(
            cube.iter()
                .map(|t| t.map(|c| [c[0] + 20.0 * k as f32, c[1], c[2]])),
        );
    }
    let mut nan = many.clone();
    nan[11_000][2][1] = f32::NAN;
    assert_same_import(&common::stl_bytes(&nan), "nan.stl");
    let whole = common::stl_bytes(&many);
    assert_same_import(&whole[..whole.len() - 20], "short.stl");
    assert_same_import(b"", "empty.stl");
    assert_same_import(
        b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid a\n",
        "two.stl",
    );
}

#[test]
fn a_build_job_with_a_unit_1_part_and_support_prepares_alike_in_steps() {
    let benchy = Model::read(&common::model_bytes("3DBenchy.stl"), "boat.stl").unwrap();
    let screw = Model::read(&common::model_bytes("M3x10_screw.stl"), "screw.stl").unwrap();
    assert_same(
        &[benchy, screw],
        r#"{"settings": {"support": "unit1", "unit1_droplet_aspect": 1.6},
            "parts": [{"file": "boat.stl"}, {"file": "screw.stl", "unit": 1, "copies": 2}]}"#,
        "boat and two unit-1 screws",
    );
}

#[test]
fn every_branch_of_the_preparation_is_taken_alike_in_steps() {
    let cube = common::cuboid([0.; 3], [10., 10., 10.]);
    // repeated facets: dropped, the index not built beside the shells
    let mut repeated = cube.clone();
    repeated.extend_from_slice(&cube[..3]);
    assert_same(
        &[model(&repeated, "r.stl")],
        r#"{"parts": [{"file": "r.stl"}]}"#,
        "repeated facets",
    );
    // an inside-out cavity box inside a box: one shell turned
    let mut cavity = cube.clone();
    cavity.extend(
        common::cuboid([3., 3., 3.], [7.0, 7.0, 7.0])
            .into_iter()
            .map(|[a, b, c]| [a, c, b]),
    );
    cavity.extend(
        common::cuboid([20., 0., 0.], [25.0, 5.0, 5.0])
            .into_iter()
            .map(|[a, b, c]| [a, c, b]),
    );
    assert_same(
        &[model(&cavity, "c.stl")],
        r#"{"parts": [{"file": "c.stl"}]}"#,
        "a cavity and an inside-out box",
    );
    // a crack: one corner of a facet moved by a micrometre
    let mut cracked = cube.clone();
    cracked[4][1][0] += 0.001;
    assert_same(
        &[model(&cracked, "k.stl")],
        r#"{"parts": [{"file": "k.stl"}]}"#,
        "a crack",
    );
    // an open box (its top missing)
    let open: Vec<Tri> = cube
        .iter()
        .enumerate()
        .filter(|(i, _)| *i / 2 != 1)
        .map(|(_, t)| *t)
        .collect();
    assert_same(
        &[model(&open, "o.stl")],
        r#"{"parts": [{"file": "o.stl"}]}"#,
        "an open box",
    );
    // refusals: a part taller than the chamber, far too many droplets
    assert_same(
        &[model(&common::cuboid([0.; 3], [10., 10., 10.]), "t.stl")],
        r#"{"settings": {"plate_z": 5}, "parts": [{"file": "t.stl"}]}"#,
        "too tall",
    );
    assert_same(
        &[model(&cube, "b.stl")],
        r#"{"parts": [{"file": "b.stl", "scale_x": 40, "scale_y": 40, "scale_z": 2}]}"#,
        "too big",
    );
}

#[test]
fn the_supported_pass_in_steps_plans_every_layer_alike() {
    use dropslice::base::steps::{Budget, Stepped};
    use std::rc::Rc;
    let spec =
        JobSpec::from_json(r#"{"settings": {"support": "unit1"}, "parts": [{"file": "u.obj"}]}"#)
            .unwrap();
    let u = Model::read(&common::model_bytes("U_overhang.obj"), "u.obj").unwrap();
    let models = [u];
    let whole = gcode(&Job::from_models(&models, &spec).unwrap());
    for items in [1, 7, usize::MAX] {
        let job = Rc::new(Job::from_models(&models, &spec).unwrap());
        let budget = Rc::new(Budget::new(0));
        let (j, b) = (job.clone(), budget.clone());
        let mut pass = Stepped::new(async move { j.supported_in_steps(&b).await });
        let mut steps = 0;
        loop {
            budget.refill(items);
            steps += 1;
            if pass.step().is_some() {
                break;
            }
            assert!(!job.supported_made(), "made before its last step");
        }
        assert!(job.supported_made());
        if items == 1 {
            // six passes of about one item a layer (sections, part plans, support regions,
            // hatches, droplet pass, final plans)
            assert!(steps > 6 * job.layer_count(), "{steps} steps");
        }
        assert!(
            gcode(&job) == whole,
            "{items} layers a step: the G-code differs"
        );
    }
}

/// Takes `bytes` (a prepared job, or with `draft` a draft) in steps of `budget` items
/// (`Job::take_in_steps`, the page's short calls of another worker taking the job).
fn take_in_steps(bytes: &[u8], draft: bool, budget: usize) -> Result<Job, String> {
    use dropslice::base::steps::{Budget, Stepped};
    use std::rc::Rc;
    let b = Rc::new(Budget::new(0));
    let (bytes, bb) = (bytes.to_vec(), b.clone());
    let mut pass = Stepped::new(async move { Job::take_in_steps(&&bytes[..], draft, &bb).await });
    loop {
        b.refill(budget);
        if let Some(job) = pass.step() {
            return job.map_err(|e| e.to_string());
        }
    }
}

#[test]
fn a_job_taken_in_steps_is_the_job_read_at_once() {
    use std::cell::RefCell;
    use std::rc::Rc;
    for name in ["3DBenchy.stl", "cube_gears.3mf", "esca_nonmanifold.stl"] {
        let m = Model::read(&common::model_bytes(name), name).unwrap();
        let spec = JobSpec::from_json(&format!(
            r#"{{"settings": {{"allow_off_plate": true}}, "parts": [{{"file": {name:?}}}]}}"#
        ))
        .unwrap();
        let job = Job::from_models(std::slice::from_ref(&m), &spec).unwrap();
        let bytes = job.to_bytes();
        for budget in BUDGETS {
            let taken = take_in_steps(&bytes, false, budget).expect("the job");
            assert!(taken.to_bytes() == bytes, "{name}, {budget}: other bytes");
            // damaged: cut short, or a draft's bytes read as a prepared job's
            let short = take_in_steps(&bytes[..bytes.len() - 3], false, budget).err();
            let at_once = Job::read_bytes(&&bytes[..bytes.len() - 3]).err();
            assert!(
                short.is_some(),
                "{name}, {budget}: the bytes cut short were taken"
            );
            assert_eq!(short, at_once.map(|e| e.to_string()), "{name}, {budget}");
        }
        // the draft, taken in steps and at once
        let draft: Rc<RefCell<Option<Vec<u8>>>> = Rc::default();
        let d = draft.clone();
        let hook: dropslice::pipeline::DraftHook =
            Box::new(move |draft| *d.borrow_mut() = Some(draft.to_bytes()));
        let mut prep = Job::prepare_drafted(Arc::new(vec![m]), &spec, Some(hook));
        while prep.step(16_384).unwrap().is_none() {}
        let draft = draft.borrow_mut().take().expect("a draft");
        let at_once = Job::from_draft(&&draft[..]).unwrap().to_bytes();
        for budget in BUDGETS {
            let taken = take_in_steps(&draft, true, budget).expect("the draft");
            assert!(taken.to_bytes() == at_once, "{name}, {budget}: the draft");
            assert!(
                take_in_steps(&draft, false, budget).is_err(),
                "{name}: a draft as a job"
            );
        }
    }
}
