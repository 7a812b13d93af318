//! The boolean engine's operations on regions (i_overlay, non-zero rule): difference,
//! intersection, union and the outward outline, every result without slivers of rounding
//! (loops under [`MIN_AREA_MM2`]).

use crate::base::geom::{DVec2, Shape, Shapes, shapes_from_overlay, signed_area};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};

/// Loops enclosing less than this are slivers of rounding, not geometry.
pub const MIN_AREA_MM2: f64 = 1e-6;

/// A region in the boolean engine's nested form (each shape: outer boundary, then holes).
pub fn nested(region: &Shapes) -> Vec<Vec<Vec<[f64; 2]>>> {
    region
        .iter()
        .map(|s| {
            s.contours()
                .map(|c| c.iter().map(|p| p.to_array()).collect())
                .collect()
        })
        .collect()
}

/// Shapes from the engine, without loops of less than [`MIN_AREA_MM2`].
pub fn cleaned(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Shapes {
    shapes_from_overlay(shapes)
        .into_iter()
        .filter_map(without_slivers)
        .collect()
}

/// A shape without its loops of less than [`MIN_AREA_MM2`] (`None` when its outer loop is one).
pub fn without_slivers(s: Shape) -> Option<Shape> {
    if signed_area(&s.outer).abs() < MIN_AREA_MM2 {
        return None;
    }
    let holes = s
        .holes
        .into_iter()
        .filter(|h| signed_area(h).abs() >= MIN_AREA_MM2)
        .collect();
    Some(Shape::new(s.outer, holes))
}

/// The region moved outward by `d` mm, round joins with chords within `tolerance` of the arcs (the chords lie inside the arcs: the
/// region grows by between d − tolerance and d).
pub fn grow_within(region: &Shapes, d: f64, tolerance: f64) -> Shapes {
    if region.is_empty() || d <= 0.0 {
        return region.clone();
    }
    let angle = 2.0 * (1.0 - (tolerance / d).min(1.0)).acos();
    let style = OutlineStyle::default()
        .outer_offset(d)
        .inner_offset(d)
        .line_join(LineJoin::Round(angle));
    cleaned(nested(region).outline(&style))
}

/// a − b.
pub fn difference(a: &Shapes, b: &Shapes) -> Shapes {
    if a.is_empty() || b.is_empty() {
        return a.clone();
    }
    cleaned(nested(a).overlay(&nested(b), OverlayRule::Difference, FillRule::NonZero))
}

/// a ∩ b.
pub fn intersection(a: &Shapes, b: &Shapes) -> Shapes {
    if a.is_empty() || b.is_empty() {
        return Shapes::new();
    }
    cleaned(nested(a).overlay(&nested(b), OverlayRule::Intersect, FillRule::NonZero))
}

/// a ∪ b.
pub fn union(a: &Shapes, b: &Shapes) -> Shapes {
    if a.is_empty() {
        return b.clone();
    }
    if b.is_empty() {
        return a.clone();
    }
    cleaned(nested(a).overlay(&nested(b), OverlayRule::Union, FillRule::NonZero))
}

/// The bounding box of a shape (of its outer loop).
pub fn bounds(s: &Shape) -> (DVec2, DVec2) {
    s.outer.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Whether two bounding boxes overlap (touching counts).
pub fn overlap(a: (DVec2, DVec2), b: (DVec2, DVec2)) -> bool {
    a.0.x <= b.1.x && b.0.x <= a.1.x && a.0.y <= b.1.y && b.0.y <= a.1.y
}
