//! Uniform-grid helpers shared by the spatial indexes (hatch ordering, boundary distances).

use crate::base::geom::{Point, segment_distance2};

/// `x.floor() as i64`, exactly (NaN → 0, saturating beyond the range), without a call to libm's
/// `floor` (the baseline x86-64 target has no rounding instruction): the cell numbers of the
/// grids here and of the 3D estimate's height maps. (The support's droplet grids have a
/// cheaper one for |x| < 2⁵¹, `support::droplets::grid::floor`, which their per-droplet loops
/// need: this one there cost their fill a fifth more instructions.)
#[inline]
pub fn floor_i64(x: f64) -> i64 {
    let i = x as i64;
    i.saturating_sub(i64::from((i as f64) > x))
}

/// Calls `f(x, y)` for the cells at Chebyshev distance exactly `r` from (cx, cy) that lie inside an
/// `nx` × `ny` grid: the ring searched in step `r` of a nearest-neighbour search.
pub fn each_ring_cell(cx: i64, cy: i64, r: i64, nx: i64, ny: i64, mut f: impl FnMut(i64, i64)) {
    // Full rows at the ring's top and bottom, only the two ends of the rows between (plain
    // loops: this runs for every nearest-end query of the hatch order), skipped when both
    // ends lie outside the grid (a ring wider than the grid would walk its rows for nothing).
    let inside_x = |x: i64| (0..nx).contains(&x);
    let (left, right) = (inside_x(cx - r), inside_x(cx + r));
    let (x0, x1) = ((cx - r).max(0), (cx + r).min(nx - 1));
    if (0..ny).contains(&(cy - r)) {
        for x in x0..=x1 {
            f(x, cy - r);
        }
    }
    if r > 0 && (left || right) {
        for y in (cy - r + 1).max(0)..=(cy + r - 1).min(ny - 1) {
            if left {
                f(cx - r, y);
            }
            if right {
                f(cx + r, y);
            }
        }
    }
    if r > 0 && (0..ny).contains(&(cy + r)) {
        for x in x0..=x1 {
            f(x, cy + r);
        }
    }
}

/// Region edges in a uniform grid, for the distance from a point to the boundary.
pub struct EdgeIndex<'a> {
    edges: &'a [(Point, Point)],
    min: Point,
    cell: f64,
    nx: i64,
    ny: i64,
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl<'a> EdgeIndex<'a> {
    /// Cells of `cell` (> 0), made larger where that would give more cells than about one per
    /// edge: the grid's memory stays proportional to the edges however large the part.
    pub fn new(edges: &'a [(Point, Point)], cell: f64) -> EdgeIndex<'a> {
        let mut min = [f64::INFINITY; 2];
        let mut max = [f64::NEG_INFINITY; 2];
        for (a, b) in edges {
            for k in 0..2 {
                min[k] = min[k].min(a[k]).min(b[k]);
                max[k] = max[k].max(a[k]).max(b[k]);
            }
        }
        if edges.is_empty() {
            min = [0.0; 2];
            max = [0.0; 2];
        }
        let spread = ((max[0] - min[0]) * (max[1] - min[1]) / edges.len().max(1) as f64).sqrt();
        let cell = cell.max(spread);
        let nx = floor_i64((max[0] - min[0]) / cell) + 1;
        let ny = floor_i64((max[1] - min[1]) / cell) + 1;
        let cell_of = |p: Point| {
            (
                floor_i64((p[0] - min[0]) / cell).clamp(0, nx - 1),
                floor_i64((p[1] - min[1]) / cell).clamp(0, ny - 1),
            )
        };
        let mut counts = vec![0u32; (nx * ny) as usize + 1];
        let each = |f: &mut dyn FnMut(usize, usize)| {
            for (i, (a, b)) in edges.iter().enumerate() {
                let (ax, ay) = cell_of(*a);
                let (bx, by) = cell_of(*b);
                for y in ay.min(by)..=ay.max(by) {
                    for x in ax.min(bx)..=ax.max(bx) {
                        f((y * nx + x) as usize, i);
                    }
                }
            }
        };
        each(&mut |c, _| counts[c + 1] += 1);
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; *counts.last().unwrap_or(&0) as usize];
        each(&mut |c, i| {
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        });
        EdgeIndex {
            edges,
            min: min.into(),
            cell,
            nx,
            ny,
            offsets: counts,
            items,
        }
    }

    /// Distance from `p` to the nearest edge; may stop early (returning a value ≤ `enough`)
    /// once the distance is known to be at most `enough`.
    pub fn distance(&self, p: Point, enough: f64) -> f64 {
        if self.edges.is_empty() {
            return 0.0;
        }
        let cx = floor_i64((p[0] - self.min[0]) / self.cell);
        let cy = floor_i64((p[1] - self.min[1]) / self.cell);
        let mut best = f64::INFINITY;
        let max_r = self.nx.max(self.ny) + cx.abs().max(cy.abs());
        for r in 0..=max_r {
            each_ring_cell(cx, cy, r, self.nx, self.ny, |x, y| {
                let c = (y * self.nx + x) as usize;
                for &e in &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize] {
                    let (a, b) = self.edges[e as usize];
                    best = best.min(segment_distance2(p, a, b));
                }
            });
            // Edges outside rings 0..=r are at least r·cell away.
            let bound = r as f64 * self.cell;
            if best <= bound * bound || best <= enough * enough {
                break;
            }
        }
        best.sqrt()
    }

    /// Whether `hit(edge)` holds for an edge that may lie within `r` of `p`: every edge
    /// within `r` is offered (and some farther ones), each at least once.
    pub fn any_near(&self, p: Point, r: f64, mut hit: impl FnMut(usize) -> bool) -> bool {
        if self.edges.is_empty() {
            return false;
        }
        let cell = |v: f64, min: f64, n: i64| floor_i64((v - min) / self.cell).clamp(0, n - 1);
        let (x0, x1) = (
            cell(p[0] - r, self.min[0], self.nx),
            cell(p[0] + r, self.min[0], self.nx),
        );
        let (y0, y1) = (
            cell(p[1] - r, self.min[1], self.ny),
            cell(p[1] + r, self.min[1], self.ny),
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                let c = (y * self.nx + x) as usize;
                for &e in &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize] {
                    // An edge whose box lies farther than r from p lies farther than r too.
                    let (a, b) = self.edges[e as usize];
                    if p[0] + r < a[0].min(b[0])
                        || p[0] - r > a[0].max(b[0])
                        || p[1] + r < a[1].min(b[1])
                        || p[1] - r > a[1].max(b[1])
                    {
                        continue;
                    }
                    if hit(e as usize) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// The layout of a sparse array over a large grid of `rows` × `cols` cells of which only some
/// parts hold anything (a part's droplets and region on a grid spanning its bounding box). The
/// rows are grouped in bands of `band_rows`; a band stores only its tiles (`band_rows` ×
/// `tile_cols` cells) that were [marked](Self::mark), a run of adjacent ones as one
/// [`Segment`], and each of its rows as one slice holding its segments one after the other.
/// Bands with no marked tile are not stored at all. Memory: the marked tiles, plus a few words
/// per band and per segment; nothing grows with the grid's area.
#[derive(Clone, Debug, Default)]
pub struct Tiles {
    rows: usize,
    cols: usize,
    band_rows: usize,
    tile_cols: usize,
    band_shift: u32,
    tile_shift: u32,
    /// Bits of a tile number in a mark.
    tile_bits: u32,
    /// (band, first tile, last tile) per mark, packed so that they sort in that order.
    marks: Vec<u64>,
    bands: Vec<Band>,
    segs: Vec<Segment>,
    len: usize,
}

/// A stored band of [`Tiles`].
#[derive(Clone, Copy, Debug)]
pub struct Band {
    /// Its rows [first_row, end_row) of the grid.
    pub first_row: usize,
    pub end_row: usize,
    /// Its segments: `Tiles::segments()[segs.0..segs.1]`.
    segs: (usize, usize),
    /// Cells in each of its rows.
    pub row_len: usize,
    /// Where its first row starts in the storage.
    pub offset: usize,
}

/// Adjacent stored tiles of a band: columns [c0, c1) of the grid, at `at`.. of each row's slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    pub c0: usize,
    pub c1: usize,
    pub at: usize,
}

impl Segment {
    /// Grid column minus slice position (≥ 0): column c is at `c - shift()` of a row's slice.
    #[inline]
    pub fn shift(&self) -> usize {
        self.c0 - self.at
    }

    /// The end of its cells in a row's slice.
    #[inline]
    pub fn end(&self) -> usize {
        self.at + self.c1 - self.c0
    }
}

/// Where [`Tiles`] stores one segment of one band (see [`Tiles::spot`]): cell (k, c) at
/// [`index(k)`](Self::index)` + c − shift`.
#[derive(Clone, Copy, Debug)]
pub struct Spot {
    /// The band's rows [first_row, end_row).
    pub first_row: usize,
    pub end_row: usize,
    offset: usize,
    /// Cells per row.
    pub row_len: usize,
    slot: usize,
    /// The segment's [`Segment::shift`].
    pub shift: usize,
    /// The segment's columns [c0, c1).
    cols: (usize, usize),
}

impl Spot {
    /// Where row k's slice starts.
    #[inline]
    pub fn index(&self, k: usize) -> usize {
        self.offset + (k - self.first_row) * self.row_len
    }

    /// Whether it holds row k's columns c0..=c1.
    #[inline]
    pub fn holds(&self, k: usize, c0: usize, c1: usize) -> bool {
        (self.first_row..self.end_row).contains(&k) && self.cols.0 <= c0 && c1 < self.cols.1
    }

    /// Row k's [`Row::slot`].
    #[inline]
    pub fn slot(&self, k: usize) -> usize {
        self.slot + k - self.first_row
    }
}

/// One stored row of [`Tiles`].
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// Where the row's slice starts in the storage, and its length.
    pub offset: usize,
    pub len: usize,
    /// Number of the row among the stored rows (`band position · band_rows + row in band`),
    /// for per-row data kept beside the storage.
    pub slot: usize,
    /// The position of its band in [`Tiles::bands`].
    pub band: usize,
    pub segs: &'a [Segment],
}

impl<'a> Row<'a> {
    /// The segment holding column `c`.
    #[inline]
    pub fn segment(&self, c: usize) -> Option<&'a Segment> {
        let i = self.segs.partition_point(|s| s.c1 <= c);
        self.segs.get(i).filter(|s| s.c0 <= c)
    }

    /// The storage range of this row.
    #[inline]
    pub fn range(&self) -> std::ops::Range<usize> {
        self.offset..self.offset + self.len
    }
}

impl Tiles {
    /// Starts a new layout of `rows` × `cols` cells in bands of `band_rows` and tiles of
    /// `tile_cols` (powers of two), keeping the memory of the last one.
    pub fn reset(&mut self, rows: usize, cols: usize, band_rows: usize, tile_cols: usize) {
        debug_assert!(band_rows.is_power_of_two() && tile_cols.is_power_of_two());
        self.rows = rows;
        self.cols = cols;
        self.band_shift = band_rows.max(1).ilog2();
        self.tile_shift = tile_cols.max(1).ilog2();
        // Bits to write the numbers below n.
        let bits = |n: usize| usize::BITS - n.saturating_sub(1).leading_zeros();
        let band_bits = bits((rows >> self.band_shift) + 1);
        // A mark holds (band, tile, tile) in 63 bits: a grid too wide for that gets wider tiles.
        while band_bits + 2 * bits((cols >> self.tile_shift) + 1) > 63 {
            self.tile_shift += 1;
        }
        self.tile_bits = bits((cols >> self.tile_shift) + 1);
        self.band_rows = 1 << self.band_shift;
        self.tile_cols = 1 << self.tile_shift;
        self.marks.clear();
        self.bands.clear();
        self.segs.clear();
        self.len = 0;
    }

    /// Marks the tiles holding cells (r, c) with r0 ≤ r ≤ r1, c0 ≤ c ≤ c1 (clamped to the
    /// grid) as used. Call before [`build`](Self::build).
    #[inline]
    pub fn mark(&mut self, r0: usize, r1: usize, c0: usize, c1: usize) {
        let (r1, c1) = (
            r1.min(self.rows.wrapping_sub(1)),
            c1.min(self.cols.wrapping_sub(1)),
        );
        if self.rows == 0 || self.cols == 0 || r0 > r1 || c0 > c1 {
            return;
        }
        let tiles = (((c0 >> self.tile_shift) << self.tile_bits) | (c1 >> self.tile_shift)) as u64;
        for band in r0 >> self.band_shift..=r1 >> self.band_shift {
            let m = ((band as u64) << (2 * self.tile_bits)) | tiles;
            // Neighbouring rows and droplets mostly mark what was just marked.
            let recent = &self.marks[self.marks.len().saturating_sub(8)..];
            if !recent.iter().rev().any(|r| *r == m) {
                self.marks.push(m);
            }
        }
    }

    /// Lays out the marked tiles; returns the number of cells to store.
    pub fn build(&mut self) -> usize {
        self.marks.sort_unstable();
        self.bands.clear();
        self.segs.clear();
        let (tb, mask) = (self.tile_bits, (1u64 << self.tile_bits) - 1);
        let unpack = |m: u64| ((m >> (2 * tb)) as usize, (m >> tb) & mask, m & mask);
        let mut offset = 0;
        let mut i = 0;
        while i < self.marks.len() {
            let band = unpack(self.marks[i]).0;
            let first = self.segs.len();
            let mut at = 0;
            while i < self.marks.len() && unpack(self.marks[i]).0 == band {
                let (_, t0, mut t1) = unpack(self.marks[i]);
                i += 1;
                // Marks sorted by first tile: merge those that overlap or touch.
                while i < self.marks.len() {
                    let (b, s0, s1) = unpack(self.marks[i]);
                    if b != band || s0 > t1 + 1 {
                        break;
                    }
                    t1 = t1.max(s1);
                    i += 1;
                }
                let c0 = t0 as usize * self.tile_cols;
                let c1 = ((t1 as usize + 1) * self.tile_cols).min(self.cols);
                self.segs.push(Segment { c0, c1, at });
                at += c1 - c0;
            }
            let first_row = band * self.band_rows;
            let end_row = (first_row + self.band_rows).min(self.rows);
            self.bands.push(Band {
                first_row,
                end_row,
                segs: (first, self.segs.len()),
                row_len: at,
                offset,
            });
            offset += at * (end_row - first_row);
        }
        self.len = offset;
        offset
    }

    /// Cells stored.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Rows per band.
    pub fn band_rows(&self) -> usize {
        self.band_rows
    }

    /// The stored bands, in order.
    pub fn bands(&self) -> &[Band] {
        &self.bands
    }

    /// A band's segments, in order.
    pub fn segments(&self, band: &Band) -> &[Segment] {
        &self.segs[band.segs.0..band.segs.1]
    }

    /// Stored rows counted as [`Row::slot`] counts them (an upper bound).
    pub fn row_slots(&self) -> usize {
        self.bands.len() * self.band_rows
    }

    /// Row `k` of the band at position `band` of [`bands`](Self::bands).
    #[inline]
    pub fn row_in(&self, band: usize, k: usize) -> Row<'_> {
        let b = &self.bands[band];
        debug_assert!((b.first_row..b.end_row).contains(&k));
        Row {
            offset: b.offset + (k - b.first_row) * b.row_len,
            len: b.row_len,
            slot: band * self.band_rows + k - b.first_row,
            band,
            segs: self.segments(b),
        }
    }

    /// Where the segment holding cell (k, c) is stored, if it is: valid for every row of
    /// that band and every column of that segment.
    #[inline]
    pub fn spot(&self, k: usize, c: usize) -> Option<Spot> {
        let row = self.row(k)?;
        let seg = row.segment(c)?;
        let b = &self.bands[row.band];
        Some(Spot {
            first_row: b.first_row,
            end_row: b.end_row,
            offset: b.offset,
            row_len: b.row_len,
            slot: row.band * self.band_rows,
            shift: seg.shift(),
            cols: (seg.c0, seg.c1),
        })
    }

    /// The [`spot`](Self::spot) of row k's cells c0..=c1, if one segment holds them all:
    /// `cache` if it does (mostly the case for the next row of an object, or the next object),
    /// else looked up and kept in `cache`.
    #[inline]
    pub fn spot_cached(
        &self,
        cache: &mut Option<Spot>,
        k: usize,
        c0: usize,
        c1: usize,
    ) -> Option<Spot> {
        if let Some(sp) = *cache
            && sp.holds(k, c0, c1)
        {
            return Some(sp);
        }
        let sp = self.spot(k, c0).filter(|sp| sp.holds(k, c0, c1))?;
        *cache = Some(sp);
        Some(sp)
    }

    /// Row `k`, if its band is stored.
    #[inline]
    pub fn row(&self, k: usize) -> Option<Row<'_>> {
        let i = self.bands.partition_point(|b| b.end_row <= k);
        self.bands
            .get(i)
            .filter(|b| b.first_row <= k)
            .map(|_| self.row_in(i, k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_index_offers_every_edge_within_reach_and_finds_the_nearest_as_a_scan_does() {
        // Edges short and long (across many cells), points, axis-parallel; queries inside,
        // outside and at the edges: every edge within r of p is offered, "any edge closer
        // than r" and the nearest edge's distance are what a scan of every edge says.
        let mut random = crate::base::testing::rng(0x9e37_79b9_7f4a_7c15u64);
        for case in 0..40 {
            let n = 1 + case * 13 % 300;
            let scale = if case % 3 == 0 { 1.0 } else { 30.0 };
            let edges: Vec<(Point, Point)> = (0..n)
                .map(|k| {
                    let a = Point::new(random() * scale, random() * scale);
                    let b = match k % 5 {
                        0 => a,
                        1 => Point::new(a.x + random() * scale, a.y),
                        2 => Point::new(random() * scale, random() * scale),
                        _ => a + Point::new(random() - 0.5, random() - 0.5) * 0.4,
                    };
                    (a, b)
                })
                .collect();
            let r: f64 = [0.01, 0.1, 0.5, 2.0][case % 4];
            let index = EdgeIndex::new(&edges, r.max(1e-3));
            for q in 0..200 {
                let p = if q % 4 == 0 {
                    let (a, b) = edges[q % n];
                    let t = random();
                    a + (b - a) * t + Point::new(random() - 0.5, random() - 0.5) * 2.0 * r
                } else {
                    Point::new(
                        random() * 1.4 * scale - 0.2 * scale,
                        random() * 1.4 * scale - 0.2 * scale,
                    )
                };
                let mut offered = vec![false; n];
                assert!(!index.any_near(p, r, |e| {
                    offered[e] = true;
                    false
                }));
                for (e, &(a, b)) in edges.iter().enumerate() {
                    if segment_distance2(p, a, b) <= r * r {
                        assert!(
                            offered[e],
                            "case {case}: edge {e} within {r} of {p} not offered"
                        );
                    }
                }
                let scan = edges
                    .iter()
                    .any(|&(a, b)| segment_distance2(p, a, b) < r * r);
                let got = index.any_near(p, r, |e| {
                    let (a, b) = edges[e];
                    segment_distance2(p, a, b) < r * r
                });
                assert_eq!(got, scan, "case {case} at {p}");
                // and the distance to the nearest edge, as the scan finds it
                let nearest = edges
                    .iter()
                    .map(|&(a, b)| segment_distance2(p, a, b))
                    .fold(f64::INFINITY, f64::min)
                    .sqrt();
                let d = index.distance(p, 0.0);
                assert!(
                    (d - nearest).abs() <= 1e-12 * nearest.max(1.0),
                    "case {case} at {p}: {d} {nearest}"
                );
            }
        }
    }

    #[test]
    fn floor_i64_is_floor_as_i64() {
        for x in crate::base::testing::floor_cases() {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x:e}");
        }
    }

    #[test]
    fn tiles_store_only_what_was_marked() {
        let mut t = Tiles::default();
        // A grid of 10⁶ × 10⁶ cells with two small things far apart and a long strip.
        t.reset(1_000_000, 1_000_000, 64, 4);
        t.mark(10, 20, 5, 9);
        t.mark(999_990, 999_999, 999_000, 999_010);
        t.mark(500_000, 500_000, 0, 999_999);
        // Touching and overlapping marks in one band merge into one segment.
        t.mark(100, 100, 8, 11);
        t.mark(101, 101, 12, 12);
        let len = t.build();
        assert_eq!(len, t.len());
        // Band 0: columns 4..12 (tiles 1 and 2); band 1: 8..16; the strip's band: every
        // column; the far corner's.
        assert_eq!(t.bands().len(), 4);
        let b0 = t.bands()[0];
        assert_eq!((b0.first_row, b0.end_row, b0.row_len), (0, 64, 8));
        let one = |c0, c1| [Segment { c0, c1, at: 0 }];
        assert_eq!(t.segments(&b0), one(4, 12));
        let b1 = t.bands()[1];
        assert_eq!(t.segments(&b1), one(8, 16));
        let last = t.bands()[3];
        assert_eq!((last.first_row, last.end_row), (999_936, 1_000_000));
        assert_eq!(t.segments(&last)[0].c0, 999_000);
        assert_eq!(len, 64 * 8 + 64 * 8 + 64 * 1_000_000 + 64 * 12);
        // Lookups.
        assert!(t.row(128).is_none() && t.row(200).is_none());
        let r = t.row(15).unwrap();
        assert_eq!((r.offset, r.len, r.slot, r.band), (15 * 8, 8, 15, 0));
        assert_eq!(
            r.segment(9),
            Some(&Segment {
                c0: 4,
                c1: 12,
                at: 0
            })
        );
        assert_eq!(r.segment(3), None);
        assert_eq!(r.segment(12), None);
        assert_eq!(t.row(70).unwrap().slot, 64 + 6);
        let sp = t.spot(999_995, 999_005).unwrap();
        assert!(sp.holds(999_940, 999_000, 999_011) && !sp.holds(999_935, 999_000, 999_001));
        assert_eq!(sp.index(999_936), 64 * 8 + 64 * 8 + 64 * 1_000_000);
        assert_eq!(sp.index(999_937) - sp.index(999_936), sp.row_len);
        assert!(t.spot(999_995, 998_000).is_none());
        let mut cache = None;
        assert_eq!(t.spot_cached(&mut cache, 20, 5, 9).unwrap().shift, 4);
        assert!(cache.is_some() && t.spot_cached(&mut cache, 20, 5, 20).is_none());
    }

    /// Grids wider than 2³² cells: natively only (usize has 64 bits there).
    #[cfg(target_pointer_width = "64")]
    #[test]
    fn wide_grids() {
        let mut t = Tiles::default();
        // Nothing marked, nothing stored.
        t.reset(1 << 40, 1 << 40, 64, 256);
        assert_eq!(t.build(), 0);
        assert!(t.row(0).is_none() && t.is_empty());
        // A grid too wide for the packed marks gets wider tiles.
        t.reset(1 << 40, 1 << 40, 64, 256);
        t.mark(5, 5, 1 << 39, 1 << 39);
        t.build();
        let seg = t.segments(&t.bands()[0])[0];
        assert!(
            seg.c0 <= 1 << 39 && 1 << 39 < seg.c1 && seg.c1 - seg.c0 >= 256,
            "{seg:?}"
        );
    }

    #[test]
    fn rings_cover_the_grid_once() {
        let (nx, ny) = (7, 5);
        let mut seen = vec![0; (nx * ny) as usize];
        for r in 0..10 {
            each_ring_cell(2, 3, r, nx, ny, |x, y| {
                assert_eq!((x - 2).abs().max((y - 3).abs()), r);
                seen[(y * nx + x) as usize] += 1;
            });
        }
        assert!(seen.iter().all(|&n| n == 1));
        // Centres outside the grid (the edge index's queries): only cells inside, once.
        let mut seen = vec![0; (nx * ny) as usize];
        for r in 0..20 {
            each_ring_cell(-4, 9, r, nx, ny, |x, y| {
                assert!((0..nx).contains(&x) && (0..ny).contains(&y));
                assert_eq!((x + 4).abs().max((y - 9).abs()), r);
                seen[(y * nx + x) as usize] += 1;
            });
        }
        assert!(seen.iter().all(|&n| n == 1));
    }

    #[test]
    fn rings_visit_their_cells_in_row_order() {
        // Narrow and wide grids, centres inside and outside, rings wider than the grid: the
        // cells in the order of a row-major scan (the searches' ties depend on it).
        for (nx, ny, cx, cy) in [(3, 40, 1, 20), (40, 2, 39, 0), (5, 5, -7, 2), (1, 1, 0, 0)] {
            for r in 0..50 {
                let mut got = Vec::new();
                each_ring_cell(cx, cy, r, nx, ny, |x, y| got.push((x, y)));
                let want: Vec<(i64, i64)> = (0..ny)
                    .flat_map(|y| (0..nx).map(move |x| (x, y)))
                    .filter(|&(x, y)| (x - cx).abs().max((y - cy).abs()) == r)
                    .collect();
                assert_eq!(got, want, "{nx}×{ny} around ({cx}, {cy}), ring {r}");
            }
        }
    }
}
