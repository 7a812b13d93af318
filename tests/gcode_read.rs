//! The `.gco` reader on files the slicer wrote: the same droplets, in the same order, as the
//! plan (and its preview), layer by layer, and the same counts.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::output::gcode_read::read_gcode;
use dropslice::output::preview::PreviewLayer;
use dropslice::{Job, Settings};

fn check(model: &str, s: Settings) {
    let job = Job::new(&common::model_bytes(model), model, s.clone()).expect("job");
    let mut code = Vec::new();
    let summary = dropslice::write_gcode(&job, &mut code, |_, _| {}).expect("code");
    let (layers, reader) = read_gcode(std::str::from_utf8(&code).unwrap()).expect("read");
    let b = s.droplet_width();
    assert_eq!(reader.droplet_width(), b);
    let plans: Vec<_> = (0..job.layer_count())
        .map(|i| job.plan_layer_and_region(i).0)
        .filter(|p| !p.moves.is_empty())
        .collect();
    assert_eq!(layers.len(), plans.len(), "{model}: layers");
    let mut total = 0;
    for (l, plan) in layers.iter().zip(&plans) {
        let want = PreviewLayer::from_plan(plan, b);
        assert_eq!(
            l.preview.droplets, want.droplets,
            "{model} layer {}",
            l.index
        );
        assert_eq!(l.preview.roles.len(), want.roles.len());
        // The plan's travel starts at the origin on every layer; the file's at the layer below.
        assert!(l.travel_mm >= 0.0);
        assert_eq!(l.counts.total(), plan.counts.total());
        total += l.counts.total();
    }
    assert_eq!(total, summary.counts.total());
}

#[test]
fn reads_back_the_droplets_of_the_plan() {
    check("cube_20mm_ascii.stl", Settings::default());
    let stagger = Settings {
        stagger: true,
        contours: 4,
        ..Settings::default()
    };
    check("extruder_idler.stl", stagger);
}
