//! A per-layer stage beside the planning: what runs on a layer's region and plan in the
//! worker that planned it, and what its result does in layer order afterwards.

use crate::base::geom;
use crate::slicing::plan::LayerPlan;

/// A stage that the native layer writer (`pipeline::write_gcode_with`) runs on every layer: [`per_layer`](Self::per_layer) on
/// the worker that planned the layer, with the layer's region and its full plan (before the
/// plan's moves are dropped), then [`ordered`](Self::ordered) with its result on the writing
/// thread, in ascending layer order, after the layer's text is written.
pub trait LayerSink {
    /// A worker's own state (one per worker, reused from layer to layer).
    type State: Send;
    /// What a layer hands from its worker to the writing thread.
    type Out: Send;
    /// A new worker's state (made on the writing thread before the workers start).
    fn init(&self) -> Self::State;
    /// On the worker that planned layer `i`.
    fn per_layer(
        state: &mut Self::State,
        i: usize,
        region: &geom::Shapes,
        plan: &LayerPlan,
    ) -> Self::Out;
    /// On the writing thread, layer by layer in ascending order.
    fn ordered(&mut self, i: usize, out: Self::Out);
}

/// No stage.
impl LayerSink for () {
    type State = ();
    type Out = ();
    fn init(&self) {}
    fn per_layer(_: &mut (), _: usize, _: &geom::Shapes, _: &LayerPlan) {}
    fn ordered(&mut self, _: usize, _: ()) {}
}

/// A stage or none (`--report` or not).
impl<S: LayerSink> LayerSink for Option<S> {
    type State = Option<S::State>;
    type Out = Option<S::Out>;
    fn init(&self) -> Self::State {
        self.as_ref().map(S::init)
    }
    fn per_layer(
        state: &mut Self::State,
        i: usize,
        region: &geom::Shapes,
        plan: &LayerPlan,
    ) -> Self::Out {
        state.as_mut().map(|st| S::per_layer(st, i, region, plan))
    }
    fn ordered(&mut self, i: usize, out: Self::Out) {
        if let (Some(s), Some(o)) = (self.as_mut(), out) {
            s.ordered(i, o);
        }
    }
}
