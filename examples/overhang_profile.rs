//! Times the per-layer overhang figure (support off) on a model: the sections, the reference
//! construction (`support::overhang::overhang_reference`: outline of the layer below, two differences)
//! and its parts, the fast one (`support::overhang`), and their largest per-layer difference
//! at the same chord tolerance. `cargo run --release --example overhang_profile MODEL`.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::{Job, Settings, base::geom, support};
use std::time::Instant;
fn best(mut f: impl FnMut() -> f64) -> (f64, f64) {
    let mut b = f64::INFINITY;
    let mut v = 0.0;
    for _ in 0..5 {
        let t = Instant::now();
        v = f();
        b = b.min(t.elapsed().as_secs_f64());
    }
    (b, v)
}
fn main() {
    let path = std::env::args().nth(1).expect("a model");
    let bytes = std::fs::read(&path).expect("readable");
    let job = Job::new(&bytes, &path, Settings::default()).expect("a job");
    let s = job.settings().clone();
    let n = job.layer_count();
    let (ts, _) = best(|| (0..n).map(|i| job.section(i).region.len() as f64).sum());
    let regions: Vec<_> = (0..n).map(|i| job.section(i).region).collect();
    let (ta, va) = best(|| {
        (1..n)
            .map(|i| {
                geom::region_area(&support::overhang::overhang_reference(
                    &regions[i],
                    Some(&regions[i - 1]),
                    &s,
                ))
            })
            .sum()
    });
    let d = s.overhang_limit * s.droplet_width();
    let (tg, _) = best(|| {
        (1..n)
            .map(|i| {
                dropslice::base::boolean::grow_within(
                    &regions[i - 1],
                    d,
                    support::SUPPORT_TOLERANCE_MM,
                )
                .len() as f64
            })
            .sum()
    });
    let (tf, _) = best(|| {
        (1..n)
            .map(|i| {
                dropslice::base::boolean::difference(&regions[i], &regions[i - 1]).len() as f64
            })
            .sum()
    });
    let (tb, vb) = best(|| {
        (1..n)
            .map(|i| geom::region_area(&support::overhang(&regions[i], Some(&regions[i - 1]), &s)))
            .sum()
    });
    let worst = (1..n)
        .map(|i| {
            let g = dropslice::base::boolean::grow_within(
                &regions[i - 1],
                s.overhang_limit * s.droplet_width(),
                dropslice::slicing::offset::CHORD_TOLERANCE_MM,
            );
            let a = geom::region_area(&dropslice::base::boolean::difference(&regions[i], &g));
            let b = geom::region_area(&support::overhang(&regions[i], Some(&regions[i - 1]), &s));
            ((a - b).abs(), i)
        })
        .fold((0.0, 0), |x, y| if y.0 > x.0 { y } else { x });
    println!(
        "largest per-layer difference {:.2e} mm² on layer {}",
        worst.0, worst.1
    );
    println!(
        "{n} layers: sections {ts:.3} s; overhang now {ta:.3} s ({va:.4} mm²), of it grow {tg:.3}, fresh {tf:.3}; new {tb:.3} s ({vb:.4} mm²)"
    );
}
