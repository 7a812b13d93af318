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

/// `even` spacing, or `None` where the loop is printed as `exact` (see the module doc).
fn even_droplets(points: &[Point], b: f64, shift: f64) -> Option<Vec<Point>> {
    let m = points.len();
    let length: f64 = (0..m).map(|i| dist(points[i], points[(i + 1) % m])).sum();
    if length.is_nan() || length < EVEN_MIN_LENGTH_B * b || b.is_nan() || b <= 0.0 {
        return None;
    }
    let path = unrolled(points, shift);
    let start = path[0];
    let mut out = Vec::new();
    walk(&path, b, usize::MAX, &mut out);
    // The walk may end exactly on the start: then k steps of B close the loop.
    if out.len() > 1 && dist(*out.last().expect("non-empty"), start) < 1e-9 {
        out.pop();
        return (out.len() >= 3).then_some(out);
    }
    let n = out.len();
    if n < 3 {
        return None;
    }
    let chord_length = (n - 1) as f64 * b + dist(out[n - 1], start);
    // Across a narrow bend, n droplets may have no closing spacing: a few more may; else
    // spacing along the arc.
    (n..n + 4)
        .find_map(|n| close_evenly(&path, b, n, chord_length))
        .or_else(|| Some(along_arc(&path, length, b)))
}

/// n = ⌈L/B⌉ droplets at arc lengths i·L/n from the start of `path` (the loop from its start
/// back to it, of length `length`).
fn along_arc(path: &[Point], length: f64, b: f64) -> Vec<Point> {
    let n = (length / b).ceil().max(1.0) as usize;
    let step = length / n as f64;
    let mut out = Vec::with_capacity(n);
    let (mut e, mut before) = (0usize, 0.0);
    for i in 0..n {
        let at = i as f64 * step;
        while e + 2 < path.len() && before + dist(path[e], path[e + 1]) <= at {
            before += dist(path[e], path[e + 1]);
            e += 1;
        }
        let (p, q) = (path[e], path[e + 1]);
        let l = dist(p, q);
        let t = if l > 0.0 {
            ((at - before) / l).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(p + (q - p) * t);
    }
    out
}

/// The walk of `n` droplets whose seam gap (droplet n − 1 → start) equals its spacing s ≤ B,
/// or, where the walk jumps, the largest s whose seam gap is between s and B.
fn close_evenly(path: &[Point], b: f64, n: usize, chord_length: f64) -> Option<Vec<Point>> {
    let start = path[0];
    // g(s) = chord from droplet n − 1 back to the start, minus s (−∞ if the walk cannot make
    // n − 1 steps of s). g(B) < 0.
    let mut buf = Vec::with_capacity(n);
    let g = |s: f64, buf: &mut Vec<Point>| -> f64 {
        walk(path, s, n, buf);
        if buf.len() < n {
            f64::NEG_INFINITY
        } else {
            dist(buf[n - 1], start) - s
        }
    };
    let (mut hi, mut g_hi) = (b, g(b, &mut buf));
    // A lower end with g > 0: from L/n down.
    let mut lo = chord_length / n as f64;
    let mut g_lo = g(lo, &mut buf);
    let mut tries = 0;
    while g_lo.is_nan() || g_lo <= 0.0 {
        if g_lo == 0.0 {
            return Some(buf);
        }
        (hi, g_hi) = (lo, g_lo);
        lo *= 0.97;
        g_lo = g(lo, &mut buf);
        tries += 1;
        if tries > 40 {
            return None;
        }
    }
    // Illinois regula falsi on [lo, hi]; the walk at `lo` (g ≥ 0) is kept.
    let mut best = buf.clone();
    let mut best_g = g_lo;
    // The walk at `hi` and its true g (g_hi is halved by the Illinois steps).
    let (mut above, mut above_g) = (Vec::new(), f64::NEG_INFINITY);
    let mut side = 0i8;
    for _ in 0..100 {
        if best_g <= 1e-9 * b || hi - lo <= 1e-12 * b {
            break;
        }
        let s = if g_hi.is_finite() {
            let t = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
            if t > lo && t < hi { t } else { 0.5 * (lo + hi) }
        } else {
            0.5 * (lo + hi)
        };
        let v = g(s, &mut buf);
        if v >= 0.0 {
            (lo, g_lo) = (s, v);
            std::mem::swap(&mut best, &mut buf);
            best_g = v;
            if side == 1 && g_hi.is_finite() {
                g_hi *= 0.5;
            }
            side = 1;
        } else {
            (hi, g_hi) = (s, v);
            above_g = v;
            std::mem::swap(&mut above, &mut buf);
            if side == -1 {
                g_lo *= 0.5;
            }
            side = -1;
        }
    }
    // Where the walk jumps (at a hairpin the first exit leaps from one side to the other as s
    // grows) g has no root: the seam gap is s + g, longer than the others below the jump,
    // shorter above it. The walk whose seam is nearer its spacing is kept if the seam is at
    // most B and at least (1 − 1/n)·s.
    let ok = |s: f64, g: f64| {
        s + g <= b && s + g >= (1.0 - 1.0 / n as f64) * s && s + g.min(0.0) >= 2.0 / 3.0 * b
    };
    match (ok(lo, best_g), ok(hi, above_g)) {
        (true, true) if above_g.abs() < best_g => Some(above),
        (true, _) => Some(best),
        (false, true) => Some(above),
        _ => None,
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
