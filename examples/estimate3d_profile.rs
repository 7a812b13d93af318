//! Times the 3D estimate alone on one model, single-threaded, the fast path against the
//! reference it replaced, and checks that they agree bit for bit:
//! `cargo run --release --example estimate3d_profile -- MODEL.stl [--set name=value]... [--runs N]`.
//! Every layer's region and droplet centres are made first (not timed); then each stage runs
//! over all layers N times (default 5), alternating fast and reference, and the best run is
//! printed. Times are seconds the thread ran on a CPU (Linux: /proc/thread-self/schedstat).
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::analysis::*;
use dropslice::{Job, Settings};

#[path = "common/cpu.rs"]
mod cpu;
use cpu::best_time;
#[path = "../tests/common/slab.rs"]
mod slab;
use slab::SlabFn;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("model path");
    let mut s = Settings::default();
    let mut runs = 5;
    let mut it = args[2..].iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--set" => {
                let (k, v) = it
                    .next()
                    .expect("--set key=value")
                    .split_once('=')
                    .expect("=");
                s.set(k, v).expect("setting");
            }
            "--runs" => runs = it.next().expect("--runs N").parse().expect("N"),
            _ => panic!("unknown argument {a}"),
        }
    }
    let bytes = std::fs::read(path).expect("read");
    let job = Job::new(&bytes, path, s.clone()).expect("job");
    let b = s.droplet_width();
    let d = footprint_diameter(&s);
    let bounds = job.info().bounds;
    let grid = Grid3 {
        origin: [bounds.min[0] - d, bounds.min[1] - d].into(),
        cell: b / GRID3_PER_B,
    };
    let layers: Vec<_> = (0..job.layer_count())
        .map(|i| {
            let (plan, region) = job.plan_layer_and_region(i);
            (region, droplet_centres(&plan, b))
        })
        .collect();
    let cells: usize = layers.iter().map(|l| l.1.len()).sum();
    // Best times: maps fast, maps reference, slabs fast, slabs reference.
    let mut best = [f64::INFINITY; 4];
    let mut figures = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let fast_maps: Vec<HeightMap> = best_time(&mut best[0], || {
            layers
                .iter()
                .map(|(_, c)| HeightMap::new(c, &grid, d))
                .collect()
        });
        let ref_maps: Vec<HeightMap> = best_time(&mut best[1], || {
            layers
                .iter()
                .map(|(_, c)| HeightMap::reference(c, &grid, d))
                .collect()
        });
        // Every layer's slab between its real neighbours, by `slab` on `maps`.
        let slabs = |maps: &[HeightMap], slab: SlabFn| -> Vec<(f64, f64)> {
            (0..layers.len())
                .map(|i| {
                    let (lo, hi) = (i.checked_sub(1).map(|j| &maps[j]), maps.get(i + 1));
                    slab(&layers[i].0, &grid, lo, &maps[i], hi, &s)
                })
                .collect()
        };
        figures.0 = best_time(&mut best[2], || slabs(&fast_maps, slab_voids));
        figures.1 = best_time(&mut best[3], || slabs(&ref_maps, slab_voids_reference));
    }
    let same_figures = figures
        .0
        .iter()
        .zip(&figures.1)
        .all(|(a, b)| a.0.to_bits() == b.0.to_bits() && a.1.to_bits() == b.1.to_bits());
    println!(
        "{} layers, {cells} droplets, best of {runs}: 3D height maps {:.3} (reference {:.3}) | 3D slabs {:.3} (reference {:.3}) | slab figures equal: {same_figures}",
        layers.len(),
        best[0],
        best[1],
        best[2],
        best[3]
    );
}
