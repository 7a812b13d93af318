//! Overhangs and support (SPEC.md "Two discharge units"; docs/support.md): layer regions →
//! each layer's overhang (area for the figures) and the support region unit 1 prints.
//!
//! **The rule.** A droplet is *supported* when the layer below has material within
//! `overhang_limit`·B of its centre. Material is the droplets' footprints: discs of diameter B
//! (B₁ for unit-1 droplets) around their centres. So a droplet centre c of layer n is supported
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
//! ([`grow_fast`]). The need is carried as bits on the lattices unit 1 hatches on
//! ([`crate::support::lattice`]: union and clip by word operations, exact at every point a
//! support droplet can take); for unusual hatch steps as outlines by a sequential union
//! ([`support_regions`], which hands the boolean engine only the shapes whose boxes meet,
//! [`carried`]). Unit 1 prints each layer's support hatch segments
//! ([`crate::support::moves::support_moves`]), leaving out the droplets within `support_gap_xy`·B of the
//! part (no offset of the part); the droplet-level pass ([`crate::support::droplets`]) then
//! adds droplets wherever the rule still fails.
//! `tests/support.rs` checks the rule on the printed droplets.

pub mod droplets;
pub mod lattice;
pub mod moves;
pub mod overhang;

use crate::base::geom::{
    DVec2, Shape, Shapes, region_area, segment_distance2, shapes_from_overlay, signed_area,
};
use crate::base::settings::Settings;
use crate::base::spatial::EdgeIndex;
use crate::slicing::hatch::{HatchLine, hatch_at};
use crate::slicing::offset::{CHORD_TOLERANCE_MM, Corners, raw_offset};
use crate::support::lattice::{Bits, Lattices, Runs};
use crate::support::overhang::overhang_figure;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::FloatOverlay;
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};

/// Loops enclosing less than this are slivers of rounding, not geometry.
const MIN_AREA_MM2: f64 = 1e-6;

/// A region in the boolean engine's nested form (each shape: outer boundary, then holes).
fn nested(region: &Shapes) -> Vec<Vec<Vec<[f64; 2]>>> {
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
fn cleaned(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Shapes {
    shapes_from_overlay(shapes)
        .into_iter()
        .filter(|s| signed_area(&s.outer).abs() >= MIN_AREA_MM2)
        .map(|s| {
            let holes = s
                .holes
                .into_iter()
                .filter(|h| signed_area(h).abs() >= MIN_AREA_MM2)
                .collect();
            Shape::new(s.outer, holes)
        })
        .collect()
}

/// The region moved outward by `d` mm (round joins, chords within [`CHORD_TOLERANCE_MM`]).
pub fn grow(region: &Shapes, d: f64) -> Shapes {
    grow_within(region, d, CHORD_TOLERANCE_MM)
}

/// How far the support's outlines may stray from the exact construction, mm: its offsets'
/// chords and its simplified outlines. Support needs no micrometres; fewer points keep its
/// booleans and its planning fast.
pub const SUPPORT_TOLERANCE_MM: f64 = 0.005;

/// [`grow`] with chords within `tolerance` of the arcs (the chords lie inside the arcs: the
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

/// [`grow_within`] by the fast offset of [`crate::slicing::offset`] instead of i_overlay's outline: every
/// loop reversed and moved by `d` to its left (outward), arcs within `tolerance`; the grown
/// region is where those curves wind negatively (the reversed loops' winding is −1 inside the
/// region, and moving them outward keeps that). Concave corners of the region are mitred; a
/// wrong mitre (another part of the region within `d` of it) takes area from the result
/// bounded by curves closer than `d` to the region, so a vertex of the result is closer than
/// `d` − 2·`tolerance` there, and the region is grown again with every such corner joined
/// through its vertex (the exact raw offset curve). About half the cost of the outline.
pub fn grow_fast(region: &Shapes, d: f64, tolerance: f64) -> Shapes {
    if region.is_empty() || !(d > 0.0 && d.is_finite()) {
        return region.clone();
    }
    let tolerance = tolerance.clamp(1e-6, 0.25 * d);
    let raw = |corners| -> Shapes {
        let curves: Vec<Vec<[f64; 2]>> = region
            .iter()
            .flat_map(|s| s.contours())
            .filter_map(|c| {
                let mut r = c.clone();
                r.reverse();
                let o = raw_offset(&r, d, tolerance, corners);
                (o.len() >= 3).then(|| o.iter().map(|p| p.to_array()).collect())
            })
            .collect();
        cleaned(curves.simplify_shape(FillRule::Negative))
    };
    let fast = raw(Corners::Miter);
    let mut edges = Vec::new();
    for c in region.iter().flat_map(|s| s.contours()) {
        for k in 0..c.len() {
            edges.push((c[k], c[(k + 1) % c.len()]));
        }
    }
    let limit = (d - 2.0 * tolerance).max(0.0).powi(2);
    let index = EdgeIndex::new(&edges, d);
    let too_near = |p: DVec2| {
        index.any_near(p, d, |e| {
            let (a, b) = edges[e];
            segment_distance2(p, a, b) < limit
        })
    };
    if fast
        .iter()
        .flat_map(|s| s.contours())
        .flatten()
        .any(|&p| too_near(p))
    {
        raw(Corners::ThroughVertex)
    } else {
        fast
    }
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

/// A region with every loop simplified within [`SUPPORT_TOLERANCE_MM`] (the slicer's
/// Douglas–Peucker, [`crate::slicing::slice::simplify_closed`]).
fn simplified(r: &Shapes) -> Shapes {
    r.iter()
        .map(|s| {
            let mut c = s
                .contours()
                .map(|c| crate::slicing::slice::simplify_closed(c, SUPPORT_TOLERANCE_MM));
            let outer = c.next().unwrap_or_default();
            Shape::new(outer, c.collect())
        })
        .collect()
}

/// The bounding box of a shape (of its outer loop).
fn bounds(s: &Shape) -> (DVec2, DVec2) {
    s.outer.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Whether two bounding boxes overlap (touching counts).
fn overlap(a: (DVec2, DVec2), b: (DVec2, DVec2)) -> bool {
    a.0.x <= b.1.x && b.0.x <= a.1.x && a.0.y <= b.1.y && b.0.y <= a.1.y
}

/// (a ∪ b) − c, a's shapes simplified within [`SUPPORT_TOLERANCE_MM`] first (b's and c's
/// are), in one pass of the boolean engine (the subject's loops under the non-zero rule are the
/// union). Only what the boxes cannot tell apart goes to the engine: a's shapes whose box
/// meets no box of b or c are disjoint from both and stay as they are (a's shapes are
/// disjoint), and only c's shapes whose box meets the rest clip it.
fn carried(a: &Shapes, b: &Shapes, c: &Shapes) -> Shapes {
    if a.is_empty() && b.is_empty() {
        return Shapes::new();
    }
    let others: Vec<(DVec2, DVec2)> = b.iter().chain(c).map(bounds).collect();
    let (touched, mut out): (Shapes, Shapes) = a
        .iter()
        .cloned()
        .partition(|s| others.iter().any(|&o| overlap(bounds(s), o)));
    if touched.is_empty() && b.is_empty() {
        return out;
    }
    let mut subject = nested(&simplified(&touched));
    subject.extend(nested(b));
    let reach = touched.iter().chain(b).map(bounds).fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
    );
    let clip: Shapes = c
        .iter()
        .filter(|s| overlap(bounds(s), reach))
        .cloned()
        .collect();
    // The list solver: the need has 1,000–5,000 edges, where it takes about 10 % fewer
    // instructions than the engine's automatic choice (the tree above 2,000 edges).
    let rule = if clip.is_empty() {
        OverlayRule::Union
    } else {
        OverlayRule::Difference
    };
    out.extend(cleaned(
        FloatOverlay::with_subj_and_clip_custom(
            &subject,
            &nested(&clip),
            Default::default(),
            Solver::LIST,
        )
        .overlay(rule, FillRule::NonZero),
    ));
    out
}

/// The bounding box of two regions' contours (infinite when both are empty).
pub(crate) fn bounds_of(region: &Shapes, below: &Shapes) -> (DVec2, DVec2) {
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

/// [`overhang`] as it was computed before (kept for `tests/support.rs`, which compares the
/// two): the region less i_overlay's outward outline of the layer below, chords within
/// [`SUPPORT_TOLERANCE_MM`] (inside the arcs: it overstates the area by up to ~2·10⁻³ mm² a
/// layer on 3DBenchy).
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
    difference(&fresh, &grow_within(below, d, SUPPORT_TOLERANCE_MM))
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
    0.5 * s.unit1_droplet_width()
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

/// One layer's overhang area and the support unit 1 prints in it.
#[derive(Clone, Debug, Default)]
pub struct LayerSupport {
    /// Area of the layer's overhang, mm².
    pub unsupported_area: f64,
    /// The support region's hatch segments (empty with `support = off`): lines
    /// B₁ / `support_density` apart at the layer's hatch angle, their ends on the lattice
    /// points k·B₁ along them, up to the part: droplets within `support_gap_xy`·B of the part
    /// are left out when they are planned ([`crate::support::moves::support_moves`]).
    pub lines: Vec<HatchLine>,
}

/// Every layer's overhang and support from all layers' regions (bottom first): the need
/// carried on unit 1's lattices ([`crate::support::lattice`]), or, for more hatch directions
/// than it carries, as regions ([`support_regions`]).
pub fn support_layers(regions: &[Shapes], s: &Settings) -> Vec<LayerSupport> {
    let s1 = crate::slicing::plan::support_settings(s);
    let b1 = s1.droplet_width();
    if s1.fill_density.is_nan() || s1.fill_density <= 0.0 {
        // No support hatch: the overhang areas only.
        return par_map(regions.len(), &|i| LayerSupport {
            unsupported_area: crate::support::overhang::overhang_area(
                &regions[i],
                i.checked_sub(1).map(|j| &regions[j]),
                s,
            ),
            lines: Vec::new(),
        });
    }
    let spacing = b1 / s1.fill_density;
    let reach = support_reach(s) + SUPPORT_TOLERANCE_MM;
    match Lattices::new(regions, s, spacing, b1, reach) {
        Some(lattices) => lattice_layers(regions, s, &lattices),
        None => {
            let areas_regions = support_regions(regions, s);
            par_map(regions.len(), &|i| LayerSupport {
                unsupported_area: areas_regions[i].0,
                lines: hatch_at(
                    &areas_regions[i].1,
                    crate::slicing::plan::hatch_angle(s, i),
                    spacing,
                    0.5,
                    Some((b1, 0.0, 0.0)),
                ),
            })
        }
    }
}

/// [`support_layers`] on lattices, top-down in blocks of layers: each block's overhangs are
/// found, grown and crossed with every lattice on all cores, then the need is carried through
/// the block by word operations. need(n) = (need(n + 1) ∪ grown overhang(n + 1)) − region(n);
/// the support of layer n is its need less the grown overhangs of the `support_gap_z` layers
/// directly above, on the layer's own lattice.
fn lattice_layers(regions: &[Shapes], s: &Settings, lat: &Lattices) -> Vec<LayerSupport> {
    /// Layers whose crossings are held at once (memory stays that of a block).
    const BLOCK: usize = 32;
    let n = regions.len();
    let reach = support_reach(s);
    let gap_z = s.support_gap_z as usize;
    let mut out: Vec<LayerSupport> = (0..n).map(|_| LayerSupport::default()).collect();
    let mut needs: Vec<Bits> = lat.lattices.iter().map(Bits::new).collect();
    // The grown overhangs of the layers directly above, nearest first, on every lattice.
    let mut above: std::collections::VecDeque<Vec<Runs>> = Default::default();
    let mut top = n;
    while top > 0 {
        let bottom = top.saturating_sub(BLOCK);
        let block = par_map(top - bottom, &|k| {
            let i = bottom + k;
            let o = crate::support::overhang::overhang_region(
                &regions[i],
                i.checked_sub(1).map(|j| &regions[j]),
                s,
            );
            let grown = grow_fast(&o, reach, SUPPORT_TOLERANCE_MM);
            let on = |r: &Shapes| -> Vec<Runs> { lat.lattices.iter().map(|l| l.runs(r)).collect() };
            (overhang_figure(&o), on(&grown), on(&regions[i]))
        });
        for (k, (area, grown, part)) in block.into_iter().enumerate().rev() {
            let i = bottom + k;
            out[i].unsupported_area = area;
            if let Some(g) = above.front() {
                for (bits, runs) in needs.iter_mut().zip(g) {
                    bits.set(runs);
                }
            }
            for (bits, runs) in needs.iter_mut().zip(&part) {
                bits.clear(runs);
            }
            let x = lat.of[i];
            out[i].lines = if gap_z == 0 {
                needs[x].lines(&lat.lattices[x])
            } else {
                let mut bits = needs[x].clone();
                for g in above.iter().take(gap_z) {
                    bits.clear(&g[x]);
                }
                bits.lines(&lat.lattices[x])
            };
            above.push_front(grown);
            above.truncate(gap_z.max(1));
        }
        top = bottom;
    }
    out
}

/// The region form of the support (for hatch directions the lattices do not carry): every
/// layer's overhang area and support region, the need carried top-down by a sequential union
/// of outlines.
pub fn support_regions(regions: &[Shapes], s: &Settings) -> Vec<(f64, Shapes)> {
    let n = regions.len();
    let overhangs = par_map(n, &|i| {
        crate::support::overhang::overhang_region(
            &regions[i],
            i.checked_sub(1).map(|j| &regions[j]),
            s,
        )
    });
    let reach = support_reach(s);
    // Simplified within the support's tolerance here, on all cores: the sequential union
    // below then works on fewer points.
    let grown: Vec<Shapes> = par_map(n, &|i| {
        simplified(&grow_fast(&overhangs[i], reach, SUPPORT_TOLERANCE_MM))
    });
    // The part as it clips the need, outlines simplified within the support's tolerance
    // (fewer points for the sequential union below; the gap to the true part is kept droplet
    // by droplet when the support is planned).
    let clips = par_map(n, &|i| simplified(&regions[i]));
    // Top-down: what the layers above still need carried (the part below carries what it
    // covers).
    let mut needs = vec![Shapes::new(); n];
    for i in (0..n.saturating_sub(1)).rev() {
        needs[i] = carried(&needs[i + 1], &grown[i + 1], &clips[i]);
    }
    let gap_z = s.support_gap_z as usize;
    let supports = if gap_z == 0 {
        needs
    } else {
        par_map(n, &|i| {
            let mut region = needs[i].clone();
            for k in 1..=gap_z.min(n - 1 - i) {
                region = difference(&region, &grown[i + k]);
            }
            region
        })
    };
    overhangs
        .iter()
        .map(overhang_figure)
        .zip(supports)
        .collect()
}

/// `f(0..n)` on all cores (natively), in index order of the result.
#[cfg(not(target_arch = "wasm32"))]
pub fn par_map<R: Send>(n: usize, f: &(dyn Fn(usize) -> R + Sync)) -> Vec<R> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(n.max(1));
    let next = AtomicUsize::new(0);
    let mut parts: Vec<Vec<(usize, R)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= n {
                            break mine;
                        }
                        mine.push((i, f(i)));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    let mut all: Vec<(usize, R)> = parts.drain(..).flatten().collect();
    all.sort_unstable_by_key(|(i, _)| *i);
    all.into_iter().map(|(_, r)| r).collect()
}

/// `f(0..n)` in order (a wasm worker is single-threaded).
#[cfg(target_arch = "wasm32")]
pub fn par_map<R: Send>(n: usize, f: &(dyn Fn(usize) -> R + Sync)) -> Vec<R> {
    (0..n).map(f).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::DVec2;
    use crate::base::geom::square;

    #[test]
    fn a_wider_layer_overhangs_by_its_band_beyond_the_limit() {
        let s = Settings::default();
        let b = s.droplet_width();
        // 10 mm square on a 10 mm square shifted 2 mm in x: the overhang is the strip
        // 2 − 0.5·B wide.
        let o = overhang(&square(2.0, 0.0, 10.0), Some(&square(0.0, 0.0, 10.0)), &s);
        let want = (2.0 - 0.5 * b) * 10.0;
        assert!((region_area(&o) - want).abs() < 1e-3, "{}", region_area(&o));
        // The same square above: none; the first layer: none.
        assert!(overhang(&square(0.0, 0.0, 10.0), Some(&square(0.0, 0.0, 10.0)), &s).is_empty());
        assert!(overhang(&square(0.0, 0.0, 10.0), None, &s).is_empty());
        // Within the limit: none.
        let o = overhang(
            &square(0.4 * b, 0.0, 10.0),
            Some(&square(0.0, 0.0, 10.0)),
            &s,
        );
        assert!(region_area(&o) < 1e-9);
    }

    #[test]
    fn grow_moves_a_square_outward_with_round_corners() {
        let g = grow(&square(0.0, 0.0, 10.0), 1.0);
        let want = 100.0 + 4.0 * 10.0 + std::f64::consts::PI;
        assert!((region_area(&g) - want).abs() < 0.01, "{}", region_area(&g));
    }

    #[test]
    fn grow_fast_agrees_with_the_exact_offset_and_the_outline() {
        // A 10 mm square with a 4 mm square hole, grown by 1 mm: the outer boundary gains
        // a 1 mm band with quarter circles at the corners, the hole shrinks to 2 × 2 mm.
        let hole: crate::base::geom::Contour = [[3.0, 3.0], [3.0, 7.0], [7.0, 7.0], [7.0, 3.0]]
            .map(DVec2::from)
            .into();
        let framed = vec![Shape::new(
            square(0.0, 0.0, 10.0)[0].outer.clone(),
            vec![hole],
        )];
        let want = 100.0 + 40.0 + std::f64::consts::PI - 4.0;
        let got = region_area(&grow_fast(&framed, 1.0, SUPPORT_TOLERANCE_MM));
        // Chords within 5 µm of the arcs (2π mm of them).
        assert!((got - want).abs() < 0.04, "{got} against {want}");
        // A U with a 0.3 mm slot: grown by 0.104 mm the slot stays open in its middle, by
        // 0.5 mm it fills. i_overlay's outline (chords within 1 µm) gives the same area
        // within the chords' error.
        let u: Shapes = vec![Shape::new(
            [
                [0.0, 0.0],
                [3.0, 0.0],
                [3.0, 5.0],
                [1.65, 5.0],
                [1.65, 1.0],
                [1.35, 1.0],
                [1.35, 5.0],
                [0.0, 5.0],
            ]
            .map(DVec2::from)
            .into(),
            vec![],
        )];
        for d in [0.104, 0.5] {
            let fast = grow_fast(&u, d, SUPPORT_TOLERANCE_MM);
            let outline = grow_within(&u, d, 0.001);
            let (a, b) = (region_area(&fast), region_area(&outline));
            assert!((a - b).abs() < 0.02, "d {d}: {a} against {b}");
            assert_eq!(fast.len(), 1);
            assert!(fast[0].holes.is_empty());
            let middle = region_area(&intersection(&fast, &square(1.49, 3.0, 0.02)));
            let want = if d < 0.15 { 0.0 } else { 0.0004 };
            assert!((middle - want).abs() < 1e-9, "d {d}: {middle}");
        }
    }

    #[test]
    fn support_fills_under_a_floating_slab_down_to_the_plate() {
        // A post (layers 0..5) and a slab beside it on layers 5..8; every hatch direction
        // carried on lattices (the default) and as regions (a step of 30°: six directions).
        for step in [90.0, 30.0] {
            let s = Settings {
                hatch_angle_step: step,
                ..Settings::default()
            };
            let b1 = s.unit1_droplet_width();
            let mut regions = vec![square(0.0, 0.0, 2.0); 5];
            regions.extend(vec![
                union(&square(0.0, 0.0, 2.0), &square(2.0, 0.0, 4.0));
                3
            ]);
            let layers = support_layers(&regions, &s);
            assert!(
                layers[5].unsupported_area > 7.0,
                "{}",
                layers[5].unsupported_area
            );
            assert_eq!(layers[6].unsupported_area, 0.0);
            let grown = grow(&square(2.0, 0.0, 4.0), support_reach(&s));
            for (i, l) in layers.iter().enumerate() {
                // Under the slab on layers 0..5, nothing from layer 5 up.
                assert_eq!(l.lines.is_empty(), i >= 5, "layer {i}");
                let droplets: Vec<DVec2> = l
                    .lines
                    .iter()
                    .flat_map(|h| crate::base::geom::line_droplets(h.a, h.b, b1))
                    .collect();
                for p in &droplets {
                    // Outside the post (the gap is kept when it is planned), within the
                    // slab and the reach around it.
                    assert!(!(p.x > -1e-9 && p.x < 2.0 + 1e-9 && p.y > -1e-9 && p.y < 2.0 + 1e-9));
                    assert!(
                        !intersection(&grown, &square(p.x - 1e-3, p.y - 1e-3, 2e-3)).is_empty(),
                        "{p}"
                    );
                }
                if i < 5 {
                    // One droplet per B₁² of the slab's area beyond the post (and its reach).
                    let cells = droplets.len() as f64 * b1 * b1;
                    assert!(
                        cells > 16.0 - 1.0 && cells < 30.0,
                        "step {step} layer {i}: {cells}"
                    );
                }
            }
        }
    }

    #[test]
    fn unsupported_droplets_agree_with_every_pair() {
        // Pseudo-random droplets of two layers, both widths: the grid's answer is the answer
        // of comparing every pair.
        let mut seed = 12345_u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let layer: Vec<[f64; 2]> = (0..400).map(|_| [rnd() * 6.0 - 3.0, rnd() * 6.0]).collect();
        let below: Vec<([f64; 2], f64)> = (0..150)
            .map(|_| {
                (
                    [rnd() * 6.0 - 3.0, rnd() * 6.0],
                    if rnd() < 0.5 { 0.2 } else { 0.5 },
                )
            })
            .collect();
        let limit = 0.1;
        let got = unsupported_droplets(&layer, Some(&below), limit);
        let want: Vec<bool> = layer
            .iter()
            .map(|c| {
                !below.iter().any(|(d, w)| {
                    ((c[0] - d[0]).powi(2) + (c[1] - d[1]).powi(2)).sqrt() <= w / 2.0 + limit
                })
            })
            .collect();
        assert_eq!(got, want);
        assert!(want.iter().any(|&u| u) && want.iter().any(|&u| !u));
        // The first layer rests on the plate; nothing below a higher layer: all unsupported.
        assert!(
            unsupported_droplets(&layer, None, limit)
                .iter()
                .all(|&u| !u)
        );
        assert!(
            unsupported_droplets(&layer, Some(&[]), limit)
                .iter()
                .all(|&u| u)
        );
    }

    #[test]
    fn a_face_overhangs_beyond_the_angle_the_limit_carries() {
        // Defaults: limit 0.5, B = 1.04 H: tan θ = 0.52, θ ≈ 27.47° from the vertical.
        let s = Settings::default();
        let z = overhang_face_normal_z(&s);
        let theta = (0.5_f64 * 1.04).atan();
        assert!((z - theta.sin()).abs() < 1e-12, "{z}");
        assert!((theta.to_degrees() - 27.47).abs() < 0.01);
    }
}
