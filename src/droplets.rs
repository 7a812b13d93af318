//! Droplets on contours, stage 5 (SPEC.md 5.3.5): a closed loop → droplet centres exactly B
//! apart (straight-line distance): the next centre is where the circle of radius B around the
//! previous one first leaves the loop further along. The walk starts `shift` mm (arc length)
//! after the loop's canonical start, its lowest point (then leftmost), so each layer's seam
//! moves on by `start_jitter`. With `close`, the first droplet is repeated at the end.

use crate::geom::{DVec2, Point, dist};

/// Droplet centres along a closed loop.
pub fn loop_droplets(points: &[Point], b: f64, shift: f64, close: bool) -> Vec<Point> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    let path = unrolled(points, shift);
    let start = path[0];
    let mut out = vec![start];
    let (mut c, mut i) = (start, 0usize);
    'walk: loop {
        while i + 1 < path.len() {
            if let Some(p) = circle_exit(path[i], path[i + 1], c, b) {
                out.push(p);
                c = p;
                continue 'walk;
            }
            i += 1;
        }
        break;
    }
    if close && out.len() > 1 {
        out.push(start);
    }
    out
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
}
