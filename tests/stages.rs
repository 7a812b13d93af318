//! The per-stage time counters (base::stages): off by default, a stage inside another counts
//! only in the outer one, and the writer's run with them on writes the same code.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target
mod common;
use dropslice::base::stages::{self, Stage};

fn ms(name: &str) -> f64 {
    stages::read()
        .into_iter()
        .find(|(n, _)| *n == name)
        .map_or(f64::NAN, |(_, v)| v)
}

fn spin(d: std::time::Duration) {
    let t = std::time::Instant::now();
    while t.elapsed() < d {
        std::hint::spin_loop();
    }
}

#[test]
fn counters_count_only_when_on_and_only_the_outer_stage() {
    // off: nothing counted
    stages::enable(false);
    stages::time(Stage::Plan, || spin(std::time::Duration::from_millis(5)));
    assert_eq!(ms("plan"), 0.0);
    // on: the outer stage gets the time, the inner one nothing
    stages::enable(true);
    let v = stages::time(Stage::Plan, || {
        stages::time(Stage::Section, || spin(std::time::Duration::from_millis(5)));
        7
    });
    assert_eq!(v, 7);
    assert!(ms("plan") >= 5.0, "plan {} ms", ms("plan"));
    assert_eq!(ms("section"), 0.0);
    // a panic inside a stage leaves the nesting as it was
    let r = std::panic::catch_unwind(|| stages::time(Stage::Text, || panic!("inside")));
    assert!(r.is_err());
    stages::time(Stage::Section, || spin(std::time::Duration::from_millis(2)));
    assert!(ms("section") >= 2.0);
    // every stage is listed, by name, in order
    let names: Vec<&str> = stages::read().into_iter().map(|(n, _)| n).collect();
    assert_eq!(
        names,
        [
            "prepare", "section", "plan", "overhang", "support", "text", "preview", "sink"
        ]
    );
    stages::enable(false);
    assert_eq!(ms("plan"), 0.0);

    // the writer with the counters on: the same bytes, and its stages counted
    let bytes = common::model_bytes("extruder_idler.stl");
    let write = || {
        let job = dropslice::Job::new(&bytes, "extruder_idler.stl", Default::default()).unwrap();
        let mut out = Vec::new();
        dropslice::write_gcode(&job, &mut out, |_, _| {}).unwrap();
        out
    };
    let plain = write();
    stages::enable(true);
    let counted = write();
    assert!(plain == counted, "the code differs with the counters on");
    for name in ["section", "plan", "overhang", "text"] {
        assert!(ms(name) > 0.0, "{name} not counted");
    }
    stages::enable(false);
}
