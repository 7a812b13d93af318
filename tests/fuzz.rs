//! Seeded, time-bounded mutation fuzzing of the import and the whole pipeline (issue
//! "Hardening"): damaged copies of the shared models — bit flips, truncations, spliced and
//! repeated chunks, triangle counts and coordinates replaced by NaN, ±Infinity, 1e38,
//! subnormals — and random settings within their ranges, sliced layer by layer. Every input
//! must end in a plan or a user-facing error (never a panic, never an internal error), and
//! every number in a plan must be finite.
//!
//! The run is reproducible (`DROPSLICE_FUZZ_SEED`, default 1) and bounded by time
//! (`DROPSLICE_FUZZ_SECONDS`, default 25): on a slow machine it does fewer cases, never more
//! time. The case count is printed. A failing case is written to the temp folder with its
//! seed and settings so it can be replayed.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::Rng;
use dropslice::base::settings::{Kind, schema};
use dropslice::{Error, Job, Settings};
use std::time::{Duration, Instant};

const MODELS: [&str; 6] = [
    "cube_20mm_ascii.stl",
    "slide_n_snap_test_a_medium.stl",
    "spikey_top_solid_header.stl",
    "M3x10_screw.stl",
    "extruder_idler.stl",
    "airfoil_wing.stl",
];

const SPECIAL_F32: [f32; 8] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    1e38,
    -1e38,
    1e-40,
    0.0,
    -0.0,
];

const SPECIAL_TEXT: [&str; 9] = [
    "nan", "inf", "-inf", "1e308", "-1e999", "1e-320", "0x10", "", "1.0.0",
];

/// One damaged copy of `bytes`.
fn mutate(rng: &mut Rng, bytes: &[u8]) -> (Vec<u8>, String) {
    // A first mutation may have left nothing (truncated at 0): nothing more to damage.
    if bytes.is_empty() {
        return (Vec::new(), "left empty".into());
    }
    let mut b = bytes.to_vec();
    let binary = b.len() >= 84 && {
        let n = u32::from_le_bytes([b[80], b[81], b[82], b[83]]) as usize;
        b.len() == 84 + 50 * n
    };
    let what = match rng.pick(8) {
        0 => {
            let n = 1 + rng.pick(32);
            for _ in 0..n {
                let i = rng.pick(b.len());
                b[i] ^= 1 << rng.pick(8);
            }
            format!("{n} bit flips")
        }
        1 => {
            let at = rng.pick(b.len());
            b.truncate(at);
            format!("truncated at {at}")
        }
        2 => {
            let (from, len) = (rng.pick(b.len()), 1 + rng.pick(4096));
            let chunk: Vec<u8> = b[from..(from + len).min(b.len())].to_vec();
            let at = rng.pick(b.len());
            b.splice(at..at, chunk);
            format!("{len} bytes from {from} spliced in at {at}")
        }
        3 if binary => {
            let n: u32 = [0, 1, u32::MAX, 0x7fff_ffff, rng.next_u64() as u32][rng.pick(5)];
            b[80..84].copy_from_slice(&n.to_le_bytes());
            format!("triangle count set to {n}")
        }
        4 | 5 if binary => {
            let k = 1 + rng.pick(16);
            let tris = (b.len() - 84) / 50;
            for _ in 0..k {
                let t = rng.pick(tris);
                let c = rng.pick(12); // normal or a vertex coordinate
                let v = SPECIAL_F32[rng.pick(SPECIAL_F32.len())];
                let at = 84 + 50 * t + 4 * c;
                b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
            format!("{k} coordinates set to special values")
        }
        4 | 5 => {
            // ASCII: replace numbers after "vertex" with special texts.
            let text = String::from_utf8_lossy(&b).into_owned();
            let mut words: Vec<String> = text.split(' ').map(str::to_string).collect();
            let k = 1 + rng.pick(8);
            for _ in 0..k {
                let i = rng.pick(words.len());
                if words[i].parse::<f64>().is_ok() {
                    words[i] = SPECIAL_TEXT[rng.pick(SPECIAL_TEXT.len())].into();
                }
            }
            b = words.join(" ").into_bytes();
            format!("up to {k} numbers replaced")
        }
        6 => {
            // Facets repeated (or, in ASCII, lines repeated) to grow the file.
            let reps = 1 + rng.pick(20);
            let (from, len) = (rng.pick(b.len()), 1 + rng.pick(2000));
            let chunk: Vec<u8> = b[from..(from + len).min(b.len())].to_vec();
            for _ in 0..reps {
                b.extend_from_slice(&chunk);
            }
            format!("{len} bytes from {from} appended {reps} times")
        }
        _ => {
            let n = rng.pick(512);
            b = (0..n).map(|_| rng.next_u64() as u8).collect();
            format!("{n} random bytes")
        }
    };
    (b, what)
}

/// Random settings: every numeric setting somewhere in its range (biased to the ends), each
/// choice setting one of its choices; layer height and droplets kept so a case stays fast.
fn random_settings(rng: &mut Rng) -> Settings {
    let mut s = Settings::default();
    if rng.pick(3) == 0 {
        return s;
    }
    for spec in schema() {
        if rng.pick(4) != 0 {
            continue;
        }
        let value = match spec.domain.kind {
            Kind::Bool => ["true", "false"][rng.pick(2)].to_string(),
            Kind::Enum | Kind::Order => {
                spec.domain.choices[rng.pick(spec.domain.choices.len())].into()
            }
            _ => {
                let (Some(lo), Some(hi)) = (spec.domain.min, spec.domain.max) else {
                    continue;
                };
                let x = match rng.pick(4) {
                    0 => lo,
                    1 => hi,
                    _ => lo + (hi - lo) * rng.unit(),
                };
                let x = if spec.domain.min_exclusive && x <= lo {
                    lo + (hi - lo) * 1e-3
                } else {
                    x
                };
                if matches!(spec.domain.kind, Kind::Integer) {
                    format!("{}", x.round())
                } else {
                    format!("{x}")
                }
            }
        };
        let _ = s.set(spec.name, &value);
    }
    // Keep cases small: at most 60 layers of droplets no smaller than 0.1 mm, few contours.
    s.layer_height = s.layer_height.max(0.5);
    let u0 = s.unit_mut(dropslice::base::settings::UnitId::FIRST);
    u0.droplet_aspect = u0.droplet_aspect.max(1.0);
    s.contours = s.contours.min(4);
    s.scale_x = s.scale_x.clamp(0.2, 2.0);
    s.scale_y = s.scale_y.clamp(0.2, 2.0);
    s.scale_z = s.scale_z.clamp(0.2, 2.0);
    // Droplet bombs of unit 1 and the support (issue 22): a tiny B₁ or B with support on must
    // be refused by the job's droplet estimate (or stay small), never run for minutes.
    if rng.pick(10) == 0 {
        s.support = dropslice::base::settings::Support::Unit(dropslice::base::settings::UnitId(1));
        match rng.pick(2) {
            0 => {
                s.unit_mut(dropslice::base::settings::UnitId(1))
                    .droplet_aspect = 1e-3
            }
            _ => {
                s.unit_mut(dropslice::base::settings::UnitId::FIRST)
                    .droplet_aspect = 1e-3
            }
        }
    }
    if s.validate().is_err() {
        return Settings::default();
    }
    s
}

fn finite_plan(job: &Job, i: usize) -> Result<(), String> {
    let plan = job.plan_layer(i);
    for m in &plan.moves {
        let p = m.to;
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(format!("layer {i}: a move to a non-finite point {p:?}"));
        }
    }
    Ok(())
}

/// Slices a case; Err with a description when it panicked or failed as a bug.
fn run_case(bytes: &[u8], settings: &Settings) -> Result<(), String> {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        match Job::new(bytes, "fuzz.stl", settings.clone()) {
            Ok(job) => {
                let n = job.layer_count();
                // Every layer of small jobs; a spread of layers of bigger ones.
                let step = (n / 40).max(1);
                for i in (0..n).step_by(step) {
                    finite_plan(&job, i)?;
                }
                let _ = job.header(None);
                Ok(())
            }
            Err(Error::Internal(m)) => Err(format!("internal error: {m}")),
            Err(e) => {
                let text = e.to_string();
                if text.trim().is_empty() {
                    Err("an error without a message".into())
                } else {
                    Ok(())
                }
            }
        }
    }));
    match result {
        Ok(r) => r,
        Err(p) => Err(format!(
            "panic: {}",
            p.downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default()
        )),
    }
}

#[test]
fn mutated_models_never_panic() {
    let seed: u64 = std::env::var("DROPSLICE_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let seconds: f64 = std::env::var("DROPSLICE_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(25.0);
    let models: Vec<(&str, Vec<u8>)> = MODELS
        .iter()
        .map(|m| (*m, common::model_bytes(m)))
        .collect();
    let mut rng = Rng::new(seed);
    let start = Instant::now();
    let mut cases = 0;
    let mut failures = Vec::new();
    // Silence the default panic printout: panics are collected and reported below.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    while start.elapsed() < Duration::from_secs_f64(seconds) && failures.len() < 5 {
        let (name, original) = &models[rng.pick(models.len())];
        let (bytes, what) = mutate(&mut rng, original);
        // Sometimes a second mutation on top of the first.
        let (bytes, what) = if rng.pick(4) == 0 {
            let (b, w) = mutate(&mut rng, &bytes);
            (b, format!("{what}, then {w}"))
        } else {
            (bytes, what)
        };
        let settings = random_settings(&mut rng);
        if let Err(e) = run_case(&bytes, &settings) {
            let path = std::env::temp_dir().join(format!("dropslice-fuzz-{seed}-{cases}.stl"));
            let _ = std::fs::write(&path, &bytes);
            failures.push(format!(
                "case {cases} ({name}: {what}; settings {}): {e}; input saved as {}",
                serde_json::to_string(&settings).unwrap_or_default(),
                path.display()
            ));
        }
        cases += 1;
    }
    std::panic::set_hook(hook);
    eprintln!(
        "fuzz: seed {seed}: {cases} cases in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(cases > 0);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
