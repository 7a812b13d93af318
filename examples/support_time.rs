//! Times the stages of the support computation on a model (docs/performance.md "Support"):
//! `cargo run --release --example support_time -- MODEL.stl`.
use dropslice::support::{self, grow, overhang, par_map};
use dropslice::{Job, Settings, geom::Shapes};
use std::time::Instant;

fn main() {
    let path = std::env::args().nth(1).expect("usage: support_time MODEL.stl");
    let bytes = std::fs::read(&path).expect("read");
    let mut s = Settings::default();
    s.support = dropslice::settings::Support::Unit1;
    let job = Job::new(&bytes, &path, s.clone()).expect("job");
    let n = job.layer_count();
    let t = Instant::now();
    let regions: Vec<Shapes> = par_map(n, &|i| job.section(i).region);
    println!("sections      {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let o: Vec<Shapes> = par_map(n, &|i| overhang(&regions[i], i.checked_sub(1).map(|j| &regions[j]), &s));
    println!("overhangs     {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let _g: Vec<Shapes> = par_map(n, &|i| grow(&regions[i], 0.5 * s.droplet_width()));
    println!("grow regions  {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let layers = support::support_layers(&regions, &s, |n, f| par_map(n, f));
    println!("support_layers {:.3} s", t.elapsed().as_secs_f64());
    let pts: usize = layers.iter().map(|l| l.region.iter().map(|s| s.contours().map(|c| c.len()).sum::<usize>()).sum::<usize>()).sum();
    println!("support points {pts}; overhang points {}", o.iter().map(|l| l.iter().map(|s| s.contours().map(|c| c.len()).sum::<usize>()).sum::<usize>()).sum::<usize>());
    if std::env::var_os("AREAS").is_some() {
        for (i, l) in layers.iter().enumerate() {
            if i % 10 == 0 || l.unsupported_area > 5.0 {
                println!("layer {i}: overhang {:.2} mm², support {:.2} mm², part {:.2} mm²", l.unsupported_area, dropslice::geom::region_area(&l.region), dropslice::geom::region_area(&regions[i]));
            }
        }
    }
    let s1 = dropslice::plan::support_settings(&s);
    let tol: f64 = std::env::var("TOL").ok().and_then(|v| v.parse().ok()).unwrap_or(0.0);
    let simp = |r: &Shapes| -> Shapes { if tol == 0.0 { return r.clone(); } r.iter().map(|s| dropslice::geom::Shape::new(dropslice::slice::simplify_closed(&s.outer, tol), s.holes.iter().map(|h| dropslice::slice::simplify_closed(h, tol)).collect())).collect() };
    let layers: Vec<Shapes> = layers.iter().map(|l| simp(&l.region)).collect();
    println!("points after simplify {}", layers.iter().map(|l| l.iter().map(|s| s.contours().map(|c| c.len()).sum::<usize>()).sum::<usize>()).sum::<usize>());
    let t = Instant::now();
    let cs: Vec<_> = par_map(n, &|i| dropslice::contours::contours(&layers[i], &s1));
    println!("support contours {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let _h: Vec<_> = par_map(n, &|i| dropslice::hatch::hatch(&cs[i].fill_region, 45.0, s1.droplet_width()).len());
    println!("support hatch {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let _p: Vec<_> = par_map(n, &|i| dropslice::plan::plan_layer(&layers[i], i, &s1).moves.len());
    println!("support plans {:.3} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let c: u64 = par_map(n, &|i| job.plan_layer(i).counts.total()).iter().sum();
    println!("plan all      {:.3} s ({c} droplets)", t.elapsed().as_secs_f64());
}
