//! Real-world damage: copies of closed shared models with facets removed, flipped or
//! duplicated, vertices jittered, or the whole mesh turned inside out still slice into
//! closed sections whose areas stay within 2 % of the undamaged part's.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::Rng;
use dropslice::{Job, Settings};

type Tri = [[f32; 3]; 3];

fn load(model: &str) -> Vec<Tri> {
    let bytes = common::model_bytes(&format!("{model}.stl"));
    dropslice::model::import::stl::parse(&bytes).unwrap().0
}

fn binary(tris: &[Tri]) -> Vec<u8> {
    common::binary_stl(b"damaged copy", tris)
}

fn areas(tris: &[Tri]) -> Vec<f64> {
    let job = Job::new(&binary(tris), "damaged", Settings::default()).unwrap();
    (0..job.layer_count())
        .map(|i| dropslice::base::geom::region_area(&job.section(i).region))
        .collect()
}

/// Every layer's area within 2 % of the undamaged one (0.05 mm² for tiny sections); no
/// layer of the part lost.
fn assert_close(model: &str, what: &str, damaged: &[Tri]) {
    let want = areas(&load(model));
    let got = areas(damaged);
    assert_eq!(got.len(), want.len(), "{model} {what}: layer count");
    let mut bad = Vec::new();
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        if (g - w).abs() > (0.02 * w).max(0.05) {
            bad.push(format!("layer {i}: {g:.3} vs {w:.3}"));
        }
    }
    assert!(
        bad.is_empty(),
        "{model} {what}: {} layers differ:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

const MODELS: [&str; 3] = [
    "extruder_idler",
    "slide_n_snap_test_a_medium",
    "M3x10_screw",
];

/// Each of [`MODELS`], damaged by `damage` (with a generator seeded `seed` + its index),
/// slices as the undamaged model does ([`assert_close`]).
fn assert_heals(seed: u64, what: &str, damage: impl Fn(Vec<Tri>, &mut Rng) -> Vec<Tri>) {
    for (k, model) in MODELS.iter().enumerate() {
        let mut rng = Rng::new(seed + k as u64);
        let t = damage(load(model), &mut rng);
        assert_close(model, what, &t);
    }
}

#[test]
fn flipped_facets() {
    assert_heals(17, "10 % flipped", |mut t, rng| {
        for tri in &mut t {
            if rng.unit() < 0.10 {
                tri.swap(1, 2);
            }
        }
        t
    });
}

#[test]
fn inside_out() {
    for model in MODELS {
        let mut t = load(model);
        for tri in &mut t {
            tri.swap(1, 2);
        }
        assert_close(model, "inside out", &t);
    }
}

#[test]
fn duplicated_facets() {
    assert_heals(99, "20 % duplicated", |mut t, rng| {
        let extra: Vec<Tri> = t.iter().filter(|_| rng.unit() < 0.2).copied().collect();
        t.extend(extra);
        t
    });
}

#[test]
fn jittered_vertices() {
    // Every corner of every facet moved by up to 1e-6 mm on its own: exact welding fails
    // everywhere, the tolerance weld closes the cracks.
    assert_heals(5, "jittered 1e-6", |mut t, rng| {
        for c in t.iter_mut().flatten().flatten() {
            *c += ((rng.unit() - 0.5) * 2e-6) as f32;
        }
        t
    });
}

#[test]
fn removed_facets() {
    assert_heals(31, "1 % removed", |t, rng| {
        t.into_iter().filter(|_| rng.unit() >= 0.01).collect()
    });
}

fn run_cli(model: &std::path::Path, extra: &[&str]) -> (String, String) {
    let out = std::env::temp_dir().join(format!(
        "dropslice-diag-{}-{}.gco",
        std::process::id(),
        model.file_stem().unwrap().to_string_lossy()
    ));
    let r = std::process::Command::new(env!("CARGO_BIN_EXE_dropslice"))
        .arg(model)
        .arg("-o")
        .arg(&out)
        .args(extra)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let gco = std::fs::read_to_string(&out).unwrap();
    let _ = std::fs::remove_file(&out);
    (String::from_utf8_lossy(&r.stderr).into_owned(), gco)
}

#[test]
fn diagnostics_in_summary_header_and_footer() {
    // The open scan: open edges in the header and the CLI; the repaired layers at the end.
    let (err, gco) = run_cli(&common::model("stanford_bunny.stl"), &["-q"]);
    assert!(
        err.contains("warning: the mesh is not closed: 223 open edges"),
        "{err}"
    );
    assert!(
        err.contains("repaired: 50 layers had open sections"),
        "{err}"
    );
    assert!(gco.contains("; warning: the mesh is not closed: 223 open edges"));
    assert!(gco.contains("; repaired: 50 layers had open sections"));
    // Non-manifold edges and several bodies.
    let (err, gco) = run_cli(&common::model("esca_nonmanifold.stl"), &["-q"]);
    assert!(err.contains("16 non-manifold edges"), "{err}");
    assert!(gco.contains("; warning: 6 separate bodies"), "{gco:.2000}");
    // A part in inches: warned, with the fix, and not rescaled.
    let inch: Vec<Tri> = load("cube_20mm_ascii")
        .into_iter()
        .map(|t| t.map(|v| v.map(|c| c / 25.4)))
        .collect();
    let path = std::env::temp_dir().join(format!("dropslice-inch-{}.stl", std::process::id()));
    std::fs::write(&path, binary(&inch)).unwrap();
    let (err, gco) = run_cli(&path, &[]);
    assert!(
        err.contains("scale it by 25.4 (--set scale_x=25.4"),
        "{err}"
    );
    assert!(gco.contains("bounding box = X0.0000..0.7874"), "{gco:.600}");
    let (_, gco) = run_cli(
        &path,
        &[
            "--set",
            "scale_x=25.4",
            "--set",
            "scale_y=25.4",
            "--set",
            "scale_z=25.4",
        ],
    );
    assert!(
        gco.contains("bounding box = X0.0000..20.0000"),
        "{gco:.600}"
    );
    let _ = std::fs::remove_file(&path);
}

/// `Job::new` builds the facet index beside the repeated-facet check and the shells, and the
/// statistics beside the shells' orientation, and makes them again where such a step changed
/// the mesh (facets dropped, cracks closed, a shell turned): on every kind of damage they are
/// those of the final mesh.
#[test]
fn the_index_and_statistics_made_beside_the_repair_are_those_of_the_repaired_mesh() {
    use dropslice::slicing::slice::{FacetBuckets, section_loops};
    let sound = [
        common::cuboid([0.0; 3], [10.0; 3]),
        common::cuboid([20.0, 0.0, 0.0], [26.0, 6.0, 6.0]),
    ]
    .concat();
    let inside_out = |t: &Tri| [t[0], t[2], t[1]];
    // Each case with what the repair must have done: (repeats dropped, vertices merged,
    // shells turned).
    let mut damaged: Vec<(&str, Vec<Tri>, [bool; 3])> = vec![("sound", sound.clone(), [false; 3])];
    let mut repeated = sound.clone();
    repeated.extend_from_slice(&sound[3..7]);
    damaged.push(("repeated facets", repeated, [true, false, false]));
    let mut turned = sound.clone();
    for t in &mut turned[12..] {
        *t = inside_out(t);
    }
    damaged.push(("one shell inside out", turned, [false, false, true]));
    // A crack: one corner of the second box moved by less than the tolerance weld's distance
    // in some of the facets that hold it; and a sliver first whose two close corners that weld
    // merges, so it is dropped and every later facet's number changes.
    let mut cracked = sound.clone();
    let corner = cracked[12][0];
    for t in cracked[12..18].iter_mut() {
        for v in t.iter_mut().filter(|v| **v == corner) {
            v[0] += 2e-5;
        }
    }
    let a = sound[0][0];
    cracked.insert(0, [a, [a[0] + 2e-5, a[1], a[2]], sound[0][1]]);
    damaged.push(("a crack", cracked, [false, true, false]));
    let mut all = sound.clone();
    all.extend_from_slice(&sound[0..2]);
    for t in &mut all[12..24] {
        *t = inside_out(t);
    }
    all[5][1][1] += 3e-5;
    damaged.push(("all at once", all, [true; 3]));
    for (what, tris, repairs) in damaged {
        let job = Job::new(&binary(&tris), "x.stl", Settings::default()).expect(what);
        let m = &job.info().mesh;
        let done = [
            m.duplicate_facets > 0,
            m.tolerance_welded > 0,
            m.flipped_shells > 0,
        ];
        assert_eq!(done, repairs, "{what}: {m:?}");
        let fresh = job.mesh().stats(m.facets_in_file, m.degenerate_facets);
        assert_eq!(
            (m.facets, m.vertices, m.open_edges, m.nonmanifold_edges),
            (
                fresh.facets,
                fresh.vertices,
                fresh.open_edges,
                fresh.nonmanifold_edges
            ),
            "{what}"
        );
        assert_eq!(
            (m.misoriented_edges, m.signed_volume, m.bodies),
            (fresh.misoriented_edges, fresh.signed_volume, fresh.bodies),
            "{what}"
        );
        // Every layer's loops as sliced through a facet index of the final mesh.
        let zs: Vec<f64> = (0..job.layer_count()).map(|i| job.plane_z(i)).collect();
        let index = FacetBuckets::new(job.mesh(), &zs);
        for (i, &z) in zs.iter().enumerate() {
            let fresh = section_loops(job.mesh(), index.layer(i), z).0;
            assert_eq!(job.section_loops(i), fresh, "{what}: layer {i}");
        }
    }
}

/// `n` random triangles in a 100 mm box: each corner anywhere in it (long triangles crossing
/// one another), or, with `size`, within `size` mm of the triangle's first corner.
fn soup(n: usize, size: Option<f64>, seed: u64) -> Vec<Tri> {
    let mut rng = Rng::new(seed);
    let mut tris = Vec::with_capacity(n);
    for _ in 0..n {
        let a: [f32; 3] = std::array::from_fn(|_| (100.0 * rng.unit()) as f32);
        let corner = |rng: &mut Rng| -> [f32; 3] {
            std::array::from_fn(|k| match size {
                Some(s) => (f64::from(a[k]) + s * (rng.unit() - 0.5)).clamp(0.0, 100.0) as f32,
                None => (100.0 * rng.unit()) as f32,
            })
        };
        let (b, c) = (corner(&mut rng), corner(&mut rng));
        tris.push([a, b, c]);
    }
    tris
}

#[test]
fn a_triangle_soup_is_refused_before_it_is_sliced() {
    // 50,000 loose triangles (a 2.5 MB STL): before, the slicer joined their sections across
    // the whole part, minutes and a gigabyte per run; now it names the problem and the fix.
    for (what, size, seed) in [("long, crossing", None, 3), ("small", Some(8.0), 4)] {
        let tris = soup(50_000, size, seed);
        let err = match Job::new(&binary(&tris), "soup.stl", Settings::default()) {
            Ok(_) => panic!("{what} soup: sliced"),
            Err(e) => e,
        };
        assert_eq!(err.kind(), "import", "{what}: {err}");
        let msg = err.to_string();
        for part in [
            "not a closed surface",
            "% of its facets' edges",
            "triangle soup",
            "repair it in a mesh tool",
        ] {
            assert!(msg.contains(part), "{what} soup: {msg}");
        }
    }
    // The CLI: refused with the message, no output file.
    let dir = common::TempDir::new("soup");
    let path = dir.join("soup.stl");
    std::fs::write(&path, binary(&soup(50_000, None, 3))).unwrap();
    let run = common::run_cli(
        &[path.to_str().unwrap(), "-o", "soup.gco"],
        dir.path(),
        std::time::Duration::from_secs(600),
    );
    assert!(
        !run.timed_out && run.code.is_some_and(|c| c != 0),
        "{run:?}"
    );
    assert!(
        run.stderr.contains("not a closed surface") && run.stderr.contains("triangle soup"),
        "{}",
        run.stderr
    );
    assert!(!dir.join("soup.gco").exists());
}

#[test]
fn meshes_with_holes_cracks_or_flipped_facets_are_not_soups() {
    // The damage the repairs handle stays well under the soup's share of open edges: a tenth
    // of the facets removed (holes everywhere) still slices.
    for model in MODELS {
        let mut rng = Rng::new(71);
        let t: Vec<Tri> = load(model)
            .into_iter()
            .filter(|_| rng.unit() >= 0.1)
            .collect();
        let job = Job::new(&binary(&t), "holes.stl", Settings::default());
        assert!(job.is_ok(), "{model}: {:?}", job.err());
    }
}
