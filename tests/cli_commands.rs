//! The command line's forms (clap): `slice` as the default command, the settings options in
//! the order given, help and version on stdout, usage errors as one short line with exit 2.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{TempDir, cli, cli_ok};

/// `dropslice MODEL...` and `dropslice slice MODEL...` write the same code, for one model
/// and for a build job of two.
#[test]
fn slice_is_the_default_command() {
    let dir = TempDir::new("commands");
    let cube = common::model("cube_20mm_ascii.stl").display().to_string();
    let bridge = common::model("bridge.obj").display().to_string();
    cli_ok(&[&cube, "-o", "a.gco", "-q"], &dir);
    cli_ok(&["slice", &cube, "-o", "b.gco", "-q"], &dir);
    cli_ok(&["-q", &cube, &bridge, "-o", "c.gco"], &dir);
    cli_ok(&["slice", &cube, &bridge, "-q", "-o", "d.gco"], &dir);
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert_eq!(read("a.gco"), read("b.gco"));
    assert_eq!(read("c.gco"), read("d.gco"));
    assert_ne!(read("a.gco"), read("c.gco"));
    // The output default: the model's name in the current directory.
    cli_ok(&["slice", &cube, "-q"], &dir);
    assert_eq!(read("cube_20mm_ascii.gco"), read("a.gco"));
}

/// A settings file replaces the settings options given before it; those given after it
/// override it. Options given twice: the last one counts.
#[test]
fn settings_options_apply_in_order() {
    let dir = TempDir::new("commands");
    let cube = common::model("cube_20mm_ascii.stl").display().to_string();
    std::fs::write(
        dir.join("s.json"),
        r#"{"contours": 3, "layer_height": 0.3}"#,
    )
    .unwrap();
    let header = |args: &[&str]| {
        let mut all = vec![cube.as_str(), "-q", "-o", "x.gco", "-o", "out.gco"];
        all.extend(args);
        cli_ok(&all, &dir);
        let text = std::fs::read_to_string(dir.join("out.gco")).unwrap();
        let value = |key: &str| {
            text.lines()
                .find_map(|l| l.strip_prefix(&format!("; {key} = ")))
                .unwrap_or_else(|| panic!("no {key} in the header"))
                .split(' ')
                .next()
                .unwrap()
                .to_string()
        };
        (value("layer_height"), value("contours"))
    };
    let h = |a: &str, b: &str| (a.to_string(), b.to_string());
    assert_eq!(
        header(&["--set", "layer_height=0.25", "--settings", "s.json"]),
        h("0.3", "3")
    );
    assert_eq!(
        header(&["--settings", "s.json", "--set", "layer_height=0.25"]),
        h("0.25", "3")
    );
    assert_eq!(
        header(&["--set", "contours=4", "--set", "contours=5"]),
        h("0.2", "5")
    );
    assert!(
        !dir.join("x.gco").exists(),
        "the first -o is replaced by the second"
    );
}

#[test]
fn help_and_version_go_to_stdout() {
    let dir = TempDir::new("commands");
    for (args, wants) in [
        (
            &["--help"][..],
            &[
                "Usage: dropslice [slice] MODEL...",
                "calibrate",
                "--list-settings",
                "Exit codes:",
                "job file",
            ][..],
        ),
        (&["-h"], &["Usage:", "--report", "--quiet"]),
        (
            &["slice", "--help"],
            &["Usage: dropslice [slice] MODEL...", "--settings"],
        ),
        (
            &["calibrate", "--help"],
            &[
                "Usage: dropslice calibrate PART.gco --mass GRAMS",
                "--density",
                "filling degree",
            ],
        ),
        (&["calibrate", "-h"], &["--mass <GRAMS>"]),
    ] {
        let r = cli_ok(args, &dir);
        assert!(r.stderr.is_empty(), "{args:?}: {}", r.stderr);
        for w in wants {
            assert!(r.stdout.contains(w), "{args:?}: no {w:?} in {}", r.stdout);
        }
    }
    let version = format!("dropslice {}\n", dropslice::VERSION);
    for args in [&["--version"][..], &["-V"], &["calibrate", "--version"]] {
        assert_eq!(cli_ok(args, &dir).stdout, version, "{args:?}");
    }
    let r = cli_ok(&["--list-settings"], &dir);
    for s in dropslice::base::settings::schema() {
        assert!(
            r.stdout.contains(&format!("\n{:<18} = ", s.name)) || r.stdout.starts_with(s.name),
            "{}",
            s.name
        );
    }
}

/// Usage errors: exit 2, nothing on stdout, one short line on stderr naming the problem,
/// no file left behind.
#[test]
fn usage_errors_are_one_short_line() {
    let dir = TempDir::new("commands");
    std::fs::write(dir.join("a.gco"), "G26 X0 Y0 Z0.2\n").unwrap();
    let long = format!("--{}", "x".repeat(100_000));
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![], "no model file given"),
        (vec!["slice"], "no model file given"),
        (vec!["-q"], "no model file given"),
        (vec!["--bogus", "m.stl"], "unknown option '--bogus'"),
        (vec!["m.stl", "--otput", "x.gco"], "did you mean '--output'"),
        (vec!["m.stl", "-o"], "--output needs a value"),
        (vec!["m.stl", "--set"], "--set needs a value"),
        (
            vec!["m.stl", "--set", "layer_height"],
            "--set expects name=value",
        ),
        (vec![&long, "m.stl"], "unknown option '--xxxx"),
        (
            vec!["calibrate", "a.gco", "b.gco", "--mass", "1"],
            "give one .gco file only ('b.gco'",
        ),
        (vec!["calibrate", "a.gco", "--mass"], "--mass needs a value"),
        (
            vec!["calibrate", "a.gco", "--mass", "1", "-o", "x"],
            "unknown option '-o'",
        ),
        (vec!["calibrate", "a.gco"], "--mass GRAMS is needed"),
        (
            vec!["slice", "m.stl", "calibrate", "--mass"],
            "unknown option '--mass'",
        ),
    ];
    for (args, want) in cases {
        let r = cli(&args, &dir);
        assert_eq!(r.code, Some(2), "{args:?}: {r:?}");
        assert!(r.stdout.is_empty(), "{args:?}: {}", r.stdout);
        assert!(
            r.stderr.contains(want),
            "{args:?}: no {want:?} in {}",
            r.stderr
        );
        assert_eq!(r.stderr.lines().count(), 1, "{args:?}: {}", r.stderr);
        assert!(r.stderr.starts_with("dropslice"), "{args:?}: {}", r.stderr);
        assert!(r.stderr.len() < 400, "{args:?}: {} bytes", r.stderr.len());
        assert_eq!(dir.files(), ["a.gco"], "{args:?}");
    }
}
