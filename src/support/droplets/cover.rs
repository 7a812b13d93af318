//! Where a layer's droplets surely support a droplet above: a raster, in the frame of the
//! layer's hatch rows, of cells every point of which lies within reach of one of its droplets
//! (rectangles along the hatch lines' runs, squares around single droplets; conservative by a
//! margin). A droplet above in a marked cell is supported, and most are; the others are
//! looked for droplet by droplet ([`super::index::Index`]). So the answer is the same, and the
//! raster only spares the search.

use super::grid::floor;
use crate::base::geom::{DVec2, Point};

/// At most this many cells (4 MB of bits); a larger box gets larger cells.
const MAX_CELLS: f64 = (1u64 << 25) as f64;

/// A layer's cells that its droplets surely support ([`Cover::covers`]).
#[derive(Default)]
pub(super) struct Cover {
    sin: f64,
    cos: f64,
    /// 1 / the cell's side.
    inv: f64,
    origin: DVec2,
    nx: usize,
    ny: usize,
    /// `nx` and `ny` as floats.
    size: DVec2,
    words: usize,
    bits: Vec<u64>,
}

impl Cover {
    /// Into the frame (rotated by −angle, `sin` and `cos` of the angle).
    pub(super) fn frame(sin: f64, cos: f64, p: Point) -> DVec2 {
        DVec2::new(cos * p.x + sin * p.y, -sin * p.x + cos * p.y)
    }

    /// Makes the raster empty: the frame of `sin` and `cos`, cells of `cell` (or larger, at
    /// most [`MAX_CELLS`] of them) over the frame's box `lo..=hi` (none when it is empty).
    pub(super) fn reset(&mut self, sin: f64, cos: f64, cell: f64, lo: DVec2, hi: DVec2) {
        self.bits.clear();
        (self.nx, self.ny, self.words, self.size) = (0, 0, 0, DVec2::ZERO);
        let size = hi - lo;
        if !(size.x >= 0.0 && size.y >= 0.0 && cell > 0.0 && size.is_finite()) {
            return;
        }
        let cell = cell.max((size.x * size.y / MAX_CELLS).sqrt());
        (self.sin, self.cos, self.inv, self.origin) = (sin, cos, 1.0 / cell, lo);
        self.nx = (size.x * self.inv) as usize + 1;
        self.ny = (size.y * self.inv) as usize + 1;
        self.words = self.nx.div_ceil(64);
        self.size = DVec2::new(self.nx as f64, self.ny as f64);
        self.bits.resize(self.words * self.ny, 0);
    }

    /// Marks the cells that lie wholly in the frame's rectangle `lo..=hi`.
    pub(super) fn mark(&mut self, lo: DVec2, hi: DVec2) {
        let a = (lo - self.origin) * self.inv;
        let b = (hi - self.origin) * self.inv;
        // Cells [k, k + 1) with a ≤ k and k + 1 ≤ b, within the raster (the box holds every
        // rectangle: |a|, |b| stay far below 2⁵¹).
        if !(a.x.abs() < 1e15 && a.y.abs() < 1e15 && b.x.abs() < 1e15 && b.y.abs() < 1e15) {
            return;
        }
        let (x0, y0) = ((-floor(-a.x)).max(0), (-floor(-a.y)).max(0));
        let x1 = (floor(b.x) - 1).min(self.nx as i64 - 1);
        let y1 = (floor(b.y) - 1).min(self.ny as i64 - 1);
        if x0 > x1 || y0 > y1 {
            return;
        }
        let (x0, x1) = (x0 as usize, x1 as usize);
        let (w0, w1) = (x0 / 64, x1 / 64);
        let (m0, m1) = (u64::MAX << (x0 % 64), u64::MAX >> (63 - x1 % 64));
        for y in y0 as usize..=y1 as usize {
            let row = &mut self.bits[y * self.words..(y + 1) * self.words];
            if w0 == w1 {
                row[w0] |= m0 & m1;
            } else {
                row[w0] |= m0;
                row[w0 + 1..w1].fill(u64::MAX);
                row[w1] |= m1;
            }
        }
    }

    /// Whether `p` lies in a marked cell.
    #[inline]
    pub(super) fn covers(&self, p: Point) -> bool {
        self.marked((Self::frame(self.sin, self.cos, p) - self.origin) * self.inv)
    }

    /// `f(j)` for each j in `0..n` whose point `from + j·step` lies in no marked cell (the
    /// points of a line by additions in the raster: the same within 10⁻¹² mm).
    #[inline]
    pub(super) fn uncovered(&self, from: Point, step: DVec2, n: u64, mut f: impl FnMut(u64)) {
        let q0 = (Self::frame(self.sin, self.cos, from) - self.origin) * self.inv;
        let d = Self::frame(self.sin, self.cos, step) * self.inv;
        for j in 0..n {
            if !self.marked(q0 + j as f64 * d) {
                f(j);
            }
        }
    }

    /// Whether the cell at the raster's position `q` is marked.
    #[inline]
    fn marked(&self, q: DVec2) -> bool {
        if !(q.x >= 0.0 && q.y >= 0.0 && q.x < self.size.x && q.y < self.size.y) {
            return false;
        }
        // 0 ≤ q < 2²⁵: the floor is the cell.
        let (x, y) = (floor(q.x) as usize, floor(q.y) as usize);
        self.bits[y * self.words + x / 64] >> (x % 64) & 1 == 1
    }
}
