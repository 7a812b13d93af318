//! Loop seams and voids, `loop_spacing` exact against even (the table of docs/quality.md):
//! `cargo run --release --example seams -- MODEL...` (default: the four shared models the
//! tests use). Seams are measured on the written code as tests/seams.rs does
//! (tests/common/seams.rs: `exact` loops end at their repeated first droplet, `even` loops are
//! found on the layer's contour paths and their arc gaps measured along them); the void
//! fraction is `--report`'s.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
#[path = "../tests/common/seams.rs"]
mod seams;
#[path = "../tests/common/segment.rs"]
mod segment;
#[path = "common/table.rs"]
mod table;

use dropslice::analysis::JobAnalysis;
use dropslice::{Job, Settings, write_gcode_with};

fn main() {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        let shared = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/models/");
        for m in [
            "cube_20mm_ascii",
            "3DBenchy",
            "extruder_idler",
            "stanford_bunny",
        ] {
            paths.push(format!("{shared}{m}.stl"));
        }
    }
    table::header(
        "model | loop_spacing | loops (≥ 3 droplets) | seams < B/4 | min arc gap mm | min straight-line gap mm | loops adjusted | loops breaking a bound | 3D void fraction | coverage",
    );
    for path in &paths {
        let (bytes, name) = table::read_model(path, true);
        for even in [false, true] {
            let mut s = Settings::default();
            if even {
                s.set("loop_spacing", "even").unwrap();
            }
            let b = s.droplet_width();
            let h = s.layer_height;
            let job = Job::new(&bytes, &name, s).expect("job");
            let mut analysis = JobAnalysis::new(&job.analysis_grid(), job.settings());
            let mut code = Vec::new();
            write_gcode_with(&job, &mut code, |_, _| {}, &mut analysis).expect("slice");
            let r = analysis.finish();
            let text = String::from_utf8(code).expect("text");
            let row = if !even {
                let st = seams::exact_stats(&text, b);
                format!(
                    "{} | {:.1} % | {:.4} (the seam) | {:.4} | – | – ",
                    st.loops,
                    100.0 * st.close_share(),
                    st.min_seam,
                    st.min_chord
                )
            } else {
                let lp = seams::loop_paths(&job);
                let (mut loops, mut below, mut adjusted, mut bad) = (0, 0, 0, 0);
                let (mut min_arc, mut min_chord) = (f64::INFINITY, f64::INFINITY);
                for (z, drops) in seams::g26_layers_z(&text) {
                    let i = (z / h).round() as usize - 1;
                    let ms = seams::even_loops(
                        &drops,
                        &lp[i],
                        b,
                        dropslice::slicing::droplets::EVEN_MIN_LENGTH_B * b,
                    )
                    .expect("loops");
                    for m in ms {
                        let n = m.drops.len();
                        loops += 1;
                        let amin = m.arc.iter().cloned().fold(f64::INFINITY, f64::min);
                        let amax = m.arc.iter().cloned().fold(0f64, f64::max);
                        let cmin = m.chord.iter().cloned().fold(f64::INFINITY, f64::min);
                        min_arc = min_arc.min(amin);
                        min_chord = min_chord.min(cmin);
                        below += usize::from(m.chord[n - 1] < b / 4.0);
                        adjusted += usize::from(amax - amin > 2.0 * seams::TOL);
                        let lower = b * (1.0 - 1.0 / n as f64);
                        bad += usize::from(
                            amin < lower - 2.5e-4
                                || amax > b + 2.5e-4
                                || cmin < 2.0 / 3.0 * b - seams::TOL,
                        );
                    }
                }
                format!(
                    "{loops} | {:.1} % | {min_arc:.4} | {min_chord:.4} | {adjusted} | {bad} ",
                    100.0 * below as f64 / loops.max(1) as f64
                )
            };
            println!(
                "| {name} | {} | {row}| {:.4} | {:.4} |",
                if even { "even" } else { "exact" },
                r.part.estimate.void_fraction,
                r.part.coverage
            );
        }
    }
}
