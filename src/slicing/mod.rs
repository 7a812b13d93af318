//! One layer from mesh to plan: slice → offset/contours → droplets and fill (hatch) → plan.

pub mod close;
pub mod contours;
pub mod droplets;
pub mod fill;
pub mod hatch;
pub mod offset;
pub mod plan;
pub mod sink;
pub mod slice;
