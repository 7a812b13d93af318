//! Shared helpers for the integration tests: locating the shared models, running the CLI with
//! a timeout in a temporary directory, a small G-code parser (docs/spec.md 4.5), and
//! geometry on a layer's section (non-zero winding point-in-region, distance to the boundary).
#![allow(dead_code)]

pub mod segment;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

pub type Point = [f64; 2];

/// Default layer height H and droplet width B = 1.04·H (the defaults of docs/spec.md 5.4.1).
pub const H: f64 = 0.2;
pub const B: f64 = 0.2 * 1.04;

// ---------------------------------------------------------------------------------------------
// Files and processes

/// The shared folder: `$DROPSLICE_SHARED`, else `<CARGO_MANIFEST_DIR>/../shared`.
pub fn shared_dir() -> PathBuf {
    match std::env::var_os("DROPSLICE_SHARED") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared"),
    }
}

/// Path of a model in `shared/models` (panics with a clear message if it is missing).
pub fn model(name: &str) -> PathBuf {
    let p = shared_dir().join("models").join(name);
    assert!(
        p.is_file(),
        "model {} not found (set DROPSLICE_SHARED to the shared folder)",
        p.display()
    );
    p
}

pub fn model_bytes(name: &str) -> Vec<u8> {
    std::fs::read(model(name)).expect("read model")
}

/// Every shared model file the slicer reads (STL, OBJ, 3MF): its name and bytes.
pub fn shared_model_files() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for file in std::fs::read_dir(shared_dir().join("models")).expect("the shared models") {
        let path = file.expect("a shared model").path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if [".stl", ".obj", ".3mf"].iter().any(|e| name.ends_with(e)) {
            files.push((name, std::fs::read(&path).expect("read model")));
        }
    }
    files
}

/// The CLI binary built by cargo for these tests.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_dropslice")
}

/// A fresh, empty directory under the system temp dir, removed on drop.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        static N: AtomicUsize = AtomicUsize::new(0);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let p = std::env::temp_dir().join(format!(
            "dropslice-test-{tag}-{}-{}-{nanos}",
            std::process::id(),
            N.fetch_add(1, Ordering::SeqCst)
        ));
        std::fs::create_dir_all(&p).expect("create temp dir");
        TempDir(p)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// Names of the files in the directory, sorted.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .map(|rd| {
                rd.filter_map(|e| e.ok())
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Result of one CLI run.
#[derive(Debug)]
pub struct Run {
    /// Exit code; `None` if killed by a signal or by the timeout.
    pub code: Option<i32>,
    pub timed_out: bool,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
}

impl Run {
    /// Asserts that the run exited with `code` and wrote `text` to stderr.
    #[track_caller]
    pub fn says(&self, code: i32, text: &str) {
        assert_eq!(self.code, Some(code), "{self:?}");
        assert!(self.stderr.contains(text), "{}", self.stderr);
    }

    /// Asserts that the run exited with `code` and wrote `text` to stdout.
    #[track_caller]
    pub fn prints(&self, code: i32, text: &str) {
        assert_eq!(self.code, Some(code), "{self:?}");
        assert!(self.stdout.contains(text), "{}", self.stdout);
    }
}

/// Runs the CLI with `args` in `cwd`, killing it after `timeout`.
pub fn run_cli<S: AsRef<OsStr>>(args: &[S], cwd: &Path, timeout: Duration) -> Run {
    static N: AtomicUsize = AtomicUsize::new(0);
    let t0 = Instant::now();
    let out_path = cwd.join(format!(
        ".stdout-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let err_path = out_path.with_extension("stderr");
    let mut child = Command::new(bin())
        .args(args)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).expect("stdout file"))
        .stderr(std::fs::File::create(&err_path).expect("stderr file"))
        .spawn()
        .expect("spawn dropslice");
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break Some(s);
        }
        if t0.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            timed_out = true;
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let read = |p: &Path| {
        let s = String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into_owned();
        let _ = std::fs::remove_file(p);
        s
    };
    Run {
        code: status.and_then(|s| s.code()),
        timed_out,
        stdout: read(&out_path),
        stderr: read(&err_path),
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// Runs the CLI in `dir` (at most 120 s), asserting that it did not time out.
#[track_caller]
pub fn cli(args: &[&str], dir: &TempDir) -> Run {
    let r = run_cli(args, dir.path(), Duration::from_secs(120));
    assert!(!r.timed_out, "{args:?} timed out");
    r
}

/// [`cli`], asserting that it succeeded.
#[track_caller]
pub fn cli_ok(args: &[&str], dir: &TempDir) -> Run {
    let r = cli(args, dir);
    assert_eq!(r.code, Some(0), "{args:?}: {r:?}");
    r
}

/// The CLI's words to slice `model` quietly into `out`, then `extra`, then `--set` for each of
/// `sets`.
pub fn slice_args(model: &Path, out: &Path, extra: &[&str], sets: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = vec![
        model.display().to_string(),
        "-q".into(),
        "-o".into(),
        out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    args
}

/// Slices `model` through the CLI with `--report` and `--set` options in a new temporary
/// directory: (the run, the report if one was written).
pub fn report_cli(model: &Path, sets: &[&str]) -> (Run, Option<serde_json::Value>) {
    let dir = TempDir::new("report");
    let (out, rep) = (dir.join("out.gco"), dir.join("r.json"));
    let args = slice_args(model, &out, &["--report", &rep.display().to_string()], sets);
    let r = run_cli(&args, dir.path(), Duration::from_secs(300));
    let v = std::fs::read_to_string(&rep)
        .ok()
        .map(|t| serde_json::from_str(&t).expect("the report is JSON"));
    (r, v)
}

/// Slices `model` through the CLI with `--set` options and returns the G-code text.
pub fn slice_cli(model: &Path, sets: &[&str]) -> String {
    let dir = TempDir::new("slice");
    let out = dir.join("out.gco");
    let args = slice_args(model, &out, &[], sets);
    let r = run_cli(&args, dir.path(), Duration::from_secs(120));
    assert_eq!(
        r.code,
        Some(0),
        "dropslice {args:?} failed: {r:?}",
        args = args
    );
    std::fs::read_to_string(&out).expect("read output")
}

// ---------------------------------------------------------------------------------------------
// G-code

/// One command: `G01`, `G25` or `G26` with its coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Cmd {
    pub code: String,
    pub x: f64,
    pub y: f64,
    pub z: f64,
    /// The discharge unit selected by the last `T0` … `T3` line before it (0 at the start).
    pub unit: u8,
}

impl Cmd {
    pub fn p(&self) -> Point {
        [self.x, self.y]
    }
}

/// Droplet centres of a layer with their unit: `G26` one, `G25` one every B of its unit
/// (`b[unit]`) from the current position (`at`: the position before the layer's first
/// command, left at the layer's last).
pub fn unit_droplets(layer: &Layer, at: &mut Point, b: &[f64]) -> Vec<(Point, u8)> {
    let mut out = Vec::new();
    for c in &layer.cmds {
        let to = c.p();
        match c.code.as_str() {
            "G26" => out.push((to, c.unit)),
            "G25" => {
                let w = b[c.unit as usize];
                let l = ((to[0] - at[0]).powi(2) + (to[1] - at[1]).powi(2)).sqrt();
                let n = (l / w + 1e-9).floor() as usize + 1;
                for j in 0..n {
                    let t = if l > 0.0 { j as f64 * w / l } else { 0.0 };
                    out.push((
                        [at[0] + t * (to[0] - at[0]), at[1] + t * (to[1] - at[1])],
                        c.unit,
                    ));
                }
            }
            _ => {}
        }
        *at = to;
    }
    out
}

/// The Python that runs the oracle: `ORACLE_PYTHON`, else the project's virtual environment
/// with numpy and shapely (`target/pyenv`, made by `scripts/setup.sh`), else `python3`.
pub fn oracle_python() -> PathBuf {
    if let Some(p) = std::env::var_os("ORACLE_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/pyenv/bin/python3");
    if venv.exists() {
        return venv;
    }
    PathBuf::from("python3")
}

/// The stored oracle sections of a shared model (`tests/fixtures/oracle/NAME.json`, made by
/// `scripts/make_oracle_fixtures.sh`).
pub fn oracle_fixture(name: &str) -> serde_json::Value {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/oracle/{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Section areas (`got[i]`: layer i) against the non-zero (union) areas of the stored oracle
/// fixture `name`, within 0.5 % or 0.05 mm², whichever is larger; layers whose plane holds
/// horizontal faces (flagged `near_plane_faces` by the oracle: ambiguous) are skipped. Fails
/// listing every layer (numbered from 1) that differs.
pub fn assert_oracle_areas(name: &str, got: &[f64], what: &str) {
    let oracle = oracle_fixture(name);
    let layers = oracle["layers"].as_array().unwrap();
    assert_eq!(got.len(), layers.len(), "{what}: layer count");
    let mut bad = Vec::new();
    for (i, (l, &g)) in layers.iter().zip(got).enumerate() {
        if l.get("near_plane_faces").is_some() {
            continue;
        }
        let want = l["nonzero"]["area"].as_f64().unwrap();
        if (g - want).abs() > (want * 0.005).max(0.05) {
            bad.push(format!("layer {}: {g:.3} vs oracle {want:.3}", i + 1));
        }
    }
    assert!(
        bad.is_empty(),
        "{what}: {} layers differ:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// The independent oracle's cross-sections (`../shared/tools/oracle_sections.py`) of an STL
/// at layer height `h`, as its JSON.
pub fn oracle_sections(stl: &Path, h: f64) -> serde_json::Value {
    let python = oracle_python();
    let out = Command::new(&python)
        .arg(shared_dir().join("tools/oracle_sections.py"))
        .arg(stl)
        .arg(h.to_string())
        .output()
        .unwrap_or_else(|e| panic!("{} runs the oracle: {e}", python.display()));
    assert!(
        out.status.success(),
        "oracle: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the oracle writes JSON")
}

/// The job's section areas against the oracle's layers (`oracle_sections`; layers with faces
/// near the plane skipped): (layers compared, the layers whose areas differ by more than
/// `tolerance(oracle area)`).
pub fn oracle_area_mismatches(
    job: &dropslice::Job,
    oracle: &serde_json::Value,
    tolerance: impl Fn(f64) -> f64,
) -> (usize, Vec<String>) {
    let layers = oracle["layers"].as_array().expect("the oracle's layers");
    assert_eq!(job.layer_count(), layers.len(), "layer count");
    let mut bad = Vec::new();
    let mut compared = 0;
    for (i, l) in layers.iter().enumerate() {
        if l.get("near_plane_faces").is_some() {
            continue;
        }
        compared += 1;
        let want = l["nonzero"]["area"].as_f64().expect("an area");
        let got = dropslice::base::geom::region_area(&job.section(i).region);
        if (got - want).abs() > tolerance(want) {
            bad.push(format!("layer {i}: {got:.4} vs oracle {want:.4}"));
        }
    }
    (compared, bad)
}

/// The commands of one layer (consecutive commands with the same Z).
#[derive(Clone, Debug)]
pub struct Layer {
    pub z: f64,
    pub cmds: Vec<Cmd>,
}

#[derive(Clone, Debug, Default)]
pub struct Gcode {
    /// `; name = value` comment lines before the first command, in order; the value without
    /// a trailing ` (unit)`.
    pub header: Vec<(String, String)>,
    pub layers: Vec<Layer>,
    /// Lines that break docs/spec.md 4.5's format (not a comment, not `G01/G25/G26 Xx Yy Zz` with
    /// exactly 4 decimals, nor `T0` … `T3`), with their line numbers.
    pub bad_lines: Vec<String>,
    /// `T0` … `T3` lines: (line number from 1, unit).
    pub unit_lines: Vec<(usize, u8)>,
}

impl Gcode {
    /// The header value of `name`.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.header
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    pub fn count(&self, code: &str) -> usize {
        self.layers
            .iter()
            .flat_map(|l| &l.cmds)
            .filter(|c| c.code == code)
            .count()
    }
}

/// A coordinate: optional minus, digits, a point and exactly 4 digits.
fn parse_coord(tok: &str, axis: char) -> Option<f64> {
    let num = tok.strip_prefix(axis)?;
    let digits = num.strip_prefix('-').unwrap_or(num);
    let (int, frac) = digits.split_once('.')?;
    let ok = !int.is_empty()
        && int.bytes().all(|c| c.is_ascii_digit())
        && frac.len() == 4
        && frac.bytes().all(|c| c.is_ascii_digit());
    if !ok {
        return None;
    }
    num.parse().ok()
}

/// Parses G-code text (strictly; see [`Gcode::bad_lines`]).
pub fn parse_gcode(text: &str) -> Gcode {
    let mut g = Gcode::default();
    let mut seen_command = false;
    let mut unit = 0u8;
    for (n, line) in text.lines().enumerate() {
        if let Some(u) = match line {
            "T0" => Some(0),
            "T1" => Some(1),
            "T2" => Some(2),
            "T3" => Some(3),
            _ => None,
        } {
            unit = u;
            g.unit_lines.push((n + 1, u));
            continue;
        }
        if let Some(c) = line.strip_prefix(';') {
            if !seen_command && let Some((k, v)) = c.split_once(" = ") {
                let v = v.trim();
                let v = match v.rfind(" (") {
                    Some(i) if v.ends_with(')') => &v[..i],
                    _ => v,
                };
                g.header.push((k.trim().to_string(), v.trim().to_string()));
            }
            continue;
        }
        let toks: Vec<&str> = line.split(' ').collect();
        let cmd = match toks.as_slice() {
            [code @ ("G01" | "G25" | "G26"), x, y, z] => {
                match (
                    parse_coord(x, 'X'),
                    parse_coord(y, 'Y'),
                    parse_coord(z, 'Z'),
                ) {
                    (Some(x), Some(y), Some(z)) => Some(Cmd {
                        code: code.to_string(),
                        x,
                        y,
                        z,
                        unit,
                    }),
                    _ => None,
                }
            }
            _ => None,
        };
        let Some(cmd) = cmd else {
            g.bad_lines.push(format!("line {}: {line:?}", n + 1));
            continue;
        };
        seen_command = true;
        match g.layers.last_mut() {
            Some(l) if l.z == cmd.z => l.cmds.push(cmd),
            _ => g.layers.push(Layer {
                z: cmd.z,
                cmds: vec![cmd],
            }),
        }
    }
    g
}

/// `T` lines (docs/spec.md "Discharge units") stand only where the unit changes, from T0,
/// and
/// each is followed by a command (comments aside). `what` prefixes failure messages.
pub fn assert_unit_changes(text: &str, what: &str) {
    let lines: Vec<&str> = text.lines().collect();
    let mut unit = "T0";
    for (i, l) in lines.iter().enumerate() {
        if l.starts_with('T') {
            assert_ne!(*l, unit, "{what} line {}: T line without a change", i + 1);
            unit = l;
            let next = lines[i + 1..].iter().find(|l| !l.starts_with(';'));
            assert!(
                next.is_some_and(|n| n.starts_with('G')),
                "{what} line {}: no command after {l}",
                i + 1
            );
        }
    }
}

/// Layer index (from 0) of a G-code layer: Z = (i + 1)·H.
pub fn layer_index(z: f64, h: f64) -> usize {
    let i = (z / h).round() as i64 - 1;
    assert!(
        i >= 0 && (z - (i + 1) as f64 * h).abs() < 1e-6,
        "Z {z} is not a multiple of H = {h}"
    );
    i as usize
}

/// Droplets of one `G25` line of length `l` (docs/spec.md 4.5: one at the start, then one every B).
pub fn line_droplets(l: f64, b: f64) -> u64 {
    (l / b + 1e-9).floor() as u64 + 1
}

/// `G25` lines of a layer as (start, end): the start is the position before the command.
pub fn g25_lines(layer: &Layer) -> Vec<(Point, Point)> {
    let mut at: Option<Point> = None;
    let mut out = Vec::new();
    for c in &layer.cmds {
        if c.code == "G25" {
            out.push((
                at.expect("G25 as a layer's first command has no start"),
                c.p(),
            ));
        }
        at = Some(c.p());
    }
    out
}

/// Maximal runs of consecutive `G26` commands of a layer.
pub fn g26_runs(layer: &Layer) -> Vec<Vec<Point>> {
    let mut runs: Vec<Vec<Point>> = Vec::new();
    let mut in_run = false;
    for c in &layer.cmds {
        if c.code == "G26" {
            if !in_run {
                runs.push(Vec::new());
                in_run = true;
            }
            runs.last_mut().unwrap().push(c.p());
        } else {
            in_run = false;
        }
    }
    runs
}

pub fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Splits a run of `G26` droplets (with closed loops, `close_loops = true`) into loops: a
/// loop ends where a droplet equals the loop's first droplet (that closing droplet is kept
/// as the loop's last point). A first droplet whose successor is not B away is a loop of one
/// droplet (a loop too small for two). `b_tol` is the spacing tolerance.
pub fn split_loops(run: &[Point], b: f64, b_tol: f64) -> Vec<Vec<Point>> {
    let mut loops: Vec<Vec<Point>> = Vec::new();
    let mut cur: Vec<Point> = Vec::new();
    for &p in run {
        if cur.len() == 1 && (dist(cur[0], p) - b).abs() > b_tol {
            loops.push(std::mem::take(&mut cur));
        }
        let closes = !cur.is_empty() && dist(cur[0], p) < 1e-9;
        cur.push(p);
        if closes {
            loops.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        loops.push(cur);
    }
    loops
}

/// A closed loop of droplets: the last repeats the first, each droplet `b` from the next
/// (within `tol`), the closing gap before the repeat at most `b + tol`. `what` names the loop
/// in failures.
pub fn assert_loop_spacing(lp: &[Point], b: f64, tol: f64, what: &str) {
    let n = lp.len();
    assert!(
        n >= 3 && lp[0] == lp[n - 1],
        "{what}: a loop of {n} droplets starting at {:?} does not end on its first droplet (ends at {:?})",
        lp.first(),
        lp.last()
    );
    for w in lp[..n - 1].windows(2) {
        let s = dist(w[0], w[1]);
        assert!(
            (s - b).abs() <= tol,
            "{what}: droplets {:?} → {:?} are {s} mm apart, not B = {b}",
            w[0],
            w[1]
        );
    }
    let closing = dist(lp[n - 2], lp[n - 1]);
    assert!(closing <= b + tol, "{what}: closing gap {closing} > B");
}

// ---------------------------------------------------------------------------------------------
// Geometry on a section (dropslice::base::geom::Shapes: shapes of contours)

pub type Shapes = Vec<Vec<Vec<Point>>>;

/// Non-zero winding number of `p` over every contour of the region.
pub fn winding(region: &Shapes, p: Point) -> i32 {
    region.iter().flatten().map(|c| contour_winding(c, p)).sum()
}

/// Winding number of one closed contour around `p`.
pub fn contour_winding(c: &[Point], p: Point) -> i32 {
    let mut wn = 0;
    {
        let n = c.len();
        for i in 0..n {
            let (a, b) = (c[i], c[(i + 1) % n]);
            let left = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
            if a[1] <= p[1] {
                if b[1] > p[1] && left > 0.0 {
                    wn += 1;
                }
            } else if b[1] <= p[1] && left < 0.0 {
                wn -= 1;
            }
        }
    }
    wn
}

fn seg_dist(p: Point, a: Point, b: Point) -> f64 {
    dropslice::base::geom::segment_distance(p.into(), a.into(), b.into())
}

/// A section's region as plain arrays (outer boundary first, then the holes).
pub fn nested(region: &dropslice::base::geom::Shapes) -> Shapes {
    dropslice::base::boolean::nested(region)
}

/// Distance from `p` to the region's boundary (its nearest contour edge).
pub fn boundary_distance(region: &Shapes, p: Point) -> f64 {
    let mut best = f64::INFINITY;
    for c in region.iter().flatten() {
        let n = c.len();
        for i in 0..n {
            best = best.min(seg_dist(p, c[i], c[(i + 1) % n]));
        }
    }
    best
}

/// `p` lies inside the region (non-zero winding) or within `tol` mm of its boundary.
pub fn in_region(region: &Shapes, p: Point, tol: f64) -> bool {
    winding(region, p) != 0 || boundary_distance(region, p) <= tol
}

/// A region with a bounding box per contour, for faster repeated queries.
pub struct IndexedRegion {
    contours: Vec<(Vec<Point>, [f64; 4])>,
}

impl IndexedRegion {
    pub fn new(region: &Shapes) -> IndexedRegion {
        let contours = region
            .iter()
            .flatten()
            .map(|c| {
                let mut bb = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
                for p in c {
                    bb[0] = bb[0].min(p[0]);
                    bb[1] = bb[1].min(p[1]);
                    bb[2] = bb[2].max(p[0]);
                    bb[3] = bb[3].max(p[1]);
                }
                (c.clone(), bb)
            })
            .collect();
        IndexedRegion { contours }
    }

    pub fn winding(&self, p: Point) -> i32 {
        let mut wn = 0;
        for (c, bb) in &self.contours {
            // A contour only winds around points within its y-range and left of its max x.
            if p[1] < bb[1] || p[1] > bb[3] || p[0] > bb[2] {
                continue;
            }
            wn += contour_winding(c, p);
        }
        wn
    }

    pub fn boundary_distance(&self, p: Point) -> f64 {
        let mut best = f64::INFINITY;
        for (c, bb) in &self.contours {
            let dx = (bb[0] - p[0]).max(p[0] - bb[2]).max(0.0);
            let dy = (bb[1] - p[1]).max(p[1] - bb[3]).max(0.0);
            if dx.hypot(dy) > best {
                continue;
            }
            let n = c.len();
            for i in 0..n {
                best = best.min(seg_dist(p, c[i], c[(i + 1) % n]));
            }
        }
        best
    }

    pub fn contains(&self, p: Point, tol: f64) -> bool {
        self.winding(p) != 0 || self.boundary_distance(p) <= tol
    }
}

// ---------------------------------------------------------------------------------------------
// STL writing

/// A binary STL of the given triangles (zero normals), written here byte by byte rather than by
/// the crate, for tests whose reference must not lean on the crate's STL writer.
pub fn stl_bytes<C: Copy + Into<f64>>(tris: &[[[C; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for p in t {
            for c in p {
                b.extend_from_slice(&((*c).into() as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

/// The 12 facets of an axis-aligned box as indices of its corners (corner `i` has bit 0 for x,
/// bit 1 for y, bit 2 for z at the maximum), each face's two triangles counter-clockwise seen
/// from outside (facing outward).
pub const BOX_FACETS: [[usize; 3]; 12] = {
    // Each face as a quad, counter-clockwise from outside.
    const QUADS: [[usize; 4]; 6] = [
        [0, 2, 3, 1], // z = min (outward -z)
        [4, 5, 7, 6], // z = max
        [0, 1, 5, 4], // y = min
        [2, 6, 7, 3], // y = max
        [0, 4, 6, 2], // x = min
        [1, 3, 7, 5], // x = max
    ];
    let mut out = [[0; 3]; 12];
    let mut k = 0;
    while k < 6 {
        let q = QUADS[k];
        out[2 * k] = [q[0], q[1], q[2]];
        out[2 * k + 1] = [q[0], q[2], q[3]];
        k += 1;
    }
    out
};

/// Corner `i` of the box [min, max] (bit 0: x, bit 1: y, bit 2: z at the maximum).
pub fn box_corner(min: [f32; 3], max: [f32; 3], i: usize) -> [f32; 3] {
    [0, 1, 2].map(|a| if i >> a & 1 == 0 { min[a] } else { max[a] })
}

/// An axis-aligned box, facets wound counter-clockwise seen from outside (outward).
pub fn cuboid(min: [f32; 3], max: [f32; 3]) -> Vec<[[f32; 3]; 3]> {
    BOX_FACETS
        .iter()
        .map(|t| t.map(|i| box_corner(min, max, i)))
        .collect()
}

/// A 3MF package (deflated) with one model part: `resources` and `build` are the XML of the
/// model's two elements.
pub fn three_mf(resources: &str, build: &str) -> Vec<u8> {
    use std::io::Write;
    let rels = r#"<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#;
    let model = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02"><resources>{resources}</resources><build>{build}</build></model>"#
    );
    let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opt = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    for (name, text) in [("_rels/.rels", rels), ("3D/3dmodel.model", model.as_str())] {
        z.start_file(name, opt).unwrap();
        z.write_all(text.as_bytes()).unwrap();
    }
    z.finish().unwrap().into_inner()
}

/// `<object id>` of a 3MF model: a cube of side `side` at the origin, facets outward or
/// (`inverted`) inside out.
pub fn cube_object(id: u32, side: f32, inverted: bool) -> String {
    let mut s = format!(r#"<object id="{id}" type="model"><mesh><vertices>"#);
    for i in 0..8 {
        let [x, y, z] = box_corner([0.0; 3], [side; 3], i);
        s += &format!(r#"<vertex x="{x}" y="{y}" z="{z}"/>"#);
    }
    s += "</vertices><triangles>";
    for [a, b, c] in BOX_FACETS {
        let [b, c] = if inverted { [c, b] } else { [b, c] };
        s += &format!(r#"<triangle v1="{a}" v2="{b}" v3="{c}"/>"#);
    }
    s + "</triangles></mesh></object>"
}

/// The default settings with the setting `name` set to `value` (which must be valid).
pub fn settings_with(name: &str, value: &str) -> dropslice::Settings {
    let mut s = dropslice::Settings::default();
    s.set(name, value).unwrap();
    s
}

/// A 3MF of about a kilobyte that fans out 10^`levels` cubes of side `side` (as
/// [`cube_object`]) by components: object 1 the cube, then `levels` objects of ten components
/// each, 1 mm apart along x, y, z, then 10 mm apart along x, y, z, …; the build holds the last.
pub fn fanned_cubes_3mf(levels: i32, side: f32, inverted: bool) -> Vec<u8> {
    let mut res = cube_object(1, side, inverted);
    for l in 0..levels {
        let pitch = 10f64.powi(l / 3);
        let comps: String = (0..10)
            .map(|k| {
                let mut d = [0.0; 3];
                d[(l % 3) as usize] = k as f64 * pitch;
                format!(
                    r#"<component objectid="{}" transform="1 0 0 0 1 0 0 0 1 {} {} {}"/>"#,
                    l + 1,
                    d[0],
                    d[1],
                    d[2]
                )
            })
            .collect();
        res += &format!(
            r#"<object id="{}" type="model"><components>{comps}</components></object>"#,
            l + 2
        );
    }
    three_mf(&res, &format!(r#"<item objectid="{}"/>"#, levels + 1))
}

/// The lower and upper corners of the box around every corner of `tris`.
pub fn bounds<T: Copy + Into<f64>>(tris: &[[[T; 3]; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in tris.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k].into());
            hi[k] = hi[k].max(p[k].into());
        }
    }
    (lo, hi)
}

/// A binary STL of the given triangles (zero normals).
pub fn binary_stl(header: &[u8], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    dropslice::model::import::stl::write_binary(header, tris)
}

/// An ASCII STL of the given triangles, coordinates written with `{}`.
pub fn ascii_stl(tris: &[[[String; 3]; 3]]) -> Vec<u8> {
    let mut s = String::from("solid test\n");
    for t in tris {
        s.push_str("facet normal 0 0 0\n  outer loop\n");
        for v in t {
            s.push_str(&format!("    vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        s.push_str("  endloop\nendfacet\n");
    }
    s.push_str("endsolid test\n");
    s.into_bytes()
}

/// A tiny deterministic random generator (xorshift64*), so tests need no extra crate.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    pub fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next_u64() as u8).collect()
    }

    /// An index below `n` (0 when `n` is 0).
    pub fn pick(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A layer plan of single droplets (`G26`, fill) at the given points, for analysis tests.
pub fn droplet_plan<P: Copy + Into<dropslice::base::geom::Point>>(
    points: &[P],
) -> dropslice::slicing::plan::LayerPlan {
    use dropslice::slicing::plan::{LayerPlan, Move, MoveKind, Role};
    LayerPlan {
        moves: points
            .iter()
            .map(|&to| Move {
                kind: MoveKind::Droplet,
                role: Role::Fill,
                to: to.into(),
                unit: 0,
            })
            .collect(),
        ..LayerPlan::default()
    }
}

/// Triangles moved onto the plate: their box minimum to (at, 0).
pub fn on_plate(tris: Vec<[[f64; 3]; 3]>, at: Point) -> Vec<[[f64; 3]; 3]> {
    let mut lo = [f64::INFINITY; 3];
    for p in tris.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
        }
    }
    let shift = [at[0] - lo[0], at[1] - lo[1], -lo[2]];
    tris.into_iter()
        .map(|t| t.map(|p| [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]]))
        .collect()
}

/// The triangles cut by the plane z: segments, not chained into loops (an independent cut
/// for checks against the part's true section).
pub fn cut(tris: &[[[f64; 3]; 3]], z: f64) -> Vec<(Point, Point)> {
    let mut out = Vec::new();
    for v in tris {
        let mut pts = Vec::new();
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            if (a[2] < z) != (b[2] < z) {
                let t = (z - a[2]) / (b[2] - a[2]);
                pts.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        if pts.len() == 2 {
            out.push((pts[0], pts[1]));
        }
    }
    out
}

/// Whether p lies in the section (odd crossings of a ray to +x) at least d from its boundary
/// (a droplet centre on a section of the part, kept d inside it).
pub fn deep_inside(segs: &[(Point, Point)], p: Point, d: f64) -> bool {
    let mut crossings = 0;
    for &(a, b) in segs {
        let (_, q) = segment::project(p, a, b);
        let (ex, ey) = (q[0] - p[0], q[1] - p[1]);
        if ex * ex + ey * ey < d * d {
            return false;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > p[0] {
                crossings += 1;
            }
        }
    }
    crossings % 2 == 1
}

/// The loop of the box [x, x + w] × [y, y + h], counter-clockwise.
pub fn rect_loop(x: f64, y: f64, w: f64, h: f64) -> Vec<dropslice::base::geom::Point> {
    vec![
        [x, y].into(),
        [x + w, y].into(),
        [x + w, y + h].into(),
        [x, y + h].into(),
    ]
}
