//! The 20 mm calibration cube through the CLI, checked against docs/spec.md's geometry with the
//! default settings: H = 0.2, B = 0.208, two loops at B/2 and 3B/2, fill boundary at 2B,
//! hatch at 45°, 135°, 45°, … spaced B, `contour_order = inside_out`.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{B, H, Point, assert_loop_spacing, g25_lines, g26_runs, parse_gcode, split_loops};

const SIDE: f64 = 20.0;
/// Tolerance of a droplet centre on its offset square (4-decimal rounding and chords).
const ON_SQUARE_MM: f64 = 0.001;
const SPACING_TOL_MM: f64 = 0.0005;

/// `p` lies on the boundary of the square [d, SIDE − d]² (within `tol`).
fn on_inset_square(p: Point, d: f64, tol: f64) -> bool {
    let (lo, hi) = (d, SIDE - d);
    let inside = p.iter().all(|&c| c >= lo - tol && c <= hi + tol);
    let near_edge = [p[0] - lo, hi - p[0], p[1] - lo, hi - p[1]]
        .iter()
        .any(|e| e.abs() <= tol);
    inside && near_edge
}

/// Layer `m`'s contour loops: one run of G26, split where a droplet is more than B from the
/// one before; a cube's layer has two.
fn contour_loops(layer: &common::Layer, m: usize) -> Vec<Vec<Point>> {
    let runs = g26_runs(layer);
    assert_eq!(runs.len(), 1, "layer {m}: contours are one run of G26");
    let loops = split_loops(&runs[0], B, SPACING_TOL_MM);
    assert_eq!(
        loops.len(),
        2,
        "layer {m}: two loops expected, got {}",
        loops.len()
    );
    loops
}

/// Every droplet of the loop lies on the cube's square inset by `d`.
fn on_square(lp: &[Point], d: f64) -> bool {
    lp.iter().all(|&p| on_inset_square(p, d, ON_SQUARE_MM))
}

fn cube_gcode(sets: &[&str]) -> common::Gcode {
    let text = common::slice_cli(&common::model("cube_20mm_ascii.stl"), sets);
    let g = parse_gcode(&text);
    assert!(g.bad_lines.is_empty(), "bad lines: {:?}", &g.bad_lines[..]);
    g
}

#[test]
fn cube_layers_loops_and_hatch() {
    let g = cube_gcode(&[]);
    assert_eq!(
        g.layers.len(),
        100,
        "a 20 mm cube at H = 0.2 has 100 layers"
    );
    assert_eq!(g.get("layers"), Some("100"));

    for (i, layer) in g.layers.iter().enumerate() {
        let m = i + 1;
        assert!(
            (layer.z - m as f64 * H).abs() < 1e-9,
            "layer {m}: Z = {}, expected {}",
            layer.z,
            m as f64 * H
        );

        // Contours: one run of G26 (contours first), two loops: k = 1 (3B/2) then k = 0 (B/2).
        let loops = contour_loops(layer, m);
        for (loop_no, (lp, d)) in loops.iter().zip([1.5 * B, 0.5 * B]).enumerate() {
            let what = if loop_no == 0 {
                "inner loop (k = 1, printed first)"
            } else {
                "outermost loop (k = 0)"
            };
            for p in lp {
                assert!(
                    on_inset_square(*p, d, ON_SQUARE_MM),
                    "layer {m}: {what}: droplet {p:?} is not on the square inset by {d}"
                );
            }
            // Closed: the last droplet repeats the first, and the gap before it is at most B.
            assert!(lp.len() > 4, "layer {m}: {what} has {} droplets", lp.len());
            assert_loop_spacing(lp, B, SPACING_TOL_MM, &format!("layer {m}: {what}"));
            let n = lp.len();
            // The loop goes all the way round: perimeter / B droplets (corners cut a little).
            let perimeter = 4.0 * (SIDE - 2.0 * d);
            let expected = perimeter / B;
            assert!(
                ((n - 1) as f64 - expected).abs() <= 4.0,
                "layer {m}: {what}: {} droplets, expected about {expected:.1}",
                n - 1
            );
        }

        // Fill: G25 lines at 45°, 135°, 45°, … spaced B, ending on the square inset by 2B.
        let lines = g25_lines(layer);
        assert!(!lines.is_empty(), "layer {m}: no fill");
        let angle = (45.0 + (m - 1) as f64 * 90.0).to_radians();
        let (dir, normal) = ([angle.cos(), angle.sin()], [-angle.sin(), angle.cos()]);
        let mut offsets = Vec::new();
        for &(a, b) in &lines {
            let v = [b[0] - a[0], b[1] - a[1]];
            let across = v[0] * normal[0] + v[1] * normal[1];
            assert!(
                across.abs() <= 3e-4,
                "layer {m}: G25 {a:?} → {b:?} is not at {}° (off by {across} mm)",
                45 + ((m - 1) * 90) % 180
            );
            let along = v[0] * dir[0] + v[1] * dir[1];
            assert!(
                along.abs() > 0.0,
                "layer {m}: zero-length G25 line at {a:?}"
            );
            for p in [a, b] {
                assert!(
                    on_inset_square(p, 2.0 * B, ON_SQUARE_MM),
                    "layer {m}: hatch end {p:?} is not on the fill boundary (square inset by 2B)"
                );
            }
            offsets.push(a[0] * normal[0] + a[1] * normal[1]);
        }
        offsets.sort_by(f64::total_cmp);
        for w in offsets.windows(2) {
            assert!(
                ((w[1] - w[0]) - B).abs() <= SPACING_TOL_MM,
                "layer {m}: hatch lines {} apart, expected B = {B}",
                w[1] - w[0]
            );
        }
        // The lines cover the fill square from corner to corner.
        let span = offsets.last().unwrap() - offsets[0];
        let diag = (SIDE - 4.0 * B) * std::f64::consts::SQRT_2;
        assert!(
            span > diag - 2.0 * B && span <= diag,
            "layer {m}: hatch lines span {span} mm across, the fill square's diagonal is {diag}"
        );

        // No droplet centre outside the part [0, 20]²; G25 ends bound the line's droplets.
        for c in &layer.cmds {
            if c.code == "G01" {
                continue;
            }
            assert!(
                (0.0..=SIDE).contains(&c.x) && (0.0..=SIDE).contains(&c.y),
                "layer {m}: {} at ({}, {}) is outside the part",
                c.code,
                c.x,
                c.y
            );
        }
        for &(a, _) in &lines {
            assert!(
                (0.0..=SIDE).contains(&a[0]) && (0.0..=SIDE).contains(&a[1]),
                "layer {m}: G25 starts at {a:?}, outside the part"
            );
        }
    }
}

#[test]
fn cube_outermost_loop_first_with_outside_in() {
    let g = cube_gcode(&["contour_order=outside_in"]);
    assert_eq!(g.layers.len(), 100);
    for (i, layer) in g.layers.iter().enumerate() {
        let loops = contour_loops(layer, i + 1);
        assert!(
            on_square(&loops[0], 0.5 * B),
            "layer {}: with outside_in the first loop must be the outermost (B/2)",
            i + 1
        );
        assert!(
            on_square(&loops[1], 1.5 * B),
            "layer {}: with outside_in the second loop must be at 3B/2",
            i + 1
        );
    }
}

#[test]
fn cube_top_slice_plane_has_100_layers() {
    let g = cube_gcode(&["slice_plane=top"]);
    assert_eq!(g.layers.len(), 100);
    assert_eq!(g.get("layers"), Some("100"));
    for (i, layer) in g.layers.iter().enumerate() {
        assert!((layer.z - (i + 1) as f64 * H).abs() < 1e-9);
        // Every layer of a cube is the full square: the outermost loop lies on B/2.
        let loops = contour_loops(layer, i + 1);
        assert!(on_square(&loops[1], 0.5 * B), "layer {}", i + 1);
    }
}
