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
//! **`even`**: n = ⌈L/B⌉ droplets (L the loop's length, n ≥ 3) spaced L/n **along the loop**
//! from the same start (`shift` moves it as in `exact`), so every arc gap, the seam's
//! included, is L/n ∈ [B·(1 − 1/n), B] and no droplet is repeated; a straight-line gap is
//! never longer than its arc. Where two consecutive droplets would be closer than 2/3 B in a
//! straight line ([`EVEN_MIN_CHORD_B`]: across acute corners, hairpins, narrow bends) the
//! droplets are moved along the loop, each arc gap kept in [B·(1 − 1/n), B] (the gaps then
//! differ a little and the seam is no longer special): droplet i sits at i·L/n + d_i with the
//! deviations d linear between a few anchored droplets, so consecutive d differ by at most
//! −(L/n − B·(1 − 1/n)) … B − L/n. First ("gates"), the arc intervals where a pair may not
//! start (chord below 2/3 B, sampled at L/128n) are found, and the deviation that puts the
//! droplet before each interval in [b − B·(1 − 1/n), a] is propagated round the loop as
//! intervals from samples of the first interval's; a start that reaches itself again gives the
//! anchors. Failing that, loops of at most 64 droplets are searched on a grid of arc
//! positions (exhaustively, from every first position), and failing that the whole loop is
//! turned (a droplet onto a corner tip) and droplets
//! near the worst pair are anchored one by one where they help. Last, for each pair still short
//! the droplets of a window round it (9, 25, 65 droplets, then for loops of at most 160
//! droplets the whole loop from 64 positions of one droplet over a spacing) are placed afresh between the window's two end droplets on a
//! fine grid of arc (B/(r·n), r = 4096/window in 4 … 32): every grid position each droplet can
//! reach with both bounds met, and one chain traced back. Where nothing helps (two sharp bends
//! closer than the spacing allows: tests/seams.rs proves it for every such loop of the shared
//! models) the best placement found is kept: rare (0–1 % of the loops of the shared models,
//! docs/quality.md). Only loops that need it pay for the search.
//! Loops shorter than 3 B ([`EVEN_MIN_LENGTH_B`]) are printed as `exact`.

use crate::base::geom::{DVec2, Point, dist};
use crate::base::settings::LoopSpacing;

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

/// The longest loop (droplets) searched exhaustively where the faster placements fail.
const GRID_MAX_N: usize = 64;

/// The longest loop (droplets) placed afresh as a whole by the last stage.
const WINDOW_LOOP_MAX_N: usize = 160;

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

    /// Last stage: for each pair still short, the droplets of a window round it (growing, up
    /// to the whole loop) are placed afresh on a fine grid of arc positions between the
    /// window's two end droplets, kept where they are: a search over every grid position
    /// each droplet can reach with gaps in [B·(1 − 1/n), B] and chords of at least 2/3 B.
    fn repair_windows(&mut self) {
        let n = self.n;
        // Bounded: a few windows per short pair.
        let mut budget = 64usize;
        while budget > 0 {
            let Some(k) = (0..n).find(|&i| self.short(i) > 0.0) else {
                return;
            };
            let mut fixed = false;
            // The whole loop only up to WINDOW_LOOP_MAX_N droplets (its cost grows as n²).
            for w in [8usize, 24, 64, n] {
                if w >= n.saturating_sub(2) && n > WINDOW_LOOP_MAX_N {
                    break;
                }
                let w = w.min(n);
                budget = budget.saturating_sub(1);
                // Droplets k − w/2 … k + 1 + w/2 round the loop; the whole loop from the
                // droplet opposite the pair back to itself.
                let (p, len) = if w >= n.saturating_sub(2) {
                    ((k + n / 2) % n, n)
                } else {
                    ((k + n - w / 2) % n, w + 1)
                };
                let ok = if len == n {
                    // Droplet p itself moved too: a sample of offsets over one spacing.
                    (0..64).any(|o| self.window_search(p, len, o as f64 / 64.0 * self.step))
                } else {
                    self.window_search(p, len, 0.0)
                };
                if ok {
                    fixed = true;
                    break;
                }
                if len == n || budget == 0 {
                    break;
                }
            }
            if !fixed {
                return;
            }
        }
    }

    /// Places droplets p + 1 … p + len − 1 (round the loop) afresh, droplets p and p + len
    /// kept: on a grid of arc positions from droplet p, fine enough (δ ≤ B/16n) that gaps in
    /// [B·(1 − 1/n), B] have room to differ, every reachable grid position of each droplet is
    /// found with its predecessor, and one chain to droplet p + len traced back. True if found
    /// (then every pair of the window meets the bounds).
    fn window_search(&mut self, p: usize, len: usize, offset: f64) -> bool {
        let n = self.n;
        let (lo, hi) = (self.step - self.shrink, self.step + self.grow);
        if len < 2 || len > n || hi - lo <= 0.0 {
            return false;
        }
        // Cost ≈ len · (cells a droplet) · (cells a gap): (r · len/2) · r.
        let r = (4096.0 / len as f64).clamp(4.0, 32.0);
        let delta = (hi - lo) / r;
        let q = p + len;
        let pos = |i: usize| i as f64 * self.step + self.dev[i % n];
        let t0 = pos(p) + offset;
        let p_pt = if offset == 0.0 {
            self.pts[p]
        } else {
            self.arc.point(t0)
        };
        // Droplet q's arc position, droplet q mod n's deviation, counted on past p.
        let (t_end, end_pt) = if len == n {
            (t0 + self.arc.length(), p_pt)
        } else {
            (q as f64 * self.step + self.dev[q % n], self.pts[q % n])
        };
        let total = t_end - t0;
        let range = |j: usize| {
            let a = (j as f64 * lo).max(total - (len - j) as f64 * hi);
            let b = (j as f64 * hi).min(total - (len - j) as f64 * lo);
            ((a / delta).ceil() as i64, (b / delta).floor() as i64)
        };
        // rows[j]: (first k, predecessor of each k or −1, points).
        let mut rows: Vec<(i64, Vec<i64>, Vec<Point>)> = vec![(0, vec![0], vec![p_pt])];
        for j in 1..len {
            let (a, b) = range(j);
            if b < a || b - a > 1_000_000 {
                return false;
            }
            let pts: Vec<Point> = (a..=b)
                .map(|k| self.arc.point(t0 + k as f64 * delta))
                .collect();
            let mut pred = vec![-1i64; pts.len()];
            let (pa, ppred, ppts) = &rows[j - 1];
            let mut any = false;
            for (r, k) in (a..=b).enumerate() {
                // Predecessors k' with (k − k')·δ in [lo, hi].
                let from = (k - (hi / delta).floor() as i64).max(*pa);
                let to = (k - (lo / delta).ceil() as i64).min(pa + ppred.len() as i64 - 1);
                for kp in from..=to {
                    let x = (kp - pa) as usize;
                    let gap = (k - kp) as f64 * delta;
                    if ppred[x] >= 0
                        && gap >= lo
                        && gap <= hi
                        && dist(ppts[x], pts[r]) >= self.min_chord
                    {
                        pred[r] = kp;
                        any = true;
                        break;
                    }
                }
            }
            if !any {
                return false;
            }
            rows.push((a, pred, pts));
        }
        // The last droplet of the window to droplet q.
        let (a, pred, pts) = &rows[len - 1];
        let last = (0..pred.len()).find(|&x| {
            let gap = total - (a + x as i64) as f64 * delta;
            pred[x] >= 0 && gap >= lo && gap <= hi && dist(pts[x], end_pt) >= self.min_chord
        });
        let Some(x) = last else { return false };
        let mut k = a + x as i64;
        for j in (1..len).rev() {
            let (a, pred, pts) = &rows[j];
            let x = (k - a) as usize;
            let i = (p + j) % n;
            let t = t0 + k as f64 * delta;
            self.dev[i] =
                t - i as f64 * self.step - if p + j >= n { self.arc.length() } else { 0.0 };
            self.pts[i] = pts[x];
            k = pred[x];
        }
        if len == n {
            self.dev[p] = t0 - p as f64 * self.step;
            self.pts[p] = p_pt;
        }
        self.dev[n] = self.dev[0];
        self.pts[n] = self.pts[0];
        true
    }

    /// The arc intervals a droplet must not start a pair in: s where the chord from s to
    /// s + g is below the least chord for a gap g of B·(1 − 1/n), L/n or B (sampled at L/128n
    /// and widened by a sample), merged, in [0, L) (one that wraps ends past L).
    fn bad_intervals(&self) -> Vec<(f64, f64)> {
        let length = self.arc.length();
        let h = self.step / 128.0;
        let samples = 128 * self.n;
        let gaps = [self.step - self.shrink, self.step, self.step + self.grow];
        let mut out: Vec<(f64, f64)> = Vec::new();
        let mut first = Point::ZERO;
        for k in 0..=samples {
            let s = k as f64 * h;
            let p = if k == samples {
                first
            } else {
                self.arc.point(s)
            };
            if k == 0 {
                first = p;
            }
            let bad = gaps
                .iter()
                .any(|&gap| dist(p, self.arc.point(s + gap)) < self.min_chord);
            if bad {
                match out.last_mut() {
                    Some(last) if last.1 >= s - 1.5 * h => last.1 = s + h,
                    _ => out.push((s - h, s + h)),
                }
            }
        }
        // One interval across the start: joined at the end.
        if out.len() > 1 && out[0].0 < 0.0 && out.last().expect("two").1 > length - 1e-12 {
            let (_, b) = out.remove(0);
            out.last_mut().expect("one").1 = length + b;
        }
        out
    }

    /// Places the droplets so that none starts a pair in a bad interval (see
    /// [`bad_intervals`](Self::bad_intervals)): for each interval ("gate") the droplet before
    /// it lies in [b − B·(1 − 1/n), a] and the deviations between gates change by at most
    /// −(L/n − B·(1 − 1/n)) … B − L/n a droplet. The reachable deviations of each gate are
    /// propagated as intervals round the loop from a sample of the first gate's, and a start
    /// that reaches itself again is traced back. True if a placement was found and checked.
    fn gates(&mut self) -> bool {
        let n = self.n;
        // (Sampling costs 384 points a droplet: loops up to 10 m.)
        if n > 50_000 {
            return false;
        }
        let gates = self.bad_intervals();
        let lo_gap = self.step - self.shrink;
        if gates.is_empty() || gates.len() > 4 * n || gates.iter().any(|g| g.1 - g.0 > lo_gap) {
            return false;
        }
        let drift = self.shrink.max(self.grow) * n as f64;
        let reach = self.step + drift;
        // (index, deviation interval) options of a gate.
        let options = |g: (f64, f64)| -> Vec<(usize, (f64, f64))> {
            let mut v = Vec::new();
            let first = ((g.0 - reach) / self.step).floor().max(0.0) as usize;
            let last = (((g.1 + reach) / self.step).ceil() as usize).min(2 * n);
            for i in first..=last {
                let base = i as f64 * self.step;
                let (lo, hi) = (g.1 - lo_gap - base, g.0 - base);
                if hi >= lo && hi >= -reach && lo <= reach {
                    v.push((i, (lo, hi)));
                }
            }
            v
        };
        let opts: Vec<Vec<(usize, (f64, f64))>> = gates.iter().map(|&g| options(g)).collect();
        if opts.iter().any(|o| o.is_empty()) {
            return false;
        }
        let (shrink, grow) = (self.shrink, self.grow);
        // Intervals reachable at `to` (index j) from `from` sets.
        let step_sets = |from: &[Reach], j: usize, allowed: (f64, f64)| {
            let mut out: Vec<(f64, f64)> = Vec::new();
            for (i, set) in from {
                if *i > j {
                    continue;
                }
                let dn = (j - i) as f64;
                for &(a, b) in set {
                    let (a, b) = (
                        (a - shrink * dn).max(allowed.0),
                        (b + grow * dn).min(allowed.1),
                    );
                    if a <= b {
                        out.push((a, b));
                    }
                }
            }
            merge(&mut out);
            out
        };
        let k = gates.len();
        for &(i0, (lo0, hi0)) in &opts[0] {
            for t in 0..=16 {
                let d0 = lo0 + (hi0 - lo0) * t as f64 / 16.0;
                // reach[g]: per option of gate g, its reachable deviations.
                let mut table: Vec<Vec<Reach>> = vec![vec![(i0, vec![(d0, d0)])]];
                for g in 1..=k {
                    let (gi, shift) = if g == k { (0, n) } else { (g, 0) };
                    let mut row = Vec::new();
                    for &(j, allowed) in &opts[gi] {
                        let j = j + shift;
                        if g == k && j != i0 + n {
                            continue;
                        }
                        let allowed = if g == k { (d0, d0) } else { allowed };
                        let set = step_sets(&table[g - 1], j, allowed);
                        if !set.is_empty() {
                            row.push((j, set));
                        }
                    }
                    if row.is_empty() {
                        break;
                    }
                    table.push(row);
                }
                if table.len() < k + 1 {
                    continue;
                }
                // Trace back from the start reached again.
                let mut chosen = vec![(i0 + n, d0)];
                for g in (1..k).rev() {
                    let (j, dj) = *chosen.last().expect("one");
                    let pick = table[g]
                        .iter()
                        .filter(|(i, _)| *i <= j)
                        .flat_map(|(i, set)| {
                            let dn = (j - i) as f64;
                            // d with dj − d ∈ [−shrink·dn, grow·dn], nearest dj.
                            let (a, b) = (dj - grow * dn, dj + shrink * dn);
                            set.iter().filter_map(move |&(x, y)| {
                                let (x, y) = (x.max(a), y.min(b));
                                (x <= y).then(|| (*i, dj.clamp(x, y)))
                            })
                        })
                        .min_by(|p, q| (p.1 - dj).abs().total_cmp(&(q.1 - dj).abs()));
                    let Some(p) = pick else { break };
                    chosen.push(p);
                }
                if chosen.len() < k {
                    continue;
                }
                chosen.push((i0, d0));
                chosen.reverse();
                if self.apply_gates(&chosen) {
                    return true;
                }
            }
        }
        false
    }

    /// Sets the anchors to the gates' droplets (the first and the start reached again last),
    /// places every droplet and checks them; restores the even placement if a pair falls short.
    fn apply_gates(&mut self, chosen: &[(usize, f64)]) -> bool {
        let n = self.n;
        let (first, last) = (chosen[0], chosen[chosen.len() - 1]);
        let before = chosen[chosen.len() - 2];
        // Droplet 0 (= n) between the last gate (before n) and the first reached again.
        let d0 = if last.0 == before.0 {
            last.1
        } else {
            before.1
                + (last.1 - before.1) * (n - before.0.min(n)) as f64 / (last.0 - before.0) as f64
        };
        let mut anchors = vec![(0, d0)];
        for &(i, d) in &chosen[..chosen.len() - 1] {
            let i = if i >= n { i - n } else { i };
            if i == 0 || anchors.last().is_some_and(|a| a.0 >= i) {
                if i != 0
                    && anchors
                        .last()
                        .is_some_and(|a| a.0 == i && (a.1 - d).abs() < 1e-12)
                {
                    continue;
                }
                if i != 0 {
                    return false;
                }
                anchors[0].1 = d;
                continue;
            }
            anchors.push((i, d));
        }
        let _ = first;
        anchors.push((n, anchors[0].1));
        let saved = (self.anchors.clone(), self.dev.clone(), self.pts.clone());
        self.anchors = anchors;
        self.dev[0] = self.anchors[0].1;
        self.dev[n] = self.anchors[0].1;
        self.pts[0] = self.arc.point(self.dev[0]);
        self.pts[n] = self.pts[0];
        self.fill(0, n);
        let ok = (0..n).all(|i| {
            let gap = self.step + self.dev[i + 1] - self.dev[i];
            self.short(i) <= 0.0
                && gap >= self.step - self.shrink - 1e-9
                && gap <= self.step + self.grow + 1e-9
        });
        if !ok {
            (self.anchors, self.dev, self.pts) = saved;
        }
        ok
    }

    /// Exhaustive search for short loops (n ≤ [`GRID_MAX_N`]), whose gaps have room to differ
    /// (B/n each): every droplet on a grid of δ = min(B/n, B/24)/8 of arc from a first one at
    /// each grid point of [0, B) (some droplet lies there in any placement), the next within
    /// [B·(1 − 1/n), B] and at least 2/3 B away, round to the first again. True if found.
    fn grid_search(&mut self) -> bool {
        let n = self.n;
        if n > GRID_MAX_N {
            return false;
        }
        let (lo, hi) = (self.step - self.shrink, self.step + self.grow);
        let length = self.arc.length();
        let delta = (hi - lo).min(hi / 24.0) / 8.0;
        if delta.is_nan() || delta <= 0.0 {
            return false;
        }
        let cells = (length / delta).ceil() as usize + 1;
        let (klo, khi) = (
            |i: usize| ((i as f64 * lo).max(length - (n - i) as f64 * hi) / delta).ceil() as i64,
            |i: usize| ((i as f64 * hi).min(length - (n - i) as f64 * lo) / delta).floor() as i64,
        );
        let starts = (hi / delta).ceil() as usize;
        // Every droplet lies on the grid of δ from 0: the points once.
        let all: Vec<Point> = (0..cells + starts)
            .map(|k| self.arc.point(k as f64 * delta))
            .collect();
        for s0 in 0..starts {
            let t0 = s0 as f64 * delta;
            let pts = &all[s0..];
            // prev[i][k − klo(i)]: the k of droplet i − 1 it is reached from.
            let mut prev: Vec<Vec<i64>> = vec![vec![0]];
            let mut ok = true;
            for i in 1..n {
                let (a, b) = (klo(i), khi(i));
                if b < a {
                    ok = false;
                    break;
                }
                let (pa, pb) = (klo(i - 1).max(0), khi(i - 1));
                let pa = if i == 1 { 0 } else { pa };
                let pb = if i == 1 { 0 } else { pb };
                let mut row = vec![-1i64; (b - a + 1) as usize];
                for (r, k) in (a..=b).enumerate() {
                    for j in pa..=pb {
                        let reached = i == 1 || prev[i - 1][(j - pa) as usize] >= 0;
                        let gap = (k - j) as f64 * delta;
                        if reached
                            && gap >= lo
                            && gap <= hi
                            && (k as usize) < cells
                            && dist(pts[j as usize], pts[k as usize]) >= self.min_chord
                        {
                            row[r] = j;
                            break;
                        }
                    }
                }
                if row.iter().all(|&x| x < 0) {
                    ok = false;
                    break;
                }
                prev.push(row);
            }
            if !ok {
                continue;
            }
            // The last droplet back to the first.
            let (a, b) = (klo(n - 1), khi(n - 1));
            let last = (a..=b).find(|&k| {
                let gap = length - k as f64 * delta;
                prev[n - 1][(k - a) as usize] >= 0
                    && gap >= lo
                    && gap <= hi
                    && dist(pts[k as usize], pts[0]) >= self.min_chord
            });
            let Some(mut k) = last else { continue };
            let mut ks = vec![0i64; n];
            for i in (1..n).rev() {
                ks[i] = k;
                k = prev[i][(k - klo(i)) as usize];
            }
            for i in 0..n {
                let t = t0 + ks[i] as f64 * delta;
                self.dev[i] = t - i as f64 * self.step;
                self.pts[i] = pts[ks[i] as usize];
            }
            self.dev[n] = self.dev[0];
            self.pts[n] = self.pts[0];
            self.anchors = (0..=n).map(|i| (i, self.dev[i])).collect();
            return true;
        }
        false
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

/// A droplet index and the deviations it can have there (sorted disjoint intervals).
type Reach = (usize, Vec<(f64, f64)>);

/// Sorts and merges overlapping intervals.
fn merge(v: &mut Vec<(f64, f64)>) {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(v.len());
    for &(a, b) in v.iter() {
        match out.last_mut() {
            Some(l) if a <= l.1 => l.1 = l.1.max(b),
            _ => out.push((a, b)),
        }
    }
    *v = out;
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

    /// Arc positions of droplets on a loop (the nearest projection, each forward of the last).
    fn arc_gaps(lp: &[Point], d: &[Point]) -> Vec<f64> {
        let m = lp.len();
        let mut at = vec![0.0];
        for i in 0..m {
            at.push(at[i] + dist(lp[i], lp[(i + 1) % m]));
        }
        let length = at[m];
        let pos = |p: Point| {
            (0..m)
                .map(|i| {
                    let (a, b) = (lp[i], lp[(i + 1) % m]);
                    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    (dist(p, a + (b - a) * t), at[i] + t * dist(a, b))
                })
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap()
                .1
        };
        let s: Vec<f64> = d.iter().map(|&p| pos(p)).collect();
        (0..d.len())
            .map(|i| (s[(i + 1) % d.len()] - s[i]).rem_euclid(length))
            .collect()
    }

    #[test]
    fn even_spacing_along_the_loop() {
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
        // A sliver with a sharp tip (7°), a narrow slot (a hairpin 0.05 mm wide) and a loop of
        // about 5 B.
        let sliver: Vec<Point> = [[0.0, 0.0], [5.0, 0.3], [0.0, 0.6]].map(Point::from).into();
        let slot: Vec<Point> = [
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 2.0],
            [2.025, 2.0],
            [2.025, 0.5],
            [1.975, 0.5],
            [1.975, 2.0],
            [0.0, 2.0],
        ]
        .map(Point::from)
        .into();
        let small: Vec<Point> = [[0.0, 0.0], [0.3, 0.0], [0.3, 0.25], [0.0, 0.25]]
            .map(Point::from)
            .into();
        for (name, lp) in [
            ("square", &sq),
            ("circle", &circle),
            ("sliver", &sliver),
            ("slot", &slot),
            ("small", &small),
        ] {
            let m = lp.len();
            let length: f64 = (0..m).map(|i| dist(lp[i], lp[(i + 1) % m])).sum();
            let n = (length / b).ceil() as usize;
            for shift in [0.0, 0.07, 3.3, 41.0] {
                let even = loop_droplets_spaced(lp, b, shift, true, LoopSpacing::Even);
                assert_eq!(even.len(), n, "{name} {shift}");
                let lower = b * (1.0 - 1.0 / n as f64);
                for (i, g) in arc_gaps(lp, &even).into_iter().enumerate() {
                    assert!(
                        g >= lower - 1e-9 && g <= b + 1e-9,
                        "{name} {shift}: arc gap {i} {g}"
                    );
                }
                for i in 0..n {
                    let c = dist(even[i], even[(i + 1) % n]);
                    assert!(
                        c >= 2.0 / 3.0 * b - 1e-9 && c <= b + 1e-9,
                        "{name} {shift}: chord {i} {c}"
                    );
                }
                // Where no pair is short, the droplets are the even ones from the start.
                if name == "circle" || name == "square" {
                    let start = loop_droplets(lp, b, shift, true)[0];
                    assert!(dist(even[0], start) < 1e-9, "{name} {shift}: start");
                }
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
