//! Orientation (docs/spec.md "Orientation"): the rotation of a part that needs the least support
//! by the overhang rule, judged from its facets, not from a slice.
//!
//! A candidate is a direction of the model that is turned down (−z): each of the mesh's
//! largest flat faces (facets clustered by normal), the model's six axes and the six axes of
//! the part's current orientation (its rotations by right angles about x and y; a turn
//! about z changes neither the area nor the height, so the 24 right-angle orientations are 6
//! directions). For each, the part is rotated and scaled as it would be sliced, and the
//! *unsupported area* is the area, projected on the plate, of the facets that face down more
//! steeply than the rule allows: unit normal n_z < −[`overhang_face_normal_z`] (the same
//! threshold as the page's 3D tint, from `overhang_limit`, B and H). Facets lying on the plate
//! (every corner within half a layer of the bottom) rest on it and do not count. The least
//! area wins; of areas within [`TIE_MM2`] of it, the lowest height.
//!
//! Cost: one pass over the facets per candidate (at most [`MAX_FACE_CANDIDATES`] faces + 12
//! axes), on all cores; 3DBenchy's 225k facets take a few tens of ms (`benches/orient.sh`).

use crate::base::geom::{DMat3, DVec3};
use crate::base::parallel::par_map;
use crate::base::settings::Settings;
use crate::model::layout::angles_down;
use crate::model::mesh::rotation;
use crate::support::overhang_face_normal_z;
use serde::Serialize;

/// Unsupported areas this close (mm²) count as equal: far below a droplet's footprint.
pub const TIE_MM2: f64 = 1e-3;

/// Most flat faces (clusters of facets by normal, largest first) tried as the face down.
pub const MAX_FACE_CANDIDATES: usize = 32;

/// One orientation and its figures.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Orientation {
    /// The part's rotation, degrees (about x, then y, then z).
    pub rotate_x: f64,
    pub rotate_y: f64,
    pub rotate_z: f64,
    /// Projected area of the facets that overhang by the rule, mm².
    pub unsupported_area: f64,
    /// The part's height in this orientation, mm.
    pub height: f64,
}

/// The candidates of a part, best first, and its current orientation's figures.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Orientations {
    pub current: Orientation,
    /// Every distinct candidate evaluated, best first (the first is the choice; the current
    /// orientation is one of them, so the first is never worse).
    pub candidates: Vec<Orientation>,
}

impl Orientations {
    /// The choice: the best candidate.
    pub fn best(&self) -> Orientation {
        self.candidates[0]
    }
}

/// A facet as the evaluation needs it: its corners and its normal × 2 area.
struct Facet {
    corners: [DVec3; 3],
    normal2: DVec3,
}

/// The orientations of a part of `tris` (model coordinates) now rotated by `rotate` and scaled
/// by `scale` (the part's scale times its shrinkage compensation), by the rule of `settings`.
/// `None` for a part without a facet of any area.
pub fn orient(
    tris: &[[[f32; 3]; 3]],
    rotate: [f64; 3],
    scale: [f64; 3],
    settings: &Settings,
) -> Option<Orientations> {
    let mut facets: Vec<Facet> = Vec::with_capacity(tris.len());
    let mut volume6 = 0.0;
    for t in tris {
        let corners = t.map(|p| DVec3::from(p.map(f64::from)));
        let normal2 = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        if !normal2.is_finite() || normal2 == DVec3::ZERO {
            continue;
        }
        volume6 += corners[0].dot(corners[1].cross(corners[2]));
        facets.push(Facet { corners, normal2 });
    }
    if facets.is_empty() {
        return None;
    }
    // An inside-out mesh: its normals point in.
    if volume6 < 0.0 {
        for f in &mut facets {
            f.normal2 = -f.normal2;
        }
    }
    let current_r = rotation(rotate);
    let mut downs: Vec<DVec3> = Vec::new();
    let mut add = |d: DVec3| {
        let d = d.normalize_or_zero();
        if d != DVec3::ZERO && !downs.iter().any(|e| e.dot(d) > 1.0 - 1e-9) {
            downs.push(d);
        }
    };
    // The current orientation first, so that it wins ties.
    add(current_r.transpose() * DVec3::NEG_Z);
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        for d in [axis, -axis] {
            add(current_r.transpose() * d);
            add(d);
        }
    }
    for n in largest_faces(&facets) {
        add(n);
    }
    let threshold = overhang_face_normal_z(settings);
    let half_layer = settings.layer_height / 2.0;
    let scale = DVec3::from(scale);
    let candidates: Vec<Orientation> = par_map(downs.len(), &|i| {
        // The current orientation keeps its rotation; another turns d down, keeping rotate_z.
        let d = downs[i];
        let (rx, ry) = if i == 0 {
            (rotate[0], rotate[1])
        } else {
            let (a, b) = angles_down(d);
            // A half turn is written 180, not −180.
            (if a == -180.0 { 180.0 } else { a }, b)
        };
        let r = rotation([rx, ry, rotate[2]]);
        let (area, height) = evaluate(&facets, r, scale, threshold, half_layer);
        Orientation {
            rotate_x: rx,
            rotate_y: ry,
            rotate_z: rotate[2],
            unsupported_area: area,
            height,
        }
    });
    let current = candidates[0];
    // The least area wins; of the areas within TIE_MM2 of it, the lowest height (the sort is
    // stable: of equal figures the earlier, the current orientation first).
    let least = candidates
        .iter()
        .map(|c| c.unsupported_area)
        .fold(f64::INFINITY, f64::min);
    let key = |c: &Orientation| {
        if c.unsupported_area <= least + TIE_MM2 {
            (0, c.height, 0.0)
        } else {
            (1, c.unsupported_area, c.height)
        }
    };
    let mut sorted = candidates;
    sorted.sort_by(|a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0)
            .then(ka.1.total_cmp(&kb.1))
            .then(ka.2.total_cmp(&kb.2))
    });
    Some(Orientations {
        current,
        candidates: sorted,
    })
}

/// The orientations of part `p` of `model` (a job's part: its rotation, scale and its unit's
/// shrinkage compensation as sliced) by the rule of `settings`.
pub fn orient_part(
    model: &crate::model::models::Model,
    p: &crate::model::spec::PartSpec,
    settings: &Settings,
) -> Result<Orientations, crate::base::error::Error> {
    let tris = model.triangles(p.item)?;
    let placement = p.placement([0.0, 0.0], settings);
    orient(&tris, placement.rotate, placement.scale, settings).ok_or_else(|| {
        crate::base::error::Error::NothingToPrint(
            "the part has no facet of any area: there is nothing to orient".into(),
        )
    })
}

/// (unsupported area, height) of the facets rotated by `r` and scaled by `scale`.
fn evaluate(
    facets: &[Facet],
    r: DMat3,
    scale: DVec3,
    threshold: f64,
    half_layer: f64,
) -> (f64, f64) {
    // Heights: the third row of the rotation, scaled.
    let row = r.row(2) * scale.z;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for f in facets {
        for c in &f.corners {
            let z = row.dot(*c);
            lo = lo.min(z);
            hi = hi.max(z);
        }
    }
    let inverse = DVec3::ONE / scale;
    let mut area2 = 0.0;
    for f in facets {
        // The normal of the scaled facet: the rotated normal divided by the scale.
        let n = r * f.normal2 * inverse;
        let len = n.length();
        if len == 0.0 || n.z >= -threshold * len {
            continue;
        }
        if f.corners.iter().all(|c| row.dot(*c) <= lo + half_layer) {
            continue;
        }
        // Projected area: |rotated normal z| × the scale in x and y (× 2; a mirrored axis,
        // a negative scale, mirrors no area).
        area2 += (r * f.normal2).z.abs() * (scale.x * scale.y).abs();
    }
    (area2 / 2.0, hi - lo)
}

/// The normals of the largest flat faces: facets clustered by normal (within about 0.3°),
/// largest area first, at most [`MAX_FACE_CANDIDATES`].
fn largest_faces(facets: &[Facet]) -> Vec<DVec3> {
    use std::collections::HashMap;
    let mut clusters: HashMap<[i32; 3], (f64, DVec3)> = HashMap::new();
    for f in facets {
        let len = f.normal2.length();
        let n = f.normal2 / len;
        let key = [n.x, n.y, n.z].map(|x| (x * 200.0).round() as i32);
        let e = clusters.entry(key).or_insert((0.0, DVec3::ZERO));
        e.0 += len;
        e.1 += f.normal2;
    }
    let mut all: Vec<(f64, DVec3)> = clusters.into_values().collect();
    all.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.x.total_cmp(&b.1.x)));
    all.into_iter()
        .take(MAX_FACE_CANDIDATES)
        .map(|(_, n)| n.normalize_or_zero())
        .collect()
}
