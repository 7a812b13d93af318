//! The welds of stage 1b ([`crate::model::mesh`]): the exact weld of a triangle soup into a
//! [`Mesh`] (float32 corners equal bit for bit, in one pass or two halves side by side), the
//! tolerance weld (near-coincident vertices, through a grid of cells) and the bounded
//! reservation of their maps ([`reserve_entries`]).

use crate::base::spatial::floor_i64;
use crate::base::steps::{self, Budget};
use crate::model::mesh::Mesh;
use rustc_hash::FxHashMap as HashMap;

impl Mesh {
    /// Welds corners whose float32 coordinates are bit-identical (−0 = +0) and drops facets
    /// that collapse to a line or a point.
    pub fn weld(tris: &[[[f32; 3]; 3]]) -> (Mesh, usize) {
        if cfg!(not(target_arch = "wasm32")) && WELD_HALVES.contains(&tris.len()) {
            return Self::weld_in_halves(tris);
        }
        Self::weld_in_one(tris)
    }

    /// [`Mesh::weld`] in one pass: each corner looked up in one map of every vertex so far.
    fn weld_in_one(tris: &[[[f32; 3]; 3]]) -> (Mesh, usize) {
        steps::now(Self::weld_in_steps(tris, &steps::UNLIMITED))
    }

    /// [`Mesh::weld`] in resumable steps ([`steps::runs`]): the one pass' mesh.
    pub async fn weld_in_steps(tris: &[[[f32; 3]; 3]], budget: &Budget) -> (Mesh, usize) {
        let (_, vertices, mut facets) =
            weld_local(tris, tris.len(), tris.len() / 2 + 16, budget).await;
        facets.retain(distinct);
        let degenerate = tris.len() - facets.len();
        (Mesh { vertices, facets }, degenerate)
    }

    /// [`Mesh::weld`] as two halves of the facets welded side by side, each into a map of its
    /// own, then joined: a vertex of the second half that the first has takes its number, the
    /// others follow in the order they were first met. That is the one pass' numbering,
    /// vertex for vertex and facet for facet.
    fn weld_in_halves(tris: &[[[f32; 3]; 3]]) -> (Mesh, usize) {
        let (first, second) = tris.split_at(tris.len() / 2);
        let ((index, mut vertices, mut facets), (later_index, later, later_ids)) =
            crate::base::parallel::both(
                // the first half's lists take the whole mesh (no copy when they grow)
                || {
                    let all = &steps::UNLIMITED;
                    steps::now(weld_local(first, tris.len(), tris.len() / 2 + 16, all))
                },
                || {
                    let all = &steps::UNLIMITED;
                    steps::now(weld_local(second, second.len(), second.len() / 2 + 16, all))
                },
            );
        drop(later_index);
        // (f32 → f64 → f32 is exact: the key of the corner as read)
        let joined: Vec<u32> = later
            .iter()
            .map(|p| match index.get(&weld_key(p.map(|c| c as f32))) {
                Some(&v) => v,
                None => {
                    vertices.push(*p);
                    (vertices.len() - 1) as u32
                }
            })
            .collect();
        drop((index, later));
        facets.retain(distinct);
        facets.extend(
            later_ids
                .iter()
                .map(|f| f.map(|v| joined[v as usize]))
                .filter(distinct),
        );
        let degenerate = tris.len() - facets.len();
        (Mesh { vertices, facets }, degenerate)
    }

    /// Merges vertices closer than `tol` (mm) to an earlier vertex (cracks left by exporters
    /// that write near-coincident corners), drops facets that collapse, and returns how many
    /// vertices were merged. Used only as a fallback when the exact weld leaves open edges.
    pub fn weld_tolerance(&mut self, tol: f64) -> usize {
        self.weld_tolerance_kept(tol).0
    }

    /// [`weld_tolerance`](Self::weld_tolerance), also returning which of the facets before
    /// were kept (the others keep their order).
    pub fn weld_tolerance_kept(&mut self, tol: f64) -> (usize, Vec<bool>) {
        let cell = |p: &[f64; 3]| p.map(|c| floor_i64(c / tol));
        // Per cell its kept vertices as a list: the first and the last (in the map), each
        // one's next (`next`), in the order they were kept. The map grows as cells are met
        // from a bounded reservation ([`reserve_entries`]).
        let entry = std::mem::size_of::<([i64; 3], [u32; 2])>();
        let mut grid: HashMap<[i64; 3], [u32; 2]> = HashMap::with_capacity_and_hasher(
            reserve_entries(self.vertices.len(), entry),
            Default::default(),
        );
        let mut next: Vec<u32> = Vec::new();
        let mut remap: Vec<u32> = Vec::with_capacity(self.vertices.len());
        let mut kept: Vec<[f64; 3]> = Vec::new();
        let mut merged = 0;
        for v in &self.vertices {
            let c = cell(v);
            let mut found = None;
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(&[first, _]) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                            let mut id = first;
                            while id != u32::MAX {
                                let w = kept[id as usize];
                                let d2 = (0..3).map(|k| (w[k] - v[k]).powi(2)).sum::<f64>();
                                if d2 <= tol * tol {
                                    found = Some(id);
                                    break 'search;
                                }
                                id = next[id as usize];
                            }
                        }
                    }
                }
            }
            let id = found.unwrap_or_else(|| {
                kept.push(*v);
                next.push(u32::MAX);
                let id = (kept.len() - 1) as u32;
                grid.entry(c)
                    .and_modify(|[_, last]| {
                        next[*last as usize] = id;
                        *last = id;
                    })
                    .or_insert([id, id]);
                id
            });
            if found.is_some() {
                merged += 1;
            }
            remap.push(id);
        }
        drop((grid, next));
        self.vertices = kept;
        let facets: Vec<[u32; 3]> = self
            .facets
            .iter()
            .map(|f| f.map(|i| remap[i as usize]))
            .collect();
        let alive: Vec<bool> = facets
            .iter()
            .map(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2])
            .collect();
        self.facets = facets
            .into_iter()
            .zip(&alive)
            .filter_map(|(f, &a)| a.then_some(f))
            .collect();
        (merged, alive)
    }
}

/// Most bytes a weld's map reserves before it is filled: beyond, it grows as vertices are
/// met, so it never asks for more than the vertices it holds need (a reservation for every
/// corner of a 20-million-triangle file would be gigabytes up front).
pub const WELD_RESERVE_BYTES: usize = 64 << 20;

/// The entries a weld's map of `entry_bytes` an entry reserves for `expected` entries: as
/// many, at most [`WELD_RESERVE_BYTES`] worth.
pub fn reserve_entries(expected: usize, entry_bytes: usize) -> usize {
    expected.min(WELD_RESERVE_BYTES / entry_bytes.max(1))
}

/// Files of this many facets are welded in two halves side by side ([`Mesh::weld`]; natively).
/// Below, the join costs more than the halves save; above, memory decides: the halves' two
/// maps and lists take up to twice the one pass' (where each half meets nearly every vertex,
/// as in a file that lists every quad's first triangles before their second ones: +80 MB on
/// 4M facets, over the largest files' memory target).
const WELD_HALVES: std::ops::RangeInclusive<usize> = 50_000..=2_000_000;

/// A corner's weld key: its coordinates' bits, −0 as +0.
fn weld_key(p: [f32; 3]) -> [u32; 3] {
    p.map(|c| if c == 0.0 { 0u32 } else { c.to_bits() })
}

/// Whether [`Mesh::weld`] keeps a facet of triangle `t`: its three corners are distinct
/// vertices (corners equal bit for bit, 0 and −0 alike, are one vertex). Counting these
/// gives the welded mesh's facets without welding.
pub fn keeps_facet(t: &[[f32; 3]; 3]) -> bool {
    let [a, b, c] = t.map(weld_key);
    a != b && b != c && a != c
}

/// Whether a welded facet's three vertices differ (it did not collapse).
fn distinct(f: &[u32; 3]) -> bool {
    f[0] != f[1] && f[1] != f[2] && f[0] != f[2]
}

/// The weld of `tris` ([`Mesh::weld_in_one`], or one half of [`Mesh::weld_in_halves`]): the
/// map of its vertices, the vertices in the order first met, and every facet's vertex numbers
/// (collapsed ones too); the two lists with room for `vertices` and `facets`.
#[allow(clippy::type_complexity)]
async fn weld_local(
    tris: &[[[f32; 3]; 3]],
    facets: usize,
    vertices: usize,
    budget: &Budget,
) -> (HashMap<[u32; 3], u32>, Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let entry = std::mem::size_of::<([u32; 3], u32)>();
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity_and_hasher(
        reserve_entries(tris.len() / 2 + 16, entry),
        Default::default(),
    );
    let mut points = Vec::with_capacity(vertices);
    let mut ids = Vec::with_capacity(facets);
    // In runs of triangles ([`steps::runs`]: the page's engine compiles the later runs well).
    steps::runs(tris.len(), budget, &mut |r| {
        ids.extend(tris[r].iter().map(|t| {
            t.map(|p| {
                *index.entry(weld_key(p)).or_insert_with(|| {
                    points.push(p.map(f64::from));
                    (points.len() - 1) as u32
                })
            })
        }))
    })
    .await;
    (index, points, ids)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_weld_reserves_at_most_its_bound() {
        // A closed mesh's vertices are reserved for as they are expected, under the bound.
        assert_eq!(reserve_entries(500_016, 16), 500_016);
        // 20 million loose triangles: 60 million corners, 32-byte entries of the tolerance
        // weld: the reservation stays at the bound (64 MB), not 2 GB (6.5 GB with the map's
        // buckets); the map grows beyond as vertices are met.
        let r = reserve_entries(60_000_000, 32);
        assert_eq!(r, WELD_RESERVE_BYTES / 32);
        assert!(r * 32 <= 64 << 20);
        assert_eq!(reserve_entries(10_000_016, 16), (64 << 20) / 16);
        assert_eq!(reserve_entries(7, 0), 7);
    }

    #[test]
    fn the_tolerance_weld_merges_into_the_first_kept_vertex_of_a_cell() {
        // Two kept vertices in one cell (farther apart than the tolerance along its diagonal)
        // and a third near both: it takes the number of the one kept first.
        let t = 1e-4;
        let mut m = Mesh {
            vertices: vec![
                [1e-6; 3],           // kept 0
                [0.99e-4; 3],        // 1.7e-4 from 0: kept 1, in the same cell
                [0.5e-4; 3],         // 0.85e-4 from both: into 0
                [5.0, 5.0, 5.0],     // kept 2
                [5.0, 5.0, 5.00005], // into 2
                [3e-4, 0.0, 0.0],    // kept 3
            ],
            facets: vec![[0, 3, 5], [1, 3, 5], [2, 4, 5]],
        };
        let (merged, alive) = m.weld_tolerance_kept(t);
        assert_eq!(merged, 2);
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(alive, vec![true, true, true]);
        assert_eq!(m.facets, vec![[0, 2, 3], [1, 2, 3], [0, 2, 3]]);
    }
}
