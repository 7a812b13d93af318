//! The thin WebAssembly facade used by the page's web workers (`www/worker/worker.ts`).
//!
//! One [`Session`] per worker owns one prepared [`Job`]; the worker asks it for layers by index
//! and gets flat typed arrays (droplet centres, roles, travel moves) and the layer's G-code text,
//! never a JS object per point. Everything else crosses as typed values through
//! serde-wasm-bindgen (plain JS objects, never JSON text): settings go in as an object; info,
//! summaries, figures, layer analyses, the schema and the defaults come out as objects. An
//! error is thrown as a plain object `{kind, message, setting?}` ([`ErrorReport`]: `kind` from
//! [`Error::kind`], `setting` the setting's name), so the page can tell the user's mistakes
//! from bugs; a value that cannot be converted is an internal error, never a silent default.
//! A panic is reported to `globalThis.dropslicePanic` (if the worker defined it) and to the
//! console, and the worker turns the trap that follows into an error message.
//!
//! The model comes in as a `File` read in the worker ([`Session::from_file`], `FileReaderSync`),
//! so the page's thread never copies its bytes. The job worker prepares the job from its
//! import of the files in short calls ([`Session::begin`]) and hands it to the others as
//! bytes ([`Session::prepared`], [`Session::from_prepared`]).
//!
//! The core knows nothing of wasm; this file only converts.

mod ahead;
mod cut;
mod layer;
mod models;
pub mod reader;
mod steps;
mod tally;

pub use layer::LayerResult;
pub use models::{Models, check_profile};
use models::{job_of, read_file};
use steps::{JsBytes, JsDraft, Preparing, Taking, Writing};
pub use tally::Tally;

use crate::Job;
use crate::analysis;
use crate::base::error::{Error, ErrorReport};
use crate::base::settings::{self, Settings};
use crate::base::stages::{self, Stage};
use crate::base::steps::{Budget, Stepped};
use crate::model::spec as job;
use crate::output::gcode;
use crate::output::summary::{Figures, Summary};
use crate::slicing::plan::LayerPlan;
use js_sys::Uint8Array;
use serde::Serialize;
use wasm_bindgen::prelude::*;

/// Cells of the void overlay's mask per droplet width B (cells of B/4: ~0.05 mm by default).
pub const MASK_CELLS_PER_B: f64 = 4.0;

/// The error as thrown to JS: a plain object `{kind, message, setting?}`.
pub fn js_error(e: Error) -> JsValue {
    let report = e.report();
    report
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .unwrap_or_else(|_| {
            // Cannot happen for this plain struct; still an error, never a silent value.
            let o = js_sys::Object::new();
            let _ = js_sys::Reflect::set(&o, &"kind".into(), &report.kind.into());
            let _ = js_sys::Reflect::set(&o, &"message".into(), &report.message.into());
            o.into()
        })
}

/// A value for JS (plain objects and arrays, `null` for `None`); a failure is an internal error.
pub(crate) fn to_js<T: Serialize + ?Sized>(value: &T, what: &str) -> Result<JsValue, JsValue> {
    value
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| {
            js_error(Error::Internal(format!(
                "cannot pass {what} to the page: {e}"
            )))
        })
}

/// A value from JS; a failure is an internal error (the page sent what the core did not make).
fn from_js<T: serde::de::DeserializeOwned>(value: JsValue, what: &str) -> Result<T, JsValue> {
    serde_wasm_bindgen::from_value(value)
        .map_err(|e| js_error(Error::Internal(format!("bad {what} from the page: {e}"))))
}

/// Settings from a JS object `{name: value, ...}` (missing names: defaults), validated.
fn settings_of(value: JsValue) -> Result<Settings, JsValue> {
    let value: serde_json::Value = serde_wasm_bindgen::from_value(value).map_err(|e| {
        js_error(Error::Setting {
            name: String::new(),
            message: format!("the settings are not a plain object of values: {e}"),
        })
    })?;
    Settings::from_value(value).map_err(js_error)
}

fn report_panic(info: &std::panic::PanicHookInfo<'_>) {
    console_error_panic_hook::hook(info);
    let global = js_sys::global();
    if let Ok(f) = js_sys::Reflect::get(&global, &JsValue::from_str("dropslicePanic"))
        && let Some(f) = f.dyn_ref::<js_sys::Function>()
    {
        let _ = f.call1(&JsValue::NULL, &JsValue::from_str(&info.to_string()));
    }
}

/// Runs once when the module is instantiated.
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(report_panic));
}

/// The core's version (`dropslice::VERSION`).
#[wasm_bindgen]
pub fn version() -> String {
    crate::base::VERSION.to_string()
}

/// A point or vector in the plane as serde writes glam's `DVec2` (the analysis' centroids,
/// boxes and deviations): `[x, y]`, mm. The other types of the values the core hands out are
/// declared by their `Tsify` derives.
#[wasm_bindgen(typescript_custom_section)]
const POINT_TS: &str = r#"/** A point in the plane, mm: [x, y]. */
export type Point = [number, number];"#;

/// The settings table: `[{name, kind, unit, min, max, min_exclusive, choices, group,
/// description, part, profile, layout, default}]`.
#[wasm_bindgen(unchecked_return_type = "SettingSpec[]")]
pub fn settings_schema() -> Result<JsValue, JsValue> {
    to_js(&settings::schema(), "the settings schema")
}

/// What the page checks a job's parts against: every number a part carries with its range
/// (the settings flagged `part`, then copies and unit) and the most parts and instances.
#[wasm_bindgen(unchecked_return_type = "JobSchema")]
pub fn job_schema() -> Result<JsValue, JsValue> {
    to_js(&job::job_schema(), "the job schema")
}

/// The default settings: `{name: value, ...}`.
#[wasm_bindgen(unchecked_return_type = "Record<string, number | boolean | string>")]
pub fn default_settings() -> Result<JsValue, JsValue> {
    to_js(&Settings::default(), "the default settings")
}

/// Turns the core's per-stage time counters on (from zero) or off ([`crate::base::stages`]):
/// the page's per-stage profile (docs/performance.md), off unless a benchmark asks.
#[wasm_bindgen]
pub fn profile_stages(on: bool) {
    stages::enable(on);
}

/// The core's time per stage since [`profile_stages`] turned the counters on:
/// `{prepare, section, plan, overhang, support, text, preview, sink}`, ms.
#[wasm_bindgen(unchecked_return_type = "Record<string, number>")]
pub fn stage_times() -> Result<JsValue, JsValue> {
    let map: std::collections::BTreeMap<&str, f64> = stages::read().into_iter().collect();
    to_js(&map, "the stage times")
}

/// Panics on purpose: lets the page's tests check that a crash becomes an error message.
#[doc(hidden)]
#[wasm_bindgen]
pub fn crash_for_test() {
    panic!("crash_for_test was called");
}

/// Checks settings; returns the validated settings (all names) or throws `{kind: "setting",
/// message, setting}`.
#[wasm_bindgen]
pub fn check_settings(settings: JsValue) -> Result<JsValue, JsValue> {
    let s = settings_of(settings)?;
    to_js(&s, "the settings")
}

/// Merges the summaries of the units of a slice (any order) into one.
#[wasm_bindgen(unchecked_return_type = "Summary")]
pub fn merge_summaries(
    #[wasm_bindgen(unchecked_param_type = "Summary[]")] parts: JsValue,
) -> Result<JsValue, JsValue> {
    let parts: Vec<Summary> = from_js(parts, "summaries")?;
    to_js(&Summary::merged(&parts), "a summary")
}

/// The overhang overlay (docs/support.md "The rule", [`crate::support::unsupported_droplets`]):
/// per droplet of a layer (`droplets` x,y pairs, `units` its discharge units) 1 if no droplet
/// of the layer below (`below`, `below_units`) lies within B_d/2 + `limit_mm`, else 0; B_d is
/// `widths[u]` for unit u (`[B, B₁]`), `limit_mm` = `overhang_limit`·B. `on_plate`: the layer is
/// the first (every droplet supported). Throws `{kind: "internal"}` on arrays that do not pair
/// up, a unit other than 0 or 1, or a width or coordinate that is not a finite number.
#[wasm_bindgen]
pub fn unsupported_droplets(
    droplets: &[f32],
    units: &[u8],
    below: &[f32],
    below_units: &[u8],
    widths: &[f64],
    limit_mm: f64,
    on_plate: bool,
) -> Result<Uint8Array, JsValue> {
    let bad = |m: &str| js_error(Error::Internal(format!("overhang overlay: {m}")));
    if droplets.len() != 2 * units.len() || below.len() != 2 * below_units.len() {
        return Err(bad("the droplets and their units do not pair up"));
    }
    let [b, b1] = widths else {
        return Err(bad("two droplet widths are needed, B and B₁"));
    };
    let (b, b1) = (*b, *b1);
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !(positive(b) && positive(b1) && limit_mm.is_finite() && limit_mm >= 0.0) {
        return Err(bad(
            "the droplet widths must be positive and the limit at least 0",
        ));
    }
    if units.iter().chain(below_units).any(|&u| u > 1) {
        return Err(bad("a droplet's unit is neither 0 nor 1"));
    }
    if !droplets.iter().chain(below).all(|v| v.is_finite()) {
        return Err(bad("a droplet centre is not a number"));
    }
    let layer: Vec<[f64; 2]> = droplets
        .chunks_exact(2)
        .map(|c| [c[0] as f64, c[1] as f64])
        .collect();
    let under: Vec<([f64; 2], f64)> = below
        .chunks_exact(2)
        .zip(below_units)
        .map(|(c, &u)| ([c[0] as f64, c[1] as f64], if u == 1 { b1 } else { b }))
        .collect();
    let mask =
        crate::support::unsupported_droplets(&layer, (!on_plate).then_some(&under[..]), limit_mm);
    let bytes: Vec<u8> = mask.into_iter().map(u8::from).collect();
    Ok(Uint8Array::from(&bytes[..]))
}

/// The 3D view's overhang tint for `settings`: a face whose unit normal (plate coordinates, z
/// up) has z below minus this overhangs ([`crate::support::overhang_face_normal_z`]).
#[wasm_bindgen]
pub fn overhang_face_normal_z(settings: JsValue) -> Result<f64, JsValue> {
    let s = settings_of(settings)?;
    Ok(crate::support::overhang_face_normal_z(&s))
}

/// A job (`{settings, parts}`, the job file's JSON) from a JS object.
impl Session {
    fn check_layer(&self, i: usize) -> Result<(), JsValue> {
        if i >= self.job.layer_count() {
            return Err(js_error(Error::Internal(format!(
                "layer {i} asked for, but the part has {} layers",
                self.job.layer_count()
            ))));
        }
        Ok(())
    }

    fn with(job: Job) -> Session {
        let settings = job.settings().clone();
        Session {
            unit_after: std::cell::Cell::new(None),
            last_section: std::cell::RefCell::new(None),
            ahead: std::cell::RefCell::new(None),
            raster: std::cell::RefCell::new(analysis::Raster::empty()),
            stage: std::sync::Arc::new(analysis::LayerStage::new(&job.analysis_grid(), &settings)),
            analysis_refused: job.analysis_grid().check(&settings).err(),
            job: std::rc::Rc::new(job),
            support_pass: std::cell::RefCell::new(None),
            settings,
            draft: false,
            as_drafted: None,
        }
    }

    /// An internal error while this session is a draft not confirmed: `what` needs the job's
    /// final info.
    fn not_draft(&self, what: &str) -> Result<(), JsValue> {
        match self.draft {
            false => Ok(()),
            true => Err(js_error(Error::Internal(format!(
                "{what} asked of a draft of the job not confirmed yet"
            )))),
        }
    }

    /// Plans layer `i` and writes its text after the unit the layers below leave selected: the
    /// unit after the layer this session planned last if that was layer i − 1 (the layers of a
    /// unit of work come in order), else [`Job::unit_before`] (which plans the layers below
    /// again, only when the job uses unit 1).
    fn planned(&self, i: usize) -> (LayerPlan, crate::base::geom::Shapes, String) {
        let (plan, region) = if self.job.needs_below() {
            // The overhang figure needs the layer below's section: the one this session sliced
            // last when that was layer i − 1 (a unit of work's layers come in order), else
            // `overhang_of` slices it (once per unit of work); made ahead by `layer_ahead`.
            let ahead = self.ahead.borrow_mut().take().filter(|a| a.layer == i);
            let (section, unsupported) = match ahead {
                Some(a) => (a.section, a.unsupported),
                None => (self.job.section(i), None),
            };
            let mine = section.region.clone();
            let mut last = self.last_section.borrow_mut();
            let below = last.take().filter(|(j, _)| j + 1 == i).map(|(_, r)| r);
            let unsupported =
                unsupported.unwrap_or_else(|| self.job.overhang_of(i, &section, below.as_ref()));
            let planned = self.job.plan_layer_overhang(i, section, unsupported);
            *last = Some((i, mine));
            planned
        } else {
            self.job.plan_layer_and_region(i)
        };
        let before = match self.unit_after.get() {
            Some((j, u)) if j + 1 == i => u,
            _ => self.job.unit_before(i),
        };
        self.unit_after.set(Some((i, plan.unit_after(before))));
        let text = stages::time(Stage::Text, || gcode::layer_text_after(&plan, before));
        (plan, region, text)
    }
}

/// The figures of a slice as the page shows them: the merged summary (to keep instead of its
/// parts), its figures, and "nothing to print" once every layer is in.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Serialize)]
struct SliceFigures {
    summary: Summary,
    figures: Figures,
    nothing_to_print: Option<ErrorReport>,
}

/// The supported pass being made in steps, and its budget.
type SupportPass = (std::rc::Rc<Budget>, Stepped<()>);

/// One prepared slicing job: the parsed, transformed mesh and its settings.
#[wasm_bindgen]
pub struct Session {
    /// Shared with the supported pass while it runs in steps ([`Session::support_step`]).
    pub(crate) job: std::rc::Rc<Job>,
    /// The supported pass in steps, while it runs, and its budget.
    support_pass: std::cell::RefCell<Option<SupportPass>>,
    pub(crate) settings: Settings,
    /// The last layer planned and the unit selected after it.
    unit_after: std::cell::Cell<Option<(usize, u8)>>,
    /// The last layer planned with support off and its section's region (the overhang figure
    /// of the next layer needs it).
    last_section: std::cell::RefCell<Option<(usize, crate::base::geom::Shapes)>>,
    /// A layer's section and then its overhang figure, made ahead of its plan in calls of
    /// their own ([`Session::layer_ahead`]).
    ahead: std::cell::RefCell<Option<ahead::Ahead>>,
    /// The raster every analysed layer is rebuilt into (its memory kept between layers).
    raster: std::cell::RefCell<analysis::Raster>,
    /// The 3D estimate's stage (its grids are the job's).
    pub(crate) stage: std::sync::Arc<analysis::LayerStage>,
    /// Why the job's layers are not analysed (too large for the analysis' memory,
    /// [`analysis::AnalysisGrid::check`]), if they are not.
    analysis_refused: Option<Error>,
    /// A draft's job not confirmed yet ([`Session::from_draft`]): its layers are the job's,
    /// its info is not.
    draft: bool,
    /// Whether the job is its draft's ([`Session::begin_drafted`]; `None`: no draft made).
    as_drafted: Option<bool>,
}

#[wasm_bindgen]
impl Session {
    /// Parses the STL bytes and prepares the job (tests and Node; the page uses
    /// [`Session::from_file`]). Throws `{kind, message, setting?}`.
    #[wasm_bindgen(constructor)]
    pub fn new(stl: &[u8], file_name: &str, settings: JsValue) -> Result<Session, JsValue> {
        let settings = settings_of(settings)?;
        let job = Job::new(stl, file_name, settings).map_err(js_error)?;
        Ok(Session::with(job))
    }

    /// Reads the model from a `File` (in a worker: `FileReaderSync`, so the page's thread
    /// never copies it) and prepares the job.
    pub fn from_file(file: web_sys::File, settings: JsValue) -> Result<Session, JsValue> {
        let settings = settings_of(settings)?;
        let bytes = read_file(&file)?;
        let job = stages::time(Stage::Prepare, || Job::new(&bytes, &file.name(), settings))
            .map_err(js_error)?;
        Ok(Session::with(job))
    }

    /// The build job `job` (`{settings, parts}`, as in a job file) of the files in `models`:
    /// every instance placed as [`Models::layout`] says and merged into one mesh; its settings
    /// are `job.settings`. The same files and job give the same session in every worker.
    pub fn from_models(models: &Models, job: JsValue) -> Result<Session, JsValue> {
        let spec = job_of(job)?;
        let job = stages::time(Stage::Prepare, || Job::from_models(&models.models, &spec))
            .map_err(js_error)?;
        Ok(Session::with(job))
    }

    /// [`Session::from_models`] in short calls (the page's engine keeps a running call's
    /// first code to its end, so later calls get the well-compiled code): this call reads the
    /// job; [`Preparing::step`] works through a budget of items a call (weld, placing,
    /// shells, facet index, statistics, checks) until it returns true;
    /// [`Session::from_preparation`] takes the job. The same job as `from_models`.
    pub fn begin(models: &Models, job: JsValue) -> Result<Preparing, JsValue> {
        let spec = job_of(job)?;
        let prep = Job::prepare_in_steps(models.models.clone(), &spec);
        Ok(Preparing {
            prep,
            job: None,
            draft: Default::default(),
        })
    }

    /// [`Session::begin`] that also makes a draft of the job as soon as its parts are merged
    /// (before the shells, their orientation, the repairs and the checks):
    /// [`Preparing::take_draft`] hands it out, written in steps of its own (a budget of items
    /// a step) straight into a buffer outside the module's memory; the other workers slice from it ([`Session::from_draft`])
    /// while this preparation goes on. Once the job is made, [`Session::confirmation`] says
    /// whether it is the draft's.
    pub fn begin_drafted(models: &Models, job: JsValue) -> Result<Preparing, JsValue> {
        let spec = job_of(job)?;
        let draft: std::rc::Rc<std::cell::RefCell<Option<Uint8Array>>> = Default::default();
        let sink = JsDraft {
            buf: None,
            out: draft.clone(),
        };
        let to = crate::pipeline::DraftTo::Steps(Box::new(sink));
        let prep = Job::prepare_drafted_to(models.models.clone(), &spec, Some(to));
        Ok(Preparing {
            prep,
            job: None,
            draft,
        })
    }

    /// The session of a finished preparation ([`Session::begin`]); `internal` if it has not
    /// ended (every step returned false so far).
    pub fn from_preparation(preparing: Preparing) -> Result<Session, JsValue> {
        let as_drafted = preparing.prep.as_drafted();
        match preparing.job {
            Some(job) => {
                let mut s = Session::with(job);
                s.as_drafted = as_drafted;
                Ok(s)
            }
            None => Err(js_error(Error::Internal(
                "the job's preparation has not ended".into(),
            ))),
        }
    }

    /// When the job is its draft's ([`Session::begin_drafted`]: no repair changed the merged
    /// mesh): the confirmation for the draft's workers ([`Session::confirm`], a few kB: the
    /// final settings and info); else `undefined` (they need [`Session::prepared`]).
    pub fn confirmation(&self) -> Option<Uint8Array> {
        (self.as_drafted == Some(true)).then(|| Uint8Array::from(&self.job.confirmation()[..]))
    }

    /// A session of the job worker's draft ([`Session::begin_drafted`]), read a run at a time
    /// out of the message's buffer (never copied whole into the module's memory). It plans layers as the
    /// finished job will if [`Session::confirm`] takes the job worker's confirmation; until
    /// then it answers nothing that needs the job's info (header, figures, the analysis).
    /// Throws `{kind: "internal", message}` if the bytes are damaged.
    pub fn from_draft(bytes: Uint8Array) -> Result<Session, JsValue> {
        let source = JsBytes(bytes);
        let job = stages::time(Stage::Prepare, || Job::from_draft(&source)).map_err(js_error)?;
        let mut s = Session::with(job);
        s.draft = true;
        Ok(s)
    }

    /// [`Session::from_prepared`] (or, with `draft`, [`Session::from_draft`]) in short calls:
    /// this call only takes the bytes; [`Taking::step`] reads a budget of items a call until
    /// it returns true; [`Session::from_taken`] makes the session. The same session.
    pub fn begin_take(bytes: Uint8Array, draft: bool) -> Taking {
        let budget = std::rc::Rc::new(Budget::new(0));
        let b = budget.clone();
        let source = JsBytes(bytes);
        Taking {
            budget,
            pass: Some(Stepped::new(async move {
                Job::take_in_steps(&source, draft, &b).await
            })),
            job: None,
            draft,
        }
    }

    /// The session of a job taken in short calls ([`Session::begin_take`]); `internal` if
    /// it has not been read to its end.
    pub fn from_taken(taking: Taking) -> Result<Session, JsValue> {
        let job = taking
            .job
            .ok_or_else(|| Error::Internal("the job has not been taken to its end".into()))
            .and_then(|read| read)
            .map_err(js_error)?;
        let mut s = Session::with(job);
        s.draft = taking.draft;
        Ok(s)
    }

    /// Takes the job worker's confirmation ([`Session::confirmation`]) into a draft's
    /// session: its final info; the layers planned so far stand. Throws `{kind: "internal"}`
    /// (the session left as it was) if it is not this draft's.
    pub fn confirm(&mut self, table: Uint8Array) -> Result<(), JsValue> {
        let internal = |m: &str| js_error(Error::Internal(m.into()));
        if !self.draft {
            return Err(internal("a confirmation for a session that is no draft"));
        }
        let job = std::rc::Rc::get_mut(&mut self.job)
            .ok_or_else(|| internal("a confirmation while the supported pass runs"))?;
        job.confirm(&JsBytes(table)).map_err(js_error)?;
        let (grid, settings) = (job.analysis_grid(), job.settings().clone());
        self.stage = std::sync::Arc::new(analysis::LayerStage::new(&grid, &settings));
        self.analysis_refused = grid.check(&settings).err();
        self.draft = false;
        Ok(())
    }

    /// The prepared job as bytes ([`Job::to_bytes`]), for [`Session::from_prepared`] in the
    /// page's other workers: they take this worker's preparation instead of repeating it.
    /// Written a run at a time straight into a new buffer outside the module's memory, so
    /// this worker never holds the job twice. (Not counted as `Prepare`: the worker times it
    /// on its own line of the profile.)
    pub fn prepared(&self) -> Uint8Array {
        let (size, write) = self.job.bytes_writer();
        let out = Uint8Array::new_with_length(size as u32);
        write(&mut JsBytes(out.clone()));
        out
    }

    /// [`Session::prepared`] in short calls: [`Writing::step`] writes a budget of items a
    /// call, then [`Writing::take`] gives the bytes (the same bytes).
    pub fn begin_prepared(&self) -> Writing {
        let budget = std::rc::Rc::new(Budget::new(0));
        let (job, b) = (self.job.clone(), budget.clone());
        Writing {
            budget,
            pass: Some(Stepped::new(async move {
                let out = job.bytes_out();
                let mut sink = JsBytes(Uint8Array::new_with_length(out.size() as u32));
                out.write(&mut sink, &b).await;
                sink.0
            })),
            bytes: None,
        }
    }

    /// The job another worker prepared ([`Session::prepared`]), read a run at a time out of
    /// the message's buffer (never copied whole into the module's memory). Throws `{kind:
    /// "internal", message}` if the bytes are damaged.
    pub fn from_prepared(bytes: Uint8Array) -> Result<Session, JsValue> {
        let source = JsBytes(bytes);
        let job = stages::time(Stage::Prepare, || Job::read_bytes(&source)).map_err(js_error)?;
        Ok(Session::with(job))
    }

    /// Works through about `items` layers' worth of the supported pass (`support = unitN`:
    /// every layer's plan with the support, which the first layer planned would otherwise
    /// make whole in one call; [`Job::supported_in_steps`]): true once it is made, at once
    /// when the support is off. The page calls it until true before it plans layers.
    pub fn support_step(&self, items: u32) -> bool {
        if !self.job.settings().support.is_on() || self.job.supported_made() {
            return true;
        }
        let mut pass = self.support_pass.borrow_mut();
        let (budget, stepped) = pass.get_or_insert_with(|| {
            let budget = std::rc::Rc::new(Budget::new(0));
            let (job, b) = (self.job.clone(), budget.clone());
            let run = Stepped::new(async move { job.supported_in_steps(&b).await });
            (budget, run)
        });
        budget.refill(items as usize);
        if stepped.step().is_some() {
            *pass = None;
        }
        self.job.supported_made()
    }

    /// Number of layers.
    pub fn layer_count(&self) -> usize {
        self.job.layer_count()
    }

    /// Facets, bounds, layers, droplet width and mesh warnings (`JobInfo`).
    #[wasm_bindgen(unchecked_return_type = "JobInfo")]
    pub fn info(&self) -> Result<JsValue, JsValue> {
        self.not_draft("the job's info")?;
        to_js(self.job.info(), "the job info")
    }

    /// Plans layer `i`: its G-code text, droplet counts and preview arrays.
    pub fn slice_layer(&self, i: usize) -> Result<LayerResult, JsValue> {
        self.check_layer(i)?;
        let (plan, _, text) = self.planned(i);
        Ok(LayerResult::new(&plan, &self.settings, text))
    }

    /// [`Session::slice_layer`] plus the void analysis of the same plan (no second planning):
    /// `analysis` and the coverage mask (cells of B / [`MASK_CELLS_PER_B`]), and what the 3D
    /// estimate needs (a [`Tally`] takes it: [`Session::finish_slabs`]). About 2–3
    /// times the work of planning the layer.
    pub fn slice_layer_analysed(&self, i: usize) -> Result<LayerResult, JsValue> {
        self.check_layer(i)?;
        self.not_draft("the analysis")?;
        if let Some(e) = &self.analysis_refused {
            return Err(js_error(e.clone()));
        }
        let (plan, region, text) = self.planned(i);
        let cell = self.settings.droplet_width() / MASK_CELLS_PER_B;
        let (a, mask) = analysis::analyse_layer_for_page(
            &mut self.raster.borrow_mut(),
            &plan,
            &region,
            &self.settings,
            cell,
        );
        let mut r = LayerResult::new(&plan, &self.settings, text);
        r.slab = Some(Box::new(tally::SlabInput {
            index: i,
            analysis: a.clone(),
            regions: self.stage.regions(&region, &plan),
            maps: stages::time(Stage::Sink, || self.stage.maps_in(&plan, &region)),
            stage: self.stage.clone(),
        }));
        r.analysis = Some(a);
        r.mask = Some(mask);
        Ok(r)
    }

    /// Why the job's layers cannot be analysed (`{kind: "analysis", message}`: a layer would
    /// take more memory than the analysis may, [`analysis::AnalysisGrid::check`]), or `null`:
    /// then [`Session::slice_layer_analysed`] analyses them. The slice is not affected.
    #[wasm_bindgen(unchecked_return_type = "ErrorReport | null")]
    pub fn analysis_refusal(&self) -> JsValue {
        self.analysis_refused
            .clone()
            .map_or(JsValue::NULL, js_error)
    }

    /// The header comment block for a finished slice (`summary`: every unit's summary
    /// merged); `null` gives the same-width placeholder header.
    pub fn header(
        &self,
        #[wasm_bindgen(unchecked_param_type = "Summary | null")] summary: JsValue,
    ) -> Result<String, JsValue> {
        self.not_draft("the header")?;
        if summary.is_null() || summary.is_undefined() {
            return Ok(self.job.header(None));
        }
        let summary: Summary = from_js(summary, "summary")?;
        Ok(self.job.header(Some(&summary)))
    }

    /// The closing comment block.
    pub fn footer(
        &self,
        #[wasm_bindgen(unchecked_param_type = "Summary")] summary: JsValue,
    ) -> Result<String, JsValue> {
        let summary: Summary = from_js(summary, "summary")?;
        Ok(gcode::footer(&summary, self.job.settings().support.unit()))
    }

    /// Merges `parts` (summaries of units, in any order) and computes the figures with this
    /// session's settings: `{summary, figures, nothing_to_print}` (`nothing_to_print` is the
    /// error `{kind, message}` when every layer is in and not one droplet fits, else `null`).
    #[wasm_bindgen(unchecked_return_type = "SliceFigures")]
    pub fn figures(
        &self,
        #[wasm_bindgen(unchecked_param_type = "Summary[]")] parts: JsValue,
    ) -> Result<JsValue, JsValue> {
        self.not_draft("the figures")?;
        let parts: Vec<Summary> = from_js(parts, "summaries")?;
        let summary = Summary::merged(&parts);
        let complete = summary.layers == self.job.layer_count();
        let out = SliceFigures {
            figures: summary.figures(&self.settings),
            nothing_to_print: if complete {
                summary.printable(&self.settings).err().map(|e| e.report())
            } else {
                None
            },
            summary,
        };
        to_js(&out, "the figures")
    }
}
