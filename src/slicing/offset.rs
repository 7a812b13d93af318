//! Offset, stage 3 (docs/spec.md 5.3.3): a region → the region moved into the material by a
//! distance, with circular arcs at convex corners and every self-overlap removed, so parts of
//! the region thinner than twice the offset vanish instead of crossing themselves.
//!
//! Every edge is moved by the distance, joined by arcs at the corners where the moved edges
//! part (reflex corners of the region: the convex corners of the offset curve, in the thesis'
//! words) and by their crossing where they meet; the self-overlaps are resolved by the winding
//! number (the thesis's step), i_overlay's positive fill rule. Arcs are approximated by chords
//! no farther than [`CHORD_TOLERANCE_MM`] from the true arc. `tests/offset.rs` compares the
//! result with i_overlay's own outline offset on every layer of the shared models.

use crate::base::boolean::{Paths, simplify_apart_known};
use crate::base::geom::{
    Contour, DVec2, Point, Shape, Shapes, all_contours, dist, segment_distance2, signed_area,
};
use i_overlay::core::fill_rule::FillRule;
use std::cell::OnceCell;

/// Largest distance between an arc and the chords that approximate it.
pub const CHORD_TOLERANCE_MM: f64 = 0.001;

/// How a corner whose moved edges cross (a convex corner of the region) is joined.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Corners {
    /// At the crossing of the moved edges (the mitre point) when it lies on both, else as
    /// `ThroughVertex`: few self-intersections, so the union is quick, but exact only where
    /// no other part of the curve reaches the corner.
    Miter,
    /// Through the original vertex (a → vertex → b): a small loop of winding −1 per corner,
    /// which makes the winding rule exact everywhere (the raw offset curve of Chen and
    /// McMains, "Polygon offsetting by computing winding numbers", 2005).
    ThroughVertex,
}

/// Moves outer boundaries inward by `d_outer` and holes into the material by `d_hole` (mm, ≥ 0).
///
/// The raw offset curve of every loop ([`raw_offset`]) is united under the positive fill
/// rule: a point stays when the curves wind around it at least once. Convex corners are
/// mitred first; if any vertex of that result lies closer to the boundary than allowed (a
/// mitre that another part of the curve reached: small features, thin walls), the layer is
/// offset again with every convex corner through its vertex. A wrong mitre only adds area near
/// its corner, bounded by curves that come closer to the boundary than allowed, so one of its
/// vertices fails the test. On the shared models that happens to 3 of esca's 372 offsets, 1
/// of 426 on spikey_top, 1 of 2,316 on the bunny and none on 3DBenchy.
pub fn inset(region: &Shapes, d_outer: f64, d_hole: f64) -> Shapes {
    inset_within(region, d_outer, d_hole, CHORD_TOLERANCE_MM)
}

/// [`inset`] with arcs approximated by chords no farther than `tolerance` from them (mm, > 0):
/// a chain of n insets, each within [`CHORD_TOLERANCE_MM`] / n, stays within it.
pub fn inset_within(region: &Shapes, d_outer: f64, d_hole: f64, tolerance: f64) -> Shapes {
    inset_of(&Boundary::new(region), d_outer, d_hole, tolerance)
}

/// [`inset_within`] of `boundary`'s region: offsets of one region share its edges' grid.
pub fn inset_of(boundary: &Boundary, d_outer: f64, d_hole: f64, tolerance: f64) -> Shapes {
    let region = boundary.region;
    if region.is_empty() || (d_outer == 0.0 && d_hole == 0.0) {
        return region.clone();
    }
    let fast = inset_with(region, d_outer, d_hole, tolerance, Corners::Miter);
    if boundary.keeps_all(&fast, d_outer, d_hole) {
        fast
    } else {
        inset_with(region, d_outer, d_hole, tolerance, Corners::ThroughVertex)
    }
}

/// A region and, made when first needed, a grid of its boundary edges: what the mitre check of
/// [`inset_within`] searches, shared by every offset of the region (a layer's loops and fill).
pub struct Boundary<'a> {
    region: &'a Shapes,
    grid: OnceCell<EdgeGrid>,
}

impl<'a> Boundary<'a> {
    pub fn new(region: &'a Shapes) -> Boundary<'a> {
        Boundary {
            region,
            grid: OnceCell::new(),
        }
    }

    /// Whether every vertex of `offset` lies at least the allowed distance from the boundary:
    /// `d_outer` from outer loops, `d_hole` from holes, less twice [`CHORD_TOLERANCE_MM`]
    /// (the chords and rounding).
    fn keeps_all(&self, offset: &Shapes, d_outer: f64, d_hole: f64) -> bool {
        self.keeps(all_contours(offset).flatten().copied(), d_outer, d_hole)
    }

    /// Whether every point lies at least the allowed distance from the boundary, as
    /// [`Boundary::keeps_all`] measures it.
    fn keeps(&self, points: impl IntoIterator<Item = Point>, d_outer: f64, d_hole: f64) -> bool {
        let mut points = points.into_iter().peekable();
        if points.peek().is_none() {
            return true;
        }
        let reach = d_outer.max(d_hole);
        let grid = self.grid.get_or_init(|| EdgeGrid::new(self.region, reach));
        let limit = |d: f64| {
            let d = (d - 2.0 * CHORD_TOLERANCE_MM).max(0.0);
            d * d
        };
        let limits = [limit(d_outer), limit(d_hole)];
        points.all(|p| !grid.any_within(p, reach, limits))
    }
}

/// Boundary edges binned to square cells: each edge (its ends, and whether it bounds a hole)
/// stored in every cell its bounding box meets, the cells' runs one after the other.
struct EdgeGrid {
    min: DVec2,
    inv_cell: f64,
    nx: usize,
    ny: usize,
    offsets: Vec<u32>,
    items: Vec<GridEdge>,
}

/// An edge in [`EdgeGrid`]: its ends, its bounding box, whether it bounds a hole.
#[derive(Clone, Copy)]
struct GridEdge {
    a: Point,
    b: Point,
    lo: Point,
    hi: Point,
    hole: bool,
}

impl EdgeGrid {
    /// Cells of about a third of the edges' mean spacing (√(box area / edges)), not smaller
    /// than a quarter of `reach`: a search within `reach` meets few edges and few cells.
    fn new(region: &Shapes, reach: f64) -> EdgeGrid {
        let mut edges: Vec<(Point, Point, bool)> = Vec::new();
        for shape in region {
            for (hole, c) in shape.contours_with_hole() {
                for k in 0..c.len() {
                    edges.push((c[k], c[(k + 1) % c.len()], hole));
                }
            }
        }
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &(a, b, _) in &edges {
            lo = lo.min(a).min(b);
            hi = hi.max(a).max(b);
        }
        if edges.is_empty() {
            (lo, hi) = (DVec2::ZERO, DVec2::ZERO);
        }
        let size = hi - lo;
        let spread = (size.x * size.y / edges.len().max(1) as f64).sqrt();
        let cell = (spread / 3.0).max(reach / 4.0).max(1e-3);
        let inv_cell = 1.0 / cell;
        // Cells per axis, at most about 2¹⁵ each (a grid of a few edges over a large plate).
        let count = |len: f64| ((len * inv_cell) as usize).min(1 << 15) + 1;
        let (nx, ny) = (count(size.x), count(size.y));
        let mut grid = EdgeGrid {
            min: lo,
            inv_cell,
            nx,
            ny,
            offsets: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        for &(a, b, _) in &edges {
            let (x0, x1, y0, y1) = grid.cells(a.min(b), a.max(b));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    grid.offsets[y * nx + x + 1] += 1;
                }
            }
        }
        for i in 1..grid.offsets.len() {
            grid.offsets[i] += grid.offsets[i - 1];
        }
        let mut fill = grid.offsets.clone();
        let none = GridEdge {
            a: DVec2::ZERO,
            b: DVec2::ZERO,
            lo: DVec2::ZERO,
            hi: DVec2::ZERO,
            hole: false,
        };
        grid.items = vec![none; grid.offsets[nx * ny] as usize];
        for &(a, b, hole) in &edges {
            let (lo, hi) = (a.min(b), a.max(b));
            let e = GridEdge { a, b, lo, hi, hole };
            let (x0, x1, y0, y1) = grid.cells(lo, hi);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let slot = &mut fill[y * nx + x];
                    grid.items[*slot as usize] = e;
                    *slot += 1;
                }
            }
        }
        grid
    }

    /// The cells (x from, x to, y from, y to) that the box `lo`..`hi` meets, clamped to the
    /// grid. The same monotone map for edges and searches: a box that meets an edge's box
    /// shares a cell with it.
    fn cells(&self, lo: Point, hi: Point) -> (usize, usize, usize, usize) {
        // `as` saturates (a negative or NaN value gives 0), so it floors every value ≥ 0.
        let at = |v: f64, min: f64, n: usize| (((v - min) * self.inv_cell) as usize).min(n - 1);
        (
            at(lo.x, self.min.x, self.nx),
            at(hi.x, self.min.x, self.nx),
            at(lo.y, self.min.y, self.ny),
            at(hi.y, self.min.y, self.ny),
        )
    }

    /// Whether an edge lies closer to `p` than its limit (squared distances: `limits[0]` for
    /// edges of outer loops, `limits[1]` for holes', both under `r`²).
    fn any_within(&self, p: Point, r: f64, limits: [f64; 2]) -> bool {
        let (x0, x1, y0, y1) = self.cells(p - DVec2::splat(r), p + DVec2::splat(r));
        for y in y0..=y1 {
            let row = y * self.nx;
            let run =
                &self.items[self.offsets[row + x0] as usize..self.offsets[row + x1 + 1] as usize];
            for e in run {
                // An edge whose box lies farther than r from p lies farther than r too.
                if p.x + r < e.lo.x || p.x - r > e.hi.x || p.y + r < e.lo.y || p.y - r > e.hi.y {
                    continue;
                }
                if segment_distance2(p, e.a, e.b) < limits[usize::from(e.hole)] {
                    return true;
                }
            }
        }
        false
    }
}

/// [`inset`] with one way of joining convex corners.
pub fn inset_with(
    region: &Shapes,
    d_outer: f64,
    d_hole: f64,
    tolerance: f64,
    corners: Corners,
) -> Shapes {
    // The raw curves of each shape: shapes far apart are united apart (`simplify_apart`).
    let raw: Vec<Paths> = region
        .iter()
        .map(|shape| {
            shape
                .contours_with_hole()
                .map(|(hole, c)| {
                    raw_offset(c, if hole { d_hole } else { d_outer }, tolerance, corners)
                })
                .filter(|r| r.len() >= 3)
                .map(|r| r.into_iter().map(|p| p.to_array()).collect())
                .collect()
        })
        .collect();
    // Through the vertices the winding rule is exact: an island that the offset provably
    // erases leaves nothing, and its curve need not go through the engine.
    let vanishes = |i: usize| {
        corners == Corners::ThroughVertex
            && region[i].holes.is_empty()
            && convex_thinner_than(&region[i].outer, 2.0 * d_outer - VANISH_MARGIN_MM)
    };
    shapes_of(simplify_apart_known(&raw, FillRule::Positive, vanishes))
}

/// The engine's shapes as the offset's region: spikes removed, loops of less than
/// [`MIN_AREA_MM2`] dropped (a shape with its outer loop).
fn shapes_of(united: crate::base::boolean::Paths3) -> Shapes {
    united
        .into_iter()
        .filter_map(|shape| {
            let mut contours = shape
                .into_iter()
                .map(crate::base::geom::contour_from_overlay)
                .map(remove_spikes);
            // The outer boundary decides whether the shape survives; holes that collapse go.
            let outer = contours
                .next()
                .filter(|c| signed_area(c).abs() >= MIN_AREA_MM2)?;
            let holes = contours.filter(|c| signed_area(c).abs() >= MIN_AREA_MM2);
            Some(Shape::new(outer, holes.collect()))
        })
        .collect()
}

/// How much thinner than twice the offset an island must be for [`inset_with`] to drop it
/// unseen: far more than the boolean engine's grid (under 10⁻⁵ mm on a plate), so the
/// engine's rounding cannot leave a loop of any size where the exact result is empty.
const VANISH_MARGIN_MM: f64 = 1e-3;

/// Largest loop (points) [`convex_thinner_than`] measures (its cost is quadratic).
const VANISH_MAX_POINTS: usize = 32;

/// Whether the closed loop `c` (counter-clockwise, material on the left) is convex and
/// narrower than `width` across some edge: no disc of diameter `width` fits in it, so moving
/// its boundary in by width / 2 leaves nothing. Convex: every corner turns left or runs
/// straight on, and the points run up then down in (x, y) order exactly once. The narrowest
/// width of a convex polygon is across one of its edges (the largest distance of a vertex
/// from that edge's line).
pub fn convex_thinner_than(c: &[Point], width: f64) -> bool {
    let n = c.len();
    if !(3..=VANISH_MAX_POINTS).contains(&n) || width <= 0.0 {
        return false;
    }
    let up = |a: Point, b: Point| (b[0], b[1]) > (a[0], a[1]);
    let mut changes = 0;
    for k in 0..n {
        let (a, b, d) = (c[k], c[(k + 1) % n], c[(k + 2) % n]);
        let (u, v) = (b - a, d - b);
        let cross = u[0] * v[1] - u[1] * v[0];
        if a == b || cross < 0.0 || (cross == 0.0 && u.dot(v) <= 0.0) {
            return false;
        }
        changes += usize::from(up(a, b) != up(b, d));
    }
    if changes != 2 {
        return false;
    }
    (0..n).any(|k| {
        let (a, b) = (c[k], c[(k + 1) % n]);
        let len = dist(a, b);
        c.iter().all(|&p| {
            let (u, v) = (b - a, p - a);
            (u[0] * v[1] - u[1] * v[0]) < width * len
        })
    })
}

/// The raw offset curve of one closed loop moved by `d` (≥ 0) to the left of its edges (the
/// material's side: outer loops run counter-clockwise, holes clockwise). Every edge is moved
/// by d; at a reflex corner the moved edges are joined by an arc of radius d around the
/// corner (chords within `tolerance` of it), or, when the corner turns so little that their
/// crossing lies within `tolerance` of that arc, at their crossing; at a convex corner as
/// `corners` says.
pub fn raw_offset(c: &[Point], d: f64, tolerance: f64, corners: Corners) -> Contour {
    let mut pts: Vec<Point> = Vec::with_capacity(c.len());
    for &p in c {
        if pts.last().is_none_or(|&q| q != p) {
            pts.push(p);
        }
    }
    while pts.len() > 1 && pts[0] == *pts.last().expect("non-empty") {
        pts.pop();
    }
    let n = pts.len();
    if n < 3 || d == 0.0 {
        return pts;
    }
    // Unit directions and lengths of the edges.
    let edges: Vec<(Point, f64)> = (0..n)
        .map(|i| {
            let (p, q) = (pts[i], pts[(i + 1) % n]);
            let len = dist(p, q);
            (DVec2::new((q[0] - p[0]) / len, (q[1] - p[1]) / len), len)
        })
        .collect();
    // For reflex corners only (a convex loop needs neither): the chord step of the arcs,
    // d·(1 − cos(step/2)) = tolerance, and the largest turn of a reflex corner whose two moved
    // edges may simply be extended to their crossing, at d / cos(turn/2) from the corner:
    // within the tolerance of the arc.
    let mut reflex: Option<(f64, f64)> = None;
    let mut reflex_consts = || {
        *reflex.get_or_insert_with(|| {
            (
                2.0 * (1.0 - (tolerance / d).min(1.0)).acos(),
                2.0 * (d / (d + tolerance)).acos(),
            )
        })
    };
    let mut out: Contour = Vec::with_capacity(2 * n);
    for i in 0..n {
        // The corner at pts[i], between edge i − 1 (in) and edge i (out).
        let (t0, l0) = edges[(i + n - 1) % n];
        let (t1, l1) = edges[i];
        let p = pts[i];
        let n0 = DVec2::new(-t0[1], t0[0]);
        let n1 = DVec2::new(-t1[1], t1[0]);
        let a = DVec2::new(p[0] + d * n0[0], p[1] + d * n0[1]);
        let b = DVec2::new(p[0] + d * n1[0], p[1] + d * n1[1]);
        let turn = (t0[0] * t1[1] - t0[1] * t1[0]).atan2(t0[0] * t1[0] + t0[1] * t1[1]);
        if turn >= 0.0 {
            // Convex corner (or straight on): the moved edges cross d·tan(turn/2) back along
            // each of them, at the mitre point.
            let mitre = corners == Corners::Miter && {
                let back = d * (0.5 * turn).tan();
                back <= l0 && back <= l1 && turn < MAX_MITER_TURN
            };
            if mitre {
                let k = d / (1.0 + n0[0] * n1[0] + n0[1] * n1[1]);
                out.push(DVec2::new(
                    p[0] + k * (n0[0] + n1[0]),
                    p[1] + k * (n0[1] + n1[1]),
                ));
            } else if turn == 0.0 {
                out.push(a);
            } else {
                out.extend([a, p, b]);
            }
        } else if -turn <= reflex_consts().1 {
            // Reflex corner turning so little that the crossing of the moved edges' lines lies
            // within the tolerance outside the arc: that one point, not the arc's two ends
            // (which would double the vertices of a curve at every offset of a chain).
            let k = d / (1.0 + n0[0] * n1[0] + n0[1] * n1[1]);
            out.push(DVec2::new(
                p[0] + k * (n0[0] + n1[0]),
                p[1] + k * (n0[1] + n1[1]),
            ));
        } else {
            // Reflex corner: the arc around p from a to b, turning clockwise by |turn|.
            out.push(a);
            let parts = (-turn / reflex_consts().0).ceil() as usize;
            let start = n0[1].atan2(n0[0]);
            for k in 1..parts {
                let ang = start + turn * k as f64 / parts as f64;
                out.push(DVec2::new(p[0] + d * ang.cos(), p[1] + d * ang.sin()));
            }
            out.push(b);
        }
    }
    out
}

/// Sharper convex corners than this (radians of turn; 172°) are always joined through their
/// vertex: their mitre point would lie far out (d / cos(turn/2)).
const MAX_MITER_TURN: f64 = 3.0;

/// Two points closer than this on either side of a vertex make that vertex a spike.
const SPIKE_BASE_MM: f64 = 1e-4;
/// Loops enclosing less than this are slivers of rounding, not geometry.
const MIN_AREA_MM2: f64 = 1e-6;

/// Removes zero-width spikes (a vertex whose neighbours coincide within [`SPIKE_BASE_MM`]):
/// the offset engine can leave such a spike running back to the original boundary where two
/// nearly opposite edges meet, and a droplet walk would follow it out of the loop.
pub fn remove_spikes(mut c: Contour) -> Contour {
    let n = c.len();
    // Most loops have no spike: found without the pass' bookkeeping.
    if n >= 3 && (0..n).all(|i| dist(c[(i + n - 1) % n], c[(i + 1) % n]) >= SPIKE_BASE_MM) {
        return c;
    }
    let mut changed = true;
    while changed && c.len() >= 3 {
        changed = false;
        let n = c.len();
        let mut keep = vec![true; n];
        let mut i = 0;
        while i < n {
            let (p, q) = ((i + n - 1) % n, (i + 1) % n);
            if keep[p] && keep[i] && dist(c[p], c[q]) < SPIKE_BASE_MM {
                // Drop the tip and one of the coinciding base points.
                keep[i] = false;
                keep[q] = false;
                changed = true;
                i += 2;
            } else {
                i += 1;
            }
        }
        if changed {
            c = c
                .into_iter()
                .zip(keep)
                .filter(|(_, k)| *k)
                .map(|(p, _)| p)
                .collect();
        }
    }
    if c.len() < 3 { Vec::new() } else { c }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::boolean::simplify_apart;
    use crate::base::testing::random;

    /// A convex island around `c`: a square (its sides split at random points, straight on)
    /// or the points of a circle of radius `r` at sorted random angles.
    fn island(seed: &mut u64, c: Point, r: f64) -> Contour {
        if random(seed) < 0.5 {
            let corners = [[-r, -r], [r, -r], [r, r], [-r, r]].map(|p| c + DVec2::from(p));
            let mut out = Vec::new();
            for k in 0..4 {
                let (a, b) = (corners[k], corners[(k + 1) % 4]);
                out.push(a);
                if random(seed) < 0.5 {
                    out.push(a + (b - a) * (0.2 + 0.6 * random(seed)));
                }
            }
            out
        } else {
            let k = 3 + (random(seed) * 12.0) as usize;
            let mut angles: Vec<f64> = (0..k)
                .map(|_| random(seed) * std::f64::consts::TAU)
                .collect();
            angles.sort_by(f64::total_cmp);
            angles
                .into_iter()
                .map(|a| c + DVec2::new(a.cos(), a.sin()) * r)
                .collect()
        }
    }

    #[test]
    fn islands_that_vanish_are_dropped_as_the_engine_drops_them() {
        // Rows of convex islands, offset through their vertices by distances around half
        // their width: the result is the one of every curve through the engine.
        let mut seed = 0x51ed_270b_a3c4_d9e5u64;
        let mut dropped = 0;
        for case in 0..120 {
            let n = 1 + (random(&mut seed) * 30.0) as usize;
            let r = 0.1 + random(&mut seed);
            let region: Shapes = (0..n)
                .map(|i| {
                    let c = DVec2::new((i % 6) as f64 * 3.0 * r, (i / 6) as f64 * 3.0 * r);
                    let size = r * (0.5 + random(&mut seed));
                    Shape::new(island(&mut seed, c, size), vec![])
                })
                .collect();
            let d = r * (0.3 + 1.2 * random(&mut seed));
            let tolerance = CHORD_TOLERANCE_MM;
            let raw: Vec<Paths> = region
                .iter()
                .map(|shape| {
                    let r = raw_offset(&shape.outer, d, tolerance, Corners::ThroughVertex);
                    vec![r.iter().map(|p| p.to_array()).collect()]
                })
                .collect();
            let want = shapes_of(simplify_apart(&raw, FillRule::Positive));
            let got = inset_with(&region, d, d, tolerance, Corners::ThroughVertex);
            assert_eq!(got, want, "case {case}");
            dropped += region
                .iter()
                .filter(|s| convex_thinner_than(&s.outer, 2.0 * d - VANISH_MARGIN_MM))
                .count();
        }
        assert!(dropped > 300, "{dropped}");
    }

    #[test]
    fn the_edge_grid_finds_what_every_edge_finds() {
        // Regions of random loops (outer loops and holes, long and short edges, some far
        // outside the rest), points in and around them: the grid's answer is the one of
        // testing every edge, for small and large reaches and either limit the smaller.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut hits = 0;
        for case in 0..200 {
            let loops = 1 + (random(&mut seed) * 6.0) as usize;
            let scale = if case % 4 == 0 { 100.0 } else { 5.0 };
            let region: Shapes = (0..loops)
                .map(|_| {
                    let c = DVec2::new(random(&mut seed), random(&mut seed)) * scale;
                    let r = 0.05 + random(&mut seed) * 2.0;
                    let outer = island(&mut seed, c, r);
                    let holes = if random(&mut seed) < 0.5 {
                        let mut h = island(&mut seed, c, r * 0.5);
                        h.reverse();
                        vec![h]
                    } else {
                        vec![]
                    };
                    Shape::new(outer, holes)
                })
                .collect();
            let (d_outer, d_hole) = (random(&mut seed) * 0.6, random(&mut seed) * 0.6);
            let reach = d_outer.max(d_hole);
            let boundary = Boundary::new(&region);
            for _ in 0..50 {
                let p = DVec2::new(random(&mut seed), random(&mut seed)) * (scale + 4.0)
                    - DVec2::splat(2.0);
                let mut want = false;
                for shape in &region {
                    for (hole, c) in shape.contours_with_hole() {
                        let d = (if hole { d_hole } else { d_outer } - 2.0 * CHORD_TOLERANCE_MM)
                            .max(0.0);
                        for k in 0..c.len() {
                            want |= segment_distance2(p, c[k], c[(k + 1) % c.len()]) < d * d;
                        }
                    }
                }
                assert_eq!(boundary.keeps([p], d_outer, d_hole), !want, "case {case}");
                hits += usize::from(want);
            }
            // The grid is made for the first reach; a larger one later still finds all.
            let far = DVec2::new(random(&mut seed), random(&mut seed)) * scale;
            let big = reach + 3.0;
            let mut want = false;
            for c in region.iter().flat_map(|s| s.contours()) {
                for k in 0..c.len() {
                    want |= segment_distance2(far, c[k], c[(k + 1) % c.len()])
                        < (big - 2.0 * CHORD_TOLERANCE_MM).powi(2);
                }
            }
            assert_eq!(boundary.keeps([far], big, big), !want, "case {case}");
        }
        assert!(hits > 500, "{hits}");
    }

    #[test]
    fn only_convex_loops_count_as_thin() {
        let sq = |w: f64| -> Contour {
            [[0.0, 0.0], [w, 0.0], [w, w], [0.0, w]]
                .map(DVec2::from)
                .into()
        };
        assert!(convex_thinner_than(&sq(0.5), 0.51));
        assert!(!convex_thinner_than(&sq(0.5), 0.5));
        // Clockwise, or an L (a reflex corner), or a spike back along an edge: not measured.
        let mut cw = sq(0.5);
        cw.reverse();
        assert!(!convex_thinner_than(&cw, 10.0));
        let l: Contour = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 0.2],
            [0.2, 0.2],
            [0.2, 2.0],
            [0.0, 2.0],
        ]
        .map(DVec2::from)
        .into();
        assert!(!convex_thinner_than(&l, 1.0));
        let spike: Contour = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.5, 0.0], [1.0, 1.0]]
            .map(DVec2::from)
            .into();
        assert!(!convex_thinner_than(&spike, 10.0));
    }
}
