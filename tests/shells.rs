//! Shell orientation (issue: inside-out shells vanish): every closed shell is printed as the
//! solid its author meant. An inside-out shell outside every other shell is turned outward;
//! one inside another shell is a cavity. References are exact areas of constructed boxes and
//! the independent oracle's areas of a shared model (tests/fixtures/oracle), never
//! dropslice's own output. Also the droplet limit, which shells of opposite orientation must
//! not be able to cancel.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::{Error, Job, Settings};
use serde_json::Value;
use std::path::PathBuf;

type Tri = [[f32; 3]; 3];

/// An axis-aligned box, facets wound counter-clockwise seen from outside (outward).
fn cuboid(min: [f32; 3], max: [f32; 3]) -> Vec<Tri> {
    let c = |i: usize| {
        [
            if i & 1 == 0 { min[0] } else { max[0] },
            if i & 2 == 0 { min[1] } else { max[1] },
            if i & 4 == 0 { min[2] } else { max[2] },
        ]
    };
    // Each face as a quad, counter-clockwise from outside.
    let quads = [
        [0, 2, 3, 1], // z = min (outward -z)
        [4, 5, 7, 6], // z = max
        [0, 1, 5, 4], // y = min
        [2, 6, 7, 3], // y = max
        [0, 4, 6, 2], // x = min
        [1, 3, 7, 5], // x = max
    ];
    quads
        .iter()
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

fn inverted(mut t: Vec<Tri>) -> Vec<Tri> {
    for f in &mut t {
        f.swap(1, 2);
    }
    t
}

fn job(tris: &[Tri]) -> Result<Job, Error> {
    let bytes = dropslice::model::import::stl::write_binary(b"constructed", tris);
    Job::new(&bytes, "constructed.stl", Settings::default())
}

/// (plane height, section area) of every layer.
fn areas(job: &Job) -> Vec<(f64, f64)> {
    (0..job.layer_count())
        .map(|i| {
            (
                job.plane_z(i),
                dropslice::base::geom::region_area(&job.section(i).region),
            )
        })
        .collect()
}

fn assert_areas(job: &Job, want: impl Fn(f64) -> f64, what: &str) {
    for (z, a) in areas(job) {
        let w = want(z);
        assert!(
            (a - w).abs() < 1e-6,
            "{what}: z = {z}: area {a} instead of {w}"
        );
    }
}

#[test]
fn an_inverted_box_beside_a_box_is_printed() {
    let mut t = cuboid([0.0; 3], [10.0; 3]);
    t.extend(inverted(cuboid([20.0, 0.0, 0.0], [30.0, 10.0, 10.0])));
    let j = job(&t).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 1);
    assert!(
        j.info()
            .warnings
            .iter()
            .any(|w| w.contains("1 closed shell was inside out")),
        "{:?}",
        j.info().warnings
    );
    assert_areas(&j, |_| 200.0, "two boxes, one inverted");
}

#[test]
fn an_inverted_box_overlapping_a_box_gives_their_union() {
    // Without orientation the overlap's winding numbers cancel (+1 − 1 = 0) and it vanishes.
    let mut t = cuboid([0.0; 3], [10.0; 3]);
    t.extend(inverted(cuboid([5.0, 0.0, 0.0], [15.0, 10.0, 10.0])));
    let j = job(&t).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 1);
    assert_areas(&j, |_| 150.0, "overlapping boxes, one inverted");
}

#[test]
fn an_inverted_shell_with_repeated_facets_or_cracks_is_still_turned() {
    // Repeated facets (removed before orientation) and corners a micrometre apart (closed by
    // the tolerance weld, then oriented): the overlap must still be printed.
    let base = cuboid([0.0; 3], [10.0; 3]);
    let other = inverted(cuboid([5.0, 0.0, 0.0], [15.0, 10.0, 10.0]));
    let mut repeated = base.clone();
    repeated.extend(other.iter().copied());
    repeated.extend(other.iter().take(4).copied());
    let j = job(&repeated).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 1);
    assert_eq!(j.info().mesh.duplicate_facets, 4);
    assert_areas(&j, |_| 150.0, "inverted box with repeated facets");

    let mut cracked = base;
    for (k, f) in other.into_iter().enumerate() {
        // Each facet's copy of a corner moved by up to 0.5 µm on its own: no exact weld.
        let f = f.map(|v| v.map(|c| c + 5e-7 * ((k % 3) as f32 - 1.0)));
        cracked.push(f);
    }
    let j = job(&cracked).unwrap();
    assert!(j.info().mesh.tolerance_welded > 0, "{:?}", j.info().mesh);
    assert_eq!(j.info().mesh.flipped_shells, 1);
    for (z, a) in areas(&j) {
        assert!((a - 150.0).abs() < 1e-3, "cracked: z = {z}: area {a}");
    }
}

#[test]
fn boxes_touching_at_a_corner_are_separate_shells() {
    // One vertex is shared after welding: a shell is what edges connect, so the inverted box
    // is still recognised, and a box overlapping both (positive) keeps both printed.
    let mut t = cuboid([0.0; 3], [10.0; 3]);
    t.extend(inverted(cuboid([10.0; 3], [20.0; 3])));
    t.extend(cuboid([15.0, 15.0, 15.0], [25.0, 25.0, 20.0]));
    let j = job(&t).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 1);
    assert_areas(
        &j,
        // Below z = 10 the first box, then the inverted one, and from z = 15 the third box
        // overlapping it by 5 × 5.
        |z| if z < 15.0 { 100.0 } else { 175.0 },
        "boxes touching at a corner",
    );
}

#[test]
fn an_inverted_box_inside_a_box_is_a_cavity() {
    let mut t = cuboid([0.0; 3], [20.0; 3]);
    t.extend(inverted(cuboid([5.0; 3], [15.0; 3])));
    let j = job(&t).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 0);
    assert_eq!(j.info().mesh.cavity_shells, 1);
    assert_areas(
        &j,
        |z| {
            if (5.0..15.0).contains(&z) {
                300.0
            } else {
                400.0
            }
        },
        "box with a cavity",
    );
}

#[test]
fn a_whole_inverted_part_with_a_cavity_and_a_core() {
    // Nesting: a box with a cavity and a solid core floating in the cavity. The author's
    // solid is box − cavity + core; only the outer box was exported inside out.
    let mut t = inverted(cuboid([0.0; 3], [30.0; 3]));
    t.extend(inverted(cuboid([5.0; 3], [25.0; 3]))); // the cavity: facets face into it
    t.extend(cuboid([10.0; 3], [20.0; 3])); // the core: outward
    let j = job(&t).unwrap();
    // The outer box was inside out and is outside everything: flipped. The cavity is inside
    // it: kept. The core is positive: untouched.
    assert_eq!(j.info().mesh.flipped_shells, 1);
    assert_eq!(j.info().mesh.cavity_shells, 1);
    assert_areas(
        &j,
        |z| {
            if (10.0..20.0).contains(&z) {
                900.0 - 400.0 + 100.0
            } else if (5.0..25.0).contains(&z) {
                900.0 - 400.0
            } else {
                900.0
            }
        },
        "inverted box with cavity and core",
    );
}

fn shared_model(name: &str) -> Vec<Tri> {
    dropslice::model::import::stl::parse(&common::model_bytes(name))
        .unwrap()
        .0
}

/// The facets of the connected piece (by shared vertices) that holds facet 0.
fn first_body(t: &[Tri]) -> Vec<bool> {
    let key = |v: &[f32; 3]| v.map(f32::to_bits);
    let mut in_body = vec![false; t.len()];
    in_body[0] = true;
    let mut verts: std::collections::HashSet<[u32; 3]> = t[0].iter().map(key).collect();
    loop {
        let mut grew = false;
        for (i, f) in t.iter().enumerate() {
            if !in_body[i] && f.iter().any(|v| verts.contains(&key(v))) {
                in_body[i] = true;
                verts.extend(f.iter().map(key));
                grew = true;
            }
        }
        if !grew {
            return in_body;
        }
    }
}

#[test]
fn a_shared_model_with_one_shell_inside_out_matches_the_oracle() {
    // slide_n_snap has two bodies (the two halves of a clip); turn the first inside out.
    let model = "slide_n_snap_test_a_medium";
    let mut t = shared_model(&format!("{model}.stl"));
    let body = first_body(&t);
    let turned = body.iter().filter(|&&b| b).count();
    assert!(turned > 0 && turned < t.len(), "the model has two bodies");
    for (f, &b) in t.iter_mut().zip(&body) {
        if b {
            f.swap(1, 2);
        }
    }
    let j = job(&t).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 1);
    let oracle: Value = serde_json::from_str(
        &std::fs::read_to_string(
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join(format!("tests/fixtures/oracle/{model}.json")),
        )
        .unwrap(),
    )
    .unwrap();
    let layers = oracle["layers"].as_array().unwrap();
    assert_eq!(j.layer_count(), layers.len());
    let mut bad = Vec::new();
    for (i, l) in layers.iter().enumerate() {
        if l.get("near_plane_faces").is_some() {
            continue;
        }
        let want = l["nonzero"]["area"].as_f64().unwrap();
        let got = dropslice::base::geom::region_area(&j.section(i).region);
        if (got - want).abs() > (want * 0.005).max(0.05) {
            bad.push(format!("layer {i}: {got:.3} vs oracle {want:.3}"));
        }
    }
    assert!(
        bad.is_empty(),
        "{} layers differ:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn the_droplet_limit_counts_inverted_shells() {
    // A 1 m box beside an inside-out 1 m box: their signed volumes cancel, yet both would be
    // printed. The limit must see 2 m³.
    let mut t = cuboid([0.0; 3], [1000.0; 3]);
    t.extend(inverted(cuboid(
        [1100.0, 0.0, 0.0],
        [2100.0, 1000.0, 1000.0 - 1e-2],
    )));
    match job(&t) {
        Err(Error::Setting { message, .. }) => assert!(message.contains("droplets"), "{message}"),
        Err(e) => panic!("refused for another reason: {e}"),
        Ok(_) => panic!("a 2 m³ job was accepted"),
    }
    // The same with both shells open (one facet missing from each): the volume of open
    // shells means little, so the limit samples the sliced area.
    let mut a = cuboid([0.0; 3], [1000.0; 3]);
    a.remove(0);
    let mut b = inverted(cuboid([1100.0, 0.0, 0.0], [2100.0, 1000.0, 999.99]));
    b.remove(0);
    a.extend(b);
    match job(&a) {
        Err(Error::Setting { message, .. }) => assert!(message.contains("droplets"), "{message}"),
        Err(e) => panic!("refused for another reason: {e}"),
        Ok(_) => panic!("a 2 m³ open job was accepted"),
    }
}

#[test]
fn the_cli_refuses_the_inverted_box_file_before_writing() {
    let dir = common::TempDir::new("shells-limit");
    let mut t = cuboid([0.0; 3], [1000.0; 3]);
    t.extend(inverted(cuboid(
        [1100.0, 0.0, 0.0],
        [2100.0, 1000.0, 1000.0 - 1e-2],
    )));
    let input = dir.path().join("boxes.stl");
    std::fs::write(
        &input,
        dropslice::model::import::stl::write_binary(b"two boxes", &t),
    )
    .unwrap();
    let out = dir.path().join("boxes.gco");
    let r = std::process::Command::new(common::bin())
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        r.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(String::from_utf8_lossy(&r.stderr).contains("droplets"));
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        left,
        vec![std::ffi::OsString::from("boxes.stl")],
        "files left: {left:?}"
    );
}
