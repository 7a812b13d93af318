//! The support regions the support's unit prints (docs/spec.md "Overhangs and support"; the rule and the
//! construction are described in [`crate::support`]): every layer's overhang grown by the
//! support's reach and carried down, on the support's lattices or as outlines.

use crate::base::boolean::{bounds, cleaned, difference, grow_within, nested, overlap};
use crate::base::geom::{DVec2, Shape, Shapes, segment_distance2};
use crate::base::settings::Settings;
use crate::base::spatial::EdgeIndex;
use crate::base::steps::{Budget, UNLIMITED, now};
use crate::slicing::fill::{FillParams, FillPattern, hatch_angle};
use crate::slicing::hatch::HatchLine;
use crate::slicing::offset::{CHORD_TOLERANCE_MM, Corners, raw_offset};
use crate::support::lattice::{Bits, Lattices, Runs};
use crate::support::map_in_steps;
use crate::support::overhang::{overhang_figure, support_reach};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::FloatOverlay;
use i_overlay::float::simplify::SimplifyShape;

/// The region moved outward by `d` mm (round joins, chords within [`CHORD_TOLERANCE_MM`]).
pub fn grow(region: &Shapes, d: f64) -> Shapes {
    grow_within(region, d, CHORD_TOLERANCE_MM)
}

/// How far the support's outlines may stray from the exact construction, mm: its offsets'
/// chords and its simplified outlines. Support needs no micrometres; fewer points keep its
/// booleans and its planning fast.
pub const SUPPORT_TOLERANCE_MM: f64 = 0.005;

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

/// One layer's overhang area and the support its unit prints in it.
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
/// carried on the support's lattices ([`crate::support::lattice`]), or, for more hatch directions
/// than it carries, as regions ([`support_regions`]).
pub fn support_layers(regions: &[Shapes], s: &Settings) -> Vec<LayerSupport> {
    now(support_layers_in_steps(regions, s, &UNLIMITED))
}

/// [`support_layers`] in resumable steps (the page's short calls, [`crate::base::steps`]):
/// each layer's overhang, growth and crossings one item of `budget`, the top-down carry one
/// item a layer; with [`UNLIMITED`], on all cores. The same result whatever the budget.
pub async fn support_layers_in_steps(
    regions: &[Shapes],
    s: &Settings,
    budget: &Budget,
) -> Vec<LayerSupport> {
    let s1 = crate::slicing::plan::support_settings(s);
    let b1 = s1.droplet_width();
    if s1.fill_density.is_nan() || s1.fill_density <= 0.0 {
        // No support hatch: the overhang areas only.
        return map_in_steps(regions.len(), budget, &|i| LayerSupport {
            unsupported_area: crate::support::overhang::overhang_area(
                &regions[i],
                i.checked_sub(1).map(|j| &regions[j]),
                s,
            ),
            lines: Vec::new(),
        })
        .await;
    }
    let spacing = b1 / s1.fill_density;
    let reach = support_reach(s) + SUPPORT_TOLERANCE_MM;
    match Lattices::new(regions, s, spacing, b1, reach) {
        Some(lattices) => lattice_layers(regions, s, &lattices, budget).await,
        None => {
            let areas_regions = support_regions_in_steps(regions, s, budget).await;
            map_in_steps(regions.len(), budget, &|i| LayerSupport {
                unsupported_area: areas_regions[i].0,
                lines: FillPattern::Lines.new_from_type().fill(
                    &areas_regions[i].1,
                    &FillParams {
                        angle_deg: hatch_angle(s, i),
                        spacing,
                        phase: 0.5,
                        lattice: Some((b1, 0.0, 0.0)),
                    },
                ),
            })
            .await
        }
    }
}

/// [`support_layers`] on lattices, top-down in blocks of layers: each block's overhangs are
/// found, grown and crossed with every lattice on all cores, then the need is carried through
/// the block by word operations. need(n) = (need(n + 1) ∪ grown overhang(n + 1)) − region(n);
/// the support of layer n is its need less the grown overhangs of the `support_gap_z` layers
/// directly above, on the layer's own lattice.
async fn lattice_layers(
    regions: &[Shapes],
    s: &Settings,
    lat: &Lattices,
    budget: &Budget,
) -> Vec<LayerSupport> {
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
        let block = map_in_steps(top - bottom, budget, &|k| {
            let i = bottom + k;
            let o = crate::support::overhang::overhang_region(
                &regions[i],
                i.checked_sub(1).map(|j| &regions[j]),
                s,
            );
            let grown = grow_fast(&o, reach, SUPPORT_TOLERANCE_MM);
            let on = |r: &Shapes| -> Vec<Runs> { lat.lattices.iter().map(|l| l.runs(r)).collect() };
            (overhang_figure(&o), on(&grown), on(&regions[i]))
        })
        .await;
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
        // The block's carry: word operations, about one layer's item.
        budget.spend(1).await;
        top = bottom;
    }
    out
}

/// The region form of the support (for hatch directions the lattices do not carry): every
/// layer's overhang area and support region, the need carried top-down by a sequential union
/// of outlines.
pub fn support_regions(regions: &[Shapes], s: &Settings) -> Vec<(f64, Shapes)> {
    now(support_regions_in_steps(regions, s, &UNLIMITED))
}

/// [`support_regions`] in resumable steps: each layer's passes one item of `budget`, the
/// top-down union one item a layer.
async fn support_regions_in_steps(
    regions: &[Shapes],
    s: &Settings,
    budget: &Budget,
) -> Vec<(f64, Shapes)> {
    let n = regions.len();
    let overhangs = map_in_steps(n, budget, &|i| {
        crate::support::overhang::overhang_region(
            &regions[i],
            i.checked_sub(1).map(|j| &regions[j]),
            s,
        )
    })
    .await;
    let reach = support_reach(s);
    // Simplified within the support's tolerance here, on all cores: the sequential union
    // below then works on fewer points.
    let grown: Vec<Shapes> = map_in_steps(n, budget, &|i| {
        simplified(&grow_fast(&overhangs[i], reach, SUPPORT_TOLERANCE_MM))
    })
    .await;
    // The part as it clips the need, outlines simplified within the support's tolerance
    // (fewer points for the sequential union below; the gap to the true part is kept droplet
    // by droplet when the support is planned).
    let clips = map_in_steps(n, budget, &|i| simplified(&regions[i])).await;
    // Top-down: what the layers above still need carried (the part below carries what it
    // covers).
    let mut needs = vec![Shapes::new(); n];
    for i in (0..n.saturating_sub(1)).rev() {
        needs[i] = super::timed(budget, || carried(&needs[i + 1], &grown[i + 1], &clips[i]));
        budget.spend(1).await;
    }
    let gap_z = s.support_gap_z as usize;
    let supports = if gap_z == 0 {
        needs
    } else {
        map_in_steps(n, budget, &|i| {
            let mut region = needs[i].clone();
            for k in 1..=gap_z.min(n - 1 - i) {
                region = difference(&region, &grown[i + k]);
            }
            region
        })
        .await
    };
    overhangs
        .iter()
        .map(overhang_figure)
        .zip(supports)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::boolean::{intersection, union};
    use crate::base::geom::DVec2;
    use crate::base::geom::region_area;
    use crate::base::geom::square;
    use crate::support::overhang::{overhang, overhang_face_normal_z, unsupported_droplets};

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
            let b1 = s.support_width();
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
