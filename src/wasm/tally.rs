//! A worker's tally of its run of layers: the summary, and the 3D estimate of the slabs
//! (the predicted density) over the run ([`SlabRun`]); the slabs at the run's ends use the
//! layers just outside it, planned once more at [`Session::finish_slabs`].

use super::{LayerResult, Session, to_js};
use crate::analysis::{LayerAnalysis, LayerMaps, LayerStage, SlabRun, UnitRegions};
use crate::output::summary::Summary;
use js_sys::Uint8Array;
use std::sync::Arc;
use wasm_bindgen::prelude::*;

/// What the 3D estimate needs of an analysed layer.
pub(crate) struct SlabInput {
    pub index: usize,
    pub analysis: LayerAnalysis,
    pub regions: UnitRegions,
    pub maps: LayerMaps,
    pub stage: Arc<LayerStage>,
}

/// A unit's summary and G-code, built layer by layer in the worker.
#[wasm_bindgen]
#[derive(Default)]
pub struct Tally {
    summary: Summary,
    /// The G-code of the layers added, in the order added.
    gcode: Vec<u8>,
    /// The 3D estimate of the analysed layers so far (they come in order).
    run: Option<SlabRun>,
}

#[wasm_bindgen]
impl Tally {
    #[wasm_bindgen(constructor)]
    pub fn new() -> Tally {
        Tally::default()
    }

    /// Adds a sliced layer (its counts, travel and repairs, its G-code, and its analysis if it
    /// has one).
    pub fn add_layer(&mut self, layer: &mut LayerResult) {
        self.summary.merge(&layer.summary);
        self.gcode.extend_from_slice(layer.gcode.as_bytes());
        self.add_analysis(layer);
    }

    /// The G-code of the layers added, as a view of the module's memory: for a `Blob` made at
    /// once (it copies the bytes), with no call into the module between (a call may move the
    /// memory and the view with it). One copy per unit instead of one array per layer, which
    /// cost the page's engine more per array than per byte.
    pub fn gcode_view(&self) -> Uint8Array {
        // SAFETY: the view is read by the caller before anything else runs in the module.
        unsafe { Uint8Array::view(&self.gcode) }
    }

    /// Adds only a layer's analysis (a layer analysed after the slice that counted it), and
    /// its slab to the 3D estimate.
    pub fn add_analysis(&mut self, layer: &mut LayerResult) {
        if let Some(a) = &layer.analysis {
            self.summary.add_analysis(a);
        }
        if let Some(input) = layer.slab.take() {
            let SlabInput {
                index,
                analysis,
                regions,
                maps,
                stage,
            } = *input;
            let run = self.run.get_or_insert_with(|| SlabRun::new(stage));
            if let Some(f) = run.push(index, analysis, regions, maps) {
                self.summary.add_slab(&f);
            }
        }
    }

    /// The summary so far (`Summary`).
    #[wasm_bindgen(unchecked_return_type = "Summary")]
    pub fn summary(&self) -> Result<JsValue, JsValue> {
        to_js(&self.summary, "a summary")
    }
}

#[wasm_bindgen]
impl Session {
    /// Completes the 3D estimate of `tally`'s run of analysed layers: the slabs at its ends,
    /// with the spheroids of the layers just below and above it (planned again here, without
    /// their text or figures). Call it after the run's last layer; nothing without analysis.
    pub fn finish_slabs(&self, tally: &mut Tally) {
        let Some(run) = tally.run.take() else {
            return;
        };
        let Some((first, end)) = run.span() else {
            return;
        };
        let maps = |i: usize| {
            let (plan, region) = self.job.plan_and_region_for_analysis(i);
            self.stage.maps_in(&plan, &region)
        };
        let below = first.checked_sub(1).map(maps);
        let above = (end < self.job.layer_count()).then(|| maps(end));
        let f = run.finish(below, above);
        tally.summary.add_slab(&f);
    }
}
