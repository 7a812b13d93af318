//! Offset, stage 3 (SPEC.md 5.3.3): a region → the region moved into the material by a
//! distance, with circular arcs at convex corners and every self-overlap removed, so parts of
//! the region thinner than twice the offset vanish instead of crossing themselves.
//!
//! The offset itself is i_overlay's outline (integer core, round joins), which resolves
//! overlaps with a winding-number rule — the thesis's step. Arcs are approximated by chords
//! no farther than [`CHORD_TOLERANCE_MM`] from the true arc.

use crate::slice::{Contour, Shapes, dist, signed_area};
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
    region
        .outline(&style)
        .into_iter()
        .filter_map(|shape| {
            let mut contours = shape.into_iter().map(remove_spikes);
            // The outer boundary decides whether the shape survives; holes that collapse go.
            let outer = contours
                .next()
                .filter(|c| signed_area(c).abs() >= MIN_AREA_MM2)?;
            let mut shape = vec![outer];
            shape.extend(contours.filter(|c| signed_area(c).abs() >= MIN_AREA_MM2));
            Some(shape)
        })
        .collect()
}

/// Two points closer than this on either side of a vertex make that vertex a spike.
const SPIKE_BASE_MM: f64 = 1e-4;
/// Loops enclosing less than this are slivers of rounding, not geometry.
const MIN_AREA_MM2: f64 = 1e-6;

/// Removes zero-width spikes (a vertex whose neighbours coincide within [`SPIKE_BASE_MM`]):
/// the offset engine can leave such a spike running back to the original boundary where two
/// nearly opposite edges meet, and a droplet walk would follow it out of the loop.
pub fn remove_spikes(mut c: Contour) -> Contour {
    let mut changed = true;
    while changed && c.len() >= 3 {
        changed = false;
        let n = c.len();
        let mut keep = vec![true; n];
        let mut i = 0;
        while i < n {
            let (p, q) = ((i + n - 1) % n, (i + 1) % n);
            if keep[p] && keep[i] && dist(c[p], c[q]) < SPIKE_BASE_MM {
                // Drop the tip and one of the coinciding base points.
                keep[i] = false;
                keep[q] = false;
                changed = true;
                i += 2;
            } else {
                i += 1;
            }
        }
        if changed {
            c = c
                .into_iter()
                .zip(keep)
                .filter(|(_, k)| *k)
                .map(|(p, _)| p)
                .collect();
        }
    }
    if c.len() < 3 { Vec::new() } else { c }
}
