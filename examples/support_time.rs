//! Times the support computation's stages on a model (docs/performance.md, "Support"):
//! `cargo run --release --example support_time -- MODEL.stl`; `AREAS=1` also prints the
//! overhang and support areas of some layers; `REGIONS_ONLY=1` stops after the support
//! regions (for a profiler); `REPEAT=N` runs the droplet pass N times, `PASS_ONLY=1` stops
//! after it (the difference of two counts, `perf stat`, is the pass').
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::base::geom::{Shapes, region_area};
use dropslice::base::parallel::par_map;
use dropslice::support;
use dropslice::support::overhang::overhang_region;
use dropslice::{Job, Settings};
use std::time::Instant;

fn points(r: &Shapes) -> usize {
    r.iter()
        .map(|s| s.contours().map(|c| c.len()).sum::<usize>())
        .sum()
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: support_time MODEL.stl");
    let bytes = std::fs::read(&path).expect("read the model");
    let s = Settings {
        support: dropslice::base::settings::Support::Unit(dropslice::base::settings::UnitId(1)),
        ..Settings::default()
    };
    let job = Job::new(&bytes, &path, s.clone()).expect("job");
    let n = job.layer_count();
    let t = Instant::now();
    let regions: Vec<Shapes> = par_map(n, &|i| job.section(i).region);
    println!("sections        {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let _o: Vec<Shapes> = par_map(n, &|i| {
        overhang_region(&regions[i], i.checked_sub(1).map(|j| &regions[j]), &s)
    });
    println!("overhangs       {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let layers = support::support_layers(&regions, &s);
    println!(
        "support_layers  {:.3} s (overhangs included; {} support hatch segments)",
        t.elapsed().as_secs_f64(),
        layers.iter().map(|l| l.lines.len()).sum::<usize>()
    );
    if std::env::var_os("REGION_FORM").is_some() {
        let t = Instant::now();
        let r = support::support_regions(&regions, &s);
        println!(
            "support_regions {:.3} s (the region form; {} points in the support regions)",
            t.elapsed().as_secs_f64(),
            r.iter().map(|(_, r)| points(r)).sum::<usize>()
        );
    }
    if std::env::var_os("REGIONS_ONLY").is_some() {
        return;
    }
    if std::env::var_os("AREAS").is_some() {
        for (i, l) in layers.iter().enumerate() {
            if i % 10 == 0 || l.unsupported_area > 5.0 {
                println!(
                    "layer {}: overhang {:.2} mm², support {} segments, part {:.2} mm²",
                    i + 1,
                    l.unsupported_area,
                    l.lines.len(),
                    region_area(&regions[i])
                );
            }
        }
    }
    let t = Instant::now();
    let hatch: Vec<Vec<dropslice::slicing::plan::Move>> = par_map(n, &|i| {
        dropslice::support::moves::support_moves(
            &layers[i].lines,
            &regions[i],
            &[],
            i,
            &s,
            Default::default(),
        )
    });
    println!("support hatch   {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let parts: Vec<dropslice::slicing::plan::LayerPlan> = par_map(n, &|i| {
        dropslice::slicing::plan::plan_layer(&regions[i], i, &s)
    });
    println!("part plans      {:.3} s", t.elapsed().as_secs_f64());
    // The droplet pass REPEAT times (1 by default), its least time.
    let repeat: usize = std::env::var("REPEAT")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1);
    let mut best = f64::INFINITY;
    let mut added = 0;
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        let (_extra, pass) =
            dropslice::support::droplets::complete(&|i| [&parts[i].moves, &hatch[i]], &regions, &s);
        best = best.min(t.elapsed().as_secs_f64());
        added = pass.added;
    }
    println!("droplet pass    {best:.3} s ({added} droplets added)");
    if std::env::var_os("PASS_ONLY").is_some() {
        return;
    }
    drop((hatch, parts));
    // The job's own pass: sections, support regions, all plans and the droplet pass.
    let t = Instant::now();
    let pass = job.supported_pass();
    let (plans, figures) = (&pass.layers, &pass.figures);
    println!(
        "supported plans {:.3} s (everything: {} droplets added, {} unplaceable; {} moves)",
        t.elapsed().as_secs_f64(),
        figures.added,
        figures.unplaceable,
        plans.iter().map(|p| p.0.moves.len()).sum::<usize>()
    );
}
