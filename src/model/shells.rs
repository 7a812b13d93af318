//! Shells of a welded [`Mesh`]: the pieces of its surface joined through well-formed edges,
//! whether each is closed, and their orientation by signed volume ([`Mesh::orient_shells`]):
//! inside-out shells turned outward unless they lie inside another shell (cavities), decided
//! by winding numbers and a grid of the shells' bounding boxes (`BoxIndex`).

use crate::base::steps::{self, Budget};
use crate::model::mesh::{CompressedRows, Mesh};

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

/// Per shell: its bounding box, its first facet and how many facets it has.
struct ShellBoxes {
    bmin: Vec<[f64; 3]>,
    bmax: Vec<[f64; 3]>,
    first_facet: Vec<u32>,
    facet_count: Vec<u32>,
}

/// The facets of each of the `n` shells, grouped (counting sort): shell `s` has
/// `grouped[start[s]..start[s + 1]]`.
fn group_by_shell(facet_shell: &[u32], n: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for &sh in facet_shell {
        start[sh as usize + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut grouped = vec![0u32; facet_shell.len()];
    for (fi, &sh) in facet_shell.iter().enumerate() {
        grouped[next[sh as usize] as usize] = fi as u32;
        next[sh as usize] += 1;
    }
    (start, grouped)
}

impl Mesh {
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
        steps::now(self.shells_in_steps(&steps::UNLIMITED))
    }

    /// [`Mesh::shells`] in resumable steps ([`steps::runs`]).
    pub async fn shells_in_steps(&self, b: &Budget) -> Shells {
        let (facet_shell, closed, bad, open_edges) = self.edge_shells(b).await;
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
        let (out, flip) = self.orientation(shells);
        self.turn(shells, &flip);
        out
    }

    /// What [`Mesh::orient`] finds, without turning anything: the figures, and per shell
    /// whether to turn it (empty when none is turned; [`Mesh::turn`] turns them). Reads the
    /// mesh only, so other work on the mesh as it is may run beside it.
    pub fn orientation(&self, shells: &Shells) -> (ShellOrientation, Vec<bool>) {
        steps::now(self.orientation_in_steps(shells, &steps::UNLIMITED))
    }

    /// [`Mesh::orientation`] in resumable steps ([`steps::runs`]).
    pub async fn orientation_in_steps(
        &self,
        shells: &Shells,
        b: &Budget,
    ) -> (ShellOrientation, Vec<bool>) {
        let mut out = ShellOrientation::default();
        let Shells {
            facet_shell,
            closed,
            bad,
            ..
        } = shells;
        if self.facets.is_empty() || facet_shell.len() != self.facets.len() {
            return (out, Vec::new());
        }
        let n = closed.len();
        out.closed = closed.iter().filter(|&&c| c).count();
        out.open = n - out.closed;
        let ShellBoxes {
            bmin,
            bmax,
            first_facet,
            facet_count,
        } = self.shell_boxes(facet_shell, n, b).await;
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
        steps::runs(self.facets.len(), b, &mut |run| {
            let volume = &mut volume[..];
            for (fi, f) in run.clone().zip(&self.facets[run]) {
                let s = facet_shell[fi] as usize;
                let o = centre(s);
                let [p, q, r] = f.map(|i| sub(self.vertices[i as usize], o));
                volume[s] += dot(p, cross(q, r)) / 6.0;
            }
        })
        .await;
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
            return (out, Vec::new());
        }
        let (start, grouped) = group_by_shell(facet_shell, n);
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
        if out.flipped + out.flipped_open == 0 {
            flip.clear();
        }
        out.closed_volume = (0..n).filter(|&s| closed[s]).map(|s| volume[s].abs()).sum();
        (out, flip)
    }

    /// Turns the shells `flip` marks (from [`Mesh::orientation`] of the same `shells`): each
    /// of their facets reversed. Nothing to do for an empty `flip`.
    pub fn turn(&mut self, shells: &Shells, flip: &[bool]) {
        if flip.is_empty() {
            return;
        }
        for (fi, f) in self.facets.iter_mut().enumerate() {
            if flip[shells.facet_shell[fi] as usize] {
                f.swap(1, 2);
            }
        }
    }

    /// Bounding boxes, first facet and facet count of the `n` shells.
    async fn shell_boxes(&self, facet_shell: &[u32], n: usize, budget: &Budget) -> ShellBoxes {
        let mut b = ShellBoxes {
            bmin: vec![[f64::INFINITY; 3]; n],
            bmax: vec![[f64::NEG_INFINITY; 3]; n],
            first_facet: vec![u32::MAX; n],
            facet_count: vec![0u32; n],
        };
        // In runs of facets ([`steps::runs`]).
        steps::runs(self.facets.len(), budget, &mut |r| {
            for (fi, f) in r.clone().zip(&self.facets[r]) {
                let s = facet_shell[fi] as usize;
                for v in f.map(|i| self.vertices[i as usize]) {
                    for (k, c) in v.into_iter().enumerate() {
                        b.bmin[s][k] = b.bmin[s][k].min(c);
                        b.bmax[s][k] = b.bmax[s][k].max(c);
                    }
                }
                if b.first_facet[s] == u32::MAX {
                    b.first_facet[s] = fi as u32;
                }
                b.facet_count[s] += 1;
            }
        })
        .await;
        b
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
    async fn edge_shells(&self, budget: &Budget) -> (Vec<u32>, Vec<bool>, Vec<u32>, usize) {
        let nf = self.facets.len();
        // Each facet around a vertex with its vertices after and before that one, so the
        // scan of a vertex's facets reads one run of memory and never the facets themselves.
        let around = CompressedRows::per_corner_in_steps(
            self,
            |fi, f, k| (f[k], [fi, f[(k + 1) % 3], f[(k + 2) % 3]]),
            budget,
        )
        .await;
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
        // In runs of facets ([`steps::runs`]: the page's engine compiles the later runs well).
        let facets = &self.facets;
        steps::runs(nf, budget, &mut |run| {
            // (a slice of its own: its bounds stay in registers through the stores)
            let parent = &mut parent[..];
            for (fi, f) in run.clone().zip(&facets[run]) {
                for k in 0..3 {
                    let (a, b) = (f[k], f[(k + 1) % 3]);
                    // The other facets with the edge a–b, and whether they run b→a (b just
                    // before a).
                    let (mut others, mut opposite, mut other) = (0, true, 0u32);
                    for &[g, after, before] in around.row(a as usize) {
                        if g as usize != fi && (after == b || before == b) {
                            others += 1;
                            other = g;
                            opposite &= before == b;
                        }
                    }
                    if others == 1 && opposite {
                        let (x, y) = (find(parent, fi as u32), find(parent, other));
                        if x != y {
                            parent[y as usize] = x;
                        }
                    } else {
                        open_edges += usize::from(others == 0);
                        bad.push(3 * fi as u32 + k as u32);
                    }
                }
            }
        })
        .await;
        drop(around);
        let mut id = vec![u32::MAX; nf];
        let mut shells = 0u32;
        let mut facet_shell: Vec<u32> = Vec::with_capacity(nf);
        steps::runs(nf, budget, &mut |run| {
            let (parent, id) = (&mut parent[..], &mut id[..]);
            facet_shell.extend(run.map(|fi| {
                let r = find(parent, fi as u32) as usize;
                if id[r] == u32::MAX {
                    id[r] = shells;
                    shells += 1;
                }
                id[r]
            }))
        })
        .await;
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
