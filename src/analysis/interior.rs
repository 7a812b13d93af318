//! The interior of a banded analysis: what a layer's regular fill gives, measured once per job
//! and kind of layer on a patch (a square planned as the job plans its layers, analysed
//! whole), for the interior the banded raster and the banded 3D estimate do not compute.

use super::droplet::footprint_diameter;
use super::estimate3d::{Grid3, HeightMap, slab_voids};
use super::lines::DropletLines;
use super::raster::Raster;
use crate::base::geom::{DVec2, Shape, Shapes};
use crate::base::settings::Settings;
use crate::slicing::plan::{hatch_angle, hatch_shifted, plan_layer};
use std::collections::HashMap;
use std::sync::Mutex;

/// What the fill's lattice gives per unit of interior.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InteriorRates {
    /// Voids per grid cell of the 2D raster's interior (those the band's voids do not hold).
    pub void_rate: f64,
    /// The void share of a slab whose layer and both neighbours are regular fill.
    pub share: f64,
}

/// The patch's radius and the margin of its measured part, in B.
const PATCH_B: f64 = 32.0;
const MARGIN_B: f64 = 12.0;

/// The rates per kind of layer (its hatch angle and shift, and its neighbours'), measured on
/// first use.
#[derive(Debug, Default)]
pub struct InteriorCache {
    rates: Mutex<HashMap<[u64; 6], InteriorRates>>,
}

fn square(x: f64, y: f64, side: f64) -> Shapes {
    let p = |a: f64, b: f64| DVec2::new(a, b);
    vec![Shape::new(
        vec![
            p(x, y),
            p(x + side, y),
            p(x + side, y + side),
            p(x, y + side),
        ],
        vec![],
    )]
}

/// A disc of radius `r` about (x, y), as a polygon of 89 sides: the fill's lines start on its
/// edge at every phase (a square's edge would start them all in step).
fn disc(x: f64, y: f64, r: f64) -> Shapes {
    let n = 89;
    let points = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            DVec2::new(x + r * a.cos(), y + r * a.sin())
        })
        .collect();
    vec![Shape::new(points, vec![])]
}

impl InteriorCache {
    /// The rates for layer `j`'s interior (its slab between layers j − 1 and j + 1).
    pub fn rates(&self, s: &Settings, j: usize, grid: &Grid3, width: f64) -> InteriorRates {
        let key = kind(s, j.max(1));
        if let Some(r) = self.lock().get(&key) {
            return *r;
        }
        // Measured on the first layer of this kind, whichever layer asks first (the workers
        // ask in any order): the same rates, so the same report, on every run.
        let first = (1..j.max(1))
            .find(|&i| kind(s, i) == key)
            .unwrap_or(j.max(1));
        let r = measure(s, first, grid, width);
        self.lock().insert(key, r);
        r
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<[u64; 6], InteriorRates>> {
        self.rates.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A layer's kind (j ≥ 1): the hatch angles and shifts of layers j − 1, j and j + 1.
fn kind(s: &Settings, j: usize) -> [u64; 6] {
    let a = [j - 1, j, j + 1].map(|i| hatch_angle(s, i).to_bits());
    let b = [j - 1, j, j + 1].map(|i| hatch_shifted(s, i) as u64);
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

/// The rates measured on a patch: layers j − 1, j, j + 1 of a disc of radius 32 B, each moved
/// by a fraction of B (so that their fills do not start in step, as two layers of a part
/// seldom do), the 3D estimate on the square 12 B within it, the voids of layer j by the whole
/// raster against the banded one's band.
fn measure(s: &Settings, j: usize, grid: &Grid3, width: f64) -> InteriorRates {
    let b = s.droplet_width();
    let radius = PATCH_B * b;
    let offsets = [(0.0, 0.0), (0.41, 0.23), (0.77, 0.59)];
    let layers: Vec<(Shapes, DropletLines)> = (0..3)
        .map(|k| {
            let (ox, oy) = offsets[k];
            let region = disc(ox * b, oy * b, radius);
            let plan = plan_layer(&region, j + k - 1, s);
            (region, DropletLines::of(&plan, b))
        })
        .collect();
    let d = footprint_diameter(s);
    let maps: Vec<HeightMap> = layers
        .iter()
        .map(|l| HeightMap::new(&l.1.centres(), grid, d))
        .collect();
    let (ox, oy) = offsets[1];
    let half = (PATCH_B - MARGIN_B) * b / std::f64::consts::SQRT_2;
    let inner = square(ox * b - half, oy * b - half, 2.0 * half);
    let (vol, void) = slab_voids(&inner, grid, Some(&maps[0]), &maps[1], Some(&maps[2]), s);
    let share = if vol > 0.0 { void / vol } else { 0.0 };
    let (region, lines) = &layers[1];
    let whole = Raster::from_centres(j, 0.0, &lines.centres(), region, s).analysis();
    let mut banded = Raster::empty();
    banded.rebuild_banded(j, 0.0, lines, region, s, width, 0.0);
    let cells = banded.interior_cells();
    let part = banded.analysis();
    let void_rate = if cells > 0 {
        (whole.voids as f64 - part.voids as f64) / cells as f64
    } else {
        0.0
    };
    InteriorRates { void_rate, share }
}
