//! The overhang figure with support off (`overhang::overhang_area`, one pass of the boolean
//! engine) against two independent constructions, layer by layer: the region of
//! `support::overhang` (the layer below's complement moved inward by the fast offset, then an
//! intersection: the figure before) and i_overlay's own outward outline of the layer below
//! (`dropslice::base::boolean::grow_within`, chords within 1 µm) taken from the layer by a difference. Also
//! on random star-shaped layers, whose sharp corners make mitres fail.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::base::geom::{DVec2, Shape, Shapes, region_area, signed_area};
use dropslice::slicing::offset::CHORD_TOLERANCE_MM;
use dropslice::support::overhang::overhang_area;
use dropslice::{Settings, support};

/// The largest difference per layer from `support::overhang` and from the outline
/// construction, and the total area.
fn compare(regions: &[Shapes], s: &Settings) -> (f64, f64, f64) {
    let d = s.overhang_limit * s.droplet_width();
    let (mut worst, mut worst_outline, mut total) = (0.0f64, 0.0f64, 0.0);
    assert_eq!(overhang_area(&regions[0], None, s), 0.0);
    for i in 1..regions.len() {
        let (r, below) = (&regions[i], &regions[i - 1]);
        let got = overhang_area(r, Some(below), s);
        let before = region_area(&support::overhang(r, Some(below), s));
        let grown = dropslice::base::boolean::grow_within(below, d, CHORD_TOLERANCE_MM);
        let outline = region_area(&dropslice::base::boolean::difference(r, &grown));
        worst = worst.max((got - before).abs());
        worst_outline = worst_outline.max((got - outline).abs());
        total += got;
    }
    (worst, worst_outline, total)
}

#[test]
fn the_figure_agrees_with_the_two_constructions_on_the_shared_models() {
    for name in [
        "3DBenchy.stl",
        "U_overhang.obj",
        "overhang.obj",
        "bridge.obj",
        "extruder_idler.stl",
        "esca_nonmanifold.stl",
        "spikey_top_solid_header.stl",
    ] {
        let bytes = common::model_bytes(name);
        let job = dropslice::Job::new(&bytes, name, Settings::default()).unwrap();
        let regions: Vec<_> = (0..job.layer_count())
            .map(|i| job.section(i).region)
            .collect();
        let (worst, worst_outline, total) = compare(&regions, job.settings());
        eprintln!(
            "{name}: {total:.4} mm²; largest difference per layer {worst:.2e} mm² (support::overhang), {worst_outline:.2e} mm² (outline)"
        );
        // Rounding only (the engine snaps to a grid of its own per call), and the outline's
        // chords (1 µm) against the offset's.
        assert!(worst < 2e-5, "{name}: {worst}");
        assert!(worst_outline < 1.5e-3, "{name}: {worst_outline}");
    }
}

/// A star around (cx, cy): `n` points at radii drawn from `radius` (a small linear
/// congruential generator, so the test is the same every run), counter-clockwise.
fn star(cx: f64, cy: f64, n: usize, radius: (f64, f64), seed: &mut u64) -> Shape {
    let mut next = || {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let outer: Vec<DVec2> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * (k as f64 + 0.3 * next()) / n as f64;
            let r = radius.0 + (radius.1 - radius.0) * next();
            DVec2::new(cx + r * a.cos(), cy + r * a.sin())
        })
        .collect();
    assert!(signed_area(&outer) > 0.0);
    Shape::new(outer, vec![])
}

#[test]
fn the_figure_agrees_on_layers_with_sharp_corners() {
    // Pairs of stars with spikes a few droplet widths long and notches narrower than 2d:
    // the mitred corners of the layer below often meet other parts of it.
    let s = Settings::default();
    let mut seed = 7u64;
    let mut regions = Vec::new();
    for k in 0..120 {
        let n = 5 + k % 23;
        let spikes = (0.2 + 0.01 * (k % 7) as f64, 0.6 + 0.1 * (k % 5) as f64);
        regions.push(vec![star(0.0, 0.0, n, spikes, &mut seed)]);
    }
    let (worst, worst_outline, total) = compare(&regions, &s);
    eprintln!(
        "stars: {total:.4} mm²; largest difference {worst:.2e} mm² (support::overhang), {worst_outline:.2e} mm² (outline)"
    );
    assert!(total > 1.0, "{total}");
    assert!(worst < 2e-5, "{worst}");
    assert!(worst_outline < 1.5e-3, "{worst_outline}");
}

#[test]
fn a_slot_narrower_than_the_limit_is_no_overhang() {
    // A 10 mm square with slots of widths between d and 2d cut into it from the top, then
    // the same square without slots: every point of a slot lies within d of the layer below
    // (no overhang), but the layer below's mitred corners at a slot's bottom reach across it.
    let s = Settings::default();
    let d = s.overhang_limit * s.droplet_width();
    let p = |x: f64, y: f64| DVec2::new(x, y);
    for w in [1.05 * d, 1.3 * d, 1.6 * d, 1.95 * d] {
        let mut outer = vec![p(0.0, 0.0), p(10.0, 0.0), p(10.0, 10.0)];
        for k in (0..4).rev() {
            let x = 2.0 + 2.0 * k as f64;
            outer.extend([p(x + w, 10.0), p(x + w, 8.0), p(x, 8.0), p(x, 10.0)]);
        }
        outer.push(p(0.0, 10.0));
        let below = vec![Shape::new(outer, vec![])];
        let layer = vec![Shape::new(
            vec![p(0.0, 0.0), p(10.0, 0.0), p(10.0, 10.0), p(0.0, 10.0)],
            vec![],
        )];
        let (worst, worst_outline, total) = compare(&[below, layer], &s);
        eprintln!("slot {w:.3}: {total:.2e} mm², {worst:.2e}, {worst_outline:.2e}");
        assert!(total.abs() < 1e-9, "{w}: {total}");
        assert!(
            worst < 2e-5 && worst_outline < 1.5e-3,
            "{w}: {worst} {worst_outline}"
        );
    }
}
