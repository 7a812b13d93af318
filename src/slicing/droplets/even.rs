//! `even` spacing: n = ⌈L/B⌉ droplets spaced L/n along the loop, moved along it where two
//! would be closer than [`EVEN_MIN_CHORD_B`] in a straight line (see the module doc of
//! [`super`]). The placements that search for such moves are in [`search`].

use super::{EVEN_MIN_CHORD_B, EVEN_MIN_LENGTH_B, loop_length, unrolled};
use crate::base::geom::{Point, dist};

mod search;

/// `even` spacing, or `None` where the loop is printed as `exact` (see the module doc).
pub(super) fn even_droplets(points: &[Point], b: f64, shift: f64) -> Option<Vec<Point>> {
    let length = loop_length(points);
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

    fn corners_in(
        &self,
        from: f64,
        to: f64,
        min_turn: f64,
        limit: usize,
        add: f64,
        out: &mut Vec<f64>,
    ) {
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
        if self.gates() || self.grid_search() {
            return;
        }
        self.rotate(&bad);
        self.pin_bends();
        let mut stuck = vec![false; n];
        // Bounded: each try costs O(n), and a loop of many hairpins must not hang the slicer.
        let mut budget = (8 + 4 * bad.len()).min(200);
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
        self.repair_windows();
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
            let mut candidates: Vec<f64> =
                (0..=32).map(|g| lo + (hi - lo) * g as f64 / 32.0).collect();
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
        let (pa, qa) = ((p, self.dev[p]), (q, self.dev[q]));
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
