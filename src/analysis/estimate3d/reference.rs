//! The 3D estimate as it was before its fast path, unchanged, kept as the reference the fast
//! path ([`super`]) is tested against (tests/estimate3d_fast.rs) and timed against
//! (examples/estimate3d_profile.rs). Built for tests and with the `reference` feature only.

use super::super::raster::region_spans;
use super::{Grid3, HeightMap, MAP_BAND_ROWS, MAP_TILE_COLS, MapRow};
use crate::base::geom::{Point, Shapes};
use crate::base::settings::Settings;
use crate::base::spatial::{Spot, Tiles};

impl HeightMap {
    /// The height map as it was built before the fast path ([`HeightMap::new`]).
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
        let mut tiles = Tiles::default();
        let (w, h) = (
            (max[0] - min[0] + 1) as usize,
            (max[1] - min[1] + 1) as usize,
        );
        // A droplet's cells [ax, bx] × [ay, by].
        let cells = |p: &Point| {
            (
                (idx(p[0] - r, 0), idx(p[0] + r, 0) + 1),
                (idx(p[1] - r, 1), idx(p[1] + r, 1) + 1),
            )
        };
        let cells: Vec<_> = centres.iter().map(cells).collect();
        tiles.reset(h, w, MAP_BAND_ROWS, MAP_TILE_COLS);
        for &((ax, bx), (ay, by)) in &cells {
            let (x, y) = (
                |v: i64| (v - min[0]) as usize,
                |v: i64| (v - min[1]) as usize,
            );
            tiles.mark(y(ay), y(by), x(ax), x(bx));
        }
        let mut q = vec![0f32; tiles.build()];
        let inv = 1.0 / (r * r);
        let mut xx = Vec::new();
        // Where the last droplet row's cells were stored (mostly the next one's too).
        let mut spot: Option<Spot> = None;
        for (p, &((ax, bx), (ay, by))) in centres.iter().zip(&cells) {
            xx.clear();
            xx.extend((ax..=bx).map(|ix| {
                let x = grid.origin[0] + (ix as f64 + 0.5) * grid.cell - p[0];
                x * x
            }));
            for iy in ay..=by {
                let y = grid.origin[1] + (iy as f64 + 0.5) * grid.cell - p[1];
                let yy = y * y;
                if yy * inv >= 1.0 {
                    // No cell of this row is inside (q ≤ 0 never raises a cell).
                    continue;
                }
                let (k, c) = ((iy - min[1]) as usize, (ax - min[0]) as usize);
                let Some(sp) = tiles.spot_cached(&mut spot, k, c, c + xx.len() - 1) else {
                    debug_assert!(false, "droplet outside the map's tiles");
                    continue;
                };
                let at = sp.index(k) + c - sp.shift;
                for (slot, &x2) in q[at..at + xx.len()].iter_mut().zip(&xx) {
                    let v = (1.0 - (x2 + yy) * inv) as f32;
                    if v > *slot {
                        *slot = v;
                    }
                }
            }
        }
        HeightMap {
            x0: min[0],
            y0: min[1],
            tiles,
            q,
        }
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
    let at = |(x0, row): (i64, &[f32]), ix: i64| -> f32 {
        usize::try_from(ix - x0)
            .ok()
            .and_then(|x| row.get(x))
            .copied()
            .unwrap_or(0.0)
    };
    region_spans(region, y0, grid.cell, ny, |k, xa, xb| {
        let iy = k0 + k as i64;
        let c0 = ((xa - grid.origin[0]) / grid.cell - 0.5).ceil() as i64;
        let c1 = ((xb - grid.origin[0]) / grid.cell - 0.5).floor() as i64;
        let below = below.map_or(MapRow::EMPTY, |m| m.row(iy));
        let above = above.map_or(MapRow::EMPTY, |m| m.row(iy));
        let this = this.row(iy);
        // Stretches of the span over which each map is one slice (or nothing).
        let mut from = c0;
        while from <= c1 {
            let (xt, rt, et) = this.piece(from);
            let (xb, rb, eb) = below.piece(from);
            let (xa, ra, ea) = above.piece(from);
            let to = c1.min(et).min(eb).min(ea);
            let (rt, rb, ra) = ((xt, rt), (xb, rb), (xa, ra));
            for ix in from..=to {
                cells += 1;
                // Local z from the slab's bottom: [0, lo] from below, the own droplet around
                // h/2, [h − hi, h] from above.
                let q = at(rt, ix);
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
                let lo = ext(at(rb, ix)).min(h);
                let hi = ext(at(ra, ix)).min(h);
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
            from = to + 1;
        }
    });
    let area = grid.cell * grid.cell;
    let volume = cells as f64 * area * h;
    (volume, (volume - filled * area).max(0.0))
}
