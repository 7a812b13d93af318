//! The `.gco` reader on files the slicer wrote: the same droplets, in the same order, as the
//! plan (and its preview), layer by layer, and the same counts.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::base::settings::UnitId;
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
    let mut s = Settings {
        travel_speed: 80.0,
        support: dropslice::base::settings::Support::Unit(UnitId(1)),
        ..Settings::default()
    };
    s.unit_mut(UnitId::FIRST).droplet_rate = 250.0;
    s.unit_mut(UnitId(1)).droplet_rate = 40.0;
    s.unit_mut(UnitId::FIRST).material_density = 1.3;
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
    let droplets = |f: &dropslice::Figures| f.units.iter().map(|u| u.droplets).collect::<Vec<_>>();
    assert_eq!(droplets(&got), droplets(&want));
    assert_eq!(got.layers, layers.len());
    for u in 0..2 {
        let (g, w) = (got.units[u], want.units[u]);
        assert!((g.volume_mm3 - w.volume_mm3).abs() < 1e-9 * w.volume_mm3);
        assert!((g.mass_g - w.mass_g).abs() < 1e-9 * w.mass_g);
    }
    let travel: f64 = layers.iter().map(|l| l.travel_mm).sum();
    let c = &want.counts;
    let (d0, d1) = (c.unit(UnitId::FIRST), c.unit(UnitId(1)));
    let seconds = d0 as f64 / 250.0 + d1 as f64 / 40.0 + travel / 80.0;
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

/// The code as the CLI leaves it: the header's placeholders filled in (same length).
fn finished_code(job: &Job) -> (String, dropslice::Summary) {
    let mut code = Vec::new();
    let summary = dropslice::write_gcode(job, &mut code, |_, _| {}).expect("code");
    let header = job.header(Some(&summary));
    assert_eq!(header.len(), job.header(None).len());
    code[..header.len()].copy_from_slice(header.as_bytes());
    (String::from_utf8(code).expect("text"), summary)
}

/// Re-opening a code shows exactly the figures of the slice that wrote it: the header's own
/// (time, travel, volume, mass, droplets by role; per unit with two units), not figures
/// computed again from the commands (whose travel and roles differ).
#[test]
fn a_finished_code_reads_back_the_figures_of_its_slice() {
    let mut one = Settings {
        travel_speed: 70.0,
        ..Settings::default()
    };
    one.unit_mut(UnitId::FIRST).droplet_aspect = 1.3;
    one.unit_mut(UnitId::FIRST).material_density = 1.17;
    let mut two = Settings {
        support: dropslice::base::settings::Support::Unit(UnitId(1)),
        ..Settings::default()
    };
    two.unit_mut(UnitId(1)).droplet_rate = 40.0;
    // Support from the third unit of three, with its own rate and droplet size.
    let mut three = Settings {
        units: 3,
        support: dropslice::base::settings::Support::Unit(UnitId(2)),
        ..Settings::default()
    };
    three.unit_mut(UnitId(2)).droplet_rate = 30.0;
    three.unit_mut(UnitId(2)).droplet_aspect = 1.2;
    let cases = [
        ("cube_20mm_ascii.stl", one),
        ("U_overhang.obj", two),
        ("U_overhang.obj", three),
    ];
    for (model, s) in cases {
        let job = Job::new(&common::model_bytes(model), model, s.clone()).expect("job");
        let (code, summary) = finished_code(&job);
        let want = summary.figures(&s);
        let (_, reader) = read_gcode(&code).expect("read");
        assert_eq!(reader.figures_note(), None, "{model}");
        let got = reader.figures().expect("figures");
        let exact = |a: f64, b: f64, what: &str| {
            assert_eq!(a.to_bits(), b.to_bits(), "{model}: {what} {a} vs {b}");
        };
        exact(got.print_seconds, want.print_seconds, "print time");
        exact(got.travel_mm, want.travel_mm, "travel");
        assert_eq!(got.units.len(), s.units as usize);
        for (g, w) in got.units.iter().zip(&want.units) {
            exact(g.seconds, w.seconds, "a unit's time");
            exact(g.volume_mm3, w.volume_mm3, "a unit's volume");
            exact(g.mass_g, w.mass_g, "a unit's mass");
            assert_eq!(g.droplets, w.droplets, "{model}: a unit's droplets");
        }
        assert_eq!(got.counts, want.counts, "{model}: droplets by role");
        assert_eq!(got.droplets, want.droplets);
        // the commands alone give another travel (and loops and fill only)
        let unfilled = read_gcode(&code.replacen("; print time", "; print tim", 1))
            .expect("read")
            .1;
        assert_eq!(
            unfilled.figures_note().as_deref(),
            Some("the header has no print time")
        );
        let moves = unfilled.figures().expect("figures");
        assert_ne!(moves.travel_mm.to_bits(), want.travel_mm.to_bits());
        assert_eq!(moves.counts.inner, 0);
        if s.units == 3 {
            assert!(want.units[2].droplets > 0 && code.contains("; volume unit 2"));
            assert!(code.contains("\nT2\n") && !code.contains("; volume unit 1"));
        } else if model.starts_with('U') {
            assert!(want.units[1].droplets > 0 && code.contains("; volume unit 1"));
        } else {
            assert!(code.contains("; droplet_aspect = 1.3") && !code.contains("unit 1"));
        }
    }
}

/// The header's figures are used only when they fit the file: a header never filled in, an
/// older header without them, a figure that is not a number ≥ 0, or commands changed after
/// slicing give the figures of the commands and say why.
#[test]
fn figures_of_the_commands_when_the_header_does_not_fit() {
    let model = "cube_20mm_ascii.stl";
    let s = Settings::default();
    let job = Job::new(&common::model_bytes(model), model, s.clone()).expect("job");
    let (code, _) = finished_code(&job);
    let mut pending = Vec::new();
    dropslice::write_gcode(&job, &mut pending, |_, _| {}).expect("code");
    let note = |text: &str| {
        let (_, r) = read_gcode(text).expect("read");
        let f = r.figures().expect("figures");
        (r.figures_note().unwrap_or_default(), f)
    };
    let (n, _) = note(std::str::from_utf8(&pending).unwrap());
    assert_eq!(
        n,
        "the header's figures were never filled in (the code was not finished)"
    );
    let older: String = code
        .lines()
        .filter(|l| {
            !["; print time", "; travel ", "; volume", "; mass"]
                .iter()
                .any(|p| l.starts_with(p))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(note(&older).0.starts_with("the header has no figures"));
    let line = code.lines().find(|l| l.starts_with("; mass")).unwrap();
    let bad = code.replacen(
        line,
        "; mass                 =                      -1 g",
        1,
    );
    assert_eq!(
        note(&bad).0,
        "the header's mass \"-1\" (line 14) is not a number ≥ 0"
    );
    let first = code.lines().find(|l| l.starts_with("G26")).unwrap();
    let (n, f) = note(&code.replacen(&format!("{first}\n"), "", 1));
    assert!(n.ends_with("the code was changed after slicing"), "{n}");
    assert_eq!(f.counts.inner, 0);
}
