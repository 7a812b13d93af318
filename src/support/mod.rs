//! Overhangs and support (docs/spec.md "Overhangs and support"; docs/support.md): layer regions →
//! each layer's overhang (area for the figures) and the support region the support's unit prints.
//!
//! **The rule.** A droplet is *supported* when the layer below has material within
//! `overhang_limit`·B of its centre. Material is the droplets' footprints: discs of diameter B
//! (B₁, the support unit's width, for its droplets) around their centres. So a droplet centre c of layer n is supported
//! iff some droplet centre d of layer n − 1 lies within B_d/2 + `overhang_limit`·B of c, where
//! B_d is d's droplet width (with the defaults: within B). Layer 1 rests on the plate.
//!
//! **Region form.** overhang(n) = region(n) − grow(region(n − 1), `overhang_limit`·B): the part
//! of a layer farther than the limit from the region below (none on layer 1). Its area per
//! layer and for the part is reported whether or not support is on.
//!
//! **Support regions**, top-down, one union, one offset and one clip per layer (no 3D
//! computation):
//! need(n) = (need(n + 1) ∪ grow(overhang(n + 1), [`support_reach`])) − region(n) (the part
//! below carries what it covers), support(n) = need(n) − the grown overhangs of the
//! `support_gap_z` layers directly above. The overhang is grown by B₁/2 before it is carried
//! down so that the support reaches under the overhang's edge. The overhangs come from the one
//! pass of [`crate::support::overhang::overhang_region`], their growth from the fast offset
//! ([`grow_fast`]). The need is carried as bits on the lattices the support is hatched on
//! ([`crate::support::lattice`]: union and clip by word operations, exact at every point a
//! support droplet can take); for unusual hatch steps as outlines by a sequential union
//! ([`support_regions`], which hands the boolean engine only the shapes whose boxes meet,
//! [`carried`]). Unit 1 prints each layer's support hatch segments
//! ([`crate::support::moves::support_moves`]), leaving out the droplets within `support_gap_xy`·B of the
//! part (no offset of the part); the droplet-level pass ([`crate::support::droplets`]) then
//! adds droplets wherever the rule still fails.
//! `tests/support.rs` checks the rule on the printed droplets.
//!
//! **Orientation** ([`orient`]): the rotation of a part with the least unsupported area by the
//! same rule, judged from its facets.

pub mod droplets;
pub mod lattice;
pub mod moves;
mod order;
pub mod orient;
pub mod overhang;
pub mod regions;

use crate::base::stages::{self, Stage};
use crate::base::steps::Budget;

/// `f()`, timed as the support's stage when the pass runs in steps (natively the caller
/// times the whole pass).
fn timed<T>(budget: &Budget, f: impl FnOnce() -> T) -> T {
    if budget.limited() {
        stages::time(Stage::Support, f)
    } else {
        f()
    }
}

/// `f(i)` for `i` in `0..n`: on all cores with an unlimited budget (natively), else one after
/// the other, each one item of `budget` (the pass may pause after each, [`crate::base::steps`]).
async fn map_in_steps<R: Send>(
    n: usize,
    budget: &Budget,
    f: &(dyn Fn(usize) -> R + Sync),
) -> Vec<R> {
    if !budget.limited() {
        return crate::base::parallel::par_map(n, f);
    }
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        out.push(timed(budget, || f(i)));
        budget.spend(1).await;
    }
    out
}

pub use overhang::{overhang, overhang_face_normal_z, support_reach, unsupported_droplets};
pub use regions::{
    LayerSupport, SUPPORT_TOLERANCE_MM, grow, grow_fast, support_layers, support_layers_in_steps,
    support_regions,
};
