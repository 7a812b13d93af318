//! The CLI's `--report`: its layers are numbered from 1 (as the G-code's layer comments, the
//! summary line and the page), and a layer too large to analyse is refused before its memory
//! is taken, with the code still written (docs/quality.md, *The report* and *Memory*).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::{TempDir, run_cli};
use std::time::Duration;

/// Slices `model` with `--report` and `sets`: (the run, the report if one was written).
fn report(model: &std::path::Path, sets: &[&str]) -> (common::Run, Option<serde_json::Value>) {
    let dir = TempDir::new("report");
    let (out, rep) = (dir.join("out.gco"), dir.join("r.json"));
    let mut args: Vec<String> = vec![
        model.display().to_string(),
        "-q".into(),
        "-o".into(),
        out.display().to_string(),
        "--report".into(),
        rep.display().to_string(),
    ];
    for s in sets {
        args.push("--set".into());
        args.push(s.to_string());
    }
    let r = run_cli(&args, dir.path(), Duration::from_secs(300));
    let v = std::fs::read_to_string(&rep)
        .ok()
        .map(|t| serde_json::from_str(&t).expect("the report is JSON"));
    (r, v)
}

#[test]
fn the_report_numbers_layers_from_1() {
    let (r, v) = report(&common::model("U_overhang.obj"), &[]);
    assert_eq!(r.code, Some(0), "{r:?}");
    let v = v.expect("a report");
    let layers = v["layers"].as_array().unwrap();
    let index: Vec<u64> = layers
        .iter()
        .map(|l| l["index"].as_u64().unwrap())
        .collect();
    let want: Vec<u64> = (1..=layers.len() as u64).collect();
    assert_eq!(index, want);
    let part = &v["part"];
    // The layer named for the largest overhang is the one whose own figure is that largest.
    let max = part["max_unsupported_area"].as_f64().unwrap();
    assert!(max > 0.0, "{part}");
    let at = part["max_unsupported_area_layer"].as_u64().unwrap();
    let by_layer = |n: u64, key: &str| layers[n as usize - 1][key].clone();
    assert_eq!(
        by_layer(at, "unsupported_area").as_f64(),
        Some(max),
        "{part}"
    );
    // Before it, no layer had as much (the first of the largest is named).
    assert!(
        layers[..at as usize - 1]
            .iter()
            .all(|l| l["unsupported_area"].as_f64().unwrap() < max)
    );
    // The same for the largest void and the largest deviation.
    let at = part["largest_void_layer"].as_u64().unwrap();
    assert_eq!(by_layer(at, "largest_void"), part["largest_void"], "{part}");
    let at = part["max_deviation_layer"].as_u64().unwrap();
    assert_eq!(
        by_layer(at, "boundary_deviation"),
        part["max_boundary_deviation"],
        "{part}"
    );
}
