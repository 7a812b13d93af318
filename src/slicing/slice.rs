//! Slice, stage 2 (docs/spec.md 5.3.2): a [`Mesh`] and a plane height → the layer's [`Section`]:
//! its material region as shapes (outer boundary counter-clockwise, holes clockwise).
//!
//! Rules:
//! - A vertex exactly on the plane counts as *above* it (the plane is taken infinitesimally
//!   below z). Every crossing facet then has exactly one below→above and one above→below edge,
//!   faces lying in the plane contribute nothing, and no loop breaks on a vertex hit.
//! - A segment runs from the point on the facet's above→below edge to the point on its
//!   below→above edge, which leaves the material on its left for outward-wound facets: the
//!   orientation comes from the facets' vertex order, never from stored normals.
//! - The point on an edge is computed from the edge's lower to its upper vertex, so the two
//!   facets sharing the edge produce bit-identical points.
//! - Segments are chained through shared mesh edges (exact topology). Segments left over
//!   (flipped facets, non-manifold or open meshes) are chained ignoring direction, and chains
//!   that still do not close are closed across the rim (hole border) their ends lie on, along
//!   the wall's curve where it runs on smoothly ([`Rims`], `slicing/close.rs`); ends on no
//!   rim take the nearest end (as CuraEngine and Slic3r do). Those repairs are counted in
//!   [`Section`].
//! - Overlapping shells are merged with the non-zero fill rule (their union), as PrusaSlicer
//!   and CuraEngine do.

pub use super::close::Rims;
use super::close::{OpenChain, join_open};
use crate::base::boolean::{Paths, simplify_apart};
use crate::base::geom::{
    Contour, DVec2, Point, Shapes, dist, greater, lesser, shapes_from_overlay, signed_area,
    to_overlay,
};
use crate::base::parallel::in_runs;
use crate::base::settings::SlicePlane;
use crate::base::steps::{self, Budget};
use crate::model::mesh::{Mesh, edge_key};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::float::simplify::SimplifyShape;
use rustc_hash::FxHashMap;
use std::sync::OnceLock;

/// Points closer than this to their predecessor on a loop are dropped (docs/spec.md 5.3.2).
pub const MIN_POINT_DISTANCE_MM: f64 = 0.001;

/// Plane heights are rounded to 1/this mm so they do not drift (0.1 + 42·0.2 = 8.5 exactly).
const Z_STEPS_PER_MM: f64 = 1e9;

/// The plane height of every layer, measured from the part's lowest point (z = 0).
pub fn layer_heights(part_height: f64, layer_height: f64, plane: SlicePlane) -> Vec<f64> {
    let round = |z: f64| (z * Z_STEPS_PER_MM).round() / Z_STEPS_PER_MM;
    let mut zs = Vec::new();
    if !(layer_height > 0.0 && part_height.is_finite()) {
        return zs;
    }
    for i in 0.. {
        let z = match plane {
            // Planes at mid-layer below the top (the oracle's and the peers' rule).
            SlicePlane::Middle => round((i as f64 + 0.5) * layer_height),
            // The layer's top, clamped to the part's top for a last, thinner layer.
            SlicePlane::Top => {
                let bottom = round(i as f64 * layer_height);
                if bottom >= part_height {
                    break;
                }
                round(((i + 1) as f64 * layer_height).min(part_height))
            }
        };
        if z >= part_height && plane == SlicePlane::Middle {
            break;
        }
        zs.push(z);
    }
    zs
}

/// Facet ids per layer: the facets crossing each plane, found once for the whole part
/// (compressed rows: layer i's facets are `facets[offsets[i]..offsets[i+1]]`), each row
/// ordered by the facets' lowest z (ties in file order), which fixes the order in which open
/// chains are joined.
pub struct FacetBuckets {
    offsets: Vec<u32>,
    facets: Vec<u32>,
}

impl FacetBuckets {
    pub fn new(mesh: &Mesh, zs: &[f64]) -> FacetBuckets {
        steps::now(FacetBuckets::new_in_steps(mesh, zs, &steps::UNLIMITED))
    }

    /// [`FacetBuckets::new`] in resumable steps ([`steps::runs`]).
    pub async fn new_in_steps(mesh: &Mesh, zs: &[f64], b: &Budget) -> FacetBuckets {
        // Every pass over the facets runs in runs of them (`in_runs`: the page's engine
        // compiles the later runs well).
        let nf = mesh.facets.len();
        // Per facet: its lowest z and the planes it crosses (lo < z <= hi).
        let mut spans: Vec<(f64, u32, u32)> = Vec::with_capacity(nf);
        steps::runs(nf, b, &mut |r| {
            spans.extend(mesh.facets[r].iter().map(|f| {
                let z = f.map(|i| mesh.vertices[i as usize][2]);
                let lo = lesser(lesser(z[0], z[1]), z[2]);
                let hi = greater(greater(z[0], z[1]), z[2]);
                let a = zs.partition_point(|&p| p <= lo) as u32;
                let b = zs.partition_point(|&p| p <= hi) as u32;
                (lo, a, b.max(a))
            }))
        })
        .await;
        let mut counts = vec![0u32; zs.len() + 1];
        // The facets by their first plane (a counting sort that keeps file order; those
        // crossing no plane are left out), counted beside the rows.
        let mut run = vec![0u32; zs.len() + 1];
        steps::runs(nf, b, &mut |r| {
            // (slices of their own: their bounds stay in registers through the stores)
            let (counts, run) = (&mut counts[..], &mut run[..]);
            for &(_, a, b) in &spans[r] {
                for i in a..b {
                    counts[i as usize + 1] += 1;
                }
                if a < b {
                    run[a as usize + 1] += 1;
                }
            }
        })
        .await;
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let offsets = counts.clone();
        let mut fill = counts;
        let mut facets = vec![0u32; *offsets.last().unwrap_or(&0) as usize];
        // Lowest z first, ties in file order. A facet's first plane never decreases with its
        // lowest z, so the facets are put in runs by their first plane, and only each run is
        // sorted by lowest z: small sorts instead of one of every facet.
        for i in 1..run.len() {
            run[i] += run[i - 1];
        }
        let mut order: Vec<(f64, u32)> = vec![(0.0, 0); *run.last().unwrap_or(&0) as usize];
        let mut at = run.clone();
        steps::runs(nf, b, &mut |r| {
            let (order, at) = (&mut order[..], &mut at[..]);
            for (f, &(lo, a, b)) in spans[r.clone()].iter().enumerate() {
                if a < b {
                    order[at[a as usize] as usize] = (lo, (r.start + f) as u32);
                    at[a as usize] += 1;
                }
            }
        })
        .await;
        drop(at);
        for w in run.windows(2) {
            order[w[0] as usize..w[1] as usize]
                .sort_unstable_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
            b.spend((w[1] - w[0]) as usize).await;
        }
        steps::runs(order.len(), b, &mut |r| {
            let (facets, fill) = (&mut facets[..], &mut fill[..]);
            for &(_, f) in &order[r] {
                let (_, a, b) = spans[f as usize];
                for i in a..b {
                    facets[fill[i as usize] as usize] = f;
                    fill[i as usize] += 1;
                }
            }
        })
        .await;
        FacetBuckets { offsets, facets }
    }

    pub fn layer(&self, i: usize) -> &[u32] {
        &self.facets[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// The rows as stored: one offset per layer and one past the last, then every layer's
    /// facets one after the other (for [`FacetBuckets::from_rows`]).
    pub(crate) fn rows(&self) -> (&[u32], &[u32]) {
        (&self.offsets, &self.facets)
    }

    /// The index [`FacetBuckets::rows`] gave, checked for `layers` layers of a mesh of
    /// `facets` facets: offsets from 0, never falling, ending at the last facet listed; every
    /// facet number below `facets`.
    pub(crate) fn from_rows(
        offsets: Vec<u32>,
        listed: Vec<u32>,
        layers: usize,
        facets: usize,
    ) -> Result<FacetBuckets, String> {
        let sound = offsets.len() == layers + 1
            && offsets[0] == 0
            && offsets.windows(2).all(|w| w[0] <= w[1])
            && offsets[layers] as usize == listed.len()
            && {
                // (in runs: [`in_runs`])
                let mut fit = true;
                in_runs(listed.len(), &mut |r| {
                    fit = fit && listed[r].iter().all(|&f| (f as usize) < facets)
                });
                fit
            };
        if !sound {
            return Err("the facet index does not fit the layers and the mesh".into());
        }
        Ok(FacetBuckets {
            offsets,
            facets: listed,
        })
    }
}

/// One layer's cross-section.
#[derive(Clone, Debug, Default)]
pub struct Section {
    pub z: f64,
    /// The material (union of all shells).
    pub region: Shapes,
    /// Loops closed by plain topology.
    pub closed_loops: usize,
    /// Loops that needed segments chained against their direction (flipped facets).
    pub reoriented_loops: usize,
    /// Open chains that were joined to close the section.
    pub open_chains: usize,
    /// Total length of the gaps bridged to close open chains, in mm.
    pub gap_length: f64,
}

#[derive(Clone, Copy, Debug)]
struct Segment {
    a: Point,
    b: Point,
    /// Edge the segment starts on (the facet's above→below edge).
    start: u64,
    /// Edge the segment ends on (the facet's below→above edge).
    end: u64,
}

/// Cuts the mesh at height `z`, using only the given facets (those that may cross it).
/// `rims` holds the mesh's [`Rims`], found on the first open section (a closed mesh never
/// needs them).
pub fn slice_layer(mesh: &Mesh, facets: &[u32], z: f64, rims: &OnceLock<Rims>) -> Section {
    let (contours, mut section) = section_loops(mesh, facets, z, rims);
    section.region = union(&contours);
    section
}

/// The closed loops of a cut before their union (and the section's statistics, without region).
pub fn section_loops(
    mesh: &Mesh,
    facets: &[u32],
    z: f64,
    rims: &OnceLock<Rims>,
) -> (Vec<Contour>, Section) {
    let segments = segments(mesh, facets, z);
    let mut section = Section {
        z,
        ..Section::default()
    };
    let (loops, joined) = chain(&segments, &mut section, || {
        rims.get_or_init(|| Rims::of(mesh))
    });
    let mut contours: Vec<Contour> = loops
        .into_iter()
        .map(clean_loop)
        .filter(|c| c.len() >= 3)
        .collect();
    for c in joined.into_iter().map(clean_loop).filter(|c| c.len() >= 3) {
        contours.extend(resolve_joined(&c));
    }
    (contours, section)
}

/// A loop closed across gaps may cross itself, so its winding numbers mean little: its
/// inside is taken by the even-odd rule, oriented as the loop's overall signed area says
/// (counter-clockwise: material; clockwise: a hole in what surrounds it).
fn resolve_joined(c: &Contour) -> Vec<Contour> {
    let clockwise = signed_area(c) < 0.0;
    to_overlay([c])
        .simplify_shape(FillRule::EvenOdd)
        .into_iter()
        .flatten()
        .map(crate::base::geom::contour_from_overlay)
        .map(|mut ring| {
            if clockwise {
                ring.reverse();
            }
            ring
        })
        .collect()
}

/// The non-zero union of closed loops: shapes with outer boundaries CCW and holes CW. Loops
/// far apart are united apart, with the result of one pass (`simplify_apart`).
pub fn union(contours: &[Contour]) -> Shapes {
    if contours.is_empty() {
        return Shapes::new();
    }
    let items: Vec<Paths> = contours
        .iter()
        .map(|c| vec![c.iter().map(|p| p.to_array()).collect()])
        .collect();
    shapes_from_overlay(simplify_apart(&items, FillRule::NonZero))
}

fn segments(mesh: &Mesh, facets: &[u32], z: f64) -> Vec<Segment> {
    let mut out = Vec::with_capacity(facets.len());
    for &f in facets {
        let ids = mesh.facets[f as usize];
        let p = ids.map(|i| mesh.vertices[i as usize]);
        let above = p.map(|v| v[2] >= z);
        let (mut down, mut up) = (None, None);
        for k in 0..3 {
            let n = (k + 1) % 3;
            if above[k] && !above[n] {
                down = Some((k, n));
            } else if !above[k] && above[n] {
                up = Some((k, n));
            }
        }
        let (Some(down), Some(up)) = (down, up) else {
            continue;
        };
        let point = |(i, j): (usize, usize)| {
            // From the lower (below) vertex to the upper one: identical in both facets.
            let (lo, hi) = if above[i] { (p[j], p[i]) } else { (p[i], p[j]) };
            let t = (z - lo[2]) / (hi[2] - lo[2]);
            DVec2::new(lo[0] + t * (hi[0] - lo[0]), lo[1] + t * (hi[1] - lo[1]))
        };
        out.push(Segment {
            a: point(down),
            b: point(up),
            start: edge_key(ids[down.0], ids[down.1]),
            end: edge_key(ids[up.0], ids[up.1]),
        });
    }
    out
}

/// Chains segments into closed loops (see the module docs for the three passes).
/// Returns the loops closed by topology and, apart, those joined across gaps (pass 3).
fn chain<'r>(
    segs: &[Segment],
    section: &mut Section,
    rims: impl FnOnce() -> &'r Rims,
) -> (Vec<Contour>, Vec<Contour>) {
    let (mut loops, leftovers) = chain_directed(segs, section);
    if leftovers.is_empty() {
        return (loops, Vec::new());
    }
    let open = chain_undirected(segs, &leftovers, &mut loops, section);
    if open.is_empty() {
        return (loops, Vec::new());
    }
    (loops, join_open(open, rims(), section))
}

/// Pass 1: directed chaining through shared edges. Returns the closed loops and the segments
/// of the chains that did not close.
fn chain_directed(segs: &[Segment], section: &mut Section) -> (Vec<Contour>, Vec<usize>) {
    let mut used = vec![false; segs.len()];
    // The segments starting on each edge, lowest index first: the first of a key in
    // `first`, each one's next in `next` (a closed mesh has one a key).
    const NONE: u32 = u32::MAX;
    let mut first: FxHashMap<u64, u32> = FxHashMap::default();
    first.reserve(segs.len());
    let mut next = vec![NONE; segs.len()];
    for (i, s) in segs.iter().enumerate().rev() {
        if let Some(later) = first.insert(s.start, i as u32) {
            next[i] = later;
        }
    }
    let find_start = |key: u64, used: &[bool]| -> Option<usize> {
        let mut i = first.get(&key).copied().unwrap_or(NONE);
        while i != NONE {
            if !used[i as usize] {
                return Some(i as usize);
            }
            i = next[i as usize];
        }
        None
    };

    let mut loops = Vec::new();
    let mut leftovers: Vec<usize> = Vec::new();
    for s0 in 0..segs.len() {
        if used[s0] {
            continue;
        }
        used[s0] = true;
        let mut chain = vec![s0];
        let mut cur = s0;
        let closed = loop {
            if segs[cur].end == segs[s0].start {
                break true;
            }
            match find_start(segs[cur].end, &used) {
                Some(n) => {
                    used[n] = true;
                    chain.push(n);
                    cur = n;
                }
                None => break false,
            }
        };
        if closed {
            section.closed_loops += 1;
            loops.push(chain.iter().map(|&i| segs[i].a).collect());
        } else {
            leftovers.extend(chain);
        }
    }
    (loops, leftovers)
}

/// Pass 2: chains the leftovers ignoring direction (flipped facets reverse a segment); loops
/// that close are added to `loops`, oriented by the majority of their facets. Returns the
/// chains that stay open, each with the lowest segment (facet order) it contains.
fn chain_undirected(
    segs: &[Segment],
    leftovers: &[usize],
    loops: &mut Vec<Contour>,
    section: &mut Section,
) -> Vec<OpenChain> {
    let mut by_key: Vec<(u64, u32)> = leftovers
        .iter()
        .flat_map(|&i| [(segs[i].start, i as u32), (segs[i].end, i as u32)])
        .collect();
    by_key.sort_unstable();
    let mut free = vec![false; segs.len()];
    for &i in leftovers {
        free[i] = true;
    }
    let neighbour =
        |key: u64, free: &[bool]| -> Option<usize> { first_of_key(&by_key, key, |i| free[i]) };
    let mut open: Vec<OpenChain> = Vec::new();
    for &s0 in leftovers {
        if !free[s0] {
            continue;
        }
        free[s0] = false;
        // Oriented steps: (segment, forward?)
        let mut steps = vec![(s0, true)];
        let mut tail = segs[s0].end;
        let mut closed = false;
        while let Some(n) = neighbour(tail, &free) {
            free[n] = false;
            let fwd = segs[n].start == tail;
            tail = if fwd { segs[n].end } else { segs[n].start };
            steps.push((n, fwd));
            if tail == segs[s0].start {
                closed = true;
                break;
            }
        }
        if !closed {
            // Grow the chain backwards from its head as well.
            let mut head = segs[s0].start;
            while let Some(n) = neighbour(head, &free) {
                free[n] = false;
                let fwd = segs[n].end == head;
                head = if fwd { segs[n].start } else { segs[n].end };
                steps.insert(0, (n, fwd));
            }
        }
        // Orientation: the majority (by length) of the facets decides.
        let (mut with, mut against) = (0.0, 0.0);
        for &(i, fwd) in &steps {
            let l = dist(segs[i].a, segs[i].b);
            if fwd { with += l } else { against += l }
        }
        let mut pts: Vec<Point> = steps
            .iter()
            .map(|&(i, fwd)| if fwd { segs[i].a } else { segs[i].b })
            .collect();
        let last = steps.last().expect("non-empty");
        pts.push(if last.1 {
            segs[last.0].b
        } else {
            segs[last.0].a
        });
        // The edges the chain starts and ends on.
        let first = steps[0];
        let mut head = if first.1 {
            segs[first.0].start
        } else {
            segs[first.0].end
        };
        let mut tail = if last.1 {
            segs[last.0].end
        } else {
            segs[last.0].start
        };
        if against > with {
            pts.reverse();
            std::mem::swap(&mut head, &mut tail);
        }
        if closed {
            pts.pop();
            section.reoriented_loops += 1;
            loops.push(pts);
        } else {
            open.push(OpenChain {
                first: steps.iter().map(|s| s.0).min().expect("non-empty"),
                pts,
                head,
                tail,
            });
        }
    }

    open
}

/// Drops points closer than [`MIN_POINT_DISTANCE_MM`] to the previous kept point, then
/// simplifies the loop (Douglas–Peucker): no removed point lies farther than
/// [`SIMPLIFY_TOLERANCE_MM`] from the result. Dense meshes give thousands of nearly collinear
/// points per section; this keeps the offsets fast while moving the outline by at most a
/// micrometre (the straight-segment merge of docs/spec.md 5.3.2, by distance, not angle).
fn clean_loop(points: Vec<Point>) -> Contour {
    let mut out: Contour = Vec::with_capacity(points.len());
    for p in points {
        if out
            .last()
            .is_none_or(|&q| dist(p, q) >= MIN_POINT_DISTANCE_MM)
        {
            out.push(p);
        }
    }
    while out.len() > 1 && dist(out[0], *out.last().unwrap()) < MIN_POINT_DISTANCE_MM {
        out.pop();
    }
    simplify_closed(&out, SIMPLIFY_TOLERANCE_MM)
}

/// Largest distance between a loop and its simplification.
pub const SIMPLIFY_TOLERANCE_MM: f64 = 0.001;

/// Douglas–Peucker on a closed polygon, anchored at point 0 and the point farthest from it.
pub fn simplify_closed(c: &[Point], tol: f64) -> Contour {
    let n = c.len();
    if n < 4 {
        return c.to_vec();
    }
    let far = (1..n)
        .max_by(|&i, &j| dist(c[0], c[i]).total_cmp(&dist(c[0], c[j])))
        .expect("n >= 4");
    let mut keep = vec![false; n + 1];
    keep[0] = true;
    keep[far] = true;
    keep[n] = true;
    // Index n stands for point 0 again (closing the loop); the points between two indices
    // are below n.
    let at = |i: usize| if i == n { c[0] } else { c[i] };
    let mut stack = vec![(0usize, far), (far, n)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (p, q) = (at(a), at(b));
        let d = q - p;
        let len = d[0].hypot(d[1]);
        let (mut worst, mut wd) = (0, -1.0);
        for (i, &r) in c[a + 1..b].iter().enumerate() {
            let i = a + 1 + i;
            let e = if len > 0.0 {
                ((r[0] - p[0]) * d[1] - (r[1] - p[1]) * d[0]).abs() / len
            } else {
                dist(r, p)
            };
            if e > wd {
                (worst, wd) = (i, e);
            }
        }
        if wd > tol {
            keep[worst] = true;
            stack.push((a, worst));
            stack.push((worst, b));
        }
    }
    (0..n).filter(|&i| keep[i]).map(|i| c[i]).collect()
}

/// In `sorted` (pairs of key and index, sorted), the first index of `key` that `ok` accepts.
#[inline]
fn first_of_key(sorted: &[(u64, u32)], key: u64, ok: impl Fn(usize) -> bool) -> Option<usize> {
    let from = sorted.partition_point(|e| e.0 < key);
    sorted[from..]
        .iter()
        .take_while(|e| e.0 == key)
        .map(|e| e.1 as usize)
        .find(|&i| ok(i))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heights_do_not_drift() {
        let zs = layer_heights(20.0, 0.2, SlicePlane::Middle);
        assert_eq!(zs.len(), 100);
        assert_eq!(zs[42], 8.5);
        let zs = layer_heights(28.31, 0.2, SlicePlane::Middle);
        assert_eq!(zs.len(), 142);
        let zs = layer_heights(20.0, 0.2, SlicePlane::Top);
        assert_eq!(zs.len(), 100);
        assert_eq!(*zs.last().unwrap(), 20.0);
    }

    // Each layer's facets are those crossing its plane, lowest z first and ties in file order,
    // as one sort of every facet gives them: facets whose lowest corners tie (many at one z,
    // ±0), lie exactly on a plane, span several planes or none.
    #[test]
    fn buckets_are_every_crossing_facet_by_lowest_z() {
        let zs = layer_heights(3.0, 0.5, SlicePlane::Middle);
        let mut vertices = Vec::new();
        let mut facets = Vec::new();
        let mut x = 7u64;
        for i in 0..600u32 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            // lowest z on a coarse grid of 0.25 (on planes, between them, ties), −0 for some
            let lo = match i % 9 {
                0 => -0.0,
                1 => 0.0,
                _ => ((x >> 40) % 13) as f64 * 0.25,
            };
            let span = ((x >> 20) % 7) as f64 * 0.3;
            let base = vertices.len() as u32;
            vertices.extend([
                [0.0, 0.0, lo + span],
                [1.0, 0.0, lo],
                [0.0, 1.0, lo + span / 2.0],
            ]);
            facets.push([base, base + 1, base + 2]);
        }
        let mesh = Mesh { vertices, facets };
        let b = FacetBuckets::new(&mesh, &zs);
        for (i, &z) in zs.iter().enumerate() {
            let mut want: Vec<(f64, u32)> = (0..mesh.facets.len() as u32)
                .filter_map(|f| {
                    let c = mesh.facets[f as usize].map(|v| mesh.vertices[v as usize][2]);
                    let (lo, hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
                    (lo < z && z <= hi).then_some((lo, f))
                })
                .collect();
            want.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
            let want: Vec<u32> = want.into_iter().map(|(_, f)| f).collect();
            assert_eq!(b.layer(i), &want[..], "layer {i} at z = {z}");
        }
    }
}
