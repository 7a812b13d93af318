//! `dropslice orient` as a command (issue 39, "The user's work survives"): `--apply` changes
//! only the rotations of the job file it is given — through a symlink, keeping the mode, the
//! hard links, the key order and the formatting — and refuses a read-only file untouched; the
//! job's triangle bound is checked before any work, with slicing's words; `--profile` as
//! slicing takes it. The expected texts are written out here from the job files made here and
//! the rotations `bridge.obj` needs (upside down: rotate_x 180, docs/process.md).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target
#![cfg(unix)] // modes, symlinks and hard links

mod common;

use common::{TempDir, model, run_cli};
use dropslice::model::import::Part;
use dropslice::model::import::stl::Format;
use dropslice::model::models::{MAX_JOB_TRIANGLES, Model, check_job_triangles};
use dropslice::model::spec::JobSpec;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::time::Duration;

fn cli(dir: &TempDir, args: &[&str]) -> common::Run {
    let r = run_cli(args, dir.path(), Duration::from_secs(120));
    assert!(!r.timed_out, "{args:?} timed out");
    r
}

/// A folder with `bridge.obj` (overhanging 400 mm² as it lies; none upside down).
fn bridge_dir(tag: &str) -> TempDir {
    let dir = TempDir::new(tag);
    std::fs::copy(model("bridge.obj"), dir.join("bridge.obj")).unwrap();
    dir
}

/// A pretty job of one part that `orient --apply` turns upside down, and its text after.
const JOB: &str = "{\n  \"parts\": [\n    {\n      \"name\": \"B\",\n      \"file\": \"bridge.obj\",\n      \"copies\": 2\n    }\n  ],\n  \"settings\": {\"layer_height\": 0.2}\n}\n";
const JOB_APPLIED: &str = "{\n  \"parts\": [\n    {\n      \"name\": \"B\",\n      \"file\": \"bridge.obj\",\n      \"copies\": 2,\n      \"rotate_x\": 180\n    }\n  ],\n  \"settings\": {\"layer_height\": 0.2}\n}\n";

fn read(dir: &TempDir, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap()
}

fn mode(dir: &TempDir, name: &str) -> u32 {
    std::fs::metadata(dir.join(name))
        .unwrap()
        .permissions()
        .mode()
        & 0o7777
}

fn set_mode(dir: &TempDir, name: &str, mode: u32) {
    std::fs::set_permissions(dir.join(name), std::fs::Permissions::from_mode(mode)).unwrap();
}

#[test]
fn apply_changes_only_the_rotations_keeping_key_order_and_formatting() {
    let dir = bridge_dir("orient-text");
    // Settings before parts, odd spacing, keys out of the usual order, an escaped key, a
    // part already upside down ("180.0": equal, so its text stays), one tilted whose
    // rotate_x is replaced where it stands (its rotate_z kept), one without a rotation.
    let job = concat!(
        "{ \"settings\" : { \"overhang_limit\": 0.5 ,\"layer_height\":0.2 },\n",
        "\t\"parts\":[\n",
        "   {\"copies\": 1, \"rotate_x\": 180.0, \"file\": \"bridge.obj\"},\n",
        "   {\"rotate_z\": 45, \"rot\\u0061te_x\": 1e0, \"file\": \"bridge.obj\", \"name\": \"tilted \\u00e9\"},\n",
        "   {\"file\": \"bridge.obj\",   \"copies\":2}\n",
        "]}\n"
    );
    let want = concat!(
        "{ \"settings\" : { \"overhang_limit\": 0.5 ,\"layer_height\":0.2 },\n",
        "\t\"parts\":[\n",
        "   {\"copies\": 1, \"rotate_x\": 180.0, \"file\": \"bridge.obj\"},\n",
        "   {\"rotate_z\": 45, \"rot\\u0061te_x\": 180, \"file\": \"bridge.obj\", \"name\": \"tilted \\u00e9\"},\n",
        "   {\"file\": \"bridge.obj\",   \"copies\":2,   \"rotate_x\":180}\n",
        "]}\n"
    );
    std::fs::write(dir.join("job.json"), job).unwrap();
    let r = cli(&dir, &["orient", "job.json", "--apply"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(r.stdout.contains("written: job.json"), "{}", r.stdout);
    assert_eq!(read(&dir, "job.json"), want);
    // Again: every part has its rotation; the file is not written.
    let before = std::fs::metadata(dir.join("job.json")).unwrap().ino();
    let r = cli(&dir, &["orient", "job.json", "--apply"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(r.stdout.contains("unchanged: job.json"), "{}", r.stdout);
    assert_eq!(read(&dir, "job.json"), want);
    assert_eq!(
        std::fs::metadata(dir.join("job.json")).unwrap().ino(),
        before
    );
    // The job slices.
    let s = cli(&dir, &["job.json", "-q", "-o", "j.gco"]);
    assert_eq!(s.code, Some(0), "{s:?}");
}

#[test]
fn apply_through_a_symlink_writes_its_target_and_keeps_the_link() {
    let dir = bridge_dir("orient-symlink");
    std::fs::create_dir(dir.join("jobs")).unwrap();
    // (the parts' files are found from the folder of the name given, as slicing finds them)
    std::fs::write(dir.join("jobs/real.json"), JOB).unwrap();
    std::os::unix::fs::symlink("jobs/real.json", dir.join("job.json")).unwrap();
    let r = cli(&dir, &["orient", "job.json", "--apply"]);
    r.prints(0, "written: job.json (the file it links to, ");
    let link = std::fs::symlink_metadata(dir.join("job.json")).unwrap();
    assert!(link.is_symlink(), "the link stays a link");
    assert_eq!(
        std::fs::read_link(dir.join("job.json")).unwrap(),
        std::path::Path::new("jobs/real.json")
    );
    assert_eq!(read(&dir, "jobs/real.json"), JOB_APPLIED);
    // No temporary file left beside either.
    let left: Vec<_> = std::fs::read_dir(dir.join("jobs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["real.json"]);
}

#[test]
fn apply_keeps_the_files_mode() {
    for m in [0o600, 0o640, 0o664, 0o604] {
        let dir = bridge_dir("orient-mode");
        std::fs::write(dir.join("job.json"), JOB).unwrap();
        set_mode(&dir, "job.json", m);
        let r = cli(&dir, &["orient", "job.json", "--apply"]);
        assert_eq!(r.code, Some(0), "{m:o}: {r:?}");
        assert_eq!(read(&dir, "job.json"), JOB_APPLIED, "{m:o}");
        assert_eq!(mode(&dir, "job.json"), m, "the mode {m:o} kept");
    }
    // Also with the named temporary file (no O_TMPFILE).
    let dir = bridge_dir("orient-mode-named");
    std::fs::write(dir.join("job.json"), JOB).unwrap();
    set_mode(&dir, "job.json", 0o600);
    let r = std::process::Command::new(common::bin())
        .args(["orient", "job.json", "--apply"])
        .current_dir(dir.path())
        .env("DROPSLICE_NAMED_TEMP", "1")
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(0), "{r:?}");
    assert_eq!(read(&dir, "job.json"), JOB_APPLIED);
    assert_eq!(mode(&dir, "job.json"), 0o600);
}

#[test]
fn a_read_only_job_file_is_refused_untouched_before_any_work() {
    for m in [0o444, 0o400, 0o000] {
        let dir = bridge_dir("orient-readonly");
        std::fs::write(dir.join("job.json"), JOB).unwrap();
        set_mode(&dir, "job.json", m);
        let ino = std::fs::metadata(dir.join("job.json")).unwrap().ino();
        let r = cli(&dir, &["orient", "job.json", "--apply"]);
        assert_eq!(r.code, Some(2), "{m:o}: {r:?}");
        if m != 0 {
            assert!(
                r.stderr.starts_with(&format!(
                    "dropslice orient: job.json is read-only (mode 0{m:o}); --apply writes the chosen rotations into the job file: make it writable (chmod u+w job.json) or orient without --apply"
                )),
                "{}",
                r.stderr
            );
        }
        assert_eq!(r.stderr.lines().count(), 1, "{}", r.stderr);
        assert_eq!(r.stdout, "", "refused before orienting");
        assert_eq!(mode(&dir, "job.json"), m);
        assert_eq!(std::fs::metadata(dir.join("job.json")).unwrap().ino(), ino);
        set_mode(&dir, "job.json", 0o644);
        assert_eq!(read(&dir, "job.json"), JOB, "untouched");
        // Without --apply it is only read.
        set_mode(&dir, "job.json", m.max(0o400));
        let r = cli(&dir, &["orient", "job.json"]);
        assert_eq!(r.code, Some(0), "{r:?}");
        assert!(r.stdout.contains("rotate_x = 180"), "{}", r.stdout);
    }
}

#[test]
fn a_hard_linked_job_file_stays_one_file_for_every_name() {
    let dir = bridge_dir("orient-hardlink");
    std::fs::write(dir.join("job.json"), JOB).unwrap();
    set_mode(&dir, "job.json", 0o640);
    std::fs::hard_link(dir.join("job.json"), dir.join("other.json")).unwrap();
    let ino = std::fs::metadata(dir.join("job.json")).unwrap().ino();
    let r = cli(&dir, &["orient", "job.json", "--apply"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    for name in ["job.json", "other.json"] {
        let m = std::fs::metadata(dir.join(name)).unwrap();
        assert_eq!((m.ino(), m.nlink()), (ino, 2), "{name}: still the one file");
        assert_eq!(read(&dir, name), JOB_APPLIED, "{name}");
    }
    assert_eq!(mode(&dir, "job.json"), 0o640);
    // A shorter text than before is cut to its length.
    std::fs::write(
        dir.join("job.json"),
        JOB_APPLIED.replace("\"rotate_x\": 180", "\"rotate_x\": 1.00000000000000000000"),
    )
    .unwrap();
    let r = cli(&dir, &["orient", "other.json", "--apply"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert_eq!(read(&dir, "job.json"), JOB_APPLIED);
}

#[test]
fn apply_on_a_model_writes_a_new_job_and_never_replaces_one() {
    let dir = bridge_dir("orient-model");
    let r = cli(&dir, &["orient", "bridge.obj", "--apply"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    let job: serde_json::Value = serde_json::from_str(&read(&dir, "bridge.job.json")).unwrap();
    assert_eq!(job["parts"][0]["rotate_x"].as_f64(), Some(180.0));
    let again = cli(&dir, &["orient", "bridge.obj", "--apply"]);
    assert_eq!(again.code, Some(2), "{again:?}");
    assert!(again.stderr.contains("exists"), "{}", again.stderr);
}

/// `dropslice ARGS` and `dropslice orient ARGS` are refused alike: exit 2, the same message
/// after the command's name.
fn refused_alike(dir: &TempDir, slice: &[&str], orient: &[&str]) -> String {
    let s = cli(dir, slice);
    let o = cli(dir, orient);
    assert_eq!((s.code, o.code), (Some(2), Some(2)), "{s:?}\n{o:?}");
    let m = s
        .stderr
        .strip_prefix("dropslice: ")
        .expect("slice's message");
    let n = o
        .stderr
        .strip_prefix("dropslice orient: ")
        .expect("orient's message");
    assert_eq!(m, n);
    assert_eq!(o.stdout, "", "nothing oriented");
    n.to_string()
}

#[test]
fn orient_refuses_a_job_past_the_triangle_bound_before_any_work_as_slicing_does() {
    let dir = TempDir::new("orient-bound");
    // 10^5 cubes of 12 facets fanned out by components: 1.2 M triangles from 1.5 KB.
    let bytes = common::fanned_cubes_3mf(5, 0.5, false);
    assert!(bytes.len() < 4000, "{} bytes", bytes.len());
    std::fs::write(dir.join("fan.3mf"), &bytes).unwrap();
    let per_part = 1_200_000;
    let parts = MAX_JOB_TRIANGLES / per_part + 1; // 17: 20.4 M
    let part = r#"{"file": "fan.3mf"}"#;
    let many = format!(r#"{{"parts": [{}]}}"#, vec![part; parts].join(", "));
    std::fs::write(dir.join("parts.json"), many).unwrap();
    std::fs::write(
        dir.join("copies.json"),
        format!(r#"{{"parts": [{{"file": "fan.3mf", "copies": {parts}}}]}}"#),
    )
    .unwrap();
    let want = format!(
        "bad job: {{}}: the job has more than {MAX_JOB_TRIANGLES} triangles in all (parts × copies); print fewer copies or simplify the models\n"
    );
    for job in ["parts.json", "copies.json"] {
        let m = refused_alike(&dir, &[job, "-q", "-o", "x.gco"], &["orient", job]);
        assert_eq!(m, want.replace("{}", job));
        // --apply too, the file untouched.
        let before = read(&dir, job);
        let r = cli(&dir, &["orient", job, "--apply"]);
        assert_eq!(r.code, Some(2), "{r:?}");
        assert_eq!(read(&dir, job), before);
    }
    // One part fewer is within the bound (the check itself: orienting 19 M facets is slow).
    let model = Model::read(&bytes, "fan.3mf").unwrap();
    let spec = |n: usize| {
        JobSpec::from_json(&format!(
            r#"{{"parts": [{{"file": "fan.3mf", "copies": {n}}}]}}"#
        ))
        .unwrap()
    };
    check_job_triangles(std::slice::from_ref(&model), &spec(parts - 1)).unwrap();
    assert!(check_job_triangles(std::slice::from_ref(&model), &spec(parts)).is_err());
}

/// A model of `kept` facets and `collapsed` triangles the weld drops (two corners equal, one
/// of them as −0 against 0).
fn model_of(kept: usize, collapsed: usize) -> Model {
    let mut triangles = Vec::with_capacity(kept + collapsed);
    for i in 0..kept {
        let x = i as f32;
        triangles.push([[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]]);
    }
    for i in 0..collapsed {
        let x = i as f32;
        let t = if i % 2 == 0 {
            [[x, 0.0, 0.0], [x, 0.0, 0.0], [x, 1.0, 0.0]]
        } else {
            [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, -0.0, 0.0]]
        };
        triangles.push(t);
    }
    Model {
        name: "m.stl".into(),
        format: Format::Binary,
        parts: vec![Part {
            name: "m".into(),
            triangles,
            transform_applied: dropslice::model::import::IDENTITY,
            source_object: None,
        }],
    }
}

#[test]
fn the_bound_counts_the_facets_the_weld_keeps() {
    // 5 parts × 100 copies of a model: 500 instances, as many as a job may have.
    let job = |parts: usize| {
        let part = r#"{"file": "m.stl", "copies": 100}"#;
        JobSpec::from_json(&format!(
            r#"{{"parts": [{}]}}"#,
            vec![part; parts].join(",")
        ))
        .unwrap()
    };
    let instances = 500;
    let fits = MAX_JOB_TRIANGLES / instances; // 40,000
    // Read: 25 M triangles; welded: 40,000 × 500 = the bound.
    let m = model_of(fits, 50_000 - fits);
    assert_eq!(
        dropslice::model::mesh::Mesh::weld(&m.parts[0].triangles)
            .0
            .facets
            .len(),
        fits
    );
    check_job_triangles(std::slice::from_ref(&m), &job(5)).unwrap();
    // One more facet kept: past it, with slicing's message.
    let m = model_of(fits + 1, 50_000 - fits - 1);
    let e = check_job_triangles(std::slice::from_ref(&m), &job(5)).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "bad job: the job has more than {MAX_JOB_TRIANGLES} triangles in all (parts × copies); print fewer copies or simplify the models"
        )
    );
}

#[test]
fn orient_takes_profiles_as_slicing_does() {
    let dir = bridge_dir("orient-profile");
    std::fs::write(
        dir.join("pc.json"),
        r#"{"name": "PC", "kind": "material", "settings": {"shrink_z": 4}}"#,
    )
    .unwrap();
    std::fs::write(dir.join("job.json"), JOB).unwrap();
    // Sliced 1/(1 − 4 %) as tall: 8.33 mm, the same as --set shrink_z=4.
    for file in ["bridge.obj", "job.json"] {
        let plain = cli(&dir, &["orient", file]);
        plain.prints(0, "height 8.00 mm → 8.00 mm");
        let with = cli(&dir, &["orient", file, "--profile", "pc.json"]);
        with.prints(0, "height 8.33 mm → 8.33 mm");
        let set = cli(&dir, &["orient", file, "--set", "shrink_z=4"]);
        assert_eq!(set.stdout, with.stdout);
        // --set after the profile wins, as for slicing.
        let both = cli(
            &dir,
            &[
                "orient",
                file,
                "--profile",
                "pc.json",
                "--set",
                "shrink_z=0",
            ],
        );
        assert_eq!(both.stdout, plain.stdout);
    }
    // A bad profile: refused the way slicing refuses it, nothing read or written.
    std::fs::write(
        dir.join("bad.json"),
        r#"{"name": "PC", "kind": "material", "settings": {"plate_z": 100}}"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("range.json"),
        r#"{"name": "PC", "kind": "material", "settings": {"shrink_z": 9}}"#,
    )
    .unwrap();
    for bad in ["bad.json", "range.json", "missing.json"] {
        let m = refused_alike(
            &dir,
            &["bridge.obj", "--profile", bad, "-o", "x.gco"],
            &["orient", "job.json", "--apply", "--profile", bad],
        );
        assert!(m.starts_with("the profile"), "{m}");
    }
    assert_eq!(read(&dir, "job.json"), JOB);
    assert!(!dir.join("x.gco").exists());
}

#[test]
fn figures_of_a_part_far_too_large_are_short() {
    // A cube 10^15 mm wide (a file in the wrong units): its height is printed as a number
    // with a power of ten, not sixteen digits.
    let dir = TempDir::new("orient-huge");
    let s = 1e15;
    let tris = common::cuboid([0.0; 3], [s as f32; 3]);
    let mut text = String::from("solid big\n");
    for t in &tris {
        text += " facet normal 0 0 0\n  outer loop\n";
        for p in t {
            text += &format!("   vertex {:e} {:e} {:e}\n", p[0], p[1], p[2]);
        }
        text += "  endloop\n endfacet\n";
    }
    text += "endsolid big\n";
    std::fs::write(dir.join("big.stl"), text).unwrap();
    let r = cli(&dir, &["orient", "big.stl"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(r.stdout.contains("height 1.000e15 mm"), "{}", r.stdout);
    let longest = r
        .stdout
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap();
    assert!(longest <= 6, "a run of {longest} digits in {}", r.stdout);
}
