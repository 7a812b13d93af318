//! Prints the section statistics of chosen layers: `cargo run --release --example section_debug -- MODEL.stl 18 19`.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let bytes = std::fs::read(&args[0]).expect("read model");
    let job = dropslice::Job::new(&bytes, &args[0], dropslice::Settings::default()).expect("job");
    for a in &args[1..] {
        let i: usize = a.parse().expect("layer number");
        let s = job.section(i);
        println!(
            "layer {i} z={} area={:.3} shapes={} holes={} closed={} reoriented={} open={} gap={:.3}",
            s.z,
            dropslice::base::geom::region_area(&s.region),
            s.region.len(),
            s.region.iter().map(|x| x.holes.len()).sum::<usize>(),
            s.closed_loops,
            s.reoriented_loops,
            s.open_chains,
            s.gap_length
        );
        if std::env::var_os("LOOPS").is_some() {
            for c in job.section_loops(i) {
                let a = dropslice::base::geom::signed_area(&c);
                println!("  loop n={} signed_area={a:.3} first={:?}", c.len(), c[0]);
            }
        }
    }
}
