//! Import, stage 1b: triangle soup → [`Mesh`] (welded vertex list + facet list), its
//! transforms (SPEC.md: rotate, scale, bounding box minimum to the origin, placement) and its
//! diagnostics (open and non-manifold edges).

use crate::base::geom::{DMat3, DVec3, sin_cos_deg};
use crate::base::settings::Settings;
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

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

/// The shells of a mesh ([`Mesh::shells`]), for [`Mesh::orient`].
#[derive(Clone, Debug, Default)]
pub struct Shells {
    /// The shell of every facet.
    facet_shell: Vec<u32>,
    /// Per shell: closed?
    closed: Vec<bool>,
    /// The edges not shared with exactly one facet running the other way (facet × 3 + corner).
    bad: Vec<u32>,
    /// Edges that only one facet has (holes in the surface).
    pub open_edges: usize,
}

/// What [`Mesh::orient_shells`] found and did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShellOrientation {
    /// Closed shells: every edge shared by exactly two facets running along it in opposite
    /// directions.
    pub closed: usize,
    /// The other shells (open, non-manifold or with flipped facets).
    pub open: usize,
    /// Inside-out closed shells outside every other shell, turned outward.
    pub flipped: usize,
    /// Inside-out open shells (by their volume with the holes capped) outside every other
    /// shell, turned outward.
    pub flipped_open: usize,
    /// Inside-out closed shells inside another shell, kept as cavities.
    pub cavities: usize,
    /// Inside-out open shells inside another shell, kept as cavities.
    pub open_cavities: usize,
    /// Inside-out shells not checked (over [`ENCLOSURE_BUDGET`]), left as they were.
    pub unchecked: usize,
    /// Sum of every closed shell's |volume| (mm³) after orientation: an upper bound of the
    /// solid they enclose (overlaps count twice, cavities are not subtracted).
    pub closed_volume: f64,
}

/// Most steps (index look-ups, box tests, facet evaluations) spent on deciding which
/// inside-out shells lie inside other shells (about half a second): a file with very many
/// inverted shells inside big ones keeps the rest as they are instead of stalling.
pub const ENCLOSURE_BUDGET: u64 = 60_000_000;
/// Relative size under which an open shell's capped volume counts as none: |volume| below
/// this × the cube of its bounding box's diagonal (a flat patch, a strip of facets).
pub const OPEN_VOLUME_EPSILON: f64 = 1e-9;

/// Levels of [`BoxIndex`] (cell sizes from the extent of all boxes / 2¹⁶ up to that extent).
const INDEX_LEVELS: u32 = 16;

/// The shells' bounding boxes in grids of doubling cell size: a box is filed at the finest
/// level whose cells are at least as large as the box, in every cell it touches there (at most
/// two a side). The boxes that contain a point are then among those of the point's one cell
/// per level: near-linear time for many small shells, however many there are.
struct BoxIndex {
    origin: [f64; 3],
    cell0: f64,
    /// (level, cell) keys and shells, sorted.
    entries: Vec<(u64, u32)>,
    /// The levels that hold boxes.
    levels: Vec<u32>,
}

impl BoxIndex {
    fn new(
        bmin: &[[f64; 3]],
        bmax: &[[f64; 3]],
        shells: impl Iterator<Item = usize> + Clone,
    ) -> BoxIndex {
        let mut origin = [f64::INFINITY; 3];
        let mut top = [f64::NEG_INFINITY; 3];
        for s in shells.clone() {
            for k in 0..3 {
                origin[k] = origin[k].min(bmin[s][k]);
                top[k] = top[k].max(bmax[s][k]);
            }
        }
        let extent = (0..3).map(|k| top[k] - origin[k]).fold(0.0, f64::max);
        let cell0 = if extent > 0.0 && extent.is_finite() {
            extent / f64::from(1u32 << INDEX_LEVELS)
        } else {
            1.0
        };
        let mut index = BoxIndex {
            origin,
            cell0,
            entries: Vec::new(),
            levels: Vec::new(),
        };
        let mut used = [false; INDEX_LEVELS as usize + 1];
        for s in shells {
            let e = (0..3).map(|k| bmax[s][k] - bmin[s][k]).fold(0.0, f64::max);
            let level = (0..INDEX_LEVELS)
                .find(|&l| index.cell(l) >= e)
                .unwrap_or(INDEX_LEVELS);
            used[level as usize] = true;
            let lo = index.cells(level, bmin[s]);
            let hi = index.cells(level, bmax[s]);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        index.entries.push((key(level, [x, y, z]), s as u32));
                    }
                }
            }
        }
        index.entries.sort_unstable();
        index.levels = (0..=INDEX_LEVELS).filter(|&l| used[l as usize]).collect();
        index
    }

    fn cell(&self, level: u32) -> f64 {
        self.cell0 * f64::from(1u32 << level)
    }

    /// The cell of `p` at `level` (coordinates clamped to the grid).
    fn cells(&self, level: u32, p: [f64; 3]) -> [u64; 3] {
        let c = self.cell(level);
        let last = f64::from((1u32 << (INDEX_LEVELS - level)) + 1);
        [0, 1, 2].map(|k| ((p[k] - self.origin[k]) / c).floor().clamp(0.0, last) as u64)
    }

    /// Adds to `out` the other shells whose box contains shell `s`'s box, paying one unit of
    /// `budget` per look-up and per box tested; false if the budget ran out first.
    fn containing(
        &self,
        bmin: &[[f64; 3]],
        bmax: &[[f64; 3]],
        s: usize,
        budget: &mut u64,
        out: &mut Vec<u32>,
    ) -> bool {
        let p = bmin[s];
        for &level in &self.levels {
            if *budget == 0 {
                return false;
            }
            *budget -= 1;
            let k = key(level, self.cells(level, p));
            let from = self.entries.partition_point(|e| e.0 < k);
            for &(_, t) in self.entries[from..].iter().take_while(|e| e.0 == k) {
                if *budget == 0 {
                    return false;
                }
                *budget -= 1;
                let t = t as usize;
                if t != s && (0..3).all(|j| bmin[t][j] <= bmin[s][j] && bmax[s][j] <= bmax[t][j]) {
                    out.push(t as u32);
                }
            }
        }
        true
    }
}

/// A cell's key: the level, then the cell's coordinates (17 bits each) interleaved (Morton
/// order), so that cells near each other have keys near each other and the look-ups of
/// neighbouring shells touch the same part of the index.
fn key(level: u32, c: [u64; 3]) -> u64 {
    fn spread(mut x: u64) -> u64 {
        // The 21 low bits of x to every third bit.
        x &= 0x1f_ffff;
        x = (x | x << 32) & 0x001f_0000_0000_ffff;
        x = (x | x << 16) & 0x001f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    }
    (u64::from(level) << 51) | spread(c[0]) << 2 | spread(c[1]) << 1 | spread(c[2])
}

impl Mesh {
    /// Welds corners whose float32 coordinates are bit-identical (−0 = +0) and drops facets
    /// that collapse to a line or a point.
    pub fn weld(tris: &[[[f32; 3]; 3]]) -> (Mesh, usize) {
        let mut index: HashMap<[u32; 3], u32> =
            HashMap::with_capacity_and_hasher(tris.len() / 2 + 16, Default::default());
        let mut vertices = Vec::with_capacity(tris.len() / 2 + 16);
        let mut facets = Vec::with_capacity(tris.len());
        let mut degenerate = 0;
        for t in tris {
            let ids = t.map(|p| {
                let key = p.map(|c| if c == 0.0 { 0u32 } else { c.to_bits() });
                *index.entry(key).or_insert_with(|| {
                    vertices.push(p.map(f64::from));
                    (vertices.len() - 1) as u32
                })
            });
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                degenerate += 1;
            } else {
                facets.push(ids);
            }
        }
        (Mesh { vertices, facets }, degenerate)
    }

    pub fn bounds(&self) -> Bounds {
        let mut min = [f64::INFINITY; 3];
        let mut max = [f64::NEG_INFINITY; 3];
        for v in &self.vertices {
            for k in 0..3 {
                min[k] = min[k].min(v[k]);
                max[k] = max[k].max(v[k]);
            }
        }
        Bounds { min, max }
    }

    /// Applies SPEC.md's transforms: rotate about x, y, z (in that order), scale, move the
    /// bounding box minimum to the origin, then rotate by `place_angle` about the z axis
    /// through the origin and move by (`place_x`, `place_y`).
    pub fn transform(&mut self, s: &Settings) {
        self.place(&Placement::of_settings(s));
    }

    /// [`Mesh::transform`] with the values of a [`Placement`] (a build job's part).
    pub fn place(&mut self, p: &Placement) {
        let r = rotation(p.rotate);
        let scale = DVec3::from(p.scale);
        for v in &mut self.vertices {
            *v = (r * DVec3::from(*v) * scale).to_array();
        }
        let b = self.bounds();
        let place = rot(2, p.place_angle);
        let min = DVec3::from(b.min);
        for v in &mut self.vertices {
            let q = place * (DVec3::from(*v) - min);
            *v = [q.x + p.place[0], q.y + p.place[1], q.z];
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
        let before = self.facets.len();
        let mut seen = HashSet::with_capacity_and_hasher(before, Default::default());
        let kept: Vec<bool> = self
            .facets
            .iter()
            .map(|f| {
                // The cyclic rotation starting at the smallest vertex id.
                let k = f
                    .iter()
                    .enumerate()
                    .min_by_key(|(_, v)| **v)
                    .map_or(0, |(k, _)| k);
                seen.insert([f[k], f[(k + 1) % 3], f[(k + 2) % 3]])
            })
            .collect();
        let mut it = kept.iter();
        self.facets.retain(|_| *it.next().unwrap_or(&true));
        kept
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
        let cell = |p: &[f64; 3]| p.map(|c| (c / tol).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<u32>> =
            HashMap::with_capacity_and_hasher(self.vertices.len(), Default::default());
        let mut remap: Vec<u32> = Vec::with_capacity(self.vertices.len());
        let mut kept: Vec<[f64; 3]> = Vec::with_capacity(self.vertices.len());
        let mut merged = 0;
        for v in &self.vertices {
            let c = cell(v);
            let mut found = None;
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(ids) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                            for &id in ids {
                                let w = kept[id as usize];
                                let d2 = (0..3).map(|k| (w[k] - v[k]).powi(2)).sum::<f64>();
                                if d2 <= tol * tol {
                                    found = Some(id);
                                    break 'search;
                                }
                            }
                        }
                    }
                }
            }
            let id = found.unwrap_or_else(|| {
                kept.push(*v);
                let id = (kept.len() - 1) as u32;
                grid.entry(c).or_default().push(id);
                id
            });
            if found.is_some() {
                merged += 1;
            }
            remap.push(id);
        }
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

    /// Number of connected bodies (facets sharing a vertex belong to one body).
    pub fn bodies(&self) -> usize {
        let root = self.vertex_components();
        let mut used = vec![false; self.vertices.len()];
        for f in &self.facets {
            used[root[f[0] as usize] as usize] = true;
        }
        used.iter().filter(|&&u| u).count()
    }

    /// Volume enclosed by the facets, signed by their orientation (negative: inside out).
    pub fn signed_volume(&self) -> f64 {
        self.facets
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| self.vertices[i as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    /// Orients every shell by its signed volume, as the part's author meant it (see
    /// [`Mesh::orient`]).
    pub fn orient_shells(&mut self) -> ShellOrientation {
        let shells = self.shells();
        self.orient(&shells)
    }

    /// The shells: pieces of the surface connected through edges shared by exactly two facets
    /// running along them in opposite directions (two bodies touching at a vertex or along a
    /// non-manifold edge stay apart). A shell is closed when it has no other edge.
    pub fn shells(&self) -> Shells {
        let (facet_shell, closed, bad, open_edges) = self.edge_shells();
        Shells {
            facet_shell,
            closed,
            bad,
            open_edges,
        }
    }

    /// Orients every shell by its signed volume, as the part's author meant it: a shell that
    /// is inside out (negative volume) and lies inside no other shell is turned outward (its
    /// facets reversed); one that lies inside another shell is a cavity and stays as it is.
    ///
    /// A closed shell's volume is exact. An open shell (holes, flipped facets or non-manifold
    /// edges) is measured with its holes capped: each boundary loop closed by a fan about the
    /// loop's centroid, so that the capped surface is closed and its sign says which way the
    /// facets face; a shell whose capped volume is negligible beside its size (a flat patch,
    /// a single facet) is left to the slicer's majority rule.
    ///
    /// "Inside" is decided by the winding number of the other (capped) shell around a point of
    /// this one (the sum of the solid angles of its facets), which needs no ray and no
    /// tolerance; only shells whose bounding box contains this one's are tried, found through
    /// a grid of the shells' boxes. Index look-ups, box tests and facet evaluations together
    /// stay under [`ENCLOSURE_BUDGET`].
    pub fn orient(&mut self, shells: &Shells) -> ShellOrientation {
        let mut out = ShellOrientation::default();
        let Shells {
            facet_shell,
            closed,
            bad,
            ..
        } = shells;
        if self.facets.is_empty() || facet_shell.len() != self.facets.len() {
            return out;
        }
        let n = closed.len();
        out.closed = closed.iter().filter(|&&c| c).count();
        out.open = n - out.closed;
        // Bounding boxes, first facet and facet count per shell.
        let mut bmin = vec![[f64::INFINITY; 3]; n];
        let mut bmax = vec![[f64::NEG_INFINITY; 3]; n];
        let mut first_facet = vec![u32::MAX; n];
        let mut facet_count = vec![0u32; n];
        for (fi, f) in self.facets.iter().enumerate() {
            let s = facet_shell[fi] as usize;
            for v in f.map(|i| self.vertices[i as usize]) {
                for k in 0..3 {
                    bmin[s][k] = bmin[s][k].min(v[k]);
                    bmax[s][k] = bmax[s][k].max(v[k]);
                }
            }
            if first_facet[s] == u32::MAX {
                first_facet[s] = fi as u32;
            }
            facet_count[s] += 1;
        }
        let centre = |s: usize| [0, 1, 2].map(|k| 0.5 * (bmin[s][k] + bmax[s][k]));
        // The caps of the open shells' holes (a single facet encloses nothing: skipped).
        let (cap_start, caps) = self.hole_caps(facet_shell, closed, bad, &facet_count);
        let caps_of = |s: usize| -> &[[[f64; 3]; 3]] {
            if cap_start.is_empty() {
                &[]
            } else {
                &caps[cap_start[s] as usize..cap_start[s + 1] as usize]
            }
        };
        // Volumes, each about its shell's centre (for precision), caps included.
        let mut volume = vec![0.0f64; n];
        for (fi, f) in self.facets.iter().enumerate() {
            let s = facet_shell[fi] as usize;
            let o = centre(s);
            let [p, q, r] = f.map(|i| sub(self.vertices[i as usize], o));
            volume[s] += dot(p, cross(q, r)) / 6.0;
        }
        for (s, v) in volume.iter_mut().enumerate() {
            let o = centre(s);
            for t in caps_of(s) {
                let [p, q, r] = t.map(|c| sub(c, o));
                *v += dot(p, cross(q, r)) / 6.0;
            }
        }
        // The shells that look inside out.
        let inverted = |s: usize| -> bool {
            if closed[s] {
                volume[s] < 0.0
            } else if facet_count[s] < 2 {
                false
            } else {
                let d = norm(sub(bmax[s], bmin[s]));
                volume[s] < -OPEN_VOLUME_EPSILON * d * d * d
            }
        };
        let queries: Vec<usize> = (0..n).filter(|&s| inverted(s)).collect();
        if queries.is_empty() {
            out.closed_volume = (0..n).filter(|&s| closed[s]).map(|s| volume[s].abs()).sum();
            return out;
        }
        // The facets of each shell, grouped (counting sort).
        let mut start = vec![0u32; n + 1];
        for &sh in facet_shell {
            start[sh as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut next = start.clone();
        let mut grouped = vec![0u32; self.facets.len()];
        for (fi, &sh) in facet_shell.iter().enumerate() {
            grouped[next[sh as usize] as usize] = fi as u32;
            next[sh as usize] += 1;
        }
        drop(next);
        // Shells that may enclose another: every closed one, and open ones of 2 facets or more.
        let encloser = |s: usize| closed[s] || facet_count[s] >= 2;
        let index = BoxIndex::new(&bmin, &bmax, (0..n).filter(|&s| encloser(s)));
        let mut flip = vec![false; n];
        let mut budget = ENCLOSURE_BUDGET;
        let mut around: Vec<u32> = Vec::new();
        for s in queries {
            around.clear();
            // Shells whose box holds this one's: through the index, each look-up and box test
            // paid from the budget.
            let complete = index.containing(&bmin, &bmax, s, &mut budget, &mut around);
            let cost: u64 = around
                .iter()
                .map(|&t| {
                    let t = t as usize;
                    u64::from(facet_count[t]) + caps_of(t).len() as u64
                })
                .sum();
            if !complete || cost > budget {
                out.unchecked += 1;
                continue;
            }
            budget -= cost;
            let f = self.facets[first_facet[s] as usize].map(|i| self.vertices[i as usize]);
            let p = [0, 1, 2].map(|k| (f[0][k] + f[1][k] + f[2][k]) / 3.0);
            let inside = around.iter().any(|&t| {
                let t = t as usize;
                let facets = &grouped[start[t] as usize..start[t + 1] as usize];
                self.winding_number(facets, caps_of(t), p).abs() > 0.5
            });
            match (inside, closed[s]) {
                (true, true) => out.cavities += 1,
                (true, false) => out.open_cavities += 1,
                (false, c) => {
                    flip[s] = true;
                    if c {
                        out.flipped += 1;
                    } else {
                        out.flipped_open += 1;
                    }
                }
            }
        }
        if out.flipped + out.flipped_open > 0 {
            for (fi, f) in self.facets.iter_mut().enumerate() {
                if flip[facet_shell[fi] as usize] {
                    f.swap(1, 2);
                }
            }
        }
        out.closed_volume = (0..n).filter(|&s| closed[s]).map(|s| volume[s].abs()).sum();
        out
    }

    /// The caps that close the holes of the open shells of 2 facets or more, grouped by shell
    /// (shell `s` has `caps[start[s]..start[s + 1]]`; `start` is empty when there are none).
    /// A shell's boundary edges are its facets' edges that are not shared with exactly one
    /// facet running the other way: at every vertex as many of them arrive as leave, so they
    /// form closed loops. Each loop is closed by a fan of triangles about its centroid,
    /// oriented as the shell's facets.
    fn hole_caps(
        &self,
        facet_shell: &[u32],
        closed: &[bool],
        bad: &[u32],
        facet_count: &[u32],
    ) -> (Vec<u32>, Vec<[[f64; 3]; 3]>) {
        // Boundary edges as (shell, from, to), sorted.
        let mut edges: Vec<(u32, u32, u32)> = bad
            .iter()
            .filter_map(|&e| {
                let (fi, k) = ((e / 3) as usize, (e % 3) as usize);
                let s = facet_shell[fi];
                (!closed[s as usize] && facet_count[s as usize] >= 2).then(|| {
                    let f = self.facets[fi];
                    (s, f[k], f[(k + 1) % 3])
                })
            })
            .collect();
        if edges.is_empty() {
            return (Vec::new(), Vec::new());
        }
        edges.sort_unstable();
        // Edges leaving (shell, vertex): the run starting at the first such edge; `taken[g]`
        // counts the run's edges already used (g: the run's first index).
        let run = |s: u32, v: u32| -> (usize, usize) {
            let a = edges.partition_point(|e| (e.0, e.1) < (s, v));
            let b = edges.partition_point(|e| (e.0, e.1) <= (s, v));
            (a, b)
        };
        let mut taken = vec![0u32; edges.len()];
        let mut caps: Vec<(u32, [[f64; 3]; 3])> = Vec::new();
        let mut ring: Vec<u32> = Vec::new();
        let mut g = 0;
        while g < edges.len() {
            let (s, v0) = (edges[g].0, edges[g].1);
            let end = g + edges[g..].partition_point(|e| (e.0, e.1) == (s, v0));
            while (g + taken[g] as usize) < end {
                // Walk a loop from v0: take any unused edge leaving the current vertex until
                // back at v0 (or stuck, which balanced boundaries never are).
                ring.clear();
                let mut e = g + taken[g] as usize;
                taken[g] += 1;
                ring.push(v0);
                loop {
                    let to = edges[e].2;
                    if to == v0 {
                        break;
                    }
                    ring.push(to);
                    let (a, b) = run(s, to);
                    if a + (taken[a] as usize) >= b {
                        break;
                    }
                    e = a + taken[a] as usize;
                    taken[a] += 1;
                }
                let m = ring.len() as f64;
                let c = ring.iter().fold([0.0; 3], |acc, &v| {
                    let p = self.vertices[v as usize];
                    [0, 1, 2].map(|k| acc[k] + p[k] / m)
                });
                for i in 0..ring.len() {
                    let a = self.vertices[ring[i] as usize];
                    let b = self.vertices[ring[(i + 1) % ring.len()] as usize];
                    // The shell runs a→b along its boundary; the cap runs b→a.
                    caps.push((s, [b, a, c]));
                }
            }
            g = end;
        }
        let mut start = vec![0u32; closed.len() + 1];
        for &(s, _) in &caps {
            start[s as usize + 1] += 1;
        }
        for k in 0..closed.len() {
            start[k + 1] += start[k];
        }
        // `caps` is already sorted by shell.
        (start, caps.into_iter().map(|c| c.1).collect())
    }

    /// The shells: pieces of the surface connected through edges shared by exactly two facets
    /// (two bodies touching at a vertex or along a non-manifold edge stay apart). Returns the
    /// shell of every facet and, per shell, whether it is closed: each of its edges shared by
    /// exactly two facets running along it in opposite directions; the other edges (facet × 3
    /// + corner: the edge from that corner to the next); and how many edges only one facet has.
    fn edge_shells(&self) -> (Vec<u32>, Vec<bool>, Vec<u32>, usize) {
        let nf = self.facets.len();
        // Facets around each vertex (compressed rows).
        let mut start = vec![0u32; self.vertices.len() + 1];
        for f in &self.facets {
            for &v in f {
                start[v as usize + 1] += 1;
            }
        }
        for k in 0..self.vertices.len() {
            start[k + 1] += start[k];
        }
        let mut next = start.clone();
        let mut around = vec![0u32; 3 * nf];
        for (fi, f) in self.facets.iter().enumerate() {
            for &v in f {
                around[next[v as usize] as usize] = fi as u32;
                next[v as usize] += 1;
            }
        }
        drop(next);
        let mut parent: Vec<u32> = (0..nf as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        let mut bad: Vec<u32> = Vec::new();
        let mut open_edges = 0;
        for (fi, f) in self.facets.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                // The other facets with the edge a–b, and whether they run b→a.
                let (mut others, mut opposite, mut other) = (0, true, 0u32);
                for &g in &around[start[a as usize] as usize..start[a as usize + 1] as usize] {
                    if g as usize == fi {
                        continue;
                    }
                    let h = self.facets[g as usize];
                    if let Some(j) = h.iter().position(|&v| v == b) {
                        others += 1;
                        other = g;
                        opposite &= h[(j + 1) % 3] == a;
                    }
                }
                if others == 1 && opposite {
                    let (x, y) = (find(&mut parent, fi as u32), find(&mut parent, other));
                    if x != y {
                        parent[y as usize] = x;
                    }
                } else {
                    open_edges += usize::from(others == 0);
                    bad.push(3 * fi as u32 + k as u32);
                }
            }
        }
        drop(around);
        let mut id = vec![u32::MAX; nf];
        let mut shells = 0u32;
        let facet_shell: Vec<u32> = (0..nf as u32)
            .map(|fi| {
                let r = find(&mut parent, fi) as usize;
                if id[r] == u32::MAX {
                    id[r] = shells;
                    shells += 1;
                }
                id[r]
            })
            .collect();
        let mut closed = vec![true; shells as usize];
        for &e in &bad {
            closed[facet_shell[(e / 3) as usize] as usize] = false;
        }
        (facet_shell, closed, bad, open_edges)
    }

    /// The winding number of the closed surface made of `facets` and `caps` around `p`: ±1
    /// inside, 0 outside (the sum of the triangles' signed solid angles over 4π, Van Oosterom
    /// & Strackee).
    fn winding_number(&self, facets: &[u32], caps: &[[[f64; 3]; 3]], p: [f64; 3]) -> f64 {
        let solid_angle = |t: [[f64; 3]; 3]| {
            let [a, b, c] = t.map(|v| sub(v, p));
            let (la, lb, lc) = (norm(a), norm(b), norm(c));
            let num = dot(a, cross(b, c));
            let den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
            2.0 * num.atan2(den)
        };
        let sum: f64 = facets
            .iter()
            .map(|&fi| solid_angle(self.facets[fi as usize].map(|i| self.vertices[i as usize])))
            .chain(caps.iter().map(|&t| solid_angle(t)))
            .sum();
        sum / (4.0 * std::f64::consts::PI)
    }

    /// The connected piece (a root vertex id) of every vertex; facets sharing a vertex are in
    /// one piece.
    fn vertex_components(&self) -> Vec<u32> {
        let mut parent: Vec<u32> = (0..self.vertices.len() as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        for f in &self.facets {
            let a = find(&mut parent, f[0]);
            for &v in &f[1..] {
                let b = find(&mut parent, v);
                if a != b {
                    parent[b as usize] = a;
                }
            }
        }
        for v in 0..parent.len() as u32 {
            let r = find(&mut parent, v);
            parent[v as usize] = r;
        }
        parent
    }

    /// Edge statistics and signed volume.
    pub fn stats(&self, facets_in_file: usize, degenerate: usize) -> MeshStats {
        // Directed edges, sorted by their undirected key.
        // Directed edges as (undirected key << 1 | direction), sorted: 8 bytes an edge, which
        // matters at millions of facets. Vertex ids stay below 2^31 (at most 3 per facet, and
        // files over 20 million facets are refused), so the shift loses nothing.
        let mut edges: Vec<u64> = Vec::with_capacity(self.facets.len() * 3);
        for f in &self.facets {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                edges.push(edge_key(a, b) << 1 | u64::from(a < b));
            }
        }
        edges.sort_unstable();
        let (mut open, mut nonmanifold, mut misoriented) = (0, 0, 0);
        for group in edges.chunk_by(|x, y| x >> 1 == y >> 1) {
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
        let signed_volume = self.signed_volume();
        MeshStats {
            facets_in_file,
            facets: self.facets.len(),
            vertices: self.vertices.len(),
            degenerate_facets: degenerate,
            open_edges: open,
            nonmanifold_edges: nonmanifold,
            misoriented_edges: misoriented,
            signed_volume,
            bodies: self.bodies(),
            tolerance_welded: 0,
            duplicate_facets: 0,
            flipped_shells: 0,
            flipped_open_shells: 0,
            cavity_shells: 0,
            unchecked_shells: 0,
        }
    }
}

/// Undirected edge key of two vertex ids.
pub fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Rotation about axis `axis` (0 x, 1 y, 2 z) by `deg` degrees; exact for multiples of 90°.
/// A part's transform (SPEC.md): rotate about x, y, z (degrees, in that order), scale, bounding
/// box minimum to the origin, rotate by `place_angle` (degrees) about z, move by `place`.
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
