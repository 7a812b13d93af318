//! The labelling and the mask counts as they were before the fast paths, kept as the
//! reference tests/analysis_fast.rs compares them with (and examples/analysis_profile.rs times
//! them against). Built for tests and with the `reference` feature only.

use super::mask::{MaskLayout, RangeCounts, set_shares};
use super::voids::{Acc, CellCounts, Deviation, Voids, find, interior, probe};
use super::{
    COLS_PER_ROW, CoverageMask, Grid, LayerAnalysis, MIN_PASSAGE_COLS, Raster, Void, count_range,
};
use crate::base::spatial::{EdgeIndex, Row};

impl Raster {
    /// [`analysis`](Self::analysis) as it was before the fast paths (for tests comparing both).
    #[doc(hidden)]
    pub fn analysis_reference(&self) -> LayerAnalysis {
        self.analysis_with(|index, counts| {
            self.count_cells(counts);
            self.voids_reference(index)
        })
    }

    /// Counts the cells into `tally` (the reference's pass; the fast path counts them as it
    /// labels).
    fn count_cells(&self, tally: &mut CellCounts) {
        let counts = &mut tally.cells;
        for (k, row, lo, hi) in self.filled_rows() {
            let range = row.offset + lo..row.offset + hi;
            let before = counts[2];
            for (r, d) in self.region_bits[range.clone()]
                .iter()
                .zip(&self.drop_bits[range])
            {
                counts[0] += r.count_ones() as u64;
                counts[1] += (r & d).count_ones() as u64;
                counts[2] += (d & !r).count_ones() as u64;
            }
            if counts[2] > before {
                tally.over_rows.push(k);
            }
        }
    }

    /// Sets `edge` to the cells of row `k` (laid out as `row`) in the region with a
    /// neighbour (left, right, above, below) outside it, over the row's extent.
    fn edge_row(
        &self,
        row: &Row,
        k: usize,
        edge: &mut [u64],
        up_buf: &mut Vec<u64>,
        down_buf: &mut Vec<u64>,
    ) {
        let (lo, hi) = self.extent[row.slot];
        let bits = &self.region_bits[row.range()];
        let (up, down) = self.neighbour_rows(row, k, (up_buf, down_buf));
        for seg in row.segs {
            let end = seg.end();
            for w in seg.at.max(lo as usize)..end.min(hi as usize) {
                edge[w] = bits[w] & !interior(bits, w, seg.at, end, up, down);
            }
        }
    }

    /// The voids by one union-find node per void run, components summed after the
    /// labelling (the labelling as it was before the fast path, for tests comparing both).
    fn voids_reference(&self, index: &EdgeIndex) -> Voids {
        let g = self.grid;
        let tiles = &self.tiles;
        // Voids: runs of region & !droplets, joined across rows.
        let mut runs: Vec<(u32, u32, u32)> = Vec::new(); // (row, start, end)
        let mut touches: Vec<bool> = Vec::new();
        let mut uf = UnionFind::new(0);
        let mut buf = Vec::new();
        // The runs of the row before, and the row after the last one looked at.
        let mut prev = 0..0;
        let mut next_k = 0;
        let widest = tiles.bands().iter().map(|b| b.row_len).max().unwrap_or(0);
        let mut edge = vec![0u64; widest];
        let (mut up_buf, mut down_buf) = (Vec::new(), Vec::new());
        for (k, row) in self.stored_rows() {
            if k != next_k {
                prev = runs.len()..runs.len();
            }
            next_k = k + 1;
            buf.clear();
            self.runs(&row, |r, d| r & !d, &mut buf);
            if buf.is_empty() {
                prev = runs.len()..runs.len();
                continue;
            }
            self.edge_row(&row, k, &mut edge, &mut up_buf, &mut down_buf);
            let first = runs.len();
            let mut seg = 0;
            for &(s, e) in &buf {
                while row.segs[seg].c1 * 64 <= s as usize {
                    seg += 1;
                }
                let shift = 64 * row.segs[seg].shift();
                let (c0, c1) = (s as usize - shift, e as usize - 1 - shift);
                runs.push((k as u32, s, e));
                touches.push(count_range(&edge, c0, c1) > 0);
                uf.parent.push(uf.parent.len() as u32);
            }
            let cur = first..runs.len();
            let (mut i, mut j) = (prev.start, cur.start);
            while i < prev.end && j < cur.end {
                let (_, s1, e1) = runs[i];
                let (_, s2, e2) = runs[j];
                if e1.min(e2) >= s1.max(s2) + MIN_PASSAGE_COLS {
                    uf.union(i, j);
                }
                if e1 < e2 { i += 1 } else { j += 1 }
            }
            prev = cur;
        }
        // Components, numbered in order of their first run (a root precedes its members).
        let mut comp = vec![0u32; runs.len()];
        let mut accs: Vec<Acc> = Vec::new();
        for (i, &(k, s, e)) in runs.iter().enumerate() {
            let root = uf.find(i);
            let id = if root == i {
                accs.push(Acc::default());
                accs.len() - 1
            } else {
                comp[root] as usize
            };
            comp[i] = id as u32;
            accs[id].add(k, s, e, touches[i]);
        }
        // Inward deviation: runs of voids that reach the boundary.
        let mut dev_in = Deviation::default();
        for (i, &(k, s, e)) in runs.iter().enumerate() {
            if accs[comp[i] as usize].boundary {
                probe(&g, index, &mut dev_in, k as usize, s, e);
            }
        }
        Voids::of(&g, accs.iter(), dev_in)
    }

    /// [`mask`](Self::mask) counting each cell's bits range by range, as before the window
    /// and 4-bit group counts, each share computed (for tests comparing both).
    #[doc(hidden)]
    pub fn mask_reference(&self, cell: f64) -> CoverageMask {
        let MaskLayout {
            rows,
            tiles: mut out,
            groups,
        } = self.mask_tiles(cell);
        let mut ranges = RangeCounts::new(self.widest_row());
        let counts = self.count_cell_by_cell(rows, &out, &groups, |r, d, c0, c1| {
            ranges.count(r, d, c0, c1)
        });
        let full = rows * rows * COLS_PER_ROW as usize;
        set_shares(&mut out, &counts, &[], full, true);
        self.mask_of(rows, out)
    }
}

impl Voids {
    /// The voids of the components summed in `accs` (in the order of their first runs).
    fn of<'a>(g: &Grid, accs: impl Iterator<Item = &'a Acc>, dev_in: Deviation) -> Voids {
        let cell = g.gx * g.gy;
        let (mut count, mut enclosed) = (0, 0u64);
        let mut largest: Option<Void> = None;
        for a in accs {
            count += 1;
            if !a.boundary {
                enclosed += a.cells;
            }
            let area = a.cells as f64 * cell;
            if largest.is_none_or(|l| area > l.area) {
                largest = Some(a.void(g));
            }
        }
        Voids {
            count,
            enclosed,
            largest,
            dev_in,
        }
    }
}

/// A union-find forest, a node per void run.
struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    fn find(&mut self, i: usize) -> usize {
        find(&mut self.parent, i)
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo as u32;
        }
    }
}
