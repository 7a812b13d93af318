//! The 3D estimate: each layer's droplet spheroids as height maps on a 3D grid, and the void
//! volume of a slab between its neighbours' maps.

use super::droplet::spheroid_half_height;
use super::raster::region_spans;
use crate::base::geom::{Point, Shapes, all_contours};
use crate::base::settings::Settings;
use crate::base::spatial::{Segment, Spot, Tiles, floor_i64};

mod band;
#[cfg(any(test, feature = "reference"))]
mod reference;
pub use band::{Blocks, Samples, UnitMap, slab_voids_banded};
#[cfg(any(test, feature = "reference"))]
pub use reference::slab_voids_reference;

/// The 3D estimate samples the part every B / this.
pub const GRID3_PER_B: f64 = 3.0;

/// Rows per band and cells per tile of a [`HeightMap`]: tiles of 32 × 32 cells (2.2 mm square
/// with the default B).
const MAP_BAND_ROWS: usize = 32;
const MAP_TILE_COLS: usize = 32;

/// The droplet spheroids of one layer on the 3D grid: per cell, the largest
/// q = 1 − (2ρ/D)² over its droplets (ρ: horizontal distance to the droplet's centre), so the
/// droplets fill the cell's column within c·√q of the layer's mid-height. Stored only in the
/// tiles the droplets touch ([`Tiles`]); q = 0 elsewhere. `Default`: the map of no droplets.
#[derive(Default)]
pub struct HeightMap {
    /// Grid indices of the map's cell (0, 0).
    x0: i64,
    y0: i64,
    tiles: Tiles,
    q: Vec<f32>,
}

/// The 3D grid: square cells of `cell` mm from a fixed origin (the same for every layer).
#[derive(Clone, Copy, Debug)]
pub struct Grid3 {
    pub origin: Point,
    pub cell: f64,
}

/// One row of a [`HeightMap`]: its segments' cells in `data`.
#[derive(Clone, Copy)]
struct MapRow<'a> {
    x0: i64,
    segs: &'a [Segment],
    data: &'a [f32],
}

impl<'a> MapRow<'a> {
    const EMPTY: MapRow<'static> = MapRow {
        x0: 0,
        segs: &[],
        data: &[],
    };

    /// The stretch of the row from grid index `ix` on: (grid index of `cells[0]`, cells, grid
    /// index of its last cell); no cells where nothing is stored.
    fn piece(&self, ix: i64) -> (i64, &'a [f32], i64) {
        for s in self.segs {
            let (a, b) = (self.x0 + s.c0 as i64, self.x0 + s.c1 as i64);
            if ix < a {
                return (ix, &[], a - 1);
            }
            if ix < b {
                return (a, &self.data[s.at..s.end()], b - 1);
            }
        }
        (ix, &[], i64::MAX)
    }
}

/// ⌈t⌉ as an integer, as `t.ceil() as i64` gives it (for the finite values used here).
#[inline]
fn ceil_i64(t: f64) -> i64 {
    floor_i64(-t).saturating_neg()
}

impl HeightMap {
    /// The most bytes a map of droplets within a `w` × `h` mm box takes on cells of `cell` mm
    /// (footprint diameter `d`): every tile over the box and its droplets' reach stored, and a
    /// tile more on each side (a box seldom starts at a tile's edge). For
    /// [`crate::analysis::AnalysisGrid::layer_bytes`], before anything is allocated.
    pub fn box_bytes(w: f64, h: f64, cell: f64, d: f64) -> f64 {
        let side = |l: f64, tile: usize| {
            let tile = tile as f64;
            (((l + 2.0 * d) / cell + 2.0) / tile).ceil() * tile + tile
        };
        // An f32 per cell.
        4.0 * side(w, MAP_TILE_COLS) * side(h, MAP_BAND_ROWS)
    }

    /// The map of droplets at `centres` of footprint diameter `d`. Every stored value is the
    /// one `HeightMap::reference` stores (the same expressions, in the same order); the work
    /// saved is around them: each droplet's cells found once, the cells' centres taken from
    /// a table per column and per row, ⌊·⌋ without libm, the rows that miss the droplet
    /// passed over, each cell raised without a branch.
    pub fn new(centres: &[Point], grid: &Grid3, d: f64) -> HeightMap {
        let r = d / 2.0;
        if centres.is_empty() {
            return HeightMap::default();
        }
        let idx = |v: f64, k: usize| floor_i64((v - grid.origin[k]) / grid.cell - 0.5);
        // A droplet's cells [ax, bx] × [ay, by], and the map's bounds.
        let mut min = [i64::MAX; 2];
        let mut max = [i64::MIN; 2];
        let cells: Vec<[i64; 4]> = centres
            .iter()
            .map(|p| {
                let c = [
                    idx(p[0] - r, 0),
                    idx(p[0] + r, 0) + 1,
                    idx(p[1] - r, 1),
                    idx(p[1] + r, 1) + 1,
                ];
                min = [min[0].min(c[0]), min[1].min(c[2])];
                max = [max[0].max(c[1]), max[1].max(c[3])];
                c
            })
            .collect();
        let mut map = HeightMap::zeros(min, max, &cells);
        let (x, y) = (
            |v: i64| (v - min[0]) as usize,
            |v: i64| (v - min[1]) as usize,
        );
        // Cell centres, computed as the reference computes them for each droplet.
        let centre = |i: i64, k: usize| grid.origin[k] + (i as f64 + 0.5) * grid.cell;
        let cx: Vec<f64> = (min[0]..=max[0]).map(|i| centre(i, 0)).collect();
        let cy: Vec<f64> = (min[1]..=max[1]).map(|i| centre(i, 1)).collect();
        let inv = 1.0 / (r * r);
        let mut xx = Vec::new();
        // Where the last droplet row's cells were stored (mostly the next one's too).
        let mut spot: Option<Spot> = None;
        for (p, &[ax, bx, ay, by]) in centres.iter().zip(&cells) {
            let c = x(ax);
            xx.clear();
            xx.extend(cx[c..=x(bx)].iter().map(|&v| {
                let d = v - p[0];
                d * d
            }));
            let k0 = y(ay);
            for (k, &yc) in (k0..).zip(&cy[k0..=y(by)]) {
                let d = yc - p[1];
                let yy = d * d;
                if yy * inv >= 1.0 {
                    // No cell of this row is inside (q ≤ 0 never raises a cell).
                    continue;
                }
                // The larger of the two, stored either way (no branch per cell).
                let row = map.cells_mut(&mut spot, k, c, xx.len());
                for (slot, &x2) in row.iter_mut().zip(&xx) {
                    let v = (1.0 - (x2 + yy) * inv) as f32;
                    *slot = if v > *slot { v } else { *slot };
                }
            }
        }
        map
    }

    /// The map of q = 0 over grid cells `min`..=`max` (x, y) that stores only the tiles of
    /// the droplets' cells `cells` ([ax, bx, ay, by], grid indices): where both builds
    /// ([`HeightMap::new`] and `HeightMap::reference`) start.
    fn zeros(min: [i64; 2], max: [i64; 2], cells: &[[i64; 4]]) -> HeightMap {
        let mut tiles = Tiles::default();
        let (w, h) = (
            (max[0] - min[0] + 1) as usize,
            (max[1] - min[1] + 1) as usize,
        );
        tiles.reset(h, w, MAP_BAND_ROWS, MAP_TILE_COLS);
        for &[ax, bx, ay, by] in cells {
            let (y0, y1) = ((ay - min[1]) as usize, (by - min[1]) as usize);
            tiles.mark(y0, y1, (ax - min[0]) as usize, (bx - min[0]) as usize);
        }
        let q = vec![0f32; tiles.build()];
        HeightMap {
            x0: min[0],
            y0: min[1],
            tiles,
            q,
        }
    }

    /// The stored values of cells c..c + n (n ≥ 1) of row k, counted from the map's cell
    /// (0, 0): cells of one droplet, which [`zeros`](Self::zeros) stored in one segment.
    /// `spot`: where the last were (mostly where these are).
    #[inline(always)]
    fn cells_mut(&mut self, spot: &mut Option<Spot>, k: usize, c: usize, n: usize) -> &mut [f32] {
        let Some(sp) = self.tiles.spot_cached(spot, k, c, c + n - 1) else {
            debug_assert!(false, "droplet outside the map's tiles");
            return &mut [];
        };
        let at = sp.index(k) + c - sp.shift;
        &mut self.q[at..at + n]
    }

    /// Row `iy` (a grid index); empty outside the map.
    fn row(&self, iy: i64) -> MapRow<'_> {
        usize::try_from(iy - self.y0)
            .ok()
            .and_then(|y| self.tiles.row(y))
            .map_or(MapRow::EMPTY, |row| MapRow {
                x0: self.x0,
                segs: row.segs,
                data: &self.q[row.range()],
            })
    }

    /// Cells stored (for tests of the memory it takes).
    pub fn stored_cells(&self) -> usize {
        self.q.len()
    }
}

/// Cells a [`slab_voids`] stretch handles at a time.
const CHUNK: usize = 64;
/// q = 0 for a stretch where a map stores nothing.
static ZEROS: [f32; CHUNK] = [0.0; CHUNK];

/// `n` cells of a row's piece ([`MapRow::piece`]) from grid index `ix` (q = 0 where nothing
/// is stored).
#[inline]
fn cut((x0, row): (i64, &[f32]), ix: i64, n: usize) -> &[f32] {
    if row.is_empty() {
        &ZEROS[..n]
    } else {
        &row[(ix - x0) as usize..][..n]
    }
}

/// The constants of a slab's column fill.
#[derive(Clone, Copy)]
struct Fill {
    /// Layer height H, its half, the spheroid's half-height c.
    h: f64,
    half: f64,
    c: f64,
    /// Above this q a neighbour's droplet reaches into the slab.
    q_reach: f32,
}

impl Fill {
    fn new(s: &Settings) -> Fill {
        let h = s.layer_height;
        let c = spheroid_half_height(s);
        let half = h / 2.0;
        Fill {
            h,
            half,
            c,
            // A neighbour's droplet reaches into this slab where c·√q > H/2.
            q_reach: ((half / c) * (half / c)) as f32,
        }
    }

    /// `filled` plus the filled lengths of the columns `from..=to` of a stretch over which
    /// each map (own, below, above: `pieces`) is one piece ([`MapRow::piece`]), added in the
    /// reference's order, [`CHUNK`] columns at a time through `col`.
    #[inline(always)]
    fn stretch(
        &self,
        pieces: [(i64, &[f32]); 3],
        from: i64,
        to: i64,
        col: &mut [f64; CHUNK],
        mut filled: f64,
    ) -> f64 {
        let [pt, pb, pa] = pieces;
        // No droplet reaches this stretch: its columns are empty (they would add +0).
        let mut ix = if pt.1.is_empty() && pb.1.is_empty() && pa.1.is_empty() {
            to + 1
        } else {
            from
        };
        while ix <= to {
            let n = ((to - ix + 1) as usize).min(CHUNK);
            let (t, b, a) = (cut(pt, ix, n), cut(pb, ix, n), cut(pa, ix, n));
            for (((v, &t), &b), &a) in col[..n].iter_mut().zip(t).zip(b).zip(a) {
                *v = self.column(t, b, a);
            }
            // In the reference's order (an empty column adds +0, which changes nothing),
            // the running sum in a register.
            let mut sum = filled;
            for &v in &col[..n] {
                sum += v;
            }
            filled = sum;
            ix += n as i64;
        }
        filled
    }

    /// The filled length of a cell's column (of height H) given the q of its own layer's map
    /// (`t`) and of the layers below (`b`) and above (`a`): the union of [0, lo] from below,
    /// [H/2 − a, H/2 + a] from its own droplet and [H − hi, H] from above, computed with the
    /// reference's operations in its order (so to the same bits) but without branches, so
    /// that a stretch of cells is computed a few at a time. `x.max(y)` and `x.min(y)` are
    /// written as comparisons: no operand here is NaN or a negative zero, where they could
    /// differ.
    #[inline(always)]
    fn column(&self, t: f32, b: f32, a: f32) -> f64 {
        let (h, half, c) = (self.h, self.half, self.c);
        let max = |x: f64, y: f64| if x > y { x } else { y };
        let min = |x: f64, y: f64| if x < y { x } else { y };
        // The reference: a = 0 for q = 0, which c·√0 gives too.
        let own = min(c * (t as f64).sqrt(), half);
        let ext = |q: f32| {
            let e = max(c * (q as f64).sqrt() - half, 0.0);
            if q > self.q_reach { e } else { 0.0 }
        };
        let lo = min(ext(b), h);
        let hi = min(ext(a), h);
        // [0, lo]: lo ≥ 0, so the union so far is exactly [0, lo].
        let (len, end) = (lo, lo);
        // [m0, m1], when it reaches past the end so far (never when m1 ≤ m0).
        let (m0, m1) = (half - own, half + own);
        let s0 = max(m0, end);
        let take = m1 > s0;
        let (len, end) = if take {
            (len + (m1 - s0), m1)
        } else {
            (len, end)
        };
        // [H − hi, H], likewise.
        let s0 = max(h - hi, end);
        let len = if h > s0 { len + (h - s0) } else { len };
        // The own droplet fills the whole column.
        if own >= half { h } else { len }
    }
}

/// Row `iy` of a slab's three maps: its own layer's and those of the layers below and above
/// (empty where a layer has no map, or the map no row).
struct SlabRow<'a> {
    this: MapRow<'a>,
    below: MapRow<'a>,
    above: MapRow<'a>,
}

impl<'a> SlabRow<'a> {
    /// Row `iy` of the maps [below, own, above].
    fn new(iy: i64, [below, this, above]: [Option<&'a HeightMap>; 3]) -> SlabRow<'a> {
        let row = |m: Option<&'a HeightMap>| m.map_or(MapRow::EMPTY, |m| m.row(iy));
        SlabRow {
            this: row(this),
            below: row(below),
            above: row(above),
        }
    }

    /// From grid index `from` on, each map's piece ([`MapRow::piece`]: own, below, above, as
    /// [`Fill::stretch`] takes them) and the grid index where the first of them ends.
    #[inline]
    fn pieces(&self, from: i64) -> ([(i64, &'a [f32]); 3], i64) {
        let (xt, rt, et) = self.this.piece(from);
        let (xb, rb, eb) = self.below.piece(from);
        let (xa, ra, ea) = self.above.piece(from);
        ([(xt, rt), (xb, rb), (xa, ra)], et.min(eb).min(ea))
    }
}

/// The cells of a slab's region on the grid, span by span: `f(iy, c0, c1)` for the cells
/// c0..=c1 of grid row `iy` whose centres lie in one span of the region (spans holding no
/// centre are passed over). `rows`: the region's [`slab_rows`].
fn slab_cells(
    region: &Shapes,
    grid: &Grid3,
    (k0, ny, y0): (i64, usize, f64),
    mut f: impl FnMut(i64, i64, i64),
) {
    region_spans(region, y0, grid.cell, ny, |k, xa, xb| {
        let c0 = ceil_i64((xa - grid.origin[0]) / grid.cell - 0.5);
        let c1 = floor_i64((xb - grid.origin[0]) / grid.cell - 0.5);
        if c0 <= c1 {
            f(k0 + k as i64, c0, c1);
        }
    });
}

/// The grid rows a slab's region spans: (grid index of the first, how many, its lower edge
/// in mm); `None` for an empty region.
fn slab_rows(region: &Shapes, grid: &Grid3) -> Option<(i64, usize, f64)> {
    let mut ymin = f64::INFINITY;
    let mut ymax = f64::NEG_INFINITY;
    for p in all_contours(region).flatten() {
        ymin = ymin.min(p[1]);
        ymax = ymax.max(p[1]);
    }
    if !ymin.is_finite() {
        return None;
    }
    let k0 = floor_i64((ymin - grid.origin[1]) / grid.cell - 0.5);
    let ny = ((ymax - ymin) / grid.cell).ceil() as usize + 2;
    Some((k0, ny, grid.origin[1] + k0 as f64 * grid.cell))
}

/// The 3D estimate for layer i's slab: (volume, void volume) in mm³ of its region × H, filled
/// by the spheroids of layers i − 1 (`below`), i and i + 1 (`above`). The figures are those of
/// `slab_voids_reference` to the bit: the same cells, each column's fill computed with the
/// same operations ([`Fill::column`]) and summed in the same order; the stretches of a row's
/// span are computed a chunk at a time without branches, and the maps' rows found once per
/// stretch instead of per cell.
pub fn slab_voids(
    region: &Shapes,
    grid: &Grid3,
    below: Option<&HeightMap>,
    this: &HeightMap,
    above: Option<&HeightMap>,
    s: &Settings,
) -> (f64, f64) {
    let fill = Fill::new(s);
    let Some(rows) = slab_rows(region, grid) else {
        return (0.0, 0.0);
    };
    let (mut cells, mut filled) = (0u64, 0.0f64);
    let mut col = [0f64; CHUNK];
    slab_cells(region, grid, rows, |iy, c0, c1| {
        let maps = SlabRow::new(iy, [below, Some(this), above]);
        // Stretches of the span over which each map is one slice (or nothing).
        let mut from = c0;
        while from <= c1 {
            let (pieces, end) = maps.pieces(from);
            let to = c1.min(end);
            cells += (to - from + 1) as u64;
            filled = fill.stretch(pieces, from, to, &mut col, filled);
            from = to + 1;
        }
    });
    let area = grid.cell * grid.cell;
    let volume = cells as f64 * area * fill.h;
    (volume, (volume - filled * area).max(0.0))
}
