//! Time per stage of the work (prepare, slice, plan, overhang, support, text, preview, sink),
//! summed over every thread, for the per-stage profile of docs/performance.md. Off unless
//! [`enable`]d: a stage then costs one relaxed atomic load. The CLI turns it on around the
//! writer when the environment has `DROPSLICE_STAGES=1` and prints the table to stderr; the
//! page's workers through the WebAssembly facade's `profile_stages`. A stage inside another (a
//! section sliced while the overhang is figured) counts only in the outer one.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The stages, in the order they are printed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// File read, parsed and prepared into a job (or a job built from another's mesh).
    Prepare,
    /// A layer's cross-section.
    Section,
    /// A layer's plan: offsets, droplets, hatch, order.
    Plan,
    /// A layer's overhang figure.
    Overhang,
    /// The supported pass (every layer's plan with support, sections included).
    Support,
    /// A layer's G-code text.
    Text,
    /// A layer's preview arrays (the page).
    Preview,
    /// A per-layer stage of the writer (the analysis of `--report`).
    Sink,
}

const STAGES: [Stage; 8] = [
    Stage::Prepare,
    Stage::Section,
    Stage::Plan,
    Stage::Overhang,
    Stage::Support,
    Stage::Text,
    Stage::Preview,
    Stage::Sink,
];

impl Stage {
    pub fn name(self) -> &'static str {
        match self {
            Stage::Prepare => "prepare",
            Stage::Section => "section",
            Stage::Plan => "plan",
            Stage::Overhang => "overhang",
            Stage::Support => "support",
            Stage::Text => "text",
            Stage::Preview => "preview",
            Stage::Sink => "sink",
        }
    }
}

static ON: AtomicBool = AtomicBool::new(false);
static NANOS: [AtomicU64; 8] = [const { AtomicU64::new(0) }; 8];

thread_local! {
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

/// Turns the counters on (set to zero) or off.
pub fn enable(on: bool) {
    for n in &NANOS {
        n.store(0, Ordering::Relaxed);
    }
    ON.store(on, Ordering::Relaxed);
}

/// Whether the counters are on.
pub fn enabled() -> bool {
    ON.load(Ordering::Relaxed)
}

/// Runs `f`, adding its time to `stage` when the counters are on.
#[inline]
pub fn time<T>(stage: Stage, f: impl FnOnce() -> T) -> T {
    if !ON.load(Ordering::Relaxed) {
        return f();
    }
    let outer = DEPTH.with(|d| {
        d.set(d.get() + 1);
        d.get() == 1
    });
    // one level down again however `f` ends (a panic is caught by the writer)
    struct Level;
    impl Drop for Level {
        fn drop(&mut self) {
            DEPTH.with(|d| d.set(d.get() - 1));
        }
    }
    let _level = Level;
    let t0 = now_ns();
    let r = f();
    if outer {
        NANOS[stage as usize].fetch_add(now_ns().saturating_sub(t0), Ordering::Relaxed);
    }
    r
}

/// Every stage's time so far, ms.
pub fn read() -> Vec<(&'static str, f64)> {
    STAGES
        .iter()
        .map(|&s| {
            (
                s.name(),
                NANOS[s as usize].load(Ordering::Relaxed) as f64 / 1e6,
            )
        })
        .collect()
}

#[cfg(not(target_arch = "wasm32"))]
fn now_ns() -> u64 {
    use std::sync::OnceLock;
    static T0: OnceLock<std::time::Instant> = OnceLock::new();
    T0.get_or_init(std::time::Instant::now).elapsed().as_nanos() as u64
}

#[cfg(target_arch = "wasm32")]
fn now_ns() -> u64 {
    // `performance.now()` of the worker (ms, fractional)
    let global = js_sys::global();
    let ms = js_sys::Reflect::get(&global, &"performance".into())
        .ok()
        .and_then(|p| {
            let now = js_sys::Reflect::get(&p, &"now".into()).ok()?;
            let now: &js_sys::Function = wasm_bindgen::JsCast::dyn_ref(&now)?;
            now.call0(&p).ok()?.as_f64()
        })
        .unwrap_or(0.0);
    (ms * 1e6) as u64
}
