//! Prints how long each stage takes on a model: `cargo run --release --example stage_times -- MODEL.stl`.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use std::time::Instant;
fn main() {
    let path = std::env::args().nth(1).expect("model path");
    let t = Instant::now();
    let bytes = std::fs::read(&path).expect("read");
    let read = t.elapsed();
    let t = Instant::now();
    let (tris, _) = dropslice::model::import::stl::parse(&bytes).expect("parse");
    let parse = t.elapsed();
    let t = Instant::now();
    let _ = dropslice::model::mesh::Mesh::weld(&tris);
    let weld = t.elapsed();
    let t = Instant::now();
    let job = dropslice::Job::new(&bytes, &path, dropslice::Settings::default()).expect("job");
    let job_new = t.elapsed();
    let t = Instant::now();
    let mut sections = 0.0;
    for i in 0..job.layer_count() {
        sections += job.section(i).region.len() as f64;
    }
    let slice = t.elapsed();
    let t = Instant::now();
    let mut moves = 0;
    for i in 0..job.layer_count() {
        moves += job.plan_layer(i).moves.len();
    }
    let plan = t.elapsed();
    println!(
        "read {read:?} parse {parse:?} weld {weld:?} job_new(all import) {job_new:?} slice(all layers) {slice:?} plan incl. slice {plan:?} ({sections} shapes, {moves} moves)"
    );
}
