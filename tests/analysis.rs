//! The coverage analysis against exact cases (disc area, square lattice, scallops along an
//! edge, overfill across an edge) and the staggering of loops and hatch lines.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::Settings;
use dropslice::analysis::{analyse_layer, analyse_layer_with_mask};
use dropslice::base::geom::{Shape, Shapes};
use dropslice::slicing::plan::{LayerPlan, Move, Role};

/// Points as plain arrays in these tests.
type Point = [f64; 2];
use std::f64::consts::PI;

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Shapes {
    let outer = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]].map(Into::into);
    vec![Shape::new(outer.into(), vec![])]
}

#[test]
fn one_disc_covers_its_area_within_one_percent() {
    let s = Settings::default();
    let b = s.droplet_width();
    let want = PI * b * b / 4.0;
    let region = rect(-1.0, -1.0, 1.0, 1.0);
    // Many positions relative to the grid.
    for i in 0..97 {
        let p = [0.0137 * i as f64 % 0.3, 0.0291 * i as f64 % 0.3];
        let a = analyse_layer(&common::droplet_plan(&[p]), &region, &s);
        let got = a.covered_area;
        assert!(
            (got - want).abs() < 0.01 * want,
            "disc at {p:?}: {got} vs {want}"
        );
        assert!(a.overfill_area == 0.0);
        assert!((a.void_area + got - 4.0).abs() < 0.01, "{}", a.void_area);
    }
}

#[test]
fn square_lattice_at_pitch_b_leaves_one_minus_pi_over_four() {
    let s = Settings::default();
    let b = s.droplet_width();
    let n = 40;
    for (ox, oy) in [(0.0, 0.0), (0.0071, 0.0133), (0.31, 0.047)] {
        let mut pts = Vec::new();
        for i in 0..n {
            for j in 0..n {
                pts.push([ox + (i as f64 + 0.5) * b, oy + (j as f64 + 0.5) * b]);
            }
        }
        let side = n as f64 * b;
        let region = rect(ox, oy, ox + side, oy + side);
        let a = analyse_layer(&common::droplet_plan(&pts), &region, &s);
        let share = a.void_area / a.region_area;
        let want = 1.0 - PI / 4.0;
        assert!(
            (share - want).abs() < 0.01,
            "offset ({ox}, {oy}): void share {share} vs {want}"
        );
        assert!(
            a.overfill_area < 1e-3 * a.region_area,
            "{}",
            a.overfill_area
        );
        // The discs only touch: voids stay apart (about one per lattice cell, plus the
        // scallops along the edges), none larger than a cell's gap.
        assert!(a.voids as f64 > 0.9 * (n * n) as f64, "{} voids", a.voids);
        let largest = a.largest_void.unwrap();
        assert!(largest.area < 0.3 * b * b, "{largest:?}");
    }
}

#[test]
fn a_row_along_an_edge_gives_the_scallop_depth() {
    let s = Settings::default();
    let b = s.droplet_width();
    let r = b / 2.0;
    for pitch in [0.6 * b, 0.8 * b, 0.9 * b] {
        // A strip one droplet wide, droplets on its centre line: scallops on both sides.
        let n = 60;
        let pts: Vec<Point> = (0..n).map(|k| [r + k as f64 * pitch, r]).collect();
        let len = 2.0 * r + (n - 1) as f64 * pitch;
        let a = analyse_layer(&common::droplet_plan(&pts), &rect(0.0, 0.0, len, b), &s);
        let want = r - (r * r - pitch * pitch / 4.0).sqrt();
        assert!(
            (a.deviation_inward - want).abs() < b / 10.0,
            "pitch {pitch}: inward {} vs {want}",
            a.deviation_inward
        );
        // Scallop area: per gap, the strip's cell minus the disc's share.
        assert!(a.deviation_outward < b / 20.0, "{}", a.deviation_outward);
        assert_eq!(a.enclosed_void_area, 0.0);
    }
    // Droplets centred on the edge reach r outside it.
    let pts: Vec<Point> = (0..50).map(|k| [1.0 + k as f64 * 0.8 * b, 0.0]).collect();
    let a = analyse_layer(&common::droplet_plan(&pts), &rect(0.0, 0.0, 12.0, b), &s);
    assert!(
        (a.deviation_outward - r).abs() < b / 10.0,
        "outward {} vs {r}",
        a.deviation_outward
    );
    assert!(a.overfill_area > 0.0);
}

#[test]
fn an_enclosed_void_is_found_with_its_position() {
    let s = Settings::default();
    let b = s.droplet_width();
    // A filled square (pitch 0.6 B, no gaps) with a 3 x 3 hole of droplets missing.
    let mut pts = Vec::new();
    let p = 0.6 * b;
    for i in 0..30 {
        for j in 0..30 {
            if (12..15).contains(&i) && (12..15).contains(&j) {
                continue;
            }
            pts.push([i as f64 * p, j as f64 * p]);
        }
    }
    let side = 29.0 * p;
    let a = analyse_layer(&common::droplet_plan(&pts), &rect(0.0, 0.0, side, side), &s);
    let v = a.largest_void.unwrap();
    assert!(!v.at_boundary, "{v:?}");
    let centre = 13.0 * p;
    assert!((v.centroid[0] - centre).abs() < b / 10.0, "{v:?}");
    assert!((v.centroid[1] - centre).abs() < b / 10.0, "{v:?}");
    // Hole of 3 pitches minus the neighbours' reach: (4p − 2r)² roughly.
    let want = (4.0 * p - b).powi(2);
    assert!((v.area - want).abs() < 0.35 * want, "{} vs {want}", v.area);
    assert!((a.enclosed_void_area - v.area).abs() < 1e-9);
    let (_, mask) = analyse_layer_with_mask(
        &common::droplet_plan(&pts),
        &rect(0.0, 0.0, side, side),
        &s,
        b,
    );
    for t in &mask.tiles {
        assert_eq!(t.void.len(), t.rect.cells());
    }
    let col = ((centre - mask.origin[0]) / mask.cell) as usize;
    let row = ((centre - mask.origin[1]) / mask.cell) as usize;
    assert!(mask.shares(col, row)[0] > 200);
}

#[test]
fn stagger_start_step_is_an_odd_multiple_of_half_a_droplet() {
    use dropslice::slicing::plan::loop_start_step;
    let mut s = Settings::default();
    let b = s.droplet_width();
    assert_eq!(loop_start_step(&s), 0.07);
    s.stagger = true;
    for (jitter, halves) in [(0.07, 1.0), (0.0, 1.0), (0.3, 3.0), (0.5, 5.0)] {
        s.start_jitter = jitter;
        assert!(
            (loop_start_step(&s) - halves * b / 2.0).abs() < 1e-12,
            "{jitter}"
        );
    }
}

#[test]
fn stagger_shifts_hatch_lattices_only_where_directions_repeat() {
    use dropslice::slicing::plan::hatch_shifted;
    let mut s = Settings {
        stagger: true,
        ..Settings::default()
    };
    // 90° steps: the turned lattice already sits over the gaps; nothing shifts.
    assert!((0..8).all(|i| !hatch_shifted(&s, i)));
    s.hatch_angle_step = 0.0;
    let got: Vec<bool> = (0..4).map(|i| hatch_shifted(&s, i)).collect();
    assert_eq!(got, [false, true, false, true]);
    s.hatch_angle_step = 60.0;
    let got: Vec<bool> = (0..7).map(|i| hatch_shifted(&s, i)).collect();
    assert_eq!(got, [false, false, false, true, true, true, false]);
    s.stagger = false;
    assert!((0..8).all(|i| !hatch_shifted(&s, i)));
}

fn cube() -> Vec<u8> {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/models/cube_20mm_ascii.stl");
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn staggered_fill_droplets_lie_on_the_lattice_and_interleave() {
    use dropslice::analysis::droplet_centres;
    let s = Settings {
        stagger: true,
        ..Settings::default()
    };
    let b = s.droplet_width();
    let job = dropslice::Job::new(&cube(), "cube", s.clone()).unwrap();
    for i in [3, 4] {
        let plan = job.plan_layer(i);
        let fill: Vec<Move> = plan
            .moves
            .iter()
            .copied()
            .filter(|m| m.role == Role::Fill)
            .collect();
        let fill_plan = LayerPlan {
            moves: fill,
            ..LayerPlan::default()
        };
        let angle = dropslice::slicing::plan::hatch_angle(&s, i).to_radians();
        let (sn, c) = angle.sin_cos();
        for p in droplet_centres(&fill_plan, b) {
            // Hatch frame: along = x', across = y'.
            let along = (c * p[0] + sn * p[1]) / b;
            let across = (-sn * p[0] + c * p[1]) / b - 0.5;
            assert!((along - along.round()).abs() < 1e-3, "layer {i}: {p:?}");
            assert!((across - across.round()).abs() < 1e-3, "layer {i}: {p:?}");
        }
    }
}

#[test]
fn stagger_lowers_the_cubes_void_fraction() {
    let mut figures = Vec::new();
    for stagger in [false, true] {
        let s = Settings {
            stagger,
            ..Settings::default()
        };
        let job = dropslice::Job::new(&cube(), "cube", s).unwrap();
        let (report, _) = report_of(&job);
        assert_eq!(report.layers.len(), job.layer_count());
        figures.push(report.part);
    }
    let (off, on) = (&figures[0], &figures[1]);
    // 2D: a filled square of discs at pitch B covers about π/4.
    assert!((off.coverage - PI / 4.0).abs() < 0.01, "{off:?}");
    assert!(off.overfill_area < 1e-3 * off.region_area);
    let volume = off.estimate.volume;
    assert!((volume - 8000.0).abs() < 1.0, "{volume}");
    assert!(
        on.estimate.void_fraction < off.estimate.void_fraction - 0.05,
        "{off:?}\n{on:?}"
    );
}

#[test]
fn staggered_hatch_ends_stay_inside_the_part_without_contours() {
    use dropslice::analysis::droplet_centres;
    let s = Settings {
        stagger: true,
        contours: 0,
        ..Settings::default()
    };
    let job = dropslice::Job::new(&cube(), "cube", s.clone()).unwrap();
    for i in [0, 1, 2, 3] {
        let plan = job.plan_layer(i);
        for p in droplet_centres(&plan, s.droplet_width()) {
            assert!(
                (-1e-6..=20.0 + 1e-6).contains(&p[0]) && (-1e-6..=20.0 + 1e-6).contains(&p[1]),
                "layer {i}: droplet at {p:?} outside the cube"
            );
        }
    }
}

/// The job's report as `--report` makes it (each layer analysed in the slicing worker that
/// planned it), and the code written meanwhile.
fn report_of(job: &dropslice::Job) -> (dropslice::analysis::Report, Vec<u8>) {
    use dropslice::analysis::JobAnalysis;
    let mut analysis = JobAnalysis::new(&job.analysis_grid(), job.settings());
    let mut code = Vec::new();
    dropslice::write_gcode_with(job, &mut code, |_, _| {}, &mut analysis).unwrap();
    (analysis.finish(), code)
}

/// The analysis in the slicing workers (the reference, rasterising every layer whole) gives
/// every layer's figures, in order, the same as a layer analysed on its own, and leaves the
/// code as it is without it; so does the banded analysis of `--report`.
#[test]
fn analysis_in_the_slicing_workers_leaves_the_code_and_figures_alone() {
    use dropslice::analysis::JobAnalysis;
    let s = Settings::default();
    let job = dropslice::Job::new(&cube(), "cube", s.clone()).unwrap();
    let (_, banded) = report_of(&job);
    let mut analysis = JobAnalysis::reference(&job.analysis_grid(), job.settings());
    let mut with = Vec::new();
    dropslice::write_gcode_with(&job, &mut with, |_, _| {}, &mut analysis).unwrap();
    let report = analysis.finish();
    assert_eq!(banded, with);
    assert_eq!(report.layers.len(), job.layer_count());
    for i in [0, 7, job.layer_count() - 1] {
        let (plan, region) = job.plan_layer_and_region(i);
        assert_eq!(
            report.layers[i],
            analyse_layer(&plan, &region, &s),
            "layer {i}"
        );
    }
    let mut without = Vec::new();
    dropslice::write_gcode(&job, &mut without, |_, _| {}).unwrap();
    assert_eq!(with, without);
}
