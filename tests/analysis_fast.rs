//! The fast paths of the analysis against the exact ones they replace, on real models: the
//! page's coverage mask cell for cell, and the layer figures within 0.1 % (absolute).

mod common;

use dropslice::analysis::Raster;
use dropslice::{Job, Settings};

const MODELS: [&str; 4] = [
    "3DBenchy.stl",
    "extruder_idler.stl",
    "stanford_bunny.stl",
    "esca_nonmanifold.stl",
];

/// Every `step`-th layer of `model` with `stagger`, as (section region, raster).
fn rasters(model: &str, stagger: bool, step: usize) -> Vec<Raster> {
    let s = Settings {
        stagger,
        ..Settings::default()
    };
    let path = common::model(model);
    let job = Job::new(
        &common::model_bytes(model),
        path.to_str().unwrap(),
        s.clone(),
    )
    .unwrap();
    (0..job.layer_count())
        .step_by(step)
        .map(|i| {
            let region = &job.section(i).region;
            let plan = dropslice::plan::plan_layer(region, i, &s);
            Raster::new(&plan, region, &s)
        })
        .collect()
}

#[test]
fn masks_are_those_counted_range_by_range() {
    let b = Settings::default().droplet_width();
    for model in MODELS {
        for r in rasters(model, false, 23) {
            for cell in [b / 4.0, b, 7.3 * b] {
                assert_eq!(r.mask(cell), r.mask_reference(cell), "{model}, cell {cell}");
            }
        }
    }
}

#[test]
fn layer_figures_are_those_of_the_reference_labelling() {
    for model in MODELS {
        for stagger in [false, true] {
            for r in rasters(model, stagger, 29) {
                assert_eq!(
                    r.analysis(),
                    r.analysis_reference(),
                    "{model} stagger {stagger}"
                );
            }
        }
    }
}
