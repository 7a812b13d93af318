//! `exact` spacing: centres exactly B apart in a straight line, walked along the loop.

use super::unrolled;
use crate::base::geom::{DVec2, Point};

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
