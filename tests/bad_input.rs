//! Bad input, through the CLI and the library (DESIGN.md "Errors": no input a user can give
//! may panic or hang). Every row must exit with code 2 (not 101 = panic, not a hang), print one
//! `dropslice: ` line on stderr naming the problem (warnings aside), and leave no output file
//! behind — an existing output file stays untouched. `Job::new` must return `Err` on each bad
//! file, never panic.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{Rng, TempDir, ascii_stl, binary_stl};
use dropslice::base::settings::{Kind, schema};
use dropslice::{Job, Settings};
use std::time::Duration;

const TIMEOUT: Duration = Duration::from_secs(20);
const EXISTING: &str = "; an existing output file that a failed run must not touch\n";

/// What a row gives the CLI.
enum Input {
    /// A model file with these bytes (written as `model.stl`).
    Bytes(Vec<u8>),
    /// A model path that does not exist.
    Missing,
    /// A directory given as the model.
    Directory,
    /// A model file with this name and these bytes.
    Named(&'static str, Vec<u8>),
    /// A path given as the model as it is; `{dir}` is replaced by the row's temp directory.
    Path(&'static str),
    /// A job file (`job.json`, this text) beside the 20 mm cube as `cube.stl`.
    Job(String),
}

struct Row {
    name: String,
    input: Input,
    /// Extra arguments; `{dir}` is replaced by the row's temp directory.
    args: Vec<String>,
    /// A settings file written as `settings.json` (used with `--settings {dir}/settings.json`).
    settings_json: Option<String>,
    /// The error line must contain one of these (case-insensitive).
    keywords: Vec<String>,
    /// Creates a FIFO `fifo` in the row's directory (nothing ever writes to it).
    fifo: bool,
    /// ... and all of these (case-insensitive).
    all: Vec<String>,
}

/// Most bytes of stderr of any row (messages are bounded: `dropslice::base::error`).
const MAX_STDERR: usize = 2500;
/// Most bytes of stderr of the rows about hostile sizes (limits_rows).
const SHORT_STDERR: usize = 1000;

fn row(name: impl Into<String>, input: Input, keywords: &[&str]) -> Row {
    Row {
        name: name.into(),
        input,
        args: Vec::new(),
        settings_json: None,
        keywords: keywords.iter().map(|s| s.to_string()).collect(),
        fifo: false,
        all: Vec::new(),
    }
}

fn setting_row(name: impl Into<String>, set: String, keywords: &[&str]) -> Row {
    let mut r = row(
        name,
        Input::Bytes(common::model_bytes("cube_20mm_ascii.stl")),
        keywords,
    );
    r.args = vec!["--set".into(), set];
    r
}

fn json_row(name: impl Into<String>, json: &str, keywords: &[&str]) -> Row {
    let mut r = row(
        name,
        Input::Bytes(common::model_bytes("cube_20mm_ascii.stl")),
        keywords,
    );
    r.args = vec!["--settings".into(), "{dir}/settings.json".into()];
    r.settings_json = Some(json.into());
    r
}

const TRUNCATED: &[&str] = &["truncated", "too short", "empty"];
const NOT_FINITE: &[&str] = &["NaN", "infinit", "finite"];
const NOT_STL: &[&str] = &[
    "not an stl",
    "not ascii stl",
    "neither",
    "truncated",
    "too short",
];

/// Bad model files (bytes), with the keywords their message must contain.
fn bad_files() -> Vec<(String, Vec<u8>, Vec<&'static str>)> {
    let mut v: Vec<(String, Vec<u8>, Vec<&'static str>)> = Vec::new();
    v.push(("empty file".into(), Vec::new(), vec!["empty"]));

    // Random bytes, several seeds and sizes 1..5000.
    for seed in 1..=6u64 {
        let mut rng = Rng::new(seed);
        for size in [
            1,
            5,
            83,
            84,
            85,
            134,
            1000,
            5000,
            1 + rng.below(4999) as usize,
        ] {
            v.push((
                format!("random bytes seed {seed} size {size}"),
                rng.bytes(size),
                NOT_STL.to_vec(),
            ));
        }
    }

    // A valid binary STL truncated at many points.
    let screw = common::model_bytes("M3x10_screw.stl");
    let len = screw.len();
    let mut cuts = vec![
        0,
        1,
        2,
        5,
        40,
        79,
        80,
        81,
        83,
        84,
        85,
        96,
        108,
        133,
        134,
        135,
        159,
        184,
        len - 1,
        len - 2,
        len - 25,
        len - 49,
        len - 50,
        len - 51,
    ];
    for k in 1..=16 {
        let record = (len - 84) / 50 * k / 17;
        cuts.push(84 + 50 * record + (k * 7) % 50); // mid-record (and some on a boundary)
    }
    cuts.sort_unstable();
    cuts.dedup();
    for cut in cuts {
        v.push((
            format!("M3x10_screw.stl truncated at {cut} of {len} bytes"),
            screw[..cut].to_vec(),
            TRUNCATED.to_vec(),
        ));
    }

    // An ASCII STL truncated in the middle of a facet.
    let cube = common::model_bytes("cube_20mm_ascii.stl");
    let text = String::from_utf8(cube.clone()).unwrap();
    let vertices: Vec<usize> = text.match_indices("vertex").map(|(i, _)| i).collect();
    for (what, k, extra) in [
        ("in facet 1 after its first vertex keyword", 0, 8),
        ("in facet 1 between two vertices", 1, 0),
        ("in facet 6 inside a vertex's numbers", 16, 10),
        ("in the last facet before its third vertex", 35, 0),
        ("in the last facet inside its third vertex", 35, 9),
    ] {
        let cut = vertices[k] + extra;
        v.push((
            format!("cube_20mm_ascii.stl truncated {what} (byte {cut})"),
            cube[..cut].to_vec(),
            vec!["truncated"],
        ));
    }
    let facet_open = text.match_indices("outer loop").nth(3).unwrap().0;
    v.push((
        "cube_20mm_ascii.stl truncated after 'outer loop' of facet 4".into(),
        cube[..facet_open + 10].to_vec(),
        vec!["truncated"],
    ));

    // NaN and infinite coordinates, binary.
    let tri_count = (len - 84) / 50;
    for (what, x) in [
        ("NaN", f32::NAN),
        ("+inf", f32::INFINITY),
        ("-inf", f32::NEG_INFINITY),
    ] {
        for t in [0, tri_count / 2, tri_count - 1] {
            for corner in [0, 2] {
                let mut b = screw.clone();
                let o = 84 + 50 * t + 12 + 12 * corner + 4; // y of that corner
                b[o..o + 4].copy_from_slice(&x.to_le_bytes());
                v.push((
                    format!("M3x10_screw.stl with {what} at triangle {t} corner {corner}"),
                    b,
                    NOT_FINITE.to_vec(),
                ));
            }
        }
    }
    // NaN and infinite coordinates, ASCII.
    let first_vertex_line = text[vertices[4]..].split('\n').next().unwrap();
    for bad in ["nan", "NaN", "inf", "-inf", "infinity", "1e39", "-3.5e38"] {
        let replaced = format!("vertex {bad} 0 0");
        let t = text.replacen(first_vertex_line, &replaced, 1);
        assert_ne!(t, text);
        v.push((
            format!("cube_20mm_ascii.stl with a coordinate '{bad}'"),
            t.into_bytes(),
            NOT_FINITE.to_vec(),
        ));
    }

    // Zero volume: every triangle in one plane; a single vertical triangle; only degenerate
    // triangles.
    let flat = [
        [[0.0, 0.0, 1.0], [10.0, 0.0, 1.0], [10.0, 10.0, 1.0]],
        [[0.0, 0.0, 1.0], [10.0, 10.0, 1.0], [0.0, 10.0, 1.0]],
        [[0.0, 0.0, 1.0], [10.0, 10.0, 1.0], [10.0, 0.0, 1.0]],
        [[0.0, 0.0, 1.0], [0.0, 10.0, 1.0], [10.0, 10.0, 1.0]],
    ];
    v.push((
        "binary mesh with every triangle in the plane z = 1".into(),
        binary_stl(b"flat", &flat),
        vec!["flat", "nothing to print"],
    ));
    let s = |t: [[f32; 3]; 3]| t.map(|p| p.map(|c| c.to_string()));
    v.push((
        "ASCII mesh with every triangle in the plane z = 1".into(),
        ascii_stl(&flat.map(s)),
        vec!["flat", "nothing to print"],
    ));
    // A flat mesh standing on its edge after rotation is not flat; lying flat after
    // rotate_x = 90 it is: covered by the settings rows below.
    let vertical = [[[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 0.0, 10.0]]];
    v.push((
        "binary single vertical triangle".into(),
        binary_stl(b"vertical", &vertical),
        vec!["nothing to print", "no droplet"],
    ));
    v.push((
        "ASCII single vertical triangle".into(),
        ascii_stl(&vertical.map(s)),
        vec!["nothing to print", "no droplet"],
    ));
    let needle = [
        [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 5.0]],
        [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 1.0]],
    ];
    v.push((
        "only degenerate triangles".into(),
        binary_stl(b"degenerate", &needle),
        vec!["degenerate", "no surface", "nothing to print"],
    ));
    v.push((
        "binary STL declaring 0 triangles".into(),
        binary_stl(b"none", &[]),
        vec!["no triangles", "empty", "no facets"],
    ));
    v.push((
        "ASCII STL without facets".into(),
        b"solid nothing\nendsolid nothing\n".to_vec(),
        vec!["no facets", "no triangles", "empty"],
    ));

    // Not an STL at all.
    v.push(("a PNG file".into(), png_bytes(), NOT_STL.to_vec()));
    v.push((
        "a tiny PNG file".into(),
        b"\x89PNG\r\n\x1a\n".to_vec(),
        NOT_STL.to_vec(),
    ));
    let json = serde_json::to_string_pretty(&Settings::default()).unwrap();
    v.push(("a JSON file".into(), json.into_bytes(), NOT_STL.to_vec()));
    v.push((
        "a short JSON file".into(),
        b"{\"solid\": true}".to_vec(),
        NOT_STL.to_vec(),
    ));
    v
}

/// A small PNG-like file: signature, IHDR, noise, IEND.
fn png_bytes() -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x10\0\0\0\x10\x08\x06\0\0\0".to_vec();
    png.extend(Rng::new(99).bytes(400));
    png.extend(b"\0\0\0\0IEND\xaeB`\x82");
    png
}

/// Every row of the CLI table.
fn rows() -> Vec<Row> {
    let mut rows: Vec<Row> = bad_files()
        .into_iter()
        .map(|(name, bytes, kw)| row(name, Input::Bytes(bytes), &kw))
        .collect();
    rows.push(row(
        "nonexistent path",
        Input::Missing,
        &["cannot open", "no such file"],
    ));
    rows.push(row(
        "a directory as the model",
        Input::Directory,
        &["cannot open", "directory"],
    ));
    rows.extend(budget_rows());

    // Every number setting out of range, NaN, infinite, not a number.
    for spec in schema() {
        if !matches!(spec.domain.kind, Kind::Number | Kind::Integer) {
            continue;
        }
        let (min, max) = (spec.domain.min.unwrap(), spec.domain.max.unwrap());
        let below = if spec.domain.min_exclusive {
            min
        } else {
            min - 1.0
        };
        let n = spec.name;
        for (what, value) in [
            ("below min", format!("{below}")),
            ("far below min", format!("{}", min - 1e6)),
            ("above max", format!("{}", max + 1.0)),
            ("far above max", "1e300".to_string()),
            ("NaN", "NaN".to_string()),
            ("nan", "nan".to_string()),
            ("inf", "inf".to_string()),
            ("-inf", "-inf".to_string()),
            ("not a number", "twelve".to_string()),
            ("empty", String::new()),
        ] {
            rows.push(setting_row(
                format!("--set {n}={value} ({what})"),
                format!("{n}={value}"),
                &[n],
            ));
        }
        // The same through a settings file (JSON numbers only: no NaN in JSON). A negative
        // `contours` is a known bug (see `known_bug_rows`).
        if n != "contours" {
            rows.push(json_row(
                format!("--settings {{\"{n}\": {below}}} (below min)"),
                &format!("{{\"{n}\": {below}}}"),
                &[n],
            ));
        }
        rows.push(json_row(
            format!("--settings {{\"{n}\": {}}} (above max)", max + 1.0),
            &format!("{{\"{n}\": {}}}", max + 1.0),
            &[n],
        ));
    }
    for (set, kw) in [
        ("no_such_setting=1", "no_such_setting"),
        ("LAYER_HEIGHT=0.2", "LAYER_HEIGHT"),
        ("contour_order=sideways", "contour_order"),
        ("print_order=", "print_order"),
        ("slice_plane=bottom", "slice_plane"),
        ("close_loops=maybe", "close_loops"),
        ("contours=2.5", "contours"),
        ("layer_height=0.000001", "layer_height"),
    ] {
        rows.push(setting_row(format!("--set {set}"), set.into(), &[kw]));
    }
    let mut r = setting_row("--set without '='", "layer_height".into(), &["--set"]);
    r.keywords.push("name=value".into());
    rows.push(r);
    // A part that would be 20 000 mm tall: the layer guard must stop it, not run for hours.
    let mut r = setting_row(
        "scale_z=1000 with layer_height=0.001 (20 million layers)",
        "scale_z=1000".into(),
        &["layer_height", "scale_z", "layers"],
    );
    r.args.extend(["--set".into(), "layer_height=0.001".into()]);
    rows.push(r);
    // Valid sizes but far too many droplets (hours of work, hundreds of GB of code).
    rows.push(setting_row(
        "layer_height=0.0002 on the cube (1e15 droplets)",
        "layer_height=0.0002".into(),
        &["droplets"],
    ));
    // Lying flat after rotation.
    rows.push(setting_row(
        "a flat mesh is flat whatever the rotation",
        "rotate_x=0".into(),
        &["flat"],
    ));
    rows.last_mut().unwrap().input = Input::Bytes(binary_stl(
        b"flat",
        &[[[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0]]],
    ));

    for (name, json, kw) in [
        ("bad JSON", "{bad", &["JSON"][..]),
        ("empty file", "", &["JSON"][..]),
        (
            "unknown name",
            "{\"no_such_setting\": 1}",
            &["no_such_setting"][..],
        ),
        (
            "string for a number",
            "{\"layer_height\": \"thick\"}",
            &["layer_height", "JSON"][..],
        ),
        (
            "fraction for an integer",
            "{\"contours\": 2.5}",
            &["contours", "JSON"][..],
        ),
        (
            "bad enum",
            "{\"contour_order\": \"sideways\"}",
            &["contour_order", "JSON"][..],
        ),
    ] {
        rows.push(json_row(format!("--settings: {name}"), json, kw));
    }
    let mut r = row(
        "--settings file that does not exist",
        Input::Bytes(common::model_bytes("cube_20mm_ascii.stl")),
        &["settings file", "cannot read"],
    );
    r.args = vec!["--settings".into(), "{dir}/nowhere.json".into()];
    rows.push(r);
    rows
}

/// The droplet estimate counts every unit and the support (issue 22): each row would otherwise
/// run for minutes or exhaust memory. The message names the unit and the setting to change.
fn budget_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for aspect in ["0.001", "0.002"] {
        let mut r = row(
            format!("a unit-1 part with unit1_droplet_aspect {aspect}"),
            Input::Job(format!(
                r#"{{"settings": {{"unit1_droplet_aspect": {aspect}}}, "parts": [{{"file": "cube.stl", "unit": 1}}]}}"#
            )),
            &["droplets"],
        );
        r.all = vec!["unit 1".into(), "raise unit1_droplet_aspect".into()];
        rows.push(r);
        // The same by `--set` on a job that asks for nothing unusual.
        let mut r = row(
            format!("a unit-1 part, --set unit1_droplet_aspect={aspect}"),
            Input::Job(
                r#"{"parts": [{"file": "cube.stl"}, {"file": "cube.stl", "unit": 1}]}"#.into(),
            ),
            &["droplets"],
        );
        r.args = vec!["--set".into(), format!("unit1_droplet_aspect={aspect}")];
        r.all = vec!["unit 1".into(), "raise unit1_droplet_aspect".into()];
        rows.push(r);
        // Support is printed by unit 1: with a tiny B₁ its droplets are counted too (a model
        // with overhangs: the support lies only under down-facing facets).
        let mut r = row(
            format!("overhang.obj, support on, unit1_droplet_aspect={aspect}"),
            Input::Named("overhang.obj", common::model_bytes("overhang.obj")),
            &["droplets"],
        );
        r.args = vec![
            "--set".into(),
            "support=unit1".into(),
            "--set".into(),
            format!("unit1_droplet_aspect={aspect}"),
        ];
        r.all = vec![
            "bad setting support".into(),
            "B₁".into(),
            "raise unit1_droplet_aspect".into(),
            "support = off".into(),
        ];
        rows.push(r);
    }
    // With support on: a small unit-0 B that is fine without support (1.6e9 droplets at most),
    // but with support the pass would list up to 1.7e7 droplets of a layer at once; and far
    // too small a unit-0 B, refused by unit 0's own count, support or not.
    let cases: [(&str, &[&str]); 2] = [
        (
            "0.025",
            &["bad setting droplet_aspect", "unit 0", "support = off"],
        ),
        ("0.001", &["unit 0", "droplet_aspect"]),
    ];
    for (aspect, all) in cases {
        let mut r = setting_row(
            format!("support on, droplet_aspect={aspect}"),
            "support=unit1".into(),
            &["droplets"],
        );
        r.args
            .extend(["--set".into(), format!("droplet_aspect={aspect}")]);
        r.all = all.iter().map(|&w| w.into()).collect();
        rows.push(r);
    }
    rows
}

/// Tiny values: refused by their range, the value shown as typed (no 300-digit number), and a
/// unit-1 setting refused for its range, not for a budget of droplets it does not print.
fn tiny_value_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for (set, kw) in [
        ("unit1_droplet_aspect=1e-300", "unit1_droplet_aspect"),
        ("plate_z=1e-300", "plate_z"),
        ("layer_height=5e-324", "layer_height"),
        ("layer_height=1e-300", "layer_height"),
        ("droplet_aspect=1e-300", "droplet_aspect"),
        ("droplet_rate=1e-300", "droplet_rate"),
        ("travel_speed=5e-324", "travel_speed"),
        ("support_density=1e-300", "support_density"),
    ] {
        let mut r = setting_row(format!("--set {set} (tiny)"), set.into(), &[kw]);
        let value = set.split_once('=').unwrap().1;
        r.all = vec!["out of range".into(), "at least".into(), value.into()];
        rows.push(r);
    }
    rows
}

#[test]
fn cli_refuses_tiny_values_by_their_range_in_a_short_message() {
    let failures: Vec<String> = tiny_value_rows()
        .iter()
        .filter_map(|r| check_row_within(r, 400).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_unit1_setting_is_checked_for_droplets_only_where_unit_1_prints() {
    // The least B₁ (unit1_droplet_aspect 0.001: B₁ = 0.2 µm) on a job without unit-1 parts and
    // with support off: nothing of unit 1 is printed, the job is sliced.
    let dir = TempDir::new("unit1");
    let cube = common::model("cube_20mm_ascii.stl");
    let args = [
        cube.to_str().unwrap(),
        "-q",
        "-o",
        "out.gco",
        "--set",
        "unit1_droplet_aspect=0.001",
        "--set",
        "support=off",
    ];
    let run = common::run_cli(&args, dir.path(), TIMEOUT);
    assert_eq!(run.code, Some(0), "{run:?}");
}

/// Settings-file regressions (fixed in 2e4b1c7): a JSON array was read as the struct's fields
/// in order (layer_height = 1, droplet_aspect = 2, contours = 3; exit 0), and a negative
/// `contours` gave serde's "invalid value: integer `-1`, expected u32" without the name.
fn settings_file_rows() -> Vec<Row> {
    vec![
        json_row("--settings: a JSON array", "[1, 2, 3]", &["object", "JSON"]),
        json_row(
            "--settings {\"contours\": -1} (below min)",
            "{\"contours\": -1}",
            &["contours"],
        ),
    ]
}

/// Regression (fixed in 2e4b1c7): a PNG or a JSON model was reported as "a binary STL
/// declaring 950467269 triangles … truncated"; the message must say it is not an STL.
fn not_stl_rows() -> Vec<Row> {
    vec![
        row(
            "a PNG file, named as not an STL",
            Input::Bytes(png_bytes()),
            &["not an stl", "neither", "png"],
        ),
        row(
            "a JSON file, named as not an STL",
            Input::Bytes(
                serde_json::to_string_pretty(&Settings::default())
                    .unwrap()
                    .into_bytes(),
            ),
            &["not an stl", "neither", "json"],
        ),
    ]
}

/// Runs one row twice: with no output file, then with an existing one.
fn check_row(r: &Row) -> Result<(), String> {
    check_row_within(r, MAX_STDERR)
}

/// [`check_row`] with at most `max_stderr` bytes on stderr.
fn check_row_within(r: &Row, max_stderr: usize) -> Result<(), String> {
    for existing in [false, true] {
        let dir = TempDir::new("bad");
        let d = dir.path().display().to_string();
        if r.fifo {
            make_fifo(&dir.join("fifo"));
        }
        let model = match &r.input {
            Input::Bytes(b) => {
                std::fs::write(dir.join("model.stl"), b).unwrap();
                dir.join("model.stl")
            }
            Input::Named(name, b) => {
                std::fs::write(dir.join(name), b).unwrap();
                dir.join(name)
            }
            Input::Path(p) => std::path::PathBuf::from(p.replace("{dir}", &d)),
            Input::Missing => dir.join("does_not_exist.stl"),
            Input::Directory => {
                std::fs::create_dir(dir.join("a_folder.stl")).unwrap();
                dir.join("a_folder.stl")
            }
            Input::Job(text) => {
                let cube = common::model_bytes("cube_20mm_ascii.stl");
                std::fs::write(dir.join("cube.stl"), cube).unwrap();
                std::fs::write(dir.join("job.json"), text).unwrap();
                dir.join("job.json")
            }
        };
        if let Some(j) = &r.settings_json {
            std::fs::write(dir.join("settings.json"), j).unwrap();
        }
        let out = dir.join("out.gco");
        if existing {
            std::fs::write(&out, EXISTING).unwrap();
        }
        let before = dir.files();
        let mut args = vec![
            model.display().to_string(),
            "-o".into(),
            out.display().to_string(),
        ];
        args.extend(r.args.iter().map(|a| a.replace("{dir}", &d)));
        let run = common::run_cli(&args, dir.path(), TIMEOUT);
        let ctx = || format!("row '{}' (existing output: {existing}): {run:?}", r.name);
        if run.timed_out {
            return Err(format!("hangs (killed after {TIMEOUT:?}): {}", ctx()));
        }
        if run.code != Some(2) {
            return Err(format!("exit code {:?}, expected 2: {}", run.code, ctx()));
        }
        let lines: Vec<&str> = run
            .stderr
            .split(['\n', '\r'])
            .filter(|l| !l.trim().is_empty())
            .collect();
        if let Some(l) = lines.iter().find(|l| !l.starts_with("dropslice: ")) {
            return Err(format!(
                "stderr line not starting with 'dropslice: ': {l:?}: {}",
                ctx()
            ));
        }
        let errors: Vec<&&str> = lines
            .iter()
            .filter(|l| !l.starts_with("dropslice: warning: "))
            .collect();
        if errors.len() != 1 {
            return Err(format!(
                "{} error lines on stderr, expected one: {}",
                errors.len(),
                ctx()
            ));
        }
        if run.stderr.len() > max_stderr {
            return Err(format!(
                "stderr is {} bytes, expected at most {max_stderr}: row '{}'",
                run.stderr.len(),
                r.name
            ));
        }
        let msg = errors[0].to_lowercase();
        if let Some(k) = r.all.iter().find(|k| !msg.contains(&k.to_lowercase())) {
            return Err(format!("the message does not say {k:?}: {}", ctx()));
        }
        if !r.keywords.iter().any(|k| msg.contains(&k.to_lowercase())) {
            return Err(format!(
                "the message does not name the problem (none of {:?}): {}",
                r.keywords,
                ctx()
            ));
        }
        if dir.files() != before {
            return Err(format!(
                "files left behind or removed: before {before:?}, after {:?}: {}",
                dir.files(),
                ctx()
            ));
        }
        if existing && std::fs::read_to_string(&out).ok().as_deref() != Some(EXISTING) {
            return Err(format!("the existing output file was changed: {}", ctx()));
        }
    }
    Ok(())
}

#[test]
fn cli_rejects_bad_input_with_exit_2_and_a_message() {
    let rows = rows();
    assert!(rows.len() > 150, "{} rows", rows.len());
    // Two workers: each row is two short runs of the binary.
    let (a, b) = rows.split_at(rows.len() / 2);
    let failures: Vec<String> = std::thread::scope(|s| {
        let h = s.spawn(|| {
            a.iter()
                .filter_map(|r| check_row(r).err())
                .collect::<Vec<_>>()
        });
        let mut f: Vec<String> = b.iter().filter_map(|r| check_row(r).err()).collect();
        f.extend(h.join().unwrap());
        f
    });
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}

fn check_rows(rows: Vec<Row>) {
    let failures: Vec<String> = rows.iter().filter_map(|r| check_row(r).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn cli_settings_file_rows() {
    check_rows(settings_file_rows());
}

#[test]
fn cli_not_stl_is_named() {
    check_rows(not_stl_rows());
}

fn make_fifo(path: &std::path::Path) {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(path.as_os_str().as_bytes()).unwrap();
    assert_eq!(
        unsafe { libc::mkfifo(c.as_ptr(), 0o600) },
        0,
        "mkfifo {path:?}"
    );
}

/// A job file `job.json` with this text.
fn job_row(name: &str, json: &str, keywords: &[&str]) -> Row {
    row(
        name,
        Input::Named("job.json", json.as_bytes().to_vec()),
        keywords,
    )
}

/// Inputs that used to run away (issue 22): files that are not files, sizes past a bound,
/// numbers and texts quoted without bound. Each must be refused quickly with a short message.
fn limits_rows() -> Vec<Row> {
    let not_regular = &["not a regular file"][..];
    let mut rows = vec![
        row("model /dev/zero", Input::Path("/dev/zero"), not_regular),
        row("model /dev/stdin", Input::Path("/dev/stdin"), not_regular),
        job_row(
            "job file part /dev/zero",
            r#"{"parts": [{"file": "/dev/zero"}]}"#,
            not_regular,
        ),
        job_row(
            "job file part /dev/stdin",
            r#"{"parts": [{"file": "/dev/stdin"}]}"#,
            not_regular,
        ),
        job_row(
            "job file part a FIFO",
            r#"{"parts": [{"file": "fifo"}]}"#,
            not_regular,
        ),
        row(
            "a FIFO as the job file",
            Input::Path("{dir}/fifo"),
            not_regular,
        ),
        job_row(
            "job file part 1e308 scale",
            r#"{"parts": [{"file": "a.stl", "scale_x": 1e308}]}"#,
            &["1e308 is out of range"],
        ),
        job_row(
            "job file with a 100 kB unknown key",
            &format!(r#"{{"parts": [], "{}": 1}}"#, "k".repeat(100_000)),
            &["unknown key 'kkkk"],
        ),
        setting_row(
            "--set layer_height=1e308",
            "layer_height=1e308".into(),
            &["1e308 is out of range"],
        ),
        setting_row(
            "--set with a 100 kB name",
            format!("{}=1", "n".repeat(100_000)),
            &["no setting named 'nnnn"],
        ),
        setting_row(
            "--set contour_order=<100 kB>",
            format!("contour_order={}", "s".repeat(100_000)),
            &["contour_order"],
        ),
        json_row(
            "--settings with a 100 kB string",
            &format!(r#"{{"contour_order": "{}"}}"#, "s".repeat(100_000)),
            &["contour_order"],
        ),
        json_row(
            "--settings over 1 MiB",
            &format!(r#"{{"layer_height": 0.2{}}}"#, " ".repeat(1 << 20)),
            &["bytes"],
        ),
    ];
    for (what, path) in [("/dev/zero", "/dev/zero"), ("a FIFO", "{dir}/fifo")] {
        let mut r = row(
            format!("--settings {what}"),
            Input::Bytes(common::model_bytes("cube_20mm_ascii.stl")),
            not_regular,
        );
        r.args = vec!["--settings".into(), path.into()];
        rows.push(r);
    }
    // OBJ corners separated by vertical tabs: 20 million + 1 triangles in one face.
    let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf".to_vec();
    for k in 0..dropslice::model::import::stl::MAX_TRIANGLES + 3 {
        obj.extend([0x0b, b'1' + (k % 3) as u8]);
    }
    obj.push(b'\n');
    rows.push(row(
        "OBJ face of 20 M triangles split by vertical tabs",
        Input::Named("tabs.obj", obj),
        &["20000001 triangles"],
    ));
    // A 3MF whose vertex has a 15 MB number.
    rows.push(row(
        "3MF vertex with a 15 MB number",
        Input::Named("huge.3mf", huge_attribute_3mf()),
        &["not a finite number ('999"],
    ));
    // An ASCII STL with a 15 MB word where a number belongs.
    let stl = format!(
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex {} 0 0\n",
        "x".repeat(15_000_000)
    );
    rows.push(row(
        "ASCII STL with a 15 MB word",
        Input::Bytes(stl.into_bytes()),
        &["is not a number"],
    ));
    for r in &mut rows {
        r.fifo = true;
    }
    rows
}

/// A 3MF package (deflated) whose one vertex has a 15-million-digit x.
fn huge_attribute_3mf() -> Vec<u8> {
    use std::io::Write;
    let rels = r#"<?xml version="1.0"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#;
    let model = format!(
        r#"<?xml version="1.0"?><model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02"><resources><object id="1"><mesh><vertices><vertex x="{}" y="0" z="0"/></vertices></mesh></object></resources><build><item objectid="1"/></build></model>"#,
        "9".repeat(15_000_000)
    );
    let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let o = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    z.start_file("_rels/.rels", o).unwrap();
    z.write_all(rels.as_bytes()).unwrap();
    z.start_file("3D/3dmodel.model", o).unwrap();
    z.write_all(model.as_bytes()).unwrap();
    z.finish().unwrap().into_inner()
}

#[test]
fn cli_refuses_runaway_inputs_quickly_and_briefly() {
    let failures: Vec<String> = limits_rows()
        .iter()
        .filter_map(|r| check_row_within(r, SHORT_STDERR).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn cli_good_run_still_works() {
    // The table's base case: the same model and options without the fault succeed.
    let dir = TempDir::new("good");
    let out = dir.join("out.gco");
    let args = [
        common::model("cube_20mm_ascii.stl").display().to_string(),
        "-o".into(),
        out.display().to_string(),
    ];
    let run = common::run_cli(&args, dir.path(), TIMEOUT);
    assert_eq!(run.code, Some(0), "{run:?}");
    assert!(out.is_file());
}

// ---------------------------------------------------------------------------------------------
// The library

/// `Job::new` on the bytes: its result, or the panic message.
fn job_result(bytes: &[u8], settings: Settings) -> Result<Result<Job, dropslice::Error>, String> {
    std::panic::catch_unwind(|| Job::new(bytes, "bad.stl", settings)).map_err(|e| {
        e.downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

#[test]
fn library_rejects_bad_files() {
    let mut failures = Vec::new();
    for (name, bytes, keywords) in bad_files() {
        match job_result(&bytes, Settings::default()) {
            Err(panic) => failures.push(format!("{name}: Job::new panicked: {panic}")),
            Ok(Ok(_)) => failures.push(format!("{name}: Job::new accepted it")),
            Ok(Err(e)) => {
                let msg = e.to_string().to_lowercase();
                if !keywords.iter().any(|k| msg.contains(&k.to_lowercase())) {
                    failures.push(format!(
                        "{name}: message {msg:?} names none of {keywords:?}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Sets a number setting directly (bypassing `Settings::set`, which rejects NaN itself).
fn set_number(s: &mut Settings, name: &str, x: f64) {
    if let Some(f) = s.number_mut(name) {
        *f = x;
        return;
    }
    // A whole number (`contours`, `support_gap_z`): NaN as 0.
    let n = if x.is_nan() { 0 } else { x as u32 };
    s.set_value(name, n.into())
        .unwrap_or_else(|e| panic!("number setting '{name}': {e}"));
}

/// The number settings with their range.
fn number_specs() -> Vec<(&'static str, f64, f64, bool, bool)> {
    schema()
        .into_iter()
        .filter(|s| matches!(s.domain.kind, Kind::Number | Kind::Integer))
        .map(|s| {
            (
                s.name,
                s.domain.min.unwrap(),
                s.domain.max.unwrap(),
                s.domain.min_exclusive,
                s.domain.kind == Kind::Integer,
            )
        })
        .collect()
}

#[test]
fn library_rejects_settings_out_of_range() {
    let cube = common::model_bytes("cube_20mm_ascii.stl");
    let mut failures = Vec::new();
    for (name, min, max, min_exclusive, integer) in number_specs() {
        let mut values = vec![max + 1.0, 1e300];
        if !integer {
            values.push(min - 1.0);
            if min_exclusive {
                values.push(min);
            }
        }
        for x in values {
            let mut s = Settings::default();
            set_number(&mut s, name, x);
            match job_result(&cube, s) {
                Err(p) => failures.push(format!("{name} = {x}: panicked: {p}")),
                Ok(Ok(_)) => failures.push(format!("{name} = {x}: accepted")),
                Ok(Err(e)) => {
                    if !e.to_string().contains(name) {
                        failures.push(format!("{name} = {x}: message {e} lacks the name"));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

const CHILD_SETTING: &str = "DROPSLICE_TEST_CHILD_SETTING";
const CHILD_VALUE: &str = "DROPSLICE_TEST_CHILD_VALUE";

/// Run in a child process by `library_rejects_non_finite_settings` (a hang there must not
/// take this process down); does nothing without its environment variables.
#[test]
#[ignore = "helper, run in a child process"]
fn child_job_with_one_setting() {
    let (Ok(name), Ok(value)) = (std::env::var(CHILD_SETTING), std::env::var(CHILD_VALUE)) else {
        return;
    };
    let mut s = Settings::default();
    set_number(&mut s, &name, value.parse().unwrap());
    match Job::new(&common::model_bytes("cube_20mm_ascii.stl"), "cube", s) {
        Ok(job) => {
            for i in (0..job.layer_count()).step_by(10) {
                let _ = job.plan_layer(i);
            }
            println!("CHILD-RESULT accepted");
        }
        Err(e) => println!("CHILD-RESULT error: {e}"),
    }
}

#[test]
fn library_rejects_non_finite_settings() {
    let exe = std::env::current_exe().unwrap();
    let dir = TempDir::new("child");
    let mut failures = Vec::new();
    // `contours` is a u32: it cannot hold NaN or infinity.
    for (name, ..) in number_specs().into_iter().filter(|s| !s.4) {
        for value in ["NaN", "inf", "-inf"] {
            // 2 GB of address space and 20 s at most.
            let mut child = std::process::Command::new("sh")
                .arg("-c")
                .arg("ulimit -v 2000000; exec \"$0\" \"$@\"")
                .arg(&exe)
                .args([
                    "--exact",
                    "child_job_with_one_setting",
                    "--ignored",
                    "--nocapture",
                ])
                .env(CHILD_SETTING, name)
                .env(CHILD_VALUE, value)
                .current_dir(dir.path())
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::null())
                .spawn()
                .unwrap();
            let t0 = std::time::Instant::now();
            let status = loop {
                if let Some(st) = child.try_wait().unwrap() {
                    break Some(st);
                }
                if t0.elapsed() > TIMEOUT {
                    let _ = child.kill();
                    let _ = child.wait();
                    break None;
                }
                std::thread::sleep(Duration::from_millis(10));
            };
            let mut out = String::new();
            use std::io::Read;
            let _ = child.stdout.take().unwrap().read_to_string(&mut out);
            let result = out
                .lines()
                .find_map(|l| l.strip_prefix("CHILD-RESULT "))
                .unwrap_or("");
            match status {
                None => failures.push(format!("{name} = {value}: Job::new hangs")),
                Some(st) if !st.success() => failures.push(format!(
                    "{name} = {value}: the process died ({st}; a panic or out of memory)"
                )),
                _ if result.starts_with("error") && result.contains(name) => {}
                _ => failures.push(format!("{name} = {value}: {result}")),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
