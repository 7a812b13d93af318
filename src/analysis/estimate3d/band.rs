//! The 3D estimate in a band: a layer's droplets deep in its interior are left out of its
//! spheroid map, and a slab's cells in blocks that are interior in its own layer and in both
//! neighbours take the void share of the fill's regular lattice, computed once per job and
//! kind of layer ([`crate::analysis::InteriorRates`]). The other cells are filled exactly, from
//! maps holding every droplet that reaches them (patches of the maps where left-out droplets
//! reach such cells).

use super::{CHUNK, Fill, Grid3, HeightMap, MapRow, ceil_i64, slab_rows};
use crate::analysis::lines::{DropletLines, SkipGrid};
use crate::analysis::raster::{dilate2, region_spans};
use crate::base::geom::{Point, Shapes, all_contours, dist};
use crate::base::settings::Settings;
use crate::base::spatial::floor_i64;

/// Grid cells per side of a block (2.7 B with the default grid).
const BLOCK_CELLS: i64 = 8;
/// At most this many blocks over a layer's box (else it is not banded).
const MAX_BLOCKS: usize = 4_000_000;
/// A block within the band is 1; in the region beyond it 2; and 3 when every block within
/// [`DEEP_MARGIN`] of it is too (its droplets are left out of the layer's map).
/// Blocks between the band and the deep interior: a layer's boundary may move this far from
/// the next layer's before a slab puts left-out droplets back.
const DEEP_MARGIN: usize = 1;
const BAND: u8 = 1;
const INTERIOR: u8 = 2;
const DEEP: u8 = 3;

/// Which blocks sample the interior (the same in every layer of a job): filled exactly, so
/// that each slab's interior takes the void share measured on its own samples. One block in
/// `every`, spread over rows and columns as a rank-1 lattice: block (bx, by) when
/// bx + `mult`·by ≡ 0 (mod `every`). Whole rows of blocks measured the interior unevenly where
/// the fill's phases repeat along a row (U_overhang with support from unit 1 1.06 points of
/// predicted density off the whole raster, 3DBenchy with stagger 0.3), a lattice does not.
///
/// `every` grows with the layers' mean area ([`Samples::for_area`]) so that a layer samples
/// about [`SAMPLED_BLOCKS`] blocks or more however large it is: the interior's cost stops
/// growing with its area (on stanford_bunny one block in 128 instead of 8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Samples {
    every: i64,
    mult: i64,
}

/// Blocks a layer of the job's mean area samples, at least (unless it has fewer than
/// [`MIN_EVERY`] times as many).
const SAMPLED_BLOCKS: f64 = 64.0;
/// One block in this many at least, and at most.
const MIN_EVERY: i64 = 8;
const MAX_EVERY: i64 = 256;

impl Samples {
    /// One block in `every` (a power of two from 8 to 256 after rounding down), its
    /// multiplier the odd number nearest `every`/φ² (for 8: 3), which spreads the samples
    /// evenly over rows and columns.
    fn every(every: i64) -> Samples {
        let every = every.clamp(MIN_EVERY, MAX_EVERY);
        let every = 1i64 << (63 - every.leading_zeros());
        let m = (every as f64 * 0.381_966).round() as i64;
        Samples { every, mult: m | 1 }
    }

    /// The samples for a job whose layers' mean region is `area` mm² on `grid`: one block in
    /// the largest power of two that still leaves [`SAMPLED_BLOCKS`] samples to such a layer.
    pub fn for_area(area: f64, grid: &Grid3) -> Samples {
        let bs = BLOCK_CELLS as f64 * grid.cell;
        let blocks = area / (bs * bs);
        let ratio = if blocks.is_finite() {
            (blocks / SAMPLED_BLOCKS).clamp(1.0, MAX_EVERY as f64)
        } else {
            1.0
        };
        Samples::every(ratio as i64)
    }

    /// Whether block (bx, by) is a sample.
    #[inline]
    fn holds(self, bx: i64, by: i64) -> bool {
        (bx + self.mult * by).rem_euclid(self.every) == 0
    }
}

/// The block holding coordinate `v` along axis `k` (`⌊(v − origin) / size⌋`).
#[inline]
fn block_of(grid: &Grid3, v: f64, k: usize) -> i64 {
    floor_i64((v - grid.origin[k]) / (BLOCK_CELLS as f64 * grid.cell))
}

/// A slab with fewer sampled interior cells than this takes the job's lattice share instead.
const MIN_SAMPLED_CELLS: u64 = 256;

/// A layer's blocks on the 3D grid (fixed to the job, so the same for every layer), over the
/// box of its region.
pub struct Blocks {
    bx0: i64,
    by0: i64,
    w: usize,
    h: usize,
    kind: Vec<u8>,
    samples: Samples,
}

impl Blocks {
    /// The blocks of a layer's `region` with a band of `width` mm, the interior sampled by
    /// `samples` (the job's); `None` for an empty region or one whose box holds too many
    /// blocks.
    pub fn new(region: &Shapes, grid: &Grid3, width: f64, samples: Samples) -> Option<Blocks> {
        let bs = BLOCK_CELLS as f64 * grid.cell;
        let (mut min, mut max) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in all_contours(region).flatten() {
            for k in 0..2 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        if !(min[0].is_finite() && max[0].is_finite()) {
            return None;
        }
        let r = (width / bs).ceil().max(1.0) as i64;
        let b = |v: f64, k: usize| block_of(grid, v, k);
        let (bx0, by0) = (b(min[0], 0) - r - 1, b(min[1], 1) - r - 1);
        let (bx1, by1) = (b(max[0], 0) + r + 1, b(max[1], 1) + r + 1);
        let (w, h) = ((bx1 - bx0 + 1) as usize, (by1 - by0 + 1) as usize);
        if w.saturating_mul(h) > MAX_BLOCKS {
            return None;
        }
        let mut edge = vec![false; w * h];
        let step = 0.25 * bs;
        for c in all_contours(region) {
            for i in 0..c.len() {
                let (p, q) = (c[i], c[(i + 1) % c.len()]);
                let n = (dist(p, q) / step).ceil().clamp(1.0, 1e9) as usize;
                for t in 0..=n {
                    let x = p + (q - p) * (t as f64 / n as f64);
                    let (ix, iy) = (b(x[0], 0) - bx0, b(x[1], 1) - by0);
                    if (0..w as i64).contains(&ix) && (0..h as i64).contains(&iy) {
                        edge[iy as usize * w + ix as usize] = true;
                    }
                }
            }
        }
        let band = dilate2(&edge, w, h, r as usize);
        let mut kind: Vec<u8> = band.iter().map(|&x| if x { BAND } else { 0 }).collect();
        // Beyond the band, a block is in the region when its centre is.
        let y0 = grid.origin[1] + by0 as f64 * bs;
        region_spans(region, y0, bs, h, |k, xa, xb| {
            let first = ceil_i64((xa - grid.origin[0]) / bs - 0.5) - bx0;
            let last = floor_i64((xb - grid.origin[0]) / bs - 0.5) - bx0;
            for ix in first.max(0)..=last.min(w as i64 - 1) {
                let i = k * w + ix as usize;
                if kind[i] == 0 {
                    kind[i] = INTERIOR;
                }
            }
        });
        let other: Vec<bool> = kind.iter().map(|&k| k != INTERIOR).collect();
        let near = dilate2(&other, w, h, DEEP_MARGIN);
        for (k, near) in kind.iter_mut().zip(near) {
            if *k == INTERIOR && !near {
                *k = DEEP;
            }
        }
        Some(Blocks {
            bx0,
            by0,
            w,
            h,
            kind,
            samples,
        })
    }

    /// The kind of block (bx, by); 0 outside the box.
    #[inline]
    fn kind(&self, bx: i64, by: i64) -> u8 {
        let (x, y) = (bx - self.bx0, by - self.by0);
        if x < 0 || y < 0 || x >= self.w as i64 || y >= self.h as i64 {
            return 0;
        }
        self.kind[y as usize * self.w + x as usize]
    }

    /// Per block of the box, whether a droplet may be left out of the map there: the block
    /// is deep and not a sample.
    fn left_out(&self) -> Vec<bool> {
        (self.kind.iter().enumerate())
            .map(|(at, &k)| {
                let (bx, by) = (
                    (at % self.w) as i64 + self.bx0,
                    (at / self.w) as i64 + self.by0,
                );
                k == DEEP && !self.samples.holds(bx, by)
            })
            .collect()
    }

    /// Whether the box `p` ± `r` (mm) touches a block of the box flagged in `flags` (`all`:
    /// whether every block it touches is flagged, blocks outside the box unflagged), the
    /// blocks found as `⌊(v − origin) / size⌋`.
    #[inline]
    fn touches(&self, grid: &Grid3, flags: &[bool], p: Point, r: f64, all: bool) -> bool {
        let b = |v: f64, k: usize| block_of(grid, v, k);
        let (x0, x1) = (b(p[0] - r, 0) - self.bx0, b(p[0] + r, 0) - self.bx0);
        let (y0, y1) = (b(p[1] - r, 1) - self.by0, b(p[1] + r, 1) - self.by0);
        let (w, h) = (self.w as i64, self.h as i64);
        if x0 < 0 || y0 < 0 || x1 >= w || y1 >= h {
            // Partly outside the box (never when `all` holds: the box's rim is not deep).
            let flag = |x: i64, y: i64| {
                (0..w).contains(&x) && (0..h).contains(&y) && flags[(y * w + x) as usize]
            };
            return if all {
                (y0..=y1).all(|y| (x0..=x1).all(|x| flag(x, y)))
            } else {
                (y0..=y1).any(|y| (x0..=x1).any(|x| flag(x, y)))
            };
        }
        let (x0, x1, y0, y1) = (x0 as usize, x1 as usize, y0 as usize, y1 as usize);
        let row = |y: usize| {
            let f = &flags[y * self.w + x0..=y * self.w + x1];
            if all {
                f.iter().all(|&x| x)
            } else {
                f.iter().any(|&x| x)
            }
        };
        if all {
            (y0..=y1).all(row)
        } else {
            (y0..=y1).any(row)
        }
    }

    /// Whether the block holding `p` lies in the box and is flagged in `flags`.
    #[inline]
    fn flagged_at(&self, grid: &Grid3, flags: &[bool], p: Point) -> bool {
        (self.at(block_of(grid, p[0], 0), block_of(grid, p[1], 1))).is_some_and(|i| flags[i])
    }

    /// The index in the box of block (bx, by), if it lies in it.
    #[inline]
    fn at(&self, bx: i64, by: i64) -> Option<usize> {
        let (x, y) = (bx - self.bx0, by - self.by0);
        (x >= 0 && y >= 0 && x < self.w as i64 && y < self.h as i64)
            .then(|| y as usize * self.w + x as usize)
    }
}

/// A layer's spheroid map for the banded estimate: its droplets but those deep in its
/// interior, which are left out (walked over along their lines, [`SkipGrid::walk`]).
pub struct UnitMap {
    pub(crate) map: HeightMap,
    blocks: Option<Blocks>,
    /// The layer's droplets (for [`patch`](Self::patch)), how many were left out of the map,
    /// and their footprint diameter.
    lines: DropletLines,
    left_out: u64,
    d: f64,
}

impl Blocks {
    /// The blocks as a [`SkipGrid`], flagged where `flag(index in the box)`.
    fn skip_grid(&self, grid: &Grid3, flag: impl Fn(usize) -> bool) -> SkipGrid {
        let bs = BLOCK_CELLS as f64 * grid.cell;
        SkipGrid::new(
            grid.origin,
            Point::splat(bs),
            (self.bx0, self.by0),
            (self.w, self.h),
            flag,
        )
    }
}

impl UnitMap {
    /// The map of the droplets on `lines` (footprint diameter `d`), without those in
    /// `blocks`' deep blocks (all of them without `blocks`).
    pub fn new(lines: &DropletLines, grid: &Grid3, d: f64, blocks: Option<Blocks>) -> UnitMap {
        let Some(bl) = blocks else {
            return UnitMap {
                map: HeightMap::new(&lines.centres(), grid, d),
                blocks: None,
                lines: DropletLines::default(),
                left_out: 0,
                d,
            };
        };
        let (r, out) = (d / 2.0, bl.left_out());
        let mut kept = Vec::new();
        let mut left_out = 0;
        let walked = bl.skip_grid(grid, |i| out[i]).walk(lines, |p| {
            // Kept at once when its own block is not left out (most the walk hands over).
            if bl.flagged_at(grid, &out, p) && bl.touches(grid, &out, p, r, true) {
                left_out += 1;
            } else {
                kept.push(p);
            }
        });
        UnitMap {
            map: HeightMap::new(&kept, grid, d),
            blocks: Some(bl),
            lines: lines.clone(),
            left_out: left_out + walked,
            d,
        }
    }

    /// For the blocks `needed` (per block of this layer's box, [`Blocks`]) flags, where
    /// droplets left out of the map reach cells a slab fills exactly: a map of every droplet
    /// that reaches them (those left out and those kept), exact there; `None` when no block is
    /// flagged. The map itself stays exact elsewhere, so a slab reads this one in the flagged
    /// blocks only, and the whole layer is not mapped again.
    fn patch(&self, grid: &Grid3, needed: &[bool]) -> Option<HeightMap> {
        let bl = self.blocks.as_ref()?;
        if !needed.iter().any(|&n| n) {
            return None;
        }
        let r = self.d / 2.0;
        // A droplet reaches only the blocks next to its own.
        let near = dilate2(needed, bl.w, bl.h, 1);
        let mut reach = Vec::new();
        bl.skip_grid(grid, |i| !near[i]).walk(&self.lines, |p| {
            if bl.touches(grid, needed, p, r, false) {
                reach.push(p);
            }
        });
        Some(HeightMap::new(&reach, grid, self.d))
    }
}

/// [`super::slab_voids`] with the slab's cells in blocks that are interior in all three layers
/// taking the void share `share` (of a slab of the fill's lattice); the maps are those of
/// [`UnitMap`], and where a droplet left out of one reaches a cell filled exactly, that map's
/// patch with it is read there ([`UnitMap::patch`]). Without blocks for all three layers, every cell is exact.
pub fn slab_voids_banded(
    region: &Shapes,
    grid: &Grid3,
    maps: [Option<&UnitMap>; 3],
    s: &Settings,
    share: f64,
) -> (f64, f64) {
    let fill = Fill::new(s);
    let Some(this) = maps[1] else {
        return (0.0, 0.0);
    };
    let Some((k0, ny, y0)) = slab_rows(region, grid) else {
        return (0.0, 0.0);
    };
    let blocks: [Option<&Blocks>; 3] = maps.map(|m| m.and_then(|m| m.blocks.as_ref()));
    let inner = |bx: i64, by: i64| {
        blocks
            .iter()
            .all(|b| b.is_some_and(|b| b.kind(bx, by) >= INTERIOR))
    };
    // Where a layer's left-out droplets reach a block of the slab's region filled exactly (a
    // deep block of that layer that is not interior in another), a patch of that layer's map
    // with them is read instead of its map. (A left-out droplet reaches only its own deep
    // blocks.)
    let own = this.blocks.as_ref();
    let patches: Vec<Option<(HeightMap, Vec<bool>, &Blocks)>> = (0..3)
        .map(|i| {
            let m = maps[i]?;
            let mb = m.blocks.as_ref()?;
            if m.left_out == 0 {
                return None;
            }
            let needed: Vec<bool> = (mb.kind.iter().enumerate())
                .map(|(at, &k)| {
                    let (bx, by) = ((at % mb.w) as i64 + mb.bx0, (at / mb.w) as i64 + mb.by0);
                    k == DEEP && own.is_none_or(|o| o.kind(bx, by) != 0) && !inner(bx, by)
                })
                .collect();
            Some((m.patch(grid, &needed)?, needed, mb))
        })
        .collect();
    let map_of = |i: usize| maps[i].map(|m| &m.map);
    let patch_of = |i: usize| patches[i].as_ref().map(|p| &p.0);
    // Whether map i reads its patch in block (bx, by).
    let patched = |i: usize, bx: i64, by: i64| {
        patches[i]
            .as_ref()
            .is_some_and(|(_, needed, mb)| mb.at(bx, by).is_some_and(|a| needed[a]))
    };
    let any_patch = patches.iter().any(Option::is_some);
    // Per block of this layer's box that is interior in all three layers and not a sample
    // (counted, not filled), where its run of such blocks along the row ends (the grid index
    // of the first block after it); `i64::MIN` for other blocks. A row's span passes over a
    // run at once.
    let run_end: Vec<i64> = own.map_or_else(Vec::new, |o| {
        let mut v = vec![i64::MIN; o.w * o.h];
        for y in 0..o.h {
            let by = y as i64 + o.by0;
            let mut end = i64::MIN;
            for x in (0..o.w).rev() {
                let bx = x as i64 + o.bx0;
                if inner(bx, by) && !o.samples.holds(bx, by) {
                    if end == i64::MIN {
                        end = bx + 1;
                    }
                    v[y * o.w + x] = end;
                } else {
                    end = i64::MIN;
                }
            }
        }
        v
    });
    let (mut cells, mut filled) = (0u64, 0.0f64);
    // The interior's cells not sampled, and the sampled ones with their fill.
    let (mut unsampled, mut sampled, mut sampled_fill) = (0u64, 0u64, 0.0f64);
    let mut col = [0f64; CHUNK];
    region_spans(region, y0, grid.cell, ny, |k, xa, xb| {
        let iy = k0 + k as i64;
        let c0 = ceil_i64((xa - grid.origin[0]) / grid.cell - 0.5);
        let c1 = floor_i64((xb - grid.origin[0]) / grid.cell - 0.5);
        if c0 > c1 {
            return;
        }
        let by = iy.div_euclid(BLOCK_CELLS);
        let rows = [0, 1, 2].map(|i| map_of(i).map_or(MapRow::EMPTY, |m| m.row(iy)));
        let patch_rows = [0, 1, 2].map(|i| patch_of(i).map_or(MapRow::EMPTY, |m| m.row(iy)));
        let mut from = c0;
        while from <= c1 {
            let bx = from.div_euclid(BLOCK_CELLS);
            let end = own
                .and_then(|o| o.at(bx, by))
                .map_or(i64::MIN, |a| run_end[a]);
            if end != i64::MIN {
                let to = c1.min(end * BLOCK_CELLS - 1);
                cells += (to - from + 1) as u64;
                unsampled += (to - from + 1) as u64;
                from = to + 1;
                continue;
            }
            let block_end = (bx + 1) * BLOCK_CELLS - 1;
            let inside = inner(bx, by);
            let row_of = |i: usize| {
                if any_patch && patched(i, bx, by) {
                    patch_rows[i]
                } else {
                    rows[i]
                }
            };
            let before = filled;
            let (xb, rb, eb) = row_of(0).piece(from);
            let (xt, rt, et) = row_of(1).piece(from);
            let (xa, ra, ea) = row_of(2).piece(from);
            let to = c1.min(et).min(eb).min(ea).min(block_end);
            cells += (to - from + 1) as u64;
            filled = fill.stretch([(xt, rt), (xb, rb), (xa, ra)], from, to, &mut col, filled);
            if inside {
                sampled += (to - from + 1) as u64;
                sampled_fill += filled - before;
            }
            from = to + 1;
        }
    });
    // The unsampled interior filled as the samples are (or as the job's lattice, when too
    // few cells are sampled).
    let full = if sampled >= MIN_SAMPLED_CELLS {
        sampled_fill / sampled as f64
    } else {
        fill.h * (1.0 - share)
    };
    filled += unsampled as f64 * full;
    let area = grid.cell * grid.cell;
    let volume = cells as f64 * area * fill.h;
    (volume, (volume - filled * area).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::{Grid3, MAX_EVERY, MIN_EVERY, SAMPLED_BLOCKS, Samples};
    use crate::base::geom::Point;

    #[test]
    fn samples_are_one_block_in_a_power_of_two_spread_over_rows_and_columns() {
        let grid = Grid3 {
            origin: Point::ZERO,
            cell: 0.208 / 3.0,
        };
        let block = 8.0 * grid.cell;
        let mut last = 0;
        for blocks in [
            0.0,
            10.0,
            1e3,
            2e4,
            6e4,
            1e5,
            1e6,
            1e9,
            f64::NAN,
            f64::INFINITY,
        ] {
            let s = Samples::for_area(blocks * block * block, &grid);
            assert!((s.every as u64).is_power_of_two(), "{blocks}: {s:?}");
            assert!(
                (MIN_EVERY..=MAX_EVERY).contains(&s.every),
                "{blocks}: {s:?}"
            );
            if blocks.is_finite() {
                // More samples to a layer than asked, unless the fewest a layer takes.
                assert!(s.every == MIN_EVERY || blocks / s.every as f64 >= SAMPLED_BLOCKS);
                assert!(
                    s.every >= last,
                    "{blocks}: fewer samples the larger the layer"
                );
                last = s.every;
            }
            // One block in `every` on every row and every column of blocks, and no block
            // farther from a sample than the lattice's spread allows.
            let n = s.every;
            for by in -3..n + 3 {
                let row = (0..n).filter(|&bx| s.holds(bx, by)).count();
                assert_eq!(row, 1, "{s:?}, row {by}");
            }
            for bx in -3..n + 3 {
                let col = (0..n).filter(|&by| s.holds(bx, by)).count();
                assert_eq!(col, 1, "{s:?}, column {bx}");
            }
            let reach = (n as f64).sqrt().ceil() as i64 + 1;
            for by in 0..n {
                for bx in 0..n {
                    let near = (-reach..=reach)
                        .any(|dy| (-reach..=reach).any(|dx| s.holds(bx + dx, by + dy)));
                    assert!(near, "{s:?}: block ({bx}, {by}) far from any sample");
                }
            }
        }
    }
}
