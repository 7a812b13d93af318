//! Per-layer section areas and counts of outer boundaries and holes against the independent
//! oracle (`../shared/tools/oracle_sections.py`, union = non-zero numbers). The fixtures in
//! tests/fixtures/oracle were made by `scripts/make_oracle_fixtures.sh`.
//!
//! Tolerance: 0.5 % or 0.05 mm², whichever is larger. Counts: the union's, except on layers
//! with pinch points (see `compare`). Layers whose plane contains horizontal
//! faces are ambiguous (the oracle flags them, `near_plane_faces`) and skipped.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::{Job, Settings};
use serde_json::Value;

struct Mismatch {
    layer: usize,
    what: String,
}

/// The default settings, a part off the plate allowed.
fn off_plate() -> Settings {
    Settings {
        allow_off_plate: true,
        ..Settings::default()
    }
}

/// Compares every layer of `model` with its fixture; returns the mismatches and layers compared.
fn compare(model: &str, fixture: &str, counts: bool) -> (Vec<Mismatch>, usize) {
    let bytes = common::model_bytes(&format!("{model}.stl"));
    let oracle: Value = common::oracle_fixture(fixture);
    // The bunny is wider than the default plate: the plate rule is not what this compares.
    let job = Job::new(&bytes, model, off_plate()).unwrap();
    let layers = oracle["layers"].as_array().unwrap();
    assert_eq!(job.layer_count(), layers.len(), "{model}: layer count");
    let mut bad = Vec::new();
    let mut compared = 0;
    for (i, l) in layers.iter().enumerate() {
        assert!(
            (job.plane_z(i) - l["z"].as_f64().unwrap()).abs() < 1e-9,
            "{model} layer {i}: plane height"
        );
        if l.get("near_plane_faces").is_some() {
            continue;
        }
        compared += 1;
        let nz = &l["nonzero"];
        let want = nz["area"].as_f64().unwrap();
        let section = job.section(i);
        let got = dropslice::base::geom::region_area(&section.region);
        let tol = (want * 0.005).max(0.05);
        if (got - want).abs() > tol {
            bad.push(Mismatch {
                layer: i,
                what: format!("area {got:.4} vs oracle {want:.4}"),
            });
        }
        if counts {
            let outer = section.region.len() as u64;
            let holes = section
                .region
                .iter()
                .map(|s| s.holes.len() as u64)
                .sum::<u64>();
            let (wo, wh) = (nz["outer"].as_u64().unwrap(), nz["holes"].as_u64().unwrap());
            // A loop touching itself at one point (a pinch) is one polygon in the even-odd count
            // and two in the oracle's union count; the oracle's signature of such a layer is
            // that both areas agree and only the counts differ. There either count is right.
            let pinch = (l["area"].as_f64().unwrap() - want).abs() <= 1e-6 * want.max(1.0);
            let even_odd = (l["outer"].as_u64().unwrap(), l["holes"].as_u64().unwrap());
            if (outer, holes) != (wo, wh) && !(pinch && (outer, holes) == even_odd) {
                bad.push(Mismatch {
                    layer: i,
                    what: format!("outer/holes {outer}/{holes} vs oracle {wo}/{wh}"),
                });
            }
        }
    }
    (bad, compared)
}

fn check(model: &str) {
    check_fixture(model, model, true);
}

/// Compares every layer of `model` with `fixture` and fails with the list of differing layers.
fn check_fixture(model: &str, fixture: &str, counts: bool) -> usize {
    let (bad, compared) = compare(model, fixture, counts);
    assert!(compared > 0);
    let report: Vec<String> = bad
        .iter()
        .map(|m| format!("layer {}: {}", m.layer, m.what))
        .collect();
    assert!(
        report.is_empty(),
        "{model}: {} of {compared} layers differ:\n{}",
        report.len(),
        report.join("\n")
    );
    compared
}

#[test]
fn cube() {
    check("cube_20mm_ascii");
}

#[test]
fn benchy() {
    check("3DBenchy");
}

#[test]
fn extruder_idler_union_of_nested_bodies() {
    check("extruder_idler");
}

#[test]
fn spikey_top() {
    check("spikey_top_solid_header");
}

#[test]
fn slide_n_snap() {
    check("slide_n_snap_test_a_medium");
}

#[test]
fn airfoil_wing() {
    check("airfoil_wing");
}

#[test]
fn m3_screw() {
    check("M3x10_screw");
}

/// The open scan (223 open edges, open chains on 50 layers) against the same scan with its
/// holes filled by an independent mesh repair (MeshFix, `scripts/fill_holes_meshfix.py`):
/// layers without open sections within the oracle's tolerance, as every model; the open
/// layers, whose closing is a guess, within 2.5 % of the filled scan's area in all and never
/// empty. Joining nearest ends instead (the oracle's `--close-open`, as CuraEngine and Slic3r
/// do) is 4.8 % off: that fixture shows the rule the test tells apart.
#[test]
fn stanford_bunny_open_mesh_closed_like_its_holes_filled() {
    let bytes = common::model_bytes("stanford_bunny.stl");
    let job = Job::new(&bytes, "bunny", off_plate()).unwrap();
    let filled = common::oracle_fixture("stanford_bunny_holes_filled");
    let nearest = common::oracle_fixture("stanford_bunny_close_open");
    let area = |v: &Value, i: usize| v["layers"][i]["nonzero"]["area"].as_f64().unwrap();
    assert_eq!(
        filled["layers"].as_array().unwrap().len(),
        job.layer_count()
    );
    let (mut open_layers, mut want, mut off, mut off_nearest) = (0, 0.0, 0.0, 0.0);
    let mut bad = Vec::new();
    for i in 0..job.layer_count() {
        let section = job.section(i);
        let got = dropslice::base::geom::region_area(&section.region);
        assert!(got > 0.0, "layer {i} is empty");
        let w = area(&filled, i);
        if section.open_chains == 0 {
            if (got - w).abs() > (w * 0.005).max(0.05) {
                bad.push(format!("layer {i}: area {got:.4} vs filled scan {w:.4}"));
            }
            continue;
        }
        open_layers += 1;
        want += w;
        off += (got - w).abs();
        off_nearest += (area(&nearest, i) - w).abs();
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    assert_eq!(open_layers, 50);
    let (share, share_nearest) = (off / want, off_nearest / want);
    eprintln!(
        "open layers off the filled scan: {:.2} % (nearest ends: {:.2} %)",
        100.0 * share,
        100.0 * share_nearest
    );
    assert!(share <= 0.025, "{:.2} % off", 100.0 * share);
    assert!(
        share_nearest > 0.04,
        "the reference no longer tells the rules apart"
    );
}

#[test]
fn esca_nonmanifold() {
    check("esca_nonmanifold");
}
