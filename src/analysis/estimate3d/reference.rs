//! The 3D estimate written plainly, kept as the reference the fast path ([`super`]) is tested
//! against (tests/estimate3d_fast.rs) and timed against (examples/estimate3d_profile.rs): a
//! droplet's cells, their centres and ⌊·⌋ (libm) computed for each droplet and every cell of
//! its box raised; a slab's cells taken one by one, each map's q found among its row's
//! segments, each column's fill the union of three intervals added in order. It shares with
//! the fast path only the maps' storage (`HeightMap::zeros` and `cells_mut`, the rows of
//! [`SlabRow`]) and the slab's constants and rows. Built for tests and with the `reference`
//! feature only.

use super::super::raster::region_spans;
use super::{Grid3, HeightMap, MapRow, SlabRow};
use crate::base::geom::{Point, Shapes};
use crate::base::settings::Settings;
use crate::base::spatial::{Segment, Spot};

impl HeightMap {
    /// The height map of [`HeightMap::new`], built plainly.
    pub fn reference(centres: &[Point], grid: &Grid3, d: f64) -> HeightMap {
        let r = d / 2.0;
        let mut min = [i64::MAX; 2];
        let mut max = [i64::MIN; 2];
        let idx = |v: f64, k: usize| ((v - grid.origin[k]) / grid.cell - 0.5).floor() as i64;
        for p in centres {
            for k in 0..2 {
                min[k] = min[k].min(idx(p[k] - r, k));
                max[k] = max[k].max(idx(p[k] + r, k) + 1);
            }
        }
        if centres.is_empty() {
            return HeightMap::default();
        }
        // A droplet's cells [ax, bx] × [ay, by].
        let cells = |p: &Point| {
            [
                idx(p[0] - r, 0),
                idx(p[0] + r, 0) + 1,
                idx(p[1] - r, 1),
                idx(p[1] + r, 1) + 1,
            ]
        };
        let cells: Vec<_> = centres.iter().map(cells).collect();
        let mut map = HeightMap::zeros(min, max, &cells);
        let inv = 1.0 / (r * r);
        let mut xx = Vec::new();
        let mut spot: Option<Spot> = None;
        for (p, &[ax, bx, ay, by]) in centres.iter().zip(&cells) {
            xx.clear();
            xx.extend((ax..=bx).map(|ix| {
                let x = grid.origin[0] + (ix as f64 + 0.5) * grid.cell - p[0];
                x * x
            }));
            // Every cell of the droplet's box (one outside the droplet gets q ≤ 0, which
            // raises none).
            for iy in ay..=by {
                let y = grid.origin[1] + (iy as f64 + 0.5) * grid.cell - p[1];
                let yy = y * y;
                let (k, c) = ((iy - min[1]) as usize, (ax - min[0]) as usize);
                for (slot, &x2) in map.cells_mut(&mut spot, k, c, xx.len()).iter_mut().zip(&xx) {
                    let v = (1.0 - (x2 + yy) * inv) as f32;
                    if v > *slot {
                        *slot = v;
                    }
                }
            }
        }
        map
    }
}

impl MapRow<'_> {
    /// The q of grid cell `ix`: from the segment holding it, 0 where none does. Cell by cell,
    /// as the fast path's stretches ([`MapRow::piece`]) must give it.
    fn q(&self, ix: i64) -> f32 {
        let holds = |s: &&Segment| (self.x0 + s.c0 as i64..self.x0 + s.c1 as i64).contains(&ix);
        self.segs.iter().find(holds).map_or(0.0, |s| {
            self.data[s.at + (ix - self.x0 - s.c0 as i64) as usize]
        })
    }
}

/// The 3D estimate for layer i's slab: (volume, void volume) in mm³ of its region × H, filled
/// by the spheroids of layers i − 1 (`below`), i and i + 1 (`above`).
pub fn slab_voids_reference(
    region: &Shapes,
    grid: &Grid3,
    below: Option<&HeightMap>,
    this: &HeightMap,
    above: Option<&HeightMap>,
    s: &Settings,
) -> (f64, f64) {
    let super::Fill {
        h,
        half,
        c,
        q_reach,
    } = super::Fill::new(s);
    let Some((k0, ny, y0)) = super::slab_rows(region, grid) else {
        return (0.0, 0.0);
    };
    let (mut cells, mut filled) = (0u64, 0.0f64);
    let ext = |q: f32| -> f64 {
        if q > q_reach {
            (c * (q as f64).sqrt() - half).max(0.0)
        } else {
            0.0
        }
    };
    region_spans(region, y0, grid.cell, ny, |k, xa, xb| {
        let iy = k0 + k as i64;
        let c0 = ((xa - grid.origin[0]) / grid.cell - 0.5).ceil() as i64;
        let c1 = ((xb - grid.origin[0]) / grid.cell - 0.5).floor() as i64;
        let maps = SlabRow::new(iy, [below, Some(this), above]);
        for ix in c0..=c1 {
            cells += 1;
            // Local z from the slab's bottom: [0, lo] from below, the own droplet around
            // h/2, [h − hi, h] from above.
            let q = maps.this.q(ix);
            let a = if q > 0.0 {
                (c * (q as f64).sqrt()).min(half)
            } else {
                0.0
            };
            if a >= half {
                // The own droplet fills the whole column.
                filled += h;
                continue;
            }
            let lo = ext(maps.below.q(ix)).min(h);
            let hi = ext(maps.above.q(ix)).min(h);
            let (m0, m1) = (half - a, half + a);
            // Union of [0, lo], [m0, m1] (if a > 0), [h − hi, h].
            let mut len = 0.0;
            let mut end = 0.0f64;
            for (s0, s1) in [(0.0, lo), (m0, m1), (h - hi, h)] {
                if s1 <= s0 {
                    continue;
                }
                let s0 = s0.max(end);
                if s1 > s0 {
                    len += s1 - s0;
                    end = s1;
                }
            }
            filled += len;
        }
    });
    let area = grid.cell * grid.cell;
    let volume = cells as f64 * area * h;
    (volume, (volume - filled * area).max(0.0))
}
