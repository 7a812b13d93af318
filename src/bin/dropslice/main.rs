//! The command-line tool (`dropslice --help`):
//! - `dropslice [slice] MODEL... [OPTIONS]`: the code of a model, or of several (a build job);
//! - `dropslice [slice] JOB.json [OPTIONS]`: the code of a job file (docs/spec.md "Build jobs");
//! - `dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]`: the droplet size from a
//!   printed part;
//! - `dropslice orient MODEL_OR_JOB [--apply]`: the rotation of each part that needs the least
//!   support.
//!
//! `slice` is the default command. The tool is native only: built for wasm32 (as a side
//! effect of building the wasm tests) it is an empty program.

#[cfg(not(target_arch = "wasm32"))]
mod calibrate;
#[cfg(not(target_arch = "wasm32"))]
mod cli;
#[cfg(not(target_arch = "wasm32"))]
mod files;
#[cfg(not(target_arch = "wasm32"))]
mod orient;
#[cfg(not(target_arch = "wasm32"))]
mod slice;
#[cfg(not(target_arch = "wasm32"))]
mod staged;

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    let argv: Vec<std::ffi::OsString> = std::env::args_os().collect();
    match cli::parse(argv.iter().cloned()) {
        Ok(cli::Action::Slice(args, settings)) => slice::main(args, settings),
        Ok(cli::Action::Calibrate(args)) => calibrate::main(args),
        Ok(cli::Action::Orient(args)) => orient::main(args),
        Err(e) => cli::exit(e, &argv),
    }
}

#[cfg(target_arch = "wasm32")]
fn main() {}
