//! The thin WebAssembly facade used by the page's web workers (`www/worker.ts`).
//!
//! One [`Session`] per worker owns one prepared [`Job`]; the worker asks it for layers by index
//! and gets flat typed arrays (droplet centres, roles, travel moves) and the layer's G-code text,
//! never a JS object per point. Errors cross the boundary as `JsError`s whose message is
//! `"<kind>: <message>"`, `kind` being [`Error::kind`] ("import", "setting", ...), so the page
//! can tell the user's mistakes from bugs. A panic is reported to `globalThis.dropslicePanic`
//! (if the worker defined it) and to the console, and the worker turns the trap that follows
//! into an error message.
//!
//! The core knows nothing of wasm; this file only converts.

use crate::analysis::{self, CoverageMask, LayerAnalysis, MaskTile};
use crate::error::Error;
use crate::gcode;
use crate::plan::{Counts, LayerPlan};
use crate::preview::PreviewLayer;
use crate::settings::{self, Settings};
use crate::{Job, Summary};
use js_sys::{Float32Array, Float64Array, Uint8Array};
use wasm_bindgen::prelude::*;

/// Cells of the void overlay's mask per droplet width B (cells of B/4: ~0.05 mm by default).
pub const MASK_CELLS_PER_B: f64 = 4.0;

fn js_error(e: Error) -> JsError {
    JsError::new(&format!("{}: {e}", e.kind()))
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
    crate::VERSION.to_string()
}

/// The settings table as JSON: `[{name, kind, unit, min, max, min_exclusive, choices, group,
/// description, default}]`.
#[wasm_bindgen]
pub fn settings_schema() -> String {
    settings::schema_json()
}

/// The default settings as a JSON object.
#[wasm_bindgen]
pub fn default_settings_json() -> String {
    serde_json::to_string(&Settings::default()).unwrap_or_default()
}

/// Panics on purpose: lets the page's tests check that a crash becomes an error message.
#[doc(hidden)]
#[wasm_bindgen]
pub fn crash_for_test() {
    panic!("crash_for_test was called");
}

/// Checks settings JSON; returns the validated settings as JSON (all names) or an error.
#[wasm_bindgen]
pub fn check_settings(settings_json: &str) -> Result<String, JsError> {
    let s = Settings::from_json(settings_json).map_err(js_error)?;
    Ok(serde_json::to_string(&s).unwrap_or_default())
}

impl Session {
    fn check_layer(&self, i: usize) -> Result<(), JsError> {
        if i >= self.job.layer_count() {
            return Err(js_error(Error::Internal(format!(
                "layer {i} asked for, but the part has {} layers",
                self.job.layer_count()
            ))));
        }
        Ok(())
    }
}

fn parse_summary(summary_json: &str) -> Result<Summary, JsError> {
    serde_json::from_str(summary_json)
        .map_err(|e| js_error(Error::Internal(format!("bad summary from the page: {e}"))))
}

/// One prepared slicing job: the parsed, transformed mesh and its settings.
#[wasm_bindgen]
pub struct Session {
    job: Job,
    settings: Settings,
}

#[wasm_bindgen]
impl Session {
    /// Parses the STL and prepares the job. Errors: `"import: ..."`, `"setting: ..."`, ...
    #[wasm_bindgen(constructor)]
    pub fn new(stl: &[u8], file_name: &str, settings_json: &str) -> Result<Session, JsError> {
        let settings = Settings::from_json(settings_json).map_err(js_error)?;
        let job = Job::new(stl, file_name, settings.clone()).map_err(js_error)?;
        Ok(Session { job, settings })
    }

    /// Number of layers.
    pub fn layer_count(&self) -> usize {
        self.job.layer_count()
    }

    /// Facets, bounds, layers and mesh warnings as JSON.
    pub fn info_json(&self) -> String {
        serde_json::to_string(self.job.info()).unwrap_or_default()
    }

    /// Plans layer `i`: its G-code text, droplet counts and preview arrays.
    pub fn slice_layer(&self, i: usize) -> Result<LayerResult, JsError> {
        self.check_layer(i)?;
        let plan = self.job.plan_layer(i);
        Ok(LayerResult::new(&plan, &self.settings))
    }

    /// [`Session::slice_layer`] plus the void analysis of the same plan (no second planning):
    /// `analysis_json` and the coverage mask (cells of B / [`MASK_CELLS_PER_B`]). About 2–3
    /// times the work of planning the layer.
    pub fn slice_layer_analysed(&self, i: usize) -> Result<LayerResult, JsError> {
        self.check_layer(i)?;
        let (plan, region) = self.job.plan_layer_and_region(i);
        let cell = self.settings.droplet_width() / MASK_CELLS_PER_B;
        let (a, mask) = analysis::analyse_layer_with_mask(&plan, &region, &self.settings, cell);
        let mut r = LayerResult::new(&plan, &self.settings);
        r.analysis = Some(a);
        r.mask = Some(mask);
        Ok(r)
    }

    /// The header comment block for a finished slice: `summary_json` is the sum of every
    /// layer's `LayerResult::summary_json` with `layers` set; an empty string gives the
    /// same-width placeholder header.
    pub fn header(&self, summary_json: &str) -> Result<String, JsError> {
        if summary_json.trim().is_empty() {
            return Ok(self.job.header(None));
        }
        let summary = parse_summary(summary_json)?;
        Ok(self.job.header(Some(&summary)))
    }

    /// What slicing repaired (open sections joined, flipped facets), as a JSON array of
    /// sentences, for the summed summary of a finished slice.
    pub fn repairs(&self, summary_json: &str) -> Result<String, JsError> {
        let summary = parse_summary(summary_json)?;
        Ok(serde_json::to_string(&summary.repairs()).unwrap_or_default())
    }

    /// The closing comment block.
    pub fn footer(&self, summary_json: &str) -> Result<String, JsError> {
        let summary = parse_summary(summary_json)?;
        Ok(gcode::footer(&summary))
    }
}

/// One planned layer, ready to be posted to the page.
#[wasm_bindgen]
pub struct LayerResult {
    index: usize,
    z: f64,
    counts: Counts,
    travel_mm: f64,
    summary: Summary,
    gcode: String,
    preview: PreviewLayer,
    analysis: Option<LayerAnalysis>,
    mask: Option<CoverageMask>,
}

impl LayerResult {
    fn new(plan: &LayerPlan, settings: &Settings) -> LayerResult {
        LayerResult {
            index: plan.index,
            z: plan.z,
            counts: plan.counts,
            travel_mm: plan.travel_mm,
            summary: {
                let mut s = Summary::default();
                s.add(plan);
                s
            },
            gcode: gcode::layer_text(plan),
            preview: PreviewLayer::from_plan(plan, settings.droplet_width()),
            analysis: None,
            mask: None,
        }
    }
}

#[wasm_bindgen]
impl LayerResult {
    #[wasm_bindgen(getter)]
    pub fn index(&self) -> usize {
        self.index
    }
    #[wasm_bindgen(getter)]
    pub fn z(&self) -> f64 {
        self.z
    }
    /// Droplets of the outermost loops.
    #[wasm_bindgen(getter)]
    pub fn outer(&self) -> f64 {
        self.counts.outer as f64
    }
    /// Droplets of the inner loops.
    #[wasm_bindgen(getter)]
    pub fn inner(&self) -> f64 {
        self.counts.inner as f64
    }
    /// Fill droplets.
    #[wasm_bindgen(getter)]
    pub fn fill(&self) -> f64 {
        self.counts.fill as f64
    }
    /// Total length of the layer's travel moves in mm.
    #[wasm_bindgen(getter)]
    pub fn travel_mm(&self) -> f64 {
        self.travel_mm
    }
    /// This layer's share of the slice's [`Summary`] as JSON (`layers` is 0): the page adds
    /// the numbers of all layers up, sets `layers`, and hands the sum to `Session::header`.
    #[wasm_bindgen(getter)]
    pub fn summary_json(&self) -> String {
        serde_json::to_string(&self.summary).unwrap_or_default()
    }
    /// The layer's G-code lines as UTF-8 bytes (a copy; the worker collects a run of layers
    /// into one Blob: a Blob per layer costs far more than the bytes).
    #[wasm_bindgen(getter)]
    pub fn gcode(&self) -> Uint8Array {
        Uint8Array::from(self.gcode.as_bytes())
    }
    /// Droplet centres, x,y pairs in mm (a copy; its buffer can be transferred).
    #[wasm_bindgen(getter)]
    pub fn droplets(&self) -> Float32Array {
        Float32Array::from(&self.preview.droplets[..])
    }
    /// Role per droplet: 0 outermost loop, 1 inner loops, 2 fill.
    #[wasm_bindgen(getter)]
    pub fn roles(&self) -> Uint8Array {
        Uint8Array::from(&self.preview.roles[..])
    }
    /// Travel moves, x0,y0,x1,y1 per move, in mm.
    #[wasm_bindgen(getter)]
    pub fn travel(&self) -> Float32Array {
        Float32Array::from(&self.preview.travel[..])
    }
    /// The layer's void analysis (`analysis::LayerAnalysis`: coverage, void_area,
    /// largest_void {area, centroid, min, max, at_boundary}, overfill_area,
    /// boundary_deviation, ...) as JSON; empty unless made by `slice_layer_analysed`.
    #[wasm_bindgen(getter)]
    pub fn analysis_json(&self) -> String {
        self.analysis
            .as_ref()
            .and_then(|a| serde_json::to_string(a).ok())
            .unwrap_or_default()
    }
    /// The coverage mask's cell, mm; 0 without analysis.
    #[wasm_bindgen(getter)]
    pub fn mask_cell(&self) -> f64 {
        self.mask.as_ref().map_or(0.0, |m| m.cell)
    }
    /// The coverage mask's tiles (only where the layer's region and droplets are): per tile
    /// origin x, origin y (mm), width, height (cells); cell (col, row) of a tile starts at its
    /// origin + (col, row)·cell. Empty without analysis.
    #[wasm_bindgen(getter)]
    pub fn mask_tiles(&self) -> Float64Array {
        let frames: Vec<f64> = self.mask.as_ref().map_or_else(Vec::new, |m| {
            m.tiles
                .iter()
                .flat_map(|t| {
                    let o = m.tile_origin(t);
                    [o[0], o[1], t.width as f64, t.height as f64]
                })
                .collect()
        });
        Float64Array::from(&frames[..])
    }
    /// Void share (region not covered) per mask cell, 0..255: the tiles one after the other,
    /// each row-major from its lowest row; empty without analysis.
    #[wasm_bindgen(getter)]
    pub fn void_mask(&self) -> Uint8Array {
        self.shares(|t| &t.void)
    }
    /// Overfill share (covered outside the region) per mask cell, laid out as `void_mask`.
    #[wasm_bindgen(getter)]
    pub fn overfill_mask(&self) -> Uint8Array {
        self.shares(|t| &t.overfill)
    }
}

impl LayerResult {
    /// One share of every tile of the mask, one tile after the other.
    fn shares(&self, of: impl Fn(&MaskTile) -> &Vec<u8>) -> Uint8Array {
        let tiles = self.mask.as_ref().map_or(&[][..], |m| &m.tiles[..]);
        let bytes: Vec<u8> = tiles.iter().flat_map(|t| of(t).iter().copied()).collect();
        Uint8Array::from(&bytes[..])
    }
}
