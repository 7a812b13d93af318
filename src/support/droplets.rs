//! The support's droplet-level pass (SPEC.md "Two discharge units"; docs/support.md): after
//! every layer is planned with its support region, find the droplets the layer below does not
//! support by the overhang rule and add single unit-1 droplets under them, top-down, so that
//! the rule holds for every droplet of the code (the added droplets need support too).
//!
//! The region form ([`crate::support`]) leaves a few droplets unsupported: where a support
//! region is a sliver, or where a part droplet lies beyond the edge of the part below by less
//! than the limit but the droplets below sit B/2 inside that edge. The pass works on droplet
//! centres only (hash grids of the layers' droplets), so it is cheap.

use crate::base::geom::{
    DVec2, Point, Shapes, all_contours, dist, round_output, segment_distance2,
};
use crate::base::settings::Settings;
use crate::base::spatial::EdgeIndex;
use crate::slicing::plan::{Move, MoveKind};
use std::collections::HashMap;

/// A droplet centre and its width (B or B₁).
pub type Droplet = (Point, f64);

/// An axis-aligned box: its least and greatest corners.
pub type Bounds = (Point, Point);

/// `f(i, within, out)` appends layer i's droplets (in the box `within` if given) to `out`.
pub type LayerDroplets<'a> = &'a (dyn Fn(usize, Option<Bounds>, &mut Vec<Droplet>) + Sync);

/// Centres kept this much inside the rule's distance, so rounding the written positions
/// cannot break it (positions are rounded to 0.05 µm).
const MARGIN_MM: f64 = 1e-3;

/// Droplets of a layer in cells over their bounding box (counts, then the droplets sorted by
/// cell), cells at least the rule's distance.
struct Grid {
    cell: f64,
    min: Point,
    nx: i64,
    ny: i64,
    offsets: Vec<u32>,
    items: Vec<Droplet>,
    /// Each droplet's cell while the grid is filled (kept for the next fill).
    keys: Vec<u32>,
}

impl Grid {
    fn new(cell: f64, droplets: &[Droplet]) -> Grid {
        let mut g = Grid {
            cell,
            min: DVec2::ZERO,
            nx: 0,
            ny: 0,
            offsets: Vec::new(),
            items: Vec::new(),
            keys: Vec::new(),
        };
        g.fill(cell, droplets);
        g
    }

    /// The grid of `droplets` in place of this one's (its buffers reused).
    fn fill(&mut self, cell: f64, droplets: &[Droplet]) {
        self.fill_where(cell, droplets, |_| true);
    }

    /// The grid of the droplets `keep` accepts in place of this one's.
    fn fill_where(&mut self, cell: f64, droplets: &[Droplet], keep: impl Fn(&Droplet) -> bool) {
        let mut min = DVec2::INFINITY;
        let mut max = DVec2::NEG_INFINITY;
        let mut count = 0usize;
        for d in droplets.iter().filter(|d| keep(d)) {
            min = min.min(d.0);
            max = max.max(d.0);
            count += 1;
        }
        if count == 0 {
            (min, max) = (DVec2::ZERO, DVec2::ZERO);
        }
        // About one cell per droplet at most, however large the layer: memory stays
        // proportional to the droplets (larger cells still hold every droplet within reach).
        let spread = ((max.x - min.x) * (max.y - min.y) / count.max(1) as f64).sqrt();
        self.cell = cell.max(spread);
        self.min = min;
        self.nx = ((max.x - min.x) / self.cell).floor() as i64 + 1;
        self.ny = ((max.y - min.y) / self.cell).floor() as i64 + 1;
        let nx = self.nx;
        self.offsets.clear();
        self.offsets.resize((nx * self.ny) as usize + 1, 0);
        self.items.clear();
        self.items.resize(count, (DVec2::ZERO, 0.0));
        let mut keys = std::mem::take(&mut self.keys);
        keys.clear();
        keys.extend(droplets.iter().filter(|d| keep(d)).map(|(p, _)| {
            let (x, y) = self.key(*p);
            (y * nx + x) as u32
        }));
        for &k in &keys {
            self.offsets[k as usize + 1] += 1;
        }
        for i in 1..self.offsets.len() {
            self.offsets[i] += self.offsets[i - 1];
        }
        // Each cell's droplets in their order, filled from the cell's start (moved along as
        // they are placed, then moved back).
        for (d, &k) in droplets.iter().filter(|d| keep(d)).zip(&keys) {
            let slot = &mut self.offsets[k as usize];
            self.items[*slot as usize] = *d;
            *slot += 1;
        }
        for i in (1..self.offsets.len()).rev() {
            self.offsets[i] = self.offsets[i - 1];
        }
        self.offsets[0] = 0;
        self.keys = keys;
    }

    fn key(&self, p: Point) -> (i64, i64) {
        (
            floor((p.x - self.min.x) / self.cell),
            floor((p.y - self.min.y) / self.cell),
        )
    }

    /// A droplet d within `reach(d's width)` of `p` (reach ≤ the cell), if any.
    /// The cells are searched from p's own outwards (the question is whether there is one).
    fn find_within(&self, p: Point, reach: impl Fn(f64) -> f64) -> Option<Droplet> {
        let (cx, cy) = self.key(p);
        let search = |x: i64, y: i64| {
            let c = (y * self.nx + x) as usize;
            let cell = &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize];
            cell.iter()
                .find(|&&(q, w)| {
                    let r = reach(w);
                    (p - q).length_squared() <= r * r
                })
                .copied()
        };
        // p's own cell lies in the grid (the grid covers every droplet, p may lie outside).
        let own = (0..self.nx).contains(&cx) && (0..self.ny).contains(&cy);
        if own && let Some(d) = search(cx, cy) {
            return Some(d);
        }
        for y in (cy - 1).max(0)..=(cy + 1).min(self.ny - 1) {
            for x in (cx - 1).max(0)..=(cx + 1).min(self.nx - 1) {
                if own && x == cx && y == cy {
                    continue;
                }
                if let Some(d) = search(x, y) {
                    return Some(d);
                }
            }
        }
        None
    }
}

/// A layer's droplets for "is there one within reach": one [`Grid`] when B and B₁ differ by at
/// most twice, else one grid per width, each in cells of its own reach (in one grid with cells
/// of the wider droplets' reach, each cell would hold (B₁/B)² of the narrow ones, all scanned by
/// every query). The answer is the same either way.
struct Below {
    grids: Vec<Grid>,
    narrow: f64,
    wide: f64,
}

impl Below {
    fn new(b: f64, b1: f64, reach: impl Fn(f64) -> f64, droplets: &[Droplet]) -> Below {
        let (narrow, wide) = (b.min(b1), b.max(b1));
        let split = wide > 2.0 * narrow;
        let grids = if split {
            vec![Grid::new(reach(narrow), &[]), Grid::new(reach(wide), &[])]
        } else {
            vec![Grid::new(reach(wide), &[])]
        };
        let mut below = Below {
            grids,
            narrow,
            wide,
        };
        below.fill(&reach, droplets);
        below
    }

    /// The index of `droplets` in place of this one's (its buffers reused).
    fn fill(&mut self, reach: impl Fn(f64) -> f64, droplets: &[Droplet]) {
        if self.grids.len() == 1 {
            self.grids[0].fill(reach(self.wide), droplets);
            return;
        }
        // Each grid's cells are at least the reach of every droplet in it.
        let narrow = self.narrow;
        let wide = droplets
            .iter()
            .filter(|d| d.1 > narrow)
            .fold(reach(self.wide), |c, d| c.max(reach(d.1)));
        self.grids[0].fill_where(reach(narrow), droplets, |d| d.1 <= narrow);
        self.grids[1].fill_where(wide, droplets, |d| d.1 > narrow);
    }

    /// A droplet d within `reach(d's width)` of `p`, if any.
    fn find_within(&self, p: Point, reach: impl Fn(f64) -> f64) -> Option<Droplet> {
        self.grids.iter().find_map(|g| g.find_within(p, &reach))
    }
}

/// ⌊x⌋ for |x| < 2⁵¹ (a grid's cells; this runs per droplet): without a call into the maths
/// library, nor the range checks of a float-to-integer cast. Adding 1.5·2⁵² rounds x to the
/// nearest integer, which the sum's low bits then hold.
fn floor(x: f64) -> i64 {
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let y = x + SHIFT;
    let t = (y.to_bits() as i64).wrapping_sub(SHIFT.to_bits() as i64);
    if y - SHIFT > x { t - 1 } else { t }
}

/// Every droplet a layer's moves set, with its width (B, or B₁ for unit 1's moves), in the
/// order they are set; with `within = Some((lo, hi))` only those in that box (a line whose
/// box misses it is not walked).
pub fn droplets_of(
    moves: &[Move],
    b: f64,
    b1: f64,
    within: Option<Bounds>,
    out: &mut Vec<Droplet>,
) {
    let mut at = Point::ZERO;
    let inside = |p: Point| within.is_none_or(|(lo, hi)| p.cmpge(lo).all() && p.cmple(hi).all());
    for m in moves {
        let w = if m.unit == 1 { b1 } else { b };
        match m.kind {
            MoveKind::Droplet if inside(m.to) => out.push((m.to, w)),
            MoveKind::Line => {
                let meets = within.is_none_or(|(lo, hi)| {
                    at.min(m.to).cmple(hi).all() && at.max(m.to).cmpge(lo).all()
                });
                if meets {
                    out.extend(
                        crate::base::geom::line_droplets(at, m.to, w)
                            .filter(|&p| inside(p))
                            .map(|p| (p, w)),
                    );
                }
            }
            _ => {}
        }
        at = m.to;
    }
}

/// Droplets added to a layer, in a hash grid (few).
struct Added {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<Point>>,
}

impl Added {
    fn key(&self, p: Point) -> (i64, i64) {
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    fn add(&mut self, p: Point) {
        let k = self.key(p);
        self.cells.entry(k).or_default().push(p);
    }

    /// Whether an added droplet lies within `r` (≤ the cell) of `p`.
    fn any_within(&self, p: Point, r: f64) -> bool {
        let (cx, cy) = self.key(p);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                self.cells
                    .get(&(cx + dx, cy + dy))
                    .is_some_and(|v| v.iter().any(|&q| (p - q).length_squared() <= r * r))
            })
        })
    }
}

/// Whether `p` lies inside `region` (non-zero winding of its loops).
fn inside(region: &Shapes, p: Point) -> bool {
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

/// `points` in the order of a greedy walk from `from`: each time the nearest point left (by
/// [`dist`]; of equal ones, the first in a list the walk takes points from by `swap_remove`).
/// The same order as the plain scan of every point left at every step, found in a grid of
/// cells around the walk's place (a layer may get hundreds of thousands of added droplets).
pub fn nearest_first(points: &[Point], from: Point) -> Vec<Point> {
    let n = points.len();
    let mut out = Vec::with_capacity(n);
    if n <= 64 {
        let mut left = points.to_vec();
        let mut at = from;
        while !left.is_empty() {
            let next = (0..left.len())
                .min_by(|&i, &j| dist(at, left[i]).total_cmp(&dist(at, left[j])))
                .expect("non-empty");
            at = left.swap_remove(next);
            out.push(at);
        }
        return out;
    }
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let size = hi - lo;
    // About two points per cell.
    let cell = (size.x * size.y * 2.0 / n as f64)
        .sqrt()
        .max(size.x.max(size.y) / 4096.0)
        .max(1e-9);
    let nx = (size.x / cell).floor() as i64 + 1;
    let ny = (size.y / cell).floor() as i64 + 1;
    let key = |p: Point| (floor((p.x - lo.x) / cell), floor((p.y - lo.y) / cell));
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); (nx * ny) as usize];
    for (i, p) in points.iter().enumerate() {
        let (x, y) = key(*p);
        cells[(y.clamp(0, ny - 1) * nx + x.clamp(0, nx - 1)) as usize].push(i as u32);
    }
    // The list the plain scan would hold: slot → point, point → slot.
    let mut slots: Vec<u32> = (0..n as u32).collect();
    let mut slot_of: Vec<u32> = (0..n as u32).collect();
    let mut at = from;
    for _ in 0..n {
        let (cx, cy) = key(at);
        // Rings of cells around at's cell (which may lie outside the grid), from the first
        // that meets the grid; a point of ring r + 1 lies at least r cells away.
        let gap = |c: i64, hi: i64| if c < 0 { -c } else { (c - hi + 1).max(0) };
        let first = gap(cx, nx).max(gap(cy, ny));
        let last = (cx.max(nx - 1 - cx)).max(cy.max(ny - 1 - cy)).max(first);
        let mut best: Option<(f64, u32, u32)> = None;
        let mut r = first;
        while r <= last {
            let mut visit = |x: i64, y: i64| {
                if x < 0 || y < 0 || x >= nx || y >= ny {
                    return;
                }
                for &i in &cells[(y * nx + x) as usize] {
                    let d = dist(at, points[i as usize]);
                    let slot = slot_of[i as usize];
                    let better = match best {
                        None => true,
                        Some((bd, bs, _)) => d.total_cmp(&bd).then(slot.cmp(&bs)).is_lt(),
                    };
                    if better {
                        best = Some((d, slot, i));
                    }
                }
            };
            if r == 0 {
                visit(cx, cy);
            } else {
                for x in (cx - r).max(-1)..=(cx + r).min(nx) {
                    visit(x, cy - r);
                    visit(x, cy + r);
                }
                for y in (cy - r + 1).max(-1)..=(cy + r - 1).min(ny) {
                    visit(cx - r, y);
                    visit(cx + r, y);
                }
            }
            // Points of the rings beyond lie more than r cells away (less a margin for
            // rounding): stop when the best is nearer.
            if let Some((d, _, _)) = best
                && d < (r as f64 * cell) * (1.0 - 1e-9) - 1e-12
            {
                break;
            }
            r += 1;
        }
        let (_, slot, i) = best.expect("a point is left");
        // swap_remove of the plain scan's list.
        let last_point = *slots.last().expect("non-empty");
        slots.swap_remove(slot as usize);
        if (slot as usize) < slots.len() {
            slot_of[last_point as usize] = slot;
        }
        let p = points[i as usize];
        let (x, y) = key(p);
        let c = &mut cells[(y.clamp(0, ny - 1) * nx + x.clamp(0, nx - 1)) as usize];
        c.retain(|&j| j != i);
        out.push(p);
        at = p;
    }
    out
}

/// Candidate places for a support droplet under `c`: c itself, then rings around it out to
/// `r` (nearest first).
fn candidates(c: Point, r: f64) -> impl Iterator<Item = Point> {
    std::iter::once(c).chain((1..=4).flat_map(move |ring| {
        let rr = r * ring as f64 / 4.0;
        let n = 8 * ring;
        (0..n).map(move |k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            c + rr * DVec2::new(a.cos(), a.sin())
        })
    }))
}

/// What the pass did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PassFigures {
    /// Unit-1 droplets added.
    pub added: usize,
    /// Droplets left unsupported: no place within the rule outside the part and its gap.
    pub unplaceable: usize,
}

/// The unit-1 droplets to add to each layer so that every droplet above the first layer is
/// supported: `droplets(i, within, out)` appends layer i's planned droplets (both units; in
/// the box `within` if given, [`droplets_of`]) to `out`
/// (about once per layer, in runs of layers on all cores; again for a layer under added
/// droplets), so that no layer's droplets need be kept; `regions[i]` is its part's region. Works top-down; an added droplet needs support from the layer below as
/// any other. Support droplets keep `support_gap_xy`·B from the part's region; a droplet with
/// no such place within the rule stays unsupported (counted). With `support_gap_z` > 0 the
/// support deliberately stops below overhangs, and the pass adds nothing.
pub fn complete(
    droplets: LayerDroplets,
    regions: &[Shapes],
    s: &Settings,
) -> (Vec<Vec<Point>>, PassFigures) {
    let n = regions.len();
    let mut extra: Vec<Vec<Point>> = vec![Vec::new(); n];
    let mut figures = PassFigures::default();
    if n < 2 || s.support_gap_z > 0 {
        return (extra, figures);
    }
    let b = s.droplet_width();
    let b1 = s.unit1_droplet_width();
    let limit = s.overhang_limit * b;
    let reach = |w: f64| w / 2.0 + limit;
    let cell = reach(b.max(b1));
    // Layer i's droplets that layer i − 1's planned droplets leave unsupported: runs of
    // consecutive layers on all cores, each layer's droplets listed and put in a grid once
    // within a run (the grid of layer i then checks layer i + 1).
    const RUN: usize = 8;
    let runs = crate::base::parallel::par_map((n - 1).div_ceil(RUN), &|r| {
        let (first, end) = (1 + r * RUN, (1 + (r + 1) * RUN).min(n));
        let mut buf = Vec::new();
        droplets(first - 1, None, &mut buf);
        let mut below = Below::new(b, b1, reach, &buf);
        let mut out = Vec::with_capacity(end - first);
        for i in first..end {
            buf.clear();
            droplets(i, None, &mut buf);
            // Consecutive droplets are neighbours: the droplet below that supported the last
            // one most often supports the next.
            let mut last: Option<Droplet> = None;
            let mut open = Vec::new();
            for &(p, w) in &buf {
                if let Some((q, wq)) = last {
                    let r = reach(wq);
                    if (p - q).length_squared() <= r * r {
                        continue;
                    }
                }
                match below.find_within(p, reach) {
                    Some(d) => last = Some(d),
                    None => open.push((p, w)),
                }
            }
            out.push(open);
            if i + 1 < end {
                below.fill(reach, &buf);
            }
        }
        out
    });
    let open: Vec<Vec<Droplet>> = std::iter::once(Vec::new())
        .chain(runs.into_iter().flatten())
        .collect();
    let gap = s.support_gap_xy * b;
    let place = reach(b1) - MARGIN_MM;
    let mut buf = Vec::new();
    // Top-down: layer i's unsupported droplets (planned or added) get droplets in layer i − 1.
    for i in (1..n).rev() {
        let mut todo: Vec<Droplet> = open[i].clone();
        if !extra[i].is_empty() {
            // The droplets added to layer i against layer i − 1's planned droplets: few, so
            // only that layer's droplets within reach of their box are listed, and scanned
            // once (a grid only for many).
            let adds: Vec<Droplet> = extra[i].iter().map(|&p| (p, b1)).collect();
            let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
            for (p, _) in &adds {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            let (lo, hi) = (lo - DVec2::splat(cell), hi + DVec2::splat(cell));
            buf.clear();
            droplets(i - 1, Some((lo, hi)), &mut buf);
            let mut held = vec![false; adds.len()];
            if adds.len() > 16 {
                let below = Below::new(b, b1, reach, &buf);
                for (h, &(p, _)) in held.iter_mut().zip(&adds) {
                    *h = below.find_within(p, reach).is_some();
                }
            } else {
                for &(q, w) in &buf {
                    let r = reach(w);
                    for (h, &(p, _)) in held.iter_mut().zip(&adds) {
                        *h = *h || (p - q).length_squared() <= r * r;
                    }
                }
            }
            todo.extend(
                adds.iter()
                    .zip(&held)
                    .filter(|(_, h)| !**h)
                    .map(|(d, _)| *d),
            );
        }
        if todo.is_empty() {
            continue;
        }
        let region = &regions[i - 1];
        // The gap is kept from the part's edges near the candidates only (within the rule's
        // reach and the gap of the droplets to support).
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for (p, _) in &todo {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let margin = DVec2::splat(place + gap.max(0.0) + MARGIN_MM);
        let (lo, hi) = (lo - margin, hi + margin);
        let mut edges = edges_of(region);
        edges.retain(|&(a, e)| a.min(e).cmple(hi).all() && a.max(e).cmpge(lo).all());
        let clear = Clearance::new(&edges, gap, b);
        let mut added = Added {
            cell,
            cells: HashMap::new(),
        };
        for &(c, _) in &todo {
            // Within the rule of an added droplet: within B₁/2 + limit.
            if added.any_within(c, reach(b1) - MARGIN_MM) {
                continue;
            }
            // Outside the part and its gap; failing that, outside the part (in the gap).
            let found = candidates(c, place)
                .find(|&p| clear.keeps(p) && !inside(region, p))
                .or_else(|| candidates(c, place).find(|&p| !inside(region, p)));
            // As written: the layer below checks the rounded position.
            match found.map(round_output) {
                Some(p) => {
                    debug_assert!(dist(p, c) <= reach(b1));
                    added.add(p);
                    extra[i - 1].push(p);
                    figures.added += 1;
                }
                None => figures.unplaceable += 1,
            }
        }
    }
    (extra, figures)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::Shape;
    use crate::base::geom::square;

    fn run(
        droplets: &[Vec<Droplet>],
        regions: &[Shapes],
        s: &Settings,
    ) -> (Vec<Vec<Point>>, PassFigures) {
        assert_eq!(droplets.len(), regions.len());
        complete(
            &|i, within: Option<Bounds>, out: &mut Vec<Droplet>| {
                out.extend(droplets[i].iter().filter(|(p, _)| {
                    within.is_none_or(|(lo, hi)| p.cmpge(lo).all() && p.cmple(hi).all())
                }))
            },
            regions,
            s,
        )
    }

    #[test]
    fn floor_is_the_floor() {
        for x in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.999_999_999,
            -1e-300,
            1e-300,
            123_456.789,
            -123_456.789,
            2_251_799_813_685_247.0,
            -2_251_799_813_685_247.5,
            f64::EPSILON,
            1.0 - f64::EPSILON / 2.0,
            -(1.0 - f64::EPSILON / 2.0),
        ] {
            assert_eq!(floor(x), x.floor() as i64, "{x}");
        }
        let mut v = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..100_000 {
            v ^= v << 13;
            v ^= v >> 7;
            v ^= v << 17;
            let x = ((v >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e6;
            assert_eq!(floor(x), x.floor() as i64, "{x}");
        }
    }

    #[test]
    fn the_grid_finds_a_droplet_within_reach_as_a_scan_of_every_droplet_does() {
        // Droplets of two widths in clusters and a sparse spread, queries inside and outside
        // the grid and right at the reach: the grid answers "is there one" as a full scan.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut random = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (b, b1, limit) = (0.208, 0.15, 0.104);
        let reach = |w: f64| w / 2.0 + limit;
        let (mut found, mut missed) = (0, 0);
        for case in 0..30 {
            let spread = if case % 2 == 0 { 3.0 } else { 40.0 };
            let droplets: Vec<Droplet> = (0..(case * 37 % 400))
                .map(|k| {
                    let w = if k % 3 == 0 { b1 } else { b };
                    (DVec2::new(random() * spread, random() * spread / 2.0), w)
                })
                .collect();
            let grid = Grid::new(reach(b), &droplets);
            for k in 0..300 {
                let p = if k % 4 == 0 && !droplets.is_empty() {
                    // At the reach of a droplet, in a random direction.
                    let (q, w) = droplets[k % droplets.len()];
                    let a = random() * std::f64::consts::TAU;
                    q + reach(w) * DVec2::new(a.cos(), a.sin())
                } else {
                    DVec2::new(
                        random() * 1.2 * spread - 0.1 * spread,
                        random() * spread - 1.0,
                    )
                };
                let scan = droplets.iter().any(|&(q, w)| {
                    let r = reach(w);
                    (p - q).length_squared() <= r * r
                });
                let got = grid.find_within(p, reach);
                assert_eq!(got.is_some(), scan, "case {case} query {k} at {p}");
                if let Some((q, w)) = got {
                    assert!((p - q).length_squared() <= reach(w) * reach(w));
                    found += 1;
                } else {
                    missed += 1;
                }
            }
        }
        assert!(found > 1000 && missed > 1000, "{found} {missed}");
    }

    #[test]
    fn nearest_first_is_the_plain_greedy_walk() {
        // Clusters, a sparse spread, repeated points and points on a lattice (equal distances:
        // the tie goes to the first in the walk's list), starts inside and far outside.
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut random = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let plain = |points: &[Point], from: Point| {
            let mut left = points.to_vec();
            let mut at = from;
            let mut out = Vec::new();
            while !left.is_empty() {
                let next = (0..left.len())
                    .min_by(|&i, &j| dist(at, left[i]).total_cmp(&dist(at, left[j])))
                    .unwrap();
                at = left.swap_remove(next);
                out.push(at);
            }
            out
        };
        for case in 0..40 {
            let n = [0, 1, 5, 64, 65, 300, 2000][case % 7];
            let points: Vec<Point> = (0..n)
                .map(|k| match case % 4 {
                    0 => DVec2::new(random() * 30.0, random() * 3.0),
                    1 => DVec2::new((k % 17) as f64 * 0.2, (k / 17) as f64 * 0.2),
                    2 => DVec2::new((random() * 6.0).floor(), (random() * 6.0).floor()),
                    _ => DVec2::new(random(), random()) * if k % 2 == 0 { 0.01 } else { 50.0 },
                })
                .collect();
            for from in [
                DVec2::new(0.1, 0.1),
                DVec2::new(-500.0, 40.0),
                DVec2::new(7.0, 2.0),
            ] {
                assert_eq!(
                    nearest_first(&points, from),
                    plain(&points, from),
                    "case {case}"
                );
            }
        }
    }

    #[test]
    fn a_droplet_over_nothing_gets_a_column_down_to_the_plate() {
        let s = Settings::default();
        let b = s.droplet_width();
        // Three layers: a droplet at (5, 5) on layer 2, a part (a square far away) on each.
        let part = square(0.0, 0.0, 2.0);
        let far = (DVec2::new(1.0, 1.0), b);
        let droplets = vec![vec![far], vec![far], vec![far, (DVec2::new(5.0, 5.0), b)]];
        let regions = vec![part.clone(), part.clone(), part];
        let (extra, figures) = run(&droplets, &regions, &s);
        assert_eq!(figures.unplaceable, 0);
        // One droplet under it on layer 1 and one under that on layer 0.
        assert_eq!(extra[2].len(), 0);
        assert_eq!(extra[1], vec![DVec2::new(5.0, 5.0)]);
        assert_eq!(extra[0], vec![DVec2::new(5.0, 5.0)]);
    }

    #[test]
    fn added_droplets_keep_the_gap_from_the_part() {
        let s = Settings::default();
        let b = s.droplet_width();
        let gap = s.support_gap_xy * b;
        // Layer 0: a 2 mm square; layer 1: a droplet just beyond its edge, unsupported by the
        // droplet far inside the square.
        let part = square(0.0, 0.0, 2.0);
        let c = DVec2::new(2.0 + 0.2 * b, 1.0);
        let droplets = vec![vec![(DVec2::new(0.5, 1.0), b)], vec![(c, b)]];
        let regions = vec![part.clone(), Shapes::new()];
        let (extra, figures) = run(&droplets, &regions, &s);
        assert_eq!(figures.added, 1);
        let p = extra[0][0];
        assert!(p.x >= 2.0 + gap - 1e-9, "{p}");
        assert!(dist(p, c) <= b1_reach(&s), "{p}");
    }

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

    fn b1_reach(s: &Settings) -> f64 {
        s.unit1_droplet_width() / 2.0 + s.overhang_limit * s.droplet_width()
    }

    #[test]
    fn supported_droplets_need_nothing_and_a_gap_z_adds_nothing() {
        let s = Settings::default();
        let b = s.droplet_width();
        let d = |x: f64| (DVec2::new(x, 0.0), b);
        let droplets = vec![vec![d(0.0)], vec![d(0.9 * b)], vec![d(1.8 * b)]];
        let regions = vec![Shapes::new(); 3];
        let (extra, figures) = run(&droplets, &regions, &s);
        assert!(extra.iter().all(|e| e.is_empty()));
        assert_eq!(figures, PassFigures::default());
        let far = vec![vec![d(0.0)], vec![d(5.0)]];
        let gap_z = Settings {
            support_gap_z: 1,
            ..s
        };
        let (extra, _) = run(&far, &regions[..2], &gap_z);
        assert!(extra.iter().all(|e| e.is_empty()));
    }
}
