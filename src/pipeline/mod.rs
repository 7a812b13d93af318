//! The job: building it from models (at once, or in steps: `preparation.rs`), planning its
//! layers (every unit, the support), and the native layer writer.

mod budget;
mod build;
pub mod handoff;
mod job;
mod preparation;
mod supported;
#[cfg(not(target_arch = "wasm32"))]
mod writer;

pub use budget::{MAX_DROPLETS, MAX_DROPLETS_WITH_SUPPORT, MAX_LAYER_DROPLETS_WITH_SUPPORT};
pub use handoff::{DraftHook, DraftSink, DraftTo};
pub use job::Job;
pub use preparation::Preparation;
pub use supported::SupportedPlans;
#[cfg(not(target_arch = "wasm32"))]
pub use writer::{write_gcode, write_gcode_with, writer_threads};
