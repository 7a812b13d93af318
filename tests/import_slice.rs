//! OBJ and 3MF files slice through the same pipeline as STL (one job; build jobs with several
//! arranged parts come later). References are independent of the importer: box.3mf is a
//! 10 × 20 × 30 mm box, so every section is exactly 200 mm²; the quad OBJ of the extruder idler
//! has the bounds of its STL twin; cube_gears.3mf's build measures 167.996 × 125.102 × 33.601 mm
//! (read from its XML with Python's zipfile and ElementTree).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::{Job, Settings};

/// The job of `name` (cube_gears' build is wider than the default plate: allowed here).
fn job(name: &str) -> Job {
    let s = Settings {
        allow_off_plate: true,
        ..Settings::default()
    };
    Job::new(&common::model_bytes(name), name, s).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn a_3mf_box_slices_to_its_exact_section() {
    let j = job("box.3mf");
    assert_eq!(j.layer_count(), 150);
    for i in 0..j.layer_count() {
        let a = dropslice::base::geom::region_area(&j.section(i).region);
        assert!((a - 200.0).abs() < 1e-6, "layer {i}: {a}");
    }
}

#[test]
fn a_quad_obj_has_the_size_of_its_stl_twin() {
    let obj = job("extruder_idler_quads.obj");
    let stl = job("extruder_idler.stl");
    assert_eq!(obj.layer_count(), stl.layer_count());
    let (a, b) = (obj.info().bounds.size(), stl.info().bounds.size());
    for k in 0..3 {
        assert!((a[k] - b[k]).abs() < 1e-4, "axis {k}: {} vs {}", a[k], b[k]);
    }
    assert_eq!(format!("{:?}", obj.info().format), "Obj");
}

#[test]
fn a_3mf_build_keeps_its_items_in_place() {
    let j = job("cube_gears.3mf");
    let s = j.info().bounds.size();
    for (k, want) in [167.996, 125.102, 33.601].into_iter().enumerate() {
        assert!((s[k] - want).abs() < 2e-3, "axis {k}: {} vs {want}", s[k]);
    }
    // A layer in the middle has material from several items.
    let mid = j.section(j.layer_count() / 4);
    assert!(mid.region.len() > 1, "{} islands", mid.region.len());
}
