//! The vertical cut: the 3D estimate ([`super::slab_voids`]'s droplet model) on a vertical
//! plane through a line of the layer plane. Along the line, a layer's slab is the region's
//! spans × [0, H]; a point of it is filled when a spheroid of layer i − 1, i or i + 1 contains
//! it. The plane crosses a droplet's spheroid (horizontal radius R = D/2, vertical semi-axis c,
//! centred at its layer's mid-height) at distance d from its centre in an ellipse; at height
//! z in the slab it covers [t − w, t + w] along the line, w = √(R²(1 − (z − z₀)²/c²) − d²).
//! The voids are computed exactly along the line at [`CUT_BANDS`] heights per slab (the
//! bands' middles), not on a grid: the section is a set of intervals per band.

use super::droplet::{footprint_diameter, spheroid_half_height};
use crate::base::error::Error;
use crate::base::geom::{Point, Shapes, scanline_spans};
use crate::base::settings::Settings;

/// Heights sampled per slab: the void intervals of band k (of H / CUT_BANDS) are those at its
/// middle.
pub const CUT_BANDS: usize = 6;

/// The longest cut line accepted, mm (a build plate is far smaller).
pub const MAX_CUT_LENGTH: f64 = 10_000.0;

/// A cut line from `a` to `b` in the layer plane: positions along it (t, mm from `a`) and
/// signed distances from it (d, mm, positive on its left).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutLine {
    a: Point,
    dir: Point,
    length: f64,
}

impl CutLine {
    /// The line from `a` to `b`; both finite, at most [`MAX_CUT_LENGTH`] apart and not the
    /// same point.
    pub fn new(a: Point, b: Point) -> Result<CutLine, Error> {
        let bad = |what: &str| Error::Setting {
            name: "cut".into(),
            message: format!("the cut line {what}; draw the line again"),
        };
        if !(a.is_finite() && b.is_finite()) {
            return Err(bad("has an end that is not a number"));
        }
        let length = (b - a).length();
        if length < 1e-6 {
            return Err(bad("has no length (its two ends are the same point)"));
        }
        if length > MAX_CUT_LENGTH {
            return Err(bad(&format!(
                "is {length:.0} mm long, more than {MAX_CUT_LENGTH:.0} mm"
            )));
        }
        Ok(CutLine {
            a,
            dir: (b - a) / length,
            length,
        })
    }

    pub fn length(&self) -> f64 {
        self.length
    }

    /// (t along the line from `a`, signed distance d from the line) of `p`.
    pub fn local(&self, p: Point) -> (f64, f64) {
        let v = p - self.a;
        (v.dot(self.dir), self.dir.perp_dot(v))
    }

    /// The spans [t0, t1] (t0 < t1, ascending) of the line inside `region` (non-zero rule),
    /// clipped to the segment [0, length].
    pub fn region_spans(&self, region: &Shapes) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        // The line's frame: x = t, y = d; the line is the row y = 0.
        scanline_spans(
            region,
            |p| {
                let (t, d) = self.local(p);
                Point::new(t, d)
            },
            0.0,
            1.0,
            0.0,
            0..1,
            |_, xa, xb| {
                let (t0, t1) = (xa.max(0.0), xb.min(self.length));
                if t1 > t0 {
                    out.push((t0, t1));
                }
            },
        );
        out
    }

    /// The droplets of `centres` whose footprint the plane crosses within the segment: (index,
    /// t, |d|) for |d| < `reach` and −reach < t < length + reach.
    pub fn near(
        &self,
        centres: impl IntoIterator<Item = Point>,
        reach: f64,
    ) -> Vec<(usize, f64, f64)> {
        centres
            .into_iter()
            .enumerate()
            .filter_map(|(i, p)| {
                let (t, d) = self.local(p);
                (d.abs() < reach && t > -reach && t < self.length + reach).then_some((
                    i,
                    t,
                    d.abs(),
                ))
            })
            .collect()
    }
}

/// A droplet near the cut: its position along the line and its distance from the plane, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Near {
    pub t: f64,
    pub d: f64,
}

/// One void of a slab's section: band `band` (of [`CUT_BANDS`], from the slab's bottom) is not
/// filled over [t0, t1] along the line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutVoid {
    pub band: usize,
    pub t0: f64,
    pub t1: f64,
}

/// The voids of a slab's section: `spans` (the region along the line, ascending, disjoint)
/// minus what the spheroids of the layer below, this layer and the layer above fill, at the
/// middle of each of [`CUT_BANDS`] bands. Voids shorter than 10⁻⁹ mm are dropped.
pub fn slab_section_voids(
    spans: &[(f64, f64)],
    below: &[Near],
    this: &[Near],
    above: &[Near],
    s: &Settings,
) -> Vec<CutVoid> {
    let h = s.layer_height;
    let r = footprint_diameter(s) / 2.0;
    let c = spheroid_half_height(s);
    let mut out = Vec::new();
    let mut filled: Vec<(f64, f64)> = Vec::new();
    for band in 0..CUT_BANDS {
        let z = (band as f64 + 0.5) / CUT_BANDS as f64 * h;
        filled.clear();
        // the droplets' mid-heights in the slab's frame: below −H/2, this H/2, above 3H/2
        for (layer, z0) in [(below, -0.5 * h), (this, 0.5 * h), (above, 1.5 * h)] {
            let dz = (z - z0) / c;
            if dz.abs() >= 1.0 {
                continue;
            }
            let rr = r * r * (1.0 - dz * dz);
            for n in layer {
                let w2 = rr - n.d * n.d;
                if w2 > 0.0 {
                    let w = w2.sqrt();
                    filled.push((n.t - w, n.t + w));
                }
            }
        }
        filled.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        // Walk the spans and the filled intervals (sorted by start) together.
        let mut k = 0;
        let mut reach = f64::NEG_INFINITY; // the end of the filled union so far
        for &(s0, s1) in spans {
            let mut at = s0;
            while at < s1 {
                // every interval starting at or before `at` extends the covered run
                while k < filled.len() && filled[k].0 <= at {
                    reach = reach.max(filled[k].1);
                    k += 1;
                }
                if reach > at {
                    at = reach.min(s1);
                    continue;
                }
                // a gap from `at` to the next interval's start (or the span's end)
                let next = filled.get(k).map_or(s1, |f| f.0.min(s1));
                if next - at > 1e-9 {
                    out.push(CutVoid {
                        band,
                        t0: at,
                        t1: next,
                    });
                }
                at = next;
                if next >= s1 {
                    break;
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::DVec2;
    use crate::base::geom::square;

    #[test]
    fn a_line_through_a_square_with_a_hole() {
        let mut region = square(0.0, 0.0, 10.0);
        let mut hole = square(4.0, 4.0, 2.0).remove(0).outer;
        hole.reverse();
        region[0].holes.push(hole);
        let line = CutLine::new(DVec2::new(-5.0, 5.0), DVec2::new(20.0, 5.0)).unwrap();
        let spans = line.region_spans(&region);
        assert_eq!(spans, vec![(5.0, 9.0), (11.0, 15.0)]);
        // clipped to the segment
        let line = CutLine::new(DVec2::new(2.0, 5.0), DVec2::new(8.0, 5.0)).unwrap();
        assert_eq!(line.region_spans(&region), vec![(0.0, 2.0), (4.0, 6.0)]);
    }

    #[test]
    fn bad_lines_are_refused() {
        let p = DVec2::new(1.0, 1.0);
        assert!(CutLine::new(p, p).is_err());
        assert!(CutLine::new(p, DVec2::new(f64::NAN, 0.0)).is_err());
        assert!(CutLine::new(p, DVec2::new(1e6, 0.0)).is_err());
    }

    #[test]
    fn a_diagonal_line_measures_along_itself() {
        let line = CutLine::new(DVec2::new(0.0, 0.0), DVec2::new(3.0, 4.0)).unwrap();
        let (t, d) = line.local(DVec2::new(3.0, 4.0));
        assert!((t - 5.0).abs() < 1e-12 && d.abs() < 1e-12);
        let (t, d) = line.local(DVec2::new(-4.0, 3.0));
        assert!(t.abs() < 1e-12 && (d - 5.0).abs() < 1e-12);
    }
}
