//! Build jobs (src/model/spec.rs, layout.rs, display.rs; `Job::from_models`): the job file,
//! the arrangement, the instance transforms against the independent oracle
//! (`../shared/tools/oracle_sections.py`), lay_flat, the display mesh and the CLI.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{Rng, TempDir, bounds, model, model_bytes, on_plate, run_cli};
use dropslice::base::settings::UnitId;
use dropslice::model::display::display_mesh;
use dropslice::model::layout::{Rect, arrange, lay_flat, layout};
use dropslice::model::models::Model;
use dropslice::model::spec::{self as job, JobSpec};
use dropslice::{Error, Job, Settings};
use serde_json::{Value, json};
use std::time::Duration;

type Tri = [[f32; 3]; 3];

/// The 12 triangles of a closed box [0,w]×[0,d]×[0,h], facing outward.
fn box_tris(w: f32, d: f32, h: f32) -> Vec<Tri> {
    let quads = [
        [[0., 0., 0.], [0., d, 0.], [w, d, 0.], [w, 0., 0.]],
        [[0., 0., h], [w, 0., h], [w, d, h], [0., d, h]],
        [[0., 0., 0.], [w, 0., 0.], [w, 0., h], [0., 0., h]],
        [[w, 0., 0.], [w, d, 0.], [w, d, h], [w, 0., h]],
        [[w, d, 0.], [0., d, 0.], [0., d, h], [w, d, h]],
        [[0., d, 0.], [0., 0., 0.], [0., 0., h], [0., d, h]],
    ];
    quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

fn spec(v: Value) -> Result<JobSpec, Error> {
    JobSpec::from_value(v)
}

fn job_message(r: Result<JobSpec, Error>) -> String {
    match r {
        Err(e) => e.to_string(),
        Ok(s) => panic!("accepted: {s:?}"),
    }
}

// ---------------------------------------------------------------------------------------------
// The job file

#[test]
fn job_file_parses_with_defaults() {
    let s = spec(json!({
        "settings": {"layer_height": 0.3},
        "parts": [
            {"file": "a.stl", "rotate_z": 90, "place_x": 30, "place_y": 5, "copies": 2},
            {"file": "b.3mf", "item": 1, "scale_x": 2}
        ]
    }))
    .unwrap();
    assert_eq!(s.settings.layer_height, 0.3);
    assert_eq!(s.parts.len(), 2);
    let a = &s.parts[0];
    assert_eq!(
        (a.rotate_z, a.place(), a.copies, a.unit),
        (90.0, Some([30.0, 5.0]), 2, 0)
    );
    let b = &s.parts[1];
    assert_eq!(b.item, Some(1));
    assert_eq!([b.scale_x, b.scale_y, b.scale_z], [2.0, 1.0, 1.0]);
    assert_eq!(b.place(), None);
    // The job file's text too, and no settings at all.
    let t = JobSpec::from_json(r#"{"parts": [{"file": "x.obj"}]}"#).unwrap();
    assert_eq!(t.settings, Settings::default());
}

#[test]
fn job_file_errors_name_the_part_and_key() {
    let cases: Vec<(Value, &str)> = vec![
        (
            json!({"parts": [{"file": "a.stl", "rotat_z": 3}]}),
            "parts[0]: unknown key 'rotat_z'",
        ),
        (
            json!({"parts": [{"file": "a.stl"}], "extra": 1}),
            "unknown key 'extra'",
        ),
        (
            json!({"parts": [{"file": "a.stl"}, {"file": "b.stl", "scale_x": 0}]}),
            "parts[1].scale_x: 0 is out of range",
        ),
        (
            json!({"parts": [{"file": "a.stl", "scale_y": -2}]}),
            "parts[0].scale_y",
        ),
        (
            json!({"parts": [{"file": "a.stl", "rotate_x": 400}]}),
            "parts[0].rotate_x",
        ),
        (
            json!({"parts": [{"file": "a.stl", "rotate_x": "NaN"}]}),
            "parts[0].rotate_x: must be a finite number",
        ),
        (
            json!({"parts": [{"file": "a.stl", "rotate_y": null}]}),
            "parts[0].rotate_y",
        ),
        (
            json!({"parts": [{"file": "a.stl", "place_x": 3}]}),
            "parts[0].place_y: is missing",
        ),
        (
            json!({"parts": [{"file": "a.stl", "place_y": 3}]}),
            "parts[0].place_x: is missing",
        ),
        (
            json!({"parts": [{"file": "a.stl", "place_x": 1e6, "place_y": 0}]}),
            "parts[0].place_x",
        ),
        (
            json!({"parts": [{"file": "a.stl", "copies": 101}]}),
            "parts[0].copies: 101 is out of range",
        ),
        (
            json!({"parts": [{"file": "a.stl", "copies": 0}]}),
            "parts[0].copies: 0",
        ),
        (
            json!({"parts": [{"file": "a.stl", "copies": 1.5}]}),
            "parts[0].copies: must be a whole number",
        ),
        (
            json!({"parts": [{"file": "a.stl", "unit": 4}]}),
            "parts[0].unit: 4 is not a discharge unit",
        ),
        (
            json!({"parts": [{"file": "a.stl", "unit": 2}]}),
            "parts[0].unit: names discharge unit 2, but the machine has 2 (units = 2",
        ),
        (
            json!({"parts": [{"file": "a.stl", "item": -1}]}),
            "parts[0].item",
        ),
        (
            json!({"parts": [{"rotate_x": 1}]}),
            "parts[0].file: is missing",
        ),
        (json!({"parts": [{"file": ""}]}), "parts[0].file: is empty"),
        (json!({"parts": []}), "no parts"),
        (
            json!({"parts": {"file": "a.stl"}}),
            "\"parts\" must be a list",
        ),
        (json!([1, 2]), "a job must be an object"),
        (
            json!({"settings": {"rotate_z": 90}, "parts": [{"file": "a.stl"}]}),
            "settings.rotate_z belongs to a part",
        ),
        (
            json!({"settings": {"place_x": 1}, "parts": [{"file": "a.stl"}]}),
            "settings.place_x belongs to a part",
        ),
    ];
    for (v, want) in cases {
        let m = job_message(spec(v.clone()));
        assert!(m.contains(want), "{v}: '{m}' does not say '{want}'");
    }
    // A bad setting is the settings' own error (kind "setting", naming it).
    let e =
        spec(json!({"settings": {"layer_height": -1}, "parts": [{"file": "a.stl"}]})).unwrap_err();
    assert_eq!(e.kind(), "setting");
    assert_eq!(e.report().setting.as_deref(), Some("layer_height"));
    // Too many parts, too many instances.
    let many: Vec<Value> = (0..257).map(|_| json!({"file": "a.stl"})).collect();
    assert!(job_message(spec(json!({"parts": many}))).contains("at most 256"));
    let copies: Vec<Value> = (0..6)
        .map(|_| json!({"file": "a.stl", "copies": 100}))
        .collect();
    assert!(job_message(spec(json!({"parts": copies}))).contains("at most 500"));
    // Not JSON, too large.
    assert!(job_message(JobSpec::from_json("{parts")).contains("not valid JSON"));
    let big = format!(
        "{{\"parts\": [{{\"file\": \"{}\"}}]}}",
        "a".repeat(job::MAX_JOB_FILE_BYTES)
    );
    assert!(job_message(JobSpec::from_json(&big)).contains("at most"));
    // Every error of the job file is of kind "job".
    assert_eq!(spec(json!({"parts": []})).unwrap_err().kind(), "job");
}

// ---------------------------------------------------------------------------------------------
// Arrangement

#[test]
fn arranged_boxes_never_overlap_and_stay_on_the_plate() {
    let mut rng = Rng::new(12);
    for round in 0..200 {
        let plate = [50.0 + 200.0 * rng.unit(), 50.0 + 200.0 * rng.unit()];
        let gap = [0.0, 1.0, 5.0, 2.5 * rng.unit()][rng.pick(4)];
        let fixed: Vec<Rect> = (0..rng.pick(4))
            .map(|_| {
                let (x, y) = (plate[0] * rng.unit(), plate[1] * rng.unit());
                Rect {
                    min: [x, y],
                    max: [x + 1.0 + 30.0 * rng.unit(), y + 1.0 + 30.0 * rng.unit()],
                }
            })
            .collect();
        let sizes: Vec<[f64; 2]> = (0..1 + rng.pick(40))
            .map(|_| [0.5 + 40.0 * rng.unit(), 0.5 + 40.0 * rng.unit()])
            .collect();
        let slots = arrange(&fixed, &sizes, plate, gap);
        assert_eq!(slots.len(), sizes.len());
        let placed: Vec<Rect> = slots
            .iter()
            .zip(&sizes)
            .filter_map(|(s, z)| {
                s.map(|s| Rect {
                    min: s,
                    max: [s[0] + z[0], s[1] + z[1]],
                })
            })
            .collect();
        // Never two closer than the gap (checked here with its own arithmetic).
        let close = |a: &Rect, b: &Rect| {
            let e = 1e-6;
            a.min[0] < b.max[0] + gap - e
                && b.min[0] < a.max[0] + gap - e
                && a.min[1] < b.max[1] + gap - e
                && b.min[1] < a.max[1] + gap - e
        };
        for (i, a) in placed.iter().enumerate() {
            assert!(
                a.min[0] >= -1e-9 && a.min[1] >= -1e-9,
                "round {round}: {a:?} off the plate"
            );
            assert!(
                a.max[0] <= plate[0] + 1e-6 && a.max[1] <= plate[1] + 1e-6,
                "round {round}: {a:?} beyond the plate {plate:?}"
            );
            for b in &placed[i + 1..] {
                assert!(
                    !close(a, b),
                    "round {round}: {a:?} and {b:?} closer than {gap}"
                );
            }
            for f in &fixed {
                assert!(
                    !close(a, f),
                    "round {round}: {a:?} too close to the fixed {f:?}"
                );
            }
        }
        // A box that was left out really has no room at the origin corner of an empty plate,
        // or the plate is crowded: at least it cannot go where nothing is (the origin) when
        // nothing is there.
        if fixed.is_empty() && !sizes.is_empty() {
            let largest = sizes
                .iter()
                .enumerate()
                .max_by(|a, b| (a.1[0] * a.1[1]).total_cmp(&(b.1[0] * b.1[1])))
                .unwrap();
            if largest.1[0] <= plate[0] && largest.1[1] <= plate[1] {
                assert_eq!(
                    slots[largest.0],
                    Some([0.0, 0.0]),
                    "round {round}: the largest box starts at the origin"
                );
            }
        }
    }
}

#[test]
fn arrangement_fills_rows_bottom_left() {
    // Four 10×10 boxes with gap 5 on a 40 mm wide plate: three in the first row (the third
    // ends exactly at the plate's edge), one above.
    let slots = arrange(&[], &[[10.0, 10.0]; 4], [40.0, 100.0], 5.0);
    let got: Vec<[f64; 2]> = slots.into_iter().map(Option::unwrap).collect();
    assert_eq!(got, vec![[0.0, 0.0], [15.0, 0.0], [30.0, 0.0], [0.0, 15.0]]);
    // Largest first: the big box takes the origin, the small ones go beside it.
    let slots = arrange(
        &[],
        &[[5.0, 5.0], [20.0, 20.0], [5.0, 5.0]],
        [40.0, 100.0],
        1.0,
    );
    assert_eq!(
        slots,
        vec![Some([21.0, 0.0]), Some([0.0, 0.0]), Some([27.0, 0.0])]
    );
}

fn box_model(name: &str, w: f32, d: f32, h: f32) -> Model {
    Model::read(&common::stl_bytes(&box_tris(w, d, h)), name).unwrap()
}

#[test]
fn a_job_that_does_not_fit_is_refused_with_what_to_do() {
    let models = [box_model("big.stl", 60.0, 60.0, 5.0)];
    let s = spec(json!({"parts": [{"file": "big.stl", "copies": 5}]})).unwrap();
    let e = layout(&models, &s).unwrap_err();
    let m = e.to_string();
    assert_eq!(e.kind(), "job");
    for want in [
        "parts[0] (big",
        "plate_x",
        "fewer copies",
        "part_spacing",
        "154 × 134",
    ] {
        assert!(m.contains(want), "'{m}' lacks '{want}'");
    }
    // 4 fit (2 × 2 with 5 mm between 60 mm boxes: 125 ≤ 154, 125 ≤ 134).
    let s = spec(json!({"parts": [{"file": "big.stl", "copies": 4}]})).unwrap();
    assert_eq!(layout(&models, &s).unwrap().instances.len(), 4);
    // The same through Job::from_models.
    let s = spec(json!({"parts": [{"file": "big.stl", "copies": 5}]})).unwrap();
    assert_eq!(Job::from_models(&models, &s).err().unwrap().kind(), "job");
}

#[test]
fn one_oversize_part_goes_to_the_origin_and_is_refused_with_what_fits() {
    let models = [box_model("huge.stl", 200.0, 20.0, 3.0)];
    let s = spec(json!({"parts": [{"file": "huge.stl"}]})).unwrap();
    let l = layout(&models, &s).unwrap();
    assert_eq!(l.instances[0].min, [0.0, 0.0, 0.0]);
    // The page's words: no "placed at the origin", no "Arrange" (it cannot help).
    assert_eq!(l.misfits.len(), 1, "{:?}", l.misfits);
    let m = &l.misfits[0];
    assert_eq!(
        m.message,
        "Part 1 “huge.stl” (200 × 20 mm) is larger than the plate (154 × 134 mm); scaled to 77 % it fits."
    );
    assert_eq!((m.scale_percent, m.turn_rotate_z), (Some(77), None));
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    // The library refuses the job with the same words and the part keys to change.
    let e = Job::from_models(&models, &s).err().unwrap();
    assert_eq!(e.kind(), "job");
    let text = e.to_string();
    assert!(text.contains(&m.message), "{text}");
    assert!(
        text.contains(
            "Use parts[0].scale_x = 0.77, parts[0].scale_y = 0.77, parts[0].scale_z = 0.77"
        ),
        "{text}"
    );
    // The scale it offers fits.
    let s77 = spec(
        json!({"parts": [{"file": "huge.stl", "scale_x": 0.77, "scale_y": 0.77, "scale_z": 0.77}]}),
    )
    .unwrap();
    assert!(layout(&models, &s77).unwrap().misfits.is_empty());
    assert!(Job::from_models(&models, &s77).is_ok());
    // allow_off_plate slices it as it is, the sentence as a warning.
    let allow =
        spec(json!({"settings": {"allow_off_plate": true}, "parts": [{"file": "huge.stl"}]}))
            .unwrap();
    let j = Job::from_models(&models, &allow).unwrap();
    assert_eq!(j.info().bounds.min, [0.0, 0.0, 0.0]);
    assert!(
        j.info().warnings.contains(&m.message),
        "{:?}",
        j.info().warnings
    );
    // Two copies of it: both at the origin, named once; refused.
    let s = spec(json!({"parts": [{"file": "huge.stl", "copies": 2}]})).unwrap();
    let l = layout(&models, &s).unwrap();
    assert_eq!(l.misfits.len(), 1);
    assert!(Job::from_models(&models, &s).is_err());
    // Turned 90° about z, 20 × 200 on a 30 × 250 plate: the turn is offered, and fits.
    let s = spec(json!({"settings": {"plate_x": 250, "plate_y": 30}, "parts": [{"file": "huge.stl", "rotate_z": 90}]})).unwrap();
    let m = &layout(&models, &s).unwrap().misfits[0];
    assert_eq!(m.turn_rotate_z, Some(180.0));
    assert!(
        m.message.ends_with("turned 90° about z it fits."),
        "{}",
        m.message
    );
    let s = spec(json!({"settings": {"plate_x": 250, "plate_y": 30}, "parts": [{"file": "huge.stl", "rotate_z": 180}]})).unwrap();
    assert!(layout(&models, &s).unwrap().misfits.is_empty());
}

#[test]
fn a_part_larger_than_the_plate_among_others_does_not_stop_their_arrangement() {
    let models = [
        box_model("huge.stl", 200.0, 20.0, 3.0),
        box_model("small.stl", 10.0, 10.0, 3.0),
    ];
    let s = spec(json!({"parts": [{"file": "small.stl"}, {"file": "huge.stl"}]})).unwrap();
    let l = layout(&models, &s).unwrap();
    assert_eq!(l.misfits.len(), 1);
    assert_eq!(l.misfits[0].id.part, 1);
    assert!(
        l.misfits[0].message.starts_with("Part 2 “huge.stl”"),
        "{}",
        l.misfits[0].message
    );
    assert!(l.instances[0].max[0] <= 154.0 && l.instances[0].max[1] <= 134.0);
}

#[test]
fn placed_and_arranged_parts_mix() {
    let models = [
        box_model("a.stl", 30.0, 20.0, 5.0),
        box_model("b.stl", 10.0, 10.0, 8.0),
    ];
    let s = spec(json!({
        "settings": {"plate_x": 100, "plate_y": 100, "part_spacing": 4},
        "parts": [
            {"file": "a.stl", "place_x": 0, "place_y": 0, "copies": 2},
            {"file": "b.stl", "copies": 3},
            {"file": "b.stl", "place_x": 95, "place_y": 95}
        ]
    }))
    .unwrap();
    let l = layout(&models, &s).unwrap();
    assert_eq!(l.instances.len(), 6);
    let a0 = &l.instances[0];
    assert!(a0.placed && a0.min == [0.0, 0.0, 0.0] && a0.max == [30.0, 20.0, 5.0]);
    // The second copy of the placed part is arranged.
    assert!(!l.instances[1].placed);
    // The last one reaches outside the 100 mm plate: placed as asked, a misfit (the job is
    // refused unless allow_off_plate).
    let last = &l.instances[5];
    assert_eq!(
        (last.min, last.max),
        ([95.0, 95.0, 0.0], [105.0, 105.0, 8.0])
    );
    assert_eq!(l.misfits.len(), 1, "{:?}", l.misfits);
    assert_eq!(
        l.misfits[0].message,
        "Part 3 “b.stl” reaches 5 mm past the plate's right edge — move it or press Arrange."
    );
    let e = Job::from_models(&models, &s).err().unwrap().to_string();
    assert!(
        e.contains("Change parts[2].place_x/place_y, or leave them out to have it arranged"),
        "{e}"
    );
    // No two instances closer than the spacing, except placed ones among themselves.
    for (i, a) in l.instances.iter().enumerate() {
        for b in &l.instances[i + 1..] {
            if a.placed && b.placed {
                continue;
            }
            let apart = (0..2)
                .any(|k| a.min[k] >= b.max[k] + 4.0 - 1e-9 || b.min[k] >= a.max[k] + 4.0 - 1e-9);
            assert!(
                apart,
                "{:?} and {:?} closer than 4 mm",
                (a.min, a.max),
                (b.min, b.max)
            );
        }
    }
    // Every matrix maps the part's box corners onto the instance's bounds.
    for inst in &l.instances {
        let size = if inst.id.part == 0 {
            [30.0, 20.0, 5.0]
        } else {
            [10.0, 10.0, 8.0]
        };
        let m = inst.matrix;
        let apply = |p: [f64; 3]| {
            [0, 1, 2].map(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r])
        };
        let lo = apply([0.0, 0.0, 0.0]);
        let hi = apply(size);
        for k in 0..3 {
            assert!(
                (lo[k] - inst.min[k]).abs() < 1e-9 && (hi[k] - inst.max[k]).abs() < 1e-9,
                "{inst:?}"
            );
        }
    }
    // The job's mesh is exactly the instances' union of boxes (allowed off the plate).
    let mut s = s;
    s.settings.allow_off_plate = true;
    assert_eq!(layout(&models, &s).unwrap(), l);
    let j = Job::from_models(&models, &s).unwrap();
    assert_eq!(j.info().instances, l.instances);
    assert_eq!(j.mesh().facets.len(), 6 * 12);
    assert_eq!(j.info().bounds, l.bounds);
}

#[test]
fn unit_1_parts_are_printed_and_files_must_be_known() {
    let models = [box_model("a.stl", 10.0, 10.0, 5.0)];
    let s = spec(json!({"parts": [{"file": "a.stl", "unit": 1}]})).unwrap();
    let j = Job::from_models(&models, &s).unwrap();
    assert!(j.uses_other_units() && j.part_units() == [UnitId(1)]);
    // All of the box is unit 1's: every droplet of a layer is printed by unit 1.
    let p = j.plan_layer(3);
    assert!(p.counts.total() > 0 && p.counts.unit(UnitId(1)) == p.counts.total());
    assert!(p.moves.iter().all(|m| m.unit == 1));
    let s = spec(json!({"parts": [{"file": "b.stl"}]})).unwrap();
    let e = Job::from_models(&models, &s).err().unwrap();
    assert!(
        e.to_string()
            .contains("parts[0].file: 'b.stl' is not among"),
        "{e}"
    );
    let s = spec(json!({"parts": [{"file": "a.stl", "item": 1}]})).unwrap();
    let e = layout(&models, &s).unwrap_err();
    assert!(
        e.to_string().contains("parts[0]: a.stl has 1 build item"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------------
// The instances' geometry against the oracle, with the transform computed here

/// Rotation about x, then y, then z (degrees), scale, as docs/spec.md 5.3.1 says — written here.
fn transform_point(p: [f64; 3], rot: [f64; 3], scale: [f64; 3]) -> [f64; 3] {
    let [mut x, mut y, mut z] = p;
    let (s, c) = rot[0].to_radians().sin_cos();
    (y, z) = (c * y - s * z, s * y + c * z);
    let (s, c) = rot[1].to_radians().sin_cos();
    (x, z) = (c * x + s * z, -s * x + c * z);
    let (s, c) = rot[2].to_radians().sin_cos();
    (x, y) = (c * x - s * y, s * x + c * y);
    [x * scale[0], y * scale[1], z * scale[2]]
}

/// The part rotated and scaled, its box minimum moved to (at, 0).
fn placed(tris: &[Tri], rot: [f64; 3], scale: [f64; 3], at: [f64; 2]) -> Vec<[[f64; 3]; 3]> {
    let t = tris
        .iter()
        .map(|t| t.map(|p| transform_point(p.map(f64::from), rot, scale)))
        .collect();
    on_plate(t, at)
}

fn all_triangles(file: &str) -> Vec<Tri> {
    let bytes = model_bytes(file);
    dropslice::model::import::read_parts(&bytes, file)
        .unwrap()
        .into_iter()
        .flat_map(|p| p.triangles)
        .collect()
}

#[test]
fn a_job_of_three_parts_slices_as_the_oracle_says() {
    let job_json = json!({
        "parts": [
            {"file": "3DBenchy.stl", "rotate_x": 90, "place_x": 5, "place_y": 5},
            {"file": "extruder_idler_quads.obj", "scale_x": 1.5, "scale_y": 1.5, "scale_z": 0.8,
             "rotate_z": 30, "place_x": 75, "place_y": 5},
            {"file": "torus.3mf"}
        ]
    });
    let s = spec(job_json).unwrap();
    let files = ["3DBenchy.stl", "extruder_idler_quads.obj", "torus.3mf"];
    let bytes: Vec<Vec<u8>> = files.iter().map(|f| model_bytes(f)).collect();
    let inputs: Vec<(&str, &[u8])> = files
        .iter()
        .zip(&bytes)
        .map(|(f, b)| (*f, &b[..]))
        .collect();
    let j = Job::from_parts(&inputs, &s).unwrap();
    let inst = &j.info().instances;
    assert_eq!(inst.len(), 3);
    // The test's own transform of every part; the arranged torus is put where the job put it
    // (the arrangement is checked above; areas do not depend on it as long as parts are apart).
    let mut mesh: Vec<[[f64; 3]; 3]> = Vec::new();
    let parts = [
        (
            all_triangles(files[0]),
            [90.0, 0.0, 0.0],
            [1.0; 3],
            [5.0, 5.0],
        ),
        (
            all_triangles(files[1]),
            [0.0, 0.0, 30.0],
            [1.5, 1.5, 0.8],
            [75.0, 5.0],
        ),
        (
            all_triangles(files[2]),
            [0.0; 3],
            [1.0; 3],
            [inst[2].min[0], inst[2].min[1]],
        ),
    ];
    for (k, (tris, rot, scale, at)) in parts.iter().enumerate() {
        let p = placed(tris, *rot, *scale, *at);
        let (lo, hi) = bounds(&p);
        for c in 0..3 {
            assert!(
                (lo[c] - inst[k].min[c]).abs() < 1e-4,
                "part {k} min {lo:?} vs {:?}",
                inst[k].min
            );
            assert!(
                (hi[c] - inst[k].max[c]).abs() < 1e-4,
                "part {k} max {hi:?} vs {:?}",
                inst[k].max
            );
        }
        mesh.extend(p);
    }
    // The torus lies apart from the others.
    assert!(
        inst[2].min[0] >= inst[1].max[0] + 5.0 - 1e-9
            || inst[2].min[1] >= inst[1].max[1] + 5.0 - 1e-9
    );
    let dir = TempDir::new("job-oracle");
    let stl = dir.join("job.stl");
    let tris: Vec<Tri> = mesh
        .iter()
        .map(|t| t.map(|p| p.map(|c| c as f32)))
        .collect();
    std::fs::write(&stl, common::stl_bytes(&tris)).unwrap();
    let oracle = common::oracle_sections(&stl, 0.2);
    let (compared, bad) =
        common::oracle_area_mismatches(&j, &oracle, |want| (want * 0.005).max(0.05));
    assert!(compared > 100, "{compared} layers compared");
    assert!(
        bad.is_empty(),
        "{} of {compared} layers differ:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// One part: Job::from_parts slices as Job::new

#[test]
fn one_part_job_gives_the_moves_of_job_new() {
    for (file, sets) in [
        (
            "3DBenchy.stl",
            vec![("rotate_z", 90.0), ("place_x", 12.5), ("place_y", 3.0)],
        ),
        (
            "cube_gears.3mf",
            vec![
                ("scale_x", 0.5),
                ("scale_y", 0.5),
                ("place_angle", 17.0),
                ("place_x", 80.0),
                ("place_y", 60.0),
            ],
        ),
        (
            "extruder_idler_quads.obj",
            vec![("rotate_x", 33.0), ("rotate_y", -20.0)],
        ),
    ] {
        let bytes = model_bytes(file);
        // Off the plate on purpose (the plate rule is not what this compares).
        let mut settings = Settings {
            allow_off_plate: true,
            ..Settings::default()
        };
        let mut part = json!({"file": file});
        for (k, v) in &sets {
            settings.set(k, &v.to_string()).unwrap();
            part[k] = json!(v);
        }
        if part.get("place_x").is_none() {
            // Job::new places at (0, 0): the arrangement's origin slot.
            part["place_x"] = json!(0);
            part["place_y"] = json!(0);
        }
        let a = Job::new(&bytes, file, settings.clone()).unwrap();
        let s = spec(json!({"settings": {"allow_off_plate": true}, "parts": [part]})).unwrap();
        let b = Job::from_parts(&[(file, &bytes[..])], &s).unwrap();
        assert_eq!(a.mesh().vertices, b.mesh().vertices, "{file}: vertices");
        assert_eq!(a.mesh().facets, b.mesh().facets, "{file}: facets");
        assert_eq!(a.layer_count(), b.layer_count());
        for i in (0..a.layer_count()).step_by(7) {
            assert_eq!(
                a.plan_layer(i).moves,
                b.plan_layer(i).moves,
                "{file}: layer {i}"
            );
        }
        assert_eq!(
            a.info().instances[0].matrix,
            b.info().instances[0].matrix,
            "{file}"
        );
    }
    // An arranged single part without rotation on the plate lands where Job::new puts it.
    let bytes = model_bytes("3DBenchy.stl");
    let a = Job::new(&bytes, "3DBenchy.stl", Settings::default()).unwrap();
    let s = spec(json!({"parts": [{"file": "3DBenchy.stl"}]})).unwrap();
    let b = Job::from_parts(&[("3DBenchy.stl", &bytes[..])], &s).unwrap();
    assert_eq!(a.mesh().vertices, b.mesh().vertices);
}

#[test]
fn matrices_map_the_model_onto_the_sliced_mesh() {
    let bytes = model_bytes("cube_gears.3mf");
    let m = Model::read(&bytes, "cube_gears.3mf").unwrap();
    assert!(m.parts.len() > 1);
    let s = spec(json!({
        "settings": {"plate_x": 400, "plate_y": 400, "allow_off_plate": true},
        "parts": [
            {"file": "cube_gears.3mf", "item": 1, "rotate_x": 20, "rotate_y": 45, "rotate_z": 10,
             "scale_z": 1.3, "place_angle": 33, "copies": 2},
            {"file": "cube_gears.3mf", "place_x": 200, "place_y": 10, "place_angle": -70}
        ]
    }))
    .unwrap();
    let j = Job::from_models(std::slice::from_ref(&m), &s).unwrap();
    // Each instance's corners, mapped by its matrix, are vertices of the sliced mesh.
    let verts = &j.mesh().vertices;
    let mut offset = 0;
    for inst in &j.info().instances {
        let tris = m.triangles(inst.item).unwrap();
        let mx = inst.matrix;
        let (welded, _) = dropslice::model::mesh::Mesh::weld(&tris);
        for (k, v) in welded.vertices.iter().enumerate() {
            let p =
                [0, 1, 2].map(|r| mx[r] * v[0] + mx[4 + r] * v[1] + mx[8 + r] * v[2] + mx[12 + r]);
            let q = verts[offset + k];
            assert!((0..3).all(|c| (p[c] - q[c]).abs() < 1e-9), "{p:?} vs {q:?}");
        }
        offset += welded.vertices.len();
    }
    assert_eq!(offset, verts.len());
}

#[test]
fn cli_job_files_mirror_parts_and_the_header_says_so() {
    let dir = TempDir::new("job-cli-mirror");
    std::fs::copy(model("U_overhang.obj"), dir.join("u.obj")).unwrap();
    let job = json!({"parts": [{"file": "u.obj", "mirror_x": true, "mirror_z": true}]});
    std::fs::write(dir.join("job.json"), job.to_string()).unwrap();
    let r = run_words("job.json -o m.gco", &dir);
    assert_eq!(r.code, Some(0), "{r:?}");
    let text = std::fs::read_to_string(dir.join("m.gco")).unwrap();
    assert!(
        text.contains("scale 1/1/1, mirror x/z, at X"),
        "{:.1500}",
        text
    );
    assert!(!r.stderr.contains("inside out"), "{}", r.stderr);
    // a mirror that is not true or false: refused, naming the part and the key
    let bad = json!({"parts": [{"file": "u.obj", "mirror_y": "yes"}]});
    std::fs::write(dir.join("bad.json"), bad.to_string()).unwrap();
    let r = run_words("bad.json -o b.gco", &dir);
    assert_eq!(r.code, Some(2), "{r:?}");
    assert!(
        r.stderr.contains("parts[0].mirror_y") && r.stderr.contains("true"),
        "{}",
        r.stderr
    );
}

#[test]
fn orient_measures_a_mirrored_part_as_its_mirror_image() {
    // Mirrored along x or y, a part overhangs as much as before (a negative scale mirrors no
    // area); mirrored along z, its current orientation is the plain part's upside down.
    let bytes = model_bytes("U_overhang.obj");
    let m = Model::read(&bytes, "U_overhang.obj").unwrap();
    let s = Settings::default();
    let part = |v: Value| serde_json::from_value::<job::PartSpec>(v).unwrap();
    let orient = |p: &job::PartSpec| dropslice::support::orient::orient_part(&m, p, &s).unwrap();
    let plain = orient(&part(json!({"file": "U_overhang.obj"})));
    let flipped = orient(&part(json!({"file": "U_overhang.obj", "rotate_x": 180})));
    assert!(plain.current.unsupported_area > 1.0 || flipped.current.unsupported_area > 1.0);
    for mirror in ["mirror_x", "mirror_y"] {
        let o = orient(&part(json!({"file": "U_overhang.obj", mirror: true})));
        assert!(
            (o.current.unsupported_area - plain.current.unsupported_area).abs() < 1e-6,
            "{mirror}: {} vs {}",
            o.current.unsupported_area,
            plain.current.unsupported_area
        );
    }
    let z = orient(&part(json!({"file": "U_overhang.obj", "mirror_z": true})));
    assert!(
        (z.current.unsupported_area - flipped.current.unsupported_area).abs() < 1e-6,
        "{} vs {}",
        z.current.unsupported_area,
        flipped.current.unsupported_area
    );
    assert!((z.current.height - plain.current.height).abs() < 1e-9);
}

#[test]
fn an_instance_gives_its_size_along_the_axes_its_scale_acts_on() {
    // The page's size fields: scale_x × wanted / size_x is a part that wide, whatever the
    // rotation on the plate.
    let models = [box_model("b.stl", 10.0, 30.0, 5.0)];
    let s = spec(
        json!({"parts": [{"file": "b.stl", "scale_x": 2, "mirror_y": true,
        "place_angle": 90, "place_x": 10, "place_y": 10}]}),
    )
    .unwrap();
    let l = layout(&models, &s).unwrap();
    let i = &l.instances[0];
    for (got, want) in i.size.iter().zip([20.0, 30.0, 5.0]) {
        assert!((got - want).abs() < 1e-9, "{:?}", i.size);
    }
    // on the plate, turned by 90°: 30 × 20
    assert!((i.max[0] - i.min[0] - 30.0).abs() < 1e-9 && (i.max[1] - i.min[1] - 20.0).abs() < 1e-9);
}

/// Six times the signed volume of a mesh (positive when its facets face out).
fn volume6(m: &dropslice::model::mesh::Mesh) -> f64 {
    m.facets
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| glam::DVec3::from(m.vertices[v as usize]));
            a.dot(b.cross(c))
        })
        .sum()
}

#[test]
fn a_mirrored_part_slices_to_mirrored_sections_facing_out() {
    let bytes = model_bytes("3DBenchy.stl");
    let m = Model::read(&bytes, "3DBenchy.stl").unwrap();
    let job_of = |part: Value| {
        let s = spec(json!({"settings": {"layer_height": 0.4}, "parts": [part]})).unwrap();
        Job::from_models(std::slice::from_ref(&m), &s).unwrap()
    };
    let plain = job_of(json!({"file": "3DBenchy.stl"}));
    let mx = job_of(json!({"file": "3DBenchy.stl", "mirror_x": true}));
    let mxz =
        job_of(json!({"file": "3DBenchy.stl", "mirror_x": true, "mirror_z": true, "copies": 2}));
    let (a, b) = (plain.mesh().bounds(), mx.mesh().bounds());
    for k in 0..3 {
        assert!((a.min[k] - b.min[k]).abs() < 1e-9 && (a.max[k] - b.max[k]).abs() < 1e-9);
    }
    // Facing out: no shell turned, the same volume, positive.
    let v = volume6(plain.mesh());
    assert!(v > 0.0);
    for j in [&mx, &mxz] {
        assert!(
            !j.info().warnings.iter().any(|w| w.contains("inside out")),
            "{:?}",
            j.info().warnings
        );
    }
    assert!((volume6(mx.mesh()) - v).abs() < 1e-6 * v);
    assert!((volume6(mxz.mesh()) - 2.0 * v).abs() < 1e-6 * v);
    // The matrix of a mirrored instance mirrors (negative determinant) and maps the model
    // onto the sliced mesh's box.
    let inst = &mx.info().instances[0];
    let c = inst.matrix;
    let det = c[0] * (c[5] * c[10] - c[9] * c[6]) - c[4] * (c[1] * c[10] - c[9] * c[2])
        + c[8] * (c[1] * c[6] - c[5] * c[2]);
    assert!(det < 0.0, "{det}");
    // Each layer: the same area, its corners those of the plain part mirrored about the
    // box's middle in x.
    let mid2 = a.min[0] + a.max[0];
    assert_eq!(plain.layer_count(), mx.layer_count());
    for i in (0..plain.layer_count()).step_by(7) {
        let (p, q) = (plain.section(i).region, mx.section(i).region);
        let area = |r: &[dropslice::base::geom::Shape]| r.iter().map(|s| s.area()).sum::<f64>();
        assert!(area(&p) > 0.0);
        assert!(
            (area(&p) - area(&q)).abs() < 1e-4 * area(&p),
            "layer {i}: {} {}",
            area(&p),
            area(&q)
        );
        // (the sections are simplified within a small tolerance, so a corner of one lies on
        // an edge of the other, not always on a corner)
        let edges = |r: &[dropslice::base::geom::Shape]| -> Vec<[glam::DVec2; 2]> {
            dropslice::base::geom::all_contours(&r.to_vec())
                .flat_map(|c| (0..c.len()).map(move |k| [c[k], c[(k + 1) % c.len()]]))
                .collect()
        };
        let pe = edges(&p);
        for [v, _] in edges(&q) {
            let w = glam::DVec2::new(mid2 - v.x, v.y);
            let near = pe
                .iter()
                .map(|[a, b]| {
                    let t = ((w - *a).dot(*b - *a) / (*b - *a).length_squared().max(1e-30))
                        .clamp(0.0, 1.0);
                    (*a + (*b - *a) * t).distance(w)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                near < 0.01,
                "layer {i}: {v:?} mirrored is {near} mm from the plain section"
            );
        }
    }
    // The job file writes it only when set, and reads it back.
    let s =
        spec(json!({"parts": [{"file": "a.stl", "mirror_y": true}, {"file": "b.stl"}]})).unwrap();
    let out = serde_json::to_value(&s.parts).unwrap();
    assert_eq!(out[0]["mirror_y"], json!(true));
    assert!(out[0].get("mirror_x").is_none() && out[1].get("mirror_y").is_none());
    assert!(
        job_message(spec(json!({"parts": [{"file": "a.stl", "mirror_x": 1}]})))
            .contains("parts[0]")
    );
}

// ---------------------------------------------------------------------------------------------
// lay_flat and the display mesh

fn rotated(tris: &[Tri], rot: [f64; 3]) -> Vec<Tri> {
    tris.iter()
        .map(|t| t.map(|p| transform_point(p.map(f64::from), rot, [1.0; 3]).map(|c| c as f32)))
        .collect()
}

fn height_after(tris: &[Tri], rx: f64, ry: f64) -> f64 {
    let r = rotated(tris, [rx, ry, 0.0]);
    let zs = r.iter().flatten().map(|p| p[2] as f64);
    let lo = zs.clone().fold(f64::INFINITY, f64::min);
    let hi = zs.fold(f64::NEG_INFINITY, f64::max);
    hi - lo
}

#[test]
fn lay_flat_puts_the_largest_face_down() {
    // A 40 × 25 × 4 plate, tilted by known angles: laid flat it is 4 mm tall again, with its
    // largest face at the bottom.
    let plate = box_tris(40.0, 25.0, 4.0);
    for rot in [
        [30.0, 0.0, 0.0],
        [0.0, 90.0, 0.0],
        [35.0, -50.0, 20.0],
        [180.0, 10.0, 0.0],
        [-75.0, 12.0, 140.0],
    ] {
        let tilted = rotated(&plate, rot);
        let (rx, ry) = lay_flat(&tilted);
        let h = height_after(&tilted, rx, ry);
        assert!(
            (h - 4.0).abs() < 1e-3,
            "{rot:?}: laid flat by {rx}/{ry} it is {h} mm tall"
        );
    }
    // A real model: Benchy rests on its hull's flat bottom already.
    let benchy = all_triangles("3DBenchy.stl");
    let (rx, ry) = lay_flat(&benchy);
    assert!(
        (height_after(&benchy, rx, ry) - 48.0).abs() < 0.01,
        "{rx} {ry}"
    );
    // Tipped on its side, it comes back onto a flat face no taller than it was.
    let side = rotated(&benchy, [90.0, 0.0, 0.0]);
    let (rx, ry) = lay_flat(&side);
    let h = height_after(&side, rx, ry);
    assert!(h <= 48.0 + 0.01, "{h}");
}

#[test]
fn display_mesh_stays_within_its_budget() {
    let tris = all_triangles("3DBenchy.stl");
    let (lo, hi) = bounds(&tris);
    let whole = display_mesh(&tris, tris.len());
    assert_eq!(whole.len(), tris.len() * 9);
    for max in [50_000usize, 5_000, 100] {
        let d = display_mesh(&tris, max);
        assert_eq!(d.len() % 9, 0);
        let n = d.len() / 9;
        assert!(n <= max && n > max / 20, "{max}: {n} triangles");
        // Every corner lies within the model's bounds (cells average their corners).
        for c in d.chunks(3) {
            for k in 0..3 {
                let x = f64::from(c[k]);
                assert!(x >= lo[k] - 1e-3 && x <= hi[k] + 1e-3, "{c:?}");
            }
        }
    }
    assert!(display_mesh(&tris, 0).is_empty());
}

// ---------------------------------------------------------------------------------------------
// The CLI

fn run(args: &[&str], dir: &TempDir) -> common::Run {
    run_cli(args, dir.path(), Duration::from_secs(300))
}

/// [`run`] with the arguments as one line of words (no word holds a space).
fn run_words(words: &str, dir: &TempDir) -> common::Run {
    run(&words.split_whitespace().collect::<Vec<_>>(), dir)
}

#[test]
fn cli_slices_several_models_and_job_files() {
    let dir = TempDir::new("job-cli");
    std::fs::write(
        dir.join("a.stl"),
        common::stl_bytes(&box_tris(20.0, 10.0, 2.0)),
    )
    .unwrap();
    std::fs::create_dir(dir.join("models")).unwrap();
    std::fs::copy(
        model("extruder_idler_quads.obj"),
        dir.join("models/idler.obj"),
    )
    .unwrap();
    // Two models: arranged, the header lists both.
    let r = run_words("a.stl models/idler.obj -o two.gco --set rotate_z=90", &dir);
    assert_eq!(r.code, Some(0), "{r:?}");
    let two = std::fs::read_to_string(dir.join("two.gco")).unwrap();
    assert!(
        two.contains("; part 1 = a.stl, rotate 0/0/90 deg"),
        "{two:.2000}"
    );
    assert!(two.contains("; part 2 = models/idler.obj"), "{two:.2000}");
    assert!(
        r.stderr.contains("part 1 = a.stl") && r.stderr.contains("part 2"),
        "{}",
        r.stderr
    );
    // place_* with several models: refused.
    let r = run(&["a.stl", "models/idler.obj", "--set", "place_x=3"], &dir);
    assert_eq!(r.code, Some(2));
    assert!(
        r.stderr.contains("place_x") && r.stderr.contains("job file"),
        "{}",
        r.stderr
    );
    // The same job as a job file in another folder, paths relative to it.
    let job = json!({
        "settings": {"layer_height": 0.2},
        "parts": [
            {"file": "../a.stl", "rotate_z": 90},
            {"file": "idler.obj", "rotate_z": 90}
        ]
    });
    std::fs::write(dir.join("models/job.json"), job.to_string()).unwrap();
    let r = run(&["models/job.json", "-o", "job.gco"], &dir);
    assert_eq!(r.code, Some(0), "{r:?}");
    let from_file = std::fs::read_to_string(dir.join("job.gco")).unwrap();
    let moves = |t: &str| {
        t.lines()
            .filter(|l| !l.starts_with(';'))
            .map(String::from)
            .collect::<Vec<_>>()
    };
    assert_eq!(
        moves(&two),
        moves(&from_file),
        "the job file slices as the two models"
    );
    assert!(
        from_file.contains("; part 2 = idler.obj"),
        "{from_file:.2000}"
    );
    // Recognised by its content too (a name that is not a model's).
    std::fs::copy(dir.join("models/job.json"), dir.join("models/the-job")).unwrap();
    let r = run(&["models/the-job", "-o", "job2.gco"], &dir);
    assert_eq!(r.code, Some(0), "{r:?}");
    let t = std::fs::read_to_string(dir.join("job2.gco")).unwrap();
    assert_eq!(moves(&t), moves(&from_file));
    // --set overrides the job file's settings; a part key is refused there.
    let r = run_words("models/job.json -o job3.gco --set layer_height=0.3", &dir);
    assert_eq!(r.code, Some(0), "{r:?}");
    let t = std::fs::read_to_string(dir.join("job3.gco")).unwrap();
    assert!(t.contains("; layer_height = 0.3 (mm)"));
    let r = run(&["models/job.json", "--set", "rotate_x=3"], &dir);
    assert_eq!(r.code, Some(2));
    assert!(r.stderr.contains("rotate_x"), "{}", r.stderr);
    // A bad job file: named, exit 2, nothing written.
    std::fs::write(
        dir.join("bad.json"),
        r#"{"parts": [{"file": "a.stl", "copies": 0}]}"#,
    )
    .unwrap();
    let r = run(&["bad.json", "-o", "bad.gco"], &dir);
    assert_eq!(r.code, Some(2));
    assert!(r.stderr.contains("parts[0].copies"), "{}", r.stderr);
    assert!(!dir.join("bad.gco").exists());
    // A missing part file names the file.
    std::fs::write(
        dir.join("missing.json"),
        r#"{"parts": [{"file": "nope.stl"}]}"#,
    )
    .unwrap();
    let r = run(&["missing.json", "-o", "m.gco"], &dir);
    assert_eq!(r.code, Some(2));
    assert!(r.stderr.contains("nope.stl"), "{}", r.stderr);
}

#[test]
fn cli_single_model_header_lists_the_part() {
    let dir = TempDir::new("job-cli-one");
    let cube_gears = model("cube_gears.3mf").display().to_string();
    let r = run_words(
        &format!("{cube_gears} -o one.gco --set place_x=3 --set place_y=4 --set plate_x=180"),
        &dir,
    );
    assert_eq!(r.code, Some(0), "{r:?}");
    let t = std::fs::read_to_string(dir.join("one.gco")).unwrap();
    assert!(
        t.contains("; part 1 = cube_gears.3mf, rotate 0/0/0 deg, scale 1/1/1, at X3.0000 Y4.0000, angle 0 deg, copy 1 of 1, unit 0"),
        "{t:.3000}"
    );
}

/// The settings the table marks `layout` are all that the plate's layout reads (the layout and
/// which of its misfits may be sliced): every other setting of the job, changed alone to
/// another value it takes, leaves them as they were (the page lays a job out again only when a
/// marked one changes), and each marked one changes them for some value. The job: a part wider than the plate (a misfit), two copies of a box, a part of
/// each other unit.
#[test]
fn the_layout_reads_the_settings_marked_layout_and_no_other() {
    use dropslice::base::settings::{Kind, MAX_UNITS, schema};
    let models = [
        box_model("wide.stl", 170.0, 20.0, 30.0),
        box_model("box.stl", 40.0, 30.0, 20.0),
        box_model("small.stl", 12.0, 8.0, 6.0),
    ];
    let mut parts = vec![
        json!({"file": "wide.stl"}),
        json!({"file": "box.stl", "copies": 2}),
    ];
    for u in 1..MAX_UNITS {
        parts.push(json!({"file": "small.stl", "unit": u}));
    }
    let machine = json!({"units": MAX_UNITS});
    let of = |name: &str, v: &Value| -> Option<String> {
        let mut settings = machine.clone();
        settings[name] = v.clone();
        // the layout, and which of its misfits the settings let be sliced
        let l = spec(json!({"settings": settings, "parts": parts}))
            .and_then(|s| {
                let l = layout(&models, &s)?;
                let allowed: Vec<bool> = l.misfits.iter().map(|m| m.allowed(&s.settings)).collect();
                Ok((l, allowed))
            })
            .map_err(|e| e.to_string());
        serde_json::to_string(&l).ok()
    };
    let base = of("units", &json!(MAX_UNITS)).unwrap();
    assert!(base.contains("misfits"), "{base}");
    let (mut marked, mut others) = (0, 0);
    for s in schema().iter().filter(|s| !s.part) {
        let d = &s.domain;
        let values: Vec<Value> = match d.kind {
            Kind::Bool => vec![json!(s.default != json!(true))],
            Kind::Enum | Kind::Order => d.choices.iter().map(|c| json!(c)).collect(),
            Kind::Number | Kind::Integer => {
                let (lo, hi) = (d.min.unwrap(), d.max.unwrap());
                let lo = if d.min_exclusive {
                    lo + (hi - lo) * 1e-6
                } else {
                    lo
                };
                let mid = (lo + hi) / 2.0;
                let mid = if d.kind == Kind::Integer {
                    mid.round()
                } else {
                    mid
                };
                vec![json!(lo), json!(mid), json!(hi)]
            }
        };
        let layouts: Vec<String> = values.iter().filter_map(|v| of(s.name, v)).collect();
        if s.layout {
            marked += 1;
            assert!(
                layouts.iter().any(|l| *l != base),
                "{}: marked `layout`, but no value of it changes the layout",
                s.name
            );
        } else {
            others += 1;
            for (v, l) in values.iter().zip(&layouts) {
                assert_eq!(
                    *l, base,
                    "{} = {v} changes the layout: mark it `layout`",
                    s.name
                );
            }
        }
    }
    assert!(
        marked >= 8 && others > 30,
        "{marked} marked, {others} others"
    );
}
