//! The searches of `even` spacing for placements with no pair too close: gates propagated
//! round the loop, the exhaustive grid for short loops and the windows placed afresh.

use super::EvenSpacing;
use crate::base::geom::{Point, dist};

/// The longest loop (droplets) searched exhaustively where the faster placements fail.
const GRID_MAX_N: usize = 64;

/// The longest loop (droplets) placed afresh as a whole by the last stage.
const WINDOW_LOOP_MAX_N: usize = 160;

impl EvenSpacing<'_> {
    /// Last stage: for each pair still short, the droplets of a window round it (growing, up
    /// to the whole loop) are placed afresh on a fine grid of arc positions between the
    /// window's two end droplets, kept where they are: a search over every grid position
    /// each droplet can reach with gaps in [B·(1 − 1/n), B] and chords of at least 2/3 B.
    pub(super) fn repair_windows(&mut self) {
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
    pub(super) fn gates(&mut self) -> bool {
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
    pub(super) fn grid_search(&mut self) -> bool {
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
