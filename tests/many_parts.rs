//! Jobs of very many small parts (issue: limits that hold for every file): 100 000 build items
//! of one 0.5 mm cube, and a small 3MF fanning out 10 000 cubes by components, slice to code
//! in which every cube gets the same droplets and every droplet lies on a cube. The expected
//! figures come from the construction (where the cubes are), never from dropslice's output
//! on another model. Timing is not asserted here (scripts and docs/performance.md carry it);
//! before the nearest-next orders used a grid, the 100 000 items took minutes.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::output::gcode_read::read_gcode;
use dropslice::{Job, Settings};
use std::collections::HashMap;

/// Side of the cubes, mm.
const SIDE: f64 = 0.5;

fn translate(x: f64, y: f64, z: f64) -> String {
    format!("1 0 0 0 1 0 0 0 1 {x} {y} {z}")
}

/// Slices `bytes` with the defaults, writes the code and reads it back: for every layer, the
/// droplets of each cube column (x, y on a grid of `pitch` mm), checking that each droplet
/// lies on a cube's square (its centre within the square, to the code's rounding).
fn droplets_per_cube(bytes: &[u8], name: &str, pitch: f64) -> Vec<HashMap<(i64, i64), u32>> {
    // 100 000 items on a 1 mm grid are wider than the plate: sliced where they are.
    let settings = Settings {
        allow_off_plate: true,
        ..Settings::default()
    };
    let job = Job::new(bytes, name, settings).expect("a job of many cubes slices");
    let mut code = Vec::new();
    let summary = dropslice::write_gcode(&job, &mut code, |_, _| {}).expect("code");
    let text = String::from_utf8(code).expect("text");
    let (layers, _) = read_gcode(&text).expect("the code reads back");
    let mut total = 0u64;
    let per_layer: Vec<HashMap<(i64, i64), u32>> = layers
        .iter()
        .map(|l| {
            let mut cubes = HashMap::new();
            for p in l.preview.droplets.chunks(2) {
                let (x, y) = (p[0] as f64, p[1] as f64);
                let key = ((x / pitch).floor() as i64, (y / pitch).floor() as i64);
                let (u, v) = (x - key.0 as f64 * pitch, y - key.1 as f64 * pitch);
                // f32 coordinates of up to a few hundred mm: within 1e-4 mm.
                let eps = 1e-4;
                assert!(
                    (-eps..=SIDE + eps).contains(&u) && (-eps..=SIDE + eps).contains(&v),
                    "layer {}: droplet ({x}, {y}) outside every cube",
                    l.index
                );
                *cubes.entry(key).or_insert(0) += 1;
                total += 1;
            }
            cubes
        })
        .collect();
    assert_eq!(total, summary.counts.total());
    per_layer
}

/// Every non-empty layer holds droplets on exactly the cubes of `columns` (the same number on
/// each); returns how many layers have droplets and the droplets of one cube over them.
fn same_on_every_cube(
    per_layer: &[HashMap<(i64, i64), u32>],
    columns: &[(i64, i64)],
) -> (usize, u32) {
    let mut layers = 0;
    let mut per_cube = 0;
    for (i, cubes) in per_layer.iter().enumerate() {
        if cubes.is_empty() {
            continue;
        }
        layers += 1;
        assert_eq!(cubes.len(), columns.len(), "layer {i}: cubes with droplets");
        let n = cubes[&columns[0]];
        assert!(n > 0);
        for c in columns {
            assert_eq!(cubes.get(c), Some(&n), "layer {i}: cube {c:?}");
        }
        per_cube += n;
    }
    (layers, per_cube)
}

/// Slices `bytes` (cubes on a 1 mm grid, see [`droplets_per_cube`]) and checks that every
/// non-empty layer holds the same droplets on each column of `columns`
/// ([`same_on_every_cube`]), that the number of such layers lies in `layers`, and that a
/// column (`per`: how the message names it) gets at least four droplets on each of them.
fn assert_cubes_alike(
    bytes: &[u8],
    name: &str,
    columns: &[(i64, i64)],
    layers: std::ops::RangeInclusive<usize>,
    per: &str,
) {
    let per_layer = droplets_per_cube(bytes, name, 1.0);
    let (n, per_cube) = same_on_every_cube(&per_layer, columns);
    assert!(layers.contains(&n), "{n} layers");
    assert!(per_cube >= 4 * n as u32, "{per_cube} droplets per {per}");
}

#[test]
fn a_hundred_thousand_build_items_of_small_cubes_slice_alike() {
    // 100 000 items of one inside-out 0.5 mm cube, 1 mm apart on a grid 317 wide (the last
    // row short): one layer of 100 000 squares, two or three times.
    let n = 100_000usize;
    let side = 317usize;
    let items: String = (0..n)
        .map(|i| {
            format!(
                r#"<item objectid="1" transform="{}"/>"#,
                translate((i % side) as f64, (i / side) as f64, 0.0)
            )
        })
        .collect();
    let bytes = common::three_mf(&common::cube_object(1, SIDE as f32, true), &items);
    let columns: Vec<(i64, i64)> = (0..n)
        .map(|i| ((i % side) as i64, (i / side) as i64))
        .collect();
    // 0.5 mm at 0.2 mm layers: 2 or 3 layers, a loop of droplets around each square in each.
    assert_cubes_alike(&bytes, "items.3mf", &columns, 2..=3, "cube");
}

#[test]
fn a_small_3mf_fanning_out_ten_thousand_cubes_slices_alike() {
    // Four levels of ten components (x 1 mm, y 1 mm, z 1 mm, x 10 mm apart): 10 000 cubes,
    // 100 × 10 columns of 10 cubes each, from a file of about a kilobyte.
    let bytes = common::fanned_cubes_3mf(4, SIDE as f32, false);
    assert!(bytes.len() < 2000, "{} bytes", bytes.len());
    let columns: Vec<(i64, i64)> = (0..100)
        .flat_map(|x| (0..10).map(move |y| (x, y)))
        .collect();
    // Ten cubes one above the other in each column, 2 or 3 layers each.
    assert_cubes_alike(&bytes, "fan.3mf", &columns, 20..=30, "column");
}
