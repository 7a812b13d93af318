//! Preview: a [`LayerPlan`] → flat arrays for the page's canvas (no object per point).

use crate::base::geom::{DVec2, dist, line_droplets};
use crate::slicing::plan::{LayerPlan, MoveKind};

#[derive(Clone, Debug, Default, PartialEq)]
pub struct PreviewLayer {
    /// x, y of every droplet (each droplet of a `G25` line too), in print order.
    pub droplets: Vec<f32>,
    /// Role of each droplet: 0 outermost loop, 1 inner loops, 2 fill, 3 support (unit 1).
    pub roles: Vec<u8>,
    /// Discharge unit of each droplet (0 or 1), in the order of `roles`.
    pub units: Vec<u8>,
    /// x0, y0, x1, y1 of every move without material (G01, and G26's way to its droplet).
    pub travel: Vec<f32>,
}

impl PreviewLayer {
    /// `b` is unit 0's droplet width (unit 1's comes with the plan).
    pub fn from_plan(plan: &LayerPlan, b: f64) -> PreviewLayer {
        let n = plan.counts.total() as usize;
        let mut p = PreviewLayer {
            droplets: Vec::with_capacity(2 * n),
            roles: Vec::with_capacity(n),
            units: Vec::with_capacity(n),
            travel: Vec::new(),
        };
        let mut at = DVec2::ZERO;
        for m in &plan.moves {
            match m.kind {
                MoveKind::Travel | MoveKind::Droplet => {
                    if dist(at, m.to) > 0.0 {
                        p.travel
                            .extend([at[0], at[1], m.to[0], m.to[1]].map(|v| v as f32));
                    }
                    if m.kind == MoveKind::Droplet {
                        p.droplets.extend([m.to[0] as f32, m.to[1] as f32]);
                        p.roles.push(m.role as u8);
                        p.units.push(m.unit);
                    }
                }
                MoveKind::Line => {
                    for d in line_droplets(at, m.to, plan.width_of(m, b)) {
                        p.droplets.extend([d.x as f32, d.y as f32]);
                        p.roles.push(m.role as u8);
                        p.units.push(m.unit);
                    }
                }
            }
            at = m.to;
        }
        p
    }
}
