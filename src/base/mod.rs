//! What every stage shares: geometry types, the spatial index, settings and errors.

pub mod error;
pub mod geom;
pub mod settings;
pub mod spatial;
