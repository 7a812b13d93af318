//! The CLI's `--report`: its layers are numbered from 1 (as the G-code's layer comments, the
//! summary line and the page), and a layer too large to analyse is refused before its memory
//! is taken, with the code still written (docs/quality.md, *The report* and *Memory*).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{TempDir, run_cli};
use std::time::Duration;

/// Slices `model` with `--report` and `sets`: (the run, the report if one was written).
fn report(model: &std::path::Path, sets: &[&str]) -> (common::Run, Option<serde_json::Value>) {
    common::report_cli(model, sets)
}

#[test]
fn the_report_numbers_layers_from_1() {
    let (r, v) = report(&common::model("U_overhang.obj"), &[]);
    assert_eq!(r.code, Some(0), "{r:?}");
    let v = v.expect("a report");
    let layers = v["layers"].as_array().unwrap();
    let index: Vec<u64> = layers
        .iter()
        .map(|l| l["index"].as_u64().unwrap())
        .collect();
    let want: Vec<u64> = (1..=layers.len() as u64).collect();
    assert_eq!(index, want);
    let part = &v["part"];
    // The layer named for the largest overhang is the one whose own figure is that largest.
    let max = part["max_unsupported_area"].as_f64().unwrap();
    assert!(max > 0.0, "{part}");
    let at = part["max_unsupported_area_layer"].as_u64().unwrap();
    let by_layer = |n: u64, key: &str| layers[n as usize - 1][key].clone();
    assert_eq!(
        by_layer(at, "unsupported_area").as_f64(),
        Some(max),
        "{part}"
    );
    // Before it, no layer had as much (the first of the largest is named).
    assert!(
        layers[..at as usize - 1]
            .iter()
            .all(|l| l["unsupported_area"].as_f64().unwrap() < max)
    );
    // The same for the largest void and the largest deviation.
    let at = part["largest_void_layer"].as_u64().unwrap();
    assert_eq!(by_layer(at, "largest_void"), part["largest_void"], "{part}");
    let at = part["max_deviation_layer"].as_u64().unwrap();
    assert_eq!(
        by_layer(at, "boundary_deviation"),
        part["max_boundary_deviation"],
        "{part}"
    );
}

/// A binary STL of the box [0, x] × [0, y] × [0, z] mm.
fn box_stl(x: f32, y: f32, z: f32) -> Vec<u8> {
    common::stl_bytes(&common::cuboid([0.0, 0.0, 0.0], [x, y, z]))
}

#[test]
fn a_layer_too_large_to_analyse_is_refused_and_the_code_still_written() {
    // A metre-square sheet: a layer of about 23 million droplets, whose analysis took 9.3 GB
    // (2 m: aborted at 13.6 GB); the slice itself takes a few MB.
    let dir = TempDir::new("large");
    let stl = dir.join("sheet.stl");
    std::fs::write(&stl, box_stl(1000.0, 1000.0, 0.2)).unwrap();
    for sets in [
        &["plate_x=1000", "plate_y=1000"][..],
        &["plate_x=2000", "plate_y=2000"][..],
    ] {
        let (r, v) = report(&stl, sets);
        assert_eq!(r.code, Some(2), "{r:?}");
        assert!(v.is_none(), "no report is written");
        let e = &r.stderr;
        assert!(e.contains("no void analysis"), "{e}");
        assert!(e.contains("GB") && e.contains("more than the 1 GB"), "{e}");
        assert!(e.contains("droplet_aspect"), "what to do: {e}");
        assert!(e.contains("was written, without the report"), "{e}");
        assert!(e.len() < 600, "{e}");
    }
    // A small droplet on a flat part (droplet_aspect 0.1: B = 0.02 mm): refused as well.
    std::fs::write(&stl, box_stl(150.0, 150.0, 0.4)).unwrap();
    let (r, v) = report(&stl, &["droplet_aspect=0.1", "plate_x=200", "plate_y=200"]);
    assert_eq!(r.code, Some(2), "{r:?}");
    assert!(
        v.is_none() && r.stderr.contains("no void analysis"),
        "{r:?}"
    );
}

#[test]
fn the_code_of_a_refused_analysis_is_the_code_without_report() {
    let dir = TempDir::new("same");
    let stl = dir.join("sheet.stl");
    std::fs::write(&stl, box_stl(600.0, 600.0, 0.2)).unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![stl.to_str().unwrap(), "-q", "-o", "out.gco"];
        args.extend(["--set", "plate_x=700", "--set", "plate_y=700"]);
        args.extend(extra);
        let r = run_cli(&args, dir.path(), Duration::from_secs(300));
        (r, std::fs::read(dir.join("out.gco")).unwrap_or_default())
    };
    let (plain, code) = run(&[]);
    assert_eq!(plain.code, Some(0), "{plain:?}");
    let (refused, with) = run(&["--report", "r.json"]);
    assert_eq!(refused.code, Some(2), "{refused:?}");
    assert!(!code.is_empty() && code == with, "the same code");
    assert!(!dir.join("r.json").exists());
}

#[test]
fn a_part_the_bound_allows_is_analysed_within_its_estimate() {
    // The estimate bounds what the raster takes: a 40 mm plate of one layer, analysed.
    let dir = TempDir::new("allowed");
    let stl = dir.join("plate.stl");
    std::fs::write(&stl, box_stl(40.0, 30.0, 0.2)).unwrap();
    let (r, v) = report(&stl, &[]);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert_eq!(v.unwrap()["layers"].as_array().unwrap().len(), 1);
}

#[test]
fn the_estimate_bounds_the_raster_a_layer_takes() {
    // `Raster::box_bytes` is a bound: for boxes of several sizes and droplet widths, the
    // raster of the box's layer takes no more.
    for (x, y, aspect) in [(40.0, 30.0, 1.04), (3.0, 70.0, 1.04), (25.0, 25.0, 0.4)] {
        let s = {
            let mut t = dropslice::Settings::default();
            t.unit_mut(dropslice::base::settings::UnitId::FIRST)
                .droplet_aspect = aspect;
            t
        };
        let job = dropslice::Job::new(&box_stl(x, y, 0.4), "box.stl", s.clone()).unwrap();
        let bound = dropslice::analysis::Raster::box_bytes(x as f64, y as f64, &s);
        let (plan, region) = job.plan_layer_and_region(0);
        let raster = dropslice::analysis::Raster::new(&plan, &region, &s);
        let taken = 8.0 * raster.stored_words() as f64;
        assert!(
            taken <= bound,
            "{x} × {y}, aspect {aspect}: {taken} > {bound}"
        );
        // And not far above it: the estimate refuses no part it could analyse.
        assert!(bound < 1.5 * taken + 1e6, "{x} × {y}: {bound} for {taken}");
        // The whole estimate of the job's layer is within the bound.
        let grid = job.analysis_grid();
        assert!(grid.layer_bytes(&s) >= bound);
        assert!(grid.check(&s).is_ok());
    }
}
