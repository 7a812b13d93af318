//! Times the analysis stages on one model, single-threaded:
//! `cargo run --release --example analysis_profile -- MODEL.stl [--set stagger=true]`.
//! Times are seconds the thread ran on a CPU (Linux: /proc/thread-self/schedstat), so waiting
//! for a core on a busy machine is not counted; elsewhere wall time. "before" is the path
//! the fast one replaced (`analysis_reference`, `mask_reference`), on the same raster. One
//! raster is rebuilt layer after layer, as the workers do; environment: FRESH=1 a new raster
//! per layer, REF_FIRST=1 the reference labelling before the fast one (the first after
//! rasterising pays for the raster's memory), FAST_ONLY=1 no reference paths (for perf),
//! REPEAT=n the fast analysis n times per layer, the fastest (wall time) of each layer counted.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::analysis::*;
use dropslice::{Job, Settings};

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("model path");
    let mut s = Settings::default();
    if args.get(2).map(String::as_str) == Some("--set") {
        let (k, v) = args[3].split_once('=').expect("--set key=value");
        s.set(k, v).expect("setting");
    }
    let bytes = std::fs::read(path).expect("read");
    let job = Job::new(&bytes, path, s.clone()).expect("job");
    let b = s.droplet_width();
    // plan, raster, analysis (before), mask (before), height map, slab
    let mut t = [0.0f64; 8];
    let mut nvoids = 0;
    let bounds = job.info().bounds;
    let grid = Grid3 {
        origin: [bounds.min[0] - b, bounds.min[1] - b].into(),
        cell: b / GRID3_PER_B,
    };
    let mut lap = |i: usize, from: &mut f64| {
        let now = cpu();
        t[i] += now - *from;
        *from = now;
    };
    // One raster rebuilt layer after layer (as the workers do); FRESH=1: a new one per layer.
    let fresh = std::env::var("FRESH").is_ok();
    // FAST_ONLY=1: not the reference paths (for perf).
    let fast_only = std::env::var("FAST_ONLY").is_ok();
    let repeat: usize = std::env::var("REPEAT").map_or(1, |v| v.parse().expect("REPEAT=n"));
    let mut r = Raster::empty();
    let mut analysis = 0.0;
    for i in 0..job.layer_count() {
        let mut at = cpu();
        let sec = job.section(i);
        let plan = dropslice::slicing::plan::plan_layer(&sec.region, i, &s);
        std::hint::black_box(dropslice::output::gcode::layer_text(&plan));
        lap(0, &mut at);
        let c = droplet_centres(&plan, b);
        if fresh {
            r = Raster::empty();
        }
        r.rebuild(i, plan.z, &c, &sec.region, &s);
        lap(1, &mut at);
        if std::env::var("REF_FIRST").is_ok() {
            std::hint::black_box(r.analysis_reference());
            lap(3, &mut at);
            let la = r.analysis();
            nvoids += la.voids;
            lap(2, &mut at);
        } else {
            // REPEAT=n: the analysis n − 1 more times on the same raster, the fastest run's wall
            // time counted (runs a busy machine interrupted drop out; the thread's CPU time is
            // counted in scheduler ticks, too coarse for one layer).
            let (la, mut best) = if repeat > 1 {
                let from = std::time::Instant::now();
                let la = r.analysis();
                (la, from.elapsed().as_secs_f64())
            } else {
                let from = cpu();
                let la = r.analysis();
                (la, cpu() - from)
            };
            nvoids += la.voids;
            for _ in 1..repeat {
                let from = std::time::Instant::now();
                std::hint::black_box(r.analysis());
                best = best.min(from.elapsed().as_secs_f64());
            }
            analysis += best;
            at = cpu();
            if !fast_only {
                std::hint::black_box(r.analysis_reference());
            }
            lap(3, &mut at);
        }
        std::hint::black_box(r.mask(b / 4.0));
        lap(4, &mut at);
        if !fast_only {
            std::hint::black_box(r.mask_reference(b / 4.0));
        }
        lap(5, &mut at);
        let m = HeightMap::new(&c, &grid, footprint_diameter(&s));
        lap(6, &mut at);
        let _ = slab_voids(&sec.region, &grid, Some(&m), &m, Some(&m), &s);
        lap(7, &mut at);
    }
    println!(
        "plan+gcode text {:.3} | raster {:.3} | analysis {:.3} (before {:.3}) | page mask {:.3} (before {:.3}) | 3D height maps {:.3} | 3D slabs {:.3} | voids {nvoids}",
        t[0],
        t[1],
        t[2] + analysis,
        t[3],
        t[4],
        t[5],
        t[6],
        t[7]
    );
}
