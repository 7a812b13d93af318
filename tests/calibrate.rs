//! `dropslice calibrate` (docs/spec.md "Calibrating the droplet size from a printed part"): a part
//! of known droplet count and a mass chosen for a known droplet volume give back exactly that
//! volume, its filling degree and the aspect whose B²H cell holds it; every refusal exits 2
//! with a message that says what to check.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{B, H, TempDir};
use dropslice::output::calibrate::{CountSource, calibrate_gcode};
use std::path::Path;
use std::time::Duration;

fn cli<S: AsRef<std::ffi::OsStr> + std::fmt::Debug>(args: &[S], dir: &Path) -> common::Run {
    let r = common::run_cli(args, dir, Duration::from_secs(60));
    assert!(!r.timed_out, "{args:?} timed out");
    r
}

/// `dropslice calibrate ARGS` (`args` separated by spaces): the arguments and the run.
fn calibrate<'a>(dir: &Path, args: &'a str) -> (Vec<&'a str>, common::Run) {
    let all: Vec<&str> = ["calibrate"].into_iter().chain(args.split(' ')).collect();
    let r = cli(&all, dir);
    (all, r)
}

/// `dropslice calibrate ARGS` (`args` separated by spaces) succeeds and prints each of `want`.
fn assert_calibrates(dir: &Path, args: &str, want: &[&str]) {
    let (all, r) = calibrate(dir, args);
    assert_eq!(r.code, Some(0), "{all:?}: {r:?}");
    for w in want {
        assert!(
            r.stdout.contains(w),
            "{all:?}: expected {w:?} in {}",
            r.stdout
        );
    }
}

/// `dropslice calibrate ARGS` (`args` separated by spaces) is refused: exit code 2, a short message containing `want`,
/// nothing on stdout.
fn assert_refused(dir: &Path, args: &str, want: &str) {
    let (all, r) = calibrate(dir, args);
    assert_eq!(r.code, Some(2), "{all:?}: {r:?}");
    assert!(
        r.stderr.contains(want),
        "{all:?}: expected {want:?} in {:?}",
        r.stderr
    );
    assert!(
        r.stderr.len() < 600,
        "{} bytes: {}",
        r.stderr.len(),
        r.stderr
    );
    assert!(r.stdout.is_empty(), "{all:?}: {}", r.stdout);
}

/// The cube's code and its header's droplet total.
fn cube_code(dir: &TempDir) -> (String, u64) {
    let text = common::slice_cli(&common::model("cube_20mm_ascii.stl"), &[]);
    let n = text
        .lines()
        .find_map(|l| l.strip_prefix("; droplets total"))
        .and_then(|r| r.trim_start().strip_prefix('='))
        .map(|v| v.trim().parse::<u64>().unwrap())
        .expect("a droplet total in the header");
    std::fs::write(dir.join("cube.gco"), &text).unwrap();
    (text, n)
}

#[test]
fn known_volume_gives_its_filling_and_aspect() {
    let dir = TempDir::new("calibrate");
    let (text, n) = cube_code(&dir);
    // A 20 mm cube at B = 0.208, H = 0.2: about 8000 mm³ / B²H droplets (six digits, so the
    // CLI writes them with one thousands separator).
    assert!((800_000..1_000_000).contains(&n), "{n}");
    let rho = 1.18;
    let cell = B * B * H;
    for fill in [0.85, 1.0, 1.12] {
        let v = fill * cell; // mm³
        let mass = n as f64 * rho * v / 1000.0; // g
        let c = calibrate_gcode(&text, mass, Some(rho)).unwrap();
        assert_eq!(c.droplets, n);
        assert_eq!(c.count_source, CountSource::Header);
        assert!(
            (c.droplet_volume_mm3 - v).abs() < 1e-12 * v.max(1.0),
            "{c:?}"
        );
        assert!((c.cell_volume_mm3 - cell).abs() < 1e-15);
        assert!((c.filling_degree - fill).abs() < 1e-9, "{c:?}");
        // The aspect a with (a·H)²·H = V.
        let a = c.suggested_droplet_aspect;
        assert!(((a * H).powi(2) * H - v).abs() < 1e-12, "{c:?}");
        assert!((a - 1.04 * fill.sqrt()).abs() < 1e-9);
        assert_eq!(c.current_droplet_aspect, 1.04);

        // The CLI prints the same figures.
        assert_calibrates(
            dir.path(),
            &format!("cube.gco --mass {mass} --density {rho}"),
            &[
                &format!("filling degree    {fill:.3}"),
                &format!("{a:.3} suggested (now 1.04)"),
                &format!("{},{:03} droplets of", n / 1000, n % 1000),
                "from the header",
            ],
        );
    }
}

#[test]
fn count_from_the_commands_without_a_header_total() {
    let dir = TempDir::new("calibrate");
    let (text, n) = cube_code(&dir);
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("; droplets total"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(dir.join("bare.gco"), &without).unwrap();
    let c = calibrate_gcode(&without, 10.0, None).unwrap();
    assert_eq!(c.count_source, CountSource::Commands);
    assert_eq!(c.droplets, n, "counted from G25/G26 as the header counts");
    // The header's material_density (1.04) is the default density.
    assert_eq!(c.density_g_cm3, 1.04);
    assert_calibrates(dir.path(), "bare.gco --mass 10", &["counted from the code"]);
}

#[test]
fn refusals_exit_2_with_a_reason() {
    let dir = TempDir::new("calibrate");
    let (_, n) = cube_code(&dir);
    // No count in the header and no droplets in the commands.
    std::fs::write(
        dir.join("empty.gco"),
        "; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\nG01 X0.0000 Y0.0000 Z0.2000\n",
    )
    .unwrap();
    // A droplet size whose suggestion leaves droplet_aspect's range (at most 10).
    std::fs::write(
        dir.join("wide.gco"),
        "; layer_height = 0.2 (mm)\n; droplet_aspect = 8\n; droplets total = 1000\nG26 X0.0000 Y0.0000 Z0.2000\n",
    )
    .unwrap();
    std::fs::write(dir.join("model.stl"), common::model_bytes("3DBenchy.stl")).unwrap();
    // A filament printer's code (as PrusaSlicer writes it).
    std::fs::write(
        dir.join("fdm.gcode"),
        "; generated by PrusaSlicer 2.7.1\nM73 P0 R12\nM140 S60\nM104 S215\nG28\nG1 X10 Y10 Z0.2 E1.5 F1200\n; layer_height = 0.2\n",
    )
    .unwrap();
    let cell = B * B * H;
    let sane = n as f64 * 1.04 * cell / 1000.0;
    // wide: cell (1.6)²·0.2 = 0.512 mm³; a filling of 4 suggests aspect 16.
    let wide_mass = 1000.0 * 1.04 * 4.0 * 0.512 / 1000.0;
    // [arguments after `calibrate`, separated by spaces; what the message must say]
    let cases: Vec<(String, &str)> = vec![
        ("empty.gco --mass 1".into(), "sets no droplets"),
        ("cube.gco --mass 0".into(), "positive number of grams"),
        ("cube.gco --mass -3".into(), "positive number of grams"),
        ("cube.gco --mass NaN".into(), "not a number"),
        ("cube.gco --mass inf".into(), "not a number"),
        (
            format!("cube.gco --mass {}", sane * 10.0),
            "impossible: check the mass",
        ),
        (format!("cube.gco --mass {}", sane / 10.0), "impossible"),
        (
            format!("cube.gco --mass {sane} --density 0"),
            "density must be greater than 0",
        ),
        (format!("wide.gco --mass {wide_mass}"), "outside its range"),
        ("missing.gco --mass 1".into(), "cannot open"),
        ("model.stl --mass 1".into(), "not a text file"),
        (
            "fdm.gcode --mass 1".into(),
            "fdm.gcode: line 2: this is G-code for another kind of printer (it has M73, M140, M104, G1 … E…): dropslice reads the droplet printer's code",
        ),
        ("cube.gco".into(), "--mass GRAMS is needed"),
        ("--mass 1".into(), "no .gco file given"),
    ];
    for (args, want) in cases {
        assert_refused(dir.path(), &args, want);
    }
}

/// A code of more droplets than the viewer expands (50 million): 700 G25 lines of 20 m each,
/// 67 million droplets in a file of 20 kB. `calibrate` counts them by arithmetic, with the
/// header's total and without it, and gives the same figures either way.
#[test]
fn large_codes_are_counted_not_expanded() {
    let dir = TempDir::new("calibrate");
    let lines = 700;
    let per_line = common::line_droplets(20_000.0, B);
    let n = lines * per_line;
    assert!(n > dropslice::output::gcode_read::MAX_DROPLETS, "{n}");
    let mut body = String::new();
    for k in 0..lines {
        let x = if k % 2 == 0 { 20_000 } else { 0 };
        body += &format!("G25 X{x}.0000 Y0.0000 Z0.2000\n");
    }
    let head = "; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\n";
    let with_total = format!("{head}; droplets total = {n}\n{body}");
    let without = format!("{head}{body}");
    std::fs::write(dir.join("total.gco"), &with_total).unwrap();
    std::fs::write(dir.join("bare.gco"), &without).unwrap();
    // The viewer refuses to expand it.
    let e = dropslice::output::gcode_read::read_gcode(&without).unwrap_err();
    assert!(e.0.contains("50 million"), "{e}");
    // A filling of exactly one cell at density 1.04.
    let mass = n as f64 * 1.04 * B * B * H / 1000.0;
    for (file, text, source) in [
        ("total.gco", &with_total, CountSource::Header),
        ("bare.gco", &without, CountSource::Commands),
    ] {
        let c = calibrate_gcode(text, mass, None).unwrap();
        assert_eq!((c.droplets, c.count_source), (n, source), "{file}");
        assert!((c.filling_degree - 1.0).abs() < 1e-9, "{file}: {c:?}");
        assert_calibrates(
            dir.path(),
            &format!("{file} --mass {mass}"),
            &[&format!("droplets          {n} (")],
        );
    }
}

/// Numbers and files that used to give long messages or hangs: short messages, exit 2.
#[test]
fn hostile_arguments_are_refused_briefly() {
    let dir = TempDir::new("calibrate");
    let (_, n) = cube_code(&dir);
    let sane = n as f64 * 1.04 * B * B * H / 1000.0;
    let fifo = dir.join("fifo.gco");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let long = "7".repeat(100_000);
    // [arguments after `calibrate`, separated by spaces; what the message must say]
    let cases: Vec<(String, &str)> = vec![
        ("cube.gco --mass 1e308".into(), "(1e308 g over"),
        (
            format!("cube.gco --mass {sane} --density 1e300"),
            "got 1e300",
        ),
        (format!("cube.gco --mass x{long}"), "not a number"),
        ("fifo.gco --mass 1".into(), "not a regular file"),
        ("/dev/zero --mass 1".into(), "not a regular file"),
    ];
    for (args, want) in cases {
        assert_refused(dir.path(), &args, want);
    }
}
