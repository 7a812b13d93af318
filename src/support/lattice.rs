//! The support's top-down need on unit 1's hatch lattices (docs/spec.md "Overhangs and support";
//! docs/support.md *Support regions*).
//!
//! Unit 1 prints a support region as hatch lines (j + ½)·spacing across the layer's hatch
//! direction, every line's droplets at k·B₁ along it ([`crate::support::moves::support_moves`]): a
//! droplet is set at exactly the lattice points inside the region. So the region matters only
//! at those points, and the top-down need
//! need(n) = (need(n + 1) ∪ grow(overhang(n + 1))) − region(n)
//! can be carried as one bit per lattice point: each layer's grown overhang and part region
//! are crossed with the lattice's lines (the scanline of the hatch, on all cores), and the
//! union and the clip become word operations on the bits. At every lattice point the bits are
//! the exact boolean of the regions (a point on a boundary counts as inside): no outline is
//! simplified or carried.
//!
//! A lattice depends on the hatch direction modulo 180° (a half turn maps it onto itself), so
//! the default 90° step has two, used by alternate layers. The need is carried on every lattice
//! a layer uses; more than [`MAX_LATTICES`] directions (an unusual step) fall back to the
//! region form of [`crate::support::support_layers`].

use crate::base::geom::{DVec2, Point, Shapes, all_contours, scanline_spans, sin_cos_deg};
use crate::base::settings::Settings;
use crate::slicing::hatch::HatchLine;

/// At most this many hatch directions (mod 180°) are carried as lattices.
pub const MAX_LATTICES: usize = 4;

/// At most this many lattice points in one lattice's box (8 MB of bits): beyond, the region
/// form (a plate far larger than the droplets).
const MAX_POINTS: u64 = 1 << 26;

/// Points of one lattice inside a region: (row, first column, last column), rows ascending,
/// relative to the lattice's box.
pub type Runs = Vec<(u32, u32, u32)>;

/// One lattice: lines (j + ½)·`spacing` across the direction `angle`, points k·`pitch` along,
/// over a box of rows `row0..row0 + rows` and columns `col0..col0 + cols`.
#[derive(Clone, Debug)]
pub struct Lattice {
    sin: f64,
    cos: f64,
    spacing: f64,
    pitch: f64,
    row0: i64,
    rows: usize,
    col0: i64,
    cols: usize,
}

impl Lattice {
    /// Into the lattice's frame (rotate by −angle): the lines are horizontal (as in
    /// [`crate::slicing::hatch::hatch_at`]).
    fn to(&self, p: Point) -> Point {
        DVec2::new(
            self.cos * p.x + self.sin * p.y,
            -self.sin * p.x + self.cos * p.y,
        )
    }

    fn back(&self, p: Point) -> Point {
        DVec2::new(
            self.cos * p.x - self.sin * p.y,
            self.sin * p.x + self.cos * p.y,
        )
    }

    /// The lattice points of `region` (non-zero rule, boundary included) in the box.
    pub fn runs(&self, region: &Shapes) -> Runs {
        let mut out = Runs::new();
        if region.is_empty() || self.rows == 0 || self.cols == 0 {
            return out;
        }
        let last = self.col0 + self.cols as i64 - 1;
        scanline_spans(
            region,
            |p| self.to(p),
            0.0,
            self.spacing,
            0.5,
            self.row0..self.row0 + self.rows as i64,
            |j, x0, x1| {
                // The first lattice point at or after x0 and the last at or before x1, as
                // `hatch_at` moves a line's ends inward.
                let mut k0 = (x0 / self.pitch).floor();
                if x0 - k0 * self.pitch > 0.0 {
                    k0 += 1.0;
                }
                let mut k1 = (x1 / self.pitch).ceil();
                if k1 * self.pitch - x1 > 0.0 {
                    k1 -= 1.0;
                }
                let (k0, k1) = ((k0 as i64).max(self.col0), (k1 as i64).min(last));
                if k0 <= k1 {
                    out.push((
                        (j - self.row0) as u32,
                        (k0 - self.col0) as u32,
                        (k1 - self.col0) as u32,
                    ));
                }
            },
        );
        out
    }

    /// The hatch segment of columns `k0..=k1` of row `r` (ends on lattice points).
    fn line(&self, r: usize, k0: usize, k1: usize) -> HatchLine {
        let y = ((self.row0 + r as i64) as f64 + 0.5) * self.spacing;
        let x = |k: usize| (self.col0 + k as i64) as f64 * self.pitch;
        HatchLine {
            a: self.back(DVec2::new(x(k0), y)),
            b: self.back(DVec2::new(x(k1), y)),
        }
    }

    fn words(&self) -> usize {
        self.cols.div_ceil(64)
    }
}

/// The lattices of a job's layers: one per hatch direction mod 180°, each over the box of
/// every layer's region grown by `reach`.
#[derive(Clone, Debug)]
pub struct Lattices {
    pub lattices: Vec<Lattice>,
    /// Layer i's lattice: `lattices[of[i]]`.
    pub of: Vec<usize>,
}

impl Lattices {
    /// The lattices of `regions`' layers for support hatched at `spacing`, droplets `pitch`
    /// apart, need grown at most `reach` beyond a region; `None` when more than
    /// [`MAX_LATTICES`] directions or a box too large for bits.
    pub fn new(
        regions: &[Shapes],
        s: &Settings,
        spacing: f64,
        pitch: f64,
        reach: f64,
    ) -> Option<Self> {
        if !(spacing > 0.0 && pitch > 0.0 && spacing.is_finite() && pitch.is_finite()) {
            return None;
        }
        let mut angles: Vec<f64> = Vec::new();
        let mut of = Vec::with_capacity(regions.len());
        for i in 0..regions.len() {
            let a = crate::slicing::plan::hatch_angle(s, i).rem_euclid(180.0);
            let a = if 180.0 - a < 1e-9 { 0.0 } else { a };
            let k = match angles.iter().position(|&b| (a - b).abs() < 1e-9) {
                Some(k) => k,
                None => {
                    if angles.len() == MAX_LATTICES {
                        return None;
                    }
                    angles.push(a);
                    angles.len() - 1
                }
            };
            of.push(k);
        }
        let mut lattices = Vec::with_capacity(angles.len());
        for a in angles {
            let (sin, cos) = sin_cos_deg(a);
            let mut l = Lattice {
                sin,
                cos,
                spacing,
                pitch,
                row0: 0,
                rows: 0,
                col0: 0,
                cols: 0,
            };
            let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
            for c in regions.iter().flat_map(all_contours) {
                for p in c {
                    let q = l.to(*p);
                    lo = lo.min(q);
                    hi = hi.max(q);
                }
            }
            if lo.x <= hi.x {
                // The grown overhangs lie within `reach` (and the offset's chords) of a
                // region; one lattice step more on every side.
                let pad = reach.max(0.0) + spacing + pitch;
                let (lo, hi) = (lo - DVec2::splat(pad), hi + DVec2::splat(pad));
                let row0 = (lo.y / spacing - 0.5).floor();
                let row1 = (hi.y / spacing - 0.5).ceil();
                let col0 = (lo.x / pitch).floor();
                let col1 = (hi.x / pitch).ceil();
                let (rows, cols) = (row1 - row0 + 1.0, col1 - col0 + 1.0);
                if rows.is_nan() || cols.is_nan() || rows * cols > MAX_POINTS as f64 {
                    return None;
                }
                (l.row0, l.rows, l.col0, l.cols) =
                    (row0 as i64, rows as usize, col0 as i64, cols as usize);
            }
            lattices.push(l);
        }
        Some(Lattices { lattices, of })
    }
}

/// Calls `f(word index, mask)` for each word of row `r` (rows of `words` words) that columns
/// `k0..=k1` touch.
fn each_word(words: usize, r: u32, k0: u32, k1: u32, mut f: impl FnMut(usize, u64)) {
    let (w0, w1) = ((k0 / 64) as usize, (k1 / 64) as usize);
    let base = r as usize * words;
    for w in w0..=w1 {
        let from = if w == w0 { k0 % 64 } else { 0 };
        let to = if w == w1 { k1 % 64 } else { 63 };
        f(base + w, (u64::MAX >> (63 - to)) & (u64::MAX << from));
    }
}

/// One bit per lattice point of a lattice's box, rows of whole words; `lo..hi` bounds the
/// rows that may hold a set bit.
#[derive(Clone, Debug)]
pub struct Bits {
    words: usize,
    data: Vec<u64>,
    lo: usize,
    hi: usize,
}

impl Bits {
    pub fn new(l: &Lattice) -> Bits {
        Bits {
            words: l.words(),
            data: vec![0; l.words() * l.rows],
            lo: usize::MAX,
            hi: 0,
        }
    }

    /// Sets the points of `runs`.
    pub fn set(&mut self, runs: &Runs) {
        for &(r, k0, k1) in runs {
            let data = &mut self.data;
            each_word(self.words, r, k0, k1, |i, m| data[i] |= m);
            self.lo = self.lo.min(r as usize);
            self.hi = self.hi.max(r as usize + 1);
        }
    }

    /// Clears the points of `runs`.
    pub fn clear(&mut self, runs: &Runs) {
        for &(r, k0, k1) in runs {
            if (r as usize) < self.lo || (r as usize) >= self.hi {
                continue;
            }
            let data = &mut self.data;
            each_word(self.words, r, k0, k1, |i, m| data[i] &= !m);
        }
    }

    /// The set points as hatch segments of `l`, row by row, each row's runs in order along it.
    pub fn lines(&self, l: &Lattice) -> Vec<HatchLine> {
        let mut out = Vec::new();
        for r in self.lo..self.hi.min(l.rows) {
            let row = &self.data[r * self.words..(r + 1) * self.words];
            let mut start: Option<usize> = None;
            for (w, &word) in row.iter().enumerate() {
                let mut bits = word;
                let mut at = 0u32;
                // Alternate between the end of a run of ones and the end of a run of zeros.
                while at < 64 {
                    if start.is_some() {
                        let zeros = (!bits).trailing_zeros().min(64 - at);
                        at += zeros;
                        bits = bits.checked_shr(zeros).unwrap_or(0);
                        if at < 64 {
                            let k1 = w * 64 + at as usize - 1;
                            out.push(l.line(r, start.take().unwrap_or(k1), k1));
                        }
                    } else {
                        let zeros = bits.trailing_zeros().min(64 - at);
                        at += zeros;
                        bits = bits.checked_shr(zeros).unwrap_or(0);
                        if at < 64 {
                            start = Some(w * 64 + at as usize);
                        }
                    }
                }
            }
            if let Some(k0) = start {
                out.push(l.line(r, k0, l.cols.max(1) - 1));
            }
        }
        out
    }

    /// Whether no point is set.
    pub fn is_empty(&self) -> bool {
        // Rows before `lo` hold nothing.
        let first = self.lo.saturating_mul(self.words).min(self.data.len());
        self.data[first..].iter().all(|&w| w == 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::{Shape, square};

    fn lattice(angle: f64) -> Lattice {
        let s = Settings {
            hatch_angle: angle,
            hatch_angle_step: 0.0,
            ..Settings::default()
        };
        let regions = vec![square(-3.03, -2.01, 9.07)];
        Lattices::new(&regions, &s, 0.3, 0.2, 0.5)
            .expect("one lattice")
            .lattices[0]
            .clone()
    }

    /// Non-zero winding number of `region` at `p` (crossings of the ray to +x), independent
    /// of the scanline.
    fn inside(region: &Shapes, p: Point) -> bool {
        let mut w = 0;
        for c in all_contours(region) {
            for i in 0..c.len() {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                let cross = (b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y);
                if a.y <= p.y && b.y > p.y && cross > 0.0 {
                    w += 1;
                } else if a.y > p.y && b.y <= p.y && cross < 0.0 {
                    w -= 1;
                }
            }
        }
        w != 0
    }

    /// Every lattice point of the box that `keep` accepts.
    fn brute(l: &Lattice, keep: impl Fn(Point) -> bool) -> Vec<Point> {
        let mut out = Vec::new();
        for r in 0..l.rows {
            for k in 0..l.cols {
                let p = l.line(r, k, k).a;
                if keep(p) {
                    out.push(p);
                }
            }
        }
        out
    }

    /// The droplets unit 1 sets on `lines` (as `moves::support_moves` does).
    fn points(l: &Lattice, lines: &[HatchLine]) -> Vec<Point> {
        let mut out = Vec::new();
        for h in lines {
            out.extend(crate::base::geom::line_droplets(h.a, h.b, l.pitch));
        }
        out
    }

    fn same(mut a: Vec<Point>, mut b: Vec<Point>) {
        let key = |p: &Point| ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64);
        a.sort_by_key(key);
        b.sort_by_key(key);
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(&b) {
            assert!((*p - *q).length() < 1e-9, "{p} {q}");
        }
    }

    fn framed() -> Shapes {
        let hole: crate::base::geom::Contour =
            [[1.01, 1.03], [1.01, 3.47], [4.03, 3.47], [4.03, 1.03]]
                .map(DVec2::from)
                .into();
        let mut region = vec![Shape::new(
            square(-2.01, -1.47, 7.03)[0].outer.clone(),
            vec![hole],
        )];
        region.push(Shape::new(
            [[-2.51, 6.03], [5.47, 6.21], [0.33, 6.91]]
                .map(DVec2::from)
                .into(),
            vec![],
        ));
        region
    }

    #[test]
    fn bits_of_a_region_are_its_lattice_points() {
        // A frame with a hole and a triangle, in frames at 45° (irrational), 0°, 30°, 135°.
        let region = framed();
        for angle in [45.0, 0.0, 30.0, 135.0] {
            let l = lattice(angle);
            let mut bits = Bits::new(&l);
            bits.set(&l.runs(&region));
            let want = brute(&l, |p| inside(&region, p));
            assert!(want.len() > 500, "{}", want.len());
            same(points(&l, &bits.lines(&l)), want);
        }
    }

    #[test]
    fn union_and_clip_are_those_of_the_regions() {
        // (a ∪ b) − c on the bits equals the lattice points of the regions' boolean.
        let l = lattice(45.0);
        let a = square(-2.01, -1.03, 4.07);
        let b = framed();
        let c = square(0.03, 0.01, 2.51);
        let mut bits = Bits::new(&l);
        bits.set(&l.runs(&a));
        bits.set(&l.runs(&b));
        bits.clear(&l.runs(&c));
        let want = brute(&l, |p| (inside(&a, p) || inside(&b, p)) && !inside(&c, p));
        assert!(want.len() > 500, "{}", want.len());
        same(points(&l, &bits.lines(&l)), want);
        // Cleared to nothing.
        bits.clear(&l.runs(&square(-9.0, -9.0, 30.0)));
        assert!(bits.lines(&l).is_empty());
        assert!(bits.is_empty());
    }

    #[test]
    fn runs_across_word_boundaries_and_to_the_box_edge() {
        let l = Lattice {
            sin: 0.0,
            cos: 1.0,
            spacing: 1.0,
            pitch: 1.0,
            row0: 0,
            rows: 12,
            col0: 0,
            cols: 130,
        };
        // Runs at word edges, across them, to the box's last column, and three in one row.
        let runs: Runs = vec![
            (3, 0, 129),
            (5, 63, 64),
            (7, 127, 128),
            (9, 129, 129),
            (10, 0, 0),
            (10, 2, 61),
            (10, 64, 64),
        ];
        let mut bits = Bits::new(&l);
        bits.set(&runs);
        // Each comes back as one segment (the frame is the identity: y = row + ½, x = column).
        let got: Vec<(i64, i64, i64)> = bits
            .lines(&l)
            .iter()
            .map(|h| (h.a.y as i64, h.a.x as i64, h.b.x as i64))
            .collect();
        let want: Vec<(i64, i64, i64)> = runs
            .iter()
            .map(|&(r, k0, k1)| (r as i64, k0 as i64, k1 as i64))
            .collect();
        assert_eq!(got, want);
        // Clearing part of a run splits it.
        bits.clear(&vec![(3, 60, 70)]);
        let row3: Vec<(i64, i64)> = bits
            .lines(&l)
            .iter()
            .filter(|h| h.a.y as i64 == 3)
            .map(|h| (h.a.x as i64, h.b.x as i64))
            .collect();
        assert_eq!(row3, vec![(0, 59), (71, 129)]);
    }

    #[test]
    fn many_directions_or_a_huge_box_fall_back() {
        let regions = vec![square(0.0, 0.0, 10.0); 8];
        let step = |a: f64| Settings {
            hatch_angle_step: a,
            ..Settings::default()
        };
        let n = |a: f64| Lattices::new(&regions, &step(a), 0.2, 0.2, 0.1).map(|l| l.lattices.len());
        assert_eq!(n(90.0), Some(2));
        assert_eq!(n(0.0), Some(1));
        assert_eq!(n(180.0), Some(1));
        assert_eq!(n(45.0), Some(4));
        assert_eq!(n(30.0), None);
        // Layers 0 and 2 share a lattice with the default step.
        let l = Lattices::new(&regions, &step(90.0), 0.2, 0.2, 0.1).unwrap();
        assert_eq!(&l.of[..4], &[0, 1, 0, 1]);
        let huge = vec![square(0.0, 0.0, 5000.0)];
        assert!(Lattices::new(&huge, &step(90.0), 0.2, 0.2, 0.1).is_none());
    }
}
