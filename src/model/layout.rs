//! Where the instances of a job go: each part's transform ([`Frame`]), the bottom-left
//! arrangement on the plate ([`arrange`]), every copy placed ([`place_instances`]) into the
//! [`Layout`] the page draws, and the rotation that lays a part on its largest flat face
//! ([`lay_flat`]).

use crate::base::error::Error;
use crate::base::geom::DVec3;
use crate::model::fit::{self, Misfit};
pub use crate::model::frame::{Frame, Instance, InstanceId};
use crate::model::mesh::Bounds;
use crate::model::models::{Model, corners, models_of};
use crate::model::spec::{JobSpec, PartSpec, clean_name};
use serde::{Deserialize, Serialize};

/// Where every instance goes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct Layout {
    pub instances: Vec<Instance>,
    pub bounds: Bounds,
    pub warnings: Vec<String>,
    /// The instances that break the plate rule ([`fit::misfit`]), in the order of `instances`;
    /// a part larger than the plate once.
    #[serde(default)]
    pub misfits: Vec<Misfit>,
}

/// An axis-aligned rectangle on the plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub min: [f64; 2],
    pub max: [f64; 2],
}

impl Rect {
    /// Whether the two come closer than `gap` (touching at exactly `gap` is allowed).
    pub fn too_close(&self, o: &Rect, gap: f64) -> bool {
        let eps = 1e-9 * (1.0 + gap);
        (0..2).all(|k| self.min[k] < o.max[k] + gap - eps && o.min[k] < self.max[k] + gap - eps)
    }
}

/// Bottom-left arrangement: every box of `sizes` (width, depth) gets a slot (its minimum
/// corner) on the plate [0, plate_x] × [0, plate_y], at least `gap` from every other box and
/// every `fixed` one; `None` where it does not fit. The boxes are taken largest footprint first
/// (stable); each goes to the lowest y, then lowest x, of the candidates: the origin, right of
/// and above every box already there, and those at x = 0 or y = 0.
pub fn arrange(
    fixed: &[Rect],
    sizes: &[[f64; 2]],
    plate: [f64; 2],
    gap: f64,
) -> Vec<Option<[f64; 2]>> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by(|&a, &b| {
        let area = |i: usize| sizes[i][0] * sizes[i][1];
        area(b).total_cmp(&area(a))
    });
    let mut there: Vec<Rect> = fixed.to_vec();
    let mut slots = vec![None; sizes.len()];
    let eps = 1e-9 * (1.0 + plate[0].max(plate[1]));
    for i in order {
        let [w, d] = sizes[i];
        if w > plate[0] + eps || d > plate[1] + eps {
            continue;
        }
        let mut candidates = vec![[0.0, 0.0]];
        for r in &there {
            let (x, y) = (r.max[0] + gap, r.max[1] + gap);
            candidates.extend([[x, r.min[1]], [r.min[0], y], [x, 0.0], [0.0, y]]);
        }
        candidates.retain(|c| {
            c[0] >= -eps && c[1] >= -eps && c[0] + w <= plate[0] + eps && c[1] + d <= plate[1] + eps
        });
        candidates.sort_by(|a, b| a[1].total_cmp(&b[1]).then(a[0].total_cmp(&b[0])));
        let found = candidates.into_iter().find(|c| {
            let r = Rect {
                min: *c,
                max: [c[0] + w, c[1] + d],
            };
            !there.iter().any(|o| r.too_close(o, gap))
        });
        if let Some(c) = found {
            there.push(Rect {
                min: c,
                max: [c[0] + w, c[1] + d],
            });
            slots[i] = Some(c);
        }
    }
    slots
}

/// Where every instance of `spec` goes, given each part's [`Frame`] (`frames[i]` for
/// `spec.parts[i]`). Refuses a job whose arranged instances do not fit the plate together; an
/// arranged instance larger than the plate goes to the origin, and every instance that breaks
/// the plate rule is one of [`Layout::misfits`] (the job is refused for them later, unless
/// `allow_off_plate`).
pub fn place_instances(
    models: &[&Model],
    spec: &JobSpec,
    frames: &[Frame],
) -> Result<Layout, Error> {
    let s = &spec.settings;
    let plate = [s.plate_x, s.plate_y];
    let gap = s.part_spacing;
    let warnings = Vec::new();
    let mut instances = Vec::new();
    let mut fixed = Vec::new();
    let mut free: Vec<InstanceId> = Vec::new();
    for (i, p) in spec.parts.iter().enumerate() {
        let f = &frames[i];
        for copy in 0..p.copies as usize {
            let id = InstanceId { part: i, copy };
            match p.place() {
                Some(at) if copy == 0 => {
                    let r = Rect {
                        min: [f.qmin.x + at[0], f.qmin.y + at[1]],
                        max: [f.qmax.x + at[0], f.qmax.y + at[1]],
                    };
                    fixed.push(r);
                    instances.push(instance(models[i], id, p, f, true, at, [at[0], at[1]]));
                }
                _ => {
                    free.push(id);
                    // Filled in below.
                    instances.push(instance(models[i], id, p, f, false, [0.0, 0.0], [0.0, 0.0]));
                }
            }
        }
    }
    let sizes: Vec<[f64; 2]> = free
        .iter()
        .map(|id| {
            let f = &frames[id.part];
            [f.qmax.x - f.qmin.x, f.qmax.y - f.qmin.y]
        })
        .collect();
    let mut slots = arrange(&fixed, &sizes, plate, gap);
    // Larger than the plate: no arrangement can help; at the origin, a misfit.
    let eps = fit::TOLERANCE_MM;
    for (slot, [w, d]) in slots.iter_mut().zip(&sizes) {
        if slot.is_none() && (*w > plate[0] + eps || *d > plate[1] + eps) {
            *slot = Some([0.0, 0.0]);
        }
    }
    let missing: Vec<InstanceId> = free
        .iter()
        .zip(&slots)
        .filter(|(_, s)| s.is_none())
        .map(|(&id, _)| id)
        .collect();
    if !missing.is_empty() {
        return Err(not_fitting(models, spec, frames, &missing));
    }
    let mut k = 0;
    for inst in instances.iter_mut() {
        if inst.placed {
            continue;
        }
        let slot = slots[k].expect("every instance has a slot");
        k += 1;
        let f = &frames[inst.id.part];
        inst.place(f, slot, [slot[0] - f.qmin.x, slot[1] - f.qmin.y]);
    }
    let mut bounds = Bounds::EMPTY;
    for inst in &instances {
        bounds.grow(inst.min, inst.max);
    }
    let mut misfits: Vec<Misfit> = Vec::new();
    for inst in &instances {
        let part = inst.id.part;
        let (p, m) = (&spec.parts[part], models[part]);
        let Some(f) = fit::misfit(inst, &frames[part], &shown_name(m, p), s) else {
            continue;
        };
        // A part larger than the plate is named once, whatever its copies.
        if f.kind == fit::MisfitKind::Outside || !misfits.iter().any(|x| x.id.part == part) {
            misfits.push(f);
        }
    }
    Ok(Layout {
        instances,
        bounds,
        warnings,
        misfits,
    })
}

/// The part's name as the page lists it: the spec's `name`; a 3MF item's name with its file,
/// "gear (gears.3mf)"; else the file's name (without the folders a job file or the command
/// line gave).
pub fn shown_name(model: &Model, p: &PartSpec) -> String {
    if let Some(n) = &p.name {
        return clean_name(n);
    }
    let file = p.file.rsplit(['/', '\\']).next().unwrap_or(&p.file);
    match p.item {
        Some(i) => clean_name(&format!("{} ({file})", model.part_name(Some(i)))),
        None => clean_name(file),
    }
}

/// The refusal of a job whose arranged instances `missing` found no slot.
fn not_fitting(
    models: &[&Model],
    spec: &JobSpec,
    frames: &[Frame],
    missing: &[InstanceId],
) -> Error {
    let s = &spec.settings;
    let (plate, gap) = ([s.plate_x, s.plate_y], s.part_spacing);
    let mut parts: Vec<String> = Vec::new();
    for (i, p) in spec.parts.iter().enumerate() {
        let n = missing.iter().filter(|m| m.part == i).count();
        if n > 0 {
            let f = &frames[i];
            parts.push(format!(
                "parts[{i}] ({}, {:.1} × {:.1} mm): {n} of {} cop{}",
                clean_name(&part_label(models[i], p)),
                f.qmax.x - f.qmin.x,
                f.qmax.y - f.qmin.y,
                p.copies,
                if p.copies == 1 { "y" } else { "ies" }
            ));
        }
    }
    Error::Job(format!(
        "not every part fits on the plate ({} × {} mm, part_spacing {} mm); these do not: {}. Use a larger plate (plate_x, plate_y), fewer copies or a smaller part_spacing",
        plate[0],
        plate[1],
        gap,
        parts.join("; ")
    ))
}

/// `name` of the spec, else the part's name in its file.
fn part_label(model: &Model, p: &PartSpec) -> String {
    p.name.clone().unwrap_or_else(|| model.part_name(p.item))
}

fn instance(
    model: &Model,
    id: InstanceId,
    p: &PartSpec,
    f: &Frame,
    placed: bool,
    at: [f64; 2],
    shift: [f64; 2],
) -> Instance {
    let mut inst = Instance {
        id,
        copies: p.copies as usize,
        name: clean_name(&part_label(model, p)),
        file: clean_name(&p.file),
        item: p.item,
        object: p
            .item
            .and_then(|i| model.parts.get(i))
            .and_then(|x| x.source_object.clone())
            .map(|o| clean_name(&o)),
        rotate: [p.rotate_x, p.rotate_y, p.rotate_z],
        scale: [p.scale_x, p.scale_y, p.scale_z],
        mirror: [p.mirror_x, p.mirror_y, p.mirror_z],
        place_angle: p.place_angle,
        placed,
        unit: p.unit,
        size: (f.max1 - f.min1).to_array(),
        ..Instance::default()
    };
    inst.place(f, at, shift);
    inst
}

/// The layout of a job from its imported files, without building the meshes (the page's 3D
/// view; [`crate::Job::from_models`] gives the same instances).
pub fn layout(models: &[Model], spec: &JobSpec) -> Result<Layout, Error> {
    spec.validate()?;
    let by_part = models_of(models, spec)?;
    let frames = spec
        .parts
        .iter()
        .zip(&by_part)
        .enumerate()
        .map(|(i, (p, m))| {
            let tris = m.triangles(p.item).map_err(|e| at_part(i, e))?;
            Frame::of(
                &tris,
                |t| t.map(|c| c.map(f64::from)),
                &p.placement([0.0, 0.0], &spec.settings),
            )
            .ok_or_else(|| Error::Job(format!("parts[{i}]: the part has no triangles")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    place_instances(&by_part, spec, &frames)
}

/// An error of part `i` with the part named.
pub fn at_part(i: usize, e: Error) -> Error {
    match e {
        Error::Job(m) if !m.starts_with("parts[") => Error::Job(format!("parts[{i}]: {m}")),
        e => e,
    }
}

/// Most facets [`lay_flat`] looks at for supporting planes (more are sampled evenly).
pub const LAY_FLAT_POINTS: usize = 300_000;
/// Largest planes [`lay_flat`] checks for being a supporting plane.
const LAY_FLAT_CANDIDATES: usize = 64;

/// `(rotate_x, rotate_y)` in degrees (SPEC's order: x first) that put the part's largest flat
/// face down: the largest set of coplanar mesh facets (facet normals within about 0.06° and
/// plane offsets within 1 µm·scale grouped) whose plane touches the part from outside (no
/// vertex beyond it), so the part rests on it. `(0, 0)` when no flat face supports the part
/// (e.g. a sphere or a torus). Cost: one pass over the facets and up to 64 passes over at most
/// [`LAY_FLAT_POINTS`] sampled corners.
pub fn lay_flat(tris: &[[[f32; 3]; 3]]) -> (f64, f64) {
    use std::collections::HashMap;
    if tris.is_empty() {
        return (0.0, 0.0);
    }
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in corners(tris) {
        lo = lo.min(DVec3::from(p));
        hi = hi.max(DVec3::from(p));
    }
    let extent = (hi - lo).max_element().max(1e-9);
    let centre = (lo + hi) / 2.0;
    // plane key → (area, area-weighted normal, area-weighted offset)
    let mut planes: HashMap<[i64; 4], (f64, DVec3, f64)> = HashMap::new();
    for t in tris {
        let [a, b, c] = t.map(|p| DVec3::from(p.map(f64::from)) - centre);
        let n2 = (b - a).cross(c - a);
        let len = n2.length();
        if len <= 1e-12 * extent * extent || !len.is_finite() {
            continue;
        }
        let n = n2 / len;
        let d = n.dot(a);
        let key = [
            (n.x * 1e3).round() as i64,
            (n.y * 1e3).round() as i64,
            (n.z * 1e3).round() as i64,
            (d / extent * 1e4).round() as i64,
        ];
        let e = planes.entry(key).or_insert((0.0, DVec3::ZERO, 0.0));
        let area = len / 2.0;
        e.0 += area;
        e.1 += n * area;
        e.2 += d * area;
    }
    let mut groups: Vec<(f64, DVec3, f64)> = planes.into_values().collect();
    groups.sort_by(|a, b| b.0.total_cmp(&a.0));
    groups.truncate(LAY_FLAT_CANDIDATES);
    let n_points = tris.len() * 3;
    let stride = n_points.div_ceil(LAY_FLAT_POINTS).max(1);
    let points: Vec<DVec3> = corners(tris)
        .step_by(stride)
        .map(|p| DVec3::from(p) - centre)
        .collect();
    let tol = 1e-4 * extent;
    // The supporting planes among the largest: (area, outward normal).
    let mut supporting: Vec<(f64, DVec3)> = Vec::new();
    for (area, nsum, dsum) in groups {
        let n = nsum.normalize_or_zero();
        if n == DVec3::ZERO {
            continue;
        }
        let d = dsum / area;
        let (mut below, mut above) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &points {
            let s = n.dot(*p);
            below = below.min(s);
            above = above.max(s);
        }
        // The facets' side of the part: outward normal n (nothing beyond the plane), or an
        // inside-out mesh's (nothing behind it).
        let outward = if above <= d + tol {
            n
        } else if below >= d - tol {
            -n
        } else {
            continue;
        };
        supporting.push((area, outward));
    }
    // The largest; of faces as large (a box's bottom and top), the one facing down most, so a
    // part already lying flat is not turned over.
    let Some(largest) = supporting.iter().map(|s| s.0).reduce(f64::max) else {
        return (0.0, 0.0);
    };
    supporting
        .iter()
        .filter(|s| s.0 >= largest * (1.0 - 1e-6))
        .min_by(|a, b| a.1.z.total_cmp(&b.1.z))
        .map_or((0.0, 0.0), |s| angles_down(s.1))
}

/// Angles (rotate x first, then y) that turn the unit vector `n` to −z.
pub fn angles_down(n: DVec3) -> (f64, f64) {
    // About x: n to (n.x, 0, −m); then about y: (n.x, 0, −m) to (0, 0, −1).
    let m = (n.y * n.y + n.z * n.z).sqrt();
    let a = if m < 1e-12 { 0.0 } else { (-n.y).atan2(-n.z) };
    let b = n.x.atan2(m);
    let clean = |r: f64| {
        let d = r.to_degrees();
        // Exact right angles stay exact (the trig of the transform is exact there).
        let q = (d / 90.0).round();
        if (d - q * 90.0).abs() < 1e-9 {
            q * 90.0 + 0.0
        } else {
            d
        }
    };
    (clean(a), clean(b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::rotation;

    #[test]
    fn angles_turn_normals_down() {
        for n in [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::new(-0.7, 0.1, -0.2).normalize(),
        ] {
            let (a, b) = angles_down(n);
            let r = rotation([a, b, 0.0]);
            let down = r * n;
            assert!(
                (down - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12,
                "{n} → {down}"
            );
        }
    }
}
