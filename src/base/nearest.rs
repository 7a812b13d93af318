//! Nearest-next orders in near-linear time: a uniform grid over the points still to visit,
//! searched in rings around the current position. The orders are exactly those of a scan of
//! every point left at each step (the same distances, the same tie-break), so a layer of
//! 10⁵ loops or hatch segments is ordered in milliseconds instead of minutes.

use crate::base::geom::{DVec2, Point, dist};
use crate::base::spatial::{each_ring_cell, floor_i64};

/// Cells a side of a block of [`NearestGrid`]'s live counts.
const BLOCK: i64 = 8;

/// Points in a uniform grid, for repeated "nearest point not yet taken" queries.
pub struct NearestGrid {
    points: Vec<Point>,
    alive: Vec<bool>,
    /// Cell c's points are `items[start[c]..start[c] + len[c]]` (one array for all cells, not
    /// a `Vec` each: a layer's grid was thousands of small allocations); a scan drops the
    /// removed ones from its cell's part.
    start: Vec<u32>,
    len: Vec<u32>,
    items: Vec<u32>,
    /// Live points per block of [`BLOCK`] × [`BLOCK`] cells (`bx` blocks a row), and in all:
    /// a search skips the rings of cells in blocks with none, whose scan finds nothing.
    block_live: Vec<u32>,
    bx: i64,
    live: usize,
    min: Point,
    cell: f64,
    /// 1 / `cell` (a point's cell by a product, not a division: per query and removal).
    inv: f64,
    nx: i64,
    ny: i64,
}

impl NearestGrid {
    /// A grid of about four points per cell over the points' box (at most 4096 cells a side):
    /// hatch ends lie on few lines across the box, so finer cells are mostly empty and a ring
    /// search looks at many of them.
    pub fn new(points: Vec<Point>) -> NearestGrid {
        assert!(
            u32::try_from(points.len()).is_ok(),
            "too many points for a grid"
        );
        let mut min = DVec2::INFINITY;
        let mut max = DVec2::NEG_INFINITY;
        for p in &points {
            min = min.min(*p);
            max = max.max(*p);
        }
        let (w, h) = ((max[0] - min[0]).max(1e-9), (max[1] - min[1]).max(1e-9));
        let n = points.len().max(1) as f64;
        let cell = (2.0 * ((w * h) / n).sqrt()).max(w.max(h) / 4096.0);
        let nx = (w / cell).floor() as i64 + 1;
        let ny = (h / cell).floor() as i64 + 1;
        let (bx, by) = ((nx + BLOCK - 1) / BLOCK, (ny + BLOCK - 1) / BLOCK);
        let mut grid = NearestGrid {
            alive: vec![true; points.len()],
            start: vec![0; (nx * ny) as usize + 1],
            len: vec![0; (nx * ny) as usize],
            items: vec![0; points.len()],
            block_live: vec![0; (bx * by) as usize],
            bx,
            live: points.len(),
            points,
            min,
            cell,
            inv: 1.0 / cell,
            nx,
            ny,
        };
        // A counting sort by cell: each cell's points in their order.
        let keys: Vec<(u32, u32)> = grid
            .points
            .iter()
            .map(|&p| {
                let (cx, cy) = grid.cell_of(p);
                (
                    (cy * nx + cx) as u32,
                    ((cy / BLOCK) * bx + cx / BLOCK) as u32,
                )
            })
            .collect();
        for &(k, b) in &keys {
            grid.len[k as usize] += 1;
            grid.block_live[b as usize] += 1;
        }
        for c in 0..grid.len.len() {
            grid.start[c + 1] = grid.start[c] + grid.len[c];
        }
        let mut fill = grid.start.clone();
        for (i, &(k, _)) in keys.iter().enumerate() {
            let at = &mut fill[k as usize];
            grid.items[*at as usize] = i as u32;
            *at += 1;
        }
        grid
    }

    /// The first ring of cells around cell (cx, cy) that may hold a live point: every ring
    /// before it lies in blocks holding none (a block at Chebyshev distance R ≥ 1 from the
    /// cell's block has no cell nearer than (R − 1)·BLOCK + 1 to it).
    fn first_ring(&self, cx: i64, cy: i64) -> i64 {
        let (bx, by) = (self.bx, self.block_live.len() as i64 / self.bx);
        let (x, y) = (cx / BLOCK, cy / BLOCK);
        for r in 0..=bx.max(by) {
            let mut any = false;
            each_ring_cell(x, y, r, bx, by, |i, j| {
                any |= self.block_live[(j * bx + i) as usize] > 0;
            });
            if any {
                return if r == 0 { 0 } else { (r - 1) * BLOCK + 1 };
            }
        }
        0
    }

    fn cell_of(&self, p: Point) -> (i64, i64) {
        // (`floor_i64`: `floor() as i64` without a call to libm per query.) The product
        // places a point on a cell's border within rounding of the quotient's choice, far
        // inside the slack the searches keep.
        let cx = floor_i64((p[0] - self.min[0]) * self.inv);
        let cy = floor_i64((p[1] - self.min[1]) * self.inv);
        (cx.clamp(0, self.nx - 1), cy.clamp(0, self.ny - 1))
    }

    /// Takes point `i` out of the grid.
    pub fn remove(&mut self, i: usize) {
        if std::mem::replace(&mut self.alive[i], false) {
            let (cx, cy) = self.cell_of(self.points[i]);
            self.block_live[((cy / BLOCK) * self.bx + cx / BLOCK) as usize] -= 1;
            self.live -= 1;
        }
    }

    /// The point not yet removed nearest to `p` (by [`dist`]); of equally near ones, the one
    /// with the least `rank`. None when every point is removed.
    pub fn nearest(&mut self, p: Point, rank: impl Fn(usize) -> usize) -> Option<usize> {
        if self.live == 0 {
            return None;
        }
        let (cx, cy) = self.cell_of(p);
        let mut best: Option<(f64, usize)> = None;
        let max_r = self.nx.max(self.ny);
        // The rings before the first that may hold a live point hold none: scanning them
        // changes nothing.
        for r in self.first_ring(cx, cy)..=max_r {
            let mut any_cell = false;
            let (nx, ny) = (self.nx, self.ny);
            each_ring_cell(cx, cy, r, nx, ny, |x, y| {
                any_cell = true;
                self.scan(x, y, p, &rank, &mut best);
            });
            // Every point outside rings 0..=r is at least max(r·cell, how far p lies outside
            // the grid) away; stop once the best is nearer than that (the slack keeps rounding
            // on the safe side: an equally near point farther out is still looked at).
            let bound = (r as f64 * self.cell).max(self.outside_distance(p));
            if !any_cell || best.is_some_and(|(bd, _)| bd * (1.0 + 1e-9) + 1e-12 < bound) {
                break;
            }
        }
        best.map(|(_, i)| i)
    }

    /// Looks at the live points of cell (x, y) for one nearer to `p` than `best` (or as near
    /// with a lesser rank).
    fn scan(
        &mut self,
        x: i64,
        y: i64,
        p: Point,
        rank: &impl Fn(usize) -> usize,
        best: &mut Option<(f64, usize)>,
    ) {
        let at = (y * self.nx + x) as usize;
        if self.len[at] == 0 {
            return;
        }
        // A cell whose box lies farther than the best point so far holds no nearer point nor
        // an equally near one (the slack keeps rounding on the safe side).
        if let Some((bd, _)) = *best {
            let lo = self.min + DVec2::new(x as f64, y as f64) * self.cell;
            let hi = lo + DVec2::splat(self.cell);
            let d = (lo - p).max(p - hi).max(DVec2::ZERO);
            if d.length_squared() > bd * bd * (1.0 + 1e-9) + 1e-18 {
                return;
            }
        }
        let (from, n) = (self.start[at] as usize, self.len[at] as usize);
        let cell = &mut self.items[from..from + n];
        let (alive, points) = (&self.alive, &self.points);
        // The live points are kept at the part's front, in their order.
        let mut kept = 0;
        for k in 0..n {
            let i = cell[k] as usize;
            if !alive[i] {
                continue;
            }
            cell[kept] = i as u32;
            kept += 1;
            let d = dist(p, points[i]);
            if best.is_none_or(|(bd, bi)| d < bd || (d == bd && rank(i) < rank(bi))) {
                *best = Some((d, i));
            }
        }
        if kept < n {
            self.len[at] = kept as u32;
        }
    }

    /// How far `p` lies outside the grid's box (0 inside).
    fn outside_distance(&self, p: Point) -> f64 {
        let maxx = self.min[0] + self.nx as f64 * self.cell;
        let maxy = self.min[1] + self.ny as f64 * self.cell;
        let dx = (self.min[0] - p[0]).max(p[0] - maxx).max(0.0);
        let dy = (self.min[1] - p[1]).max(p[1] - maxy).max(0.0);
        dx.max(dy)
    }
}

/// The order of a walk from `from` that always goes next to the nearest of `starts` not yet
/// visited, and from item i on from `end(i)`: exactly the order of this list walk
///
/// ```text
/// while !left.is_empty() {
///     let next = (0..left.len()).min_by(|&i, &j| dist(at, left[i].start).total_cmp(&dist(at, left[j].start)));
///     let item = left.swap_remove(next);
///     at = item.end;
/// }
/// ```
///
/// including its ties (the first of equally near items in the list, whose order
/// `swap_remove` changes), in near-linear time.
pub fn nearest_walk(starts: &[Point], from: Point, end: impl Fn(usize) -> Point) -> Vec<usize> {
    let n = starts.len();
    let mut grid = NearestGrid::new(starts.to_vec());
    // The list of the walk above: the item at each place, and each item's place.
    let mut item_at: Vec<usize> = (0..n).collect();
    let mut place_of: Vec<usize> = (0..n).collect();
    let mut order = Vec::with_capacity(n);
    let mut at = from;
    while let Some(i) = grid.nearest(at, |j| place_of[j]) {
        grid.remove(i);
        let place = place_of[i];
        item_at.swap_remove(place);
        if let Some(&moved) = item_at.get(place) {
            place_of[moved] = place;
        }
        order.push(i);
        at = end(i);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::base::testing::random;

    /// The list walk of [`nearest_walk`]'s description, step by step.
    fn list_walk(starts: &[Point], from: Point, end: impl Fn(usize) -> Point) -> Vec<usize> {
        let mut left: Vec<usize> = (0..starts.len()).collect();
        let mut at = from;
        let mut order = Vec::new();
        while !left.is_empty() {
            let next = (0..left.len())
                .min_by(|&i, &j| dist(at, starts[left[i]]).total_cmp(&dist(at, starts[left[j]])))
                .expect("non-empty");
            let item = left.swap_remove(next);
            order.push(item);
            at = end(item);
        }
        order
    }

    #[test]
    fn the_walk_is_the_list_walk_ties_included() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for case in 0..60 {
            let n = case * 5;
            // Random points in clusters far apart, or on a small lattice (many equal
            // distances, many points in one place); each item ends at another random point
            // or where it starts.
            let point = |s: &mut u64| match case % 3 {
                0 => {
                    let c = if random(s) < 0.3 { 80.0 } else { 0.0 };
                    DVec2::new(c + random(s) * 10.0, random(s) * 4.0)
                }
                1 => DVec2::new((random(s) * 6.0).floor() * 0.5, (random(s) * 6.0).floor()),
                _ => DVec2::new((random(s) * 2.0).floor(), 0.0),
            };
            let starts: Vec<Point> = (0..n).map(|_| point(&mut seed)).collect();
            let ends: Vec<Point> = (0..n)
                .map(|i| {
                    if case % 2 == 0 {
                        starts[i]
                    } else {
                        point(&mut seed)
                    }
                })
                .collect();
            let from = DVec2::new(random(&mut seed) * 100.0 - 10.0, -5.0);
            let want = list_walk(&starts, from, |i| ends[i]);
            let got = nearest_walk(&starts, from, |i| ends[i]);
            assert_eq!(got, want, "case {case}");
        }
    }

    #[test]
    fn a_walk_over_a_large_lattice_visits_every_point_once() {
        // 300 × 300 points: a scan of every point left at each step would take minutes.
        let starts: Vec<Point> = (0..90_000)
            .map(|i| DVec2::new((i % 300) as f64, (i / 300) as f64))
            .collect();
        let order = nearest_walk(&starts, DVec2::new(-1.0, -1.0), |i| starts[i]);
        let mut seen = vec![false; starts.len()];
        for &i in &order {
            assert!(!seen[i]);
            seen[i] = true;
        }
        assert!(seen.iter().all(|&s| s));
        // Every step but the jumps between rows goes to a neighbour.
        let far = order
            .windows(2)
            .filter(|w| dist(starts[w[0]], starts[w[1]]) > 1.0)
            .count();
        assert!(far < 1000, "{far}");
    }
}
