//! One planned layer for the page ([`LayerResult`]): its counts and time, its G-code bytes,
//! its droplets, roles, units and travel as flat typed arrays, and (when analysed) its void
//! analysis and coverage mask.

use super::{tally, to_js};
use crate::analysis::{CoverageMask, LayerAnalysis, MaskTile};
use crate::base::settings::Settings;
use crate::base::stages::{self, Stage};
use crate::output::preview::PreviewLayer;
use crate::output::summary::{self, Summary};
use crate::slicing::plan::{Counts, LayerPlan};
use js_sys::{Float32Array, Float64Array, Uint8Array};
use wasm_bindgen::prelude::*;

/// One planned layer, ready to be posted to the page.
#[wasm_bindgen]
pub struct LayerResult {
    index: usize,
    z: f64,
    counts: Counts,
    travel_mm: f64,
    seconds: f64,
    unsupported_area: f64,
    pub(crate) summary: Summary,
    pub(super) gcode: String,
    preview: PreviewLayer,
    pub(super) analysis: Option<LayerAnalysis>,
    pub(super) mask: Option<CoverageMask>,
    /// What the 3D estimate needs of an analysed layer, until a [`Tally`](super::Tally) takes it.
    pub(super) slab: Option<Box<tally::SlabInput>>,
}

impl LayerResult {
    pub(super) fn new(plan: &LayerPlan, settings: &Settings, gcode: String) -> LayerResult {
        LayerResult {
            index: plan.index,
            z: plan.z,
            counts: plan.counts,
            travel_mm: plan.travel_mm,
            seconds: summary::layer_seconds(plan, settings),
            unsupported_area: plan.unsupported_area,
            summary: Summary::of_layer(plan),
            gcode,
            preview: stages::time(Stage::Preview, || {
                PreviewLayer::from_plan(plan, settings.droplet_width())
            }),
            analysis: None,
            mask: None,
            slab: None,
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
    /// The layer's estimated print time, s (`summary::layer_seconds`: the layers' times add up
    /// to the job's `print_seconds`).
    #[wasm_bindgen(getter)]
    pub fn seconds(&self) -> f64 {
        self.seconds
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
    /// Role per droplet: 0 outermost loop, 1 inner loops, 2 fill, 3 support.
    #[wasm_bindgen(getter)]
    pub fn roles(&self) -> Uint8Array {
        Uint8Array::from(&self.preview.roles[..])
    }
    /// Discharge unit per droplet (0 … `units` − 1), in the order of `roles`.
    #[wasm_bindgen(getter)]
    pub fn units(&self) -> Uint8Array {
        Uint8Array::from(&self.preview.units[..])
    }
    /// Travel moves, x0,y0,x1,y1 per move, in mm.
    #[wasm_bindgen(getter)]
    pub fn travel(&self) -> Float32Array {
        Float32Array::from(&self.preview.travel[..])
    }
    /// The layer's overhang area, mm² (its region farther than `overhang_limit`·B from the
    /// region below; 0 on the first layer).
    #[wasm_bindgen(getter)]
    pub fn unsupported_area(&self) -> f64 {
        self.unsupported_area
    }
    /// Support droplets (of the unit `support` names).
    #[wasm_bindgen(getter)]
    pub fn support(&self) -> f64 {
        self.counts.support as f64
    }
    /// Droplets each unit prints (its parts' and, for the support's unit, the support),
    /// indexed by unit (`MAX_UNITS` entries).
    #[wasm_bindgen(getter)]
    pub fn unit_droplets(&self) -> Float64Array {
        let n: Vec<f64> = self.counts.units.iter().map(|&n| n as f64).collect();
        Float64Array::from(&n[..])
    }
    /// The layer's void analysis (`analysis::LayerAnalysis`: coverage, void_area,
    /// largest_void {area, centroid, min, max, at_boundary}, overfill_area,
    /// boundary_deviation, ...); `null` unless made by `slice_layer_analysed`.
    #[wasm_bindgen(unchecked_return_type = "LayerAnalysis | null")]
    pub fn analysis(&self) -> Result<JsValue, JsValue> {
        match &self.analysis {
            Some(a) => to_js(a, "a layer analysis"),
            None => Ok(JsValue::NULL),
        }
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
                    [o[0], o[1], t.rect.width as f64, t.rect.height as f64]
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
    /// Per tile of the mask, 1 when any of its cells has overfill, else 0 (most tiles have
    /// none: the page then reads no overfill share of them); empty without analysis.
    #[wasm_bindgen(getter)]
    pub fn mask_overfilled(&self) -> Uint8Array {
        let tiles = self.mask.as_ref().map_or(&[][..], |m| &m.tiles[..]);
        let flags: Vec<u8> = tiles
            .iter()
            .map(|t| u8::from(t.overfill.iter().any(|&v| v != 0)))
            .collect();
        Uint8Array::from(&flags[..])
    }
}

impl LayerResult {
    /// One share of every tile of the mask, one tile after the other (copied once, tile by
    /// tile, into the JS array).
    fn shares(&self, of: impl Fn(&MaskTile) -> &Vec<u8>) -> Uint8Array {
        let tiles = self.mask.as_ref().map_or(&[][..], |m| &m.tiles[..]);
        let total: usize = tiles.iter().map(|t| of(t).len()).sum();
        let out = Uint8Array::new_with_length(total as u32);
        let mut at = 0u32;
        for t in tiles {
            let v = of(t);
            let end = at + v.len() as u32;
            out.subarray(at, end).copy_from(v);
            at = end;
        }
        out
    }
}
