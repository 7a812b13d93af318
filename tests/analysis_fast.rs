//! The fast paths of the analysis against the exact ones they replace, on real models: the
//! page's coverage mask cell for cell (the 4-bit-group counts for cells of B/4, the window
//! counts for larger cells) against the masks counted range by range, and the layer figures
//! of the one-pass labelling against the run-per-node labelling, equal (the 0.1 % the
//! analysis may differ by is not needed); the page's mask (no covered shares) and one raster
//! reused from layer to layer against new ones.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::analysis::{
    CoverageMask, MaskTile, Raster, analyse_layer_for_page, analyse_layer_with_mask,
};
use dropslice::{Job, Settings};

const MODELS: [&str; 4] = [
    "3DBenchy.stl",
    "extruder_idler.stl",
    "stanford_bunny.stl",
    "esca_nonmanifold.stl",
];

/// Every `step`-th layer of each of [`MODELS`], stagger off and on, as rasters, each with its
/// model and stagger.
fn rasters(step: usize) -> impl Iterator<Item = (&'static str, bool, Raster)> {
    MODELS.into_iter().flat_map(move |model| {
        [false, true].into_iter().flat_map(move |stagger| {
            // The bunny is wider than the default plate: allowed here.
            let s = Settings {
                stagger,
                allow_off_plate: true,
                ..Settings::default()
            };
            let layers = rasters_with(model, s, step);
            layers.into_iter().map(move |r| (model, stagger, r))
        })
    })
}

fn rasters_with(model: &str, s: Settings, step: usize) -> Vec<Raster> {
    let job = Job::new(&common::model_bytes(model), model, s.clone()).unwrap();
    (0..job.layer_count())
        .step_by(step)
        .map(|i| {
            let region = &job.section(i).region;
            let plan = dropslice::slicing::plan::plan_layer(region, i, &s);
            Raster::new(&plan, region, &s)
        })
        .collect()
}

#[test]
fn masks_are_those_counted_range_by_range() {
    let b = Settings::default().droplet_width();
    for (model, stagger, r) in rasters(23) {
        // B/4: the page's cells (4-bit groups); B, 7.3 B: by windows.
        let cells: &[f64] = if stagger {
            &[b / 4.0]
        } else {
            &[b / 4.0, b / 6.0, b, 7.3 * b]
        };
        for &cell in cells {
            let want = r.mask_reference(cell);
            assert_eq!(
                r.mask(cell),
                want,
                "{model}, stagger {stagger}, cell {cell}"
            );
            // The page's: the same without the covered shares.
            assert_eq!(
                r.page_mask(cell),
                without_covered(want),
                "page mask: {model}, stagger {stagger}, cell {cell}"
            );
        }
    }
}

fn without_covered(m: CoverageMask) -> CoverageMask {
    CoverageMask {
        tiles: m
            .tiles
            .into_iter()
            .map(|t| MaskTile {
                covered: Vec::new(),
                ..t
            })
            .collect(),
        ..m
    }
}

/// The page's worker rasterises every layer into one raster (`analyse_layer_for_page`): the
/// figures and masks are those of a new raster per layer, whatever layer came before
/// (larger, smaller, empty).
#[test]
fn one_raster_reused_gives_the_figures_of_new_ones() {
    let s = Settings::default();
    let b = s.droplet_width();
    let model = "3DBenchy.stl";
    let job = Job::new(&common::model_bytes(model), model, s.clone()).unwrap();
    let n = job.layer_count();
    let mut r = Raster::empty();
    // Up and down the part, every 7th layer, then the first layers in order.
    let order = (0..n)
        .step_by(7)
        .chain((0..n).rev().step_by(11))
        .chain(0..4);
    for i in order {
        let region = &job.section(i).region;
        let plan = dropslice::slicing::plan::plan_layer(region, i, &s);
        let (a, mask) = analyse_layer_with_mask(&plan, region, &s, b / 4.0);
        let (pa, pmask) = analyse_layer_for_page(&mut r, &plan, region, &s, b / 4.0);
        assert_eq!(pa, a, "layer {i}");
        assert_eq!(pmask, without_covered(mask), "layer {i}");
    }
}

#[test]
fn layer_figures_are_those_of_the_reference_labelling() {
    for (model, stagger, r) in rasters(29) {
        let want = r.analysis_reference();
        assert_eq!(r.analysis(), want, "{model} stagger {stagger}");
        // Natively the fast path may take the popcount instruction: also without it.
        assert_eq!(
            r.analysis_portable(),
            want,
            "portable: {model} stagger {stagger}"
        );
    }
}

#[test]
fn figures_and_masks_with_evenly_spaced_loops() {
    let s = common::settings_with("loop_spacing", "even");
    let b = s.droplet_width();
    for r in rasters_with("3DBenchy.stl", s, 31) {
        assert_eq!(r.analysis(), r.analysis_reference());
        assert_eq!(r.mask(b / 4.0), r.mask_reference(b / 4.0));
    }
}

/// Random layers the models do not give: rectangles (some with a hole, some a few tiles
/// apart, so rows have several segments and bands), droplets scattered in and around them,
/// sparse (long void runs across words, touching the edge or not) and dense (overfill, small
/// voids). The fast labelling's figures, with and without the popcount instruction, are the
/// reference's.
#[test]
fn random_layers_give_the_reference_figures() {
    use dropslice::base::geom::{Point, Shape, Shapes};
    let s = Settings::default();
    let b = s.droplet_width();
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let rect = common::rect_loop;
    for case in 0..400 {
        let mut region: Shapes = Vec::new();
        let mut x = 0.0;
        for _ in 0..1 + case % 3 {
            let (w, h) = (0.5 + 4.0 * rnd(), 0.5 + 4.0 * rnd());
            let y = 3.0 * rnd();
            let holes = if w > 2.0 && h > 2.0 && rnd() < 0.5 {
                let mut hole = rect(x + w / 4.0, y + h / 4.0, w / 2.0, h / 2.0);
                hole.reverse();
                vec![hole]
            } else {
                vec![]
            };
            region.push(Shape::new(rect(x, y, w, h), holes));
            // Next to it or a few tiles (1.33 mm) away.
            x += w + 0.2 + if rnd() < 0.5 { 3.0 * rnd() } else { 0.0 };
        }
        let density = [0.3, 1.0, 3.0][case % 3];
        let n = (density * x * 7.0 / (b * b)) as usize;
        let centres: Vec<Point> = (0..n)
            .map(|_| [x * rnd() - 0.3, 7.5 * rnd() - 0.3].into())
            .collect();
        let r = Raster::from_centres(case, 0.0, &centres, &region, &s);
        let want = r.analysis_reference();
        assert_eq!(r.analysis(), want, "case {case}");
        assert_eq!(r.analysis_portable(), want, "portable: case {case}");
    }
}
