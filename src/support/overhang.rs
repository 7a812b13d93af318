//! The overhang figure with support off (docs/spec.md "Overhangs and support"): each layer's
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

use crate::base::boolean::{MIN_AREA_MM2, difference, intersection, without_slivers};
use crate::base::geom::{DVec2, Shape, Shapes, region_area, segment_distance2, signed_area};
use crate::base::settings::Settings;
use crate::base::spatial::EdgeIndex;
use crate::slicing::offset::{CHORD_TOLERANCE_MM, Corners, raw_offset};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;

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
        // A layer whose region is the one below, point for point (prisms: walls straight
        // up), lies a whole d within the region below grown by d: no overhang, without
        // the boolean pass (which gives the same on such layers; it costs most where a
        // layer holds thousands of small parts).
        Some(b) if b == region && d.is_finite() && d > 2.0 * CHORD_TOLERANCE_MM => Shapes::new(),
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
        // every loop's vertices, the slivers' too, are checked against the mitres
        .inspect(|s| points.extend(s.contours().flatten().copied()))
        .filter_map(without_slivers)
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

/// The bounding box of two regions' contours (infinite when both are empty).
fn bounds_of(region: &Shapes, below: &Shapes) -> (DVec2, DVec2) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in region
        .iter()
        .chain(below)
        .flat_map(|s| s.contours())
        .flatten()
    {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (lo, hi)
}

/// [`overhang`] as it was computed before (`tests/support.rs` compares the two): the region less i_overlay's outward outline of the layer below, chords within
/// [`SUPPORT_TOLERANCE_MM`] (inside the arcs: it overstates the area by up to ~2·10⁻³ mm² a
/// layer on 3DBenchy).
#[cfg(any(test, feature = "reference"))]
pub fn overhang_reference(region: &Shapes, below: Option<&Shapes>, s: &Settings) -> Shapes {
    let Some(below) = below else {
        return Shapes::new();
    };
    // What is new in this layer first (a cheap clip): most layers of most parts have little.
    let fresh = difference(region, below);
    if region_area(&fresh) < MIN_AREA_MM2 {
        return Shapes::new();
    }
    // Chords within the support's tolerance: the area is a figure, not an outline to print.
    let d = s.overhang_limit * s.droplet_width();
    let grown = crate::base::boolean::grow_within(below, d, crate::support::SUPPORT_TOLERANCE_MM);
    difference(&fresh, &grown)
}

/// The overhang of a layer: its region farther than `overhang_limit`·B from the region of the
/// layer below (`None` for layer 1, which rests on the plate: no overhang).
///
/// Computed as region ∩ inset(complement of below, d): the complement is a frame around both
/// layers with every loop of the layer below reversed as a hole, moved inward by d with the
/// fast offset of [`crate::slicing::offset::inset_within`] (arcs within
/// [`CHORD_TOLERANCE_MM`]), then one intersection. About 2.5 times faster than
/// growing the layer below with i_overlay's outline and two differences
/// ([`overhang_reference`]); per layer the areas agree within ~10⁻³ mm² with that
/// construction at the same chord tolerance (tests/support.rs).
pub fn overhang(region: &Shapes, below: Option<&Shapes>, s: &Settings) -> Shapes {
    let Some(below) = below else {
        return Shapes::new();
    };
    if region.is_empty() {
        return Shapes::new();
    }
    let d = s.overhang_limit * s.droplet_width();
    if below.is_empty() || d <= 0.0 {
        return if d <= 0.0 {
            difference(region, below)
        } else {
            region.clone()
        };
    }
    let (lo, hi) = bounds_of(region, below);
    let m = d + 1.0;
    let (lo, hi) = (lo - DVec2::splat(m), hi + DVec2::splat(m));
    let frame: crate::base::geom::Contour =
        vec![lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    let holes = below
        .iter()
        .flat_map(|s| s.contours())
        .map(|c| {
            let mut r = c.clone();
            r.reverse();
            r
        })
        .collect();
    let far = crate::slicing::offset::inset_within(
        &vec![Shape::new(frame, holes)],
        d,
        d,
        CHORD_TOLERANCE_MM,
    );
    intersection(region, &far)
}

/// How far beyond an overhang its support reaches, mm: half a unit-1 droplet width B₁, so
/// the support's contour loop (B₁/2 inside its boundary) runs under the overhang's outline
/// and the support under an overhang's edge is wider. One whole B₁ measured worse: support
/// then hangs beyond the edges of the part below (U_overhang.obj), see docs/support.md.
pub fn support_reach(s: &Settings) -> f64 {
    0.5 * s.support_width()
}

/// The droplet form of the rule: which droplets of a layer have no droplet of the layer below
/// within B_d/2 + `limit_mm` (B_d: the width of the droplet d below; `limit_mm` =
/// `overhang_limit`·B). `layer`: the layer's droplet centres; `below`: the layer below's
/// centres with their widths, `None` for the first layer (it rests on the plate: every droplet
/// supported). A hash grid of the layer below: O(droplets) for any layer.
pub fn unsupported_droplets(
    layer: &[[f64; 2]],
    below: Option<&[([f64; 2], f64)]>,
    limit_mm: f64,
) -> Vec<bool> {
    let Some(below) = below else {
        return vec![false; layer.len()];
    };
    let reach = below
        .iter()
        .map(|&(_, w)| w / 2.0 + limit_mm)
        .fold(0.0_f64, f64::max);
    if !(reach > 0.0 && reach.is_finite()) {
        return vec![true; layer.len()];
    }
    let key = |p: [f64; 2]| ((p[0] / reach).floor() as i64, (p[1] / reach).floor() as i64);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> =
        std::collections::HashMap::with_capacity(below.len());
    for (j, &(p, _)) in below.iter().enumerate() {
        grid.entry(key(p)).or_default().push(j);
    }
    layer
        .iter()
        .map(|&c| {
            let (cx, cy) = key(c);
            !(-1..=1).any(|dx| {
                (-1..=1).any(|dy| {
                    grid.get(&(cx.saturating_add(dx), cy.saturating_add(dy)))
                        .is_some_and(|v| {
                            v.iter().any(|&j| {
                                let (d, w) = below[j];
                                let r = w / 2.0 + limit_mm;
                                (c[0] - d[0]).powi(2) + (c[1] - d[1]).powi(2) <= r * r + 1e-9
                            })
                        })
                })
            })
        })
        .collect()
}

/// The steepest face that needs no support, as the z of its outward normal: a face whose unit
/// normal has n_z < −this overhangs. A face at angle θ from the vertical moves H·tan θ per layer;
/// the rule carries a layer offset of up to `overhang_limit`·B, so the face overhangs when
/// tan θ > `overhang_limit`·B/H, and a downward face's normal has n_z = −sin θ.
pub fn overhang_face_normal_z(s: &Settings) -> f64 {
    let t = s.overhang_limit * s.droplet_width() / s.layer_height;
    t / (1.0 + t * t).sqrt()
}
