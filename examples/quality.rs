//! Coverage and void figures with stagger off and on, and the analysis time against slicing:
//! `cargo run --release --example quality -- MODEL.stl...` (the figures of docs/quality.md).
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::analysis::JobAnalysis;
use dropslice::{Job, Settings, write_gcode, write_gcode_with};
use std::time::Instant;

#[path = "common/table.rs"]
mod table;

fn main() {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    table::header(
        "model | stagger | coverage | void area share | enclosed void share | overfill share | largest void mm² (layer) | max deviation mm | 3D void fraction | slicing s | slicing + analysis s",
    );
    for path in &paths {
        let (bytes, name) = table::read_model(path, false);
        for stagger in [false, true] {
            let s = Settings {
                stagger,
                ..Settings::default()
            };
            let job = Job::new(&bytes, &name, s).expect("job");
            let t = Instant::now();
            write_gcode(&job, &mut std::io::sink(), |_, _| {}).expect("slice");
            let slicing = t.elapsed().as_secs_f64();
            // As `--report` does it: each layer analysed by the worker that planned it.
            let t = Instant::now();
            let mut analysis = JobAnalysis::new(&job.analysis_grid(), job.settings());
            write_gcode_with(&job, &mut std::io::sink(), |_, _| {}, &mut analysis)
                .expect("slice and analyse");
            let r = analysis.finish();
            let with_analysis = t.elapsed().as_secs_f64();
            let p = &r.part;
            println!(
                "| {name} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} ({}) | {:.4} ({}) | {:.4} | {slicing:.3} | {with_analysis:.3} |",
                if stagger { "on" } else { "off" },
                p.coverage,
                p.void_area / p.region_area,
                p.enclosed_void_area / p.region_area,
                p.overfill_area / p.region_area,
                p.largest_void.map_or(0.0, |v| v.area),
                p.largest_void_layer.map_or(0, |l| l + 1),
                p.max_boundary_deviation,
                p.max_deviation_layer.map_or(0, |l| l + 1),
                p.estimate.void_fraction,
            );
        }
    }
}
