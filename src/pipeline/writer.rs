//! The native layer writer: every layer planned on all cores and written in ascending order,
//! a window of layers at a time, with an optional per-layer stage ([`LayerSink`]).
#![cfg(not(target_arch = "wasm32"))]

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

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
pub fn write_gcode<W: std::io::Write + ?Sized>(
    job: &Job,
    out: &mut W,
    progress: impl FnMut(usize, usize),
) -> Result<Summary, Error> {
    write_gcode_with(job, out, progress, &mut ())
}

/// The number of threads [`write_gcode`] plans a job of `layers` layers on.
pub fn writer_threads(layers: usize) -> usize {
    std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(layers.max(1))
}

/// [`write_gcode`] with a [`LayerSink`] run on every layer. The code written is the same as
/// [`write_gcode`]'s.
pub fn write_gcode_with<W, K>(
    job: &Job,
    out: &mut W,
    progress: impl FnMut(usize, usize),
    sink: &mut K,
) -> Result<Summary, Error>
where
    W: std::io::Write + ?Sized,
    K: LayerSink,
{
    out.write_all(job.header(None).as_bytes()).map_err(io)?;
    let n = job.layer_count();
    let threads = writer_threads(n);
    let queue = Queue::new(n, 4 * threads + 4);
    let below = Below::default();
    let states: Vec<K::State> = (0..threads).map(|_| sink.init()).collect();
    let summary = std::thread::scope(|scope| {
        for state in states {
            let (queue, below) = (&queue, &below);
            scope.spawn(move || plan_layers::<K>(job, queue, below, state));
        }
        let result = write_in_order(&queue, out, sink, progress);
        queue.stop();
        result
    })?;
    out.write_all(gcode::footer(&summary, job.settings().support.unit()).as_bytes())
        .map_err(io)?;
    Ok(summary)
}

fn io(e: std::io::Error) -> Error {
    Error::Io(format!("cannot write the code: {e}"))
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// A layer's text, plan (without its moves), sink output, and first and last unit; or why it
/// could not be planned.
type Done<T> = Result<(String, LayerPlan, T, Option<u8>, Option<u8>), String>;

/// The layers between the workers and the writer: the next layer to take, the layers done and
/// not yet written, and how far the writer got (a worker waits while it is a window ahead).
struct Queue<T> {
    n: usize,
    window: usize,
    next: AtomicUsize,
    stop: AtomicBool,
    shared: Mutex<Shared<T>>,
    changed: Condvar,
}

struct Shared<T> {
    done: BTreeMap<usize, Done<T>>,
    written: usize,
}

impl<T> Queue<T> {
    fn new(n: usize, window: usize) -> Self {
        Queue {
            n,
            window,
            next: AtomicUsize::new(0),
            stop: AtomicBool::new(false),
            shared: Mutex::new(Shared {
                done: BTreeMap::new(),
                written: 0,
            }),
            changed: Condvar::new(),
        }
    }

    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
        self.changed.notify_all();
    }

    /// The next layer for a worker, once it is within the window; `None` when all are taken or
    /// the writer stopped.
    fn take(&self) -> Option<usize> {
        let i = self.next.fetch_add(1, Ordering::Relaxed);
        if i >= self.n {
            return None;
        }
        let mut g = lock(&self.shared);
        while i >= g.written + self.window && !self.stopped() {
            g = self.changed.wait(g).unwrap_or_else(|p| p.into_inner());
        }
        (!self.stopped()).then_some(i)
    }

    fn finish(&self, i: usize, done: Done<T>) {
        lock(&self.shared).done.insert(i, done);
        self.changed.notify_all();
    }

    /// Layer `i` once its worker is done with it.
    fn wait_for(&self, i: usize) -> Done<T> {
        let mut g = lock(&self.shared);
        loop {
            if let Some(d) = g.done.remove(&i) {
                g.written = i + 1;
                self.changed.notify_all();
                return d;
            }
            g = self.changed.wait(g).unwrap_or_else(|p| p.into_inner());
        }
    }
}

/// Each layer's region, from its worker to the worker of the layer above (the overhang needs
/// it; slicing it again cost about a fifth of the time). `None`: its worker failed.
#[derive(Default)]
struct Below {
    regions: Mutex<HashMap<usize, Option<Arc<geom::Shapes>>>>,
    published: Condvar,
}

impl Below {
    fn publish(&self, i: usize, region: Option<Arc<geom::Shapes>>) {
        lock(&self.regions).insert(i, region);
        self.published.notify_all();
    }

    /// Layer `j`'s region from its worker (it took its layer before the one above and
    /// publishes it first thing); `None` if that worker failed or the writer stopped.
    fn take<T>(&self, j: usize, queue: &Queue<T>) -> Option<Arc<geom::Shapes>> {
        let mut g = lock(&self.regions);
        loop {
            if let Some(r) = g.remove(&j) {
                return r;
            }
            if queue.stopped() {
                return None;
            }
            g = self
                .published
                .wait_timeout(g, std::time::Duration::from_millis(20))
                .map_or_else(|p| p.into_inner().0, |r| r.0);
        }
    }
}

/// A worker: takes layers until none is left, plans each and hands its text to the writer.
fn plan_layers<K: LayerSink>(job: &Job, queue: &Queue<K::Out>, below: &Below, mut state: K::State) {
    let needs_below = job.needs_below();
    while let Some(i) = queue.take() {
        // With support on, the plan comes from the supported pass, which sliced every layer
        // already: no section here.
        let section = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            if needs_below {
                job.section(i)
            } else {
                Section::default()
            }
        }));
        if needs_below {
            let mine = section.as_ref().ok().map(|s| Arc::new(s.region.clone()));
            below.publish(i, mine);
        }
        let region_below = match i.checked_sub(1) {
            Some(j) if needs_below => below.take(j, queue),
            _ => None,
        };
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let section = section.unwrap_or_else(|p| std::panic::resume_unwind(p));
            plan_one::<K>(job, i, section, region_below.as_deref(), &mut state)
        }))
        .map_err(|e| {
            e.downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| e.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a layer could not be planned".into())
        });
        queue.finish(i, result);
    }
}

/// Layer `i`'s text, its plan without the moves, the sink's output and its first and last unit.
fn plan_one<K: LayerSink>(
    job: &Job,
    i: usize,
    section: Section,
    below: Option<&geom::Shapes>,
    state: &mut K::State,
) -> (String, LayerPlan, K::Out, Option<u8>, Option<u8>) {
    let (mut p, region) = job.plan_layer_with(i, section, below);
    let text = stages::time(Stage::Text, || gcode::layer_text(&p));
    let extra = stages::time(Stage::Sink, || K::per_layer(state, i, &region, &p));
    let units = (p.first_unit(), p.moves.last().map(|m| m.unit));
    p.moves = Vec::new();
    p.unit_regions = Vec::new();
    (text, p, extra, units.0, units.1)
}

/// The writing thread: each layer in ascending order, its unit change at its start, summed and
/// handed to the sink.
fn write_in_order<W, K>(
    queue: &Queue<K::Out>,
    out: &mut W,
    sink: &mut K,
    mut progress: impl FnMut(usize, usize),
) -> Result<Summary, Error>
where
    W: std::io::Write + ?Sized,
    K: LayerSink,
{
    let mut summary = Summary::default();
    // The unit selected after the layers written so far (a file starts with unit 0).
    let mut unit = 0u8;
    for i in 0..queue.n {
        let (mut text, plan, extra, first, last) = queue
            .wait_for(i)
            .map_err(|m| Error::Internal(format!("layer {}: {m}", i + 1)))?;
        // The layer's text has `T` lines only within it; the unit change at its start depends
        // on the layers below.
        if let Some(u) = first
            && u != unit
        {
            gcode::insert_unit_line(&mut text, u);
        }
        unit = last.unwrap_or(unit);
        out.write_all(text.as_bytes()).map_err(io)?;
        summary.add(&plan);
        sink.ordered(i, extra);
        progress(i + 1, queue.n);
    }
    Ok(summary)
}
