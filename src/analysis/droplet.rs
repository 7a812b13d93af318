//! The droplet model: a droplet's footprint in its layer's plane and its spheroid in 3D, and
//! where a layer's droplets are.

use crate::base::geom::{Point, line_droplets};
use crate::base::settings::{Footprint, Settings, UnitId};
use crate::slicing::plan::{LayerPlan, Move, MoveKind, Role};
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
/// unit 0's droplets (the support, printed by another unit, is not the part the analysis
/// measures).
pub fn droplet_centres(plan: &LayerPlan, b: f64) -> Vec<Point> {
    let n = plan.counts.unit(UnitId::FIRST) as usize;
    centres_where(plan, b, n, |m| m.unit == 0)
}

/// Every droplet centre unit `u` (not 0) prints for its parts in a layer (another material,
/// droplets of B_u = `plan.unit_widths[u]`; not the support), in print order.
pub fn unit_part_centres(plan: &LayerPlan, u: UnitId) -> Vec<Point> {
    let n = plan.counts.unit(u) as usize;
    centres_where(plan, plan.unit_widths[u.index()], n, |m| {
        m.unit == u.0 && m.role != Role::Support
    })
}

/// The droplet centres of the moves `keep` takes (`b`: their droplet width, `n`: about how
/// many there are).
fn centres_where(plan: &LayerPlan, b: f64, n: usize, keep: impl Fn(&Move) -> bool) -> Vec<Point> {
    let mut out = Vec::with_capacity(n);
    let mut at = Point::ZERO;
    for m in &plan.moves {
        if !keep(m) {
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
