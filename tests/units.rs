//! The discharge units as a list on the command line (docs/spec.md "Discharge units"): a unit
//! the machine does not have is refused naming `units`; a material profile goes to the unit
//! `--profile unitN=FILE.json` names, and gives the code `--set unitN_…` gives.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{TempDir, model, run_cli};
use std::time::Duration;

fn run(dir: &TempDir, args: &[&str]) -> common::Run {
    let mut all: Vec<String> = vec![model("U_overhang.obj").display().to_string()];
    all.extend(args.iter().map(|s| s.to_string()));
    run_cli(&all, dir.path(), Duration::from_secs(300))
}

fn code(dir: &TempDir, args: &[&str], out: &str) -> String {
    let mut all = args.to_vec();
    all.extend(["-q", "-o", out]);
    let r = run(dir, &all);
    assert_eq!(r.code, Some(0), "{args:?}: {r:?}");
    std::fs::read_to_string(dir.join(out)).unwrap()
}

#[test]
fn a_unit_the_machine_does_not_have_is_refused_naming_units() {
    let dir = TempDir::new("units");
    for (args, named) in [
        (&["--set", "support=unit2"][..], "support"),
        (
            &["--set", "units=1", "--set", "support=unit1"][..],
            "support",
        ),
        (&["--set", "unit_order=2,0,1"][..], "unit_order"),
        (
            &["--set", "unit3_droplet_aspect=1.5"][..],
            "unit3_droplet_aspect",
        ),
    ] {
        let r = run(&dir, &[args, &["-q", "-o", "x.gco"]].concat());
        assert_eq!(r.code, Some(2), "{args:?}: {r:?}");
        assert!(
            r.stderr.contains(named) && r.stderr.contains("units ="),
            "{args:?}: {}",
            r.stderr
        );
        assert!(!dir.join("x.gco").exists());
    }
    // A part of a unit the machine lacks, in a job file.
    std::fs::copy(model("U_overhang.obj"), dir.join("u.obj")).unwrap();
    let job = r#"{"settings": {"units": 1}, "parts": [{"file": "u.obj", "unit": 1}]}"#;
    std::fs::write(dir.join("job.json"), job).unwrap();
    let r = run_cli(
        &["job.json", "-q", "-o", "j.gco"],
        dir.path(),
        Duration::from_secs(60),
    );
    assert_eq!(r.code, Some(2), "{r:?}");
    assert!(
        r.stderr.contains("parts[0].unit") && r.stderr.contains("units = 1"),
        "{}",
        r.stderr
    );
    // A unit beyond 1 on a machine that has it prints the support (T2).
    let r = run(&dir, &["--set", "units=3", "--set", "support=unit2", "-q"]);
    assert_eq!(r.code, Some(0), "{r:?}");
}

#[test]
fn a_material_profile_goes_to_the_unit_named() {
    let dir = TempDir::new("units-profile");
    let pva = r#"{"name": "PVA", "kind": "material", "settings": {"droplet_aspect": 1.5, "material_density": 1.19, "shrink_xy": 0.3}}"#;
    std::fs::write(dir.join("pva.json"), pva).unwrap();
    // Unit 1 (the support's unit) with the profile, and with the same values set by hand.
    let with_profile = code(
        &dir,
        &["--profile", "unit1=pva.json", "--set", "support=unit1"],
        "a.gco",
    );
    let by_hand = code(
        &dir,
        &[
            "--set",
            "support=unit1",
            "--set",
            "unit1_droplet_aspect=1.5",
            "--set",
            "unit1_material_density=1.19",
            "--set",
            "unit1_shrink_xy=0.3",
        ],
        "b.gco",
    );
    let profile_line = "; profiles = PVA (material, unit 1)\n";
    assert!(with_profile.contains(profile_line));
    assert_eq!(with_profile.replacen(profile_line, "", 1), by_hand);
    assert!(by_hand.contains("; unit1_droplet_aspect = 1.5\n"));
    // Unit 0's values untouched.
    assert!(with_profile.contains("; droplet_aspect = 1.04\n"));
    // Unit 2 needs a machine of three units.
    let r = run(&dir, &["--profile", "unit2=pva.json", "-q", "-o", "c.gco"]);
    assert_eq!(r.code, Some(2), "{r:?}");
    assert!(r.stderr.contains("unit2_droplet_aspect") && r.stderr.contains("units = 2"));
    // With three units the material goes to unit 2, which prints nothing here: the code is
    // the default code but for the profile's line.
    let three = code(
        &dir,
        &["--set", "units=3", "--profile", "unit2=pva.json"],
        "d.gco",
    );
    let plain = code(&dir, &[], "e.gco");
    let line = "; profiles = PVA (material, unit 2)\n";
    assert_eq!(three.replacen(line, "", 1), plain);
    // Not a unit, and a machine profile given to a unit.
    let r = run(&dir, &["--profile", "unit9=pva.json", "-q"]);
    assert_eq!(r.code, Some(2));
    assert!(r.stderr.contains("not a unit"), "{}", r.stderr);
    let m = r#"{"name": "M", "kind": "machine", "settings": {"plate_z": 180}}"#;
    std::fs::write(dir.join("m.json"), m).unwrap();
    let r = run(&dir, &["--profile", "unit1=m.json", "-q"]);
    assert_eq!(r.code, Some(2));
    assert!(r.stderr.contains("machine profile"), "{}", r.stderr);
}

#[test]
fn orient_takes_a_profile_for_a_unit() {
    let dir = TempDir::new("units-orient");
    let pva = r#"{"name": "PVA", "kind": "material", "settings": {"droplet_aspect": 1.5}}"#;
    std::fs::write(dir.join("pva.json"), pva).unwrap();
    let m = model("U_overhang.obj").display().to_string();
    let r = run_cli(
        &["orient", &m, "--profile", "unit1=pva.json"],
        dir.path(),
        Duration::from_secs(120),
    );
    assert_eq!(r.code, Some(0), "{r:?}");
    let r = run_cli(
        &["orient", &m, "--profile", "unit2=pva.json"],
        dir.path(),
        Duration::from_secs(120),
    );
    assert_eq!(r.code, Some(2), "{r:?}");
    assert!(r.stderr.contains("units = 2"), "{}", r.stderr);
}
