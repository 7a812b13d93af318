//! The model: files in (STL, OBJ, 3MF), the welded mesh, the job file.

pub mod import;
pub mod mesh;
pub mod prepare;
pub mod shells;
pub mod spec;
