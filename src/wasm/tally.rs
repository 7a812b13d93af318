//! A worker's tally of its run of layers: the summary, and the 3D estimate of the slabs
//! (the predicted density) over the run ([`SlabRun`]); the slabs at the run's ends use the
//! layers just outside it, planned once more at [`Session::finish_slabs`].

use super::{LayerResult, Session, to_js};
use crate::analysis::{LayerAnalysis, LayerMaps, LayerStage, SlabRun, UnitRegions};
use crate::output::summary::Summary;
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

/// A unit's summary, built layer by layer in the worker.
#[wasm_bindgen]
#[derive(Default)]
pub struct Tally {
    summary: Summary,
    /// The 3D estimate of the analysed layers so far (they come in order).
    run: Option<SlabRun>,
}

#[wasm_bindgen]
impl Tally {
    #[wasm_bindgen(constructor)]
    pub fn new() -> Tally {
        Tally::default()
    }

    /// Adds a sliced layer (its counts, travel and repairs, and its analysis if it has one).
    pub fn add_layer(&mut self, layer: &mut LayerResult) {
        self.summary.merge(&layer.summary);
        self.add_analysis(layer);
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
        let maps = |i: usize| self.stage.maps(&self.job.plan_for_analysis(i));
        let below = first.checked_sub(1).map(maps);
        let above = (end < self.job.layer_count()).then(|| maps(end));
        let f = run.finish(below, above);
        tally.summary.add_slab(&f);
    }
}
