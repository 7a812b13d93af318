//! The banded raster of `--report`: a layer rasterised only in a band around its boundary;
//! the interior (blocks of 16 rows × 64 columns, 1.6 B square, at least the band's width from
//! the boundary), where the droplets are the fill's regular lines, is not rasterised but
//! counted: its cells, its droplets' cells, and its voids at the rate of the job's
//! calibration ([`crate::analysis::InteriorRates`]). The interior blocks inside the stored
//! tiles are stored as covered region, so the band's voids end at the interior as at droplets
//! (they are neither cut open nor taken for the boundary).

use super::build::{Prep, Store, widen};
use super::{Grid, Raster};
use crate::analysis::lines::{DropletLines, SkipGrid};
use crate::base::geom::{Point, Shapes, dist};
use crate::base::settings::{Footprint, Settings};

/// Rows of a block; a block is one word (64 columns) wide.
const BLOCK_ROWS: usize = 16;
const BLOCK_COLS: usize = 64;
/// Blocks per storage tile, down and across (tiles of 32 rows × 2 words: a band stored
/// with less of the interior around it than the whole raster's tiles would).
const TILE_BLOCK_ROWS: usize = 2;
const TILE_BLOCK_COLS: usize = 2;

/// What a banded rebuild left out of the bitmaps and counted instead, in grid cells.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Banding {
    /// Cells of the interior blocks (all in the region).
    pub(super) interior_cells: u64,
    /// Cells of the interior blocks stored as covered region (counted by the labelling).
    pub(super) stored_interior_cells: u64,
    /// The droplets' cells in interior blocks (the discs do not overlap: see
    /// [`Raster::can_band`]).
    pub(super) interior_drop_cells: u64,
    /// Voids per interior cell (the job's calibration).
    pub(super) void_rate: f64,
}

/// At most this many blocks over a layer's box (else it is rasterised whole).
const MAX_BLOCKS: usize = 4_000_000;

/// A block's kind.
const OUTSIDE: u8 = 0;
const BAND: u8 = 1;
const INTERIOR: u8 = 2;

/// A `w` × `h` grid of `flags` (row by row) dilated by `r` places along both axes (a square
/// of 2r + 1): the band's blocks here and in the 3D estimate's. Counts of the flags in a
/// window sliding along each row, then (row by row, a count per column) down the columns.
pub(in crate::analysis) fn dilate2(flags: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    if w == 0 || h == 0 {
        return vec![false; flags.len()];
    }
    let mut across = vec![0u32; flags.len()];
    for (f, o) in flags.chunks_exact(w).zip(across.chunks_exact_mut(w)) {
        let mut n: u32 = f[..r.min(w)].iter().map(|&x| x as u32).sum();
        for (i, o) in o.iter_mut().enumerate() {
            if i + r < w {
                n += f[i + r] as u32;
            }
            *o = (n > 0) as u32;
            if i >= r {
                n -= f[i - r] as u32;
            }
        }
    }
    let mut out = vec![false; flags.len()];
    let mut count = vec![0u32; w];
    for row in across.chunks_exact(w).take(r.min(h)) {
        count.iter_mut().zip(row).for_each(|(c, &x)| *c += x);
    }
    for k in 0..h {
        if k + r < h {
            let row = &across[(k + r) * w..(k + r + 1) * w];
            count.iter_mut().zip(row).for_each(|(c, &x)| *c += x);
        }
        let o = &mut out[k * w..(k + 1) * w];
        o.iter_mut().zip(&count).for_each(|(o, &c)| *o = c > 0);
        if k >= r {
            let row = &across[(k - r) * w..(k - r + 1) * w];
            count.iter_mut().zip(row).for_each(|(c, &x)| *c -= x);
        }
    }
    out
}

impl Store<'_> {
    /// Sets grid columns c0..=c1 of row `k` in `bits` where they are stored (any segments).
    fn set_stored(&mut self, bits: &mut [u64], k: usize, c0: usize, c1: usize) {
        if let Some(sp) = self.spot
            && sp.holds(k, c0 >> 6, c1 >> 6)
        {
            return self.set_cols(bits, k, c0, c1);
        }
        let Some(row) = self.tiles.row(k) else { return };
        for seg in row.segs {
            let (a, b) = ((c0 >> 6).max(seg.c0), ((c1 >> 6) + 1).min(seg.c1));
            if a < b {
                let (x0, x1) = (c0.max(64 * a), c1.min(64 * b - 1));
                self.set_cols(bits, k, x0, x1);
            }
        }
    }
}

impl Raster {
    /// Grid cells of the interior a banded rebuild counted instead of rasterising (0 after
    /// a whole one).
    pub fn interior_cells(&self) -> u64 {
        self.banding.map_or(0, |b| b.interior_cells)
    }

    /// Whether a layer sliced with `s` can be banded: each droplet a disc of diameter B, the
    /// fill's lines B apart, so that no two droplets of the interior overlap (their cells
    /// add up) and its voids are the small gaps between them. Otherwise (`spread`, a fill
    /// density other than 1: overlapping discs, or channels along the lines as long as the
    /// part) [`rebuild_banded`](Self::rebuild_banded) rasterises the whole layer.
    pub fn can_band(s: &Settings) -> bool {
        s.footprint == Footprint::Disc && s.fill_density == 1.0
    }

    /// [`rebuild`](Self::rebuild), rasterising only the band of about `width` mm around the
    /// region's boundary (where the contours, the hatch ends and the gaps between them are);
    /// the interior's cells and its droplets' are counted, and its voids estimated at
    /// `void_rate` per cell. [`analysis`](Self::analysis) then gives the layer's figures with
    /// the interior's added: coverage, void and enclosed areas as counted; the void count
    /// estimated; the largest void, the overfill and the boundary deviation the band's.
    ///
    /// The droplets come as their lines ([`DropletLines`]): those deep in the interior (2
    /// blocks or more from any block not in it) are counted a stretch of a line at a time
    /// and take the cells of an average droplet; the others are placed one by one.
    #[allow(clippy::too_many_arguments)]
    pub fn rebuild_banded(
        &mut self,
        index: usize,
        z: f64,
        lines: &DropletLines,
        region: &Shapes,
        s: &Settings,
        width: f64,
        void_rate: f64,
    ) {
        let whole = |r: &mut Raster| r.rebuild(index, z, &lines.centres(), region, s);
        if !Raster::can_band(s) {
            return whole(self);
        }
        let prep = self.prepare_grid(lines.bounds(), region, s);
        let g = prep.grid;
        if g.ny.div_ceil(BLOCK_ROWS).saturating_mul(g.nx.div_ceil(64)) > MAX_BLOCKS {
            // Parts far apart in one layer: its sparse tiles, not a dense map of blocks.
            return whole(self);
        }
        let kind = self.blocks(&prep.grid, width);
        self.tiles.reset(
            g.ny,
            g.nx.div_ceil(64),
            BLOCK_ROWS * TILE_BLOCK_ROWS,
            BLOCK_COLS / 64 * TILE_BLOCK_COLS,
        );
        let (nc, nr) = (g.nx.div_ceil(64), g.ny.div_ceil(BLOCK_ROWS));
        let skip = SkipGrid::new(
            Point::new(g.x0, g.y0),
            Point::new(BLOCK_COLS as f64 * g.gx, BLOCK_ROWS as f64 * g.gy),
            (0, 0),
            (nc, nr),
            |i| kind[i] == INTERIOR,
        );
        let places = &mut self.places;
        let passed = skip.walk(lines, |p| places.push(prep.place(p)));
        let mut banding = self.set_banded(&prep, &kind, void_rate);
        // The droplets passed over: the cells of an average droplet each (a droplet covers
        // its disc's area within half a cell wherever it lies).
        let mean = prep
            .spans
            .iter()
            .map(|&(n, _)| n.max(0) as f64)
            .sum::<f64>()
            / prep.widest.len().max(1) as f64;
        banding.interior_drop_cells += (passed as f64 * mean).round() as u64;
        self.finish(index, z, lines.count() as usize, region, s, prep.grid);
        self.banding = Some(banding);
    }

    /// Each block's kind: in the band (within about `width` of an edge), in the interior (in
    /// the region, beyond the band) or outside.
    fn blocks(&self, grid: &Grid, width: f64) -> Vec<u8> {
        let nw = grid.nx.div_ceil(64);
        let (nr, nc) = (grid.ny.div_ceil(BLOCK_ROWS), nw);
        let (bh, bw) = (BLOCK_ROWS as f64 * grid.gy, BLOCK_COLS as f64 * grid.gx);
        let mut edge = vec![false; nr * nc];
        let block = |p: Point| {
            let (r, c) = (
                ((p[1] - grid.y0) / bh).floor(),
                ((p[0] - grid.x0) / bw).floor(),
            );
            (r >= 0.0 && c >= 0.0 && r < nr as f64 && c < nc as f64)
                .then(|| r as usize * nc + c as usize)
        };
        // Points along each edge a quarter of a block apart: every block it crosses but
        // across a corner, which the band around its neighbours holds.
        let step = 0.25 * bh.min(bw);
        for &(a, b) in &self.edges {
            let n = (dist(a, b) / step).ceil().clamp(1.0, 1e9) as usize;
            for i in 0..=n {
                if let Some(i) = block(a + (b - a) * (i as f64 / n as f64)) {
                    edge[i] = true;
                }
            }
        }
        let r = (width / bh.min(bw)).ceil().max(1.0) as usize;
        let band = dilate2(&edge, nc, nr, r);
        let mut kind: Vec<u8> = band
            .iter()
            .map(|&b| if b { BAND } else { OUTSIDE })
            .collect();
        // A block beyond the band is inside the region when its middle is.
        for &(k, c0, c1) in &self.spans {
            let k = k as usize;
            let br = k / BLOCK_ROWS;
            if k != (br * BLOCK_ROWS + BLOCK_ROWS / 2).min(grid.ny - 1) {
                continue;
            }
            let half = BLOCK_COLS as i64 / 2;
            let first = (c0 as i64 - half + BLOCK_COLS as i64 - 1).div_euclid(BLOCK_COLS as i64);
            let last = (c1 as i64 - half).div_euclid(BLOCK_COLS as i64);
            for bc in first.max(0)..=last.min(nc as i64 - 1) {
                let i = br * nc + bc as usize;
                if kind[i] == OUTSIDE {
                    kind[i] = INTERIOR;
                }
            }
        }
        kind
    }

    /// Marks the tiles (those holding band blocks and their neighbours), then sets the region's
    /// and the droplets' bits in the band, and the interior blocks of the stored tiles as
    /// covered region; counts the interior.
    fn set_banded(&mut self, prep: &Prep, kind: &[u8], void_rate: f64) -> Banding {
        let Prep {
            grid,
            rows,
            ref spans,
            ref widest,
            ..
        } = *prep;
        let (nx, ny) = (grid.nx, grid.ny);
        let nc = nx.div_ceil(64);
        let nr = ny.div_ceil(BLOCK_ROWS);
        let (tr, tc) = (nr.div_ceil(TILE_BLOCK_ROWS), nc.div_ceil(TILE_BLOCK_COLS));
        // The tiles holding band blocks, or interior blocks next to one (which the band's
        // voids must find covered, not outside the region).
        let band: Vec<bool> = kind.iter().map(|&k| k == BAND).collect();
        let near = dilate2(&band, nc, nr, 1);
        let mut stored = vec![false; tr * tc];
        for (i, (&k, &near)) in kind.iter().zip(&near).enumerate() {
            if k == BAND || (k == INTERIOR && near) {
                stored[(i / nc) / TILE_BLOCK_ROWS * tc + (i % nc) / TILE_BLOCK_COLS] = true;
            }
        }
        let tiles = &mut self.tiles;
        for (t, _) in stored.iter().enumerate().filter(|(_, s)| **s) {
            let (r0, w0) = (
                (t / tc) * BLOCK_ROWS * TILE_BLOCK_ROWS,
                (t % tc) * TILE_BLOCK_COLS,
            );
            tiles.mark(
                r0,
                r0 + BLOCK_ROWS * TILE_BLOCK_ROWS - 1,
                w0,
                w0 + TILE_BLOCK_COLS - 1,
            );
        }
        self.allocate();
        let interior = |k: usize, w: usize| kind[(k / BLOCK_ROWS) * nc + w] == INTERIOR;
        debug_assert!(rows <= BLOCK_ROWS + 1 && widest.iter().all(|w| w.0 < 64));
        let mut out = Banding {
            void_rate,
            interior_cells: (kind.iter().filter(|&&k| k == INTERIOR).count()
                * BLOCK_ROWS
                * BLOCK_COLS) as u64,
            ..Banding::default()
        };
        let (region_bits, drop_bits) = (&mut self.region_bits, &mut self.drop_bits);
        let mut store = Store::new(&self.tiles, &mut self.extent);
        // Per block row, its runs of interior blocks [first, last].
        let runs: Vec<Vec<(usize, usize)>> = kind
            .chunks(nc)
            .map(|row| {
                let mut out: Vec<(usize, usize)> = Vec::new();
                for (w, _) in row.iter().enumerate().filter(|(_, k)| **k == INTERIOR) {
                    match out.last_mut() {
                        Some(r) if r.1 + 1 == w => r.1 = w,
                        _ => out.push((w, w)),
                    }
                }
                out
            })
            .collect();
        // The region in the band: each span but its stretches over interior blocks.
        for &(k, c0, c1) in self.spans.iter() {
            let (k, c0, c1) = (k as usize, c0 as usize, c1 as usize);
            let row = &runs[k / BLOCK_ROWS];
            let mut i = row.partition_point(|r| r.1 < c0 >> 6);
            let mut from = c0;
            while from <= c1 {
                match row.get(i) {
                    Some(&(a, e)) if 64 * a <= c1 => {
                        if from < 64 * a {
                            store.set_stored(region_bits, k, from, 64 * a - 1);
                        }
                        from = from.max(64 * (e + 1));
                        i += 1;
                    }
                    _ => {
                        store.set_stored(region_bits, k, from, c1);
                        break;
                    }
                }
            }
        }
        // The interior blocks of the stored tiles, as covered region.
        let tiles = store.tiles;
        for (bi, band) in tiles.bands().iter().enumerate() {
            for seg in tiles.segments(band) {
                for w in seg.c0..seg.c1 {
                    let at = w - seg.shift();
                    for k0 in (band.first_row..band.end_row).step_by(BLOCK_ROWS) {
                        if !interior(k0, w) {
                            continue;
                        }
                        for k in k0..(k0 + BLOCK_ROWS).min(band.end_row) {
                            let i = band.offset + (k - band.first_row) * band.row_len + at;
                            region_bits[i] = !0;
                            drop_bits[i] = !0;
                            let e = &mut store.extent[bi * tiles.band_rows() + k - band.first_row];
                            widen(e, 64 * at, 64 * at + 63);
                            out.stored_interior_cells += BLOCK_COLS as u64;
                        }
                    }
                }
            }
        }
        // The droplets: those touching the band rasterised (their cells in the interior
        // counted), the others counted.
        let cells_of: Vec<u64> = spans
            .chunks(rows)
            .map(|c| c.iter().map(|&(n, _)| n.max(0) as u64).sum())
            .collect();
        for &place in self.places.iter() {
            let d = prep.droplet(place);
            // Whether it lies in the grid and in blocks of kind `want` only (it spans at
            // most two blocks each way: 12 rows, 41 columns).
            let within = |want: u8| {
                d.in_grid(&grid) && {
                    let (r0, r1) = (d.k0 / BLOCK_ROWS * nc, d.k1 / BLOCK_ROWS * nc);
                    let (w0, w1) = (d.c0 as usize >> 6, d.c1 as usize >> 6);
                    [r0 + w0, r0 + w1, r1 + w0, r1 + w1]
                        .iter()
                        .all(|&i| kind[i] == want)
                }
            };
            if within(INTERIOR) {
                out.interior_drop_cells += cells_of[d.ph];
                continue;
            }
            // Wholly in band blocks (stored), mostly in one band and segment of the storage.
            if within(BAND) && d.set_in_one_segment(&mut store, drop_bits) {
                continue;
            }
            for (k, c0, c1) in d.rows_in(&grid) {
                store.set_stored(drop_bits, k, c0, c1);
                for w in c0 >> 6..=c1 >> 6 {
                    if interior(k, w) {
                        let (a, b) = (c0.max(64 * w), c1.min(64 * w + 63));
                        out.interior_drop_cells += (b - a + 1) as u64;
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::dilate2;

    #[test]
    fn dilation_is_the_square_around_each_flag() {
        let mut random = crate::base::testing::rng(0x9e37_79b9_7f4a_7c15u64);
        for case in 0..400 {
            let (w, h, r) = (1 + case % 13, 1 + case / 13 % 11, case / 7 % 5);
            let density = [0.02, 0.1, 0.5][case % 3];
            let flags: Vec<bool> = (0..w * h).map(|_| random() < density).collect();
            let want: Vec<bool> = (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as i64, (i / w) as i64);
                    (0..w * h).any(|j| {
                        let (a, b) = ((j % w) as i64, (j / w) as i64);
                        flags[j] && (a - x).abs() <= r as i64 && (b - y).abs() <= r as i64
                    })
                })
                .collect();
            assert_eq!(
                dilate2(&flags, w, h, r),
                want,
                "case {case}: {w} × {h}, r {r}"
            );
        }
    }
}
