//! Shell orientation (issue: inside-out shells vanish): every closed shell is printed as the
//! solid its author meant. An inside-out shell outside every other shell is turned outward;
//! one inside another shell is a cavity. References are exact areas of constructed boxes and
//! the independent oracle's areas of a shared model (tests/fixtures/oracle), never
//! dropslice's own output. Also the droplet limit, which shells of opposite orientation must
//! not be able to cancel.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::cuboid;
use dropslice::{Error, Job, Settings};
use std::path::PathBuf;

type Tri = [[f32; 3]; 3];

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

/// The section area of the 20 mm box with the 10 mm cavity [5, 15]³: 400 mm², less the
/// cavity's 100 mm² at its heights.
fn cavity_box_area(z: f64) -> f64 {
    if (5.0..15.0).contains(&z) {
        300.0
    } else {
        400.0
    }
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

/// One of the job's warnings contains every one of `parts`.
fn assert_warned(j: &Job, parts: &[&str]) {
    let warnings = &j.info().warnings;
    assert!(
        warnings.iter().any(|w| parts.iter().all(|p| w.contains(p))),
        "{warnings:?}"
    );
}

/// The job of a 10 mm box at the origin and an inside-out 10 mm box at `at`, whose one shell
/// turned outward it checks.
fn box_and_inverted_box(at: [f32; 3]) -> Job {
    let mut t = cuboid([0.0; 3], [10.0; 3]);
    t.extend(inverted(cuboid(at, at.map(|c| c + 10.0))));
    let j = job(&t).unwrap();
    assert_eq!(j.info().mesh.flipped_shells, 1);
    j
}

#[test]
fn an_inverted_box_beside_a_box_is_printed() {
    let j = box_and_inverted_box([20.0, 0.0, 0.0]);
    assert_warned(&j, &["1 closed shell was inside out"]);
    assert_areas(&j, |_| 200.0, "two boxes, one inverted");
}

#[test]
fn an_inverted_box_overlapping_a_box_gives_their_union() {
    // Without orientation the overlap's winding numbers cancel (+1 − 1 = 0) and it vanishes.
    let j = box_and_inverted_box([5.0, 0.0, 0.0]);
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
    assert_areas(&j, cavity_box_area, "box with a cavity");
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
    let areas: Vec<f64> = areas(&j).into_iter().map(|(_, a)| a).collect();
    common::assert_oracle_areas(model, &areas, "one shell inside out");
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

// ---------------------------------------------------------------------------------------------
// Many shells: the orientation step is near-linear in the number of shells and bounded.

/// The signed volume of facets (outward: positive).
fn volume(t: &[Tri]) -> f64 {
    t.iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| v.map(f64::from));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

#[test]
fn a_million_tiny_inverted_cubes_are_all_turned_outward() {
    // 100 × 100 × 100 inside-out cubes of 0.5 mm, 1 mm apart, as one mesh: every one is
    // outside every other, so every one is turned outward (none left unchecked).
    let n = 100usize;
    let mut mesh = dropslice::model::mesh::Mesh::default();
    for i in 0..n * n * n {
        let at = [i % n, i / n % n, i / (n * n)].map(|c| c as f64);
        let base = mesh.vertices.len() as u32;
        for k in 0..8 {
            mesh.vertices
                .push([0, 1, 2].map(|j| at[j] + 0.5 * ((k >> j) & 1) as f64));
        }
        // The cube's faces wound inward (clockwise seen from outside).
        for q in [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ] {
            mesh.facets.push([q[0], q[1], q[2]].map(|v| base + v));
            mesh.facets.push([q[0], q[2], q[3]].map(|v| base + v));
        }
    }
    assert!(mesh.signed_volume() < 0.0);
    let t = std::time::Instant::now();
    let o = mesh.orient_shells();
    eprintln!(
        "orientation of {} inverted cubes: {:.2?}",
        n * n * n,
        t.elapsed()
    );
    assert_eq!(o.closed, n * n * n);
    assert_eq!((o.flipped, o.cavities, o.unchecked), (n * n * n, 0, 0));
    for (i, cube) in mesh.facets.chunks(12).enumerate() {
        let v: f64 = cube
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
                let (b, c) = (
                    [0, 1, 2].map(|k| b[k] - a[k]),
                    [0, 1, 2].map(|k| c[k] - a[k]),
                );
                // Outward: the normal points away from the cube's centre.
                let nrm = [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ];
                let centre = [i % n, i / n % n, i / (n * n)].map(|c| c as f64 + 0.25);
                (0..3).map(|k| nrm[k] * (a[k] - centre[k])).sum::<f64>()
            })
            .sum();
        assert!(v > 0.0, "cube {i} still faces inward");
    }
    assert!((mesh.signed_volume() - 0.125 * (n * n * n) as f64).abs() < 1e-3);
}

#[test]
fn many_nested_or_overlapping_inverted_shells_stay_within_the_budget() {
    // 5000 nested inside-out cubes: each is inside all the bigger ones, so deciding them all
    // would take every bigger cube's facets for every cube (1.5 × 10⁸ evaluations). The
    // outermost is turned outward; the others are cavities (inside it) or, past the budget,
    // left as they are.
    let k = 5000;
    let mut t = Vec::new();
    for i in 0..k {
        let d = i as f32 * 0.005;
        t.extend(inverted(cuboid([d; 3], [60.0 - d; 3])));
    }
    let mut mesh = dropslice::model::mesh::Mesh::weld(&t).0;
    let clock = std::time::Instant::now();
    let o = mesh.orient_shells();
    eprintln!("{k} nested inverted cubes: {:.2?}, {o:?}", clock.elapsed());
    assert_eq!(o.flipped, 1);
    assert_eq!(o.flipped + o.cavities + o.unchecked, k);
    assert!(o.unchecked > 0, "{o:?}");
    // 20 000 inside-out cubes shifted by 0.01 µm each: every box overlaps every other, none holds
    // another. Each is turned outward or, past the budget, left as it is.
    let k = 20_000;
    let mut t = Vec::new();
    for i in 0..k {
        let d = i as f32 * 1e-5;
        t.extend(inverted(cuboid([d, 0.0, 0.0], [1.0 + d, 1.0, 1.0])));
    }
    let mut mesh = dropslice::model::mesh::Mesh::weld(&t).0;
    let clock = std::time::Instant::now();
    let o = mesh.orient_shells();
    eprintln!(
        "{k} overlapping inverted cubes: {:.2?}, {o:?}",
        clock.elapsed()
    );
    assert_eq!(o.closed, k);
    assert_eq!(o.cavities, 0);
    assert_eq!(o.flipped + o.unchecked, k);
}

#[test]
fn a_small_3mf_fanning_out_inverted_cubes_by_components_is_oriented_quickly() {
    // Five levels of ten components each: 100 000 inside-out cubes from a file of about a
    // kilobyte, every one outside the others.
    let bytes = common::fanned_cubes_3mf(5, 0.5, true);
    assert!(bytes.len() < 2000, "{} bytes", bytes.len());
    let t = std::time::Instant::now();
    let j = Job::new(&bytes, "fan.3mf", Settings::default()).unwrap();
    eprintln!(
        "3MF with 100 000 inverted cubes: Job::new {:.2?}",
        t.elapsed()
    );
    let m = &j.info().mesh;
    assert_eq!((m.flipped_shells, m.unchecked_shells), (100_000, 0));
    assert!(m.signed_volume > 0.0);
    assert_warned(&j, &["100000 closed shells were inside out"]);
}

// ---------------------------------------------------------------------------------------------
// Open shells: oriented by their own volume, holes capped.

/// A prism over the convex polygon `ring` (counter-clockwise seen from above) from z = 0 to
/// `h`, outward: side quads, and fans for the bottom and the top.
fn prism(ring: &[[f32; 2]], h: f32) -> Vec<Tri> {
    let n = ring.len();
    let p = |i: usize, z: f32| [ring[i % n][0], ring[i % n][1], z];
    let mut t = Vec::new();
    for i in 0..n {
        t.push([p(i, 0.0), p(i + 1, 0.0), p(i + 1, h)]);
        t.push([p(i, 0.0), p(i + 1, h), p(i, h)]);
    }
    for i in 1..n - 1 {
        t.push([p(0, 0.0), p(i + 1, 0.0), p(i, 0.0)]);
        t.push([p(0, h), p(i, h), p(i + 1, h)]);
    }
    t
}

/// A "D": the part of a circle of radius `r` (vertices every 9°, from 2°) with x < `cut`,
/// closed by the chord at x = `cut`; counter-clockwise.
fn d_ring(r: f32, cut: f32) -> Vec<[f32; 2]> {
    let y = (r * r - cut * cut).sqrt();
    // Angles from 2° in steps of 9° lie in (0, 360°): in order, they run counter-clockwise
    // from the chord's top end round the left side to its bottom end.
    let mut ring = vec![[cut, y]];
    for k in 0..40 {
        let a = (2.0 + 9.0 * k as f32).to_radians();
        if r * a.cos() < cut {
            ring.push([r * a.cos(), r * a.sin()]);
        }
    }
    ring.push([cut, -y]);
    ring
}

fn mirrored_x(t: &[Tri]) -> Vec<Tri> {
    // A mirror reverses the facets' turning sense: the copy is inside out, as exporters that
    // mirror a half leave it.
    t.iter().map(|f| f.map(|v| [-v[0], v[1], v[2]])).collect()
}

fn write_stl(dir: &common::TempDir, name: &str, t: &[Tri]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(
        &path,
        dropslice::model::import::stl::write_binary(b"constructed", t),
    )
    .unwrap();
    path
}

#[test]
fn mirrored_open_halves_print_as_their_union() {
    // A cylinder (r = 10 mm, 12 mm tall) made of two "D" halves overlapping by 2 mm; the right
    // one is the left one mirrored, so inside out. Each has a hole: a side facet missing.
    let left = prism(&d_ring(10.0, 1.0), 12.0);
    let right = mirrored_x(&left);
    assert!(volume(&left) > 0.0 && volume(&right) < 0.0);
    let mut model = left.clone();
    model.remove(10); // a side facet of the left half
    let mut holed_right = right.clone();
    holed_right.remove(25); // another side facet of the right half
    model.extend(&holed_right);
    // The reference: the oracle's union of the two halves as meant (both outward, closed).
    let dir = common::TempDir::new("shells-halves");
    let mut meant = left.clone();
    meant.extend(inverted(right.clone()));
    let oracle = common::oracle_sections(&write_stl(&dir, "meant.stl", &meant), 0.2);
    let bytes = dropslice::model::import::stl::write_binary(b"halves", &model);
    let j = Job::new(&bytes, "halves.stl", Settings::default()).unwrap();
    let m = &j.info().mesh;
    assert_eq!((m.flipped_open_shells, m.flipped_shells), (1, 0), "{m:?}");
    assert!(m.open_edges > 0);
    assert_warned(&j, &["1 open shell was inside out", "turned outward"]);
    let layers = oracle["layers"].as_array().unwrap();
    assert_eq!(j.layer_count(), layers.len());
    let mut bad = Vec::new();
    for (i, l) in layers.iter().enumerate() {
        if l.get("near_plane_faces").is_some() {
            continue;
        }
        let want = l["nonzero"]["area"].as_f64().unwrap();
        // Two D's of 2 mm overlap: well over a half circle each.
        assert!(want > 250.0, "layer {i}: oracle {want}");
        let section = j.section(i);
        let got = dropslice::base::geom::region_area(&section.region);
        if (got - want).abs() > (want * 0.005).max(0.05) || section.region.len() != 1 {
            bad.push(format!(
                "layer {i}: {got:.3} in {} pieces vs oracle {want:.3}",
                section.region.len()
            ));
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
fn an_open_inside_out_shell_inside_an_open_shell_stays_a_cavity() {
    // A hollow box: outer walls outward, inner walls facing into the cavity (negative volume),
    // both with a hole. The inner shell is a cavity, not a part turned inside out.
    let mut t = cuboid([0.0; 3], [20.0; 3]);
    t.remove(5);
    let mut cavity = inverted(cuboid([5.0; 3], [15.0; 3]));
    cavity.remove(7);
    t.extend(cavity);
    let j = job(&t).unwrap();
    let m = &j.info().mesh;
    assert_eq!((m.flipped_open_shells, m.flipped_shells), (0, 0), "{m:?}");
    assert_areas(&j, cavity_box_area, "hollow box, open shells");
}

#[test]
fn flipped_facets_and_flat_patches_are_not_turned_as_shells() {
    // A box with one side's two facets flipped: the pair is a flat open shell (no volume),
    // the rest an open shell facing outward. Nothing is turned; the slicer's majority rule
    // keeps the box whole.
    let mut t = cuboid([0.0; 3], [10.0; 3]);
    t[4].swap(1, 2);
    t[5].swap(1, 2);
    let j = job(&t).unwrap();
    let m = &j.info().mesh;
    assert_eq!((m.flipped_open_shells, m.flipped_shells), (0, 0), "{m:?}");
    assert!(m.misoriented_edges > 0);
    assert_areas(&j, |_| 100.0, "box with a flipped side");
}
