//! The model: files in (STL, OBJ, 3MF), the welded mesh, the job file.

pub mod display;
pub mod import;
pub mod layout;
pub mod mesh;
pub mod models;
pub mod prepare;
pub mod shells;
pub mod spec;
