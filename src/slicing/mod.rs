//! One layer from mesh to plan: slice → offset/contours → droplets and hatch → plan.

pub mod contours;
pub mod droplets;
pub mod hatch;
pub mod offset;
pub mod plan;
pub mod sink;
pub mod slice;
