//! Droplets on contours, stage 5 (SPEC.md 5.3.5, "Loop seams"): a closed loop → droplet
//! centres.
//!
//! **`exact`** (the thesis): centres exactly B apart (straight-line distance): the next centre
//! is where the circle of radius B around the previous one first leaves the loop further
//! along. The walk starts `shift` mm (arc length) after the loop's canonical start, its lowest
//! point (then leftmost), so each layer's seam moves on by `start_jitter`. With `close`, the
//! first droplet is repeated at the end. The last gap (last droplet → first) is whatever is
//! left of the loop, often a few µm.
//!
//! **`even`**: the same walk with a spacing s ≤ B chosen so that the loop closes after n
//! equal steps. Spacing is straight-line distance throughout, as in the thesis (B is a
//! droplet's width: two droplets' overlap depends on the distance of their centres, not on the
//! arc between them; at a sharp corner the chord is shorter than the arc, so arc-length
//! spacing would crowd droplets there). So L is the loop's length *as the walk measures it*:
//! the perimeter of the `exact` walk's droplet polygon, k·B + r (k steps of B, then the
//! remainder r < B back to the start), and n = ⌈L/B⌉ = k + 1 droplets. s is the root of
//! "the chord from droplet n − 1 back to the start equals s", found by bracketing and regula
//! falsi (Illinois) on the walk itself; every gap, the seam's included, is then s, and
//! s ≈ L/n ∈ (B·(1 − 1/n), B]. No droplet is repeated. `shift` moves the start as in `exact`.
//! Where no such s exists (at a hairpin the walk jumps: as s grows, the first exit leaps from
//! one side of the tip to the other), the walk just below or just above the jump is kept,
//! whichever seam gap is nearer s, if that gap lies in [(1 − 1/n)·s, B] and no gap is below
//! 2/3 B; failing that, n + 1
//! droplets, up to n + 3, are tried the same way, and failing that (narrow bends and acute tips
//! the walk jumps across), the droplets are spaced L/n along the arc instead
//! (L the polyline length, n = ⌈L/B⌉): every chord ≤ L/n ≤ B, none repeated, but chords
//! across a sharp corner are shorter than L/n. Loops shorter than 3 B (polyline length) and
//! loops whose walk gives fewer than 3 droplets are printed as `exact`.
//! A walk that closes exactly after k steps of B keeps s = B and drops the repeated droplet.

use crate::geom::{DVec2, Point, dist};
use crate::settings::LoopSpacing;

/// Droplet centres along a closed loop, `exact` spacing.
pub fn loop_droplets(points: &[Point], b: f64, shift: f64, close: bool) -> Vec<Point> {
    if points.is_empty() {
        return Vec::new();
    }
    let path = unrolled(points, shift);
    let start = path[0];
    let mut out = Vec::new();
    walk(&path, b, usize::MAX, &mut out);
    if close && out.len() > 1 {
        out.push(start);
    }
    out
}

/// Droplet centres along a closed loop with the given spacing rule (`close` applies to
/// `exact` loops only: `even` loops repeat nothing).
pub fn loop_droplets_spaced(
    points: &[Point],
    b: f64,
    shift: f64,
    close: bool,
    spacing: LoopSpacing,
) -> Vec<Point> {
    match spacing {
        LoopSpacing::Exact => loop_droplets(points, b, shift, close),
        LoopSpacing::Even => even_droplets(points, b, shift)
            .unwrap_or_else(|| loop_droplets(points, b, shift, close)),
    }
}

/// The shortest loop (polyline length, in B) spaced evenly.
pub const EVEN_MIN_LENGTH_B: f64 = 3.0;

/// The least straight-line distance of two consecutive droplets of an `even` loop, in B.
pub const EVEN_MIN_CHORD_B: f64 = 2.0 / 3.0;

/// `even` spacing, or `None` where the loop is printed as `exact` (see the module doc).
fn even_droplets(points: &[Point], b: f64, shift: f64) -> Option<Vec<Point>> {
    let m = points.len();
    let length: f64 = (0..m).map(|i| dist(points[i], points[(i + 1) % m])).sum();
    if !length.is_finite() || length < EVEN_MIN_LENGTH_B * b || !b.is_finite() || b <= 0.0 {
        return None;
    }
    let path = unrolled(points, shift);
    let arc = ArcPath::new(&path);
    let mut spacing = EvenSpacing::new(arc, b)?;
    spacing.adjust();
    Some(spacing.points())
}

/// An open polyline measured by arc length.
struct ArcPath<'a> {
    path: &'a [Point],
    /// Arc length at each vertex.
    at: Vec<f64>,
}

impl<'a> ArcPath<'a> {
    fn new(path: &'a [Point]) -> ArcPath<'a> {
        let mut at = Vec::with_capacity(path.len());
        let mut s = 0.0;
        at.push(0.0);
        for w in path.windows(2) {
            s += dist(w[0], w[1]);
            at.push(s);
        }
        ArcPath { path, at }
    }

    fn length(&self) -> f64 {
        *self.at.last().expect("non-empty")
    }

    /// The point at arc length `t` (mod the loop's length: the path runs once round it).
    fn point(&self, t: f64) -> Point {
        let n = self.path.len();
        let length = self.length();
        let t = if (0.0..length).contains(&t) || length <= 0.0 {
            t
        } else {
            t.rem_euclid(length)
        };
        if n == 1 || t <= 0.0 {
            return self.path[0];
        }
        // The edge e → e + 1 with at[e] ≤ t < at[e + 1].
        let e = (self.at.partition_point(|&a| a <= t).max(1) - 1).min(n - 2);
        let l = self.at[e + 1] - self.at[e];
        let u = if l > 0.0 {
            ((t - self.at[e]) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.path[e] + (self.path[e + 1] - self.path[e]) * u
    }

    /// Arc lengths of the vertices in [from, to] (taken round the loop: outside [0, L] they are
    /// counted on from the start) where the path turns by more than `min_turn` radians (corner
    /// tips, hairpins), at most `limit` of them.
    fn corners(&self, from: f64, to: f64, min_turn: f64, limit: usize) -> Vec<f64> {
        let length = self.length();
        let mut out = Vec::new();
        if length <= 0.0 || to < from || to - from >= length {
            return out;
        }
        let lap = (from / length).floor() * length;
        let (a, b) = (from - lap, to - lap);
        self.corners_in(a, b.min(length), min_turn, limit, lap, &mut out);
        if b > length {
            self.corners_in(0.0, b - length, min_turn, limit, lap + length, &mut out);
        }
        out
    }

    fn corners_in(&self, from: f64, to: f64, min_turn: f64, limit: usize, add: f64, out: &mut Vec<f64>) {
        let first = self.at.partition_point(|&a| a < from).max(1);
        for v in first..self.path.len() - 1 {
            if self.at[v] > to || out.len() >= limit {
                break;
            }
            let (u, w) = (
                self.path[v] - self.path[v - 1],
                self.path[v + 1] - self.path[v],
            );
            let turn = u.perp_dot(w).atan2(u.dot(w)).abs();
            if turn > min_turn {
                out.push(self.at[v] + add);
            }
        }
    }
}

/// Score of a set of consecutive pairs: how many are closer than the least chord, and by how
/// much in all (compared lexicographically).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
struct Shortfall {
    pairs: usize,
    sum: f64,
}

impl Shortfall {
    fn add(&mut self, short: f64) {
        if short > 0.0 {
            self.pairs += 1;
            self.sum += short;
        }
    }
}

/// `even` droplets of one loop: droplet i at arc length i·L/n + d_i (d_0 = d_n = 0: the start
/// stays where `shift` put it), the deviations d linear between anchors.
struct EvenSpacing<'a> {
    arc: ArcPath<'a>,
    n: usize,
    /// L/n.
    step: f64,
    /// How far one gap may shrink (L/n − B·(1 − 1/n)) and grow (B − L/n).
    shrink: f64,
    grow: f64,
    min_chord: f64,
    /// (index, deviation), sorted, starting with (0, 0) and ending with (n, 0).
    anchors: Vec<(usize, f64)>,
    /// d_0 … d_n.
    dev: Vec<f64>,
    /// Each droplet's point (droplet n is droplet 0).
    pts: Vec<Point>,
}

impl<'a> EvenSpacing<'a> {
    fn new(arc: ArcPath<'a>, b: f64) -> Option<EvenSpacing<'a>> {
        let length = arc.length();
        let n = (length / b).ceil();
        if !(3.0..=1e7).contains(&n) {
            return None;
        }
        let n = n as usize;
        let step = length / n as f64;
        let lower = b * (1.0 - 1.0 / n as f64);
        let mut s = EvenSpacing {
            n,
            step,
            shrink: (step - lower).max(0.0),
            grow: (b - step).max(0.0),
            min_chord: EVEN_MIN_CHORD_B * b,
            anchors: vec![(0, 0.0), (n, 0.0)],
            dev: vec![0.0; n + 1],
            pts: Vec::with_capacity(n + 1),
            arc,
        };
        s.pts = (0..n).map(|i| s.arc.point(i as f64 * step)).collect();
        s.pts.push(s.pts[0]);
        Some(s)
    }

    fn points(mut self) -> Vec<Point> {
        self.pts.truncate(self.n);
        self.pts
    }

    /// How much pair i → i + 1 falls short of the least chord.
    fn short(&self, i: usize) -> f64 {
        self.min_chord - dist(self.pts[i], self.pts[i + 1])
    }

    /// Moves droplets where consecutive ones are closer than the least chord (acute corners,
    /// hairpins, narrow bends): greedily, the worst pair first, one droplet near it is anchored
    /// where the pairs it changes fall short least (snapped to a corner tip or on a grid of its
    /// window); the droplets between anchors follow linearly, so every gap stays in
    /// [B·(1 − 1/n), B]. Stops when no pair falls short or no move helps.
    fn adjust(&mut self) {
        let n = self.n;
        let bad: Vec<usize> = (0..n).filter(|&i| self.short(i) > 0.0).collect();
        if bad.is_empty() {
            return;
        }
        self.rotate(&bad);
        self.pin_bends();
        let mut stuck = vec![false; n];
        let mut budget = 8 + 4 * bad.len();
        while budget > 0 {
            budget -= 1;
            let worst = (0..n)
                .filter(|&i| !stuck[i])
                .map(|i| (i, self.short(i)))
                .filter(|&(_, s)| s > 0.0)
                .max_by(|a, b| a.1.total_cmp(&b.1));
            let Some((k, _)) = worst else { break };
            if !self.improve_pair(k) {
                stuck[k] = true;
            }
        }
    }

    /// Turns every droplet along the loop by the same arc length (gaps unchanged) where that
    /// leaves fewer pairs short: to put a droplet on a corner tip inside a short pair, or by a
    /// fraction of the spacing.
    fn rotate(&mut self, bad: &[usize]) {
        let n = self.n;
        let mut candidates: Vec<f64> = (1..16)
            .map(|g| (g as f64 / 16.0 - 0.5) * self.step)
            .collect();
        for &k in bad.iter().take(16) {
            let (a, b) = (k as f64 * self.step, (k + 1) as f64 * self.step);
            for c in self.arc.corners(a, b, 0.35, 8) {
                candidates.extend([c - a, c - b]);
            }
        }
        let score = |s: &Self, r: f64| {
            let mut f = Shortfall::default();
            let mut prev = s.arc.point(r);
            let first = prev;
            for i in 1..=n {
                let p = if i == n {
                    first
                } else {
                    s.arc.point(i as f64 * s.step + r)
                };
                f.add(s.min_chord - dist(prev, p));
                prev = p;
            }
            f
        };
        let mut best = (score(self, 0.0), 0.0);
        for r in candidates {
            let f = score(self, r);
            if f.pairs < best.0.pairs || (f.pairs == best.0.pairs && f.sum < best.0.sum - 1e-12) {
                best = (f, r);
            }
        }
        let r = best.1;
        if r != 0.0 {
            self.anchors = vec![(0, r), (n, r)];
            self.dev.iter_mut().for_each(|d| *d = r);
            for i in 0..n {
                self.pts[i] = self.arc.point(i as f64 * self.step + r);
            }
            self.pts[n] = self.pts[0];
        }
    }

    /// The anchors around index j (0 < j < n): positions in `anchors` of the last one before j
    /// and the first one after it, and whether j is an anchor itself.
    fn around(&self, j: usize) -> Option<(usize, usize, bool)> {
        let q = self.anchors.partition_point(|&(i, _)| i < j);
        if q == 0 || q >= self.anchors.len() || j == 0 || j >= self.n {
            return None;
        }
        let own = self.anchors[q].0 == j;
        Some((q - 1, q + usize::from(own), own))
    }

    /// Anchors, where they are, the droplets of pairs that turn at a bend (chord below 0.95 of
    /// the arc): moves elsewhere then leave them be.
    fn pin_bends(&mut self) {
        for i in 0..self.n {
            let arc = self.step + self.dev[i + 1] - self.dev[i];
            if dist(self.pts[i], self.pts[i + 1]) < 0.95 * arc {
                for j in [i, i + 1] {
                    if let Some((_, qa, false)) = self.around(j) {
                        self.anchors.insert(qa, (j, self.dev[j]));
                    }
                }
            }
        }
    }

    /// Tries anchoring each droplet near pair k; keeps the best move if it helps.
    fn improve_pair(&mut self, k: usize) -> bool {
        let n = self.n;
        let mut best: Option<((i64, f64), usize, f64)> = None;
        let mut trial = Vec::new();
        for j in [k, k + 1, k + n - 1, k + 2] {
            let j = j % n;
            let Some((pa, qa, _)) = self.around(j) else {
                continue;
            };
            let ((p, dp), (q, dq)) = (self.anchors[pa], self.anchors[qa]);
            // d_j's window: reachable from both anchors with gaps in bounds.
            let lo = (dp - self.shrink * (j - p) as f64).max(dq - self.grow * (q - j) as f64);
            let hi = (dp + self.grow * (j - p) as f64).min(dq + self.shrink * (q - j) as f64);
            if hi < lo {
                continue;
            }
            let base = j as f64 * self.step;
            let mut candidates: Vec<f64> = (0..=32).map(|g| lo + (hi - lo) * g as f64 / 32.0).collect();
            candidates.extend(
                self.arc
                    .corners(base + lo, base + hi, 0.35, 16)
                    .into_iter()
                    .map(|t| t - base),
            );
            let before = self.range_shortfall(p, q, None, &mut trial);
            for d in candidates {
                let after = self.range_shortfall(p, q, Some((j, d)), &mut trial);
                // Fewer short pairs, then less shortfall, than before in this range.
                let gain = (
                    after.pairs as i64 - before.pairs as i64,
                    after.sum - before.sum,
                );
                if gain.0 > 0 || (gain.0 == 0 && gain.1 >= -1e-12) {
                    continue;
                }
                if best.as_ref().is_none_or(|(g, _, _)| gain < *g) {
                    best = Some((gain, j, d));
                }
            }
        }
        let Some((_, j, d)) = best else {
            return false;
        };
        let (pa, qa, own) = self.around(j).expect("0 < j < n");
        if own {
            self.anchors[qa - 1].1 = d;
        } else {
            self.anchors.insert(qa, (j, d));
        }
        let (p, q) = (self.anchors[pa].0, self.anchors[pa + 2].0);
        self.fill(p, q);
        true
    }

    /// Deviation at i between anchors (p, dp) and (q, dq), with an extra anchor (j, dj).
    fn interpolate(p: (usize, f64), q: (usize, f64), extra: Option<(usize, f64)>, i: usize) -> f64 {
        let (a, b) = match extra {
            Some(e) if i <= e.0 => (p, e),
            Some(e) => (e, q),
            None => (p, q),
        };
        if b.0 == a.0 {
            return a.1;
        }
        a.1 + (b.1 - a.1) * (i - a.0) as f64 / (b.0 - a.0) as f64
    }

    /// The shortfall of pairs p … q − 1 with droplets p + 1 … q − 1 placed linearly between
    /// the anchors at p and q, and through `extra` if given; `buf` is scratch space.
    fn range_shortfall(
        &self,
        p: usize,
        q: usize,
        extra: Option<(usize, f64)>,
        buf: &mut Vec<Point>,
    ) -> Shortfall {
        let (pa, qa) = (
            (p, self.dev[p]),
            (q, self.dev[q]),
        );
        buf.clear();
        buf.push(self.pts[p]);
        for i in p + 1..q {
            let d = Self::interpolate(pa, qa, extra, i);
            buf.push(self.arc.point(i as f64 * self.step + d));
        }
        buf.push(self.pts[q]);
        let mut s = Shortfall::default();
        for w in buf.windows(2) {
            s.add(self.min_chord - dist(w[0], w[1]));
        }
        s
    }

    /// Places droplets p + 1 … q − 1 through the anchors between p and q.
    fn fill(&mut self, p: usize, q: usize) {
        let first = self.anchors.partition_point(|&(i, _)| i < p);
        let mut a = first;
        for i in p + 1..q {
            while self.anchors[a + 1].0 < i {
                a += 1;
            }
            let d = Self::interpolate(self.anchors[a], self.anchors[a + 1], None, i);
            self.dev[i] = d;
            self.pts[i] = self.arc.point(i as f64 * self.step + d);
        }
    }
}

/// The walk: `out` gets the start and each next centre where the circle of radius `r` around
/// the previous one first leaves the path further along, at most `limit` centres.
fn walk(path: &[Point], r: f64, limit: usize, out: &mut Vec<Point>) {
    out.clear();
    let start = path[0];
    out.push(start);
    let (mut c, mut i) = (start, 0usize);
    'walk: while out.len() < limit {
        while i + 1 < path.len() {
            if let Some(p) = circle_exit(path[i], path[i + 1], c, r) {
                out.push(p);
                c = p;
                continue 'walk;
            }
            i += 1;
        }
        break;
    }
}

/// The loop as an open polyline from the start point around and back to it.
fn unrolled(points: &[Point], shift: f64) -> Vec<Point> {
    let n = points.len();
    let s0 = (0..n)
        .min_by(|&a, &b| {
            let (p, q) = (points[a], points[b]);
            p[1].total_cmp(&q[1]).then(p[0].total_cmp(&q[0]))
        })
        .expect("non-empty");
    let length: f64 = (0..n).map(|i| dist(points[i], points[(i + 1) % n])).sum();
    let mut rest = if length > 0.0 {
        shift.rem_euclid(length)
    } else {
        0.0
    };
    // Find the edge holding the start point.
    let mut e = s0;
    let mut start = points[s0];
    for _ in 0..n {
        let (p, q) = (points[e], points[(e + 1) % n]);
        let l = dist(p, q);
        if rest < l {
            let t = rest / l;
            start = DVec2::new(p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]));
            break;
        }
        rest -= l;
        e = (e + 1) % n;
        start = points[e];
    }
    let mut path = Vec::with_capacity(n + 2);
    path.push(start);
    for k in 1..=n {
        path.push(points[(e + k) % n]);
    }
    path.push(start);
    path
}

/// Where the segment p→q leaves the circle of radius `r` around `c`, if it does; p is inside.
fn circle_exit(p: Point, q: Point, c: Point, r: f64) -> Option<Point> {
    let (d, f) = (q - p, p - c);
    let a = d[0] * d[0] + d[1] * d[1];
    if a == 0.0 {
        return None;
    }
    let bq = 2.0 * (f[0] * d[0] + f[1] * d[1]);
    let cq = f[0] * f[0] + f[1] * f[1] - r * r;
    let disc = bq * bq - 4.0 * a * cq;
    if disc < 0.0 {
        return None;
    }
    // Numerically stable larger root.
    let sq = disc.sqrt();
    let t = if bq >= 0.0 {
        (2.0 * -cq) / (bq + sq)
    } else {
        (-bq + sq) / (2.0 * a)
    };
    let t = if bq >= 0.0 && bq + sq == 0.0 { 0.0 } else { t };
    (0.0..=1.0)
        .contains(&t)
        .then(|| DVec2::new(p[0] + t * d[0], p[1] + t * d[1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_loop_spacing() {
        let sq: Vec<Point> = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
            .map(Point::from)
            .into();
        let b = 0.208;
        for shift in [0.0, 0.07, 3.3, 41.0] {
            let d = loop_droplets(&sq, b, shift, true);
            for w in d[..d.len() - 1].windows(2) {
                assert!((dist(w[0], w[1]) - b).abs() < 1e-9, "{:?}", w);
            }
            assert_eq!(d[0], *d.last().unwrap());
            // Perimeter 40 mm: about 40 / B droplets (corners cut a little).
            let n = d.len() as f64 - 1.0;
            assert!((n - 40.0 / b).abs() < 3.0, "{n}");
        }
    }

    #[test]
    fn tiny_loop_gets_one_droplet() {
        let tri: Vec<Point> = [[0.0, 0.0], [0.05, 0.0], [0.0, 0.05]]
            .map(Point::from)
            .into();
        assert_eq!(loop_droplets(&tri, 0.2, 0.0, true).len(), 1);
    }

    /// Gaps between consecutive droplets, the seam (last → first) included.
    fn gaps(d: &[Point]) -> Vec<f64> {
        (0..d.len())
            .map(|i| dist(d[i], d[(i + 1) % d.len()]))
            .collect()
    }

    #[test]
    fn even_spacing_closes_with_equal_gaps() {
        let b = 0.208;
        let sq: Vec<Point> = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
            .map(Point::from)
            .into();
        let circle: Vec<Point> = (0..720)
            .map(|i| {
                let a = i as f64 / 720.0 * std::f64::consts::TAU;
                Point::new(3.0 * a.cos(), 3.0 * a.sin())
            })
            .collect();
        // A sliver with a sharp tip, and a loop of about 5 B.
        let sliver: Vec<Point> = [[0.0, 0.0], [5.0, 0.3], [0.0, 0.6]].map(Point::from).into();
        let small: Vec<Point> = [[0.0, 0.0], [0.3, 0.0], [0.3, 0.25], [0.0, 0.25]]
            .map(Point::from)
            .into();
        // A chord straddling a corner of turn φ spans up to sec(φ/2) times its length of loop
        // (√2 at a right angle), so each corner may shorten n·s against k·B + r by up to
        // (sec(φ/2) − 1)·s: the loops' corners (their sum of that factor) loosen the bound.
        let sec = |deg: f64| 1.0 / (deg.to_radians() / 2.0).cos() - 1.0;
        let sliver_turn = 180.0 - 2.0 * (0.3f64 / 5.0).atan().to_degrees();
        let cases = [
            ("square", &sq, 4.0 * sec(90.0)),
            ("circle", &circle, 0.0),
            ("sliver", &sliver, 2.0 * sec(90.0 + 3.5) + sec(sliver_turn)),
            ("small", &small, 4.0 * sec(90.0)),
        ];
        for (name, lp, corners) in cases {
            for shift in [0.0, 0.07, 3.3, 41.0] {
                let exact = loop_droplets(lp, b, shift, true);
                let even = loop_droplets_spaced(lp, b, shift, true, LoopSpacing::Even);
                let n = even.len();
                assert_ne!(even[0], even[n - 1], "{name} {shift}");
                if name == "sliver" {
                    // At the hairpin the walk may leave no closing spacing: spaced along the
                    // arc, every chord at most L/n ≤ B.
                    assert!(gaps(&even).iter().all(|&g| g <= b), "{name} {shift}");
                    continue;
                }
                // One droplet per exact one, none repeated.
                assert_eq!(n, exact.len() - 1, "{name} {shift}");
                assert_eq!(even[0], exact[0], "{name} {shift}: same start");
                assert_ne!(even[0], even[n - 1], "{name} {shift}");
                let g = gaps(&even);
                let seam = g[n - 1];
                let (lo, hi) = g[..n - 1]
                    .iter()
                    .fold((f64::MAX, 0.0f64), |(a, c), &x| (a.min(x), c.max(x)));
                assert!(hi - lo < 1e-9, "{name} {shift}: gaps {lo}..{hi}");
                // The seam equals the other gaps, except after a hairpin (the sliver's tip).
                if name == "sliver" {
                    assert!(
                        seam >= (1.0 - 1.0 / n as f64) * lo && seam <= b,
                        "{name} {shift}: seam {seam}, gaps {lo}"
                    );
                } else {
                    assert!(
                        (seam - lo).abs() < 1e-6,
                        "{name} {shift}: seam {seam}, gaps {lo}"
                    );
                }
                let bound = b * (1.0 - (1.0 + corners) / n as f64) - 1e-9;
                assert!(
                    hi <= b + 1e-12 && lo > bound,
                    "{name} {shift}: {lo}..{hi}, n {n}, bound {bound}"
                );
            }
        }
    }

    #[test]
    fn even_leaves_short_loops_exact() {
        let b = 0.208;
        // Perimeter 2.9 B: printed as exact, first droplet repeated.
        let side = 2.9 * b / 4.0;
        let sq: Vec<Point> = [[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]]
            .map(Point::from)
            .into();
        let d = loop_droplets_spaced(&sq, b, 0.0, true, LoopSpacing::Even);
        assert_eq!(d, loop_droplets(&sq, b, 0.0, true));
        assert_eq!(d[0], *d.last().unwrap());
    }
}
