//! The plate rule on the command line (docs/jobs.md "The plate rule"): a part that does not
//! fit the plate is refused (exit 2, no file) with the turn or the scale that fits as the
//! `--set` or part keys to use, unless `allow_off_plate`; and the separate-bodies warning,
//! which is about one part, never about a job of several.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{TempDir, cli, cli_ok};

/// A box `size` mm written as `name` into `dir`.
fn box_file(dir: &TempDir, name: &str, size: [f32; 3]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, common::stl_bytes(&common::cuboid([0.0; 3], size))).unwrap();
    path.display().to_string()
}

/// Two boxes apart in one file: one part of two bodies.
fn two_box_file(dir: &TempDir, name: &str) -> String {
    let mut tris = common::cuboid([0.0; 3], [10.0, 10.0, 5.0]);
    tris.extend(common::cuboid([20.0, 0.0, 0.0], [30.0, 10.0, 5.0]));
    let path = dir.join(name);
    std::fs::write(&path, common::stl_bytes(&tris)).unwrap();
    path.display().to_string()
}

#[test]
fn a_part_deeper_than_the_plate_is_refused_with_the_turn_that_fits() {
    let dir = TempDir::new("plate-turn");
    // Nefertiti's footprint, 95.5 × 145 mm, on the 154 × 134 mm plate.
    let big = box_file(&dir, "tall.stl", [95.5, 145.0, 3.0]);
    let r = cli(&[&big, "-o", "tall.gco"], &dir);
    assert_eq!(r.code, Some(2), "{r:?}");
    assert_eq!(
        r.stderr.trim_end(),
        "dropslice: bad job: Part 1 “tall.stl” (95.5 × 145 mm) is larger than the plate (154 × 134 mm); turned 90° about z it fits. Use --set rotate_z=90, or --set allow_off_plate=true to slice it as it is."
    );
    assert!(!r.stderr.contains("Arrange"), "{}", r.stderr);
    assert_eq!(dir.files(), vec!["tall.stl".to_string()]);
    // The change it names fits.
    cli_ok(
        &[&big, "-q", "-o", "tall.gco", "--set", "rotate_z=90"],
        &dir,
    );
    assert!(dir.join("tall.gco").exists());
    // allow_off_plate slices it as it is, the sentence as a warning in the summary and header.
    let r = cli(
        &[&big, "-o", "allowed.gco", "--set", "allow_off_plate=true"],
        &dir,
    );
    r.says(
        0,
        "warning: Part 1 “tall.stl” (95.5 × 145 mm) is larger than the plate",
    );
    let text = std::fs::read_to_string(dir.join("allowed.gco")).unwrap();
    assert!(text.contains("; warning: Part 1 “tall.stl” (95.5 × 145 mm) is larger than the plate"));
    assert!(text.contains("; allow_off_plate = true"));
}

#[test]
fn a_part_larger_than_the_plate_both_ways_is_refused_with_the_scale_that_fits() {
    let dir = TempDir::new("plate-scale");
    let big = box_file(&dir, "big.stl", [200.0, 150.0, 3.0]);
    let r = cli(&[&big, "-o", "big.gco"], &dir);
    r.says(2, "Part 1 “big.stl” (200 × 150 mm) is larger than the plate (154 × 134 mm); scaled to 77 % it fits. Use --set scale_x=0.77 --set scale_y=0.77 --set scale_z=0.77, or --set allow_off_plate=true");
    assert_eq!(dir.files(), vec!["big.stl".to_string()]);
    // The change it names fits; so does the part as it is on a larger plate.
    let sliced_with = |sets: &[&str]| {
        let mut args = vec![big.as_str(), "-q", "-o", "big.gco"];
        for set in sets {
            args.extend(["--set", set]);
        }
        cli_ok(&args, &dir);
    };
    sliced_with(&["scale_x=0.77", "scale_y=0.77", "scale_z=0.77"]);
    sliced_with(&["plate_x=200", "plate_y=150"]);
}

#[test]
fn a_job_file_names_the_part_keys_and_a_placed_part_off_the_plate_is_refused() {
    let dir = TempDir::new("plate-job");
    box_file(&dir, "tall.stl", [95.5, 145.0, 3.0]);
    box_file(&dir, "cube.stl", [20.0, 20.0, 20.0]);
    // A job refused: its code not written.
    let refused = |name: &str, job: &str, says: &str| {
        let (file, out) = (format!("{name}.json"), format!("{name}.gco"));
        std::fs::write(dir.join(&file), job).unwrap();
        cli(&[&file, "-o", &out], &dir).says(2, says);
        assert!(!dir.join(&out).exists());
    };
    refused(
        "job",
        r#"{"parts": [{"file": "cube.stl"}, {"file": "tall.stl"}]}"#,
        "Part 2 “tall.stl” (95.5 × 145 mm) is larger than the plate (154 × 134 mm); turned 90° about z it fits. Use parts[1].rotate_z = 90, or the setting allow_off_plate = true",
    );
    // A part placed past an edge: moving it (or the arrangement) helps.
    refused(
        "placed",
        r#"{"parts": [{"file": "cube.stl", "place_x": 140, "place_y": 0}]}"#,
        "Part 1 “cube.stl” reaches 6 mm past the plate's right edge — move it or press Arrange. Change parts[0].place_x/place_y, or leave them out to have it arranged",
    );
    // Allowed by the job's settings.
    std::fs::write(
        dir.join("allowed.json"),
        r#"{"settings": {"allow_off_plate": true}, "parts": [{"file": "cube.stl", "place_x": 140, "place_y": 0}]}"#,
    )
    .unwrap();
    cli_ok(&["allowed.json", "-q", "-o", "allowed.gco"], &dir);
}

#[test]
fn separate_bodies_are_warned_of_per_part_never_for_a_job_of_several() {
    let dir = TempDir::new("plate-bodies");
    let cube = common::model("cube_20mm_ascii.stl").display().to_string();
    let bridge = common::model("bridge.obj").display().to_string();
    // Two files: two parts, no "separate bodies".
    let r = cli_ok(&[&cube, &bridge, "-o", "two.gco"], &dir);
    assert!(!r.stderr.contains("separate bodies"), "{}", r.stderr);
    let text = std::fs::read_to_string(dir.join("two.gco")).unwrap();
    assert!(!text.contains("separate bodies"));
    // Two copies of one part: neither.
    std::fs::write(
        dir.join("copies.json"),
        format!(r#"{{"parts": [{{"file": {cube:?}, "copies": 2}}]}}"#),
    )
    .unwrap();
    let r = cli_ok(&["copies.json", "-o", "copies.gco"], &dir);
    assert!(!r.stderr.contains("separate bodies"), "{}", r.stderr);
    // One file of two bodies: warned, naming the part, alone and beside another file.
    let pair = two_box_file(&dir, "pair.stl");
    let want = "warning: Part “pair.stl” has 2 separate bodies; where they overlap they are printed as one";
    let r = cli_ok(&[&pair, "-o", "pair.gco"], &dir);
    assert!(r.stderr.contains(want), "{}", r.stderr);
    let r = cli_ok(&[&pair, &cube, "-o", "both.gco"], &dir);
    assert_eq!(
        r.stderr.matches("separate bodies").count(),
        1,
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains(want), "{}", r.stderr);
    let text = std::fs::read_to_string(dir.join("both.gco")).unwrap();
    assert!(text.contains(&format!("; {want}")));
}
