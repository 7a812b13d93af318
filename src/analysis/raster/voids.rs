//! The layer's figures: cells counted and voids labelled in one pass over the rows, and the
//! boundary deviation.

use super::{Grid, LayerAnalysis, MIN_PASSAGE_COLS, Raster, Void};
use crate::base::geom::{DVec2, Point, dist};
use crate::base::spatial::{EdgeIndex, Row};

/// A void run's label before the labelling gives it one.
const NO_LABEL: u32 = u32::MAX;

/// The cells of word `w` of a row's region words `bits` (its segment starting at word `at`,
/// ending before `end`) whose four neighbours (left, right, above in `up`, below in `down`)
/// all lie in the region: a region cell not among them is an edge cell.
#[inline(always)]
pub(super) fn interior(
    bits: &[u64],
    w: usize,
    at: usize,
    end: usize,
    up: Option<&[u64]>,
    down: Option<&[u64]>,
) -> u64 {
    let r = bits[w];
    let left = (r << 1) | if w > at { bits[w - 1] >> 63 } else { 0 };
    let right = (r >> 1) | if w + 1 < end { bits[w + 1] << 63 } else { 0 };
    left & right & up.map_or(0, |x| x[w]) & down.map_or(0, |x| x[w])
}
/// The runs of set bits of a row, one word at a time: `v` the word's bits, `carry` the top bit
/// of the word before (a run open across them), `base` the grid column of the word's bit 0,
/// `open` where the run open at the top of the word before starts (kept up to date for the
/// next word). Calls `end(start, t)` for each run ending in the word, in order: at bit t, so
/// it spans columns [start, base + t). Each end closes the lowest start left (the run open
/// from the words before first); a start left over opens the run that goes on.
#[inline(always)]
fn close_runs(v: u64, carry: u64, base: u32, open: &mut u32, mut end: impl FnMut(u32, u32)) {
    let prev = (v << 1) | carry;
    let mut starts = v & !prev;
    let mut ends = !v & prev;
    if carry != 0 && ends != 0 {
        end(*open, ends.trailing_zeros());
        ends &= ends - 1;
    }
    while ends != 0 {
        end(base + starts.trailing_zeros(), ends.trailing_zeros());
        starts &= starts - 1;
        ends &= ends - 1;
    }
    if starts != 0 {
        *open = base + starts.trailing_zeros();
    }
}

impl Raster {
    /// Runs [start, end) of set bits of `mask(region word, droplet word)` in `row`, in grid
    /// columns, appended to `out`.
    pub(super) fn runs(
        &self,
        row: &Row,
        mask: impl Fn(u64, u64) -> u64,
        out: &mut Vec<(u32, u32)>,
    ) {
        let (r, d) = (&self.region_bits[row.range()], &self.drop_bits[row.range()]);
        let (lo, hi) = self.extent[row.slot];
        for seg in row.segs {
            let (a, e) = (seg.at.max(lo as usize), seg.end().min(hi as usize));
            if a >= e {
                continue;
            }
            // Grid column of the slice's column 0 in this segment.
            let shift = (64 * seg.shift()) as u32;
            let (mut carry, mut open) = (0u64, 0u32);
            for w in a..e {
                let v = mask(r[w], d[w]);
                let base = (w * 64) as u32 + shift;
                close_runs(v, carry, base, &mut open, |s, t| out.push((s, base + t)));
                carry = v >> 63;
            }
            // The segment's next word is not stored (zero) or beyond the row's bits.
            if carry != 0 {
                out.push((open, (e * 64) as u32 + shift));
            }
        }
    }

    /// The region words of the rows above and below row `k`, laid out as `row`'s slice
    /// ([`region_row_as`](Self::region_row_as); `None` where there is no such row or it holds
    /// nothing).
    pub(super) fn neighbour_rows<'a>(
        &'a self,
        row: &Row,
        k: usize,
        (up_buf, down_buf): (&'a mut Vec<u64>, &'a mut Vec<u64>),
    ) -> (Option<&'a [u64]>, Option<&'a [u64]>) {
        let up = (k + 1 < self.grid.ny)
            .then(|| self.region_row_as(row, k + 1, up_buf))
            .flatten();
        let down = (k > 0)
            .then(|| self.region_row_as(row, k - 1, down_buf))
            .flatten();
        (up, down)
    }

    /// The region words of row `k` laid out as `row`'s slice (its own slice when both are in
    /// the same band, else copied into `buf`); `None` when row `k` holds nothing.
    fn region_row_as<'a>(
        &'a self,
        row: &Row,
        k: usize,
        buf: &'a mut Vec<u64>,
    ) -> Option<&'a [u64]> {
        let other = self.tiles.row(k)?;
        if other.band == row.band {
            return Some(&self.region_bits[other.range()]);
        }
        buf.clear();
        buf.resize(row.len, 0);
        for s in row.segs {
            for o in other.segs {
                let (c0, c1) = (s.c0.max(o.c0), s.c1.min(o.c1));
                if c0 < c1 {
                    let from = other.offset + c0 - o.shift();
                    buf[c0 - s.shift()..c1 - s.shift()]
                        .copy_from_slice(&self.region_bits[from..from + c1 - c0]);
                }
            }
        }
        Some(buf)
    }

    /// The figures of the layer.
    pub fn analysis(&self) -> LayerAnalysis {
        self.analysis_with(|index, counts| self.voids_fast(index, counts))
    }

    /// [`analysis`](Self::analysis) compiled without the popcount instruction, whichever CPU
    /// runs it (for tests: natively the fast path takes the instruction when the CPU has it).
    #[cfg(any(test, feature = "reference"))]
    #[doc(hidden)]
    pub fn analysis_portable(&self) -> LayerAnalysis {
        self.analysis_with(|index, counts| self.voids_fast_with(index, counts))
    }

    /// The figures of the layer, its voids by `labelling`: given the boundary's index, it
    /// labels the voids and counts the cells ([`CellCounts`]).
    pub(super) fn analysis_with(
        &self,
        labelling: impl FnOnce(&EdgeIndex, &mut CellCounts) -> Voids,
    ) -> LayerAnalysis {
        let g = self.grid;
        let tiles = &self.tiles;
        let cell = g.gx * g.gy;
        let index = EdgeIndex::new(&self.edges, self.b);
        let mut counts = CellCounts::default();
        let v = labelling(&index, &mut counts);
        let [mut n_region, mut n_covered, n_over] = counts.cells;
        let (mut count, mut enclosed) = (v.count, v.enclosed);
        // A banded raster's interior: its cells and its droplets' cells for the covered
        // region stored there, its voids (all enclosed) added.
        if let Some(b) = &self.banding {
            n_region = n_region - b.stored_interior_cells + b.interior_cells;
            n_covered = (n_covered - b.stored_interior_cells + b.interior_drop_cells).min(n_region);
            let gaps = b.interior_cells.saturating_sub(b.interior_drop_cells);
            enclosed += gaps;
            count += (b.interior_cells as f64 * b.void_rate).round() as usize;
        }
        let dev_in = v.dev_in;
        // Outward deviation: overfill runs.
        let mut dev_out = Deviation::default();
        let mut buf = Vec::new();
        for &k in &counts.over_rows {
            buf.clear();
            if let Some(row) = tiles.row(k) {
                self.runs(&row, |r, d| d & !r, &mut buf);
            }
            for &(s, e) in &buf {
                probe(&g, &index, &mut dev_out, k, s, e);
            }
        }
        let coverage = if n_region > 0 {
            n_covered as f64 / n_region as f64
        } else {
            0.0
        };
        let (boundary_deviation, deviation_at) = if dev_out.max > dev_in.max {
            (dev_out.max, dev_out.at)
        } else {
            (dev_in.max, dev_in.at)
        };
        LayerAnalysis {
            index: self.index,
            z: self.z,
            droplets: self.droplets,
            region_area: self.region_area,
            covered_area: n_covered as f64 * cell,
            coverage,
            void_area: (n_region - n_covered) as f64 * cell,
            enclosed_void_area: enclosed as f64 * cell,
            voids: count,
            largest_void: v.largest,
            overfill_area: n_over as f64 * cell,
            deviation_inward: dev_in.max,
            deviation_outward: dev_out.max,
            boundary_deviation,
            deviation_at,
            unsupported_area: 0.0,
        }
    }

    /// The void runs of row `k` (laid out as `row`) appended to `runs` as (row, start, end,
    /// touches), touches 1 when the run touches a region cell with a neighbour (left, right,
    /// above, below) outside the region, else 0: the runs of [`runs`](Self::runs) with the
    /// boundary test of the reference's `edge_row`, in one pass over the words. A run
    /// touches the edge when adding its edge cells to the void bits carries out of it: the
    /// row's void words plus their edge cells, added as one long number, set the bit just
    /// above each run holding an edge cell (where the run ends) and no other bit outside the
    /// void.
    #[inline(always)]
    fn void_runs(
        &self,
        row: &Row,
        k: usize,
        runs: &mut Vec<(u32, u32, u32, u32)>,
        (up_buf, down_buf): &mut (Vec<u64>, Vec<u64>),
        counts: &mut [u64; 3],
    ) -> bool {
        let mut over = 0u64;
        let (lo, hi) = self.extent[row.slot];
        let range = row.range();
        let (bits, drops) = (&self.region_bits[range.clone()], &self.drop_bits[range]);
        let (up, down) = self.neighbour_rows(row, k, (up_buf, down_buf));
        let k = k as u32;
        for seg in row.segs {
            let end = seg.end();
            let (a, e) = (seg.at.max(lo as usize), end.min(hi as usize));
            if a >= e {
                continue;
            }
            let (bits, drops) = (&bits[..end], &drops[..end]);
            let (up, down) = (up.map(|x| &x[..end]), down.map(|x| &x[..end]));
            // Grid column of the slice's column 0 in this segment.
            let shift = (64 * seg.shift()) as u32;
            // The last word's top void bit, and the carry of the addition.
            let (mut carry, mut touch) = (0u64, false);
            // Where the run open at the last word's top starts.
            let mut open = 0u32;
            for w in a..e {
                let (r, dr) = (bits[w], drops[w]);
                counts[0] += r.count_ones() as u64;
                counts[1] += (r & dr).count_ones() as u64;
                counts[2] += (dr & !r).count_ones() as u64;
                over |= dr & !r;
                let v = r & !dr;
                if v | carry == 0 {
                    // No run here and none open (so no carry of the addition either).
                    continue;
                }
                let edge = v & !interior(bits, w, seg.at, end, up, down);
                let (sum, c1) = v.overflowing_add(edge);
                let (sum, c2) = sum.overflowing_add(touch as u64);
                touch = c1 | c2;
                let touched = sum & !v;
                let base = (w * 64) as u32 + shift;
                // Each run pushed whole at its end, with its flag.
                close_runs(v, carry, base, &mut open, |s, t| {
                    runs.push((k, s, base + t, ((touched >> t) & 1) as u32))
                });
                carry = v >> 63;
            }
            // The segment's next word is not stored (zero) or beyond the row's bits.
            if carry != 0 {
                runs.push((k, open, (e * 64) as u32 + shift, touch as u32));
            }
        }
        over != 0
    }

    /// The voids of the reference's labelling (`voids_reference`) in one pass over the rows: a run takes the
    /// label of the first run above it joins (a new label when none), labels are joined by
    /// union-find, and each label's cell count and boundary flag are kept at its root as runs
    /// come in, so there are as many union-find nodes as runs that start a void, not as runs.
    /// The largest void's centroid and box are summed afterwards from its runs. Figures
    /// identical.
    /// Also counts the cells into `counts`, as the reference's `count_cells` does, in the
    /// same pass over the words. Natively on a CPU with a popcount instruction, compiled for
    /// it (the baseline x86-64 target counts bits by shifts and adds).
    fn voids_fast(&self, index: &EdgeIndex, counts: &mut CellCounts) -> Voids {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("popcnt") {
            // SAFETY: the CPU has the instruction, as the check above found.
            return unsafe { self.voids_popcnt(index, counts) };
        }
        self.voids_fast_with(index, counts)
    }

    /// [`voids_fast_with`](Self::voids_fast_with) compiled with the popcount instruction.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "popcnt")]
    fn voids_popcnt(&self, index: &EdgeIndex, counts: &mut CellCounts) -> Voids {
        self.voids_fast_with(index, counts)
    }

    #[inline(always)]
    fn voids_fast_with(&self, index: &EdgeIndex, counts: &mut CellCounts) -> Voids {
        // A label's cells, with the boundary flag in the top bit.
        const TOP: u64 = 1 << 63;
        let g = self.grid;
        let mut guard = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        let scratch = &mut *guard;
        // The buffers as locals while labelling (not reached through the lock's guard).
        let mut runs = std::mem::take(&mut scratch.runs);
        let mut parent = std::mem::take(&mut scratch.parent);
        let mut cells = std::mem::take(&mut scratch.cells);
        let mut root = std::mem::take(&mut scratch.root);
        let around = &mut scratch.around;
        // (row, start, end, label; the touch flag of `void_runs` until labelled)
        runs.clear();
        cells.clear();
        parent.clear();
        let mut prev = 0..0;
        let mut next_k = 0;
        for (k, row) in self.stored_rows() {
            if k != next_k {
                prev = runs.len()..runs.len();
            }
            next_k = k + 1;
            let first = runs.len();
            if self.void_runs(&row, k, &mut runs, around, &mut counts.cells) {
                counts.over_rows.push(k);
            }
            // Each run takes the label of the first run above it joins (a new label when
            // none); the others it joins are united with it. Runs above that end before a
            // run could overlap it by the passage are passed once (nor can they join a later
            // run); those starting after it could overlap end the search.
            let (head, row_runs) = runs.split_at_mut(first);
            let above = &head[prev.clone()];
            let mut i = 0;
            for run in row_runs {
                let (_, s2, e2, touches) = *run;
                while i < above.len() && above[i].2 < s2 + MIN_PASSAGE_COLS {
                    i += 1;
                }
                let mut label = NO_LABEL;
                let mut t = i;
                while t < above.len() && above[t].1 + MIN_PASSAGE_COLS <= e2 {
                    let (_, s1, e1, l1) = above[t];
                    if e1.min(e2) >= s1.max(s2) + MIN_PASSAGE_COLS {
                        let a = find(&mut parent, l1 as usize) as u32;
                        if label == NO_LABEL {
                            label = a;
                        } else if a != label {
                            // A second run above: rare. The earlier label stays the root:
                            // roots in order of their component's first run, as the
                            // reference numbers them.
                            let (lo, hi) = (a.min(label) as usize, a.max(label) as usize);
                            parent[hi] = lo as u32;
                            let h = cells[hi];
                            cells[lo] = (cells[lo] + (h & !TOP)) | (h & TOP);
                            label = lo as u32;
                        }
                    }
                    t += 1;
                }
                if label == NO_LABEL {
                    label = cells.len() as u32;
                    parent.push(label);
                    cells.push(0);
                }
                let l = label as usize;
                cells[l] = (cells[l] + (e2 - s2) as u64) | ((touches as u64) << 63);
                run.3 = label;
            }
            prev = first..runs.len();
        }
        // Each label's root (a label's parent precedes it), the voids and the largest: the
        // first of the largest roots, in label order, as `Voids::of` takes them.
        let cell = g.gx * g.gy;
        root.clear();
        let (mut count, mut enclosed) = (0, 0u64);
        let mut largest: Option<(usize, f64)> = None;
        for l in 0..cells.len() {
            let p = parent[l] as usize;
            if p != l {
                let r = root[p];
                root.push(r);
                continue;
            }
            root.push(l as u32);
            count += 1;
            let c = cells[l];
            if c & TOP == 0 {
                enclosed += c;
            }
            let area = (c & !TOP) as f64 * cell;
            if largest.is_none_or(|(_, a)| area > a) {
                largest = Some((l, area));
            }
        }
        // Inward deviation (runs of voids that reach the boundary) and the largest's sums.
        let mut dev_in = Deviation::default();
        let mut acc = Acc::default();
        let big = largest.map_or(u32::MAX, |(l, _)| l as u32);
        // Per label what its runs need, from its root (one look-up per run below): 1 a
        // probe (the void reaches the boundary), 2 the largest's sums. (In the roots' buffer:
        // each label's root is read once, here.)
        let mut need = root;
        for r in need.iter_mut() {
            let reaches = cells[*r as usize] & TOP != 0;
            *r = reaches as u32 | ((*r == big) as u32) << 1;
        }
        for &(k, s, e, l) in runs.iter() {
            let need = need[l as usize];
            if need & 1 != 0 {
                probe(&g, index, &mut dev_in, k as usize, s, e);
            }
            if need & 2 != 0 {
                acc.add(k, s, e, false);
            }
        }
        acc.boundary = largest.is_some_and(|(l, _)| cells[l] & TOP != 0);
        // The buffers back, for the next layer.
        (scratch.runs, scratch.parent, scratch.cells, scratch.root) = (runs, parent, cells, need);
        Voids {
            count,
            enclosed,
            largest: largest.map(|_| acc.void(&g)),
            dev_in,
        }
    }
}

/// A void's sums while labelling.
#[derive(Clone, Copy)]
pub(super) struct Acc {
    pub(super) cells: u64,
    /// Sums of column·cells (twice, to stay whole) and row·cells.
    sx2: u64,
    sy: u64,
    min: [u32; 2],
    max: [u32; 2],
    pub(super) boundary: bool,
}

impl Default for Acc {
    fn default() -> Acc {
        Acc {
            cells: 0,
            sx2: 0,
            sy: 0,
            min: [u32::MAX; 2],
            max: [0; 2],
            boundary: false,
        }
    }
}

impl Acc {
    /// Adds the run [s, e) of row k.
    #[inline]
    pub(super) fn add(&mut self, k: u32, s: u32, e: u32, boundary: bool) {
        let n = (e - s) as u64;
        self.cells += n;
        self.sx2 += n * (s + e - 1) as u64;
        self.sy += n * k as u64;
        self.min = [self.min[0].min(s), self.min[1].min(k)];
        self.max = [self.max[0].max(e), self.max[1].max(k + 1)];
        self.boundary |= boundary;
    }

    /// The void these sums describe.
    pub(super) fn void(&self, g: &Grid) -> Void {
        let n = self.cells as f64;
        Void {
            area: self.cells as f64 * (g.gx * g.gy),
            centroid: DVec2::new(
                g.x0 + (self.sx2 as f64 / (2.0 * n) + 0.5) * g.gx,
                g.y0 + (self.sy as f64 / n + 0.5) * g.gy,
            ),
            min: DVec2::new(
                g.x0 + self.min[0] as f64 * g.gx,
                g.y0 + self.min[1] as f64 * g.gy,
            ),
            max: DVec2::new(
                g.x0 + self.max[0] as f64 * g.gx,
                g.y0 + self.max[1] as f64 * g.gy,
            ),
            at_boundary: self.boundary,
        }
    }
}

/// The root of `i` in the union-find forest `parent` (each node's parent, a root its own),
/// halving the paths it walks.
#[inline]
pub(super) fn find(parent: &mut [u32], mut i: usize) -> usize {
    while parent[i] as usize != i {
        let p = parent[i] as usize;
        parent[i] = parent[p];
        i = p;
    }
    i
}

/// A layer's voids: how many, the cells of those that do not reach the boundary, the largest
/// (the first of equal ones in the order of their first runs) and the inward deviation.
pub(super) struct Voids {
    pub(super) count: usize,
    pub(super) enclosed: u64,
    pub(super) largest: Option<Void>,
    pub(super) dev_in: Deviation,
}

/// What a labelling counts as it passes over the words: the cells of the region, of the
/// covered region and of the overfill (droplets outside the region), and the rows holding
/// overfill (in order), which the outward deviation probes.
#[derive(Default)]
pub(super) struct CellCounts {
    pub(super) cells: [u64; 3],
    pub(super) over_rows: Vec<usize>,
}

/// Probes the run [s, e) of row k (its ends and middle) for a larger distance to the
/// boundary than `best`'s.
pub(super) fn probe(g: &Grid, index: &EdgeIndex, best: &mut Deviation, k: usize, s: u32, e: u32) {
    let y = g.ry(k);
    for c in [s, (s + e - 1) / 2, e - 1] {
        let p = DVec2::new(g.cx(c as usize), y);
        // The distance to the boundary changes no faster than the point moves: a point
        // this close to the last one probed cannot beat the maximum.
        if best.last_d + dist(p, best.last) <= best.max {
            continue;
        }
        let d = index.distance(p, best.max);
        (best.last, best.last_d) = (p, d);
        if d > best.max {
            (best.max, best.at) = (d, Some(p));
        }
    }
}

/// The largest distance to the boundary found so far, where, and the last point probed with
/// an upper bound of its distance.
pub(super) struct Deviation {
    max: f64,
    at: Option<Point>,
    last: Point,
    last_d: f64,
}

impl Default for Deviation {
    fn default() -> Deviation {
        Deviation {
            max: 0.0,
            at: None,
            last: DVec2::ZERO,
            last_d: f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_closed_word_by_word_are_the_rows_runs_of_set_bits() {
        // Rows of 1 to 5 words, sparse to dense, against a scan of the bits one by one
        // (the labelling and the reference both take their runs from `close_runs`).
        let mut random = crate::base::testing::rng(0x2545_f491_4f6c_dd1du64);
        let mut seen = 0;
        for case in 0..3000 {
            let words = 1 + case % 5;
            let density = [0.05, 0.5, 0.95, 0.999][case / 5 % 4];
            let row: Vec<u64> = (0..words)
                .map(|_| (0..64).fold(0u64, |w, b| w | (((random() < density) as u64) << b)))
                .collect();
            let shift = 64 * (case % 3) as u32;
            let mut want = Vec::new();
            let mut start = None;
            for c in 0..64 * words {
                let set = row[c / 64] >> (c % 64) & 1 != 0;
                match (set, start) {
                    (true, None) => start = Some(c as u32 + shift),
                    (false, Some(s)) => {
                        want.push((s, c as u32 + shift));
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = start {
                want.push((s, (64 * words) as u32 + shift));
            }
            let (mut got, mut carry, mut open) = (Vec::new(), 0u64, 0u32);
            for (w, &v) in row.iter().enumerate() {
                let base = (w * 64) as u32 + shift;
                close_runs(v, carry, base, &mut open, |s, t| got.push((s, base + t)));
                carry = v >> 63;
            }
            if carry != 0 {
                got.push((open, (64 * words) as u32 + shift));
            }
            assert_eq!(got, want, "case {case}: {row:x?}");
            seen += want.len();
        }
        assert!(seen > 10_000, "{seen}");
    }
}
