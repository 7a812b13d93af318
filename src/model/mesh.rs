//! Import, stage 1b: triangle soup → [`Mesh`] (welded vertex list + facet list; the welds:
//! [`crate::model::weld`]), its transforms (docs/spec.md 5.3.1: rotate, scale, box minimum to
//! the origin, placement) and its diagnostics (open and non-manifold edges). Its shells and
//! their orientation: [`crate::model::shells`].

use crate::base::geom::{DMat3, DVec3, greater, lesser, sin_cos_deg};
use crate::base::parallel::in_runs;
use crate::base::settings::Settings;
use crate::base::steps::{self, Budget};

/// A welded triangle mesh in millimetres.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub vertices: Vec<[f64; 3]>,
    /// Vertex indices in the file's order (which gives the orientation).
    pub facets: Vec<[u32; 3]>,
}

/// Axis-aligned bounding box.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bounds {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Bounds {
    /// A box that holds nothing (every minimum +∞, every maximum −∞), to [`grow`](Self::grow).
    pub const EMPTY: Bounds = Bounds {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };

    /// Grown to hold the box `lo`..`hi`.
    pub fn grow(&mut self, lo: [f64; 3], hi: [f64; 3]) {
        for k in 0..3 {
            self.min[k] = lesser(self.min[k], lo[k]);
            self.max[k] = greater(self.max[k], hi[k]);
        }
    }

    pub fn size(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| self.max[k] - self.min[k])
    }
}

/// What the import found in the mesh.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshStats {
    pub facets_in_file: usize,
    pub facets: usize,
    pub vertices: usize,
    /// Facets dropped because two of their corners are the same vertex.
    pub degenerate_facets: usize,
    /// Edges used by only one facet (holes in the surface).
    pub open_edges: usize,
    /// Edges used by more than two facets.
    pub nonmanifold_edges: usize,
    /// Edges whose two facets run along them in the same direction (a flipped facet).
    pub misoriented_edges: usize,
    /// Signed volume from the facets' orientation (negative: the mesh is inside out).
    pub signed_volume: f64,
    /// Connected pieces of the surface.
    pub bodies: usize,
    /// Vertices merged by the tolerance weld (0 when exact welding closed the surface).
    pub tolerance_welded: usize,
    /// Facets dropped because they repeat another facet.
    pub duplicate_facets: usize,
    /// Closed shells that were inside out (negative volume) and not inside another shell:
    /// turned outward (see [`Mesh::orient_shells`]).
    pub flipped_shells: usize,
    /// Open shells that were inside out (negative volume with their holes capped) and not
    /// inside another shell: turned outward.
    #[serde(default)]
    pub flipped_open_shells: usize,
    /// Closed inside-out shells inside another closed shell: kept as cavities.
    pub cavity_shells: usize,
    /// Inside-out shells left as they were because checking them would have taken too long.
    pub unchecked_shells: usize,
}

impl Mesh {
    pub fn bounds(&self) -> Bounds {
        bounds_of(&self.vertices)
    }

    /// Applies docs/spec.md 5.3.1's transforms: rotate about x, y, z (in order), scale, move the
    /// bounding box minimum to the origin, then rotate by `place_angle` about the z axis
    /// through the origin and move by (`place_x`, `place_y`).
    pub fn transform(&mut self, s: &Settings) {
        self.place(&Placement::of_settings(s));
    }

    /// [`Mesh::transform`] with the values of a [`Placement`] (a build job's part); a
    /// mirroring placement also turns every facet ([`turn_facets`]).
    pub fn place(&mut self, p: &Placement) {
        place_vertices(&mut self.vertices, p);
        if p.mirrors() {
            turn_facets(&mut self.facets);
        }
    }

    /// Drops facets that repeat another facet with the same orientation (the same three
    /// vertices in the same cyclic order). Two copies of opposite orientation are kept: they are
    /// the shared face of two touching bodies, and each closes its own body's surface.
    /// Returns how many were dropped.
    pub fn remove_duplicate_facets(&mut self) -> usize {
        let before = self.facets.len();
        self.remove_duplicate_facets_kept();
        before - self.facets.len()
    }

    /// [`remove_duplicate_facets`](Self::remove_duplicate_facets), returning which of the
    /// facets before were kept (the others keep their order).
    pub fn remove_duplicate_facets_kept(&mut self) -> Vec<bool> {
        let kept = self.unrepeated_facets();
        self.keep_facets(&kept);
        kept
    }

    /// Keeps the facets `kept` marks (from [`Mesh::unrepeated_facets`]), in their order.
    pub fn keep_facets(&mut self, kept: &[bool]) {
        let mut it = kept.iter();
        self.facets.retain(|_| *it.next().unwrap_or(&true));
    }

    /// Per facet, whether [`remove_duplicate_facets`](Self::remove_duplicate_facets) keeps it:
    /// false for a repeat of an earlier facet. Reads the mesh only.
    pub fn unrepeated_facets(&self) -> Vec<bool> {
        steps::now(self.unrepeated_in_steps(&steps::UNLIMITED))
    }

    /// [`Mesh::unrepeated_facets`] in resumable steps ([`steps::runs`]).
    pub async fn unrepeated_in_steps(&self, b: &Budget) -> Vec<bool> {
        // Each facet as the cyclic rotation starting at its smallest vertex id; two facets are
        // equal exactly when these are. The facets are bucketed by that smallest vertex (in
        // their order), and within a bucket a facet is a repeat when an earlier one equals it:
        // a few sequential passes instead of a hash set of every facet.
        // (Each pass in runs: [`steps::runs`].)
        let mut canon: Vec<[u32; 3]> = Vec::with_capacity(self.facets.len());
        steps::runs(self.facets.len(), b, &mut |r| {
            canon.extend(self.facets[r].iter().map(|f| {
                let k = (0..3).min_by_key(|&k| f[k]).unwrap_or(0);
                [f[k], f[(k + 1) % 3], f[(k + 2) % 3]]
            }))
        })
        .await;
        let n = self
            .vertices
            .len()
            .max(canon.iter().map(|c| c[0] as usize + 1).max().unwrap_or(0));
        let mut start = vec![0u32; n + 1];
        steps::runs(canon.len(), b, &mut |r| {
            // (slices of their own: their bounds stay in registers through the stores)
            let start = &mut start[..];
            for c in &canon[r] {
                start[c[0] as usize + 1] += 1;
            }
        })
        .await;
        counts_to_starts_in_steps(&mut start, b).await;
        let mut next = start.clone();
        let mut order = vec![0u32; canon.len()];
        steps::runs(canon.len(), b, &mut |r| {
            let (order, next) = (&mut order[..], &mut next[..]);
            for (i, c) in r.clone().zip(&canon[r]) {
                let at = &mut next[c[0] as usize];
                order[*at as usize] = i as u32;
                *at += 1;
            }
        })
        .await;
        let mut kept = vec![true; canon.len()];
        steps::runs(n, b, &mut |r| {
            let (order, kept) = (&mut order[..], &mut kept[..]);
            for v in r {
                repeats_in(
                    &mut order[start[v] as usize..start[v + 1] as usize],
                    &canon,
                    kept,
                );
            }
        })
        .await;
        kept
    }

    /// Number of connected bodies (facets sharing a vertex belong to one body).
    pub fn bodies(&self) -> usize {
        steps::now(self.bodies_in_steps(&steps::UNLIMITED))
    }

    async fn bodies_in_steps(&self, b: &Budget) -> usize {
        let root = self.vertex_components(b).await;
        let mut used = vec![false; self.vertices.len()];
        steps::runs(self.facets.len(), b, &mut |r| {
            let used = &mut used[..];
            for f in &self.facets[r] {
                used[root[f[0] as usize] as usize] = true;
            }
        })
        .await;
        used.iter().filter(|&&u| u).count()
    }

    /// Volume enclosed by the facets, signed by their orientation (negative: inside out).
    pub fn signed_volume(&self) -> f64 {
        steps::now(self.signed_volume_in_steps(&steps::UNLIMITED))
    }

    async fn signed_volume_in_steps(&self, b: &Budget) -> f64 {
        // The sum in facet order from −0.0, as `Iterator::sum` adds (in runs: [`steps::runs`]).
        let mut sum = -0.0;
        steps::runs(self.facets.len(), b, &mut |r| {
            for f in &self.facets[r] {
                let [a, b, c] = f.map(|i| self.vertices[i as usize]);
                sum += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0;
            }
        })
        .await;
        sum
    }

    /// The connected piece (a root vertex id) of every vertex; facets sharing a vertex are in
    /// one piece.
    async fn vertex_components(&self, b: &Budget) -> Vec<u32> {
        let mut parent: Vec<u32> = (0..self.vertices.len() as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        steps::runs(self.facets.len(), b, &mut |r| {
            let parent = &mut parent[..];
            for f in &self.facets[r] {
                let a = find(parent, f[0]);
                for &v in &f[1..] {
                    let b = find(parent, v);
                    if a != b {
                        parent[b as usize] = a;
                    }
                }
            }
        })
        .await;
        steps::runs(parent.len(), b, &mut |r| {
            let parent = &mut parent[..];
            for v in r {
                let root = find(parent, v as u32);
                parent[v] = root;
            }
        })
        .await;
        parent
    }

    /// Edge statistics and signed volume.
    pub fn stats(&self, facets_in_file: usize, degenerate: usize) -> MeshStats {
        steps::now(self.stats_in_steps(facets_in_file, degenerate, &steps::UNLIMITED))
    }

    /// [`Mesh::stats`] in resumable steps ([`steps::runs`]).
    pub async fn stats_in_steps(
        &self,
        facets_in_file: usize,
        degenerate: usize,
        b: &Budget,
    ) -> MeshStats {
        let (open, nonmanifold, misoriented) = self.edge_counts(b).await;
        let signed_volume = self.signed_volume_in_steps(b).await;
        MeshStats {
            facets_in_file,
            facets: self.facets.len(),
            vertices: self.vertices.len(),
            degenerate_facets: degenerate,
            open_edges: open,
            nonmanifold_edges: nonmanifold,
            misoriented_edges: misoriented,
            signed_volume,
            bodies: self.bodies_in_steps(b).await,
            tolerance_welded: 0,
            duplicate_facets: 0,
            flipped_shells: 0,
            flipped_open_shells: 0,
            cavity_shells: 0,
            unchecked_shells: 0,
        }
    }

    /// The undirected edges used by one facet, by more than two, and by two running along it
    /// the same way. Every facet's edges are filed under their lower vertex ([`CompressedRows`],
    /// 4 bytes an edge: the other vertex and the direction), and each vertex's few are sorted
    /// and grouped: no sort of all edges, and each row read once.
    async fn edge_counts(&self, b: &Budget) -> (usize, usize, usize) {
        // The other vertex << 1 | whether the edge runs from the lower vertex. Vertex ids
        // stay below 2^31 (at most 3 per facet, and files over 20 million facets are
        // refused), so the shift loses nothing.
        let mut rows = CompressedRows::per_corner_in_steps(
            self,
            |_, f, k| {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                (a.min(b), a.max(b) << 1 | u32::from(a < b))
            },
            b,
        )
        .await;
        let (mut open, mut nonmanifold, mut misoriented) = (0, 0, 0);
        steps::runs(self.vertices.len(), b, &mut |r| {
            for v in r {
                let row = rows.row_mut(v);
                row.sort_unstable();
                for group in row.chunk_by(|x, y| x >> 1 == y >> 1) {
                    match group.len() {
                        1 => open += 1,
                        2 => {
                            if group[0] & 1 == group[1] & 1 {
                                misoriented += 1
                            }
                        }
                        _ => nonmanifold += 1,
                    }
                }
            }
        })
        .await;
        (open, nonmanifold, misoriented)
    }
}
/// Marks in `kept` every facet of `bucket` (facet numbers with one smallest vertex, in facet
/// order) that repeats an earlier one of it ([`Mesh::unrepeated_facets`]).
fn repeats_in(bucket: &mut [u32], canon: &[[u32; 3]], kept: &mut [bool]) {
    if bucket.len() < 2 {
        return;
    }
    if bucket.len() > 16 {
        // in facet order within equal keys (a stable sort), so the first is kept
        bucket.sort_by_key(|&i| (canon[i as usize][1], canon[i as usize][2]));
        for j in 1..bucket.len() {
            if canon[bucket[j] as usize] == canon[bucket[j - 1] as usize] {
                kept[bucket[j] as usize] = false;
            }
        }
        return;
    }
    for j in 1..bucket.len() {
        let c = canon[bucket[j] as usize];
        if bucket[..j].iter().any(|&k| canon[k as usize] == c) {
            kept[bucket[j] as usize] = false;
        }
    }
}

/// The box of `vertices` ([`Bounds::EMPTY`] for none).
fn bounds_of(vertices: &[[f64; 3]]) -> Bounds {
    let mut b = Bounds::EMPTY;
    in_runs(vertices.len(), &mut |r| {
        for v in &vertices[r] {
            b.grow(*v, *v);
        }
    });
    b
}

/// [`Mesh::place`] on the vertices of one mesh (the box moved to the origin is theirs), where
/// they lie: a build job places each instance's vertices after copying them into the merged
/// mesh, with no placed copy between.
pub fn place_vertices(vertices: &mut [[f64; 3]], p: &Placement) {
    steps::now(place_vertices_in_steps(vertices, p, &steps::UNLIMITED))
}

/// [`place_vertices`] in resumable steps ([`steps::runs`]).
pub async fn place_vertices_in_steps(vertices: &mut [[f64; 3]], p: &Placement, budget: &Budget) {
    let r = rotation(p.rotate);
    let scale = DVec3::from(p.scale);
    steps::runs(vertices.len(), budget, &mut |run| {
        for v in vertices[run].iter_mut() {
            *v = (r * DVec3::from(*v) * scale).to_array();
        }
    })
    .await;
    let mut b = Bounds::EMPTY;
    steps::runs(vertices.len(), budget, &mut |run| {
        for v in &vertices[run] {
            b.grow(*v, *v);
        }
    })
    .await;
    let place = rot(2, p.place_angle);
    let min = DVec3::from(b.min);
    steps::runs(vertices.len(), budget, &mut |run| {
        for v in vertices[run].iter_mut() {
            let q = place * (DVec3::from(*v) - min);
            *v = [q.x + p.place[0], q.y + p.place[1], q.z];
        }
    })
    .await;
}

/// Each facet's corners in the other order (its normal reversed): after a mirroring
/// [`Placement`] the facets face out again.
pub fn turn_facets(facets: &mut [[u32; 3]]) {
    for f in facets {
        f.swap(1, 2);
    }
}

/// Items filed under rows 0..n, each row's items one run of memory in the order given (the
/// compressed rows of a sparse matrix): a mesh's per-vertex lists without a `Vec` per vertex.
pub(crate) struct CompressedRows<T> {
    start: Vec<u32>,
    items: Vec<T>,
}

impl<T: Copy + Default> CompressedRows<T> {
    /// Three items per facet of `mesh`, filed under vertex rows: `item(facet, its vertices, k)`
    /// for k = 0, 1, 2 gives (row, item). It is called twice per item (once to count the rows,
    /// once to fill them): plain loops, which run faster than a flattened iterator walked
    /// twice. At most `u32::MAX` items.
    /// In resumable steps ([`steps::runs`]; [`steps::now`] runs them at once).
    pub(crate) async fn per_corner_in_steps(
        mesh: &Mesh,
        item: impl Fn(u32, &[u32; 3], usize) -> (u32, T),
        b: &Budget,
    ) -> Self {
        // Each pass in runs of facets ([`steps::runs`]: the page's engine compiles the later
        // runs well).
        let n = mesh.vertices.len();
        let facets = &mesh.facets;
        let mut start = vec![0u32; n + 1];
        steps::runs(facets.len(), b, &mut |run| {
            // (a slice of its own: its bounds stay in registers through the stores)
            let start = &mut start[..];
            for (fi, f) in run.clone().zip(&facets[run]) {
                for k in 0..3 {
                    start[item(fi as u32, f, k).0 as usize + 1] += 1;
                }
            }
        })
        .await;
        counts_to_starts_in_steps(&mut start, b).await;
        let mut next = start.clone();
        let mut items = vec![T::default(); start[n] as usize];
        steps::runs(facets.len(), b, &mut |run| {
            let (items, next) = (&mut items[..], &mut next[..]);
            for (fi, f) in run.clone().zip(&facets[run]) {
                for k in 0..3 {
                    let (r, x) = item(fi as u32, f, k);
                    items[next[r as usize] as usize] = x;
                    next[r as usize] += 1;
                }
            }
        })
        .await;
        CompressedRows { start, items }
    }

    /// Row `r`'s items.
    pub(crate) fn row(&self, r: usize) -> &[T] {
        &self.items[self.start[r] as usize..self.start[r + 1] as usize]
    }

    /// Row `r`'s items, to reorder in place.
    pub(crate) fn row_mut(&mut self, r: usize) -> &mut [T] {
        &mut self.items[self.start[r] as usize..self.start[r + 1] as usize]
    }
}

/// Undirected edge key of two vertex ids.
pub fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

/// A part's transform (docs/spec.md 5.3.1): rotate about x, y, z (degrees, in that order),
/// scale, bounding box minimum to the origin, rotate by `place_angle` (degrees) about z, move by
/// `place`. A negative scale mirrors that axis (a job's `mirror_*`, docs/jobs.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub rotate: [f64; 3],
    pub scale: [f64; 3],
    pub place_angle: f64,
    pub place: [f64; 2],
}

impl Placement {
    /// The settings' `rotate_*`, `scale_*`, `place_*`.
    pub fn of_settings(s: &Settings) -> Placement {
        Placement {
            rotate: [s.rotate_x, s.rotate_y, s.rotate_z],
            scale: [s.scale_x, s.scale_y, s.scale_z],
            place_angle: s.place_angle,
            place: [s.place_x, s.place_y],
        }
    }

    /// Whether it mirrors the part (an odd number of negative scales): its facets' corners
    /// then run the other way round ([`Mesh::place`] turns them, so that they face out).
    pub fn mirrors(&self) -> bool {
        self.scale.iter().filter(|s| **s < 0.0).count() % 2 == 1
    }

    /// The same placement with its scale multiplied by `factors` (the shrinkage
    /// compensation, [`Settings::shrink_factors`]): exactly unchanged for factors of 1.
    pub fn compensated(self, factors: [f64; 3]) -> Placement {
        Placement {
            scale: [0, 1, 2].map(|k| self.scale[k] * factors[k]),
            ..self
        }
    }
}

/// The rotation of [`Mesh::place`]: about x, then y, then z (degrees).
pub fn rotation(rotate: [f64; 3]) -> DMat3 {
    rot(2, rotate[2]) * (rot(1, rotate[1]) * rot(0, rotate[0]))
}

/// The rotation about one axis (0 = x, 1 = y, 2 = z) by `deg` degrees (exact at right angles).
pub fn rot(axis: usize, deg: f64) -> DMat3 {
    let (s, c) = sin_cos_deg(deg);
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    // Rows, then transposed into glam's columns.
    let mut m = [[0.0; 3]; 3];
    m[axis][axis] = 1.0;
    m[i][i] = c;
    m[j][j] = c;
    m[i][j] = -s;
    m[j][i] = s;
    DMat3::from_cols_array_2d(&m).transpose()
}

/// Counts to starts in resumable steps: `start[i + 1]` (the count of bucket `i`) becomes the
/// start of bucket `i + 1`, `start[0]` staying 0.
async fn counts_to_starts_in_steps(start: &mut [u32], b: &Budget) {
    let n = start.len() - 1;
    steps::runs(n, b, &mut |run| {
        for r in run {
            start[r + 1] += start[r];
        }
    })
    .await;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_exact_at_right_angles() {
        let mut m = Mesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]],
            facets: vec![],
        };
        let s = Settings {
            rotate_x: 90.0,
            ..Settings::default()
        };
        m.transform(&s);
        // (1,2,3) about x by 90°: (1,-3,2); then min (0,-3,0) moves to the origin.
        assert_eq!(m.vertices[1], [1.0, 0.0, 2.0]);
        assert_eq!(m.vertices[0], [0.0, 3.0, 0.0]);
    }
}
