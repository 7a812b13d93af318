//! Uniform-grid helpers shared by the spatial indexes (hatch ordering, boundary distances).

use crate::slice::{Point, segment_distance2};

/// The cells (x, y) at Chebyshev distance exactly `r` from (cx, cy) that lie inside an
/// `nx` × `ny` grid: the ring searched in step `r` of a nearest-neighbour search.
pub fn ring_cells(cx: i64, cy: i64, r: i64, nx: i64, ny: i64) -> impl Iterator<Item = (i64, i64)> {
    ((cy - r)..=(cy + r))
        .filter(move |y| (0..ny).contains(y))
        .flat_map(move |y| {
            // Full rows at the ring's top and bottom, only the two ends in between.
            let step = if y == cy - r || y == cy + r {
                1
            } else {
                (2 * r).max(1)
            };
            (0..)
                .map(move |k| cx - r + k * step)
                .take_while(move |&x| x <= cx + r)
                .filter(move |x| (0..nx).contains(x))
                .map(move |x| (x, y))
        })
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
        let nx = ((max[0] - min[0]) / cell).floor() as i64 + 1;
        let ny = ((max[1] - min[1]) / cell).floor() as i64 + 1;
        let cell_of = |p: Point| {
            (
                (((p[0] - min[0]) / cell).floor() as i64).clamp(0, nx - 1),
                (((p[1] - min[1]) / cell).floor() as i64).clamp(0, ny - 1),
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
            min,
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
        let cx = ((p[0] - self.min[0]) / self.cell).floor() as i64;
        let cy = ((p[1] - self.min[1]) / self.cell).floor() as i64;
        let mut best = f64::INFINITY;
        let max_r = self.nx.max(self.ny) + cx.abs().max(cy.abs());
        for r in 0..=max_r {
            for (x, y) in ring_cells(cx, cy, r, self.nx, self.ny) {
                let c = (y * self.nx + x) as usize;
                for &e in &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize] {
                    let (a, b) = self.edges[e as usize];
                    best = best.min(segment_distance2(p, a, b));
                }
            }
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
        let cell =
            |v: f64, min: f64, n: i64| (((v - min) / self.cell).floor() as i64).clamp(0, n - 1);
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
                    if hit(e as usize) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_cover_the_grid_once() {
        let (nx, ny) = (7, 5);
        let mut seen = vec![0; (nx * ny) as usize];
        for r in 0..10 {
            for (x, y) in ring_cells(2, 3, r, nx, ny) {
                assert_eq!((x - 2).abs().max((y - 3).abs()), r);
                seen[(y * nx + x) as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
    }
}
