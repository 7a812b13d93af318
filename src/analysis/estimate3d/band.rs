//! The 3D estimate in a band: a layer's droplets deep in its interior are left out of its
//! spheroid map, and a slab's cells in blocks that are interior in its own layer and in both
//! neighbours take the void share of the fill's regular lattice, computed once per job and
//! kind of layer ([`crate::analysis::InteriorRates`]). The other cells are filled exactly, from
//! maps holding every droplet that reaches them (the left-out droplets near them restored).

use super::{CHUNK, Fill, Grid3, HeightMap, SlabRow, ceil_i64, slab_cells, slab_rows};
use crate::analysis::raster::{dilate2, region_spans};
use crate::base::geom::{Point, Shapes, all_contours, dist};
use crate::base::settings::Settings;
use crate::base::spatial::floor_i64;

/// Grid cells per side of a block (2.7 B with the default grid).
const BLOCK_CELLS: i64 = 8;
/// At most this many blocks over a layer's box (else it is not banded).
const MAX_BLOCKS: usize = 4_000_000;
/// Blocks between the band and the deep interior: a layer's boundary may move this far from
/// the next layer's before a slab puts left-out droplets back.
const DEEP_MARGIN: usize = 1;
/// The kinds of block ([`Blocks::kind`]; 0: outside the region): a block within the band
/// is [`BAND`]; in the region beyond it [`INTERIOR`]; and [`DEEP`] when every block within
/// [`DEEP_MARGIN`] of it is too (its droplets are left out of the layer's map).
const BAND: u8 = 1;
const INTERIOR: u8 = 2;
const DEEP: u8 = 3;
/// One block in this many is a sample ([`sample`]).
const SAMPLE_EVERY: i64 = 8;
/// A slab with fewer sampled interior cells than this takes the job's lattice share instead.
const MIN_SAMPLED_CELLS: u64 = 256;

/// Whether block (bx, by) is one of the samples of the interior (one block in 8, the same in
/// every layer): filled exactly, so that each slab's interior takes the void share measured on
/// its own samples.
#[inline]
fn sample(bx: i64, by: i64) -> bool {
    (bx + 3 * by).rem_euclid(SAMPLE_EVERY) == 0
}

/// A layer's blocks on the 3D grid (fixed to the job, so the same for every layer), over the
/// box of its region.
pub struct Blocks {
    /// Block indices (counted from the grid's origin, [`BLOCK_CELLS`] cells a block) of the
    /// box's first block.
    bx0: i64,
    by0: i64,
    /// Blocks across and down the box.
    w: usize,
    h: usize,
    /// Each block's kind, row by row: 0 (outside the region), [`BAND`], [`INTERIOR`] or
    /// [`DEEP`].
    kind: Vec<u8>,
}

impl Blocks {
    /// The blocks of a layer's `region` with a band of `width` mm; `None` for an empty region
    /// or one whose box holds too many blocks.
    pub fn new(region: &Shapes, grid: &Grid3, width: f64) -> Option<Blocks> {
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
        let b = |v: f64, k: usize| floor_i64((v - grid.origin[k]) / bs);
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

    /// Whether every block of the box `lo`..`hi` (mm) is deep and none is a sample.
    fn deep(&self, grid: &Grid3, lo: Point, hi: Point) -> bool {
        let bs = BLOCK_CELLS as f64 * grid.cell;
        let b = |v: f64, k: usize| floor_i64((v - grid.origin[k]) / bs);
        (b(lo[1], 1)..=b(hi[1], 1)).all(|by| {
            (b(lo[0], 0)..=b(hi[0], 0)).all(|bx| self.kind(bx, by) == DEEP && !sample(bx, by))
        })
    }
}

/// A layer's spheroid map for the banded estimate: its droplets but those deep in its
/// interior, which are kept aside.
pub struct UnitMap {
    pub(crate) map: HeightMap,
    blocks: Option<Blocks>,
    /// The droplets left out of the map, and their footprint diameter.
    skipped: Vec<Point>,
    kept: Vec<Point>,
    d: f64,
}

impl UnitMap {
    /// The map of droplets at `centres` (footprint diameter `d`), without those in `blocks`'
    /// deep blocks (all of them without `blocks`).
    pub fn new(centres: &[Point], grid: &Grid3, d: f64, blocks: Option<Blocks>) -> UnitMap {
        let Some(bl) = blocks else {
            return UnitMap {
                map: HeightMap::new(centres, grid, d),
                blocks: None,
                skipped: Vec::new(),
                kept: Vec::new(),
                d,
            };
        };
        let r = Point::splat(d / 2.0);
        let (skipped, kept): (Vec<Point>, Vec<Point>) =
            centres.iter().partition(|&&p| bl.deep(grid, p - r, p + r));
        UnitMap {
            map: HeightMap::new(&kept, grid, d),
            blocks: Some(bl),
            skipped,
            kept,
            d,
        }
    }

    /// The map with the droplets left out of it restored where `needed` (per block of this
    /// layer's box, [`Blocks`]) says: itself (`None`) when no block is.
    fn restored(&self, grid: &Grid3, needed: &[bool]) -> Option<HeightMap> {
        let bl = self.blocks.as_ref()?;
        if !needed.iter().any(|&n| n) {
            return None;
        }
        let bs = BLOCK_CELLS as f64 * grid.cell;
        let b = |v: f64, k: usize| floor_i64((v - grid.origin[k]) / bs);
        let r = self.d / 2.0;
        let at = |bx: i64, by: i64| {
            let (x, y) = (bx - bl.bx0, by - bl.by0);
            x >= 0
                && y >= 0
                && (x as usize) < bl.w
                && (y as usize) < bl.h
                && needed[y as usize * bl.w + x as usize]
        };
        let back = self.skipped.iter().filter(|p| {
            (b(p[1] - r, 1)..=b(p[1] + r, 1))
                .any(|by| (b(p[0] - r, 0)..=b(p[0] + r, 0)).any(|bx| at(bx, by)))
        });
        let all: Vec<Point> = self.kept.iter().chain(back).copied().collect();
        Some(HeightMap::new(&all, grid, self.d))
    }
}

/// [`super::slab_voids`] with the slab's cells in blocks that are interior in all three layers
/// taking the void share `share` (of a slab of the fill's lattice); the maps are those of
/// [`UnitMap`], and where a droplet left out of one reaches a cell filled exactly, that map is
/// rebuilt with it for this slab. Without blocks for all three layers, every cell is exact.
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
    let Some(rows) = slab_rows(region, grid) else {
        return (0.0, 0.0);
    };
    let blocks: [Option<&Blocks>; 3] = maps.map(|m| m.and_then(|m| m.blocks.as_ref()));
    let inner = |bx: i64, by: i64| {
        blocks
            .iter()
            .all(|b| b.is_some_and(|b| b.kind(bx, by) >= INTERIOR))
    };
    // The maps for this slab: those whose left-out droplets lie in a block of the slab's
    // region filled exactly (a deep block of one layer that is not interior in another),
    // rebuilt with them. (A left-out droplet reaches only its own deep blocks.)
    let own = this.blocks.as_ref();
    let restored: Vec<Option<HeightMap>> = (0..3)
        .map(|i| {
            let m = maps[i]?;
            let mb = m.blocks.as_ref()?;
            if m.skipped.is_empty() {
                return None;
            }
            let needed: Vec<bool> = (mb.kind.iter().enumerate())
                .map(|(at, &k)| {
                    let (bx, by) = ((at % mb.w) as i64 + mb.bx0, (at / mb.w) as i64 + mb.by0);
                    k == DEEP && own.is_none_or(|o| o.kind(bx, by) != 0) && !inner(bx, by)
                })
                .collect();
            m.restored(grid, &needed)
        })
        .collect();
    let map_of =
        |i: usize| -> Option<&HeightMap> { restored[i].as_ref().or(maps[i].map(|m| &m.map)) };
    let (below, this_map, above) = (map_of(0), map_of(1).expect("own map"), map_of(2));
    let (mut cells, mut filled) = (0u64, 0.0f64);
    // The interior's cells not sampled, and the sampled ones with their fill.
    let (mut unsampled, mut sampled, mut sampled_fill) = (0u64, 0u64, 0.0f64);
    let mut col = [0f64; CHUNK];
    slab_cells(region, grid, rows, |iy, c0, c1| {
        let by = iy.div_euclid(BLOCK_CELLS);
        let maps = SlabRow::new(iy, [below, Some(this_map), above]);
        let mut from = c0;
        while from <= c1 {
            let bx = from.div_euclid(BLOCK_CELLS);
            let block_end = (bx + 1) * BLOCK_CELLS - 1;
            let inside = inner(bx, by);
            if inside && !sample(bx, by) {
                let to = c1.min(block_end);
                cells += (to - from + 1) as u64;
                unsampled += (to - from + 1) as u64;
                from = to + 1;
                continue;
            }
            let before = filled;
            let (pieces, end) = maps.pieces(from);
            let to = c1.min(end).min(block_end);
            cells += (to - from + 1) as u64;
            filled = fill.stretch(pieces, from, to, &mut col, filled);
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
