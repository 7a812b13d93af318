//! The native layer writer: every layer planned on all cores and written in ascending order,
//! a window of layers at a time, with an optional per-layer stage ([`LayerSink`]).
#![cfg(not(target_arch = "wasm32"))]

use crate::base::error::Error;
use crate::base::geom;
use crate::base::stages::{self, Stage};
use crate::output::gcode;
use crate::output::summary::Summary;
use crate::pipeline::Job;
use crate::slicing::plan::LayerPlan;
use crate::slicing::sink::LayerSink;
use crate::slicing::slice::Section;

/// Plans every layer in parallel and writes header, layers (ascending) and footer to `out`.
/// The header carries placeholders for the droplet counts (see [`gcode::header`]).
///
/// Worker threads take layers in order from a shared counter and may run at most a window of
/// layers ahead of the writer, so memory is bounded by the mesh plus that window, however tall
/// the part. `progress(done, total)` is called after each written layer.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_gcode<W: std::io::Write + ?Sized>(
    job: &Job,
    out: &mut W,
    progress: impl FnMut(usize, usize),
) -> Result<Summary, Error> {
    write_gcode_with(job, out, progress, &mut ())
}

/// [`write_gcode`] with a [`LayerSink`] run on every layer. The code written is the same as
/// [`write_gcode`]'s.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_gcode_with<W, K>(
    job: &Job,
    out: &mut W,
    mut progress: impl FnMut(usize, usize),
    sink: &mut K,
) -> Result<Summary, Error>
where
    W: std::io::Write + ?Sized,
    K: LayerSink,
{
    use std::collections::{BTreeMap, HashMap};
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::{Condvar, Mutex, MutexGuard};

    fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
        m.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// A layer's text, plan (without its moves), sink output, and first and last unit.
    type Done<T> = Result<(String, LayerPlan, T, Option<u8>, Option<u8>), String>;
    struct Shared<T> {
        done: BTreeMap<usize, Done<T>>,
        written: usize,
    }
    let io = |e: std::io::Error| Error::Io(format!("cannot write the code: {e}"));
    // DROPSLICE_STAGES=1: the time of each stage, summed over the threads, to stderr at the end
    let profile = std::env::var_os("DROPSLICE_STAGES").is_some_and(|v| v == "1");
    if profile {
        stages::enable(true);
    }
    let started = std::time::Instant::now();
    out.write_all(job.header(None).as_bytes()).map_err(io)?;
    let n = job.layer_count();
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(n.max(1));
    let window = 4 * threads + 4;
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let shared = Mutex::new(Shared {
        done: BTreeMap::new(),
        written: 0,
    });
    let changed = Condvar::new();
    // Each layer's region, from its worker to the worker of the layer above (the overhang
    // needs it; slicing it again cost about a fifth of the time). `None`: its worker failed.
    let regions: Mutex<HashMap<usize, Option<std::sync::Arc<geom::Shapes>>>> =
        Mutex::new(HashMap::new());
    let published = Condvar::new();
    let needs_below = job.needs_below();
    let mut summary = Summary::default();
    // The unit selected after the layers written so far (a file starts with unit 0).
    let mut unit = 0u8;
    let states: Vec<K::State> = (0..threads).map(|_| sink.init()).collect();
    std::thread::scope(|scope| -> Result<(), Error> {
        for mut state in states {
            let (next, stop, shared, changed) = (&next, &stop, &shared, &changed);
            let (regions, published) = (&regions, &published);
            scope.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= n {
                        break;
                    }
                    {
                        let mut g = shared.lock().unwrap_or_else(|p| p.into_inner());
                        while i >= g.written + window && !stop.load(Ordering::Relaxed) {
                            g = changed.wait(g).unwrap_or_else(|p| p.into_inner());
                        }
                    }
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    // With support on, the plan comes from the supported pass, which sliced
                    // every layer already: no section here.
                    let section = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        if needs_below {
                            job.section(i)
                        } else {
                            Section::default()
                        }
                    }));
                    if needs_below {
                        let mine = section
                            .as_ref()
                            .ok()
                            .map(|s| std::sync::Arc::new(s.region.clone()));
                        lock(regions).insert(i, mine);
                        published.notify_all();
                    }
                    // The region below from its worker (it took its layer before this one and
                    // publishes it first thing); sliced here if that worker failed or stopped.
                    let below = match i.checked_sub(1) {
                        Some(j) if needs_below => {
                            let mut g = lock(regions);
                            loop {
                                if let Some(r) = g.remove(&j) {
                                    break r;
                                }
                                if stop.load(Ordering::Relaxed) {
                                    break None;
                                }
                                g = published
                                    .wait_timeout(g, std::time::Duration::from_millis(20))
                                    .map_or_else(|p| p.into_inner().0, |r| r.0);
                            }
                        }
                        _ => None,
                    };
                    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        let section = section.unwrap_or_else(|p| std::panic::resume_unwind(p));
                        let (mut p, region) = job.plan_layer_with(i, section, below.as_deref());
                        let text = stages::time(Stage::Text, || gcode::layer_text(&p));
                        let extra =
                            stages::time(Stage::Sink, || K::per_layer(&mut state, i, &region, &p));
                        let units = (p.first_unit(), p.moves.last().map(|m| m.unit));
                        p.moves = Vec::new();
                        p.unit1_region = geom::Shapes::new();
                        (text, p, extra, units.0, units.1)
                    }))
                    .map_err(|e| {
                        e.downcast_ref::<&str>()
                            .map(|s| s.to_string())
                            .or_else(|| e.downcast_ref::<String>().cloned())
                            .unwrap_or_else(|| "a layer could not be planned".into())
                    });
                    let mut g = shared.lock().unwrap_or_else(|p| p.into_inner());
                    g.done.insert(i, result);
                    changed.notify_all();
                }
            });
        }
        let result = (|| {
            for i in 0..n {
                let done = {
                    let mut g = shared.lock().unwrap_or_else(|p| p.into_inner());
                    loop {
                        if let Some(d) = g.done.remove(&i) {
                            g.written = i + 1;
                            changed.notify_all();
                            break d;
                        }
                        g = changed.wait(g).unwrap_or_else(|p| p.into_inner());
                    }
                };
                let (mut text, plan, extra, first, last) =
                    done.map_err(|m| Error::Internal(format!("layer {}: {m}", i + 1)))?;
                // The layer's text has `T` lines only within it; the unit change at its start
                // depends on the layers below.
                if let Some(u) = first
                    && u != unit
                {
                    gcode::insert_unit_line(&mut text, u);
                }
                unit = last.unwrap_or(unit);
                out.write_all(text.as_bytes()).map_err(io)?;
                summary.add(&plan);
                sink.ordered(i, extra);
                progress(i + 1, n);
            }
            Ok(())
        })();
        stop.store(true, Ordering::Relaxed);
        changed.notify_all();
        result
    })?;
    out.write_all(gcode::footer(&summary).as_bytes())
        .map_err(io)?;
    if profile {
        let parts: Vec<String> = stages::read()
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.0}"))
            .collect();
        eprintln!(
            "stages (ms, summed over {threads} threads): {}; the writer's wall {:.0}",
            parts.join(", "),
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(summary)
}
