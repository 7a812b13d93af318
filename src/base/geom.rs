//! Geometry kernel: the plane types every stage shares, with the few figures they all use.
//!
//! - Points are [`glam::DVec2`] in millimetres (`p[0]`, `p[1]` or `p.x`, `p.y`).
//! - A [`Shape`] is an outer boundary, counter-clockwise, and its holes, clockwise: the
//!   material lies left of every loop. A [`Shapes`] is a layer's region: disjoint shapes.
//! - Angles are in degrees; [`sin_cos_deg`] is exact at multiples of 90°.
//! - Positions are written with [`OUTPUT_DECIMALS`] decimals; plans are rounded to them
//!   ([`round_output`]) so counts, previews and the code agree exactly.
//! - A `G25` line sets one droplet at its start and then one every B ([`line_droplets`]):
//!   the one rule the plan, the preview, the analysis and the `.gco` reader use.
//! - The boolean operations (i_overlay) take `[f64; 2]`: [`to_overlay`] and
//!   [`shapes_from_overlay`] convert at that boundary.

pub use glam::{DMat3, DVec2, DVec3};

/// A point of a layer, in mm.
pub type Point = DVec2;
/// A closed polygon (the last point connects to the first).
pub type Contour = Vec<Point>;

/// One connected piece of a layer's material.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Shape {
    /// The outer boundary, counter-clockwise.
    pub outer: Contour,
    /// The holes, clockwise.
    pub holes: Vec<Contour>,
}

/// A region of one layer: disjoint shapes.
pub type Shapes = Vec<Shape>;

impl Shape {
    pub fn new(outer: Contour, holes: Vec<Contour>) -> Shape {
        Shape { outer, holes }
    }

    /// The outer boundary, then the holes.
    pub fn contours(&self) -> impl Iterator<Item = &Contour> {
        std::iter::once(&self.outer).chain(&self.holes)
    }

    /// The outer boundary (`false`) then the holes (`true`).
    pub fn contours_with_hole(&self) -> impl Iterator<Item = (bool, &Contour)> {
        std::iter::once((false, &self.outer)).chain(self.holes.iter().map(|h| (true, h)))
    }

    /// Its area (outer minus holes).
    pub fn area(&self) -> f64 {
        self.contours().map(|c| signed_area(c)).sum()
    }
}

/// Every loop of a region, outer boundaries and holes.
pub fn all_contours(region: &Shapes) -> impl Iterator<Item = &Contour> {
    region.iter().flat_map(Shape::contours)
}

/// Positions are written with this many decimals.
pub const OUTPUT_DECIMALS: usize = 4;
/// 10^[`OUTPUT_DECIMALS`]: a position in output units is `(v * OUTPUT_SCALE).round()`.
pub const OUTPUT_SCALE: f64 = 10_000.0;

/// `p` rounded to the output precision, as written in the code.
pub fn round_output(p: Point) -> Point {
    DVec2::new(
        (p.x * OUTPUT_SCALE).round() / OUTPUT_SCALE,
        (p.y * OUTPUT_SCALE).round() / OUTPUT_SCALE,
    )
}

pub fn dist(a: Point, b: Point) -> f64 {
    // Not `hypot`: coordinates are millimetres, far from overflow, and hypot is several
    // times slower.
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    (dx * dx + dy * dy).sqrt()
}

/// Distance from `p` to the segment a–b.
pub fn segment_distance(p: Point, a: Point, b: Point) -> f64 {
    segment_distance2(p, a, b).sqrt()
}

/// Squared distance from `p` to the segment a–b.
pub fn segment_distance2(p: Point, a: Point, b: Point) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (x, y) = (p[0] - a[0] - t * d[0], p[1] - a[1] - t * d[1]);
    x * x + y * y
}

/// Signed area of a closed contour (positive = counter-clockwise).
pub fn signed_area(c: &[Point]) -> f64 {
    let n = c.len();
    (0..n)
        .map(|i| {
            let (p, q) = (c[i], c[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        / 2.0
}

/// Area of a region (outer boundaries minus holes).
pub fn region_area(shapes: &Shapes) -> f64 {
    all_contours(shapes).map(|c| signed_area(c)).sum()
}

/// sin and cos of an angle in degrees, exact at multiples of 90°.
pub fn sin_cos_deg(deg: f64) -> (f64, f64) {
    let q = deg / 90.0;
    if q == q.round() {
        match (q.round() as i64).rem_euclid(4) {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        deg.to_radians().sin_cos()
    }
}

/// Number of droplets a `G25` line of this length sets: one at its start, then one every B.
pub fn line_droplet_count(length: f64, b: f64) -> u64 {
    line_droplet_count_f64(length, b) as u64
}

/// [`line_droplet_count`] as a float, unbounded: for checking a line from an untrusted file
/// before it is expanded.
pub fn line_droplet_count_f64(length: f64, b: f64) -> f64 {
    (length / b + 1e-9).floor() + 1.0
}

/// The droplets of a `G25` line from `from` to `to`: one at `from`, then one every `b`
/// ([`line_droplet_count`] of them).
pub fn line_droplets(from: Point, to: Point, b: f64) -> impl Iterator<Item = Point> {
    let l = dist(from, to);
    (0..line_droplet_count(l, b)).map(move |j| line_droplet(from, to, l, b, j))
}

/// Droplet `j` of the line from `from` to `to` of length `l`: the one point of it that
/// [`line_droplets`] and [`line_droplets_in`] both compute.
#[inline]
pub fn line_droplet(from: Point, to: Point, l: f64, b: f64, j: u64) -> Point {
    let t = if l > 0.0 { j as f64 * b / l } else { 0.0 };
    DVec2::new(
        from[0] + t * (to[0] - from[0]),
        from[1] + t * (to[1] - from[1]),
    )
}

/// The droplets of [`line_droplets`] that lie in the box `lo`..=`hi` (both ends included), in
/// their order: the same points, but only those near the box are computed (a long line
/// crossing a small box costs a few, not all of its droplets).
pub fn line_droplets_in(
    from: Point,
    to: Point,
    b: f64,
    lo: Point,
    hi: Point,
) -> impl Iterator<Item = Point> {
    let l = dist(from, to);
    let count = line_droplet_count(l, b);
    // The line's parameter range within the box, s ∈ [s0, s1] (empty when s0 > s1).
    let (mut s0, mut s1) = (0.0f64, 1.0f64);
    for k in 0..2 {
        let d = to[k] - from[k];
        if d != 0.0 {
            let (a, e) = ((lo[k] - from[k]) / d, (hi[k] - from[k]) / d);
            s0 = s0.max(a.min(e));
            s1 = s1.min(a.max(e));
        } else if from[k] < lo[k] || from[k] > hi[k] {
            s1 = -1.0;
        }
    }
    // Droplet j lies at s = j·b/l: its indices, one more on each side for the rounding, and
    // every point still checked against the box.
    let js = if l.is_nan() || l <= 0.0 {
        0..count
    } else if s0.partial_cmp(&s1).is_none_or(|o| o.is_gt()) {
        0..0
    } else {
        let k = l / b;
        let j0 = ((s0 * k).floor() - 1.0).max(0.0) as u64;
        let j1 = ((s1 * k).ceil() + 2.0).max(0.0) as u64;
        j0.min(count)..j1.min(count)
    };
    js.map(move |j| line_droplet(from, to, l, b, j))
        .filter(move |p| p.cmpge(lo).all() && p.cmple(hi).all())
}

/// Loops in the boolean engine's point type.
pub fn to_overlay<'a>(contours: impl IntoIterator<Item = &'a Contour>) -> Vec<Vec<[f64; 2]>> {
    contours
        .into_iter()
        .map(|c| c.iter().map(|p| p.to_array()).collect())
        .collect()
}

/// A loop from the boolean engine's point type.
pub fn contour_from_overlay(c: Vec<[f64; 2]>) -> Contour {
    c.into_iter().map(DVec2::from).collect()
}

/// Shapes from the boolean engine (each its outer boundary followed by its holes).
pub fn shapes_from_overlay(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Shapes {
    shapes
        .into_iter()
        .filter_map(|s| {
            let mut loops = s.into_iter().map(contour_from_overlay);
            let outer = loops.next()?;
            Some(Shape::new(outer, loops.collect()))
        })
        .collect()
}

/// Crosses a region with the lines y = y0 + (k + phase)·step, k in `rows`: calls
/// `span(k, xa, xb)` for every span of a line inside the region (non-zero rule), in order of
/// k, then x; spans have xa < xb (a line touching the region at a point gives none). `to`
/// maps the region's points first (the hatch turns its lines horizontal).
pub fn scanline_spans(
    region: &Shapes,
    to: impl Fn(Point) -> Point,
    y0: f64,
    step: f64,
    phase: f64,
    rows: std::ops::Range<i64>,
    mut span: impl FnMut(i64, f64, f64),
) {
    // (line k, x, winding)
    let mut hits: Vec<(i64, f64, i32)> = Vec::new();
    for contour in all_contours(region) {
        let n = contour.len();
        for i in 0..n {
            let (p, q) = (to(contour[i]), to(contour[(i + 1) % n]));
            if p[1] == q[1] {
                continue;
            }
            let (lo, hi, w) = if p[1] < q[1] { (p, q, 1) } else { (q, p, -1) };
            // Lines with lo.y <= y < hi.y.
            let mut k = (((lo[1] - y0) / step - phase).ceil() as i64).max(rows.start);
            while k < rows.end {
                let y = y0 + (k as f64 + phase) * step;
                if y >= hi[1] {
                    break;
                }
                if y >= lo[1] {
                    let x = lo[0] + (y - lo[1]) * (hi[0] - lo[0]) / (hi[1] - lo[1]);
                    hits.push((k, x, w));
                }
                k += 1;
            }
        }
    }
    let (Some(k_min), Some(k_max)) = (
        hits.iter().map(|h| h.0).min(),
        hits.iter().map(|h| h.0).max(),
    ) else {
        return;
    };
    // By line, then x. The lines crossed are at most as many as the region spans steps: a
    // counting sort by line (each line's hits kept in the edges' order), then each line's
    // few hits by x, instead of a sort of all of them by both. Lines far more numerous than
    // the hits (parts far apart on a fine step) are sorted the other way.
    let lines = k_max.abs_diff(k_min);
    let by_line = if lines < 4 * hits.len() as u64 + 1024 {
        let lines = lines as usize + 1;
        let mut at = vec![0u32; lines + 1];
        for h in &hits {
            at[(h.0 - k_min) as usize + 1] += 1;
        }
        for i in 1..=lines {
            at[i] += at[i - 1];
        }
        let mut sorted = vec![(0i64, 0.0, 0i32); hits.len()];
        let mut next = at.clone();
        for &h in &hits {
            let slot = &mut next[(h.0 - k_min) as usize];
            sorted[*slot as usize] = h;
            *slot += 1;
        }
        for i in 0..lines {
            sorted[at[i] as usize..at[i + 1] as usize].sort_by(|a, b| a.1.total_cmp(&b.1));
        }
        sorted
    } else {
        hits.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        hits
    };
    for row in by_line.chunk_by(|a, b| a.0 == b.0) {
        let (mut winding, mut start) = (0, 0.0);
        // Crossings at one x are taken together: whatever their order, a line touching the
        // region at a point gives no span, and one passing a vertex inside it is not split.
        for at_x in row.chunk_by(|a, b| a.1 == b.1) {
            let (k, x) = (at_x[0].0, at_x[0].1);
            let before = winding;
            winding += at_x.iter().map(|h| h.2).sum::<i32>();
            if before == 0 && winding != 0 {
                start = x;
            } else if before != 0 && winding == 0 {
                span(k, start, x);
            }
        }
    }
}

/// The square [x0, x0 + a] × [y0, y0 + a], counter-clockwise (for the crate's unit tests).
#[cfg(test)]
pub(crate) fn square(x0: f64, y0: f64, a: f64) -> Shapes {
    let outer = [[x0, y0], [x0 + a, y0], [x0 + a, y0 + a], [x0, y0 + a]]
        .map(DVec2::from)
        .into();
    vec![Shape::new(outer, vec![])]
}

/// The smaller of two numbers that are not NaN, by one comparison: `f64::min` is a call into
/// the maths library in WebAssembly (its NaN rule), which the per-vertex loops of the mesh
/// preparation felt.
#[inline(always)]
pub fn lesser(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// The larger of two numbers that are not NaN (see [`lesser`]).
#[inline(always)]
pub fn greater(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lines_droplets_in_a_box_are_those_of_the_whole_line_in_it() {
        // Lines long and short, axis-parallel and of no length; boxes around, across, at an
        // end and beside them: the same points in the same order as the whole line filtered.
        let mut random = crate::base::testing::rng(0x5851_f42d_4c95_7f2du64);
        let mut kept = 0;
        for case in 0..2000 {
            let from = DVec2::new(random() * 40.0, random() * 40.0);
            let to = match case % 5 {
                0 => from,
                1 => DVec2::new(random() * 40.0, from.y),
                2 => DVec2::new(from.x, random() * 40.0),
                _ => DVec2::new(random() * 40.0, random() * 40.0),
            };
            let b = [0.2, 0.208, 0.5, 3.0][case % 4];
            let c = from + (to - from) * (random() * 1.4 - 0.2);
            let half = DVec2::new(random(), random()) * [0.0, 0.3, 2.0, 30.0][case / 4 % 4];
            let (lo, hi) = (c - half, c + half);
            let whole: Vec<Point> = line_droplets(from, to, b)
                .filter(|p| p.cmpge(lo).all() && p.cmple(hi).all())
                .collect();
            let part: Vec<Point> = line_droplets_in(from, to, b, lo, hi).collect();
            assert_eq!(part, whole, "case {case}: {from} {to} {b} {lo} {hi}");
            kept += whole.len();
        }
        assert!(kept > 5000, "{kept}");
    }

    #[test]
    fn right_angles_are_exact() {
        assert_eq!(sin_cos_deg(90.0), (1.0, 0.0));
        assert_eq!(sin_cos_deg(-90.0), (-1.0, 0.0));
        assert_eq!(sin_cos_deg(540.0), (0.0, -1.0));
    }

    #[test]
    fn a_line_sets_a_droplet_every_b() {
        let d: Vec<Point> =
            line_droplets(DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), 0.25).collect();
        assert_eq!(d.len(), 5);
        assert_eq!(d[4], DVec2::new(1.0, 0.0));
        assert_eq!(line_droplets(DVec2::ZERO, DVec2::ZERO, 0.2).count(), 1);
    }

    #[test]
    fn area_of_a_square_with_a_hole() {
        let sq = |a: f64| {
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(a, 0.0),
                DVec2::new(a, a),
                DVec2::new(0.0, a),
            ]
        };
        let mut hole = sq(1.0);
        hole.reverse();
        let s = vec![Shape::new(sq(4.0), vec![hole])];
        assert_eq!(region_area(&s), 15.0);
    }

    /// The spans of [`scanline_spans`] by one sort of all the crossings by line and x.
    fn spans_by_one_sort(
        region: &Shapes,
        y0: f64,
        step: f64,
        phase: f64,
        rows: std::ops::Range<i64>,
    ) -> Vec<(i64, f64, f64)> {
        let mut hits: Vec<(i64, f64, i32)> = Vec::new();
        for contour in all_contours(region) {
            for i in 0..contour.len() {
                let (p, q) = (contour[i], contour[(i + 1) % contour.len()]);
                if p[1] == q[1] {
                    continue;
                }
                let (lo, hi, w) = if p[1] < q[1] { (p, q, 1) } else { (q, p, -1) };
                for k in rows.clone() {
                    let y = y0 + (k as f64 + phase) * step;
                    if y >= lo[1] && y < hi[1] {
                        let x = lo[0] + (y - lo[1]) * (hi[0] - lo[0]) / (hi[1] - lo[1]);
                        hits.push((k, x, w));
                    }
                }
            }
        }
        hits.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let mut out = Vec::new();
        for row in hits.chunk_by(|a, b| a.0 == b.0) {
            // The winding just right of each crossing's x, spans where it is not zero.
            let mut winding = 0;
            let mut start = None;
            for (i, &(k, x, w)) in row.iter().enumerate() {
                winding += w;
                if row.get(i + 1).is_some_and(|h| h.1 == x) {
                    continue;
                }
                match (start, winding != 0) {
                    (None, true) => start = Some(x),
                    (Some(a), false) => {
                        out.push((k, a, x));
                        start = None;
                    }
                    _ => {}
                }
            }
        }
        out
    }

    #[test]
    fn scanline_spans_are_those_of_one_sort_of_every_crossing() {
        // Random loops (self-crossing ones too: windings of 2 and more), with holes, on
        // steps fine and coarse; and parts far apart on a fine step (far more lines than
        // crossings: the other way of sorting).
        let mut random = crate::base::testing::rng(0x9e37_79b9_7f4a_7c15u64);
        let mut spans = 0;
        for case in 0..300 {
            let mut loop_at = |cx: f64, cy: f64, r: f64, n: usize| -> Contour {
                (0..n)
                    .map(|_| DVec2::new(cx + (random() - 0.5) * r, cy + (random() - 0.5) * r))
                    .collect()
            };
            let far = case % 5 == 4;
            let mut region: Shapes =
                vec![Shape::new(loop_at(5.0, 5.0, 10.0, 3 + case % 40), vec![])];
            region.push(Shape::new(
                loop_at(8.0, if far { 900.0 } else { 6.0 }, 4.0, 3 + case % 7),
                vec![loop_at(8.0, 6.0, 2.0, 4)],
            ));
            let step = if far {
                0.01
            } else {
                [0.02, 0.2, 1.0][case % 3]
            };
            let (y0, phase) = (-1.0 + random(), [0.5, 0.0, 0.25][case % 3]);
            let rows = -100..((1000.0 / step) as i64);
            let mut got = Vec::new();
            scanline_spans(
                &region,
                |p| p,
                y0,
                step,
                phase,
                rows.clone(),
                |k, a, b| got.push((k, a, b)),
            );
            let want = spans_by_one_sort(&region, y0, step, phase, rows);
            assert_eq!(got, want, "case {case}");
            spans += got.len();
        }
        assert!(spans > 10_000, "{spans}");
    }

    #[test]
    fn a_line_through_a_vertex_neither_touches_nor_splits() {
        // A triangle whose lowest corner lies on the line y = 1: alone, the line touches it
        // at a point (no span); inside a square, the square's span is not split there.
        let tri = |p: [f64; 2]| -> Contour {
            vec![
                DVec2::new(p[0], p[1]),
                DVec2::new(p[0] + 1.0, p[1] + 2.0),
                DVec2::new(p[0] - 1.0, p[1] + 2.0),
            ]
        };
        let square = |a: f64| -> Contour {
            [[0.0, 0.0], [a, 0.0], [a, a], [0.0, a]]
                .map(DVec2::from)
                .into()
        };
        let spans = |region: &Shapes| {
            let mut out = Vec::new();
            scanline_spans(
                region,
                |p| p,
                0.0,
                1.0,
                0.0,
                0..5,
                |k, a, b| out.push((k, a, b)),
            );
            out
        };
        let alone = vec![Shape::new(tri([2.0, 1.0]), vec![])];
        assert_eq!(spans(&alone), vec![(2, 1.5, 2.5)]);
        let inside = vec![
            Shape::new(square(4.0), vec![]),
            Shape::new(tri([2.0, 1.0]), vec![]),
        ];
        assert_eq!(
            spans(&inside),
            vec![(0, 0.0, 4.0), (1, 0.0, 4.0), (2, 0.0, 4.0), (3, 0.0, 4.0)]
        );
    }
}
