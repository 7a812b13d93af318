//! Times the offset of every layer (d = B/2, 3B/2, 2B) with dropslice's inset and i_overlay's
//! outline, and prints where they differ: `cargo run --release --example offset_compare -- MODEL.stl`.
use dropslice::offset::inset;
use dropslice::slice::{Shapes, region_area};
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};
use std::time::Instant;

fn outline(region: &Shapes, d: f64) -> Shapes {
    let angle = 2.0 * (1.0 - (dropslice::offset::CHORD_TOLERANCE_MM / d).min(1.0)).acos();
    let style = OutlineStyle::default()
        .outer_offset(-d)
        .inner_offset(-d)
        .line_join(LineJoin::Round(angle));
    region.outline(&style)
}

fn describe(s: &Shapes) -> Vec<String> {
    s.iter()
        .flatten()
        .map(|c| {
            format!(
                "{} pts, area {:.6}",
                c.len(),
                dropslice::slice::signed_area(c)
            )
        })
        .collect()
}

fn main() {
    let path = std::env::args().nth(1).expect("model path");
    let bytes = std::fs::read(&path).expect("read");
    let job = dropslice::Job::new(&bytes, &path, dropslice::Settings::default()).expect("job");
    let b = job.settings().droplet_width();
    let (mut t_ours, mut t_outline, mut worst) = (0.0, 0.0, (0.0f64, 0usize, 0.0f64));
    for i in 0..job.layer_count() {
        let sec = job.section(i);
        for f in [0.5, 1.5, 2.0] {
            let t = Instant::now();
            let a = inset(&sec.region, f * b, f * b);
            t_ours += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let c = outline(&sec.region, f * b);
            t_outline += t.elapsed().as_secs_f64();
            let (aa, ca) = (region_area(&a), region_area(&c));
            let n_a: usize = a.iter().map(|s| s.len()).sum();
            let n_c: usize = c.iter().map(|s| s.len()).sum();
            if (aa - ca).abs() > worst.0 {
                worst = ((aa - ca).abs(), i, f);
            }
            if (aa - ca).abs() > 0.01 + 1e-3 * ca || n_a != n_c {
                println!("layer {i} d = {f} B: area {aa:.4} vs {ca:.4}, loops {n_a} vs {n_c}");
                if std::env::var("VERBOSE").is_ok() {
                    println!(
                        "  inset:   {:?}\n  outline: {:?}",
                        describe(&a),
                        describe(&c)
                    );
                }
            }
        }
    }
    println!(
        "inset {t_ours:.3} s, i_overlay outline {t_outline:.3} s; largest area difference {:.5} mm² (layer {}, d = {} B)",
        worst.0, worst.1, worst.2
    );
}
