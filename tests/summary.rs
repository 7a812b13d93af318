//! One summary, however it is assembled: per-unit summaries merged in any order give the same
//! figures as one summary over all layers, and the CLI prints the library's figures.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::analysis::analyse_layer;
use dropslice::output::summary::layer_seconds;
use dropslice::{Figures, Job, Settings, Summary};
use std::process::Command;

/// Every layer's summary (plan and analysis) of a shared model.
fn layer_summaries(model: &str, settings: Settings) -> (Job, Vec<Summary>) {
    let job = Job::new(&common::model_bytes(model), model, settings).unwrap();
    let layers = (0..job.layer_count())
        .map(|i| {
            let (plan, region) = job.plan_layer_and_region(i);
            let mut s = Summary::of_layer(&plan);
            s.add_analysis(&analyse_layer(&plan, &region, job.settings()));
            s
        })
        .collect();
    (job, layers)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

fn assert_same(a: &Figures, b: &Figures, what: &str) {
    assert_eq!(a.layers, b.layers, "{what}");
    assert_eq!(a.counts, b.counts, "{what}");
    assert_eq!(a.droplets, b.droplets, "{what}");
    assert_eq!(a.analysed_layers, b.analysed_layers, "{what}");
    assert_eq!(a.repairs, b.repairs, "{what}");
    for (x, y, name) in [
        (a.units[0].volume_mm3, b.units[0].volume_mm3, "volume"),
        (a.units[0].mass_g, b.units[0].mass_g, "mass"),
        (a.print_seconds, b.print_seconds, "time"),
        (a.travel_mm, b.travel_mm, "travel"),
        (a.coverage.unwrap(), b.coverage.unwrap(), "coverage"),
        (a.void_area.unwrap(), b.void_area.unwrap(), "void area"),
    ] {
        assert!(close(x, y), "{what}: {name} {x} vs {y}");
    }
    let (wa, wb) = (a.worst_layer.unwrap(), b.worst_layer.unwrap());
    assert_eq!(wa.index, wb.index, "{what}");
    assert_eq!(wa.area, wb.area, "{what}");
}

#[test]
fn merging_units_in_any_order_gives_the_figures_of_one_summary() {
    let (job, layers) = layer_summaries("3DBenchy.stl", Settings::default());
    let n = layers.len();
    // one summary over all layers, in order
    let mut whole = Summary::default();
    for i in 0..n {
        let (plan, region) = job.plan_layer_and_region(i);
        whole.add(&plan);
        whole.add_analysis(&analyse_layer(&plan, &region, job.settings()));
    }
    let reference = whole.figures(job.settings());
    assert_eq!(reference.layers, n);
    assert!(reference.droplets > 0 && reference.worst_layer.is_some());
    // units of several sizes, merged forwards, backwards and shuffled, and merged in a tree
    for size in [1, 3, 16, n] {
        let units: Vec<Summary> = layers.chunks(size).map(Summary::merged).collect();
        let mut orders = vec![
            (0..units.len()).collect::<Vec<_>>(),
            (0..units.len()).rev().collect(),
        ];
        let mut shuffled: Vec<usize> = (0..units.len()).collect();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64 ^ size as u64;
        for i in (1..shuffled.len()).rev() {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            shuffled.swap(i, (seed % (i as u64 + 1)) as usize);
        }
        orders.push(shuffled);
        for order in orders {
            let merged = Summary::merged(order.iter().map(|&k| &units[k]));
            assert_same(
                &merged.figures(job.settings()),
                &reference,
                &format!("units of {size}"),
            );
        }
        // pairs merged first, then the pairs (as two workers' shares would be)
        let (even, odd): (Vec<_>, Vec<_>) = units.iter().enumerate().partition(|(k, _)| k % 2 == 0);
        let mut a = Summary::merged(even.into_iter().map(|(_, u)| u));
        a.merge(&Summary::merged(odd.into_iter().map(|(_, u)| u)));
        assert_same(&a.figures(job.settings()), &reference, "two shares");
    }
}

#[test]
fn figures_follow_the_estimate_settings() {
    let (job, layers) = layer_summaries("cube_20mm_ascii.stl", Settings::default());
    let s = Summary::merged(&layers);
    let f = s.figures(job.settings());
    let b = job.settings().droplet_width();
    let h = job.settings().layer_height;
    let u0 = f.units[0];
    assert!(close(u0.volume_mm3, f.droplets as f64 * b * b * h));
    assert!(close(u0.mass_g, u0.volume_mm3 / 1000.0 * 1.04));
    assert!(close(
        f.print_seconds,
        f.droplets as f64 / 100.0 + s.travel_mm / 50.0
    ));
    let mut other = Settings {
        travel_speed: 100.0,
        ..Settings::default()
    };
    let u0 = other.unit_mut(dropslice::base::settings::UnitId::FIRST);
    (u0.droplet_rate, u0.material_density) = (200.0, 2.08);
    let g = s.figures(&other);
    assert!(close(g.print_seconds, f.print_seconds / 2.0));
    assert!(close(g.units[0].mass_g, 2.0 * f.units[0].mass_g));
    assert!(s.printable(job.settings()).is_ok());
    // coverage of a cube: most of each layer
    assert!((0.7..1.0).contains(&f.coverage.unwrap()), "{f:?}");
}

/// The page's per-layer plot shows each layer's time (`layer_seconds`, on `LayerResult`); its
/// running total must reach the job's print time. Settings other than the defaults, so a
/// layer estimate that ignored them would not add up.
#[test]
fn layer_times_add_up_to_the_print_time() {
    let mut settings = Settings {
        travel_speed: 23.0,
        ..Settings::default()
    };
    settings
        .unit_mut(dropslice::base::settings::UnitId::FIRST)
        .droplet_rate = 137.0;
    let job = Job::new(
        &common::model_bytes("3DBenchy.stl"),
        "3DBenchy.stl",
        settings.clone(),
    )
    .unwrap();
    let mut whole = Summary::default();
    let mut sum = 0.0;
    let mut with_travel = 0;
    for i in 0..job.layer_count() {
        let plan = job.plan_layer(i);
        let t = layer_seconds(&plan, job.settings());
        // droplets at droplet_rate per second, travel at travel_speed mm/s
        let droplets = (plan.counts.outer + plan.counts.inner + plan.counts.fill) as f64;
        assert!(
            close(t, droplets / 137.0 + plan.travel_mm / 23.0),
            "layer {i}: {t}"
        );
        with_travel += usize::from(plan.travel_mm > 0.0);
        sum += t;
        whole.add(&plan);
    }
    let f = whole.figures(job.settings());
    assert!(f.droplets > 100_000 && with_travel > 100, "{f:?}");
    assert!(close(sum, f.print_seconds), "{sum} vs {}", f.print_seconds);
}

#[test]
fn nothing_to_print_is_one_error() {
    let s = Summary {
        layers: 3,
        ..Summary::default()
    };
    let e = s.printable(&Settings::default()).unwrap_err();
    assert_eq!(e.kind(), "nothing_to_print");
    assert!(
        e.to_string()
            .contains("thinner than the droplet width B = 0.208 mm"),
        "{e}"
    );
    let r = e.report();
    assert_eq!((r.kind, r.setting), ("nothing_to_print", None));
}

/// The number written just before the word `unit` in `line` ("120 layers" → 120).
fn figure(line: &str, unit: &str) -> f64 {
    let words: Vec<&str> = line
        .split([' ', ',', '(', ')'])
        .filter(|w| !w.is_empty())
        .collect();
    words
        .windows(2)
        .find_map(|w| (w[1] == unit).then(|| w[0].parse().ok()).flatten())
        .unwrap_or_else(|| panic!("no figure in {unit} in {line}"))
}

#[test]
fn the_cli_prints_the_librarys_figures() {
    let dir = common::TempDir::new("summary-cli");
    let out = dir.path().join("cube.gco");
    let run = Command::new(common::bin())
        .arg(common::model("cube_20mm_ascii.stl"))
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success());
    let text = String::from_utf8_lossy(&run.stderr);
    let (job, layers) = layer_summaries("cube_20mm_ascii.stl", Settings::default());
    let f = Summary::merged(&layers).figures(job.settings());
    let lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.contains(" layers, ")).unwrap();
    let line = lines[at];
    // The overhang line follows it: a cube has none.
    assert_eq!(f.worst_overhang, None);
    assert_eq!(
        lines.get(at + 1).copied(),
        Some("dropslice: no overhangs (every layer rests on the one below)")
    );
    // Each figure is read back from the line (not rebuilt with the CLI's format): the number
    // written before its unit, to the places the line shows.
    let c = f.counts;
    for (unit, want, places) in [
        ("layers", f.layers as f64, 0),
        ("droplets", f.droplets as f64, 0),
        ("outer", c.outer as f64, 0),
        ("inner", c.inner as f64, 0),
        ("fill", c.fill as f64, 0),
        ("cm³", f.units[0].volume_mm3 / 1000.0, 2),
        ("g", f.units[0].mass_g, 2),
    ] {
        let got = figure(line, unit);
        assert!(
            (got - want).abs() <= 0.5 * 10f64.powi(-places) + 1e-9,
            "{unit}: {got} instead of {want} in {line}"
        );
    }
    assert!(line.contains(" g, print time "), "{line}");
    // the header's counts are the same
    let gco = std::fs::read_to_string(&out).unwrap();
    assert!(gco.contains(&format!("; droplets total       = {:>12}", f.droplets)));
    assert!(gco.contains(&format!(
        "; end of code: {} layers, {} droplets",
        f.layers, f.droplets
    )));
}
