//! The wasm facade (src/wasm/) in Node: `wasm-bindgen-test-runner` runs these when
//! `cargo test --target wasm32-unknown-unknown --test wasm_session` is given it as the runner.
#![cfg(target_arch = "wasm32")]

use dropslice::wasm::reader::{GcodeStream, calibrate};
use dropslice::wasm::{
    Models, Session, Tally, check_profile, default_settings, job_schema, merge_summaries,
    settings_schema, version,
};
use serde::Serialize;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

/// A closed axis-aligned box as an ASCII STL.
fn box_stl(w: f64, d: f64, h: f64) -> String {
    let v = |x: f64, y: f64, z: f64| format!("vertex {x} {y} {z}\n");
    let quads = [
        // bottom (normal -z), top (+z), then the four sides, counter-clockwise from outside
        [(0.0, 0.0, 0.0), (0.0, d, 0.0), (w, d, 0.0), (w, 0.0, 0.0)],
        [(0.0, 0.0, h), (w, 0.0, h), (w, d, h), (0.0, d, h)],
        [(0.0, 0.0, 0.0), (w, 0.0, 0.0), (w, 0.0, h), (0.0, 0.0, h)],
        [(w, 0.0, 0.0), (w, d, 0.0), (w, d, h), (w, 0.0, h)],
        [(w, d, 0.0), (0.0, d, 0.0), (0.0, d, h), (w, d, h)],
        [(0.0, d, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, h), (0.0, d, h)],
    ];
    let mut s = String::from("solid box\n");
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            s.push_str("facet normal 0 0 0\nouter loop\n");
            for p in t {
                s.push_str(&v(p.0, p.1, p.2));
            }
            s.push_str("endloop\nendfacet\n");
        }
    }
    s.push_str("endsolid box\n");
    s
}

/// Models holding, under each name, a box of (width, depth, height) as [`box_stl`] makes it.
fn boxes(files: &[(&str, [f64; 3])]) -> Models {
    let mut models = Models::new();
    for &(name, [w, d, h]) in files {
        models.add_bytes(box_stl(w, d, h).as_bytes(), name).unwrap();
    }
    models
}

/// Two boxes as one ASCII STL, the second moved by (dx, dy).
fn two_boxes_stl(w: f64, d: f64, h: f64, dx: f64, dy: f64) -> String {
    let one = box_stl(w, d, h);
    let moved: String = one
        .lines()
        .filter(|l| l.starts_with("vertex") || l.contains("facet") || l.contains("loop"))
        .map(|l| match l.strip_prefix("vertex ") {
            Some(xyz) => {
                let v: Vec<f64> = xyz.split(' ').map(|c| c.parse().unwrap()).collect();
                format!("vertex {} {} {}\n", v[0] + dx, v[1] + dy, v[2])
            }
            None => format!("{l}\n"),
        })
        .collect();
    one.replace("endsolid box\n", &moved) + "endsolid box\n"
}

/// A JS value as the page makes it (plain objects).
fn js(v: serde_json::Value) -> JsValue {
    v.serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .unwrap()
}

/// A value from the facade, as JSON for the assertions.
fn json(v: JsValue) -> serde_json::Value {
    serde_wasm_bindgen::from_value(v).unwrap()
}

/// A session made as another worker makes it: its own import of the same files (`name`,
/// bytes; added in the reverse order) prepared for the same job.
fn worker_copy(files: &[(&str, &[u8])], job: &serde_json::Value) -> Session {
    let mut models = Models::new();
    for &(name, bytes) in files.iter().rev() {
        models.add_bytes(bytes, name).unwrap();
    }
    Session::from_models(&models, js(job.clone())).unwrap()
}

fn defaults() -> JsValue {
    js(serde_json::json!({}))
}

/// The error `r` threw (it must have thrown) as `{kind, message, setting?}`.
fn thrown<T>(r: Result<T, JsValue>) -> serde_json::Value {
    let Err(e) = r else {
        panic!("no error was thrown")
    };
    assert!(
        !e.is_instance_of::<js_sys::Error>(),
        "a plain object, not an Error"
    );
    json(e)
}

/// [`thrown`], checking that the error is of `kind`.
fn throws<T>(r: Result<T, JsValue>, kind: &str) -> serde_json::Value {
    let e = thrown(r);
    assert_eq!(e["kind"], kind, "{e}");
    e
}

#[wasm_bindgen_test]
fn schema_defaults_and_version() {
    let schema = json(settings_schema().unwrap());
    let names: Vec<&str> = schema
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert!(names.contains(&"layer_height") && names.contains(&"droplet_aspect"));
    // the part keys are flagged, and the job schema gives the page their ranges (then copies
    // and unit): the same rows
    let rows = schema.as_array().unwrap();
    let part: Vec<&serde_json::Value> = rows.iter().filter(|s| s["part"] == true).collect();
    let keys: Vec<&str> = part.iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(keys, dropslice::model::spec::PART_KEYS);
    assert!(rows.iter().all(|s| s["part"].is_boolean()));
    let job = json(job_schema().unwrap());
    let numbers = job["part_numbers"].as_array().unwrap();
    assert_eq!(
        &numbers[..part.len()],
        &part.into_iter().cloned().collect::<Vec<_>>()[..]
    );
    let rest: Vec<&str> = numbers[keys.len()..]
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(rest, ["copies", "unit"]);
    assert_eq!(job["max_parts"], dropslice::model::spec::MAX_PARTS);
    let defaults = json(default_settings().unwrap());
    assert_eq!(defaults["layer_height"], 0.2);
    assert_eq!(defaults["contours"], 2);
    assert_eq!(version(), dropslice::VERSION);
}

#[wasm_bindgen_test]
fn slices_a_box() {
    let stl = box_stl(10.0, 6.0, 2.0);
    let s = Session::new(stl.as_bytes(), "box.stl", defaults()).unwrap();
    assert_eq!(s.layer_count(), 10);
    let info = json(s.info().unwrap());
    assert_eq!(info["layers"], 10);
    let mut totals = [0u64; 3];
    let mut text = String::new();
    let mut tally = Tally::new();
    let mut seconds = 0.0;
    for i in 0..s.layer_count() {
        let mut l = s.slice_layer(i).unwrap();
        assert_eq!(l.index(), i);
        // the layer's time: droplets at droplet_rate (100/s), travel at travel_speed (50 mm/s)
        let t = (l.outer() + l.inner() + l.fill()) / 100.0 + l.travel_mm() / 50.0;
        assert!(
            (l.seconds() - t).abs() <= 1e-9 * t,
            "layer {i}: {}",
            l.seconds()
        );
        seconds += l.seconds();
        assert!((l.z() - 0.2 * (i + 1) as f64).abs() < 1e-9);
        let n = (l.outer() + l.inner() + l.fill()) as u32;
        assert!(n > 100, "layer {i}: only {n} droplets");
        assert_eq!(l.droplets().length(), 2 * n);
        assert_eq!(l.roles().length(), n);
        assert_eq!(l.travel().length() % 4, 0);
        // every droplet inside the box
        let d = l.droplets().to_vec();
        assert!(
            d.chunks(2)
                .all(|p| (0.0..=10.0).contains(&p[0]) && (0.0..=6.0).contains(&p[1]))
        );
        // roles: 0 outer, 1 inner, 2 fill, in the counted numbers
        let roles = l.roles().to_vec();
        for (k, t) in totals.iter_mut().enumerate() {
            *t += roles.iter().filter(|&&r| r as usize == k).count() as u64;
        }
        text.push_str(&String::from_utf8(l.gcode().to_vec()).unwrap());
        tally.add_layer(&mut l);
    }
    assert!(text.contains("G26 ") && text.contains("G25 ") && text.contains("G01 "));
    let summary = json(tally.summary().unwrap());
    assert_eq!(summary["layers"], 10);
    assert_eq!(summary["counts"]["outer"], totals[0]);
    assert_eq!(summary["counts"]["inner"], totals[1]);
    assert_eq!(summary["counts"]["fill"], totals[2]);
    let header = s.header(js(summary.clone())).unwrap();
    assert!(header.contains("; layer_height = 0.2"), "{header}");
    assert!(header.contains("box.stl"));
    let placeholder = s.header(JsValue::NULL).unwrap();
    assert_eq!(placeholder.len(), header.len());
    let footer = s.footer(js(summary.clone())).unwrap();
    assert!(footer.contains("10 layers"), "{footer}");
    let f = json(s.figures(js(serde_json::json!([summary]))).unwrap());
    let figures = &f["figures"];
    assert!(figures["repairs"].as_array().unwrap().is_empty(), "{f}");
    let droplets = totals.iter().sum::<u64>();
    assert_eq!(figures["droplets"], droplets);
    let b = 0.2 * 1.04;
    let volume = figures["units"][0]["volume_mm3"].as_f64().unwrap();
    assert!((volume - droplets as f64 * b * b * 0.2).abs() < 1e-6 * volume);
    let print_seconds = figures["print_seconds"].as_f64().unwrap();
    assert!(print_seconds > droplets as f64 / 100.0);
    // the page's per-layer plot: the layers' times add up to the job's
    assert!((seconds - print_seconds).abs() <= 1e-9 * print_seconds);
    assert!(f["nothing_to_print"].is_null(), "{f}");
    assert!(figures["coverage"].is_null() && figures["worst_layer"].is_null());
    assert!(s.slice_layer(10).is_err());
}

#[wasm_bindgen_test]
fn settings_change_the_slice() {
    let stl = box_stl(10.0, 6.0, 2.0);
    let s = Session::new(
        stl.as_bytes(),
        "box.stl",
        js(serde_json::json!({"layer_height": 0.25, "contours": 3})),
    )
    .unwrap();
    assert_eq!(s.layer_count(), 8);
    let l = s.slice_layer(0).unwrap();
    assert!((l.z() - 0.25).abs() < 1e-9);
}

#[wasm_bindgen_test]
fn errors_are_typed_objects() {
    let garbage = b"this is not an STL file at all, just some words";
    let e = throws(Session::new(garbage, "x.stl", defaults()), "import");
    assert!(
        e["message"]
            .as_str()
            .unwrap()
            .starts_with("cannot read the model file"),
        "{e}"
    );
    assert!(e.get("setting").is_none(), "{e}");

    let stl = box_stl(10.0, 6.0, 2.0);
    // each of these is a setting error
    let bad = |settings: serde_json::Value| {
        throws(
            Session::new(stl.as_bytes(), "box.stl", js(settings)),
            "setting",
        )
    };
    let e = bad(serde_json::json!({"layer_height": -1}));
    assert_eq!(e["setting"], "layer_height", "{e}");
    assert!(
        e["message"].as_str().unwrap().contains("layer_height"),
        "{e}"
    );
    let e = bad(serde_json::json!({"contours": "many"}));
    assert_eq!(e["setting"], "contours", "{e}");
    bad(serde_json::json!({"no_such_setting": 1}));
    let e = bad(serde_json::json!("not an object"));
    assert!(e.get("setting").is_none(), "{e}");
    // a part thinner than half a layer
    let thin = box_stl(10.0, 6.0, 0.05);
    throws(
        Session::new(thin.as_bytes(), "thin.stl", defaults()),
        "nothing_to_print",
    );

    throws(Session::new(&[], "empty.stl", defaults()), "import");
    // a truncated binary STL
    let mut bin = vec![0u8; 84];
    bin[80] = 5;
    bin.extend_from_slice(&[0u8; 60]);
    throws(Session::new(&bin, "cut.stl", defaults()), "import");
    // a layer out of range and a summary the core did not make are internal errors
    let s = Session::new(stl.as_bytes(), "box.stl", defaults()).unwrap();
    throws(s.slice_layer(99), "internal");
    throws(s.footer(js(serde_json::json!({"counts": 5}))), "internal");
}

#[wasm_bindgen_test]
fn nothing_to_print_comes_with_the_figures() {
    // 0.1 mm walls: thinner than a droplet, so no droplet fits
    let stl = box_stl(0.1, 20.0, 2.0);
    let s = Session::new(stl.as_bytes(), "wall.stl", defaults()).unwrap();
    let mut tally = Tally::new();
    for i in 0..s.layer_count() {
        tally.add_layer(&mut s.slice_layer(i).unwrap());
    }
    let f = json(
        s.figures(js(serde_json::json!([json(tally.summary().unwrap())])))
            .unwrap(),
    );
    assert_eq!(f["figures"]["droplets"], 0, "{f}");
    assert_eq!(f["nothing_to_print"]["kind"], "nothing_to_print", "{f}");
    assert!(
        f["nothing_to_print"]["message"]
            .as_str()
            .unwrap()
            .contains("thinner than the droplet width"),
        "{f}"
    );
}

#[wasm_bindgen_test]
fn every_worker_s_own_session_slices_the_same() {
    let stl = two_boxes_stl(10.0, 6.0, 2.0, 3.0, 2.0);
    let job = serde_json::json!({
        "settings": {"layer_height": 0.25},
        "parts": [{"file": "two.stl", "rotate_z": 30}]
    });
    let files: [(&str, &[u8]); 1] = [("two.stl", stl.as_bytes())];
    let first = worker_copy(&files, &job);
    let other = worker_copy(&files, &job);
    assert_eq!(other.layer_count(), first.layer_count());
    assert_eq!(json(other.info().unwrap()), json(first.info().unwrap()));
    assert_eq!(
        other.header(JsValue::NULL).unwrap(),
        first.header(JsValue::NULL).unwrap()
    );
    let (mut a, mut b) = (Tally::new(), Tally::new());
    for i in 0..first.layer_count() {
        let (mut x, mut y) = (
            first.slice_layer_analysed(i).unwrap(),
            other.slice_layer_analysed(i).unwrap(),
        );
        assert_eq!(x.gcode().to_vec(), y.gcode().to_vec(), "layer {i}");
        assert_eq!(x.droplets().to_vec(), y.droplets().to_vec(), "layer {i}");
        assert_eq!(x.roles().to_vec(), y.roles().to_vec(), "layer {i}");
        assert_eq!(
            json(x.analysis().unwrap()),
            json(y.analysis().unwrap()),
            "layer {i}"
        );
        a.add_layer(&mut x);
        b.add_layer(&mut y);
    }
    assert_eq!(json(a.summary().unwrap()), json(b.summary().unwrap()));
    // merged in another order, the summary is the same
    let sa = json(a.summary().unwrap());
    let merged = json(merge_summaries(js(serde_json::json!([sa]))).unwrap());
    assert_eq!(merged["counts"], sa["counts"]);
}

#[wasm_bindgen_test]
fn analysed_layers_have_sane_void_figures() {
    let stl = box_stl(10.0, 6.0, 2.0);
    let s = Session::new(stl.as_bytes(), "box.stl", defaults()).unwrap();
    // plain slicing carries no analysis
    let plain = s.slice_layer(3).unwrap();
    assert!(plain.analysis().unwrap().is_null());
    assert_eq!(plain.void_mask().length(), 0);
    assert_eq!(plain.mask_tiles().length(), 0);
    assert_eq!(plain.mask_cell(), 0.0);
    for i in [0, 3, 9] {
        let l = s.slice_layer_analysed(i).unwrap();
        // the same layer as plain slicing
        assert_eq!(
            l.droplets().to_vec(),
            s.slice_layer(i).unwrap().droplets().to_vec()
        );
        let a = json(l.analysis().unwrap());
        assert_eq!(a["index"], i);
        let coverage = a["coverage"].as_f64().unwrap();
        assert!(
            (0.7..0.9).contains(&coverage),
            "layer {i}: coverage {coverage}"
        );
        let region = a["region_area"].as_f64().unwrap();
        assert!((region - 60.0).abs() < 0.01, "region {region}");
        let void = a["void_area"].as_f64().unwrap();
        assert!(
            (void - (1.0 - coverage) * region).abs() < 0.05 * region,
            "void {void}"
        );
        let largest = &a["largest_void"];
        let area = largest["area"].as_f64().unwrap();
        assert!(area > 0.0 && area <= void, "largest {area} of {void}");
        let (min, max) = (&largest["min"], &largest["max"]);
        assert!(min[0].as_f64().unwrap() >= -0.5 && max[0].as_f64().unwrap() <= 10.5);
        assert!(a["overfill_area"].as_f64().unwrap() >= 0.0);
        // the mask: tiles of cells of B/4 over the layer, its void share adds up to the void
        // area
        let cell = l.mask_cell();
        let b = 0.2 * 1.04;
        assert!((cell - b / 4.0).abs() < b / 10.0, "cell {cell}");
        let tiles = l.mask_tiles().to_vec();
        assert!(
            !tiles.is_empty() && tiles.len().is_multiple_of(4),
            "{tiles:?}"
        );
        let mut cells = 0;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for t in tiles.chunks(4) {
            let (w, h) = (t[2] as usize, t[3] as usize);
            cells += w * h;
            lo = [lo[0].min(t[0]), lo[1].min(t[1])];
            hi = [
                hi[0].max(t[0] + w as f64 * cell),
                hi[1].max(t[1] + h as f64 * cell),
            ];
        }
        // the tiles cover the box (10 x 6 mm) and not much more
        assert!(lo[0] <= 0.0 && lo[1] <= 0.0, "{lo:?}");
        assert!(hi[0] >= 10.0 && hi[1] >= 6.0, "{hi:?}");
        assert!(hi[0] < 15.0 && hi[1] < 11.0, "{hi:?}");
        let mask = l.void_mask().to_vec();
        assert_eq!(mask.len(), cells);
        assert_eq!(l.overfill_mask().length() as usize, cells);
        // per tile, whether any of its cells has overfill (the page reads only those)
        let (overfill, flags) = (l.overfill_mask().to_vec(), l.mask_overfilled().to_vec());
        assert_eq!(flags.len(), tiles.len() / 4);
        let mut at = 0;
        for (t, &flag) in tiles.chunks(4).zip(&flags) {
            let end = at + t[2] as usize * t[3] as usize;
            let any = overfill[at..end].iter().any(|&v| v != 0);
            assert_eq!(flag, u8::from(any), "tile {t:?}");
            at = end;
        }
        assert!(
            flags.contains(&1),
            "droplets past the box's edge overfill: {flags:?}"
        );
        let masked: f64 = mask.iter().map(|&v| v as f64 / 255.0).sum::<f64>() * cell * cell;
        assert!(
            (masked - void).abs() < 0.05 * void,
            "mask {masked} vs void {void}"
        );
    }
    assert!(s.slice_layer_analysed(10).is_err());
}

#[wasm_bindgen_test]
fn the_mask_of_parts_far_apart_has_tiles_near_them_only() {
    // Two 3 x 3 mm boxes 1 m apart: a dense mask over their bounding box (cells of B/4) would
    // hold 2.6e8 cells of 2 bytes and not fit in the 4 GB a wasm instance can address.
    let stl = two_boxes_stl(3.0, 3.0, 1.0, 1000.0, 1000.0);
    // a metre past the default plate: sliced where it lies
    let off_plate = js(serde_json::json!({"allow_off_plate": true}));
    let s = Session::new(stl.as_bytes(), "two.stl", off_plate).unwrap();
    let l = s.slice_layer_analysed(2).unwrap();
    let a = json(l.analysis().unwrap());
    let region = a["region_area"].as_f64().unwrap();
    assert!((region - 18.0).abs() < 0.01, "region {region}");
    let coverage = a["coverage"].as_f64().unwrap();
    assert!((0.7..0.9).contains(&coverage), "coverage {coverage}");
    let cell = l.mask_cell();
    let tiles = l.mask_tiles().to_vec();
    let cells: f64 = tiles.chunks(4).map(|t| t[2] * t[3]).sum();
    assert!(
        cells * cell * cell < 200.0,
        "tiles over {} mm²",
        cells * cell * cell
    );
    for t in tiles.chunks(4) {
        let near = |c: f64| (t[0] - c).abs() < 10.0 && (t[1] - c).abs() < 10.0;
        assert!(near(0.0) || near(1000.0), "tile at {t:?}");
    }
    assert_eq!(l.void_mask().length() as f64, cells);
}

/// A JSON array of numbers (integers and floats alike).
fn nums(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[wasm_bindgen_test]
fn models_give_infos_layouts_and_a_merged_session() {
    let mut models = Models::new();
    let info = json(
        models
            .add_bytes(box_stl(20.0, 10.0, 2.0).as_bytes(), "a.stl")
            .unwrap(),
    );
    assert_eq!(info["name"], "a.stl");
    assert_eq!(info["format"], "ascii");
    assert_eq!(info["triangles"], 12);
    assert_eq!(nums(&info["bounds"]["max"]), [20.0, 10.0, 2.0]);
    assert_eq!(info["items"].as_array().unwrap().len(), 1);
    assert_eq!(info["suggested_scale"], serde_json::Value::Null);
    models
        .add_bytes(box_stl(5.0, 5.0, 3.0).as_bytes(), "b.stl")
        .unwrap();
    assert_eq!(
        json(models.names().unwrap()),
        serde_json::json!(["a.stl", "b.stl"])
    );
    // The display mesh: the 12 triangles of the box, 9 floats each, in model coordinates.
    let d = models.display_mesh("a.stl", None, 1000).unwrap().to_vec();
    assert_eq!(d.len(), 12 * 9);
    assert!(d.iter().all(|&c| (0.0..=20.0).contains(&c)));
    // lay_flat of a box lying on its largest face: nothing to turn.
    let flat = json(models.lay_flat("a.stl", None).unwrap());
    let (rx, ry) = (
        flat["rotate_x"].as_f64().unwrap(),
        flat["rotate_y"].as_f64().unwrap(),
    );
    assert!(rx == 0.0 && ry == 0.0, "{flat}");
    let job = serde_json::json!({
        "settings": {"part_spacing": 3},
        "parts": [
            {"file": "a.stl", "place_x": 10, "place_y": 10},
            {"file": "b.stl", "copies": 2}
        ]
    });
    let layout = json(models.layout(js(job.clone())).unwrap());
    let inst = layout["instances"].as_array().unwrap();
    assert_eq!(inst.len(), 3);
    assert_eq!(nums(&inst[0]["min"]), [10.0, 10.0, 0.0]);
    assert_eq!(inst[0]["matrix"].as_array().unwrap().len(), 16);
    // The matrix of the placed box: a translation by (10, 10, 0).
    let m = nums(&inst[0]["matrix"]);
    assert_eq!(
        m,
        [
            1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 10., 10., 0., 1.
        ]
    );
    assert_eq!(inst[1]["copy"], 0);
    assert_eq!(inst[2]["copy"], 1);
    // The merged session slices all three, as another worker's own import of the files does.
    let s = Session::from_models(&models, js(job.clone())).unwrap();
    let info = json(s.info().unwrap());
    assert_eq!(info["instances"].as_array().unwrap().len(), 3);
    assert_eq!(info["layers"], 15);
    assert_eq!(info["bounds"], layout["bounds"]);
    let (a, b) = (box_stl(20.0, 10.0, 2.0), box_stl(5.0, 5.0, 3.0));
    let other = worker_copy(&[("a.stl", a.as_bytes()), ("b.stl", b.as_bytes())], &job);
    for i in [0, 7, 14] {
        assert_eq!(
            s.slice_layer(i).unwrap().gcode().to_vec(),
            other.slice_layer(i).unwrap().gcode().to_vec()
        );
    }
    // Layer 1 has the three footprints: 20×10 + 2 × 5×5 = 250 mm² of droplets at B² each.
    let l = s.slice_layer(0).unwrap();
    let n = l.outer() + l.inner() + l.fill();
    let b = 0.2 * 1.04;
    assert!((n * b * b - 250.0).abs() < 0.15 * 250.0, "{n} droplets");
    let header = s.header(JsValue::NULL).unwrap();
    assert!(header.contains("; part 2 = b.stl"), "{header}");
    assert!(models.remove("b.stl"));
    assert!(!models.remove("b.stl"));
}

#[wasm_bindgen_test]
fn refused_jobs_throw_typed_errors() {
    let mut models = boxes(&[("big.stl", [100.0, 100.0, 2.0])]);
    let job = js(serde_json::json!({"parts": [{"file": "big.stl", "copies": 2}]}));
    let e = throws(models.layout(job), "job");
    assert!(e["message"].as_str().unwrap().contains("do not"), "{e}");
    let job = js(serde_json::json!({"parts": [{"file": "big.stl", "copies": 2}]}));
    throws(Session::from_models(&models, job), "job");
    let job = js(serde_json::json!({"parts": [{"file": "big.stl", "scale_x": 0}]}));
    let e = thrown(models.layout(job));
    assert!(
        e["message"].as_str().unwrap().contains("parts[0].scale_x"),
        "{e}"
    );
    let job =
        js(serde_json::json!({"settings": {"layer_height": 0}, "parts": [{"file": "big.stl"}]}));
    let e = thrown(models.layout(job));
    assert_eq!(
        (e["kind"].as_str(), e["setting"].as_str()),
        (Some("setting"), Some("layer_height"))
    );
    throws(models.display_mesh("nope.stl", None, 10), "job");
    throws(models.add_bytes(b"not a model", "x.stl"), "import");
}

/// A job of a box a (10 × 10 × 2 mm) at the origin in unit 0 and a box b of `b` at x = `b_x`
/// in unit 1 (`unit1_droplet_aspect` 1.5): its session and the job.
fn two_units(b: [f64; 3], b_x: f64) -> (Session, serde_json::Value) {
    let models = boxes(&[("a.stl", [10.0, 10.0, 2.0]), ("b.stl", b)]);
    let job = serde_json::json!({
        "settings": {"unit1_droplet_aspect": 1.5},
        "parts": [
            {"file": "a.stl", "place_x": 0, "place_y": 0},
            {"file": "b.stl", "place_x": b_x, "place_y": 0, "unit": 1}
        ]
    });
    (Session::from_models(&models, js(job.clone())).unwrap(), job)
}

#[wasm_bindgen_test]
fn a_job_with_a_unit_1_part_slices_the_same_in_every_worker() {
    // b overlaps a by 4 mm in x; a is listed first and keeps the overlap.
    let (s, job) = two_units([10.0, 10.0, 3.0], 6.0);
    let (a, b) = (box_stl(10.0, 10.0, 2.0), box_stl(10.0, 10.0, 3.0));
    let other = worker_copy(&[("a.stl", a.as_bytes()), ("b.stl", b.as_bytes())], &job);
    assert_eq!(json(other.info().unwrap()), json(s.info().unwrap()));
    assert_eq!(
        other.header(JsValue::NULL).unwrap(),
        s.header(JsValue::NULL).unwrap()
    );
    let header = s.header(JsValue::NULL).unwrap();
    assert!(header.contains("unit1_droplet_aspect = 1.5"), "{header}");
    let (mut ta, mut tb) = (Tally::new(), Tally::new());
    let mut text = String::new();
    for i in 0..s.layer_count() {
        let (mut x, mut y) = (s.slice_layer(i).unwrap(), other.slice_layer(i).unwrap());
        assert_eq!(x.gcode().to_vec(), y.gcode().to_vec(), "layer {i}");
        ta.add_layer(&mut x);
        tb.add_layer(&mut y);
        text.push_str(&String::from_utf8(x.gcode().to_vec()).unwrap());
    }
    let summary = json(ta.summary().unwrap());
    assert_eq!(summary, json(tb.summary().unwrap()));
    // Unit 1 prints b less the overlap: 6 × 10 mm² on each of its 15 layers (B₁ = 0.3 mm
    // cells), and b alone on the top 5.
    let unit1 = summary["counts"]["units"][1].as_f64().unwrap();
    let b1: f64 = 0.2 * 1.5;
    let want = (10.0 * 60.0 + 5.0 * 100.0) / (b1 * b1);
    assert!((unit1 - want).abs() < 0.1 * want, "{unit1} vs {want}");
    // Every unit-1 droplet beside a (z ≤ 2 mm) lies right of it (x > 10), above it from
    // x > 6: read from the code after T1.
    let mut unit = 0;
    let mut checked = 0;
    for l in text.lines() {
        match l {
            "T0" => unit = 0,
            "T1" => unit = 1,
            _ if unit == 1 && (l.starts_with("G26") || l.starts_with("G25")) => {
                let word = |c: char| -> f64 {
                    l.split(' ')
                        .find_map(|w| w.strip_prefix(c))
                        .unwrap()
                        .parse()
                        .unwrap()
                };
                let left = if word('Z') <= 2.0 + 1e-9 { 10.0 } else { 6.0 };
                assert!(word('X') > left, "{l}");
                checked += 1;
            }
            _ => {}
        }
    }
    assert!(checked > 100, "{checked}");
}

/// `stl` (ASCII) with every vertex moved by (dx, dy, dz), as the facets of a second solid.
fn moved_facets(stl: &str, dx: f64, dy: f64, dz: f64) -> String {
    stl.lines()
        .filter(|l| l.starts_with("vertex") || l.contains("facet") || l.contains("loop"))
        .map(|l| match l.strip_prefix("vertex ") {
            Some(xyz) => {
                let v: Vec<f64> = xyz.split(' ').map(|c| c.parse().unwrap()).collect();
                format!("vertex {} {} {}\n", v[0] + dx, v[1] + dy, v[2] + dz)
            }
            None => format!("{l}\n"),
        })
        .collect()
}

#[wasm_bindgen_test]
fn units_of_work_in_different_sessions_join_with_the_right_t_lines() {
    // A post with a slab on top that overhangs it: support under the slab.
    let post = box_stl(2.0, 2.0, 3.0);
    let slab = moved_facets(&box_stl(6.0, 2.0, 1.0), -2.0, 0.0, 3.0);
    let stl = post.replace("endsolid box\n", &slab) + "endsolid box\n";
    let settings = js(serde_json::json!({"layer_height": 0.25, "support": "unit1"}));
    let whole = Session::new(stl.as_bytes(), "t.stl", settings.clone()).unwrap();
    let a = Session::new(stl.as_bytes(), "t.stl", settings.clone()).unwrap();
    let b = Session::new(stl.as_bytes(), "t.stl", settings).unwrap();
    let n = whole.layer_count();
    let mut one = Vec::new();
    for i in 0..n {
        one.extend(whole.slice_layer(i).unwrap().gcode().to_vec());
    }
    // Blocks of 3 layers, alternately in two other sessions (as the page's workers take them).
    let mut joined = Vec::new();
    for start in (0..n).step_by(3) {
        let s = if (start / 3) % 2 == 0 { &a } else { &b };
        for i in start..(start + 3).min(n) {
            joined.extend(s.slice_layer(i).unwrap().gcode().to_vec());
        }
    }
    assert_eq!(
        String::from_utf8(joined).unwrap(),
        String::from_utf8(one.clone()).unwrap()
    );
    let text = String::from_utf8(one).unwrap();
    let mut unit = "T0";
    let mut changes = 0;
    for l in text.lines().filter(|l| l.starts_with('T')) {
        assert_ne!(l, unit, "a T line without a change");
        unit = l;
        changes += 1;
    }
    assert!(changes >= 2, "{changes} unit changes");
}

#[wasm_bindgen_test]
fn the_overhang_figure_is_the_same_in_any_order_of_layers() {
    // A 2 × 2 mm post under a 6 × 2 mm slab reaching 2 mm beyond it on both sides in x, support
    // off: only the slab's first layer overhangs, by the slab less the post grown by
    // d = overhang_limit·B (cut to the slab's width in y: straight edges only), 12 − 2·(2 + 2d)
    // mm². A session keeps the section it planned last for the next layer's figure; layers
    // out of order or in blocks must give the same figures.
    let post = box_stl(2.0, 2.0, 3.0);
    let slab = moved_facets(&box_stl(6.0, 2.0, 1.0), -2.0, 0.0, 3.0);
    let stl = post.replace("endsolid box\n", &slab) + "endsolid box\n";
    let settings = js(serde_json::json!({"layer_height": 0.25}));
    let whole = Session::new(stl.as_bytes(), "t.stl", settings.clone()).unwrap();
    let n = whole.layer_count();
    let areas: Vec<f64> = (0..n)
        .map(|i| whole.slice_layer(i).unwrap().unsupported_area())
        .collect();
    let info = json(whole.info().unwrap());
    let d = 0.5 * info["droplet_width"].as_f64().unwrap();
    let over: Vec<usize> = (0..n).filter(|&i| areas[i] > 1e-9).collect();
    assert_eq!(over.len(), 1, "{areas:?}");
    let want = 12.0 - 2.0 * (2.0 + 2.0 * d);
    assert!(
        (areas[over[0]] - want).abs() < 1e-6,
        "{} ≠ {want}",
        areas[over[0]]
    );
    // Out of order, repeated, and in blocks of 3 in one other session.
    let other = Session::new(stl.as_bytes(), "t.stl", settings).unwrap();
    let k = over[0];
    for i in [k, k - 1, k, k + 1, k + 1, 0, n - 1, k - 2, k] {
        assert_eq!(
            other.slice_layer(i).unwrap().unsupported_area(),
            areas[i],
            "layer {i}"
        );
    }
    for start in (0..n).rev().step_by(3) {
        let block = start.saturating_sub(2)..start + 1;
        for (i, &want) in areas.iter().enumerate().take(block.end).skip(block.start) {
            assert_eq!(
                other.slice_layer(i).unwrap().unsupported_area(),
                want,
                "layer {i}"
            );
        }
    }
}

/// The message of an error the `.gco` facade throws (a JS `Error`, as `JsError` makes it).
fn error_message(e: JsValue) -> String {
    assert!(e.is_instance_of::<js_sys::Error>(), "an Error: {e:?}");
    String::from(e.unchecked_into::<js_sys::Error>().message())
}

/// The page's calibration of a slice (`calibrate`) against docs/spec.md's formula computed here:
/// V = m / (N ρ) · 1000 mm³, filling V / (B² H), aspect √(V/H) / H; refusals are Errors.
#[wasm_bindgen_test]
fn calibrates_a_slice() {
    // 15,000 droplets of H 0.25 at aspect 1.1 (B = 0.275): cell 0.275² · 0.25 mm³. A mass
    // that fills each cell of aspect 1.1 exactly, printed at aspect 1.0, density 1.2.
    let (n, h, rho) = (15_000.0, 0.25, 1.2);
    let cell = |aspect: f64| (aspect * h) * (aspect * h) * h;
    let mass = n * cell(1.1) * rho / 1000.0;
    let c = json(calibrate(n, h, 1.0, mass, rho).unwrap());
    let close = |key: &str, want: f64| {
        let got = c[key].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-9 * want.abs(),
            "{key}: {got} ≠ {want}"
        );
    };
    close("droplet_volume_mm3", cell(1.1));
    close("cell_volume_mm3", cell(1.0));
    close("filling_degree", 1.21);
    close("suggested_droplet_aspect", 1.1);
    close("current_droplet_aspect", 1.0);
    assert_eq!(c["droplets"], 15_000);
    assert_eq!(c["count_source"], "given");
    let text = c["explanation"].as_str().unwrap();
    assert!(
        text.contains("15,000 droplets") && text.contains("121 %") && text.contains("1.10"),
        "{text}"
    );
    // refusals: an impossible mass, none, a bad density, no droplets, a bad count
    let m = error_message(calibrate(n, h, 1.0, 1.0e6, rho).unwrap_err());
    assert!(m.starts_with("impossible"), "{m}");
    let m = error_message(calibrate(n, h, 1.0, f64::NAN, rho).unwrap_err());
    assert!(m.contains("mass"), "{m}");
    let m = error_message(calibrate(n, h, 1.0, mass, 0.0).unwrap_err());
    assert!(m.contains("density"), "{m}");
    let m = error_message(calibrate(0.0, h, 1.0, mass, rho).unwrap_err());
    assert!(m.contains("no droplets"), "{m}");
    let m = error_message(calibrate(-1.0, h, 1.0, mass, rho).unwrap_err());
    assert!(m.contains("droplet count"), "{m}");
}

/// A `.gco` made by a session, read back by `GcodeStream` (counting, and the full reader): its
/// header's count, H, aspect and density; without the header's total, the commands' count.
#[wasm_bindgen_test]
fn calibrates_a_gcode_stream() {
    let stl = box_stl(10.0, 6.0, 2.0);
    let settings =
        serde_json::json!({"layer_height": 0.25, "droplet_aspect": 1.1, "material_density": 1.3});
    let s = Session::new(stl.as_bytes(), "box.stl", js(settings)).unwrap();
    let mut body = String::new();
    let mut tally = Tally::new();
    let mut n = 0.0;
    for i in 0..s.layer_count() {
        let mut l = s.slice_layer(i).unwrap();
        n += l.outer() + l.inner() + l.fill();
        body.push_str(&String::from_utf8(l.gcode().to_vec()).unwrap());
        tally.add_layer(&mut l);
    }
    let summary = tally.summary().unwrap();
    let text = s.header(summary.clone()).unwrap() + &body + &s.footer(summary).unwrap();
    assert!(
        text.contains("; droplets total"),
        "the header gives the total"
    );
    let read = |text: &str, counting: bool| {
        let mut r = if counting {
            GcodeStream::counting()
        } else {
            GcodeStream::new()
        };
        for piece in text.as_bytes().chunks(1000) {
            r.feed(std::str::from_utf8(piece).unwrap()).unwrap();
            while r.take_layer().is_some() {}
        }
        r.finish().unwrap();
        while r.take_layer().is_some() {}
        r
    };
    // a mass that fills cells of aspect 1.2 (B = 0.3) at the header's density 1.3
    let h = 0.25;
    let mass = n * (1.2 * h) * (1.2 * h) * h * 1.3 / 1000.0;
    for counting in [true, false] {
        let c = json(read(&text, counting).calibrate(mass, None).unwrap());
        assert_eq!(c["droplets"].as_f64(), Some(n));
        assert_eq!(c["count_source"], "header");
        assert_eq!(c["density_g_cm3"], 1.3);
        assert_eq!(c["layer_height"], 0.25);
        assert_eq!(c["current_droplet_aspect"], 1.1);
        let a = c["suggested_droplet_aspect"].as_f64().unwrap();
        assert!((a - 1.2).abs() < 1e-9, "{a}");
    }
    // a density given wins over the header's: ρ 2.6 halves V, aspect 1.2 / √2
    let c = json(read(&text, true).calibrate(mass, Some(2.6)).unwrap());
    let a = c["suggested_droplet_aspect"].as_f64().unwrap();
    assert!((a - 1.2 / 2f64.sqrt()).abs() < 1e-9, "{a}");
    // no total in the header: the commands' droplets, said so
    let bare: String = text
        .lines()
        .filter(|l| !l.starts_with("; droplets total"))
        .map(|l| format!("{l}\n"))
        .collect();
    let c = json(read(&bare, true).calibrate(mass, None).unwrap());
    assert_eq!(c["droplets"].as_f64(), Some(n));
    assert_eq!(c["count_source"], "commands");
    assert!(
        c["explanation"]
            .as_str()
            .unwrap()
            .contains("counted from the code")
    );
    // an impossible mass is refused with the core's message
    let m = error_message(read(&text, true).calibrate(1.0e6, None).unwrap_err());
    assert!(m.starts_with("impossible"), "{m}");
}

// ---------------------------------------------------------------------------------------------
// The process engineer's tools (docs/process.md)

#[wasm_bindgen_test]
fn orient_ranks_a_part_as_sliced_and_names_a_missing_one() {
    let models = boxes(&[("a.stl", [20.0, 10.0, 2.0])]);
    // Standing on its long edge (10 mm tall), with z compensated by 1/(1 - 0.05).
    let job = serde_json::json!({
        "settings": {"shrink_z": 5},
        "parts": [{"file": "a.stl", "rotate_x": 90}]
    });
    let o = json(models.orient(js(job.clone()), 0).unwrap());
    let height = |v: &serde_json::Value| v["height"].as_f64().unwrap();
    assert!((height(&o["current"]) - 10.0 / 0.95).abs() < 1e-9, "{o}");
    let best = &o["candidates"][0];
    assert!((height(best) - 2.0 / 0.95).abs() < 1e-9, "{o}");
    assert_eq!(best["unsupported_area"], 0.0);
    assert!(o["candidates"].as_array().unwrap().len() >= 3);
    let e = throws(models.orient(js(job), 1), "job");
    assert!(e["message"].as_str().unwrap().contains("parts[1]"), "{e}");
}

/// A binary STL of `n` separate small triangles in a row (welded: `n` facets).
fn strip_stl(n: usize) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(n as u32).to_le_bytes());
    for i in 0..n {
        let x = (i % 1000) as f32 * 0.1;
        let y = (i / 1000) as f32 * 0.1;
        b.extend_from_slice(&[0u8; 12]);
        for p in [[x, y, 0.0], [x + 0.05, y, 0.0], [x, y + 0.05, 0.05]] {
            for c in p {
                b.extend_from_slice(&f32::to_le_bytes(c));
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

#[wasm_bindgen_test]
fn orient_refuses_a_job_past_the_triangle_bound_in_slicings_words() {
    // 5 parts × 100 copies (the most instances a job may have) of 40,001 facets: 20,000,500
    // triangles, past the bound of 20 M; orient is refused before any work, as slicing is.
    let mut models = Models::new();
    models.add_bytes(&strip_stl(40_001), "s.stl").unwrap();
    let part = serde_json::json!({"file": "s.stl", "copies": 100});
    let job = serde_json::json!({"parts": [part, part, part, part, part]});
    let e = throws(models.orient(js(job.clone()), 0), "job");
    let message = e["message"].as_str().unwrap();
    assert!(
        message.contains("the job has more than 20000000 triangles in all (parts × copies)"),
        "{e}"
    );
    let sliced = throws(Session::from_models(&models, js(job)), "job");
    assert_eq!(sliced["message"].as_str(), Some(message));
    // 4 parts are within it.
    let part = serde_json::json!({"file": "s.stl", "copies": 100});
    let job = serde_json::json!({"parts": [part, part, part, part]});
    assert!(models.orient(js(job), 0).is_ok());
}

#[wasm_bindgen_test]
fn a_session_refuses_a_job_taller_than_the_chamber() {
    let models = boxes(&[("b.stl", [5.0, 5.0, 3.0])]);
    let job = serde_json::json!({"settings": {"plate_z": 2.5}, "parts": [{"file": "b.stl"}]});
    let e = thrown(Session::from_models(&models, js(job)));
    assert_eq!(
        (e["kind"].as_str(), e["setting"].as_str()),
        (Some("setting"), Some("plate_z"))
    );
    assert!(
        e["message"].as_str().unwrap().contains("3.000 mm tall"),
        "{e}"
    );
    // The schema carries the new settings with their units and ranges.
    let schema = json(settings_schema().unwrap());
    for (name, unit, max) in [
        ("shrink_xy", "%", 5.0),
        ("unit1_shrink_z", "%", 5.0),
        ("plate_z", "mm", 1e5),
    ] {
        let spec = schema
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["name"] == name)
            .unwrap();
        assert_eq!(
            (spec["unit"].as_str(), spec["max"].as_f64()),
            (Some(unit), Some(max))
        );
    }
}

#[wasm_bindgen_test]
fn check_profile_returns_the_profile_or_names_the_key() {
    let p = json(
        check_profile(
            r#"{"name": " M ", "kind": "machine", "settings": {"plate_z": 180}}"#.as_bytes(),
        )
        .unwrap(),
    );
    assert_eq!(
        p,
        serde_json::json!({"name": "M", "kind": "machine", "settings": {"plate_z": 180}})
    );
    let e = thrown(check_profile(
        r#"{"name": "M", "kind": "machine", "settings": {"shrink_z": 1}}"#.as_bytes(),
    ));
    assert_eq!(
        (e["kind"].as_str(), e["setting"].as_str()),
        (Some("setting"), Some("shrink_z"))
    );
    // The bytes as the file holds them: UTF-16 with its mark as the CLI reads it; a name of
    // just U+FEFF is refused here as the page refuses it.
    let text = r#"{"name": "Mü", "kind": "machine", "settings": {}}"#;
    let utf16: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(text.encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    assert_eq!(json(check_profile(&utf16).unwrap())["name"], "Mü");
    let e = thrown(check_profile(
        "{\"name\": \"\u{feff}\", \"kind\": \"machine\", \"settings\": {}}".as_bytes(),
    ));
    assert!(e["message"].as_str().unwrap().contains("name"), "{e}");
}

/// The merged summary of a session's layers analysed in runs of layers [from, to), each run's
/// tally finished as a worker finishes it.
fn density_in_runs(s: &Session, runs: &[(usize, usize)]) -> serde_json::Value {
    let mut parts = Vec::new();
    for &(from, to) in runs {
        let mut tally = Tally::new();
        for i in from..to {
            tally.add_layer(&mut s.slice_layer_analysed(i).unwrap());
        }
        s.finish_slabs(&mut tally);
        parts.push(json(tally.summary().unwrap()));
    }
    json(s.figures(js(serde_json::Value::Array(parts))).unwrap())["figures"].clone()
}

#[wasm_bindgen_test]
fn the_predicted_density_per_unit_is_the_same_in_any_runs_of_layers() {
    let (s, _) = two_units([8.0, 8.0, 3.0], 14.0);
    let n = s.layer_count();
    let whole = density_in_runs(&s, &[(0, n)]);
    let density = |f: &serde_json::Value, u: usize| f["units"][u]["predicted_density"].as_f64();
    let (d0, d1) = (density(&whole, 0).unwrap(), density(&whole, 1).unwrap());
    assert!(
        (50.0..100.0).contains(&d0) && (50.0..100.0).contains(&d1),
        "{whole}"
    );
    // unit 1's droplets are 1.5 times as wide: the two estimates are of different lattices
    assert!((d0 - d1).abs() > 1e-6, "{whole}");
    for runs in [
        vec![(0, 1), (1, n)],
        vec![(0, 3), (3, 4), (4, 9), (9, n)],
        vec![(5, n), (0, 5)],
    ] {
        let f = density_in_runs(&s, &runs);
        for u in 0..2 {
            let (a, b) = (density(&f, u).unwrap(), density(&whole, u).unwrap());
            assert!((a - b).abs() < 1e-9, "{runs:?} unit {u}: {a} against {b}");
        }
    }
    // a layer analysed alone (not in a tally's run) leaves no density
    let mut tally = Tally::new();
    tally.add_layer(&mut s.slice_layer(2).unwrap());
    s.finish_slabs(&mut tally);
    let f = json(
        s.figures(js(serde_json::json!([json(tally.summary().unwrap())])))
            .unwrap(),
    );
    assert!(density(&f["figures"], 0).is_none(), "{f}");
}

/// Steps `Session::begin`'s preparation to its end, one run of items a step.
fn prepared_in_steps(models: &Models, job: &serde_json::Value) -> Result<Session, JsValue> {
    let mut p = Session::begin(models, js(job.clone()))?;
    for _ in 0..10_000 {
        if p.step(1)? {
            // a step after the end changes nothing
            assert!(p.step(1).unwrap());
            return Session::from_preparation(p);
        }
    }
    panic!("the preparation did not end in 10,000 steps");
}

#[wasm_bindgen_test]
fn the_preparation_in_short_calls_is_the_one_call_preparation() {
    let models = boxes(&[("a.stl", [20.0, 10.0, 5.0]), ("b.stl", [8.0, 8.0, 8.0])]);
    let job = serde_json::json!({"parts": [{"file": "a.stl"}, {"file": "b.stl", "copies": 2}]});
    let whole = Session::from_models(&models, js(job.clone())).unwrap();
    let stepped = prepared_in_steps(&models, &job).unwrap();
    assert!(
        whole.prepared().to_vec() == stepped.prepared().to_vec(),
        "other bytes"
    );
    // the hand-off's bytes make the same session in another worker
    let other = Session::from_prepared(stepped.prepared()).unwrap();
    assert!(other.prepared().to_vec() == whole.prepared().to_vec());
    assert_eq!(json(whole.info().unwrap()), json(stepped.info().unwrap()));
    for i in 0..whole.layer_count() {
        let (a, b) = (
            whole.slice_layer(i).unwrap(),
            stepped.slice_layer(i).unwrap(),
        );
        assert!(a.gcode().to_vec() == b.gcode().to_vec(), "layer {i}");
    }
    // a refusal is the same refusal, as a typed error
    let big = boxes(&[("big.stl", [100.0, 100.0, 2.0])]);
    let job = serde_json::json!({"parts": [{"file": "big.stl", "copies": 2}]});
    let a = throws(Session::from_models(&big, js(job.clone())), "job");
    let b = throws(prepared_in_steps(&big, &job), "job");
    assert_eq!(a, b);
    // a preparation not finished is not a session
    let p = Session::begin(
        &models,
        js(serde_json::json!({"parts": [{"file": "a.stl"}]})),
    )
    .unwrap();
    throws(Session::from_preparation(p), "internal");
}

/// A prepared job taken in short calls (`Session::begin_take`, `Taking::step`) is the one
/// taken at once; damaged bytes are refused as `from_prepared` refuses them, and every step
/// after the refusal throws it again (a step never answers "not yet" for ever).
#[wasm_bindgen_test]
fn a_job_taken_in_short_calls_is_the_one_taken_at_once() {
    let models = boxes(&[("a.stl", [20.0, 10.0, 5.0]), ("b.stl", [8.0, 8.0, 8.0])]);
    let job = serde_json::json!({"parts": [{"file": "a.stl"}, {"file": "b.stl", "copies": 2}]});
    let whole = Session::from_models(&models, js(job)).unwrap();
    let bytes = whole.prepared();
    let mut t = Session::begin_take(bytes.clone(), false);
    let mut steps = 0;
    while !t.step(1).unwrap() {
        steps += 1;
        assert!(steps < 100_000, "not taken in 100,000 steps");
    }
    assert!(steps > 1, "{steps} steps");
    let taken = Session::from_taken(t).unwrap();
    assert!(taken.prepared().to_vec() == bytes.to_vec());

    let mut cut = bytes.to_vec();
    cut.truncate(cut.len() / 2);
    let at_once = throws(
        Session::from_prepared(js_sys::Uint8Array::from(&cut[..])),
        "internal",
    );
    let mut t = Session::begin_take(js_sys::Uint8Array::from(&cut[..]), false);
    let first = loop {
        match t.step(1) {
            Ok(false) => continue,
            Ok(true) => panic!("half a job taken"),
            Err(e) => break e,
        }
    };
    let first = throws::<()>(Err(first), "internal");
    assert_eq!(first, at_once);
    assert_eq!(throws(t.step(1), "internal"), first, "refused again");
    throws(Session::from_taken(t), "internal");
}

/// A box of `size` whose least corner is at `at`, as ASCII STL facets (no `solid` lines).
fn box_facets(at: (f64, f64, f64), size: (f64, f64, f64)) -> String {
    let body = box_stl(size.0, size.1, size.2);
    let shift = |line: &str| -> String {
        let Some(rest) = line.strip_prefix("vertex ") else {
            return line.to_string();
        };
        let c: Vec<f64> = rest.split(' ').map(|v| v.parse().unwrap()).collect();
        format!("vertex {} {} {}", c[0] + at.0, c[1] + at.1, c[2] + at.2)
    };
    (body.lines())
        .filter(|l| !l.starts_with("solid") && !l.starts_with("endsolid"))
        .map(|l| shift(l) + "\n")
        .collect()
}

#[wasm_bindgen_test]
fn a_layer_made_in_three_calls_is_the_layer_made_in_one() {
    // A pillar under a wide slab: the slab's first layers overhang the pillar.
    let stl = format!(
        "solid t\n{}{}endsolid t\n",
        box_facets((4.0, 4.0, 0.0), (2.0, 2.0, 2.0)),
        box_facets((0.0, 0.0, 2.0), (10.0, 10.0, 1.0)),
    );
    let one = Session::new(stl.as_bytes(), "t.stl", defaults()).unwrap();
    let steps = Session::new(stl.as_bytes(), "t.stl", defaults()).unwrap();
    let n = one.layer_count();
    assert_eq!(n, 15);
    let mut overhangs = 0;
    // In order, as a worker's unit of layers; then out of order (the layer below not the last
    // sliced) and with a layer made ahead but another sliced (what was made ahead is dropped).
    let order: Vec<usize> = (0..n).chain([12, 3, 10]).collect();
    for (k, &i) in order.iter().enumerate() {
        let mut calls = 0;
        while !steps.layer_ahead(i).unwrap() {
            calls += 1;
            assert!(
                calls < 3,
                "layer {i}: more calls than a section and an overhang figure"
            );
        }
        if k == n + 1 {
            // Made ahead for layer 3, but layer 4 is asked for: made again, not taken.
            steps.layer_ahead(4).unwrap();
        }
        let (a, b) = (one.slice_layer(i).unwrap(), steps.slice_layer(i).unwrap());
        assert_eq!(a.gcode().to_vec(), b.gcode().to_vec(), "layer {i}");
        assert_eq!(a.droplets().to_vec(), b.droplets().to_vec(), "layer {i}");
        assert_eq!(a.roles().to_vec(), b.roles().to_vec(), "layer {i}");
        assert_eq!(a.travel().to_vec(), b.travel().to_vec(), "layer {i}");
        assert_eq!(
            a.unsupported_area().to_bits(),
            b.unsupported_area().to_bits(),
            "layer {i}"
        );
        overhangs += usize::from(a.unsupported_area() > 1.0);
    }
    assert!(
        overhangs >= 2,
        "the slab's first layer overhangs, in order and again"
    );
    // The analysed layer too.
    for i in [9, 10] {
        while !steps.layer_ahead(i).unwrap() {}
        let (a, b) = (
            one.slice_layer_analysed(i).unwrap(),
            steps.slice_layer_analysed(i).unwrap(),
        );
        assert_eq!(a.gcode().to_vec(), b.gcode().to_vec(), "layer {i}");
        assert_eq!(
            json(a.analysis().unwrap()),
            json(b.analysis().unwrap()),
            "layer {i}"
        );
    }
    assert!(steps.layer_ahead(n).is_err());
}
