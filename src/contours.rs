//! Contours, stage 3b (SPEC.md "Geometry derived from them"): a layer's region → its contour
//! loops and its fill region.
//!
//! Loop k (k = 0 … contours−1) runs at d_k = (f + k)·B from the boundary, f = `outer_offset`
//! for outer boundaries and `inner_offset` for holes; the fill region is the material moved in
//! by d_fill = d_(contours−1) + (1 − `fill_overlap`)·B (never less than 0: no fill droplet
//! centre lies outside the part).

use crate::offset::inset;
use crate::settings::Settings;
use crate::slice::{Contour, Shapes};

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

/// The loops and the fill region of one layer.
pub fn contours(region: &Shapes, s: &Settings) -> LayerContours {
    let b = s.droplet_width();
    let mut loops = Vec::new();
    for k in 0..s.contours {
        let shapes = inset(
            region,
            (s.outer_offset + k as f64) * b,
            (s.inner_offset + k as f64) * b,
        );
        for shape in shapes {
            for (i, points) in shape.into_iter().enumerate() {
                loops.push(Loop {
                    k,
                    hole: i > 0,
                    points,
                });
            }
        }
    }
    let fill_region = if s.fill_density > 0.0 {
        let last = s.contours as f64 - 1.0;
        let extra = 1.0 - s.fill_overlap;
        inset(
            region,
            ((s.outer_offset + last + extra) * b).max(0.0),
            ((s.inner_offset + last + extra) * b).max(0.0),
        )
    } else {
        Shapes::new()
    };
    LayerContours { loops, fill_region }
}
