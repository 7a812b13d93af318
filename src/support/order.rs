//! The support hatch's nearest-end order ([`crate::support::moves::support_moves`]): the order of
//! [`order_greedy`] (always the nearest end of a segment not yet printed, of equally near ends
//! the least end id), found through the rows the segments lie on.
//!
//! The support's runs lie along the rows of its lattice (docs/support.md), so their ends lie on
//! few rows across the hatch direction, most of them on a region's boundary: a uniform grid
//! over their box holds them unevenly and its ring searches look at many empty cells. Here the
//! ends are bucketed by rows of the hatch spacing across the direction, each row's ends sorted
//! along it; a query looks at the rows outward from its own and, in each, at the ends outward
//! from its place, while they may lie as near as the best so far. Removed ends and emptied
//! rows are skipped by links to the next live one (path halving). The distances are the same
//! `dist`s and the ties the same ids as [`order_greedy`]'s, so the order is the same (its test
//! below); the rows only choose which ends are looked at.

use crate::base::geom::{Point, dist};
use crate::slicing::hatch::{HatchLine, order_greedy, walk_ends};

/// Exactly `order_greedy(lines, from)`, faster for segments along the direction whose sine and
/// cosine are `sin`, `cos` and lying on rows `h` apart across it (any segments give the same
/// order; segments spread over far more rows than ends fall back to [`order_greedy`]).
pub fn order_by_rows(
    lines: Vec<HatchLine>,
    from: Point,
    sin: f64,
    cos: f64,
    h: f64,
) -> Vec<HatchLine> {
    if lines.len() <= 1 {
        return lines;
    }
    match Rows::new(&lines, sin, cos, h) {
        Some(mut rows) => walk_ends(&lines, from, |at| {
            let end = rows.nearest(at)?;
            rows.remove(end);
            rows.remove(end ^ 1);
            Some(end)
        }),
        None => order_greedy(lines, from),
    }
}

/// First live index at or after `q` (`next[q] == q`: live, or the end marker), halving the
/// paths it walks.
fn find(next: &mut [u32], mut q: usize) -> usize {
    while next[q] as usize != q {
        let g = next[next[q] as usize];
        next[q] = g;
        q = g as usize;
    }
    q
}

/// The ends of segments by rows across a direction, live ones linked ([`order_by_rows`]).
struct Rows {
    sin: f64,
    cos: f64,
    h: f64,
    /// The first row's number (rows ⌊y / h⌋ of the ends' places `y` across).
    k0: f64,
    rows: usize,
    /// End id e's point (2·segment + {0: a, 1: b}).
    ends: Vec<Point>,
    /// Row r's ends are `order[start[r]..start[r + 1]]`, by their place along (`xs`).
    start: Vec<u32>,
    order: Vec<u32>,
    xs: Vec<f64>,
    /// End id e's position in `order`, and its row.
    pos: Vec<u32>,
    row_of: Vec<u32>,
    live: Vec<u32>,
    /// Links to the next live position at or after (`right`) and at or before (`left`,
    /// shifted by one: 0 is the marker) a position; the same for non-empty rows.
    right: Vec<u32>,
    left: Vec<u32>,
    up: Vec<u32>,
    down: Vec<u32>,
}

impl Rows {
    fn new(lines: &[HatchLine], sin: f64, cos: f64, h: f64) -> Option<Rows> {
        if !(h > 0.0 && h.is_finite() && sin.is_finite() && cos.is_finite()) {
            return None;
        }
        let ends: Vec<Point> = lines.iter().flat_map(|l| [l.a, l.b]).collect();
        let n = ends.len();
        u32::try_from(n + 1).ok()?;
        let across = |p: Point| (-sin * p.x + cos * p.y) / h;
        let (mut k0, mut k1) = (f64::INFINITY, f64::NEG_INFINITY);
        for &p in &ends {
            let k = across(p).floor();
            (k0, k1) = (k0.min(k), k1.max(k));
        }
        if !(k0.is_finite() && k1.is_finite() && k1 - k0 <= (4 * n + 1024) as f64) {
            return None;
        }
        let rows = (k1 - k0) as usize + 1;
        let row_of: Vec<u32> = ends
            .iter()
            .map(|&p| (across(p).floor() - k0) as u32)
            .collect();
        // By row (a counting sort), then by place along.
        let mut start = vec![0u32; rows + 1];
        for &r in &row_of {
            start[r as usize + 1] += 1;
        }
        for r in 0..rows {
            start[r + 1] += start[r];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; n];
        for (e, &r) in row_of.iter().enumerate() {
            let at = &mut fill[r as usize];
            order[*at as usize] = e as u32;
            *at += 1;
        }
        let along = |p: Point| cos * p.x + sin * p.y;
        for r in 0..rows {
            order[start[r] as usize..start[r + 1] as usize].sort_unstable_by(|&a, &b| {
                along(ends[a as usize]).total_cmp(&along(ends[b as usize]))
            });
        }
        let xs: Vec<f64> = order.iter().map(|&e| along(ends[e as usize])).collect();
        let mut pos = vec![0u32; n];
        for (q, &e) in order.iter().enumerate() {
            pos[e as usize] = q as u32;
        }
        let live: Vec<u32> = (0..rows).map(|r| start[r + 1] - start[r]).collect();
        let up = (0..=rows)
            .map(|r| if r < rows && live[r] == 0 { r + 1 } else { r } as u32)
            .collect();
        let down = (0..=rows)
            .map(|r| if r > 0 && live[r - 1] == 0 { r - 1 } else { r } as u32)
            .collect();
        Some(Rows {
            sin,
            cos,
            h,
            k0,
            rows,
            ends,
            start,
            order,
            xs,
            pos,
            row_of,
            live,
            right: (0..=n as u32).collect(),
            left: (0..=n as u32).collect(),
            up,
            down,
        })
    }

    /// Takes end `e` out.
    fn remove(&mut self, e: usize) {
        let q = self.pos[e] as usize;
        if self.right[q] as usize != q {
            return;
        }
        self.right[q] = q as u32 + 1;
        self.left[q + 1] = q as u32;
        let r = self.row_of[e] as usize;
        self.live[r] -= 1;
        if self.live[r] == 0 {
            self.up[r] = r as u32 + 1;
            self.down[r + 1] = r as u32;
        }
    }

    /// The live end nearest to `p` (by [`dist`]; of equally near ones the least id), if any.
    fn nearest(&mut self, p: Point) -> Option<usize> {
        let x = self.cos * p.x + self.sin * p.y;
        let y = -self.sin * p.x + self.cos * p.y;
        // p's row (clamped into the rows: the rows' bounds below are then 0 or more).
        let kp = ((y / self.h).floor() - self.k0).clamp(-1.0, self.rows as f64);
        let kp = kp as i64;
        let mut up = (kp.max(0) as usize).min(self.rows);
        up = find(&mut self.up, up);
        // `down` shifted by one: row r is r + 1, 0 none.
        let mut down = find(&mut self.down, (kp.min(self.rows as i64)).max(0) as usize);
        let mut best: Option<(f64, usize)> = None;
        // How far a row lies across from p at least (less a slack for the rounding of the
        // rows' numbers and of the turn into the rows' frame).
        let (k0, h) = (self.k0, self.h);
        let gap = |r: usize| {
            let lo = (r as f64 + k0) * h;
            (lo - y).max(y - (lo + h)).max(0.0)
        };
        let bound =
            |b: Option<(f64, usize)>| b.map_or(f64::INFINITY, |(d, _)| d * (1.0 + 1e-9) + 1e-9);
        loop {
            let g_up = (up < self.rows).then(|| gap(up));
            let g_down = (down > 0).then(|| gap(down - 1));
            let (r, go_up) = match (g_up, g_down) {
                (Some(a), Some(b)) if a <= b => (up, true),
                (Some(_), Some(_)) => (down - 1, false),
                (Some(_), None) => (up, true),
                (None, Some(_)) => (down - 1, false),
                (None, None) => break,
            };
            let g = if go_up { g_up } else { g_down }.unwrap_or(0.0);
            if g > bound(best) {
                // Every row farther this way lies farther across.
                if go_up {
                    up = self.rows;
                } else {
                    down = 0;
                }
                continue;
            }
            self.scan_row(r, p, x, &mut best);
            if go_up {
                up = find(&mut self.up, r + 1);
            } else {
                down = find(&mut self.down, r);
            }
        }
        best.map(|(_, e)| e)
    }

    /// Looks at row `r`'s live ends outward from `x` (p's place along) for one nearer to `p`
    /// than `best` (or as near with a lesser id).
    fn scan_row(&mut self, r: usize, p: Point, x: f64, best: &mut Option<(f64, usize)>) {
        let (a, b) = (self.start[r] as usize, self.start[r + 1] as usize);
        let s = a + self.xs[a..b].partition_point(|&v| v < x);
        let look = |e: usize, best: &mut Option<(f64, usize)>| {
            let d = dist(p, self.ends[e]);
            if best.is_none_or(|(bd, be)| d < bd || (d == bd && e < be)) {
                *best = Some((d, e));
            }
        };
        let far = |b: &Option<(f64, usize)>, off: f64| {
            b.is_some_and(|(d, _)| off > d * (1.0 + 1e-9) + 1e-9)
        };
        let mut q = find(&mut self.right, s);
        while q < b && !far(best, self.xs[q] - x) {
            look(self.order[q] as usize, best);
            q = find(&mut self.right, q + 1);
        }
        // `left` shifted by one: position q is q + 1, 0 none.
        let mut q = find(&mut self.left, s);
        while q > a && !far(best, x - self.xs[q - 1]) {
            look(self.order[q - 1] as usize, best);
            q = find(&mut self.left, q - 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::sin_cos_deg;
    use crate::base::testing::random;

    use crate::base::geom::DVec2;

    #[test]
    fn the_order_is_that_of_the_greedy_order() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for case in 0..80 {
            let angle = [0.0, 90.0, 45.0, 135.0, 30.0][case % 5];
            let (sin, cos) = sin_cos_deg(angle);
            let h = 0.25;
            let back = |x: f64, y: f64| DVec2::new(cos * x - sin * y, sin * x + cos * y);
            let n = 1 + case * 3;
            let lines: Vec<HatchLine> = (0..n)
                .map(|k| {
                    let r = |s: &mut u64| random(s);
                    match case % 4 {
                        // Runs on rows, ends on a lattice (many equal distances), some in a
                        // cluster far away.
                        0 | 1 => {
                            let far = if k % 5 == 0 { 40.0 } else { 0.0 };
                            let row = ((r(&mut seed) * 12.0).floor() + 0.5) * h;
                            let x0 = (r(&mut seed) * 20.0).floor() * 0.25 + far;
                            let x1 = x0 + (r(&mut seed) * 8.0).floor() * 0.25;
                            let (a, b) = (back(x0, row), back(x1, row));
                            if case % 2 == 0 {
                                HatchLine { a, b }
                            } else {
                                HatchLine { a: b, b: a }
                            }
                        }
                        // Anywhere.
                        2 => HatchLine {
                            a: DVec2::new(r(&mut seed) * 10.0, r(&mut seed) * 10.0),
                            b: DVec2::new(r(&mut seed) * 10.0, r(&mut seed) * 10.0),
                        },
                        // Points on a small lattice, both ends in one place at times.
                        _ => {
                            let a = DVec2::new(
                                (r(&mut seed) * 4.0).floor() * 0.5,
                                (r(&mut seed) * 4.0).floor() * 0.5,
                            );
                            let b = if r(&mut seed) < 0.3 {
                                a
                            } else {
                                DVec2::new((r(&mut seed) * 4.0).floor() * 0.5, a.y)
                            };
                            HatchLine { a, b }
                        }
                    }
                })
                .collect();
            let from = DVec2::new(
                random(&mut seed) * 60.0 - 10.0,
                random(&mut seed) * 8.0 - 4.0,
            );
            let want = order_greedy(lines.clone(), from);
            let got = order_by_rows(lines, from, sin, cos, h);
            assert_eq!(got, want, "case {case}");
        }
    }
}
