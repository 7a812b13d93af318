//! Fill, stage 4 (docs/spec.md 5.3.4): fill region → hatch segments at the layer's angle, spaced
//! B / fill_density, clipped to the region (non-zero rule), then ordered greedily: after each
//! segment, go to the nearest end of an unprinted segment, reversing it if that end is its end.
//!
//! Hatch lines lie at (j + ½)·spacing from the origin across the hatch direction, for whole j,
//! so two layers with the same angle have their lines in the same places; with `stagger`, some
//! layers use (j + 0)·spacing instead (see [`crate::slicing::fill::hatch_shifted`]).

use crate::base::nearest::NearestGrid;

use crate::base::geom::{DVec2, Point, Shapes, scanline_spans, sin_cos_deg};

/// One hatch segment: a `G25` line from `a` to `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HatchLine {
    pub a: Point,
    pub b: Point,
}

/// Segments shorter than this are dropped (tangent touches of a scanline).
const MIN_LENGTH_MM: f64 = 1e-6;

/// Unordered hatch segments of a region, lines at (j + ½)·spacing.
pub fn hatch(region: &Shapes, angle_deg: f64, spacing: f64) -> Vec<HatchLine> {
    hatch_at(region, angle_deg, spacing, 0.5, None)
}

/// Unordered hatch segments of a region, lines at (j + `phase`)·spacing across the hatch
/// direction. With `lattice = Some((pitch, along, reach))`, each segment's ends move to points
/// (k + along)·pitch along the hatch direction, so its droplets lie on that lattice whichever
/// end it is printed from: outward (by less than a pitch, leaving no gap) where that stays
/// within `reach` of the region (the margin between the fill region and the part), else inward.
pub fn hatch_at(
    region: &Shapes,
    angle_deg: f64,
    spacing: f64,
    phase: f64,
    lattice: Option<(f64, f64, f64)>,
) -> Vec<HatchLine> {
    let (s, c) = sin_cos_deg(angle_deg);
    // Into the hatch frame (rotate by −angle): the lines become horizontal.
    let to = |p: Point| DVec2::new(c * p[0] + s * p[1], -s * p[0] + c * p[1]);
    let back = |p: Point| DVec2::new(c * p[0] - s * p[1], s * p[0] + c * p[1]);
    let mut lines = Vec::new();
    scanline_spans(
        region,
        to,
        0.0,
        spacing,
        phase,
        i64::MIN..i64::MAX,
        |j, x0, x1| {
            if x1 - x0 < MIN_LENGTH_MM {
                return;
            }
            let y = (j as f64 + phase) * spacing;
            let (mut x0, mut x1) = (x0, x1);
            if let Some((pitch, along, reach)) = lattice {
                let (lo, hi) = ((x0 / pitch - along).floor(), (x1 / pitch - along).ceil());
                let mut s0 = (lo + along) * pitch;
                let mut s1 = (hi + along) * pitch;
                // Whether a lattice point is left is decided on the whole numbers: one point
                // reached from both sides may differ in its last bit.
                let (mut k0, mut k1) = (lo, hi);
                if x0 - s0 > reach {
                    s0 += pitch;
                    k0 += 1.0;
                }
                if s1 - x1 > reach {
                    s1 -= pitch;
                    k1 -= 1.0;
                }
                if k1 >= k0 {
                    (x0, x1) = (s0, if k1 == k0 { s0 } else { s1 });
                }
            }
            lines.push(HatchLine {
                a: back(DVec2::new(x0, y)),
                b: back(DVec2::new(x1, y)),
            });
        },
    );
    lines
}

/// Greedy order from `from`: always the nearest unprinted segment end next.
pub fn order_greedy(lines: Vec<HatchLine>, from: Point) -> Vec<HatchLine> {
    if lines.len() <= 1 {
        return lines;
    }
    // End id = 2·segment + {0: a, 1: b}; of equally near ends, the least id.
    let mut grid = NearestGrid::new(lines.iter().flat_map(|l| [l.a, l.b]).collect());
    walk_ends(&lines, from, |at| {
        let end = grid.nearest(at, |e| e)?;
        grid.remove(end);
        grid.remove(end ^ 1);
        Some(end)
    })
}

/// The walk over `lines` from `from` that takes next the end `next(at)` gives (end id =
/// 2·segment + {0: a, 1: b}; `next` also takes that segment's ends out), each segment from
/// that end, until `next` gives none.
pub fn walk_ends(
    lines: &[HatchLine],
    from: Point,
    mut next: impl FnMut(Point) -> Option<usize>,
) -> Vec<HatchLine> {
    let mut out = Vec::with_capacity(lines.len());
    let mut at = from;
    while let Some(end) = next(at) {
        let l = lines[end / 2];
        let l = if end % 2 == 0 {
            l
        } else {
            HatchLine { a: l.b, b: l.a }
        };
        at = l.b;
        out.push(l);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::dist;
    use crate::base::geom::square;

    #[test]
    fn a_span_with_one_lattice_point_gives_that_point() {
        // Spans holding exactly one lattice point k·pitch, for k where that point reached from
        // below ((k − 1)·pitch + pitch) and from above ((k + 1)·pitch − pitch) differ in the
        // last bit: one droplet on the lattice point, not the span's own ends.
        let pitch = 0.208;
        let ks: Vec<f64> = (1..2000)
            .map(|k| k as f64)
            .filter(|&k| (k - 1.0) * pitch + pitch != (k + 1.0) * pitch - pitch)
            .take(20)
            .collect();
        assert!(ks.len() >= 5, "{}", ks.len());
        for k in ks {
            let (x0, x1) = ((k - 0.45) * pitch, (k + 0.4) * pitch);
            let region = vec![crate::base::geom::Shape::new(
                [[x0, 0.0], [x1, 0.0], [x1, 1.0], [x0, 1.0]]
                    .map(DVec2::from)
                    .into(),
                vec![],
            )];
            let lines = hatch_at(&region, 0.0, 0.5, 0.5, Some((pitch, 0.0, 0.0)));
            assert_eq!(lines.len(), 2, "k {k}");
            for l in lines {
                assert_eq!(l.a, l.b, "k {k}");
                assert!((l.a.x - k * pitch).abs() < 1e-12, "k {k}: {}", l.a.x);
            }
        }
    }

    #[test]
    fn horizontal_hatch_of_a_square() {
        let lines = hatch(&square(0.0, 0.0, 10.0), 0.0, 1.0);
        assert_eq!(lines.len(), 10);
        for l in &lines {
            assert!((dist(l.a, l.b) - 10.0).abs() < 1e-12);
        }
    }

    use crate::base::testing::random;

    #[test]
    fn greedy_takes_the_nearest_end_as_a_scan_of_every_end_does() {
        // Random segments in clusters (far jumps between them) and on a lattice (equal
        // distances, where the lower end id wins): each next segment is the one a scan of
        // every remaining end picks.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        for case in 0..40 {
            let mut lines = Vec::new();
            // (A single line is kept as it is.)
            let n = 2 + case * 7;
            for k in 0..n {
                let c = if k % 3 == 0 { 50.0 } else { 0.0 };
                let p = |s: &mut u64| {
                    if case % 2 == 0 {
                        DVec2::new(c + random(s) * 10.0, random(s) * 5.0)
                    } else {
                        DVec2::new((random(s) * 8.0).floor() * 0.25, (random(s) * 8.0).floor())
                    }
                };
                lines.push(HatchLine {
                    a: p(&mut seed),
                    b: p(&mut seed),
                });
            }
            let from = DVec2::new(random(&mut seed) * 60.0, -3.0);
            let ordered = order_greedy(lines.clone(), from);
            // The scan: the least (distance, end id) over the ends of the lines left.
            let mut left: Vec<Option<HatchLine>> = lines.iter().copied().map(Some).collect();
            let mut at = from;
            for got in ordered {
                let mut best: Option<(f64, usize)> = None;
                for (i, l) in left.iter().enumerate() {
                    if let Some(l) = l {
                        for (e, q) in [(2 * i, l.a), (2 * i + 1, l.b)] {
                            let d = dist(at, q);
                            if best.is_none_or(|(bd, be)| d < bd || (d == bd && e < be)) {
                                best = Some((d, e));
                            }
                        }
                    }
                }
                let (_, e) = best.expect("a line is left");
                let l = left[e / 2].take().expect("alive");
                let want = if e % 2 == 0 {
                    l
                } else {
                    HatchLine { a: l.b, b: l.a }
                };
                assert_eq!(got, want, "case {case}");
                at = want.b;
            }
            assert!(left.iter().all(Option::is_none));
        }
    }

    #[test]
    fn greedy_is_a_boustrophedon_on_a_square() {
        let lines = hatch(&square(0.0, 0.0, 10.0), 45.0, 0.5);
        let total: f64 = lines.iter().map(|l| dist(l.a, l.b)).sum();
        // Area / spacing.
        assert!((total - 200.0).abs() < 1.0, "{total}");
        // From the corner where the 45° lines begin, greedy sweeps to the opposite corner.
        let ordered = order_greedy(lines.clone(), DVec2::new(0.0, 10.0));
        assert_eq!(ordered.len(), lines.len());
        // Each next segment starts at the nearest remaining end: consecutive lines are neighbours.
        for w in ordered.windows(2) {
            assert!(dist(w[0].b, w[1].a) < 1.0, "{:?}", w);
        }
    }
}
