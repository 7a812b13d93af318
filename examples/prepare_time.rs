//! Time of `Job::new` (import, shells, checks, repair, facet index) on a model, median of 7.
//! Usage: cargo run --release --example prepare_time -- MODEL.stl (`SUPPORT=1`: with
//! `support = unit1`, whose droplet estimate also reads the down-facing facets)
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::{Job, Settings};
use std::time::Instant;

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: prepare_time MODEL.stl");
    let bytes = std::fs::read(&path).expect("read the model");
    let mut settings = Settings::default();
    if std::env::var("SUPPORT").is_ok_and(|v| v == "1") {
        settings.set("support", "unit1").expect("support setting");
    }
    let mut times: Vec<f64> = (0..7)
        .map(|_| {
            let t = Instant::now();
            let job = Job::new(&bytes, &path, settings.clone()).expect("job");
            std::hint::black_box(job.layer_count());
            t.elapsed().as_secs_f64() * 1000.0
        })
        .collect();
    times.sort_by(f64::total_cmp);
    let mut mesh = dropslice::model::mesh::Mesh::weld(
        &dropslice::model::import::stl::parse(&bytes).unwrap().0,
    )
    .0;
    let t = Instant::now();
    let shells = mesh.orient_shells();
    let orient = t.elapsed().as_secs_f64() * 1000.0;
    let t = Instant::now();
    let stats = mesh.stats(0, 0);
    let st = t.elapsed().as_secs_f64() * 1000.0;
    let b = mesh.bounds();
    let zs: Vec<f64> = (0..((b.max[2] - b.min[2]) / 0.2) as usize)
        .map(|i| b.min[2] + (i as f64 + 0.5) * 0.2)
        .collect();
    let t = Instant::now();
    let buckets = dropslice::slicing::slice::FacetBuckets::new(&mesh, &zs);
    let bt = t.elapsed().as_secs_f64() * 1000.0;
    std::hint::black_box((stats, buckets.layer(0).len()));
    println!("stats {st:.1} ms, facet index {bt:.1} ms");
    println!(
        "Job::new: median {:.1} ms; orient_shells alone {orient:.1} ms ({} closed, {} open shells)",
        times[3], shells.closed, shells.open
    );
}
