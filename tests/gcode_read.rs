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

/// The figures of a file read back use its header's settings: the same droplets, material and
/// mass as the slice that wrote it, and the time of its droplets and of the travel it holds.
#[test]
fn figures_come_from_the_header_settings() {
    let s = Settings {
        droplet_rate: 250.0,
        unit1_droplet_rate: 40.0,
        travel_speed: 80.0,
        material_density: 1.3,
        support: dropslice::base::settings::Support::Unit1,
        ..Settings::default()
    };
    let model = "U_overhang.obj";
    let job = Job::new(&common::model_bytes(model), model, s.clone()).expect("job");
    let mut code = Vec::new();
    let summary = dropslice::write_gcode(&job, &mut code, |_, _| {}).expect("code");
    let want = summary.figures(&s);
    let (layers, reader) = read_gcode(std::str::from_utf8(&code).unwrap()).expect("read");
    let got = reader.figures().expect("figures");
    assert!(want.counts.support > 0, "the model needs support");
    // the code does not tell loops from fill or support: G26 droplets count as loops, G25 as fill
    assert_eq!(got.droplets, want.droplets);
    assert_eq!(got.unit1_droplets, want.unit1_droplets);
    assert_eq!(got.layers, layers.len());
    assert!((got.volume_mm3 - want.volume_mm3).abs() < 1e-9 * want.volume_mm3);
    assert!((got.mass_g - want.mass_g).abs() < 1e-9 * want.mass_g);
    assert!((got.unit1_mass_g - want.unit1_mass_g).abs() < 1e-9 * want.unit1_mass_g);
    let travel: f64 = layers.iter().map(|l| l.travel_mm).sum();
    let c = &want.counts;
    let seconds = (c.total() - c.unit1) as f64 / 250.0 + c.unit1 as f64 / 40.0 + travel / 80.0;
    assert!(
        (got.print_seconds - seconds).abs() < 1e-6 * seconds,
        "{} vs {seconds}",
        got.print_seconds
    );

    // a header setting out of range: no figures, the reason named
    let header = "; layer_height = 0.2\n; droplet_aspect = 1\n; droplet_rate = -5\n";
    let (_, bad) = read_gcode(&format!("{header}G26 X1 Y1 Z0.2\n")).expect("read");
    assert!(
        bad.figures()
            .unwrap_err()
            .to_string()
            .contains("droplet_rate")
    );
}
