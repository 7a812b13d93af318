//! Loop seams and voids, `loop_spacing` exact against even (the table of docs/quality.md):
//! `cargo run --release --example seams -- MODEL...` (default: the four shared models the
//! tests use). Seams are measured on the written code as tests/seams.rs does
//! (tests/common/seams.rs); the void fraction is `--report`'s.
#[path = "../tests/common/seams.rs"]
mod seams;

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
    println!(
        "| model | loop_spacing | loops (≥ 3 droplets) | seams < B/4 | smallest seam mm | gap min / mean mm | loops arc-spaced / with extra droplets | 3D void fraction | coverage |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in &paths {
        let bytes = std::fs::read(path).expect("read model");
        let name = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut texts: Vec<String> = Vec::new();
        for even in [false, true] {
            let mut s = Settings::default();
            if even {
                s.set("loop_spacing", "even").unwrap();
            }
            let b = s.droplet_width();
            let job = Job::new(&bytes, &name, s).expect("job");
            let mut analysis = JobAnalysis::new(&job);
            let mut code = Vec::new();
            write_gcode_with(&job, &mut code, |_, _| {}, &mut analysis).expect("slice");
            let r = analysis.finish();
            let text = String::from_utf8(code).expect("text");
            let mut st = seams::SeamStats::new();
            let (mut arc, mut extra) = (0, 0);
            let layers = seams::g26_layers(&text);
            if !even {
                for l in &layers {
                    for lp in seams::exact_loops(l, b) {
                        st.add(&lp, b);
                    }
                }
            } else {
                let exact_layers = seams::g26_layers(&texts[0]);
                for (l, e) in layers.iter().zip(&exact_layers) {
                    let el = seams::exact_loops(e, b);
                    let starts: Vec<_> = el.iter().map(|l| l.points[0]).collect();
                    let n: std::collections::HashMap<_, _> = el
                        .iter()
                        .map(|l| (seams::key(l.points[0]), l.points.len()))
                        .collect();
                    for lp in seams::loops_from_starts(l, &starts).expect("loops") {
                        let g = lp.gaps();
                        if g.is_empty() {
                            continue;
                        }
                        st.add(&lp, b);
                        let inner = &g[..g.len() - 1];
                        let (lo, hi) = inner
                            .iter()
                            .fold((f64::MAX, 0f64), |(a, c), &x| (a.min(x), c.max(x)));
                        if hi - lo > 2.0 * seams::TOL {
                            arc += 1;
                        } else if lp.points.len() > n[&seams::key(lp.points[0])] {
                            extra += 1;
                        }
                    }
                }
            }
            println!(
                "| {name} | {} | {} | {:.1} % | {:.4} | {:.4} / {:.4} | {} | {:.4} | {:.4} |",
                if even { "even" } else { "exact" },
                st.loops,
                100.0 * st.close_share(),
                st.min_seam,
                st.min_gap,
                st.mean_gap(),
                if even {
                    format!("{arc} / {extra}")
                } else {
                    "–".into()
                },
                r.part.void_fraction,
                r.part.coverage
            );
            texts.push(text);
        }
    }
}
