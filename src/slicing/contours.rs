//! Contours, stage 3b (docs/spec.md "Geometry derived from them"): a layer's region → its contour
//! loops and its fill region.
//!
//! Loop k (k = 0 … contours−1) runs at d_k = (f + k)·B from the boundary, f = `outer_offset`
//! for outer boundaries and `inner_offset` for holes; the fill region is the material moved in
//! by d_fill = d_(contours−1) + (1 − `fill_overlap`)·B (never less than 0: no fill droplet
//! centre lies outside the part).

use crate::base::geom::{Contour, Shapes};
use crate::base::settings::Settings;
use crate::slicing::offset::{Boundary, CHORD_TOLERANCE_MM, inset_of, inset_within};

/// One closed contour loop, in print direction (material on the left: outer loops
/// counter-clockwise, loops around holes clockwise).
#[derive(Clone, Debug)]
pub struct Loop {
    /// 0 = the outermost loop along its boundary.
    pub k: u32,
    /// True for a loop that runs around a hole.
    pub hole: bool,
    pub points: Contour,
}

#[derive(Clone, Debug, Default)]
pub struct LayerContours {
    pub loops: Vec<Loop>,
    /// Where the fill's droplet centres go.
    pub fill_region: Shapes,
}

/// The values the contours of a layer depend on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContourParams {
    /// B, mm.
    pub b: f64,
    pub contours: u32,
    pub outer_offset: f64,
    pub inner_offset: f64,
    pub fill_density: f64,
    pub fill_overlap: f64,
}

impl ContourParams {
    /// The part's contours with the settings `s`.
    pub fn from_settings(s: &Settings) -> ContourParams {
        ContourParams {
            b: s.droplet_width(),
            contours: s.contours,
            outer_offset: s.outer_offset,
            inner_offset: s.inner_offset,
            fill_density: s.fill_density,
            fill_overlap: s.fill_overlap,
        }
    }

    /// B, mm.
    pub fn droplet_width(&self) -> f64 {
        self.b
    }
}

/// Offsets up to this many B are made from the part's region itself; farther in, from the
/// previous loop.
const DIRECT_MAX_B: f64 = 3.0;

/// The loops and the fill region of one layer with the settings `s`.
pub fn contours(region: &Shapes, s: &Settings) -> LayerContours {
    contours_with(region, &ContourParams::from_settings(s))
}

/// The loops and the fill region of one layer.
///
/// Near the boundary (up to [`DIRECT_MAX_B`]·B) each region is the part's region moved in by
/// its whole distance. Farther in, a loop's region is the previous loop's moved in by B, and
/// the fill region the last loop's moved in by (1 − fill_overlap)·B: eroding by a disc of
/// radius a, then b, is eroding by a + b. One offset by tens of B of a finely tessellated
/// section crosses itself everywhere (50–120 ms on some layers of 3DBenchy at 20–40 B); a step
/// of B costs well under a millisecond. A chain of n such steps approximates its arcs within
/// [`CHORD_TOLERANCE_MM`] / n each, so it stays within the tolerance of the true distance.
pub fn contours_with(region: &Shapes, s: &ContourParams) -> LayerContours {
    let b = s.droplet_width();
    let fill = s.fill_density > 0.0;
    let last = s.contours as f64 - 1.0;
    let extra = (1.0 - s.fill_overlap) * b;
    // Distances (outer, hole) of loop k and of the fill region, from the part's boundary.
    let loop_d = |k: f64| ((s.outer_offset + k) * b, (s.inner_offset + k) * b);
    let fill_d = (
        ((s.outer_offset + last) * b + extra).max(0.0),
        ((s.inner_offset + last) * b + extra).max(0.0),
    );
    let direct = |(o, h): (f64, f64)| o.max(h) <= DIRECT_MAX_B * b;
    let chained = (1..s.contours)
        .filter(|&k| !direct(loop_d(k as f64)))
        .count()
        + usize::from(fill && s.contours > 0 && !direct(fill_d));
    let tolerance = CHORD_TOLERANCE_MM / (chained + 1) as f64;
    let mut loops = Vec::new();
    // The offsets made from the region itself share its boundary's grid.
    let boundary = Boundary::new(region);
    // The region of the last loop so far.
    let mut inner: Option<Shapes> = None;
    for k in 0..s.contours {
        let d = loop_d(k as f64);
        let shapes = match &inner {
            Some(prev) if !direct(d) => inset_within(prev, b, b, tolerance),
            _ => inset_of(&boundary, d.0, d.1, tolerance),
        };
        for shape in &shapes {
            for (hole, points) in shape.contours_with_hole() {
                loops.push(Loop {
                    k,
                    hole,
                    points: points.clone(),
                });
            }
        }
        inner = Some(shapes);
    }
    let fill_region = match (&inner, fill) {
        (_, false) => Shapes::new(),
        (Some(prev), true) if !direct(fill_d) => inset_within(prev, extra, extra, tolerance),
        _ => inset_of(&boundary, fill_d.0, fill_d.1, tolerance),
    };
    LayerContours { loops, fill_region }
}
