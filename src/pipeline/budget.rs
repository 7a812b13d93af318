//! The droplet estimate of a whole job, checked when the job is built (before a layer is
//! sliced or a byte written; the page's `Session` builds the same [`crate::Job`]): the parts
//! of unit 0 by their volume and B, the parts of every other unit N by theirs and B_N, and the
//! support by a bound of its region (droplets of its unit's B_N), each against
//! [`MAX_DROPLETS`] in all; the width of each other unit's region in its droplets against
//! [`MAX_WIDTH_IN_DROPLETS`]; and with support on, the droplets one
//! layer can hold against [`MAX_LAYER_DROPLETS_WITH_SUPPORT`] (the support's droplet-level
//! pass lists a layer's droplets at once) and the whole job against
//! [`MAX_DROPLETS_WITH_SUPPORT`] (the pass checks every droplet). docs/security.md *Droplet budget*.

use crate::base::error::Error;
use crate::base::settings::{MAX_UNITS, Settings, UnitId};
use crate::base::steps::{self, Budget};
use crate::model::layout::Instance;
use crate::model::mesh::Mesh;
use crate::model::prepare::{FacetGroup, MAX_WIDTH_IN_DROPLETS};
use crate::slicing::slice;

/// Most droplets a job may set (volume / B²H): beyond this the code would not fit on a disk.
pub const MAX_DROPLETS: f64 = 2e9;

/// Most droplets one layer may hold with support on: the droplet-level pass
/// ([`crate::support::droplets::complete`]) lists a layer's droplets and sorts them into a grid,
/// about 50 bytes each (0.5 GB per worker at this limit).
pub const MAX_LAYER_DROPLETS_WITH_SUPPORT: f64 = 1e7;

/// Most droplets a job with support on may have (every unit and the support): the support's
/// droplet-level pass checks every droplet of the job against the layer below (about 10 s per
/// 10⁸ droplets natively, more in the page, where each worker runs it).
pub const MAX_DROPLETS_WITH_SUPPORT: f64 = 1e8;

/// The facets one unit other than 0 prints (its parts): their signed volume and bounding box.
#[derive(Clone, Copy, Debug)]
pub struct UnitParts {
    signed_volume: f64,
    min: [f64; 3],
    max: [f64; 3],
}

/// Each unit's parts, indexed by unit (`None` for unit 0 and for a unit without a facet).
pub type PartsByUnit = [Option<UnitParts>; MAX_UNITS];

impl UnitParts {
    /// The facets of `groups`' runs of each unit but 0.
    pub fn of(mesh: &Mesh, groups: &[FacetGroup]) -> PartsByUnit {
        let mut out: PartsByUnit = [None; MAX_UNITS];
        let mut at = 0usize;
        for g in groups {
            let end = (at + g.facets).min(mesh.facets.len());
            let unit = usize::from(g.unit);
            if unit > 0 && unit < MAX_UNITS && end > at {
                let u = out[unit].get_or_insert(UnitParts {
                    signed_volume: 0.0,
                    min: [f64::INFINITY; 3],
                    max: [f64::NEG_INFINITY; 3],
                });
                for f in &mesh.facets[at..end] {
                    let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
                    u.signed_volume += (a[0] * (b[1] * c[2] - b[2] * c[1])
                        - a[1] * (b[0] * c[2] - b[2] * c[0])
                        + a[2] * (b[0] * c[1] - b[1] * c[0]))
                        / 6.0;
                    for p in [a, b, c] {
                        for ((lo, hi), x) in u.min.iter_mut().zip(&mut u.max).zip(p) {
                            *lo = lo.min(x);
                            *hi = hi.max(x);
                        }
                    }
                }
            }
            at = end;
        }
        out
    }

    fn size(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| (self.max[k] - self.min[k]).max(0.0))
    }
}

/// The down-facing facets of a closed mesh (outward normals), summed over the layers for the
/// support's bound ([`Overhangs::droplets`]).
///
/// **Why the support lies under them.** The support of layer n lies under the overhangs of the
/// layers above (grown by the support's reach, [`crate::support::support_reach`], within
/// [`crate::support::SUPPORT_TOLERANCE_MM`]), and overhang(m) ⊂ region(m) − region(m − 1): a
/// point inside the section at z(m) and outside at z(m − 1) has a surface crossing between the
/// two planes where the vertical line enters the solid going up, on a facet whose outward
/// normal points down and whose top is at least z(m − 1). Layer n < m then has z(n) ≤ the
/// facet's top: a facet of top t counts for the N(t) layers of plane at most t. So layer n's
/// support lies within the reach of U(n), the projections of the down-facing facets with
/// N > n.
///
/// **The area within r of U(n)** is at most A + P·r + π r²·C: A the sum of their areas, P the
/// length of U(n)'s boundary, C its pieces (each boundary loop of a polygon, moved out by t,
/// is at most 2π t longer for an outer loop and no longer for a hole; integrate over t ≤ r).
/// Two down-facing facets sharing an edge in opposite directions (a closed, oriented shell)
/// lie on both sides of its projection, so the edge is no boundary of U(n) while both count:
/// P ≤ Σ over edges of the length × the facets using it that count without their partner.
/// C is at most the pieces of U(n) joined through shared edges (union–find, the facets added
/// from the highest N down). Summed over the layers: O(facets), the edges grouped by a counting
/// sort on their lower vertex.
#[derive(Clone, Copy, Debug, Default)]
pub struct Overhangs {
    /// Σₙ A(n) (mm²·layers).
    area: f64,
    /// Σₙ P(n) (mm·layers).
    perimeter: f64,
    /// Σₙ C(n) (layers).
    pieces: f64,
}

impl Overhangs {
    /// The down-facing facets of `mesh` (oriented outward), sliced at the planes `zs` (the
    /// unit tests'; the preparation runs [`Overhangs::of_in_steps`]).
    #[cfg(test)]
    pub fn of(mesh: &Mesh, zs: &[f64]) -> Overhangs {
        steps::now(Overhangs::of_in_steps(mesh, zs, &steps::UNLIMITED))
    }

    /// [`Overhangs::of`] in resumable steps (its long loops in runs: [`steps::runs`]).
    pub async fn of_in_steps(mesh: &Mesh, zs: &[f64], budget: &Budget) -> Overhangs {
        // The edges are visited in a fixed order (by their vertices), so the perimeter's sum
        // is the same to the last bit in every run.
        let count = |top: f64| zs.partition_point(|&z| z <= top) as u32;
        let mut o = Overhangs::default();
        // Each down-facing facet that counts for some layer: its corners and N.
        let mut down: Vec<([u32; 3], u32)> = Vec::new();
        steps::runs(mesh.facets.len(), budget, &mut |r| {
            for f in &mesh.facets[r] {
                let v = |i: u32| mesh.vertices.get(i as usize).copied();
                let (Some(a), Some(b), Some(c)) = (v(f[0]), v(f[1]), v(f[2])) else {
                    continue;
                };
                // Twice the projection's signed area: negative for a facet facing down.
                let twice = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
                let n = count(a[2].max(b[2]).max(c[2]));
                if twice < 0.0 && n > 0 {
                    o.area += -0.5 * twice * n as f64;
                    down.push((*f, n));
                }
            }
        })
        .await;
        let top = down.iter().map(|d| d.1).max().unwrap_or(0) as usize;
        // Pairs of facets sharing an edge, by the layer count both reach.
        let mut joins: Vec<Vec<(u32, u32)>> = vec![Vec::new(); top + 1];
        let mut fresh = vec![0u32; top + 1];
        for &(_, n) in &down {
            fresh[n as usize] += 1;
        }
        // Each edge's facets, with the direction they use it in, grouped by the edge's lower
        // vertex (a counting sort: a hash map's random reads took most of the time), then by
        // its other vertex, in the order of the facets. Every corner of `down` is a vertex of
        // the mesh (checked above).
        let sides = |f: &[u32; 3]| [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])];
        let nv = mesh.vertices.len();
        let mut first = vec![0u32; nv + 1];
        for (f, _) in &down {
            for (p, q) in sides(f) {
                first[p.min(q) as usize + 1] += 1;
            }
        }
        let mut sum = 0;
        for c in first.iter_mut() {
            sum += *c;
            *c = sum;
        }
        let mut fill = first.clone();
        // (the other vertex, the facet, whether the facet runs from the lower vertex to it)
        let mut uses = vec![(0u32, 0u32, false); sum as usize];
        for (k, (f, _)) in down.iter().enumerate() {
            for (p, q) in sides(f) {
                let at = &mut fill[p.min(q) as usize];
                uses[*at as usize] = (p.max(q), k as u32, p < q);
                *at += 1;
            }
        }
        drop(fill);
        let mut per_vertex = |r: std::ops::Range<usize>| {
            for p in r {
                let around = &mut uses[first[p] as usize..first[p + 1] as usize];
                // Stable (the facets' order kept); O(k log k) however many facets share a vertex.
                around.sort_by_key(|u| u.0);
                for edge in around.chunk_by(|a, b| a.0 == b.0) {
                    let used = edge.len();
                    // The first two users (the first twice when it is alone: only it is read then).
                    let users = [edge[0], edge[used.min(2) - 1]].map(|u| (u.1, u.2));
                    let (a, b) = (mesh.vertices[p], mesh.vertices[edge[0].0 as usize]);
                    let len = (b[0] - a[0]).hypot(b[1] - a[1]);
                    let n = |u: (u32, bool)| down[u.0 as usize].1;
                    if used == 2 && users[0].1 != users[1].1 {
                        o.perimeter += len * n(users[0]).abs_diff(n(users[1])) as f64;
                    } else {
                        let stored: u32 = users[..used.min(2)].iter().map(|&u| n(u)).sum();
                        o.perimeter +=
                            len * (stored as f64 + used.saturating_sub(2) as f64 * top as f64);
                    }
                    if used >= 2 {
                        let level = n(users[0]).min(n(users[1]));
                        joins[level as usize].push((users[0].0, users[1].0));
                    }
                }
            }
        };
        steps::runs(nv, budget, &mut per_vertex).await;
        drop(uses);
        let mut parent: Vec<u32> = (0..down.len() as u32).collect();
        fn root(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let up = parent[parent[i as usize] as usize];
                parent[i as usize] = up;
                i = up;
            }
            i
        }
        let mut pieces = 0u64;
        for level in (1..=top).rev() {
            pieces += fresh[level] as u64;
            for &(a, b) in &joins[level] {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                if ra != rb {
                    parent[ra as usize] = rb;
                    pieces -= 1;
                }
            }
            o.pieces += pieces as f64;
        }
        o
    }

    /// Σₙ of the area within `r` of U(n) (mm²·layers), at most: A + P·r + π r²·C.
    fn grown(&self, r: f64) -> f64 {
        self.area + self.perimeter * r + std::f64::consts::PI * r * r * self.pieces
    }

    /// A bound of the support's droplets under these facets with settings `s`, both kinds:
    ///
    /// * **Hatch** ([`crate::support::moves::support_moves`]; the support has no contour
    ///   loop): droplets on a lattice of pitch B₁ along lines B₁ / `support_density` apart,
    ///   inside the support region, which lies within r = support reach + 2 × the support's
    ///   tolerance (its offsets and the sections' simplification) of the facets' projections.
    ///   Each lattice point owns its cell (B₁ × B₁ / `support_density`), which lies within the
    ///   cell's half-diagonal d of it: at most area(region ⊕ d) × `support_density` / B₁²
    ///   droplets.
    /// * **The droplet-level pass** ([`crate::support::droplets::complete`]) adds a droplet
    ///   to layer n − 1 only under a droplet c of layer n with no droplet of layer n − 1
    ///   within its reach, at most `place` = B₁/2 + `overhang_limit`·B from c. It skips a c
    ///   within R' = `place` − 1 µm of a droplet it already added to that layer and tries c
    ///   itself first, so the added droplets of a layer are more than R' apart (discs of
    ///   radius R'/2 around them disjoint): at most 4 / (π R'²) per mm² of where they lie,
    ///   grown by R'/2. Where they lie: c is where layer n overhangs layer n − 1 (under the
    ///   facets, as the support), and where the hatch is dense (every point within the rule's
    ///   reach of a lattice point, d ≤ B₁/2 + `overhang_limit`·B) the hatch of layer n − 1
    ///   supports all of its region but a strip of width d along the edge: so within
    ///   w = d + `place` + R'/2 of U(n)'s grown edge, an area at most P·(r + w) + π (r + w)²·C
    ///   per layer (the grown area less U(n)'s own). With sparse hatch, all of U(n) grown by
    ///   r + w. (A droplet placed beside c, where c itself lies in the part or its gap below,
    ///   can come nearer an earlier one; those lie at the part's edges, a small share.)
    pub fn droplets(&self, s: &Settings) -> f64 {
        let (b, b1) = (s.droplet_width(), s.support_width());
        let rho = s.support_density;
        let r = crate::support::support_reach(s) + 2.0 * crate::support::SUPPORT_TOLERANCE_MM;
        let d = 0.5 * b1.hypot(b1 / rho);
        let hatch = self.grown(r + d) * rho / (b1 * b1);
        let place = 0.5 * b1 + s.overhang_limit * b;
        let apart = (place - crate::support::droplets::MARGIN_MM).max(0.25 * b1);
        let w = d + place + 0.5 * apart;
        let region = if d <= place - crate::support::droplets::MARGIN_MM {
            self.grown(r + w) - self.area
        } else {
            self.grown(r + w)
        };
        let pass = region * 4.0 / (std::f64::consts::PI * apart * apart);
        hatch + pass
    }
}

/// The volumes and areas the estimate counts droplets in.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Each unit's parts (mm³), indexed by unit.
    pub unit_volumes: [f64; MAX_UNITS],
    /// A bound of the support's droplets (of its unit's B_N): the lesser of
    /// [`Overhangs::droplets`] (under the down-facing facets) and the hatch under each
    /// instance's footprint grown by the support's reach, from the plate to the instance's top
    /// (that alone for open shells).
    pub support_droplets: f64,
    /// A bound of the area one layer covers (mm²): the instances' footprints, grown.
    pub footprint: f64,
    /// The width of the region each unit but 0 prints (mm): its parts', or for the support's
    /// unit with support on the job's grown; indexed by unit.
    pub unit_extents: [f64; MAX_UNITS],
    /// The job's size (mm), for the messages.
    size: [f64; 3],
}

/// B, B₁, B₂, B₃: unit `u`'s droplet width in a message.
fn b_of(u: usize) -> &'static str {
    ["B", "B₁", "B₂", "B₃"].get(u).copied().unwrap_or("B")
}

impl Estimate {
    /// The estimate of a job of `size` (mm) whose mesh encloses `volume` (mm³), of which
    /// `parts` are the other units' (`open`: some shell is not closed, so their signed volumes
    /// mean nothing and their bounding boxes are taken, and the support is bounded by the
    /// footprints alone), placed as `instances` say; `overhangs`: the mesh's down-facing
    /// facets (every unit's: support goes under any).
    pub fn new(
        volume: f64,
        parts: &PartsByUnit,
        open: bool,
        size: &[f64; 3],
        instances: &[Instance],
        overhangs: &Overhangs,
        s: &Settings,
    ) -> Estimate {
        let (b0, bs) = (s.droplet_width(), s.support_width());
        let mut unit_volumes = [0.0; MAX_UNITS];
        let mut unit_extents = [0.0; MAX_UNITS];
        let mut others = None;
        for (k, p) in parts.iter().enumerate().skip(1) {
            if let Some(u) = p {
                let [x, y, z] = u.size();
                let bbox = x * y * z;
                unit_volumes[k] = if open {
                    bbox
                } else {
                    u.signed_volume.abs().min(bbox)
                };
                unit_extents[k] = x.max(y);
                *others.get_or_insert(0.0) += unit_volumes[k];
            }
        }
        unit_volumes[0] = match others {
            Some(v) if !open => (volume - v).max(0.0),
            _ => volume,
        };
        let mut e = Estimate {
            unit_volumes,
            support_droplets: 0.0,
            footprint: 0.0,
            unit_extents,
            size: *size,
        };
        // Support lies under overhangs grown by B_N/2 (its droplets on lattice lines B_N /
        // support_density apart), and the droplet-level pass adds droplets within
        // B_N/2 + overhang_limit × B of a droplet: all within `grow` of the parts' footprints.
        let grow = 2.0 * bs / s.support_density + s.overhang_limit * b0;
        let grown = |w: f64, d: f64| (w.min(size[0]) + 2.0 * grow) * (d.min(size[1]) + 2.0 * grow);
        let whole = grown(size[0], size[1]);
        let (mut area, mut under) = (0.0, 0.0);
        let bottom = instances
            .iter()
            .map(|i| i.min[2])
            .fold(f64::INFINITY, f64::min);
        for i in instances {
            let a = grown(i.max[0] - i.min[0], i.max[1] - i.min[1]);
            area += a;
            under += a * (i.max[2] - bottom).clamp(0.0, size[2]);
        }
        let ok = |x: f64| x.is_finite() && x > 0.0;
        e.footprint = if instances.len() > 1 && ok(area) {
            area.min(whole)
        } else {
            whole
        };
        let under = if instances.len() > 1 && ok(under) {
            under.min(whole * size[2])
        } else {
            whole * size[2]
        };
        let footprint_bound = s.support_density * under / (bs * bs * s.layer_height);
        e.support_droplets = if open {
            // The slicer closes open sections itself: down-facing facets may be missing.
            footprint_bound
        } else {
            footprint_bound.min(overhangs.droplets(s))
        };
        if let Some(su) = s.support.unit() {
            e.unit_extents[su.index()] = size[0].max(size[1]) + 2.0 * grow;
        }
        e
    }

    /// Refuses a job beyond the limits (module doc), naming the unit and the setting to change.
    pub fn check(&self, s: &Settings) -> Result<(), Error> {
        check_droplets(self.unit_volumes[0], s)?;
        let h = s.layer_height;
        let b: Vec<f64> = UnitId::all(MAX_UNITS).map(|u| s.unit_width(u)).collect();
        let aspect = |u: usize| UnitId(u as u8).name("droplet_aspect");
        let su = s.support_unit().index();
        let support = s.support.is_on();
        // A unit's droplets only where it prints: a B_N that no part and no support uses is
        // never checked (its B_N² may be tiny).
        let d: Vec<f64> = (0..MAX_UNITS)
            .map(|u| match u {
                0 => self.unit_volumes[0] / (b[0] * b[0] * h),
                _ if self.unit_volumes[u] > 0.0 => self.unit_volumes[u] / (b[u] * b[u] * h),
                _ => 0.0,
            })
            .collect();
        let ds = if support { self.support_droplets } else { 0.0 };
        let total = d.iter().sum::<f64>() + ds;
        // The other unit whose parts take the most droplets.
        let most = (1..MAX_UNITS)
            .max_by(|&x, &y| d[x].total_cmp(&d[y]))
            .unwrap_or(1);
        let [x, y, z] = self.size;
        if over(total, MAX_DROPLETS) {
            let (name, message) = if over(d[most], ds) && self.unit_volumes[most] > 0.0 {
                (
                    aspect(most),
                    format!(
                        "the parts of unit {most} ({:.0} mm³) would take about {:.1e} droplets of {} = {} mm ({total:.1e} for the whole job), more than the {MAX_DROPLETS:.0e} allowed; raise {} (or layer_height)",
                        self.unit_volumes[most],
                        d[most],
                        b_of(most),
                        mm(b[most]),
                        aspect(most)
                    ),
                )
            } else {
                (
                    "support".to_string(),
                    format!(
                        "support under the parts ({x:.0} × {y:.0} × {z:.0} mm) could take up to {ds:.1e} droplets of {} = {} mm ({total:.1e} for the whole job), more than the {MAX_DROPLETS:.0e} allowed; raise {} (or layer_height), or set support = off",
                        b_of(su),
                        mm(b[su]),
                        aspect(su)
                    ),
                )
            };
            return Err(Error::setting(&name, message));
        }
        if support && over(total, MAX_DROPLETS_WITH_SUPPORT) {
            let (name, what) = if d[0] >= d[most].max(ds) {
                (
                    aspect(0),
                    format!("{:.1e} of unit 0's B = {} mm", d[0], mm(b[0])),
                )
            } else if d[most] >= ds {
                (
                    aspect(most),
                    format!(
                        "{:.1e} of unit {most}'s parts, {} = {} mm",
                        d[most],
                        b_of(most),
                        mm(b[most])
                    ),
                )
            } else {
                (
                    aspect(su),
                    format!("up to {ds:.1e} of support, {} = {} mm", b_of(su), mm(b[su])),
                )
            };
            let figure = format!("the job could take up to {total:.1e} droplets");
            return Err(too_many_with_support(
                &name,
                &figure,
                &what,
                MAX_DROPLETS_WITH_SUPPORT,
            ));
        }
        let widths = (b.iter()).zip(self.unit_extents.iter().zip(&self.unit_volumes));
        for (u, (&bu, (&extent, &volume))) in widths.enumerate().skip(1) {
            let prints_support = support && u == su;
            let used = prints_support || volume > 0.0;
            if used && over(extent / bu, MAX_WIDTH_IN_DROPLETS) {
                return Err(Error::setting(
                    &aspect(u),
                    format!(
                        "unit {u}'s region would be {extent:.0} mm wide{}, more than {MAX_WIDTH_IN_DROPLETS} droplets of {} = {} mm; raise {}{}",
                        if prints_support { " (support)" } else { "" },
                        b_of(u),
                        mm(bu),
                        aspect(u),
                        if prints_support {
                            " or set support = off"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        }
        if support {
            let a = self.footprint;
            let per: Vec<f64> = (0..MAX_UNITS)
                .map(|u| {
                    let layers = match u {
                        0 => 1.0,
                        _ => {
                            (if u == su { s.support_density } else { 0.0 })
                                + if self.unit_volumes[u] > 0.0 { 1.0 } else { 0.0 }
                        }
                    };
                    a * layers / (b[u] * b[u])
                })
                .collect();
            let per_layer: f64 = per.iter().sum();
            if over(per_layer, MAX_LAYER_DROPLETS_WITH_SUPPORT) {
                let worst = (1..MAX_UNITS)
                    .max_by(|&x, &y| per[x].total_cmp(&per[y]))
                    .unwrap_or(1);
                let others: f64 = per[1..].iter().sum();
                let (name, what) = if per[0] >= others {
                    (aspect(0), format!("unit 0's B = {} mm", mm(b[0])))
                } else {
                    (
                        aspect(worst),
                        format!("unit {worst}'s {} = {} mm", b_of(worst), mm(b[worst])),
                    )
                };
                let figure =
                    format!("a layer of {a:.0} mm² could hold up to {per_layer:.1e} droplets");
                return Err(too_many_with_support(
                    &name,
                    &figure,
                    &what,
                    MAX_LAYER_DROPLETS_WITH_SUPPORT,
                ));
            }
        }
        Ok(())
    }
}

/// Whether `x` is beyond `limit` (or not a number).
/// The refusal of a job whose support pass would check more droplets than `cap`.
fn too_many_with_support(name: &str, figure: &str, what: &str, cap: f64) -> Error {
    Error::setting(
        name,
        format!(
            "with support {figure} ({what}), more than the {cap:.0e} the support's check of every droplet allows; raise {name} (or layer_height), or set support = off"
        ),
    )
}

fn over(x: f64, limit: f64) -> bool {
    x.is_nan() || x > limit
}

/// A droplet width for a message: 4 decimals, or 2 significant digits below a micrometre.
pub fn mm(x: f64) -> String {
    if x >= 1e-3 {
        format!("{x:.4}")
    } else {
        format!("{x:.1e}")
    }
}

/// Refuses a job whose estimated volume would take more than [`MAX_DROPLETS`] droplets.
fn check_droplets(volume: f64, settings: &Settings) -> Result<(), Error> {
    let b = settings.droplet_width();
    let droplets = volume / (b * b * settings.layer_height);
    if droplets > MAX_DROPLETS || !droplets.is_finite() {
        return Err(Error::Setting {
            name: "layer_height".into(),
            message: format!(
                "the part ({volume:.0} mm³) would take about {droplets:.1e} droplets of unit 0's B = {} mm, more than the {MAX_DROPLETS:.0e} allowed (the code would be hundreds of gigabytes); use larger droplets (layer_height, droplet_aspect) or check the scale",
                mm(b)
            ),
        });
    }
    Ok(())
}

/// Checks unit 0's width in droplets (against [`MAX_WIDTH_IN_DROPLETS`]); the plane heights
/// of the layers (at least one).
pub(super) fn plane_heights(size: &[f64; 3], settings: &Settings) -> Result<Vec<f64>, Error> {
    let b = settings.droplet_width();
    let h = settings.layer_height;
    if size[0].max(size[1]) / b > MAX_WIDTH_IN_DROPLETS {
        return Err(Error::Setting {
            name: "scale_x".into(),
            message: format!(
                "the part is {:.0} mm wide, more than {MAX_WIDTH_IN_DROPLETS} droplets of {b:.4} mm; check the scale (is the file in micrometres?)",
                size[0].max(size[1])
            ),
        });
    }
    let zs = slice::layer_heights(size[2], h, settings.slice_plane);
    if zs.is_empty() {
        return Err(Error::NothingToPrint(format!(
            "the part is {:.4} mm tall, less than half a layer ({} mm): scale it up or lower layer_height",
            size[2],
            h / 2.0
        )));
    }
    Ok(zs)
}

#[cfg(test)]
mod tests;

/// Layers sampled by [`sampled_volume`].
const VOLUME_SAMPLES: usize = 24;

/// The volume the slicer will print, estimated from the sliced area of up to
/// [`VOLUME_SAMPLES`] evenly spaced layers (their mean area × the part's height).
pub(crate) fn sampled_volume(
    mesh: &Mesh,
    buckets: &crate::slicing::slice::FacetBuckets,
    zs: &[f64],
    h: f64,
) -> f64 {
    let n = zs.len();
    let samples = n.min(VOLUME_SAMPLES);
    let rims = std::sync::OnceLock::new();
    let total: f64 = (0..samples)
        .map(|k| {
            let i = (2 * k + 1) * n / (2 * samples);
            crate::base::geom::region_area(
                &crate::slicing::slice::slice_layer(mesh, buckets.layer(i), zs[i], &rims).region,
            )
        })
        .sum();
    total / samples as f64 * n as f64 * h
}
