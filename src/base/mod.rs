//! What every stage shares: geometry types, the boolean engine's operations, the spatial
//! index, work on all cores, settings and errors, the per-stage time counters.

pub mod boolean;
pub mod error;
pub mod geom;
pub mod nearest;
pub mod parallel;
pub mod settings;
pub mod spatial;
pub mod stages;
pub mod steps;
#[cfg(test)]
pub(crate) mod testing;

/// The version of dropslice, written into every `.gco` header.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
