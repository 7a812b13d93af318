//! The overhang figure with support off (SPEC.md "Two discharge units"): each layer's
//! overhang *area* in one pass of the boolean engine.
//!
//! [`crate::support::overhang`] builds the region F farther than d = `overhang_limit`·B from
//! the layer below (the complement of the layer below moved inward by the fast offset: the
//! raw offset curves united under the positive fill rule, then a check of the mitred corners)
//! and intersects the layer's region R with it: two passes of the boolean engine over about
//! as many points. The figure needs only the area of R ∩ F, so [`overhang_area`] gives the
//! engine R and the raw curves (mitred corners) at once and intersects R with their
//! positive-winding region in one pass. A mitre is wrong only where another part of the
//! layer below comes closer than d to its corner; it then adds area bounded by curves closer
//! than allowed, so a vertex of the result inside that area is closer than allowed too: the
//! result's vertices are checked (few: most layers have no overhang) and a layer that fails
//! is computed by [`crate::support::overhang`]. `tests/overhang.rs` compares every layer's
//! area with [`crate::support::overhang`] on shared models. The support pass takes the
//! region itself from the same pass ([`overhang_region`]), so with support on each layer's
//! figure is the very figure of support off.

use crate::base::geom::{DVec2, Shape, Shapes, region_area, segment_distance2, signed_area};
use crate::base::settings::Settings;
use crate::base::spatial::EdgeIndex;
use crate::slicing::offset::{CHORD_TOLERANCE_MM, Corners, raw_offset};
use crate::support::{bounds_of, overhang};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;

/// Loops enclosing less than this are slivers of rounding, not geometry (as in
/// [`crate::support`]).
const MIN_AREA_MM2: f64 = 1e-6;

/// The overhang area of a layer, mm²: the area of [`crate::support::overhang`] (`region`: the
/// layer's region; `below`: the layer below's, `None` on layer 1), up to floating-point noise.
pub fn overhang_area(region: &Shapes, below: Option<&Shapes>, s: &Settings) -> f64 {
    overhang_figure(&overhang_region(region, below, s))
}

/// The overhang area of a layer's overhang shapes ([`overhang_region`]), mm²: +0.0 for none
/// (a sum of no loops' areas starts at −0.0). The support pass reports the same figure.
pub fn overhang_figure(shapes: &Shapes) -> f64 {
    if shapes.is_empty() {
        0.0
    } else {
        region_area(shapes)
    }
}

/// The overhang of a layer as [`crate::support::overhang`] gives it, up to rounding, by the one
/// pass of [`overhang_area`] (whose figure is this region's area): what the support pass
/// carries down.
pub fn overhang_region(region: &Shapes, below: Option<&Shapes>, s: &Settings) -> Shapes {
    let d = s.overhang_limit * s.droplet_width();
    match below {
        // The first layer, an empty layer or nothing below, a limit too small for the mitres:
        // the construction of `support::overhang` (which answers those cases itself).
        Some(b)
            if !region.is_empty()
                && !b.is_empty()
                && d.is_finite()
                && d > 2.0 * CHORD_TOLERANCE_MM =>
        {
            one_pass(region, b, d).unwrap_or_else(|| overhang(region, below, s))
        }
        _ => overhang(region, below, s),
    }
}

/// R ∩ F in one pass (loops of less than [`MIN_AREA_MM2`] left out), or `None` when a mitred
/// corner was wrong.
fn one_pass(region: &Shapes, below: &Shapes, d: f64) -> Option<Shapes> {
    let (lo, hi) = bounds_of(region, below);
    // A frame around both layers (positive winding), and every loop of the layer below
    // reversed and moved by d to its left: outward from the material.
    let (lo, hi) = (lo - DVec2::splat(d + 1.0), hi + DVec2::splat(d + 1.0));
    let mut far: Vec<Vec<[f64; 2]>> = Vec::with_capacity(1 + below.len());
    far.push(vec![
        lo.to_array(),
        [hi.x, lo.y],
        hi.to_array(),
        [lo.x, hi.y],
    ]);
    for c in below.iter().flat_map(|s| s.contours()) {
        let mut r = c.clone();
        r.reverse();
        let o = raw_offset(&r, d, CHORD_TOLERANCE_MM, Corners::Miter);
        if o.len() >= 3 {
            far.push(o.iter().map(|p| p.to_array()).collect());
        }
    }
    let layer: Vec<Vec<[f64; 2]>> = region
        .iter()
        .flat_map(|s| s.contours())
        .map(|c| c.iter().map(|p| p.to_array()).collect())
        .collect();
    // Outer loops run counter-clockwise and holes clockwise, so the layer's region is its
    // positive winding too.
    let out = layer.overlay(&far, OverlayRule::Intersect, FillRule::Positive);
    let mut points = Vec::new();
    let shapes: Shapes = crate::base::geom::shapes_from_overlay(out)
        .into_iter()
        .filter(|s| signed_area(&s.outer).abs() >= MIN_AREA_MM2)
        .map(|s| {
            points.extend(s.contours().flatten().copied());
            let holes = s
                .holes
                .into_iter()
                .filter(|h| signed_area(h).abs() >= MIN_AREA_MM2)
                .collect();
            Shape::new(s.outer, holes)
        })
        .collect();
    if points.is_empty() {
        return Some(shapes);
    }
    // Every vertex of the overhang lies at least d from the layer below (less the chords'
    // tolerance and rounding), as `offset::inset_within` checks its mitres.
    let mut edges = Vec::new();
    for c in below.iter().flat_map(|s| s.contours()) {
        for k in 0..c.len() {
            edges.push((c[k], c[(k + 1) % c.len()]));
        }
    }
    let limit = (d - 2.0 * CHORD_TOLERANCE_MM).powi(2);
    let near = |p: DVec2, index: Option<&EdgeIndex>| match index {
        Some(index) => index.any_near(p, d, |e| {
            let (a, b) = edges[e];
            segment_distance2(p, a, b) < limit
        }),
        None => edges
            .iter()
            .any(|&(a, b)| segment_distance2(p, a, b) < limit),
    };
    // Few vertices: test them against every edge; many: through a grid of the edges.
    let index = (points.len() * edges.len() > 20_000).then(|| EdgeIndex::new(&edges, d));
    if points.iter().any(|&p| near(p, index.as_ref())) {
        return None;
    }
    Some(shapes)
}
