//! The droplet model: a droplet's footprint in its layer's plane and its spheroid in 3D, and
//! where a layer's droplets are.

use crate::base::geom::{Point, line_droplets};
use crate::base::settings::{Footprint, Settings};
use crate::slicing::plan::{LayerPlan, MoveKind};
use std::f64::consts::PI;

/// Footprint diameter D of a droplet, in mm.
pub fn footprint_diameter(s: &Settings) -> f64 {
    let b = s.droplet_width();
    match s.footprint {
        Footprint::Disc => b,
        Footprint::Spread => 2.0 * b / PI.sqrt(),
    }
}

/// Vertical semi-axis of the droplet spheroid (volume B·B·H), in mm.
pub fn spheroid_half_height(s: &Settings) -> f64 {
    let b = s.droplet_width();
    let d = footprint_diameter(s);
    3.0 * b * b * s.layer_height / (PI * d * d)
}

/// Every droplet centre of a layer's part (each droplet of a `G25` line too), in print order:
/// unit 0's droplets (support, printed by unit 1, is not the part the analysis measures).
pub fn droplet_centres(plan: &LayerPlan, b: f64) -> Vec<Point> {
    let mut out = Vec::with_capacity(plan.counts.unit0() as usize);
    let mut at = Point::ZERO;
    for m in &plan.moves {
        if m.unit != 0 {
            at = m.to;
            continue;
        }
        match m.kind {
            MoveKind::Travel => {}
            MoveKind::Droplet => out.push(m.to),
            MoveKind::Line => out.extend(line_droplets(at, m.to, b)),
        }
        at = m.to;
    }
    out
}
