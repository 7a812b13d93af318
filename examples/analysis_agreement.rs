//! The part's 2D figures by the analysis' fast paths and by the reference paths they replaced,
//! summed over every `STEP`-th layer:
//! `cargo run --release --example analysis_agreement -- STEP MODEL.stl... [--stagger]`.
//! Prints a Markdown table: coverage, void share, enclosed void share (of the region area),
//! largest void and boundary deviation, fast / reference, and the largest difference.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::analysis::{LayerAnalysis, Raster};
use dropslice::{Job, Settings};

#[derive(Default)]
struct Part {
    region: f64,
    covered: f64,
    void: f64,
    enclosed: f64,
    largest: f64,
    deviation: f64,
}

impl Part {
    fn add(&mut self, a: &LayerAnalysis) {
        self.region += a.region_area;
        self.covered += a.covered_area;
        self.void += a.void_area;
        self.enclosed += a.enclosed_void_area;
        self.largest = self.largest.max(a.largest_void.map_or(0.0, |v| v.area));
        self.deviation = self.deviation.max(a.boundary_deviation);
    }

    fn figures(&self) -> [f64; 5] {
        let r = self.region.max(1e-12);
        [
            self.covered / r,
            self.void / r,
            self.enclosed / r,
            self.largest,
            self.deviation,
        ]
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let step: usize = args[0].parse().expect("STEP");
    let stagger = args.iter().any(|a| a == "--stagger");
    println!(
        "| model | stagger | layers | coverage | void share | enclosed share | largest void mm² | deviation mm | largest difference |"
    );
    println!("|---|---|---:|---|---|---|---|---|---:|");
    for path in args[1..].iter().filter(|a| !a.starts_with("--")) {
        let s = Settings {
            stagger,
            ..Settings::default()
        };
        let job = Job::new(&std::fs::read(path).expect("read"), path, s.clone()).expect("job");
        let (mut fast, mut reference) = (Part::default(), Part::default());
        let mut n = 0;
        for i in (0..job.layer_count()).step_by(step) {
            let region = &job.section(i).region;
            let plan = dropslice::slicing::plan::plan_layer(region, i, &s);
            let r = Raster::new(&plan, region, &s);
            fast.add(&r.analysis());
            reference.add(&r.analysis_reference());
            n += 1;
        }
        let (f, r) = (fast.figures(), reference.figures());
        let diff = f
            .iter()
            .zip(&r)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let cell = |k: usize| format!("{:.4} / {:.4}", f[k], r[k]);
        let name = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy();
        println!(
            "| {name} | {} | {n} | {} | {} | {} | {} | {} | {diff:.1e} |",
            if stagger { "on" } else { "off" },
            cell(0),
            cell(1),
            cell(2),
            cell(3),
            cell(4)
        );
    }
}
