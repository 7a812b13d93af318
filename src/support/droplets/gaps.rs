//! Distances to a layer region's boundary for the support: inside tests, its edges, the
//! clearance of single points ([`Clearance`]) and of hatch lines ([`LineGaps`]).

use super::grid::floor;
use crate::base::geom::{DVec2, Point, Shapes, all_contours, dist, segment_distance2};
use crate::base::spatial::EdgeIndex;

/// Whether `p` lies inside `region` (non-zero winding of its loops).
pub(super) fn inside(region: &Shapes, p: Point) -> bool {
    let mut winding = 0i32;
    for c in all_contours(region) {
        for k in 0..c.len() {
            let (a, b) = (c[k], c[(k + 1) % c.len()]);
            if (a[1] <= p[1]) != (b[1] <= p[1]) {
                let t = (p[1] - a[1]) / (b[1] - a[1]);
                if a[0] + t * (b[0] - a[0]) > p[0] {
                    winding += if b[1] > a[1] { 1 } else { -1 };
                }
            }
        }
    }
    winding != 0
}

/// A region's boundary edges.
pub fn edges_of(region: &Shapes) -> Vec<(Point, Point)> {
    all_contours(region)
        .flat_map(|c| (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()])))
        .collect()
}

/// Whether points keep `gap` from a region's boundary (edges from [`edges_of`]).
pub struct Clearance<'a> {
    edges: &'a [(Point, Point)],
    index: EdgeIndex<'a>,
    gap: f64,
}

impl<'a> Clearance<'a> {
    pub fn new(edges: &'a [(Point, Point)], gap: f64, cell: f64) -> Clearance<'a> {
        Clearance {
            edges,
            index: EdgeIndex::new(edges, cell.max(gap).max(1e-3)),
            gap,
        }
    }

    /// No edge closer than the gap to `p`.
    pub fn keeps(&self, p: Point) -> bool {
        let g2 = self.gap * self.gap;
        self.gap <= 0.0
            || !self.index.any_near(p, self.gap, |e| {
                let (a, b) = self.edges[e];
                segment_distance2(p, a, b) < g2
            })
    }
}

/// The parts of parallel lines (a layer's support hatch) closer than a gap to a region's
/// boundary, as intervals along each line: each boundary edge's capsule (the points within the
/// gap of it) cuts a line in one interval. Edges are sorted into bands across the lines, so a
/// line meets only the edges of its band.
pub struct LineGaps<'a> {
    edges: &'a [(Point, Point)],
    /// Across the lines: y = −sin·x + cos·y of the hatch direction.
    sin: f64,
    cos: f64,
    band: f64,
    first: i64,
    /// Band k's edges: `order[starts[k]..starts[k + 1]]`.
    starts: Vec<u32>,
    order: Vec<u32>,
    gap: f64,
}

impl<'a> LineGaps<'a> {
    /// For lines at `angle_deg`, about `spacing` apart.
    pub fn new(
        edges: &'a [(Point, Point)],
        gap: f64,
        angle_deg: f64,
        spacing: f64,
    ) -> LineGaps<'a> {
        let (sin, cos) = crate::base::geom::sin_cos_deg(angle_deg);
        let across = |p: Point| -sin * p.x + cos * p.y;
        let band = spacing.max(gap).max(1e-3);
        let range = |e: &(Point, Point)| {
            let (y0, y1) = (across(e.0), across(e.1));
            (
                floor((y0.min(y1) - gap) / band),
                floor((y0.max(y1) + gap) / band),
            )
        };
        let (mut first, mut last) = (i64::MAX, i64::MIN);
        for e in edges {
            let (a, b) = range(e);
            first = first.min(a);
            last = last.max(b);
        }
        let bands = if edges.is_empty() || gap <= 0.0 {
            0
        } else {
            (last - first + 1) as usize
        };
        let mut starts = vec![0u32; bands + 1];
        if bands > 0 {
            for e in edges {
                let (a, b) = range(e);
                for k in a..=b {
                    starts[(k - first) as usize + 1] += 1;
                }
            }
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        let mut order = vec![0u32; starts.last().map_or(0, |&t| t as usize)];
        let mut fill = starts.clone();
        if bands > 0 {
            for (i, e) in edges.iter().enumerate() {
                let (a, b) = range(e);
                for k in a..=b {
                    let slot = &mut fill[(k - first) as usize];
                    order[*slot as usize] = i as u32;
                    *slot += 1;
                }
            }
        }
        LineGaps {
            edges,
            sin,
            cos,
            band,
            first,
            starts,
            order,
            gap,
        }
    }

    /// The parameters t (distance from `a` along the line a → b) of the points within the gap
    /// of the boundary, as sorted, merged closed intervals, appended to `out` (cleared first).
    pub fn intervals(&self, a: Point, b: Point, out: &mut Vec<(f64, f64)>) {
        out.clear();
        let len = dist(a, b);
        if self.starts.len() < 2 {
            return;
        }
        // A line of one droplet: along the hatch direction.
        let u = if len > 0.0 {
            (b - a) / len
        } else {
            DVec2::new(self.cos, self.sin)
        };
        let k = floor((-self.sin * a.x + self.cos * a.y) / self.band) - self.first;
        if k < 0 || k as usize + 1 >= self.starts.len() {
            return;
        }
        let k = k as usize;
        let g2 = self.gap * self.gap;
        for &e in &self.order[self.starts[k] as usize..self.starts[k + 1] as usize] {
            let (p, q) = self.edges[e as usize];
            // The edge's capsule lies within its ends' span along the line widened by the gap:
            // wholly before the line's start or beyond its end, it gives no interval.
            let (sp, sq) = ((p - a).dot(u), (q - a).dot(u));
            if sp.max(sq) + self.gap < -1e-9 || sp.min(sq) - self.gap > len + 1e-9 {
                continue;
            }
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            // The discs at both ends.
            for c in [p, q] {
                let w = c - a;
                let along = w.dot(u);
                let off = w.perp_dot(u);
                let h2 = g2 - off * off;
                if h2 >= 0.0 {
                    let h = h2.sqrt();
                    lo = lo.min(along - h);
                    hi = hi.max(along + h);
                }
            }
            // The band beside the edge: 0 ≤ (x − p)·v ≤ |pq| and |v × (x − p)| ≤ gap, both
            // linear in t for x = a + t·u.
            let el = dist(p, q);
            if el > 0.0 {
                let v = (q - p) / el;
                let w = a - p;
                let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
                for (base, slope, min, max) in [
                    (w.dot(v), u.dot(v), 0.0, el),
                    (v.perp_dot(w), v.perp_dot(u), -self.gap, self.gap),
                ] {
                    if slope.abs() < 1e-12 {
                        if base < min || base > max {
                            t0 = f64::INFINITY;
                        }
                    } else {
                        let (x0, x1) = ((min - base) / slope, (max - base) / slope);
                        t0 = t0.max(x0.min(x1));
                        t1 = t1.min(x0.max(x1));
                    }
                }
                if t0 <= t1 {
                    lo = lo.min(t0);
                    hi = hi.max(t1);
                }
            }
            if lo <= hi && hi >= 0.0 && lo <= len {
                out.push((lo, hi));
            }
        }
        out.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        let mut merged = 0;
        for j in 0..out.len() {
            if merged > 0 && out[j].0 <= out[merged - 1].1 {
                out[merged - 1].1 = out[merged - 1].1.max(out[j].1);
            } else {
                out[merged] = out[j];
                merged += 1;
            }
        }
        out.truncate(merged);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::Shape;

    #[test]
    fn line_gaps_agree_with_the_distance_to_every_edge() {
        // A square with a square hole, lines at several angles and offsets (and of one
        // point): a point of a line lies in an interval iff some edge is within the gap.
        let outer = [[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]].map(DVec2::from);
        let hole = [[1.0, 1.0], [1.0, 2.0], [2.5, 2.0], [2.5, 1.0]].map(DVec2::from);
        let region = vec![Shape::new(outer.into(), vec![hole.into()])];
        let edges = edges_of(&region);
        let gap = 0.15;
        let mut near = Vec::new();
        let (mut inside_hits, mut outside_hits) = (0, 0);
        for angle in [0.0, 30.0, 45.0, 90.0, 137.0] {
            let gaps = LineGaps::new(&edges, gap, angle, 0.2);
            let (sn, cs) = crate::base::geom::sin_cos_deg(angle);
            let u = DVec2::new(cs, sn);
            let across = DVec2::new(-sn, cs);
            for k in -40..60 {
                let c = DVec2::new(2.0, 1.5) + (k as f64 * 0.0731) * across;
                for len in [0.0, 9.0] {
                    let a = c - 0.5 * len * u;
                    gaps.intervals(a, a + len * u, &mut near);
                    for j in 0..=(len / 0.01) as usize {
                        let t = j as f64 * 0.01;
                        let p = a + t * u;
                        let d = edges
                            .iter()
                            .map(|&(e0, e1)| segment_distance2(p, e0, e1))
                            .fold(f64::INFINITY, f64::min)
                            .sqrt();
                        if (d - gap).abs() < 1e-9 {
                            continue;
                        }
                        let within = near.iter().any(|&(lo, hi)| lo <= t && t <= hi);
                        assert_eq!(within, d <= gap, "angle {angle} line {k} t {t} d {d}");
                        if within {
                            inside_hits += 1;
                        } else {
                            outside_hits += 1;
                        }
                    }
                }
            }
        }
        assert!(inside_hits > 1000 && outside_hits > 1000);
    }
}
