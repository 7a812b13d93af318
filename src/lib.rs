//! dropslice: a slicer for droplet-based plastic 3D printing.
//!
//! The pipeline (docs/spec.md 5.3), one module per stage, each a plain function from one named
//! type to the next:
//!
//! `&[u8]` —[`model::import`]→ triangles —[`model::mesh::Mesh::weld`],
//! [`model::mesh::Mesh::transform`]→ [`model::mesh::Mesh`] —[`slicing::slice::slice_layer`]→
//! [`slicing::slice::Section`] (region: outer CCW + holes CW) —[`slicing::contours::contours`]
//! (via [`slicing::offset::inset`])→ loops + fill region —[`slicing::droplets::loop_droplets`],
//! [`slicing::hatch::hatch`]→ droplet centres + hatch segments —[`slicing::plan::plan_layer`]→
//! [`slicing::plan::LayerPlan`] —[`output::gcode::layer_text`]→ `.gco` text, and
//! [`output::preview::PreviewLayer`] for the canvas.
//!
//! The folders, each importing only those listed before it: [`base`] (geometry, booleans,
//! the spatial index, parallel helpers, settings, errors) ← [`model`] (import, mesh,
//! preparation, the job file) ← [`slicing`] ← [`support`] and [`analysis`] ← [`output`]
//! (G-code written and read, calibration, preview, figures) ← [`pipeline`] (the [`Job`], the
//! layer writer) ← `wasm` (the page's facade) and the CLI.
//!
//! Layers are independent: [`Job::plan_layer`] plans any layer on any thread. Natively,
//! [`write_gcode`] plans them in parallel and writes them in ascending order, a window at a
//! time, so memory stays bounded however tall the part is.

pub mod analysis;
pub mod base;
pub mod model;
pub mod output;
pub mod pipeline;
pub mod slicing;
pub mod support;
#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use base::error::Error;
pub use base::settings::Settings;
pub use model::prepare::{FacetGroup, JobInfo, MAX_LAYERS, MAX_WIDTH_IN_DROPLETS};
pub use output::summary::{Figures, Summary};
pub use pipeline::{Job, MAX_DROPLETS, SupportedPlans};
#[cfg(not(target_arch = "wasm32"))]
pub use pipeline::{write_gcode, write_gcode_with};
pub use slicing::sink::LayerSink;

pub use base::VERSION;
