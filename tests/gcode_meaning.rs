//! Meaning, not bytes: the CLI's G-code on shared models, checked against docs/spec.md 4.5 —
//! only G01/G25/G26 and comments, 4 decimals, Z = i·H, every setting in the header, header
//! droplet totals equal to the commands' count, every droplet inside the part, loop droplets
//! exactly B apart and closed, loops at (outer_offset + k)·B from the boundary — and that
//! settings take effect.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{
    B, Gcode, H, IndexedRegion, Point, dist, g25_lines, g26_runs, layer_index, line_droplets,
    parse_gcode, split_loops,
};
use dropslice::{Job, Settings};
use std::collections::HashMap;

const SPACING_TOL_MM: f64 = 0.0005;
/// Droplets may lie this far outside the section (SPEC: inside, up to float noise).
const INSIDE_TOL_MM: f64 = 1e-6;
/// A loop droplet's distance from the boundary may differ from (f + k)·B by this much:
/// 4-decimal rounding (7e-5), chords of arcs (0.001) and the boolean engine's integer grid.
const RING_TOL_MM: f64 = 0.002;

fn settings_with(sets: &[&str]) -> Settings {
    let mut s = Settings::default();
    for kv in sets {
        let (k, v) = kv.split_once('=').unwrap();
        s.set(k, v).unwrap();
    }
    s.validate().unwrap();
    s
}

fn slice(model: &str, sets: &[&str]) -> Gcode {
    let text = common::slice_cli(&common::model(model), sets);
    let g = parse_gcode(&text);
    assert!(
        g.bad_lines.is_empty(),
        "{model} {sets:?}: lines that are neither G01/G25/G26 with 4-decimal X Y Z nor comments: {:?}",
        &g.bad_lines[..g.bad_lines.len().min(10)]
    );
    g
}

/// Every check of the machine code of docs/spec.md 4.5 on one model; geometry checks on every
/// `stride`-th layer.
fn check_model(model: &str, stride: usize) {
    let sets: &[&str] = &[];
    let s = settings_with(sets);
    let g = slice(model, sets);
    let job = Job::new(&common::model_bytes(model), model, s.clone()).expect("job");
    let n = job.layer_count();

    // Z: layer i (from 1) at i·H, every layer present, ascending.
    assert_eq!(
        g.layers.len(),
        n,
        "{model}: {} layers with commands, the job has {n}",
        g.layers.len()
    );
    for (i, l) in g.layers.iter().enumerate() {
        let want = (i + 1) as f64 * H;
        assert!(
            (l.z - want).abs() < 1e-9,
            "{model}: layer {} has Z = {}, expected {want}",
            i + 1,
            l.z
        );
        assert!(l.cmds.iter().all(|c| c.z == l.z));
    }
    assert_eq!(g.get("layers"), Some(n.to_string().as_str()), "{model}");

    check_header(model, &g, &s);

    // Header totals equal the droplets the commands set (G25 counted from the written,
    // 4-decimal coordinates: what the machine sees).
    let (g26, g25) = recount(&g);
    let header_num = |k: &str| -> u64 {
        g.get(k)
            .unwrap_or_else(|| panic!("{model}: header has no '{k}'"))
            .parse()
            .unwrap_or_else(|_| panic!("{model}: header '{k}' is not a number"))
    };
    let loops = header_num("droplets outer loops") + header_num("droplets inner loops");
    assert_eq!(loops, g26, "{model}: header loop droplets vs G26 commands");
    let fill = header_num("droplets fill");
    assert_eq!(
        fill, g25,
        "{model}: header fill droplets vs droplets of the G25 lines (floor(L/B) + 1 each)"
    );
    assert_eq!(header_num("droplets total"), loops + fill, "{model}");

    // Loops: droplets B apart, each loop closed by repeating its first droplet.
    for l in &g.layers {
        for run in g26_runs(l) {
            for lp in split_loops(&run, B, SPACING_TOL_MM) {
                check_loop(model, l.z, &lp);
            }
        }
    }

    // Geometry against the layer's section.
    for l in g.layers.iter().step_by(stride) {
        let i = layer_index(l.z, H);
        let region = common::nested(&job.section(i).region);
        let idx = IndexedRegion::new(&region);
        let inside = |p: Point, what: &str| {
            assert!(
                idx.contains(p, INSIDE_TOL_MM),
                "{model}: layer {}: {what} at {p:?} lies outside the part (distance {} to the boundary)",
                i + 1,
                idx.boundary_distance(p)
            );
        };
        for c in l.cmds.iter().filter(|c| c.code == "G26") {
            inside(c.p(), "G26 droplet");
        }
        for (a, b) in g25_lines(l) {
            inside(a, "G25 line start");
            inside(b, "G25 line end");
        }
    }
}

/// Droplets set by the G26 commands and by the G25 lines (floor(L/B + 1e-9) + 1 each, L from
/// the written coordinates).
fn recount(g: &Gcode) -> (u64, u64) {
    let (mut g26, mut g25) = (0, 0);
    for l in &g.layers {
        g26 += l.cmds.iter().filter(|c| c.code == "G26").count() as u64;
        for (a, b) in g25_lines(l) {
            g25 += line_droplets(dist(a, b), B);
        }
    }
    (g26, g25)
}

/// Every loop droplet lies (outer_offset + k)·B from the section's boundary, k < contours
/// (docs/spec.md "Geometry derived from them": loop k runs at d_k = (f + k)·B), on every
/// `stride`-th layer.
fn check_rings(model: &str, stride: usize) {
    let s = Settings::default();
    let g = slice(model, &[]);
    let job = Job::new(&common::model_bytes(model), model, s.clone()).expect("job");
    let mut bad = Vec::new();
    for l in g.layers.iter().step_by(stride) {
        let i = layer_index(l.z, H);
        let idx = IndexedRegion::new(&common::nested(&job.section(i).region));
        for c in l.cmds.iter().filter(|c| c.code == "G26") {
            let d = idx.boundary_distance(c.p());
            let k = (d / B - s.outer_offset).round();
            let ok = k >= 0.0
                && k < s.contours as f64
                && (d - (s.outer_offset + k) * B).abs() <= RING_TOL_MM;
            if !ok {
                bad.push(format!("layer {}: {:?} at {d:.4} mm", i + 1, c.p()));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{model}: {} loop droplets are not (0.5 + k)·B from the boundary (k = 0, 1), e.g. {:?}",
        bad.len(),
        &bad[..bad.len().min(8)]
    );
}

/// A loop's droplets: B apart, closed by repeating the first, the closing gap at most B.
fn check_loop(model: &str, z: f64, lp: &[Point]) {
    if lp.len() == 1 {
        return; // a loop too small for a second droplet
    }
    common::assert_loop_spacing(lp, B, SPACING_TOL_MM, &format!("{model}: Z {z}"));
}

/// Every setting is in the header as `; name = value` (unit 1's only when unit 1 is used), and
/// the header reproduces the settings.
fn check_header(model: &str, g: &Gcode, used: &Settings) {
    let mut rebuilt = Settings::default();
    let unit1_used = used.support != dropslice::base::settings::Support::Off;
    let listed: Vec<&str> = used
        .entries_with(|u| u.0 == 0 || (u.0 == 1 && unit1_used))
        .into_iter()
        .map(|(name, _, _)| name)
        .collect();
    for name in dropslice::base::settings::names() {
        if !listed.contains(&name) {
            // docs/spec.md "The header": a unit's settings are listed only when it is used.
            assert!(
                g.get(name).is_none(),
                "{model}: setting '{name}' of an unused unit listed"
            );
            continue;
        }
        let v = g
            .get(name)
            .unwrap_or_else(|| panic!("{model}: setting '{name}' is missing from the header"));
        rebuilt
            .set(name, v)
            .unwrap_or_else(|e| panic!("{model}: header '{name} = {v}' does not parse back: {e}"));
    }
    assert_eq!(
        &rebuilt, used,
        "{model}: the header's settings do not reproduce the run's settings"
    );
    let input = g.get("input").unwrap_or("");
    assert_eq!(input, model, "{model}: header names the input file");
    // The header comes before any command (parse_gcode only reads it there).
    assert!(g.header.len() >= listed.len());
}

#[test]
fn meaning_cube() {
    check_model("cube_20mm_ascii.stl", 1);
}

#[test]
fn meaning_extruder_idler() {
    check_model("extruder_idler.stl", 1);
}

#[test]
fn meaning_slide_n_snap() {
    check_model("slide_n_snap_test_a_medium.stl", 1);
}

#[test]
fn meaning_m3x10_screw() {
    check_model("M3x10_screw.stl", 1);
}

#[test]
fn meaning_3dbenchy() {
    check_model("3DBenchy.stl", 10);
}

#[test]
fn rings_cube() {
    check_rings("cube_20mm_ascii.stl", 1);
}

#[test]
fn rings_m3x10_screw() {
    check_rings("M3x10_screw.stl", 1);
}

#[test]
fn rings_extruder_idler() {
    check_rings("extruder_idler.stl", 1);
}

#[test]
fn rings_slide_n_snap() {
    check_rings("slide_n_snap_test_a_medium.stl", 1);
}

#[test]
fn rings_3dbenchy() {
    check_rings("3DBenchy.stl", 10);
}

// ---------------------------------------------------------------------------------------------
// Settings take effect

#[test]
fn no_contours_no_g26() {
    for model in ["cube_20mm_ascii.stl", "extruder_idler.stl"] {
        let g = slice(model, &["contours=0"]);
        assert_eq!(g.count("G26"), 0, "{model}: contours=0 still prints loops");
        assert!(g.count("G25") > 0, "{model}: contours=0 has no fill either");
    }
}

#[test]
fn no_fill_no_g25() {
    for model in ["cube_20mm_ascii.stl", "extruder_idler.stl"] {
        let g = slice(model, &["fill_density=0"]);
        assert_eq!(
            g.count("G25"),
            0,
            "{model}: fill_density=0 still prints fill"
        );
        assert!(
            g.count("G26") > 0,
            "{model}: fill_density=0 has no loops either"
        );
        assert_eq!(g.get("droplets fill").map(str::trim), Some("0"));
    }
}

/// Ring index k of each loop of each checked layer, in print order, from the distance of its
/// droplets to the section's boundary.
fn loop_rings(model: &str, sets: &[&str]) -> Vec<(usize, Vec<u32>)> {
    let s = settings_with(sets);
    let g = slice(model, sets);
    let job = Job::new(&common::model_bytes(model), model, s).unwrap();
    let mut out = Vec::new();
    for l in &g.layers {
        let i = layer_index(l.z, H);
        let idx = IndexedRegion::new(&common::nested(&job.section(i).region));
        let mut rings = Vec::new();
        for run in g26_runs(l) {
            for lp in split_loops(&run, B, SPACING_TOL_MM) {
                // The median droplet's ring (a few droplets may sit on offset spikes).
                let mut ks: Vec<u32> = lp
                    .iter()
                    .map(|&p| (idx.boundary_distance(p) / B - 0.5).round() as u32)
                    .collect();
                ks.sort_unstable();
                let k = ks[ks.len() / 2];
                rings.push(k);
            }
        }
        out.push((i, rings));
    }
    out
}

#[test]
fn contour_order_outside_in_puts_outermost_first() {
    for model in ["cube_20mm_ascii.stl", "extruder_idler.stl"] {
        for (i, ks) in loop_rings(model, &["contour_order=outside_in"]) {
            assert_eq!(
                ks.first(),
                Some(&0),
                "{model}: layer {}: outside_in: the first loop is not an outermost one: rings {ks:?}",
                i + 1
            );
            assert!(
                ks.windows(2).all(|w| w[0] <= w[1]),
                "{model}: layer {}: outside_in: rings in print order {ks:?}",
                i + 1
            );
        }
        // The default, inside_out: inner loops first, the outermost last.
        for (i, ks) in loop_rings(model, &[]) {
            assert!(
                ks.windows(2).all(|w| w[0] >= w[1]) && ks.last() == Some(&0),
                "{model}: layer {}: inside_out: rings in print order {ks:?}",
                i + 1
            );
        }
    }
}

#[test]
fn print_order_fill_first() {
    for model in ["cube_20mm_ascii.stl", "extruder_idler.stl"] {
        let g = slice(model, &["print_order=fill_first"]);
        let mut layers_with_both = 0;
        for l in &g.layers {
            let last_fill = l.cmds.iter().rposition(|c| c.code == "G25");
            let first_loop = l.cmds.iter().position(|c| c.code == "G26");
            if let (Some(f), Some(c)) = (last_fill, first_loop) {
                layers_with_both += 1;
                assert!(
                    f < c,
                    "{model}: Z {}: fill_first, but a G25 (command {f}) follows a G26 (command {c})",
                    l.z
                );
            }
        }
        assert!(layers_with_both > 0, "{model}");
        // And the default prints contours first.
        let g = slice(model, &[]);
        for l in &g.layers {
            let first_fill = l.cmds.iter().position(|c| c.code != "G26");
            let last_loop = l.cmds.iter().rposition(|c| c.code == "G26");
            if let (Some(f), Some(c)) = (first_fill, last_loop) {
                assert!(c < f, "{model}: Z {}: contours_first violated", l.z);
            }
        }
    }
}

#[test]
fn close_loops_false_drops_the_closing_droplet() {
    for model in [
        "cube_20mm_ascii.stl",
        "extruder_idler.stl",
        "M3x10_screw.stl",
    ] {
        let closed = slice(model, &[]);
        let open = slice(model, &["close_loops=false"]);
        assert_eq!(closed.layers.len(), open.layers.len(), "{model}");
        for (lc, lo) in closed.layers.iter().zip(&open.layers) {
            // The closed run's loops without their closing droplets…
            let mut want: HashMap<(i64, i64), i32> = HashMap::new();
            let key = |p: Point| ((p[0] * 1e4).round() as i64, (p[1] * 1e4).round() as i64);
            for run in g26_runs(lc) {
                for lp in split_loops(&run, B, SPACING_TOL_MM) {
                    let keep = if lp.len() > 1 { lp.len() - 1 } else { 1 };
                    for &p in &lp[..keep] {
                        *want.entry(key(p)).or_default() += 1;
                    }
                }
            }
            // …are exactly the open run's droplets.
            let mut got: HashMap<(i64, i64), i32> = HashMap::new();
            for c in lo.cmds.iter().filter(|c| c.code == "G26") {
                *got.entry(key(c.p())).or_default() += 1;
            }
            assert_eq!(
                got, want,
                "{model}: Z {}: close_loops=false should set the same loop droplets minus each loop's closing one",
                lo.z
            );
        }
        let count = |g: &Gcode, k: &str| -> u64 { g.get(k).unwrap().trim().parse().unwrap() };
        assert!(
            count(&open, "droplets outer loops") < count(&closed, "droplets outer loops"),
            "{model}"
        );
    }
}

#[test]
fn slice_plane_top_cube_layers() {
    let g = slice("cube_20mm_ascii.stl", &["slice_plane=top"]);
    assert_eq!(g.get("layers"), Some("100"));
    assert_eq!(g.get("slice_plane"), Some("top"));
    assert_eq!(g.layers.len(), 100, "every layer of the cube has droplets");
    for (i, l) in g.layers.iter().enumerate() {
        assert!((l.z - (i + 1) as f64 * H).abs() < 1e-9);
        assert!(l.cmds.iter().any(|c| c.code == "G26"));
        assert!(l.cmds.iter().any(|c| c.code == "G25"));
    }
}
