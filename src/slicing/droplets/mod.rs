//! Droplets on contours, stage 5 (docs/spec.md 5.3.5, "Loop seams"): a closed loop → droplet
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
//!
//! Here the dispatch by `loop_spacing` and the loop's start; `exact.rs` walks the circles,
//! `even.rs` spaces and moves the droplets (its searches in `even/search.rs`).

use crate::base::geom::{DVec2, Point, dist};
use crate::base::settings::LoopSpacing;

mod even;
mod exact;

use even::even_droplets;
pub use exact::loop_droplets;

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

/// The length of the closed polyline `points`.
fn loop_length(points: &[Point]) -> f64 {
    let n = points.len();
    (0..n).map(|i| dist(points[i], points[(i + 1) % n])).sum()
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
    let length = loop_length(points);
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
