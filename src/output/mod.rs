//! What leaves the core: the `.gco` code (and reading it back), calibration, the canvas
//! preview and the figures.

pub mod calibrate;
pub mod gcode;
pub mod gcode_read;
pub mod preview;
pub mod summary;
