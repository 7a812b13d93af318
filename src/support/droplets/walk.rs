//! The order a layer's added support droplets are printed in: a greedy nearest-first walk.

use super::grid::floor;
use crate::base::geom::{DVec2, Point, dist};

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
