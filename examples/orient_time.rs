//! Times the orientation of a model (docs/process.md, "Orientation") and prints its candidates
//! as JSON: `cargo run --release --example orient_time -- MODEL [RUNS]`. The median of RUNS
//! (default 7) evaluations goes to stderr; `scripts/orient_time.sh` checks it against the
//! target and `scripts/process_figures.py` draws the candidates.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::Settings;
use dropslice::model::models::Model;
use dropslice::support::orient::orient;
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: orient_time MODEL [RUNS]");
    let runs: usize = args
        .next()
        .map_or(7, |r| r.parse().expect("RUNS: a number"));
    let bytes = std::fs::read(&path).expect("read the model");
    let model = Model::read(&bytes, &path).expect("a model");
    let tris = model.triangles(None).expect("triangles");
    let settings = Settings::default();
    let mut times = Vec::new();
    let mut result = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        result = orient(&tris, [0.0; 3], [1.0; 3], &settings);
        times.push(t0.elapsed().as_secs_f64() * 1000.0);
    }
    times.sort_by(f64::total_cmp);
    let o = result.expect("the model has facets");
    eprintln!(
        "orient_time: {path}: {} facets, {} candidates, median {:.1} ms of {} runs",
        tris.len(),
        o.candidates.len(),
        times[times.len() / 2],
        times.len()
    );
    println!("{}", serde_json::to_string_pretty(&o).expect("serializes"));
}
