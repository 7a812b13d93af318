//! The fast paths of the analysis against the exact ones they replace, on real models: the
//! page's coverage mask cell for cell (the 4-bit-group counts for cells of B/4, the window
//! counts for larger cells) against the masks counted range by range, and the layer figures
//! of the one-pass labelling against the run-per-node labelling, equal (the 0.1 % the
//! analysis may differ by is not needed).

mod common;

use dropslice::analysis::Raster;
use dropslice::{Job, Settings};

const MODELS: [&str; 4] = [
    "3DBenchy.stl",
    "extruder_idler.stl",
    "stanford_bunny.stl",
    "esca_nonmanifold.stl",
];

/// Every `step`-th layer of `model` with `stagger`, as rasters.
fn rasters(model: &str, stagger: bool, step: usize) -> Vec<Raster> {
    let s = Settings {
        stagger,
        ..Settings::default()
    };
    rasters_with(model, s, step)
}

fn rasters_with(model: &str, s: Settings, step: usize) -> Vec<Raster> {
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
        for stagger in [false, true] {
            for r in rasters(model, stagger, 23) {
                // B/4: the page's cells (4-bit groups); B, 7.3 B: by windows.
                let cells: &[f64] = if stagger {
                    &[b / 4.0]
                } else {
                    &[b / 4.0, b / 6.0, b, 7.3 * b]
                };
                for &cell in cells {
                    assert_eq!(
                        r.mask(cell),
                        r.mask_reference(cell),
                        "{model}, stagger {stagger}, cell {cell}"
                    );
                }
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

#[test]
fn figures_and_masks_with_evenly_spaced_loops() {
    let mut s = Settings::default();
    s.set("loop_spacing", "even").unwrap();
    let b = s.droplet_width();
    for r in rasters_with("3DBenchy.stl", s, 31) {
        assert_eq!(r.analysis(), r.analysis_reference());
        assert_eq!(r.mask(b / 4.0), r.mask_reference(b / 4.0));
    }
}
