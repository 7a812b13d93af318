//! Times the analysis stages on one model: `cargo run --release --example analysis_profile -- MODEL.stl`.
use dropslice::analysis::*;
use dropslice::{Job, Settings};
use std::time::Instant;
fn main() {
    let path = std::env::args().nth(1).expect("model path");
    let bytes = std::fs::read(&path).expect("read");
    let s = Settings::default();
    let job = Job::new(&bytes, &path, s.clone()).expect("job");
    let b = s.droplet_width();
    let (mut tp, mut tr, mut ta, mut th, mut tv, mut tm) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut tmr = 0.0;
    let mut nvoids = 0;
    let bounds = job.info().bounds;
    let grid = Grid3 {
        origin: [bounds.min[0] - b, bounds.min[1] - b].into(),
        cell: b / GRID3_PER_B,
    };
    for i in 0..job.layer_count() {
        let t = Instant::now();
        let sec = job.section(i);
        let plan = dropslice::plan::plan_layer(&sec.region, i, &s);
        let text = dropslice::gcode::layer_text(&plan);
        tp += t.elapsed().as_secs_f64();
        std::hint::black_box(text);
        let t = Instant::now();
        let c = droplet_centres(&plan, b);
        let r = Raster::from_centres(i, plan.z, &c, &sec.region, &s);
        tr += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let la = r.analysis();
        nvoids += la.voids;
        ta += t.elapsed().as_secs_f64();
        let t = Instant::now();
        std::hint::black_box(r.mask(b / 4.0));
        tm += t.elapsed().as_secs_f64();
        let t = Instant::now();
        std::hint::black_box(r.mask_reference(b / 4.0));
        tmr += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let m = HeightMap::new(&c, &grid, footprint_diameter(&s));
        th += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let _ = slab_voids(&sec.region, &grid, Some(&m), &m, Some(&m), &s);
        tv += t.elapsed().as_secs_f64();
    }
    println!(
        "plan+gcode text {tp:.3} raster {tr:.3} analysis {ta:.3} mask {tm:.3} (before {tmr:.3}) heightmap {th:.3} slab {tv:.3} voids {nvoids}"
    );
}
