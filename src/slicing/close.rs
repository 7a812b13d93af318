//! Closing a layer's open sections (docs/spec.md 5.3.2), pass 3 of [`super::slice`]'s
//! chaining: the chains that did not close are joined across the rim (the hole's border) their
//! ends lie on, along the wall's curve where the section runs on smoothly.

use super::slice::{MIN_POINT_DISTANCE_MM, Section};
use crate::base::geom::{Contour, DVec2, Point, dist};
use crate::model::mesh::{Mesh, edge_key};

/// A chain that did not close: its points, the mesh edges it starts and ends on, and the
/// lowest segment (facet order) it contains.
pub(super) struct OpenChain {
    pub(super) first: usize,
    pub(super) pts: Vec<Point>,
    pub(super) head: u64,
    pub(super) tail: u64,
}

/// The open boundary of a mesh: every edge that only one facet has, walked into *rims* (a
/// hole's border, the cut edge of a half shell), each edge with its rim and its place along
/// it. A plane crosses a rim an even number of times, and the surface missing inside the rim
/// joins each crossing to one next to it along the rim: an open section is closed across the
/// rim its ends lie on, never across to another piece of the part (docs/spec.md 5.3.2).
#[derive(Debug, Default)]
pub struct Rims {
    /// (edge key, rim, place along the rim), sorted by key.
    edges: Vec<(u64, u32, u32)>,
    /// Edges per rim.
    len: Vec<u32>,
}

impl Rims {
    /// Walks the rims: one sort of the facets' edges, one of the open ones by their first
    /// vertex (the cost of a few passes over the facets; only meshes with open sections ask).
    pub fn of(mesh: &Mesh) -> Rims {
        let mut keys: Vec<(u64, u32, u32)> = mesh
            .facets
            .iter()
            .flat_map(|f| [(0, 1), (1, 2), (2, 0)].map(|(i, j)| (edge_key(f[i], f[j]), f[i], f[j])))
            .collect();
        keys.sort_unstable_by_key(|e| e.0);
        // Open edges, directed as their facet runs along them: (from, to).
        let mut open: Vec<(u32, u32)> = Vec::new();
        let mut k = 0;
        while k < keys.len() {
            let run = keys[k..].partition_point(|e| e.0 == keys[k].0);
            if run == 1 {
                open.push((keys[k].1, keys[k].2));
            }
            k += run;
        }
        drop(keys);
        open.sort_unstable();
        let mut taken = vec![false; open.len()];
        let leaving = |v: u32, taken: &[bool]| -> Option<usize> {
            let a = open.partition_point(|e| e.0 < v);
            (a..open.len())
                .take_while(|&i| open[i].0 == v)
                .find(|&i| !taken[i])
        };
        let mut edges: Vec<(u64, u32, u32)> = Vec::with_capacity(open.len());
        let mut len: Vec<u32> = Vec::new();
        for s in 0..open.len() {
            if taken[s] {
                continue;
            }
            let rim = len.len() as u32;
            let mut e = s;
            let mut at = 0u32;
            loop {
                taken[e] = true;
                edges.push((edge_key(open[e].0, open[e].1), rim, at));
                at += 1;
                match leaving(open[e].1, &taken) {
                    Some(n) => e = n,
                    None => break,
                }
            }
            len.push(at);
        }
        edges.sort_unstable_by_key(|e| e.0);
        Rims { edges, len }
    }

    /// The rim of an edge and its place along it, if only one facet has the edge.
    fn of_edge(&self, edge: u64) -> Option<(u32, u32)> {
        let k = self.edges.partition_point(|e| e.0 < edge);
        self.edges
            .get(k)
            .filter(|e| e.0 == edge)
            .map(|e| (e.1, e.2))
    }

    /// Steps along rim `rim` from place `a` to place `b` forward and backward.
    fn steps(&self, rim: u32, a: u32, b: u32) -> (u32, u32) {
        let n = self.len[rim as usize];
        let fwd = (b + n - a) % n;
        (fwd, (n - fwd) % n)
    }
}

/// Pass 3: joins open chains, taking them in order of their lowest segment. The current
/// chain's end is joined to a free chain end next to it along the rim it lies on (of the
/// nearest such ends before and after it, the nearer in the plane); an end on no rim (a
/// non-manifold edge), or a rim that offers none, takes the nearest end, as CuraEngine and
/// Slic3r stitch open sections. The loop closes when its own start is the one chosen.
pub(super) fn join_open(
    mut open: Vec<OpenChain>,
    rims: &Rims,
    section: &mut Section,
) -> Vec<Contour> {
    section.open_chains += open.len();
    let mut joined = Vec::new();
    open.sort_by_key(|c| c.first);
    let mut open: std::collections::VecDeque<OpenChain> = open.into();
    while let Some(mut cur) = open.pop_front() {
        loop {
            let end = *cur.pts.last().expect("non-empty");
            // Candidates: (chain or None for the own start, reversed?, point, edge).
            let mut cands: Vec<(Option<usize>, bool, Point, u64)> =
                vec![(None, false, cur.pts[0], cur.head)];
            for (k, c) in open.iter().enumerate() {
                cands.push((Some(k), false, c.pts[0], c.head));
                cands.push((Some(k), true, *c.pts.last().expect("non-empty"), c.tail));
            }
            let mut pick = None;
            if let Some((rim, at)) = rims.of_edge(cur.tail) {
                // Along the rim, the candidates closest before and after the end; of those
                // two the nearer in the plane.
                // (steps along the rim, candidate)
                let mut after: Option<(u32, usize)> = None;
                let mut before: Option<(u32, usize)> = None;
                for (n, c) in cands.iter().enumerate() {
                    let Some((r, place)) = rims.of_edge(c.3) else {
                        continue;
                    };
                    if r != rim {
                        continue;
                    }
                    let (fwd, back) = rims.steps(rim, at, place);
                    if after.is_none_or(|a| fwd < a.0) {
                        after = Some((fwd, n));
                    }
                    if before.is_none_or(|b| back < b.0) {
                        before = Some((back, n));
                    }
                }
                pick = match (after, before) {
                    (Some(a), Some(b)) => {
                        Some(if dist(cands[b.1].2, end) < dist(cands[a.1].2, end) {
                            b.1
                        } else {
                            a.1
                        })
                    }
                    _ => None,
                };
            }
            let n = pick.unwrap_or_else(|| {
                let mut n = 0;
                let mut bd = dist(cands[0].2, end);
                for (k, c) in cands.iter().enumerate().skip(1) {
                    let d = dist(c.2, end);
                    if d < bd {
                        (n, bd) = (k, d);
                    }
                }
                n
            });
            let (chain, rev, q, _) = cands[n];
            section.gap_length += dist(q, end);
            let Some(k) = chain else {
                if pick.is_some() {
                    let own = cur.pts.clone();
                    cur.pts.extend(bridge(&own, &own));
                }
                break;
            };
            let mut c = open.remove(k).expect("index in range");
            if rev {
                c.pts.reverse();
                std::mem::swap(&mut c.head, &mut c.tail);
            }
            if pick.is_some() {
                let across = bridge(&cur.pts, &c.pts);
                cur.pts.extend(across);
            }
            cur.pts.extend(c.pts);
            cur.tail = c.tail;
        }
        let cur = cur.pts;
        if cur.len() >= 3 {
            joined.push(cur);
        }
    }
    joined
}

/// Most a join across a rim may turn from a chain's direction (60°, as its cosine): a
/// sharper turn is a corner of the missing surface, bridged straight.
const BRIDGE_MIN_COS: f64 = 0.5;

/// The points that carry a section across a gap in its rim from the end of `from` to the
/// start of `to`, where the gap continues the curve on both sides (a hole in a smooth wall):
/// a cubic Hermite curve with the chains' directions at both ends, so the section keeps the
/// wall's curvature instead of a chord across it (docs/spec.md 5.3.2). Empty (a straight
/// join) where the section turns a corner at the gap, or bends both ways across it.
fn bridge(from: &[Point], to: &[Point]) -> Vec<Point> {
    let (Some(&a), Some(&b)) = (from.last(), to.first()) else {
        return Vec::new();
    };
    let l = dist(a, b);
    if l <= MIN_POINT_DISTANCE_MM * 4.0 {
        return Vec::new();
    }
    // A chain's direction at an end: the secants over a sixth and a third of the gap turn
    // from the tangent in proportion to their length, so the tangent is the first secant
    // turned back by the angle between the two.
    let direction = |pts: &[Point], at: Point| -> Option<DVec2> {
        let back = |reach: f64| -> Option<DVec2> {
            let far = pts
                .iter()
                .take(256)
                .find(|&&p| dist(p, at) >= reach)
                .or(pts.last())?;
            let d = at - *far;
            (d.length() > 1e-9).then(|| d.normalize())
        };
        let (near, far) = (back(l / 6.0)?, back(l / 3.0)?);
        // `near` turned by the angle from `far` to `near`.
        Some(DVec2::from_angle(far.angle_to(near)).rotate(near))
    };
    let from_back: Vec<Point> = from.iter().rev().skip(1).take(256).copied().collect();
    let to_ahead: Vec<Point> = to.iter().skip(1).take(256).copied().collect();
    let (Some(t0), Some(t1)) = (
        direction(&from_back, a),
        direction(&to_ahead, b).map(|d| -d),
    ) else {
        return Vec::new();
    };
    let c = (b - a) / l;
    let (turn0, turn1) = (t0.perp_dot(c), c.perp_dot(t1));
    if t0.dot(c) < BRIDGE_MIN_COS || t1.dot(c) < BRIDGE_MIN_COS || turn0 * turn1 < 0.0 {
        return Vec::new();
    }
    // Tangent length of the Hermite curve closest to a circular arc turning by θ.
    let theta = t0.dot(t1).clamp(-1.0, 1.0).acos();
    let m = if theta < 1e-6 {
        l
    } else {
        l * 2.0 * (theta / 4.0).tan() / (theta / 2.0).sin()
    };
    let steps = ((l / 0.25).ceil() as usize).clamp(2, 32);
    (1..steps)
        .map(|k| {
            let s = k as f64 / steps as f64;
            let (s2, s3) = (s * s, s * s * s);
            let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
            let h10 = s3 - 2.0 * s2 + s;
            let h01 = -2.0 * s3 + 3.0 * s2;
            let h11 = s3 - s2;
            a * h00 + t0 * (m * h10) + b * h01 + t1 * (m * h11)
        })
        .collect()
}
