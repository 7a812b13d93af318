//! The 3D estimate's fast path (`HeightMap::new`, `slab_voids`) against the code it replaced,
//! kept unchanged as `HeightMap::reference` and `slab_voids_reference`: every slab's (volume, void
//! volume) equal to the bit, on real models (each layer between its real neighbours, stagger
//! off and on, both footprints) and on random droplets and regions (droplets on cell centres
//! and edges, far apart, missing neighbours). And the slabs the slicing workers compute give
//! the report the writing thread gave when it computed them in order.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;
#[path = "common/slab.rs"]
mod slab;

use dropslice::analysis::{
    GRID3_PER_B, Grid3, HeightMap, JobAnalysis, droplet_centres, footprint_diameter, slab_voids,
    slab_voids_reference,
};
use dropslice::base::geom::{Point, Shape, Shapes};
use dropslice::{Job, Settings};
use slab::SlabFn;

fn bits(f: (f64, f64)) -> (u64, u64) {
    (f.0.to_bits(), f.1.to_bits())
}

/// Every slab of `layers` (region, droplet centres), fast and reference, equal to the bit.
fn assert_slabs_equal(what: &str, layers: &[(Shapes, Vec<Point>)], grid: &Grid3, s: &Settings) {
    let d = footprint_diameter(s);
    let [fast, slow] = [
        HeightMap::new as fn(&[Point], &Grid3, f64) -> HeightMap,
        HeightMap::reference,
    ]
    .map(|make| {
        layers
            .iter()
            .map(|l| make(&l.1, grid, d))
            .collect::<Vec<_>>()
    });
    let mut nonzero = 0;
    for i in 0..layers.len() {
        // Between its neighbours, then without them.
        for alone in [false, true] {
            let slab = |f: SlabFn, maps: &[HeightMap]| {
                let near = |j: Option<usize>| j.filter(|_| !alone).and_then(|j| maps.get(j));
                f(
                    &layers[i].0,
                    grid,
                    near(i.checked_sub(1)),
                    &maps[i],
                    near(Some(i + 1)),
                    s,
                )
            };
            let (a, b) = (slab(slab_voids, &fast), slab(slab_voids_reference, &slow));
            let how = if alone { " alone" } else { "" };
            assert_eq!(
                bits(a),
                bits(b),
                "{what}, slab {i}{how}: {a:?} against {b:?}"
            );
            if alone {
                nonzero += usize::from(a.1 > 0.0 && a.1 < a.0);
            }
        }
    }
    // The comparison saw partly filled slabs, not only empty or full ones.
    assert!(nonzero > 0, "{what}: no slab partly filled");
}

fn model_layers(model: &str, s: &Settings, step: usize) -> (Vec<(Shapes, Vec<Point>)>, Grid3) {
    let job = Job::new(&common::model_bytes(model), model, s.clone()).unwrap();
    let b = s.droplet_width();
    let d = footprint_diameter(s);
    let bounds = job.info().bounds;
    let grid = Grid3 {
        origin: [bounds.min[0] - d, bounds.min[1] - d].into(),
        cell: b / GRID3_PER_B,
    };
    // Runs of three adjacent layers every `step` layers: each middle one between its real
    // neighbours.
    let mut layers = Vec::new();
    for i in (0..job.layer_count()).step_by(step) {
        for k in i..(i + 3).min(job.layer_count()) {
            let (plan, region) = job.plan_layer_and_region(k);
            layers.push((region, droplet_centres(&plan, b)));
        }
    }
    (layers, grid)
}

#[test]
fn slabs_of_real_models_are_the_reference_slabs() {
    for model in ["3DBenchy.stl", "extruder_idler.stl", "esca_nonmanifold.stl"] {
        for (stagger, footprint) in [(false, "disc"), (true, "disc"), (false, "spread")] {
            let mut s = Settings {
                stagger,
                ..Settings::default()
            };
            s.set("footprint", footprint).unwrap();
            let (layers, grid) = model_layers(model, &s, 17);
            assert_slabs_equal(
                &format!("{model}, stagger {stagger}, footprint {footprint}"),
                &layers,
                &grid,
                &s,
            );
        }
    }
}

#[test]
fn slabs_of_random_droplets_are_the_reference_slabs() {
    let mut rng = common::Rng::new(1);
    for footprint in ["disc", "spread"] {
        let s = common::settings_with("footprint", footprint);
        let b = s.droplet_width();
        let grid = Grid3 {
            origin: [-1.3, -0.7].into(),
            cell: b / GRID3_PER_B,
        };
        for case in 0..40 {
            let mut layers = Vec::new();
            for _ in 0..3 {
                // A region of one or two boxes (the second sometimes a hole, sometimes far
                // away), droplets scattered over and around it, some exactly on cell centres
                // or cell edges, some in a lattice.
                let (x0, y0) = (rng.unit() * 2.0, rng.unit() * 2.0);
                let (w, h) = (0.2 + rng.unit() * 3.0, 0.2 + rng.unit() * 3.0);
                let rect = common::rect_loop;
                let mut region: Shapes = vec![Shape::new(rect(x0, y0, w, h), vec![])];
                match case % 3 {
                    1 => {
                        let mut hole = rect(x0 + w / 4.0, y0 + h / 4.0, w / 2.0, h / 2.0);
                        hole.reverse();
                        region[0] = Shape::new(rect(x0, y0, w, h), vec![hole]);
                    }
                    2 => region.push(Shape::new(rect(x0 + 40.0, y0 - 30.0, 1.0, 1.0), vec![])),
                    _ => {}
                }
                let mut pts: Vec<Point> = Vec::new();
                let n = (rng.unit() * 400.0) as usize;
                for k in 0..n {
                    let (u, v) = (
                        x0 - 0.3 + rng.unit() * (w + 0.6),
                        y0 - 0.3 + rng.unit() * (h + 0.6),
                    );
                    let p = match k % 4 {
                        // On a cell centre, or on a cell edge.
                        0 => {
                            let snap = |t: f64, o: f64, half: f64| {
                                o + (((t - o) / grid.cell).floor() + half) * grid.cell
                            };
                            [snap(u, grid.origin[0], 0.5), snap(v, grid.origin[1], 0.0)]
                        }
                        // A lattice of pitch B at a random phase.
                        1 => {
                            let j = k as f64;
                            [x0 + (j % 13.0) * b, y0 + (j / 13.0).floor() * b]
                        }
                        _ => [u, v],
                    };
                    pts.push(p.into());
                }
                if case % 7 == 3 {
                    pts.clear();
                }
                if case % 3 == 2 {
                    pts.push([x0 + 40.5, y0 - 29.5].into());
                }
                layers.push((region, pts));
            }
            for stagger in [false, true] {
                let s = Settings {
                    stagger,
                    ..s.clone()
                };
                let d = footprint_diameter(&s);
                let fast: Vec<HeightMap> = layers
                    .iter()
                    .map(|l| HeightMap::new(&l.1, &grid, d))
                    .collect();
                let slow: Vec<HeightMap> = layers
                    .iter()
                    .map(|l| HeightMap::reference(&l.1, &grid, d))
                    .collect();
                for (lo, hi) in [(Some(0), Some(2)), (None, Some(2)), (Some(0), None)] {
                    let run = |f: SlabFn, maps: &[HeightMap]| {
                        let pick = |j: Option<usize>| j.map(|j| &maps[j]);
                        f(&layers[1].0, &grid, pick(lo), &maps[1], pick(hi), &s)
                    };
                    let (a, r) = (run(slab_voids, &fast), run(slab_voids_reference, &slow));
                    assert_eq!(
                        bits(a),
                        bits(r),
                        "case {case}, {footprint}, stagger {stagger}, {lo:?} {hi:?}: {a:?} against {r:?}"
                    );
                }
            }
        }
    }
}

/// The report when the writing thread computes every slab in order (the layers analysed and
/// pushed one by one, as before the workers computed them).
fn report_in_order(job: &Job) -> dropslice::analysis::Report {
    let mut analysis = JobAnalysis::new(&job.analysis_grid(), job.settings());
    let stage = analysis.stage();
    let mut raster = dropslice::analysis::Raster::empty();
    for i in 0..job.layer_count() {
        let (plan, region) = job.plan_layer_and_region(i);
        analysis.push(stage.analyse(&mut raster, &region, &plan));
    }
    analysis.finish()
}

#[test]
fn slabs_from_the_workers_give_the_report_of_the_ordered_slabs() {
    for (model, stagger) in [("3DBenchy.stl", false), ("esca_nonmanifold.stl", true)] {
        let s = Settings {
            stagger,
            ..Settings::default()
        };
        let job = Job::new(&common::model_bytes(model), model, s).unwrap();
        let mut analysis = JobAnalysis::new(&job.analysis_grid(), job.settings());
        dropslice::write_gcode_with(&job, &mut std::io::sink(), |_, _| {}, &mut analysis).unwrap();
        let workers = analysis.finish();
        let ordered = report_in_order(&job);
        assert_eq!(workers.part, ordered.part, "{model}");
        assert_eq!(workers.layers, ordered.layers, "{model}");
        // Every slab counted: the part's volume is every layer's area times H, in order.
        let mut volume = 0.0;
        for l in &ordered.layers {
            volume += l.region_area * job.settings().layer_height;
        }
        let estimate = workers.part.estimate;
        assert_eq!(estimate.volume.to_bits(), volume.to_bits(), "{model}");
        assert!(estimate.void_volume > 0.0 && estimate.void_fraction < 0.5);
        assert!(workers.part.units.is_empty(), "{model}");
    }
}

#[test]
fn a_second_material_has_its_own_estimate_from_the_workers_and_in_order() {
    use dropslice::model::models::Model;
    use dropslice::model::spec::JobSpec;
    let models = vec![
        Model::read(&common::model_bytes("3DBenchy.stl"), "benchy.stl").unwrap(),
        Model::read(&common::model_bytes("cube_20mm_ascii.stl"), "cube.stl").unwrap(),
    ];
    let spec = JobSpec::from_json(
        r#"{"settings": {"unit1_droplet_aspect": 1.5, "stagger": true}, "parts": [{"file": "benchy.stl"}, {"file": "cube.stl", "unit": 1}]}"#,
    )
    .unwrap();
    let job = Job::from_models(&models, &spec).unwrap();
    let mut analysis = JobAnalysis::new(&job.analysis_grid(), job.settings());
    dropslice::write_gcode_with(&job, &mut std::io::sink(), |_, _| {}, &mut analysis).unwrap();
    let workers = analysis.finish();
    let ordered = report_in_order(&job);
    assert_eq!(workers.part, ordered.part);
    let u1 = workers.part.units[1].expect("unit 1's estimate");
    assert!(
        workers.part.units[0].is_none(),
        "unit 0's figures are the part's own"
    );
    // the cube (8 cm³, 20 mm high) ends below the boat's top: its slabs are all in
    assert!((u1.volume - 8000.0).abs() < 1.0, "{u1:?}");
    assert!(u1.void_volume > 0.0 && u1.void_fraction < 0.5, "{u1:?}");
    assert_eq!(u1.predicted_density, Some(100.0 * (1.0 - u1.void_fraction)));
}
