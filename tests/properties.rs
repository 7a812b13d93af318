//! Properties (DESIGN.md "Tests"): transformations that do not change the part must not change
//! the result. Rotating a part about z (`rotate_z`), or shuffling its facets (and cycling each
//! facet's corners, which keeps its orientation), leaves every layer's region area unchanged
//! (±0.1 %) and the droplet count nearly so (±1 %).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::base::geom::region_area;
use dropslice::{Job, Settings};
use proptest::prelude::*;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

const MODELS: [&str; 3] = [
    "extruder_idler.stl",
    "slide_n_snap_test_a_medium.stl",
    "M3x10_screw.stl",
];
/// Droplets are counted on every `DROPLET_STRIDE`-th layer.
const DROPLET_STRIDE: usize = 2;
const AREA_REL_TOL: f64 = 1e-3;
/// Floor for the area tolerance of tiny sections, in mm².
const AREA_ABS_TOL: f64 = 1e-4;
const DROPLET_REL_TOL: f64 = 0.01;

#[derive(Clone, Debug)]
struct Measure {
    areas: Vec<f64>,
    droplets: u64,
}

/// Layer areas and the droplet total (every `DROPLET_STRIDE`-th layer) of a job.
fn measure(job: &Job) -> Measure {
    let n = job.layer_count();
    let areas = (0..n)
        .map(|i| region_area(&job.section(i).region))
        .collect();
    let layers: Vec<usize> = (0..n).step_by(DROPLET_STRIDE).collect();
    let droplets = std::thread::scope(|s| {
        let (a, b) = layers.split_at(layers.len() / 2);
        let count =
            |ls: &[usize]| -> u64 { ls.iter().map(|&i| job.plan_layer(i).counts.total()).sum() };
        let h = s.spawn(move || count(a));
        count(b) + h.join().unwrap()
    });
    Measure { areas, droplets }
}

fn job(bytes: &[u8], name: &str, settings: Settings) -> Job {
    Job::new(bytes, name, settings).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The untransformed part's measures, computed once per model.
fn baseline(model: &str) -> Measure {
    static CACHE: OnceLock<Mutex<HashMap<String, Measure>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(m) = cache.lock().unwrap().get(model) {
        return m.clone();
    }
    let m = measure(&job(
        &common::model_bytes(model),
        model,
        Settings::default(),
    ));
    cache.lock().unwrap().insert(model.to_string(), m.clone());
    m
}

fn compare(what: &str, base: &Measure, got: &Measure) -> Result<(), TestCaseError> {
    prop_assert_eq!(
        base.areas.len(),
        got.areas.len(),
        "{}: layer count changed",
        what
    );
    for (i, (a, b)) in base.areas.iter().zip(&got.areas).enumerate() {
        let tol = (a.abs() * AREA_REL_TOL).max(AREA_ABS_TOL);
        prop_assert!(
            (a - b).abs() <= tol,
            "{}: layer {} area {} mm², originally {} mm² (off by {:.4} %)",
            what,
            i + 1,
            b,
            a,
            (b - a) / a * 100.0
        );
    }
    let (a, b) = (base.droplets as f64, got.droplets as f64);
    prop_assert!(
        (a - b).abs() <= a * DROPLET_REL_TOL,
        "{}: {} droplets (every {}th layer), originally {} ({:+.3} %)",
        what,
        got.droplets,
        DROPLET_STRIDE,
        base.droplets,
        (b - a) / a * 100.0
    );
    Ok(())
}

/// A tiny permutation generator (Fisher–Yates with the tests' xorshift).
fn shuffled_stl(bytes: &[u8], seed: u64) -> Vec<u8> {
    let (mut tris, _) = dropslice::model::import::stl::parse(bytes).expect("model parses");
    let mut rng = common::Rng::new(seed);
    for i in (1..tris.len()).rev() {
        let j = rng.below(i as u64 + 1) as usize;
        tris.swap(i, j);
    }
    // Cycle each facet's corners (same orientation, another first corner).
    for t in &mut tris {
        let k = rng.below(3) as usize;
        t.rotate_left(k);
    }
    common::binary_stl(b"shuffled", &tris)
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 8,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn rotating_about_z_keeps_areas_and_droplets(
        model in 0..MODELS.len(),
        angle in -360.0f64..360.0,
    ) {
        let model = MODELS[model];
        let mut s = Settings::default();
        s.set("rotate_z", &angle.to_string()).unwrap();
        let got = measure(&job(&common::model_bytes(model), model, s));
        compare(&format!("{model} rotated by {angle}°"), &baseline(model), &got)?;
    }

    #[test]
    fn shuffling_facets_keeps_areas_and_droplets(
        model in 0..MODELS.len(),
        seed in any::<u64>(),
    ) {
        let model = MODELS[model];
        let bytes = shuffled_stl(&common::model_bytes(model), seed);
        let got = measure(&job(&bytes, model, Settings::default()));
        compare(&format!("{model} with facets shuffled (seed {seed})"), &baseline(model), &got)?;
    }
}

/// Fixed angles that hit the hatch's own directions and the axes, for every model.
#[test]
fn rotating_by_special_angles() {
    for model in MODELS {
        for angle in [90.0, 180.0, -45.0, 45.0, 0.001] {
            let s = Settings {
                rotate_z: angle,
                ..Settings::default()
            };
            let got = measure(&job(&common::model_bytes(model), model, s));
            if let Err(e) = compare(
                &format!("{model} rotated by {angle}°"),
                &baseline(model),
                &got,
            ) {
                panic!("{e}");
            }
        }
    }
}
