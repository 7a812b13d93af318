//! The support's droplet-level pass (SPEC.md "Two discharge units"; docs/support.md): after
//! every layer is planned with its support region, find the droplets the layer below does not
//! support by the overhang rule and add single unit-1 droplets under them, top-down, so that
//! the rule holds for every droplet of the code (the added droplets need support too).
//!
//! The region form ([`crate::support`]) leaves a few droplets unsupported: where a support
//! region is a sliver, or where a part droplet lies beyond the edge of the part below by less
//! than the limit but the droplets below sit B/2 inside that edge. The pass works on droplet
//! centres only, so it is cheap: a layer below is read as its `G25` lines, kept whole and
//! sorted across the layer's hatch direction ([`Below`]), and its other droplets in a grid; the
//! droplets of a line above are mostly settled at once by a sound certificate (the strips
//! beside the lines below, [`Below::certified`]), and only the rest are searched droplet by
//! droplet.

use crate::geom::{
    DVec2, Point, Shapes, all_contours, dist, line_droplet_count, round_output, segment_distance2,
};
use crate::grid::EdgeIndex;
use crate::plan::{Move, MoveKind};
use crate::settings::Settings;
use std::collections::HashMap;

/// A droplet centre and its width (B or B₁).
pub type Droplet = (Point, f64);

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
}

impl Grid {
    fn new(cell: f64, droplets: &[Droplet]) -> Grid {
        let mut min = DVec2::INFINITY;
        let mut max = DVec2::NEG_INFINITY;
        for (p, _) in droplets {
            min = min.min(*p);
            max = max.max(*p);
        }
        if droplets.is_empty() {
            (min, max) = (DVec2::ZERO, DVec2::ZERO);
        }
        // About one cell per droplet at most, however large the layer: memory stays
        // proportional to the droplets (larger cells still hold every droplet within reach).
        let spread = ((max.x - min.x) * (max.y - min.y) / droplets.len().max(1) as f64).sqrt();
        let cell = cell.max(spread);
        let nx = ((max.x - min.x) / cell).floor() as i64 + 1;
        let ny = ((max.y - min.y) / cell).floor() as i64 + 1;
        let mut g = Grid {
            cell,
            min,
            nx,
            ny,
            offsets: vec![0; (nx * ny) as usize + 1],
            items: vec![(DVec2::ZERO, 0.0); droplets.len()],
        };
        let keys: Vec<usize> = droplets
            .iter()
            .map(|(p, _)| {
                let (x, y) = g.key(*p);
                (y * nx + x) as usize
            })
            .collect();
        for &k in &keys {
            g.offsets[k + 1] += 1;
        }
        for i in 1..g.offsets.len() {
            g.offsets[i] += g.offsets[i - 1];
        }
        let mut fill = g.offsets.clone();
        for (d, &k) in droplets.iter().zip(&keys) {
            g.items[fill[k] as usize] = *d;
            fill[k] += 1;
        }
        g
    }

    fn key(&self, p: Point) -> (i64, i64) {
        (
            floor((p.x - self.min.x) / self.cell),
            floor((p.y - self.min.y) / self.cell),
        )
    }

    /// A droplet d within `reach(d's width)` of `p` (reach ≤ the cell), if any.
    fn find_within(&self, p: Point, reach: impl Fn(f64) -> f64) -> Option<Droplet> {
        let (cx, cy) = self.key(p);
        for y in (cy - 1).max(0)..=(cy + 1).min(self.ny - 1) {
            for x in (cx - 1).max(0)..=(cx + 1).min(self.nx - 1) {
                let c = (y * self.nx + x) as usize;
                let cell = &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize];
                if let Some(&d) = cell.iter().find(|&&(q, w)| {
                    let r = reach(w);
                    (p - q).length_squared() <= r * r
                }) {
                    return Some(d);
                }
            }
        }
        None
    }
}

/// ⌊x⌋ for |x| < 2⁶³ (without a call into the maths library: this runs per droplet).
fn floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// Every droplet a layer's moves set, with its width (B, or B₁ for unit 1's moves), in the
/// order they are set.
pub fn droplets_of(moves: &[Move], b: f64, b1: f64, out: &mut Vec<Droplet>) {
    let mut at = Point::ZERO;
    for m in moves {
        let w = if m.unit == 1 { b1 } else { b };
        match m.kind {
            MoveKind::Droplet => out.push((m.to, w)),
            MoveKind::Line => out.extend(crate::geom::line_droplets(at, m.to, w).map(|p| (p, w))),
            MoveKind::Travel => {}
        }
        at = m.to;
    }
}

/// The `j`-th droplet of the `G25` line `from` → `to` of length `len` = dist(from, to) and
/// pitch `w`: exactly the point [`crate::geom::line_droplets`] sets.
fn line_droplet(from: Point, to: Point, len: f64, w: f64, j: u64) -> Point {
    let t = if len > 0.0 { j as f64 * w / len } else { 0.0 };
    DVec2::new(
        from[0] + t * (to[0] - from[0]),
        from[1] + t * (to[1] - from[1]),
    )
}

/// A `G25` line of the layer below, kept whole.
#[derive(Clone, Copy, Debug)]
struct Line {
    from: Point,
    to: Point,
    len: f64,
    /// Unit vector from → to.
    u: DVec2,
    /// Droplet width (the pitch along the line).
    w: f64,
    /// Its droplets (at least 2).
    n: u64,
    /// The box of its ends in the frame of the layer's common direction (along, across).
    lo: DVec2,
    hi: DVec2,
    /// Half-width of the strip beside it whose points are certainly supported (< 0: none).
    h: f64,
}

/// A piece of a line in a row of [`Below`]: its span along the common direction (at most the
/// row's chunk long) and the line.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    lo: f64,
    hi: f64,
    line: u32,
}

/// Slack for rounding in the search windows, mm (coordinates are below 10⁴ mm).
const PAD_MM: f64 = 1e-6;

/// Clips the parameter range [s0, s1] to where `base + s·slope` lies in [min, max].
fn clip(base: f64, slope: f64, min: f64, max: f64, s: &mut (f64, f64)) {
    if slope.abs() < 1e-12 {
        // Over any line of a layer (< 10⁴ mm) the value moves by < 10⁻⁸ mm, far inside the
        // margin the strips keep.
        if base < min || base > max {
            *s = (f64::INFINITY, f64::NEG_INFINITY);
        }
    } else {
        let (x0, x1) = ((min - base) / slope, (max - base) / slope);
        s.0 = s.0.max(x0.min(x1));
        s.1 = s.1.min(x0.max(x1));
    }
}

/// A layer's droplets for the question "does a droplet of this layer lie within the rule of
/// p": its `G25` lines whole, in cells of a grid in the frame of the layer's hatch direction
/// (every hatch line of a layer, the part's fill and the support's, runs at the layer's hatch
/// angle; a line that does not is read as droplets), and its other droplets in a [`Grid`].
struct Below {
    lines: Vec<Line>,
    /// Unit vectors along and across the common direction.
    along: DVec2,
    across: DVec2,
    /// The lines in rows across the common direction: row y covers across ∈ c0 + [y, y + 1)·row;
    /// its entries (sorted by their start along) are `entries[offsets[y]..offsets[y + 1]]`.
    c0: f64,
    row: f64,
    chunk: f64,
    offsets: Vec<u32>,
    entries: Vec<Entry>,
    /// The largest strip half-width.
    h_max: f64,
    singles: Grid,
    /// The rule's reach of a droplet of width w below is w/2 + limit.
    limit: f64,
    /// The largest reach.
    reach_max: f64,
}

/// ⌈x⌉ for |x| < 2⁶³.
fn ceil(x: f64) -> i64 {
    -floor(-x)
}

impl Below {
    /// Reads a layer's moves (`layer` hands each of its move lists; every list starts at the
    /// origin as in [`droplets_of`]): unit 0's droplets are `b` wide, unit 1's `b1`.
    fn new(layer: &mut dyn FnMut(&mut dyn FnMut(&[Move])), b: f64, b1: f64, limit: f64) -> Below {
        let mut raw: Vec<(Point, Point, f64)> = Vec::new();
        let mut singles: Vec<Droplet> = Vec::new();
        layer(&mut |moves: &[Move]| {
            let mut at = Point::ZERO;
            for m in moves {
                let w = if m.unit == 1 { b1 } else { b };
                match m.kind {
                    MoveKind::Droplet => singles.push((m.to, w)),
                    MoveKind::Line => raw.push((at, m.to, w)),
                    MoveKind::Travel => {}
                }
                at = m.to;
            }
        });
        // The common direction: the longest line's.
        let longest = raw
            .iter()
            .max_by(|x, y| dist(x.0, x.1).total_cmp(&dist(y.0, y.1)));
        let along = longest.map_or(DVec2::X, |&(a, b, _)| {
            let l = dist(a, b);
            if l > 0.0 { (b - a) / l } else { DVec2::X }
        });
        let across = DVec2::new(-along.y, along.x);
        let frame = |p: Point| DVec2::new(along.dot(p), across.dot(p));
        let strip = |w: f64| {
            let r = w / 2.0 + limit - MARGIN_MM;
            if r > w / 2.0 {
                (r * r - w * w / 4.0).sqrt()
            } else {
                -1.0
            }
        };
        let reach_max = b.max(b1) / 2.0 + limit;
        let mut lines = Vec::with_capacity(raw.len());
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for (from, to, w) in raw {
            let len = dist(from, to);
            let n = line_droplet_count(len, w);
            let (fa, fb) = (frame(from), frame(to));
            // Lines across the common direction, and lines of one droplet, as droplets.
            if n < 2 || len <= 0.0 || (fa.y - fb.y).abs() > reach_max {
                singles.extend(crate::geom::line_droplets(from, to, w).map(|p| (p, w)));
                continue;
            }
            let (a, z) = (fa.min(fb), fa.max(fb));
            lo = lo.min(a);
            hi = hi.max(z);
            lines.push(Line {
                from,
                to,
                len,
                u: (to - from) / len,
                w,
                n,
                lo: a,
                hi: z,
                h: strip(w),
            });
        }
        if lines.is_empty() {
            (lo, hi) = (DVec2::ZERO, DVec2::ZERO);
        }
        // Rows of a few reaches (no more than about one per line).
        let row = (2.0 * reach_max)
            .max((hi.y - lo.y) / (lines.len() + 1) as f64)
            .max(1e-3);
        let rows = floor((hi.y - lo.y) / row) as usize + 1;
        let span = |l: &Line| {
            (
                floor((l.lo.y - lo.y) / row) as usize,
                floor((l.hi.y - lo.y) / row) as usize,
            )
        };
        // Entries of at most `chunk` along, so a search by start can stop `chunk` back.
        let chunk = 8.0 * reach_max;
        let pieces = |l: &Line| ceil((l.hi.x - l.lo.x) / chunk).max(1) as usize;
        let mut offsets = vec![0u32; rows + 1];
        for l in &lines {
            let (y0, y1) = span(l);
            for y in y0..=y1 {
                offsets[y + 1] += pieces(l) as u32;
            }
        }
        for k in 1..offsets.len() {
            offsets[k] += offsets[k - 1];
        }
        let mut entries = vec![Entry::default(); *offsets.last().unwrap_or(&0) as usize];
        let mut fill = offsets.clone();
        for (i, l) in lines.iter().enumerate() {
            let (y0, y1) = span(l);
            let k = pieces(l);
            for y in y0..=y1 {
                for j in 0..k {
                    let lo = l.lo.x + j as f64 * chunk;
                    let hi = if j + 1 == k { l.hi.x } else { lo + chunk };
                    entries[fill[y] as usize] = Entry {
                        lo,
                        hi,
                        line: i as u32,
                    };
                    fill[y] += 1;
                }
            }
        }
        for y in 0..rows {
            entries[offsets[y] as usize..offsets[y + 1] as usize]
                .sort_unstable_by(|x, y| x.lo.total_cmp(&y.lo));
        }
        let h_max = lines.iter().map(|l| l.h).fold(-1.0, f64::max);
        Below {
            lines,
            along,
            across,
            c0: lo.y,
            row,
            chunk,
            offsets,
            entries,
            h_max,
            singles: Grid::new(reach_max, &singles),
            limit,
            reach_max,
        }
    }

    /// The rows over across ∈ [c_lo, c_hi].
    fn rows(&self, c_lo: f64, c_hi: f64) -> std::ops::RangeInclusive<i64> {
        let last = self.offsets.len() as i64 - 2;
        floor((c_lo - self.c0) / self.row).max(0)..=floor((c_hi - self.c0) / self.row).min(last)
    }

    /// Row y's lines whose span along meets [t_lo, t_hi] (a line may come more than once).
    fn in_row(&self, y: i64, t_lo: f64, t_hi: f64) -> impl Iterator<Item = &Line> {
        let e =
            &self.entries[self.offsets[y as usize] as usize..self.offsets[y as usize + 1] as usize];
        let k = e.partition_point(|x| x.lo <= t_hi);
        e[..k]
            .iter()
            .rev()
            .take_while(move |x| x.lo >= t_lo - self.chunk)
            .filter(move |x| x.hi >= t_lo)
            .map(|x| &self.lines[x.line as usize])
    }

    fn frame(&self, p: Point) -> DVec2 {
        DVec2::new(self.along.dot(p), self.across.dot(p))
    }

    /// A droplet of the layer within the rule's reach of `p` (w/2 + limit for a droplet of
    /// width w), if any: the same answer as a search over every droplet of the layer.
    fn find(&self, p: Point) -> Option<Droplet> {
        let limit = self.limit;
        if let Some(d) = self.singles.find_within(p, |w| w / 2.0 + limit) {
            return Some(d);
        }
        let f = self.frame(p);
        // A droplet within reach lies in the box f ± r, and so does some point of its line.
        let r = self.reach_max + PAD_MM;
        for l in self
            .rows(f.y - r, f.y + r)
            .flat_map(|y| self.in_row(y, f.x - r, f.x + r))
        {
            let r = l.w / 2.0 + limit;
            let last = (l.n - 1) as f64;
            let jf = (p - l.from).dot(l.u) / l.w;
            if jf < -r / l.w - 1.0 || jf > last + r / l.w + 1.0 {
                continue;
            }
            // The nearest droplet along the line and its neighbours: any droplet of the line
            // within r is no farther than they are.
            let j0 = (floor(jf) - 1).clamp(0, l.n as i64 - 1) as u64;
            let j1 = (ceil(jf) + 1).clamp(0, l.n as i64 - 1) as u64;
            for j in j0..=j1 {
                let q = line_droplet(l.from, l.to, l.len, l.w, j);
                if (p - q).length_squared() <= r * r {
                    return Some((q, l.w));
                }
            }
        }
        None
    }

    /// The droplets k of the line `a` → `b` above (length `len` = dist(a, b), pitch `w`, `n`
    /// droplets) that are certainly supported, as sorted, merged ranges (k0, k1) in `out`
    /// (cleared first). A droplet p is certain when it lies in the strip beside a line below
    /// (width w′, droplets w′ apart along it from its first to its last): along it no farther
    /// than w′/2 beyond its first or last droplet, across it no farther than h with
    /// h² + (w′/2)² = (w′/2 + limit − MARGIN_MM)². A droplet of that line then lies within
    /// √(h² + (w′/2)²), inside the rule's reach by the margin, which covers every rounding.
    fn certified(&self, a: Point, b: Point, len: f64, w: f64, n: u64, out: &mut Vec<(u64, u64)>) {
        out.clear();
        if self.h_max < 0.0 || len <= 0.0 || n < 2 || self.lines.is_empty() {
            return;
        }
        let u = (b - a) / len;
        let last = (n - 1) as f64;
        // Row by row (in the order the line crosses them), the lines below whose strips the
        // line may cross.
        let (fa, fu) = (
            self.frame(a),
            DVec2::new(self.along.dot(u), self.across.dot(u)),
        );
        let fz = fa + last * w * fu;
        let grow = self.h_max + PAD_MM;
        let mut ys = self.rows(fa.y.min(fz.y) - grow, fa.y.max(fz.y) + grow);
        let backwards = fu.y < 0.0;
        let along_grow = self.reach_max + PAD_MM;
        while let Some(y) = if backwards { ys.next_back() } else { ys.next() } {
            // Where the line is within the row's band, grown by the widest strip.
            let band = self.c0 + y as f64 * self.row;
            let mut s = (0.0, last * w);
            clip(fa.y, fu.y, band - grow, band + self.row + grow, &mut s);
            if s.0 > s.1 {
                continue;
            }
            let (t0, t1) = (fa.x + s.0 * fu.x, fa.x + s.1 * fu.x);
            for l in self.in_row(y, t0.min(t1) - along_grow, t0.max(t1) + along_grow) {
                if l.h < 0.0 {
                    continue;
                }
                let d = a - l.from;
                let mut s = (0.0, last * w);
                clip(
                    d.dot(l.u),
                    u.dot(l.u),
                    -l.w / 2.0,
                    (l.n - 1) as f64 * l.w + l.w / 2.0,
                    &mut s,
                );
                clip(l.u.perp_dot(d), l.u.perp_dot(u), -l.h, l.h, &mut s);
                if s.0 > s.1 {
                    continue;
                }
                let (k0, k1) = (ceil(s.0 / w).max(0), floor(s.1 / w).min(n as i64 - 1));
                if k0 <= k1 {
                    out.push((k0 as u64, k1 as u64));
                }
            }
        }
        out.sort_unstable();
        let mut merged = 0;
        for j in 0..out.len() {
            if merged > 0 && out[j].0 <= out[merged - 1].1 + 1 {
                out[merged - 1].1 = out[merged - 1].1.max(out[j].1);
            } else {
                out[merged] = out[j];
                merged += 1;
            }
        }
        out.truncate(merged);
    }
}

/// The droplets of a layer (`layer` hands its move lists, each starting at the origin as in
/// [`droplets_of`]) that no droplet of the layer below (`below`) supports by the rule: none
/// within w/2 + `overhang_limit`·B of it for a droplet of width w below. In the order
/// [`droplets_of`] gives them.
pub fn unsupported(
    below: &mut dyn FnMut(&mut dyn FnMut(&[Move])),
    layer: &mut dyn FnMut(&mut dyn FnMut(&[Move])),
    s: &Settings,
) -> Vec<Droplet> {
    let (b, b1) = (s.droplet_width(), s.unit1_droplet_width());
    let limit = s.overhang_limit * b;
    let below = Below::new(below, b, b1, limit);
    let reach = |w: f64| w / 2.0 + limit;
    let mut open = Vec::new();
    // Consecutive droplets are neighbours: the droplet below that supported the last one
    // most often supports the next.
    let mut last: Option<Droplet> = None;
    let mut check = |p: Point, w: f64| {
        if let Some((q, wq)) = last {
            let r = reach(wq);
            if (p - q).length_squared() <= r * r {
                return;
            }
        }
        match below.find(p) {
            Some(d) => last = Some(d),
            None => open.push((p, w)),
        }
    };
    let mut sure = Vec::new();
    layer(&mut |moves: &[Move]| {
        let mut at = Point::ZERO;
        for m in moves {
            let w = if m.unit == 1 { b1 } else { b };
            match m.kind {
                MoveKind::Droplet => check(m.to, w),
                MoveKind::Line => {
                    let len = dist(at, m.to);
                    let n = line_droplet_count(len, w);
                    below.certified(at, m.to, len, w, n, &mut sure);
                    // The droplets between the certain ranges, one by one.
                    let mut k = 0;
                    for &(k0, k1) in sure.iter().chain([(n, n)].iter()) {
                        for j in k..k0.min(n) {
                            check(line_droplet(at, m.to, len, w, j), w);
                        }
                        k = k1 + 1;
                    }
                }
                MoveKind::Travel => {}
            }
            at = m.to;
        }
    });
    open
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
        let (sin, cos) = crate::geom::sin_cos_deg(angle_deg);
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
/// supported: `layer(i, f)` hands layer i's planned move lists (both units; each starts at the
/// origin as in [`droplets_of`]) to `f` (called about twice per layer, so that no layer's
/// droplets need be kept), `regions[i]` is its part's region. Works top-down; an added droplet
/// needs support from the layer below as any other. Support droplets keep `support_gap_xy`·B
/// from the part's region; a droplet with no such place within the rule stays unsupported
/// (counted). With `support_gap_z` > 0 the support deliberately stops below overhangs, and the
/// pass adds nothing.
pub fn complete(
    layer: &(dyn Fn(usize, &mut dyn FnMut(&[Move])) + Sync),
    regions: &[Shapes],
    s: &Settings,
    par_map: impl Fn(usize, &(dyn Fn(usize) -> Vec<Droplet> + Sync)) -> Vec<Vec<Droplet>>,
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
    // Layer i's droplets that layer i − 1's planned droplets leave unsupported (in parallel).
    let open = par_map(n, &|i| {
        if i == 0 {
            return Vec::new();
        }
        let mut open = unsupported(&mut |f| layer(i - 1, f), &mut |f| layer(i, f), s);
        open.shrink_to_fit();
        open
    });
    let gap = s.support_gap_xy * b;
    let place = reach(b1) - MARGIN_MM;
    // Top-down: layer i's unsupported droplets (planned or added) get droplets in layer i − 1.
    for i in (1..n).rev() {
        let mut todo: Vec<Droplet> = open[i].clone();
        if !extra[i].is_empty() {
            // The droplets added to layer i against layer i − 1's planned droplets.
            let below = Below::new(&mut |f| layer(i - 1, f), b, b1, limit);
            todo.extend(
                extra[i]
                    .iter()
                    .filter(|&&p| below.find(p).is_none())
                    .map(|&p| (p, b1)),
            );
        }
        if todo.is_empty() {
            continue;
        }
        let region = &regions[i - 1];
        let edges = edges_of(region);
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
    use crate::geom::Shape;

    fn square(x0: f64, y0: f64, a: f64) -> Shapes {
        let outer = [[x0, y0], [x0 + a, y0], [x0 + a, y0 + a], [x0, y0 + a]]
            .map(DVec2::from)
            .into();
        vec![Shape::new(outer, vec![])]
    }

    fn run(
        droplets: &[Vec<Droplet>],
        regions: &[Shapes],
        s: &Settings,
    ) -> (Vec<Vec<Point>>, PassFigures) {
        assert_eq!(droplets.len(), regions.len());
        // Single droplets (G26) of unit 0 when B wide, else of unit 1.
        let b = s.droplet_width();
        let moves: Vec<Vec<Move>> = droplets
            .iter()
            .map(|l| {
                l.iter()
                    .map(|&(p, w)| single(p, u8::from(w != b)))
                    .collect()
            })
            .collect();
        complete(&|i, f| f(&moves[i]), regions, s, serial)
    }

    fn single(p: Point, unit: u8) -> Move {
        Move {
            kind: MoveKind::Droplet,
            role: crate::plan::Role::Support,
            to: p,
            unit,
        }
    }

    fn serial(n: usize, f: &(dyn Fn(usize) -> Vec<Droplet> + Sync)) -> Vec<Vec<Droplet>> {
        (0..n).map(f).collect()
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
            let (sn, cs) = crate::geom::sin_cos_deg(angle);
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
