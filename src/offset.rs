//! Offset, stage 3 (SPEC.md 5.3.3): a region → the region moved into the material by a
//! distance, with circular arcs at convex corners and every self-overlap removed, so parts of
//! the region thinner than twice the offset vanish instead of crossing themselves.
//!
//! The offset itself is i_overlay's outline (integer core, round joins), which resolves
//! overlaps with a winding-number rule — the thesis's step. Arcs are approximated by chords
//! no farther than [`CHORD_TOLERANCE_MM`] from the true arc.

use crate::slice::Shapes;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};

/// Largest distance between an arc and the chords that approximate it.
pub const CHORD_TOLERANCE_MM: f64 = 0.001;

/// Moves outer boundaries inward by `d_outer` and holes into the material by `d_hole` (mm, ≥ 0).
pub fn inset(region: &Shapes, d_outer: f64, d_hole: f64) -> Shapes {
    if region.is_empty() || (d_outer == 0.0 && d_hole == 0.0) {
        return region.clone();
    }
    let r = d_outer.max(d_hole);
    // Chord angle θ with r·(1 − cos(θ/2)) = tolerance; i_overlay takes θ (= chord / radius).
    let angle = 2.0 * (1.0 - (CHORD_TOLERANCE_MM / r).min(1.0)).acos();
    let style = OutlineStyle::default()
        .outer_offset(-d_outer)
        .inner_offset(-d_hole)
        .line_join(LineJoin::Round(angle));
    region.outline(&style)
}
