//! Finds offset loop vertices closer to the section boundary than the loop's offset:
//! `cargo run --release --example offset_debug -- MODEL.stl LAYER`.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::base::geom::segment_distance as seg_dist;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let bytes = std::fs::read(&a[0]).unwrap();
    let s = dropslice::Settings::default();
    let job = dropslice::Job::new(&bytes, &a[0], s.clone()).unwrap();
    let layers: Vec<usize> = if a.len() > 1 {
        vec![a[1].parse().unwrap()]
    } else {
        (0..job.layer_count()).collect()
    };
    let b = s.droplet_width();
    let mut bad = 0;
    for i in layers {
        let region = job.section(i).region;
        let c = dropslice::slicing::contours::contours(&region, &s);
        for l in &c.loops {
            let want = (0.5 + l.k as f64) * b;
            for (j, p) in l.points.iter().enumerate() {
                let d = dropslice::base::geom::all_contours(&region)
                    .flat_map(|c| (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()])))
                    .map(|(x, y)| seg_dist(*p, x, y))
                    .fold(f64::INFINITY, f64::min);
                if d < want - 0.002 {
                    bad += 1;
                    if bad < 10 {
                        let n = l.points.len();
                        println!(
                            "layer {i} k={} n={n} vertex {j} {:?} at {d:.4} (want {want:.4}); prev {:?} next {:?}",
                            l.k,
                            p,
                            l.points[(j + n - 1) % n],
                            l.points[(j + 1) % n]
                        );
                    }
                }
            }
        }
    }
    println!("{bad} vertices too close");
}
