//! Loop seams measured on written G-code (docs/spec.md "Loop seams"), shared by tests/seams.rs and
//! examples/seams.rs.
//!
//! The droplets are the `G26` lines of each layer, in file order, as written (4 decimals). The
//! loops they lie on are the layer's contour loops: the path every loop's droplets are placed
//! along. They come from the library's contour function (`dropslice::slicing::contours::contours` on
//! the layer's section): an offset by (f + k)·B of a section with round joins, chained for the
//! inner loops, is what `even` spaces along, and a polygon offset written again here would
//! have to reproduce its joins and chord tolerance to the µm for arc lengths to agree. So the
//! paths are checked independently instead ([`check_paths`]): every vertex of loop k lies
//! (f + k)·B from the test's own cut of the mesh (`common::cut`), within the offset's chord
//! tolerance. Everything measured on the droplets (which loop a droplet is on, its arc
//! position, the arc and straight-line gaps, laps) is computed here from the written code.
//!
//! An *arc gap* is the distance along the loop, forward in print direction, from a droplet to
//! the next (the seam, last → first, included); a *chord* is their straight-line distance.
#![allow(dead_code)]

// `segment` is the crate's: tests/seams.rs takes `common::segment`, examples/seams.rs its own.
use crate::segment::project;

pub type P = [f64; 2];

/// Rounding of written coordinates (±0.00005 each) moves a point by up to 7.1e-5 mm and a
/// distance between two by up to 1.42e-4 mm.
pub const TOL: f64 = 1.5e-4;

/// A written droplet lies on a loop when it is this close to its path (rounding 7.1e-5 mm).
pub const ON_PATH: f64 = 1e-4;

pub fn d(a: P, b: P) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The `G26` droplets of each layer, in file order (a new layer where Z changes).
pub fn g26_layers(text: &str) -> Vec<Vec<P>> {
    let mut layers: Vec<Vec<P>> = Vec::new();
    let mut z = f64::NAN;
    for line in text.lines() {
        if line.starts_with(';') || line.starts_with('T') {
            continue;
        }
        let mut w = line.split(' ');
        let code = w.next().unwrap_or("");
        let mut num = |c: char| {
            w.next()
                .and_then(|t| t.strip_prefix(c))
                .and_then(|t| t.parse::<f64>().ok())
                .unwrap_or_else(|| panic!("bad line {line:?}"))
        };
        let (x, y, lz) = (num('X'), num('Y'), num('Z'));
        if lz != z {
            layers.push(Vec::new());
            z = lz;
        }
        if code == "G26" {
            layers.last_mut().expect("a layer").push([x, y]);
        }
    }
    layers
}

/// The `G26` droplets of each layer with its Z, in file order.
pub fn g26_layers_z(text: &str) -> Vec<(f64, Vec<P>)> {
    let mut zs = Vec::new();
    let mut z = f64::NAN;
    for line in text.lines() {
        if line.starts_with(';') || line.starts_with('T') {
            continue;
        }
        let lz = line
            .split(' ')
            .nth(3)
            .and_then(|t| t.strip_prefix('Z'))
            .and_then(|t| t.parse::<f64>().ok())
            .unwrap_or_else(|| panic!("bad line {line:?}"));
        if lz != z {
            zs.push(lz);
            z = lz;
        }
    }
    zs.into_iter().zip(g26_layers(text)).collect()
}

/// A closed loop path measured by arc length.
#[derive(Clone, Debug)]
pub struct LoopPath {
    pub points: Vec<P>,
    /// Arc length at each vertex, and at the closing return to vertex 0 (last).
    at: Vec<f64>,
    pub length: f64,
    /// Ring index (0 = outermost).
    pub k: u32,
    bbox: [f64; 4],
}

impl LoopPath {
    pub fn new(points: Vec<P>, k: u32) -> LoopPath {
        let m = points.len();
        let mut at = vec![0.0];
        let mut bbox = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
        for i in 0..m {
            let s = at[i] + d(points[i], points[(i + 1) % m]);
            at.push(s);
            let p = points[i];
            bbox = [
                bbox[0].min(p[0]),
                bbox[1].min(p[1]),
                bbox[2].max(p[0]),
                bbox[3].max(p[1]),
            ];
        }
        LoopPath {
            length: at[m],
            points,
            at,
            k,
            bbox,
        }
    }

    /// Arc positions of `p`'s projections on the edges within `tol` of it.
    pub fn on(&self, p: P, tol: f64) -> Vec<f64> {
        let mut out = Vec::new();
        let b = &self.bbox;
        if p[0] < b[0] - tol || p[0] > b[2] + tol || p[1] < b[1] - tol || p[1] > b[3] + tol {
            return out;
        }
        let m = self.points.len();
        for i in 0..m {
            let (a, c) = (self.points[i], self.points[(i + 1) % m]);
            let (t, q) = project(p, a, c);
            if d(p, q) <= tol {
                let (dx, dy) = (c[0] - a[0], c[1] - a[1]);
                let length = (dx * dx + dy * dy).sqrt();
                out.push((self.at[i] + t * length).rem_euclid(self.length));
            }
        }
        out
    }

    /// The point at arc length `s` (mod the length).
    pub fn point(&self, s: f64) -> P {
        let s = s.rem_euclid(self.length);
        let e = (self.at.partition_point(|&a| a <= s).max(1) - 1).min(self.points.len() - 1);
        let (a, c) = (self.points[e], self.points[(e + 1) % self.points.len()]);
        let l = self.at[e + 1] - self.at[e];
        let t = if l > 0.0 { (s - self.at[e]) / l } else { 0.0 };
        [a[0] + t * (c[0] - a[0]), a[1] + t * (c[1] - a[1])]
    }
}

/// The contour loop paths of every layer of `job` (see the module doc).
pub fn loop_paths(job: &dropslice::Job) -> Vec<Vec<LoopPath>> {
    (0..job.layer_count())
        .map(|i| {
            let region = job.section(i).region;
            dropslice::slicing::contours::contours(&region, job.settings())
                .loops
                .into_iter()
                .map(|l| LoopPath::new(l.points.iter().map(|p| p.to_array()).collect(), l.k))
                .collect()
        })
        .collect()
}

/// Checks the loop paths of every `every`-th layer against the test's own cut of the mesh
/// (`cut`: the triangles and a plane height → unchained segments):
/// each vertex of loop k is (offset + k)·B from the nearest cut segment (offset 0.5, the
/// default `outer_offset` = `inner_offset`), within `tol`. Returns the largest deviation of
/// those within `tol`, how many vertices were checked, and those that are not (where the
/// library's section differs from the raw cut: shells overlapping, slivers cleaned away).
pub fn check_paths(
    job: &dropslice::Job,
    paths: &[Vec<LoopPath>],
    every: usize,
    tol: f64,
    cut: impl Fn(&[[[f64; 3]; 3]], f64) -> Vec<(P, P)>,
) -> (f64, usize, Vec<String>) {
    let mesh = job.mesh();
    let tris: Vec<[[f64; 3]; 3]> = mesh
        .facets
        .iter()
        .map(|f| f.map(|i| mesh.vertices[i as usize]))
        .collect();
    let b = job.settings().droplet_width();
    let (mut worst, mut vertices, mut off) = (0f64, 0usize, Vec::new());
    for (i, layer) in paths.iter().enumerate().step_by(every.max(1)) {
        let segs = cut(&tris, job.plane_z(i));
        for l in layer {
            let want = (0.5 + l.k as f64) * b;
            for &p in &l.points {
                let got = segs
                    .iter()
                    .map(|&(a, c)| seg_dist(p, a, c))
                    .fold(f64::INFINITY, f64::min);
                let dev = (got - want).abs();
                vertices += 1;
                if dev > tol {
                    off.push(format!(
                        "layer {}: vertex {p:?} of loop k = {} lies {got:.5} mm from the cut, not {want:.5}",
                        i + 1,
                        l.k
                    ));
                } else {
                    worst = worst.max(dev);
                }
            }
        }
    }
    (worst, vertices, off)
}

fn seg_dist(p: P, a: P, c: P) -> f64 {
    d(p, project(p, a, c).1)
}

/// One loop's droplets as written, with where they lie on its path.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Index of the loop's path in the layer.
    pub path: usize,
    pub drops: Vec<P>,
    /// Each droplet's arc position on the path (increasing; the first in [0, L)).
    pub at: Vec<f64>,
    /// Arc gaps: droplet i → i + 1 forward along the path, the seam (last → first) last.
    pub arc: Vec<f64>,
    /// Straight-line gaps, in the same order.
    pub chord: Vec<f64>,
    /// How many times the droplets go round the loop (1 for a loop spaced once around).
    pub laps: f64,
    /// Whether the first droplet is written again at the end (`exact` with `close_loops`).
    pub repeated: bool,
}

/// The loops of one layer of `even` code: the droplets on each loop path of at least
/// `min_length` (3 B), n = ⌈L/B⌉ of them, consecutive in the file. Droplets on no loop (fill)
/// and on shorter loops (printed as `exact`) are passed over. Err where a loop's droplets are
/// missing, off its path, or a loop is printed twice or not at all.
pub fn even_loops(
    drops: &[P],
    paths: &[LoopPath],
    b: f64,
    min_length: f64,
) -> Result<Vec<Measured>, String> {
    let mut used = vec![false; paths.len()];
    let mut out = Vec::new();
    let mut i = 0;
    while i < drops.len() {
        let p = drops[i];
        let on: Vec<usize> = (0..paths.len())
            .filter(|&k| !paths[k].on(p, ON_PATH).is_empty())
            .collect();
        if on.is_empty() {
            i += 1;
            continue;
        }
        let fresh: Vec<usize> = on.iter().copied().filter(|&k| !used[k]).collect();
        let next_on = |k: usize| {
            drops
                .get(i + 1)
                .is_some_and(|&q| !paths[k].on(q, ON_PATH).is_empty())
        };
        let Some(k) = fresh
            .iter()
            .copied()
            .find(|&k| next_on(k))
            .or(fresh.first().copied())
        else {
            // A droplet on a loop already printed: the end of a short (exact) loop.
            i += 1;
            continue;
        };
        used[k] = true;
        let path = &paths[k];
        if path.length < min_length {
            i += 1;
            continue;
        }
        let n = (path.length / b).ceil() as usize;
        if i + n > drops.len() {
            return Err(format!(
                "loop at {p:?}: {n} droplets expected, the layer ends"
            ));
        }
        let ld = drops[i..i + n].to_vec();
        // Arc positions: the first droplet's nearest projection, then each forward from the
        // one before; where a droplet is on two parts of the path (the two sides of a bend
        // narrower than the rounding, one place in space), the step nearest L/n.
        let mut arcs = Vec::with_capacity(n);
        for (j, &q) in ld.iter().enumerate() {
            let proj = path.on(q, ON_PATH);
            if proj.is_empty() {
                return Err(format!(
                    "loop at {p:?}: droplet {j} of {n} ({q:?}) is not on the loop's path"
                ));
            }
            let a = if j == 0 {
                proj[0]
            } else {
                let prev: f64 = arcs[j - 1];
                let nominal = path.length / n as f64;
                proj.iter()
                    .map(|&s| (s - prev).rem_euclid(path.length))
                    .filter(|&f| f > 1e-7)
                    .min_by(|a, b| (a - nominal).abs().total_cmp(&(b - nominal).abs()))
                    .unwrap_or(f64::INFINITY)
                    + prev
            };
            if !a.is_finite() {
                return Err(format!(
                    "loop at {p:?}: droplet {j} repeats droplet {}",
                    j - 1
                ));
            }
            arcs.push(a);
        }
        let mut arc: Vec<f64> = arcs.windows(2).map(|w| w[1] - w[0]).collect();
        let last = arcs[n - 1];
        arc.push((arcs[0] - last).rem_euclid(path.length));
        let chord = (0..n).map(|j| d(ld[j], ld[(j + 1) % n])).collect();
        let laps = arc.iter().sum::<f64>() / path.length;
        let repeated = drops.get(i + n).is_some_and(|&q| d(q, ld[0]) < TOL);
        out.push(Measured {
            path: k,
            drops: ld,
            at: arcs,
            arc,
            chord,
            laps,
            repeated,
        });
        i += n + usize::from(repeated);
    }
    let missing: Vec<usize> = (0..paths.len())
        .filter(|&k| !used[k] && paths[k].length >= min_length)
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "{} loop(s) of at least 3 B printed no droplets, e.g. one at {:?}",
            missing.len(),
            paths[missing[0]].points[0]
        ));
    }
    Ok(out)
}

/// The loops of one layer of `exact` code (`close_loops = true`): a loop runs from a droplet
/// to the next copy of it, its steps B apart; only loops of at least 3 droplets are returned,
/// as (droplets, seam: the last droplet → the repeated first).
pub fn exact_loops(drops: &[P], b: f64) -> Vec<(Vec<P>, f64)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < drops.len() {
        let mut j = i + 1;
        let mut closed = None;
        while j < drops.len() && d(drops[j - 1], drops[j]) <= b + TOL {
            if d(drops[j], drops[i]) < 1e-9 {
                closed = Some(j);
                break;
            }
            j += 1;
        }
        match closed {
            Some(j) => {
                if j - i >= 3 {
                    out.push((drops[i..j].to_vec(), d(drops[j - 1], drops[j])));
                }
                i = j + 1;
                // A walk that lands exactly on its start writes it twice before the copy.
                while i < drops.len() && d(drops[i], drops[j]) < 1e-9 {
                    i += 1;
                }
            }
            None => i += 1,
        }
    }
    out
}

/// Seam figures of many loops.
#[derive(Clone, Debug)]
pub struct SeamStats {
    pub loops: usize,
    pub seams_below_quarter_b: usize,
    pub min_seam: f64,
    pub min_chord: f64,
}

impl Default for SeamStats {
    fn default() -> SeamStats {
        SeamStats {
            loops: 0,
            seams_below_quarter_b: 0,
            min_seam: f64::INFINITY,
            min_chord: f64::INFINITY,
        }
    }
}

impl SeamStats {
    /// A loop's seam chord and its smallest chord.
    pub fn add(&mut self, seam: f64, min_chord: f64, b: f64) {
        self.loops += 1;
        self.seams_below_quarter_b += usize::from(seam < b / 4.0);
        self.min_seam = self.min_seam.min(seam);
        self.min_chord = self.min_chord.min(min_chord);
    }

    pub fn close_share(&self) -> f64 {
        self.seams_below_quarter_b as f64 / self.loops.max(1) as f64
    }
}

/// `exact` code's seam figures over all layers.
pub fn exact_stats(text: &str, b: f64) -> SeamStats {
    let mut s = SeamStats::default();
    for layer in g26_layers(text) {
        for (drops, seam) in exact_loops(&layer, b) {
            let n = drops.len();
            let min = (0..n - 1)
                .map(|j| d(drops[j], drops[j + 1]))
                .fold(seam, f64::min);
            s.add(seam, min, b);
        }
    }
    s
}

/// A proof that no placement of a loop meets the bounds in the arc window [a, b]: every way
/// to put consecutive droplets with arc gaps in [`lower`, `upper`] through it puts two of them
/// closer than `min_chord` in a straight line. The first droplet at or after a lies within
/// `upper` of it; the window is cut into cells of `cell` mm of arc from a, and the cells each
/// next droplet can reach are found droplet by droplet (from all first cells at once), a pair
/// of cells allowed where some points in them could meet the gap bounds and their centres'
/// chord plus `cell` reaches `min_chord` (each point is within cell/2 of its centre). True
/// when no droplet reaches past b: a placement of the whole loop would.
pub fn infeasible_in(
    path: &LoopPath,
    (a, b): (f64, f64),
    (lower, upper): (f64, f64),
    min_chord: f64,
    cell: f64,
) -> bool {
    let cells = ((b - a) / cell).ceil() as usize + 1;
    let mid: Vec<P> = (0..cells)
        .map(|k| path.point(a + (k as f64 + 0.5) * cell))
        .collect();
    let (smin, smax) = (
        ((lower - cell) / cell).ceil().max(1.0) as usize,
        ((upper + cell) / cell).floor() as usize,
    );
    let first = ((upper / cell).ceil() as usize).min(cells);
    let mut reach: Vec<usize> = (0..first).collect();
    while !reach.is_empty() {
        let mut next = vec![false; cells];
        for &k in &reach {
            for j in k + smin..=k + smax {
                if j >= cells {
                    // A droplet past b.
                    return false;
                }
                if !next[j] && d(mid[k], mid[j]) + cell >= min_chord {
                    next[j] = true;
                }
            }
        }
        reach = (0..cells).filter(|&j| next[j]).collect();
    }
    true
}

/// A proof that no placement of n droplets round a whole (short) loop meets the bounds: arc
/// gaps in [`lower`, `upper`], the seam's included, and every straight-line gap at least
/// `min_chord`. Some droplet lies in any arc interval as long as `upper`, so the first is put
/// in each cell of `cell` mm of [0, upper); the others in cells of the same grid from it,
/// droplet by droplet (the cells each can reach, only those from which the n − i gaps left
/// can still close the loop), a pair of cells allowed where some points in them could meet
/// the gap bounds and their centres' chord plus `cell` reaches `min_chord` (each point is
/// within cell/2 of its cell's centre). True when no cell of the last droplet reaches back to
/// the first: then no placement exists.
pub fn infeasible_loop(
    path: &LoopPath,
    n: usize,
    (lower, upper): (f64, f64),
    min_chord: f64,
    cell: f64,
) -> bool {
    let length = path.length;
    let cells = (length / cell).ceil() as i64 + 2;
    let starts = (upper / cell).ceil() as i64;
    // Cell centres from 0: the grid of a first droplet in cell x0 is this one from x0.
    let all: Vec<P> = (0..cells + starts)
        .map(|k| path.point((k as f64 + 0.5) * cell))
        .collect();
    // Cell steps k' − k whose gaps could lie in [lower, upper].
    let (smin, smax) = (
        ((lower - cell) / cell).ceil().max(1.0) as i64,
        ((upper + cell) / cell).floor() as i64,
    );
    // Cells of droplet i from which n − i gaps can still end at the first droplet + length
    // (a droplet in cell k lies within cell of k·cell from the first).
    let window = |i: usize| {
        let left = (n - i) as f64;
        (
            ((length - left * upper - cell) / cell).ceil() as i64,
            ((length - left * lower + cell) / cell).floor() as i64,
        )
    };
    // Cells from which every step's chord may reach min_chord ("free": away from bends), and
    // how many are not free before each.
    let mut not_free = vec![0usize; all.len() + 1];
    for g in 0..all.len() {
        let free = (smin..=smax).all(|s| {
            let h = g + s as usize;
            h < all.len() && d(all[g], all[h]) + cell >= min_chord
        });
        not_free[g + 1] = not_free[g] + usize::from(!free);
    }
    let is_free = |g: usize| not_free[g + 1] == not_free[g];
    for x0 in 0..starts {
        let mid = &all[x0 as usize..];
        let g0 = x0 as usize;
        // Droplet i's reachable cells: first ..= last, all of them or those marked.
        let (mut first, mut last, mut marks): (i64, i64, Option<Vec<bool>>) = (0, 0, None);
        let mut empty = false;
        for i in 1..n {
            let (wa, wb) = window(i);
            let a = (first + smin).max(wa);
            let b = (last + smax).min(wb).min(cells - 1);
            if b < a {
                empty = true;
                break;
            }
            let all_free = not_free[g0 + last as usize + 1] == not_free[g0 + first as usize];
            if marks.is_none() && all_free {
                (first, last) = (a, b);
                continue;
            }
            // Steps from free cells as ranges (a difference array), the others cell by cell.
            let w = (b - a + 1) as usize;
            let mut diff = vec![0i32; w + 1];
            let mut next = vec![false; w];
            for k in first..=last {
                if marks.as_ref().is_some_and(|m| !m[(k - first) as usize]) {
                    continue;
                }
                let (ja, jb) = ((k + smin).max(a), (k + smax).min(b));
                if ja > jb {
                    continue;
                }
                if is_free(g0 + k as usize) {
                    diff[(ja - a) as usize] += 1;
                    diff[(jb - a) as usize + 1] -= 1;
                } else {
                    for j in ja..=jb {
                        let x = (j - a) as usize;
                        if !next[x] && d(mid[k as usize], mid[j as usize]) + cell >= min_chord {
                            next[x] = true;
                        }
                    }
                }
            }
            let mut run = 0;
            for x in 0..w {
                run += diff[x];
                next[x] |= run > 0;
            }
            let (Some(s), Some(e)) = (next.iter().position(|&x| x), next.iter().rposition(|&x| x))
            else {
                empty = true;
                break;
            };
            first = a + s as i64;
            last = a + e as i64;
            let m = &next[s..=e];
            marks = if m.iter().all(|&x| x) {
                None
            } else {
                Some(m.to_vec())
            };
        }
        if empty {
            continue;
        }
        let closes = (first..=last)
            .filter(|&k| marks.as_ref().is_none_or(|m| m[(k - first) as usize]))
            .any(|k| {
                let gap = length - k as f64 * cell;
                gap + cell >= lower
                    && gap - cell <= upper
                    && d(mid[k as usize], mid[0]) + cell >= min_chord
            });
        if closes {
            return false;
        }
    }
    true
}
