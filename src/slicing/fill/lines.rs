//! Parallel lines (docs/spec.md 5.3.4): lines at (j + phase)·spacing across the layer's
//! angle, clipped to the region (non-zero rule), their ends on a lattice when asked.

use super::{Fill, FillParams};
use crate::base::geom::Shapes;
use crate::slicing::hatch::{HatchLine, hatch_at};

/// The parallel-lines pattern.
pub struct Lines;

impl Fill for Lines {
    fn fill(&self, region: &Shapes, p: &FillParams) -> Vec<HatchLine> {
        hatch_at(region, p.angle_deg, p.spacing, p.phase, p.lattice)
    }
}
