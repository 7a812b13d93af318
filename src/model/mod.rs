//! The model: files in (STL, OBJ, 3MF: [`import`]), the welded mesh ([`mesh`], its welds [`weld`]) and its shells
//! ([`shells`]), the job file ([`spec`]), the files a job reads ([`models`]), where its
//! instances go ([`layout`]; each one's transform [`frame`]) and whether they fit the plate ([`fit`]), the page's display meshes ([`display`]) and the preparation of
//! one file's mesh ([`prepare`]).

pub mod display;
pub mod fit;
pub mod frame;
pub mod import;
pub mod layout;
pub mod mesh;
pub mod models;
pub mod models_job;
pub mod prepare;
pub mod shells;
pub mod spec;
pub mod weld;
