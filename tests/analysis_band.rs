//! The banded report (`--report`: only a band around each layer's boundary rasterised and
//! filled exactly, the interior counted and sampled) held to the reference that rasterises and
//! fills every layer whole ([`JobAnalysis::reference`]) on the shared models, stagger off and
//! on: the part's void fraction and predicted density within 0.2 percentage points, each
//! layer's coverage within 0.5 points, the same worst layer by boundary deviation and by
//! overhang, the overfill and the boundary deviations of the band (where they all are).
//!
//! Not held: the largest void and its layer. The largest void is mostly a network of the
//! channels between the fill's lines joined through the interior (the bunny's: 22.7 mm²
//! across 74 × 73 mm of layer 234, counted from 1), which the band does not see: the banded report gives the
//! band's largest void. The void count is estimated for the interior (within 3 % here).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::analysis::{JobAnalysis, Report};
use dropslice::base::settings::{Support, UnitId};
use dropslice::{Job, Settings};

fn reports(model: &str, s: Settings) -> (Report, Report) {
    let job = Job::new(&common::model_bytes(model), model, s).unwrap();
    let grid = job.analysis_grid();
    let mut fast = JobAnalysis::new(&grid, job.settings());
    let mut exact = JobAnalysis::reference(&grid, job.settings());
    let mut a = Vec::new();
    dropslice::write_gcode_with(&job, &mut a, |_, _| {}, &mut fast).unwrap();
    let mut b = Vec::new();
    dropslice::write_gcode_with(&job, &mut b, |_, _| {}, &mut exact).unwrap();
    assert!(a == b, "{model}: the code changed with the analysis");
    (fast.finish(), exact.finish())
}

fn check(model: &str, stagger: bool) {
    let s = Settings {
        stagger,
        allow_off_plate: true,
        ..Settings::default()
    };
    check_with(model, s, &format!("{model}, stagger {stagger}"));
}

fn check_with(model: &str, s: Settings, at: &str) {
    let (fast, exact) = reports(model, s);
    let (f, e) = (&fast.part, &exact.part);
    println!(
        "{at}: void fraction {:.5} / {:.5}, density {:?} / {:?}, coverage {:.5} / {:.5}, \
         voids {} / {}, largest {:?} in {:?} / {:?} in {:?}",
        f.estimate.void_fraction,
        e.estimate.void_fraction,
        f.estimate.predicted_density,
        e.estimate.predicted_density,
        f.coverage,
        e.coverage,
        fast.layers.iter().map(|l| l.voids).sum::<usize>(),
        exact.layers.iter().map(|l| l.voids).sum::<usize>(),
        f.largest_void.map(|v| v.area),
        f.largest_void_layer,
        e.largest_void.map(|v| v.area),
        e.largest_void_layer,
    );
    let (fe, ee) = (f.estimate, e.estimate);
    assert!(ee.void_fraction > 0.05, "{at}: {e:?}");
    assert!((fe.void_fraction - ee.void_fraction).abs() <= 0.002, "{at}");
    let (df, de) = (fe.predicted_density.unwrap(), ee.predicted_density.unwrap());
    assert!((df - de).abs() <= 0.2, "{at}: {df} against {de}");
    assert_eq!(fe.volume.to_bits(), ee.volume.to_bits(), "{at}");
    assert_eq!(f.region_area.to_bits(), e.region_area.to_bits(), "{at}");
    assert_eq!(f.droplets, e.droplets, "{at}");
    assert!((f.coverage - e.coverage).abs() <= 0.005, "{at}");
    assert_eq!(f.max_deviation_layer, e.max_deviation_layer, "{at}");
    assert_eq!(f.max_boundary_deviation, e.max_boundary_deviation, "{at}");
    assert_eq!(
        f.max_unsupported_area_layer, e.max_unsupported_area_layer,
        "{at}"
    );
    assert!(
        (f.overfill_area - e.overfill_area).abs() <= 1e-9 * e.overfill_area.max(1.0),
        "{at}"
    );
    let (vf, ve) = (
        fast.layers.iter().map(|l| l.voids).sum::<usize>() as f64,
        exact.layers.iter().map(|l| l.voids).sum::<usize>() as f64,
    );
    assert!(
        (vf - ve).abs() <= 0.05 * ve,
        "{at}: {vf} voids against {ve}"
    );
    assert_eq!(fast.layers.len(), exact.layers.len(), "{at}");
    let row = Settings::default().droplet_width() / 10.0;
    for (a, b) in fast.layers.iter().zip(&exact.layers) {
        let at = format!("{at}, layer {}", b.index);
        assert!(
            (a.coverage - b.coverage).abs() <= 0.005,
            "{at}: {} against {}",
            a.coverage,
            b.coverage
        );
        assert_eq!(a.region_area.to_bits(), b.region_area.to_bits(), "{at}");
        assert!(
            (a.boundary_deviation - b.boundary_deviation).abs() <= row,
            "{at}"
        );
        assert!(
            (a.overfill_area - b.overfill_area).abs() <= 1e-9 * b.overfill_area.max(1.0),
            "{at}"
        );
        // The interior's voids are all enclosed: the area reaching the boundary is the band's.
        let open = |l: &dropslice::analysis::LayerAnalysis| l.void_area - l.enclosed_void_area;
        assert!(
            (open(a) - open(b)).abs() <= 0.02 * b.void_area.max(row * row),
            "{at}"
        );
    }
}

#[test]
fn the_banded_report_holds_to_the_whole_raster_on_benchy() {
    check("3DBenchy.stl", false);
    check("3DBenchy.stl", true);
}

#[test]
fn the_banded_report_holds_to_the_whole_raster_on_parts_with_holes_and_damage() {
    for model in ["extruder_idler.stl", "esca_nonmanifold.stl"] {
        check(model, false);
        check(model, true);
    }
}

/// A part with support from unit 1 printed first with its own droplets (the saved job of
/// tests/saved_jobs.rs): the support is no part of the estimate, and the interior's samples
/// must hold here too (whole rows of blocks as samples were 1.06 points off on it).
#[test]
fn the_banded_report_holds_to_the_whole_raster_with_support() {
    let mut s = Settings {
        support: Support::Unit(UnitId(1)),
        ..Settings::default()
    };
    s.set("unit_order", "unit1_first").unwrap();
    s.unit_mut(UnitId(1)).droplet_aspect = 1.5;
    check_with("U_overhang.obj", s, "U_overhang.obj, support from unit 1");
}

#[test]
fn the_banded_report_holds_to_the_whole_raster_on_the_bunny() {
    // The large solid whose interior the band leaves out (stagger off: its reference alone
    // takes about a minute of CPU).
    check("stanford_bunny.stl", false);
}
