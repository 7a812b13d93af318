//! The coverage mask: per square cell of the page's overlay, the shares of void, overfill and
//! covered region.

use super::{COLS_PER_ROW, CellRect, CoverageMask, MaskTile, Raster, count_range, window};
use crate::base::geom::DVec2;

/// Mask cells of at most this many grid rows are counted by 4-bit groups
/// ([`Raster::count_by_nibbles`]).
const NIBBLE_ROWS: usize = 3;
/// Mask rows per band of a [`CoverageMask`]'s tiles.
const MASK_BAND_ROWS: usize = 64;

impl Raster {
    /// A [`CoverageMask`] with square cells of about `cell` mm, in tiles over the raster's.
    pub fn mask(&self, cell: f64) -> CoverageMask {
        self.mask_with(cell, true)
    }

    /// [`mask`](Self::mask) with only the void and overfill shares, what the page draws: its
    /// tiles' `covered` are empty (a third less to count).
    pub fn page_mask(&self, cell: f64) -> CoverageMask {
        self.mask_with(cell, false)
    }

    /// Each mask cell's counts [void, overfill, covered] (per tile of `out`, `groups` the
    /// tiles of each mask band), added cell by cell in each grid row: `count(region words,
    /// droplet words, c0, c1)` counts columns c0..=c1 of a row (its slice's columns).
    pub(super) fn count_cell_by_cell(
        &self,
        rows: usize,
        out: &[MaskTile],
        groups: &[(usize, std::ops::Range<usize>)],
        mut count: impl FnMut(&[u64], &[u64], usize, usize) -> [u32; 3],
    ) -> Vec<Vec<[u32; 3]>> {
        let g = self.grid;
        let cols = rows * COLS_PER_ROW as usize;
        let mut counts: Vec<Vec<[u32; 3]>> =
            out.iter().map(|t| vec![[0; 3]; t.rect.cells()]).collect();
        let mut group = 0;
        for (k, row, lo, hi) in self.filled_rows() {
            let my = k / rows;
            while groups[group].0 < my / MASK_BAND_ROWS {
                group += 1;
            }
            let (r, d) = (&self.region_bits[row.range()], &self.drop_bits[row.range()]);
            let mut t = groups[group].1.start;
            for seg in row.segs {
                let (a, e) = (seg.at.max(lo), seg.end().min(hi));
                if a >= e {
                    continue;
                }
                // Grid columns [gc0, gc1] of the segment's bits; column c at c − shift.
                let shift = 64 * seg.shift();
                let (gc0, gc1) = (64 * a + shift, (64 * e + shift).min(g.nx) - 1);
                for cx in gc0 / cols..=gc1 / cols {
                    let (c0, c1) = ((cx * cols).max(gc0), ((cx + 1) * cols - 1).min(gc1));
                    while out[t].rect.end_col() <= cx {
                        t += 1;
                    }
                    let slot = &mut counts[t][out[t].rect.index(cx, my)];
                    let add = count(r, d, c0 - shift, c1 - shift);
                    for (s, a) in slot.iter_mut().zip(add) {
                        *s += a;
                    }
                }
            }
        }
        counts
    }

    /// The words of the widest stored row.
    pub(super) fn widest_row(&self) -> usize {
        let bands = self.tiles.bands();
        bands.iter().map(|b| b.row_len).max().unwrap_or(0)
    }

    /// [`count_cell_by_cell`](Self::count_cell_by_cell) for cells of at most [`NIBBLE_ROWS`] rows
    /// (the page's cells of B/4): a cell is `rows` × 4·`rows` columns, so its columns are
    /// whole 4-bit groups of the words, and a cell's bits in one row count at most 4 per
    /// group. Each grid row adds the bit counts of its 4-bit groups (SWAR, a word at a time)
    /// into the mask row's words, at most 4·`rows` ≤ 15 per group; when the mask row is
    /// done, each cell sums its `rows` groups. Counts identical, per cell once a mask row.
    ///
    /// `N` = 3 counts void, overfill and covered; `N` = 2 only void and overfill (the page's
    /// mask, [`page_mask`](Self::page_mask)).
    fn count_by_nibbles<const N: usize>(
        &self,
        rows: usize,
        out: &mut [MaskTile],
        groups: &[(usize, std::ops::Range<usize>)],
        table: &[u8],
    ) {
        debug_assert!((1..=NIBBLE_ROWS).contains(&rows));
        // Grid words [first, end) under tile t's cells: its 4-bit groups are
        // [col·rows, (col + width)·rows).
        let words = |t: &MaskTile| {
            let r = t.rect;
            (r.col * rows / 16, (r.end_col() * rows).div_ceil(16))
        };
        // Per grid word under the current mask band's tiles (tile by tile, `at[t]` where tile
        // t's words start), the 4-bit counts of void, overfill, covered: memory for the
        // tiles, not for the grid's width.
        let mut acc: Vec<[u64; N]> = Vec::new();
        let mut at: Vec<usize> = Vec::new();
        // The current band's tiles' words [first, end).
        let mut spans: Vec<(usize, usize)> = Vec::new();
        let nibbles = |x: u64| {
            let x = x - ((x >> 1) & 0x5555_5555_5555_5555);
            (x & 0x3333_3333_3333_3333) + ((x >> 2) & 0x3333_3333_3333_3333)
        };
        // The cells of mask row `my` (tiles `range`, their words `spans`) from `acc`, their
        // shares (`table`: per count) into the tiles, then `acc` cleared: each tile's 4-bit
        // groups read in order along its words, `rows` of them per cell.
        let flush = |my: usize,
                     range: std::ops::Range<usize>,
                     acc: &mut [[u64; N]],
                     at: &[usize],
                     spans: &[(usize, usize)],
                     out: &mut [MaskTile]| {
            for ((t, &base_at), &(w0, w1)) in range.zip(at).zip(spans) {
                let tile = &mut out[t];
                let mine = &acc[base_at..base_at + (w1 - w0)];
                let base = tile.rect.index(tile.rect.col, my);
                // The tile's first group is (col·rows) mod 16 of its first word.
                let (mut w, mut sh) = (0, 4 * ((tile.rect.col * rows) & 15));
                let mut a = mine.first().copied().unwrap_or([0; N]);
                for i in base..base + tile.rect.width {
                    let mut sum = [0usize; N];
                    for _ in 0..rows {
                        for c in 0..N {
                            sum[c] += ((a[c] >> sh) & 15) as usize;
                        }
                        sh += 4;
                        if sh == 64 {
                            sh = 0;
                            w += 1;
                            a = mine.get(w).copied().unwrap_or([0; N]);
                        }
                    }
                    tile.void[i] = table[sum[0]];
                    tile.overfill[i] = table[sum[1]];
                    if N == 3 {
                        tile.covered[i] = table[sum[N - 1]];
                    }
                }
            }
            acc.fill([0; N]);
        };
        // The mask row being summed and its band's tiles.
        let mut current: Option<(usize, std::ops::Range<usize>)> = None;
        // The tiles `acc` is laid out for.
        let mut laid: Option<std::ops::Range<usize>> = None;
        let mut group = 0;
        for (k, row, lo, hi) in self.filled_rows() {
            let my = k / rows;
            if current.as_ref().is_none_or(|c| c.0 != my) {
                if let Some((c, range)) = current.take() {
                    flush(c, range, &mut acc, &at, &spans, out);
                }
                while groups[group].0 < my / MASK_BAND_ROWS {
                    group += 1;
                }
                let range = groups[group].1.clone();
                if laid.as_ref() != Some(&range) {
                    at.clear();
                    spans.clear();
                    let mut n = 0;
                    for t in &out[range.clone()] {
                        at.push(n);
                        let (w0, w1) = words(t);
                        spans.push((w0, w1));
                        n += w1 - w0;
                    }
                    acc.clear();
                    acc.resize(n, [0; N]);
                    laid = Some(range.clone());
                }
                current = Some((my, range));
            }
            let range = current.as_ref().map_or(0..0, |c| c.1.clone());
            let (r, d) = (&self.region_bits[row.range()], &self.drop_bits[row.range()]);
            // The tiles' word ranges are in order along the row, as the words are.
            let mut t = range.start;
            for seg in row.segs {
                let (a, e) = (seg.at.max(lo), seg.end().min(hi));
                let shift = seg.shift();
                for w in a..e {
                    let (rw, dw) = (r[w], d[w]);
                    if rw | dw == 0 {
                        continue;
                    }
                    let gw = w + shift;
                    while t < range.end && spans[t - range.start].1 <= gw {
                        t += 1;
                    }
                    let add: [u64; N] = std::array::from_fn(|c| match c {
                        0 => nibbles(rw & !dw),
                        1 => nibbles(dw & !rw),
                        _ => nibbles(rw & dw),
                    });
                    // Every tile whose words hold word gw (two when they are closer
                    // than a word); a set bit always lies under a tile.
                    let mut u = t;
                    while u < range.end && spans[u - range.start].0 <= gw {
                        let i = u - range.start;
                        let x = &mut acc[at[i] + gw - spans[i].0];
                        for (x, a) in x.iter_mut().zip(add) {
                            *x += a;
                        }
                        u += 1;
                    }
                    debug_assert!(u > t, "mask bits outside the mask's tiles");
                }
            }
        }
        if let Some((c, range)) = current {
            flush(c, range, &mut acc, &at, &spans, out);
        }
    }

    /// The mask's cells in grid rows (a cell of about `cell` mm), its tiles (their shares
    /// empty) and per mask band the range of its tiles.
    pub(super) fn mask_tiles(&self, cell: f64) -> MaskLayout {
        let g = self.grid;
        let tiles = &self.tiles;
        let rows = ((cell / g.gy).round() as usize).max(1);
        let cols = rows * COLS_PER_ROW as usize;
        let height = g.ny.div_ceil(rows);
        // In each band of MASK_BAND_ROWS mask rows, the mask columns over the raster's segments
        // in those rows, merged: (mask band, first column, last column).
        let mut spans = Vec::new();
        for band in tiles.bands() {
            let mb0 = band.first_row / rows / MASK_BAND_ROWS;
            let mb1 = (band.end_row - 1) / rows / MASK_BAND_ROWS;
            for seg in tiles.segments(band) {
                let (c0, c1) = (64 * seg.c0 / cols, ((64 * seg.c1).min(g.nx) - 1) / cols);
                spans.extend((mb0..=mb1).map(|mb| (mb, c0, c1)));
            }
        }
        spans.sort_unstable();
        // The tiles, and per mask band the range of its tiles.
        let mut out: Vec<MaskTile> = Vec::new();
        let mut groups: Vec<(usize, std::ops::Range<usize>)> = Vec::new();
        let mut i = 0;
        while i < spans.len() {
            let mb = spans[i].0;
            let first = out.len();
            while i < spans.len() && spans[i].0 == mb {
                let (_, c0, mut c1) = spans[i];
                i += 1;
                while i < spans.len() && spans[i].0 == mb && spans[i].1 <= c1 + 1 {
                    c1 = c1.max(spans[i].2);
                    i += 1;
                }
                let row = mb * MASK_BAND_ROWS;
                out.push(MaskTile {
                    rect: CellRect {
                        col: c0,
                        row,
                        width: c1 - c0 + 1,
                        height: MASK_BAND_ROWS.min(height - row),
                    },
                    ..MaskTile::default()
                });
            }
            groups.push((mb, first..out.len()));
        }
        MaskLayout {
            rows,
            tiles: out,
            groups,
        }
    }

    /// A [`CoverageMask`] with square cells of about `cell` mm, with the covered shares if
    /// `covered`.
    fn mask_with(&self, cell: f64, covered: bool) -> CoverageMask {
        let MaskLayout {
            rows,
            tiles: mut out,
            groups,
        } = self.mask_tiles(cell);
        let full = rows * rows * COLS_PER_ROW as usize;
        // The shares of every count a cell can hold, when there are not too many.
        let table: Vec<u8> = if full > 1 << 16 {
            Vec::new()
        } else {
            (0..=full as u32).map(|n| share_of(n, full)).collect()
        };
        if rows <= NIBBLE_ROWS {
            // The shares written as each mask row is summed (every cell is, once).
            for t in &mut out {
                let n = t.rect.cells();
                t.void = vec![0; n];
                t.overfill = vec![0; n];
                if covered {
                    t.covered = vec![0; n];
                }
            }
            if covered {
                self.count_by_nibbles::<3>(rows, &mut out, &groups, &table);
            } else {
                self.count_by_nibbles::<2>(rows, &mut out, &groups, &table);
            }
        } else {
            let mut ranges = RangeCounts::new(self.widest_row());
            let counts = self.count_cell_by_cell(rows, &out, &groups, |r, d, c0, c1| {
                if c1 - c0 < 64 {
                    // The cell's bits of both rows in one word each.
                    let (rw, dw) = (window(r, c0, c1), window(d, c0, c1));
                    [
                        (rw & !dw).count_ones(),
                        (dw & !rw).count_ones(),
                        (rw & dw).count_ones(),
                    ]
                } else {
                    ranges.count(r, d, c0, c1)
                }
            });
            set_shares(&mut out, &counts, &table, full, covered);
        }
        self.mask_of(rows, out)
    }

    /// The mask of `tiles`, cells of `rows` grid rows.
    pub(super) fn mask_of(&self, rows: usize, tiles: Vec<MaskTile>) -> CoverageMask {
        let g = self.grid;
        CoverageMask {
            origin: DVec2::new(g.x0, g.y0),
            cell: rows as f64 * g.gy,
            tiles,
        }
    }
}

/// The layout of a [`CoverageMask`]: its cells in grid rows, its tiles (shares empty) and per
/// mask band (of [`MASK_BAND_ROWS`] mask rows) the range of its tiles.
pub(super) struct MaskLayout {
    pub(super) rows: usize,
    pub(super) tiles: Vec<MaskTile>,
    pub(super) groups: Vec<(usize, std::ops::Range<usize>)>,
}

/// The share (0 … 255) of a cell of `full` grid cells that `n` of them make.
pub(super) fn share_of(n: u32, full: usize) -> u8 {
    ((n as f64 / full as f64) * 255.0).round().min(255.0) as u8
}

/// Sets the tiles' shares from their cells' `counts` (`table`: the share of each count, where
/// it has one; a cell of `full` grid cells).
pub(super) fn set_shares(
    out: &mut [MaskTile],
    counts: &[Vec<[u32; 3]>],
    table: &[u8],
    full: usize,
    covered: bool,
) {
    let share = |n: u32| match table.get(n as usize) {
        Some(&v) => v,
        None => share_of(n, full),
    };
    for (tile, counts) in out.iter_mut().zip(counts) {
        tile.void = counts.iter().map(|c| share(c[0])).collect();
        tile.overfill = counts.iter().map(|c| share(c[1])).collect();
        if covered {
            tile.covered = counts.iter().map(|c| share(c[2])).collect();
        }
    }
}

/// Counts a row's void, overfill and covered bits over a range of columns, word by word.
pub(super) struct RangeCounts {
    void: Vec<u64>,
    over: Vec<u64>,
    cov: Vec<u64>,
}

impl RangeCounts {
    /// For rows of at most `words` words.
    pub(super) fn new(words: usize) -> RangeCounts {
        RangeCounts {
            void: vec![0; words],
            over: vec![0; words],
            cov: vec![0; words],
        }
    }

    /// [void, overfill, covered] of columns c0..=c1 of a row's region words `r` and droplet
    /// words `d`.
    pub(super) fn count(&mut self, r: &[u64], d: &[u64], c0: usize, c1: usize) -> [u32; 3] {
        for w in c0 >> 6..=c1 >> 6 {
            self.void[w] = r[w] & !d[w];
            self.over[w] = d[w] & !r[w];
            self.cov[w] = d[w] & r[w];
        }
        [
            count_range(&self.void, c0, c1),
            count_range(&self.over, c0, c1),
            count_range(&self.cov, c0, c1),
        ]
    }
}
