//! A layer's droplets as the lines the plan lays them on, and walks along them that pass over
//! the interior: the banded analysis visits the droplets near a boundary one by one and
//! counts those deep in the interior a stretch of a line at a time (the same droplets as
//! [`super::droplet_centres`], at the same points).

use crate::base::geom::{DVec2, Point, dist, line_droplet_count};
use crate::base::spatial::floor_i64;
use crate::slicing::plan::{LayerPlan, MoveKind};

/// Unit 0's droplets of a layer as lines (a single droplet a line from its point to itself):
/// droplet j of a line from a to c of length l lies at a + (j·B/l)·(c − a), j < the line's
/// count, as [`crate::base::geom::line_droplets`] places it.
#[derive(Clone, Debug, Default)]
pub struct DropletLines {
    b: f64,
    /// (from, to, droplets)
    lines: Vec<(Point, Point, u64)>,
    count: u64,
}

impl DropletLines {
    /// The lines of unit 0's droplets in `plan` (droplet width `b`), in print order.
    pub fn of(plan: &LayerPlan, b: f64) -> DropletLines {
        let mut lines = Vec::new();
        let mut count = 0;
        let mut at = Point::ZERO;
        for m in &plan.moves {
            if m.unit == 0 {
                let line = match m.kind {
                    MoveKind::Travel => None,
                    MoveKind::Droplet => Some((m.to, m.to, 1)),
                    MoveKind::Line => Some((at, m.to, line_droplet_count(dist(at, m.to), b))),
                };
                if let Some(l) = line.filter(|l| l.2 > 0) {
                    count += l.2;
                    lines.push(l);
                }
            }
            at = m.to;
        }
        DropletLines { b, lines, count }
    }

    /// Every droplet's centre, in order (those of [`super::droplet_centres`]).
    pub fn centres(&self) -> Vec<Point> {
        let mut out = Vec::with_capacity(self.count as usize);
        for &(a, c, n) in &self.lines {
            let l = dist(a, c);
            out.extend((0..n).map(|j| droplet(a, c, l, self.b, j)));
        }
        out
    }

    /// How many droplets.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The box of the droplets' centres (least, greatest corner; `None` without droplets):
    /// of the lines' ends, which hold them.
    pub fn bounds(&self) -> Option<(Point, Point)> {
        let mut it = self.lines.iter().flat_map(|l| [l.0, l.1]);
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }
}

/// Droplet j of the line from `a` to `c` of length `l`: the point
/// [`crate::base::geom::line_droplets`] computes.
#[inline]
fn droplet(a: Point, c: Point, l: f64, b: f64, j: u64) -> Point {
    let t = if l > 0.0 { j as f64 * b / l } else { 0.0 };
    DVec2::new(a[0] + t * (c[0] - a[0]), a[1] + t * (c[1] - a[1]))
}

/// Blocks over a layer (rectangles of `size` from `origin`, block (bx0, by0) first) flagged
/// where the droplets may be passed over, with each block's distance (in blocks, along both
/// axes at once) to the nearest block not flagged (0 for those; blocks outside the box are
/// not flagged). A droplet in a block 2 or more from any block not flagged lies with every
/// block its footprint touches (a block is wider than a droplet) among the flagged.
pub(super) struct SkipGrid {
    origin: Point,
    size: Point,
    bx0: i64,
    by0: i64,
    w: usize,
    h: usize,
    dist: Vec<u8>,
}

impl SkipGrid {
    /// The grid of `flags` (`w` × `h`, row by row) for blocks of `size` from `origin`, the
    /// first block (bx0, by0).
    pub(super) fn new(
        origin: Point,
        size: Point,
        (bx0, by0): (i64, i64),
        (w, h): (usize, usize),
        flags: impl Fn(usize) -> bool,
    ) -> SkipGrid {
        let mut d: Vec<u8> = (0..w * h).map(|i| if flags(i) { 255 } else { 0 }).collect();
        // Chessboard distances in two passes; outside the box counts as not flagged.
        let at = |d: &[u8], x: i64, y: i64| {
            if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                0
            } else {
                d[y as usize * w + x as usize]
            }
        };
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let i = y as usize * w + x as usize;
                if d[i] != 0 {
                    let m = [(-1, 0), (-1, -1), (0, -1), (1, -1)]
                        .iter()
                        .map(|&(dx, dy)| at(&d, x + dx, y + dy))
                        .min()
                        .unwrap_or(0);
                    d[i] = d[i].min(m.saturating_add(1));
                }
            }
        }
        for y in (0..h as i64).rev() {
            for x in (0..w as i64).rev() {
                let i = y as usize * w + x as usize;
                if d[i] != 0 {
                    let m = [(1, 0), (1, 1), (0, 1), (-1, 1)]
                        .iter()
                        .map(|&(dx, dy)| at(&d, x + dx, y + dy))
                        .min()
                        .unwrap_or(0);
                    d[i] = d[i].min(m.saturating_add(1));
                }
            }
        }
        SkipGrid {
            origin,
            size,
            bx0,
            by0,
            w,
            h,
            dist: d,
        }
    }

    /// The distance of the block holding `p`.
    #[inline]
    fn dist_at(&self, p: Point) -> u8 {
        let x = floor_i64((p[0] - self.origin[0]) / self.size[0]) - self.bx0;
        let y = floor_i64((p[1] - self.origin[1]) / self.size[1]) - self.by0;
        if x < 0 || y < 0 || x >= self.w as i64 || y >= self.h as i64 {
            return 0;
        }
        self.dist[y as usize * self.w + x as usize]
    }

    /// Calls `keep(p)` for every droplet of `lines` but those in blocks 2 or more from any
    /// block not flagged, which are counted: the count. A droplet in a block d ≥ 2 from one
    /// not flagged passes over the next droplets of its line that lie within d − 2 blocks of
    /// it along both axes (their blocks are within d − 1, so 1 or more from one not flagged …
    /// and, being less than d − 2 blocks away, 2 or more).
    pub(super) fn walk(&self, lines: &DropletLines, mut keep: impl FnMut(Point)) -> u64 {
        let mut passed = 0;
        let b = lines.b;
        let least = self.size[0].min(self.size[1]);
        for &(a, c, n) in &lines.lines {
            let l = dist(a, c);
            // How far a droplet moves along the axis it moves most on, per droplet.
            let step = if l > 0.0 {
                b * (c[0] - a[0]).abs().max((c[1] - a[1]).abs()) / l
            } else {
                0.0
            };
            let mut j = 0;
            while j < n {
                let p = droplet(a, c, l, b, j);
                let d = self.dist_at(p);
                if d < 2 {
                    keep(p);
                    j += 1;
                    continue;
                }
                // Strictly within d − 2 blocks: a droplet's block index moves by at most
                // ⌊moved / size⌋ + 1 along an axis.
                let room = (d - 2) as f64 * least * (1.0 - 1e-9);
                let more = if step > 0.0 {
                    (room / step).floor().min((n - j) as f64) as u64
                } else {
                    n
                };
                let k = (1 + more).min(n - j);
                passed += k;
                j += k;
            }
        }
        passed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(ls: &[(Point, Point)], b: f64) -> DropletLines {
        let mut out = DropletLines {
            b,
            ..Default::default()
        };
        for &(a, c) in ls {
            let n = line_droplet_count(dist(a, c), b);
            out.lines.push((a, c, n));
            out.count += n;
        }
        out
    }

    #[test]
    fn droplets_are_those_of_the_plans_lines() {
        let b = 0.208;
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let ls = lines(&[(p(0.1, 0.2), p(5.3, 7.7)), (p(1.0, 1.0), p(1.0, 1.0))], b);
        let want: Vec<Point> = crate::base::geom::line_droplets(p(0.1, 0.2), p(5.3, 7.7), b)
            .chain([p(1.0, 1.0)])
            .collect();
        assert_eq!(ls.centres(), want);
        assert_eq!(ls.count(), want.len() as u64);
    }

    #[test]
    fn a_walk_passes_over_only_droplets_deep_among_the_flagged_blocks() {
        // Blocks 1 mm square; flagged: a ring-free 30 × 20 patch with holes punched in.
        let mut random = crate::base::testing::rng(0x1234_5678_9abc_def1u64);
        let (w, h) = (40usize, 30usize);
        let flags: Vec<bool> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                (5..35).contains(&x) && (5..25).contains(&y) && random() > 0.03
            })
            .collect();
        let size = DVec2::new(1.0, 0.8);
        let g = SkipGrid::new(DVec2::new(-3.0, 2.0), size, (0, 0), (w, h), |i| flags[i]);
        let flag = |p: Point| {
            let (x, y) = (((p[0] + 3.0) / 1.0).floor(), ((p[1] - 2.0) / 0.8).floor());
            x >= 0.0
                && y >= 0.0
                && (x as usize) < w
                && (y as usize) < h
                && flags[y as usize * w + x as usize]
        };
        let r = 0.3;
        let mut passed_total = 0;
        for case in 0..300 {
            let q = |random: &mut dyn FnMut() -> f64| {
                DVec2::new(-3.0 + 40.0 * random(), 2.0 + 24.0 * random())
            };
            let (a, c) = (q(&mut random), q(&mut random));
            let ls = lines(&[(a, c)], 0.208);
            let mut kept = Vec::new();
            let passed = g.walk(&ls, |p| kept.push(p));
            let all = ls.centres();
            assert_eq!(passed + kept.len() as u64, all.len() as u64, "case {case}");
            // Every droplet passed over has its footprint among flagged blocks.
            let mut k = kept.iter().peekable();
            for p in &all {
                if k.peek() == Some(&p) {
                    k.next();
                    continue;
                }
                for (dx, dy) in [(-r, -r), (r, -r), (-r, r), (r, r)] {
                    assert!(flag(*p + DVec2::new(dx, dy)), "case {case}: {p}");
                }
            }
            passed_total += passed;
        }
        assert!(passed_total > 10_000, "{passed_total}");
    }
}
