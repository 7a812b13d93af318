//! The job: building it from models, planning its layers (both units, the support), and the
//! native layer writer.

mod budget;
mod build;
pub mod handoff;
mod job;
mod supported;
#[cfg(not(target_arch = "wasm32"))]
mod writer;

pub use budget::{MAX_DROPLETS, MAX_DROPLETS_WITH_SUPPORT, MAX_LAYER_DROPLETS_WITH_SUPPORT};
pub use build::{DraftHook, Preparation};
pub use job::Job;
pub use supported::SupportedPlans;
#[cfg(not(target_arch = "wasm32"))]
pub use writer::{write_gcode, write_gcode_with, writer_threads};
