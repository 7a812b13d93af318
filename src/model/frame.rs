//! An instance's transform ([`Frame`]: rotation, scale, the turn on the plate) and one copy of
//! a part on the plate ([`Instance`]): what the arrangement, the plate rule and the import
//! share.

use crate::base::geom::{DMat3, DVec3};
use crate::base::steps::{self, Budget};
use crate::model::mesh::{Placement, rot, rotation};
use serde::{Deserialize, Serialize};

/// An instance's transform before its last move: the rotation and scale of [`Placement`],
/// the bounding box after them (`min1`, moved to the origin, and `max1`), the rotation on the
/// plate and the bounding box that gives (`qmin`, `qmax`; `qmin.z` = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub rotation: DMat3,
    pub scale: DVec3,
    pub min1: DVec3,
    pub max1: DVec3,
    pub angle: DMat3,
    pub qmin: DVec3,
    pub qmax: DVec3,
}

impl Frame {
    /// The frame of the part's points under `p` (its `place` is not used): `corners(item)` of
    /// every item in order (a vertex, or a triangle's three corners). The same arithmetic as
    /// [`crate::model::mesh::Mesh::place`], so `qmin + place` is exactly the placed mesh's
    /// bounding box. Each pass runs in runs of items ([`steps::runs`]: the page's engine compiles
    /// the later runs well).
    pub fn of<T, const K: usize>(
        items: &[T],
        corners: impl Fn(&T) -> [[f64; 3]; K],
        p: &Placement,
    ) -> Option<Frame> {
        steps::now(Frame::of_in_steps(items, corners, p, &steps::UNLIMITED))
    }

    /// [`Frame::of`] in resumable steps ([`steps::runs`]).
    pub async fn of_in_steps<T, const K: usize>(
        items: &[T],
        corners: impl Fn(&T) -> [[f64; 3]; K],
        p: &Placement,
        b: &Budget,
    ) -> Option<Frame> {
        if items.is_empty() || K == 0 {
            return None;
        }
        let r = rotation(p.rotate);
        let scale = DVec3::from(p.scale);
        let step1 = |v: [f64; 3]| r * DVec3::from(v) * scale;
        let (mut min1, mut max1) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        steps::runs(items.len(), b, &mut |run| {
            for v in items[run].iter().flat_map(&corners) {
                let q = step1(v);
                min1 = min1.min(q);
                max1 = max1.max(q);
            }
        })
        .await;
        let angle = rot(2, p.place_angle);
        let (mut qmin, mut qmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        steps::runs(items.len(), b, &mut |run| {
            for v in items[run].iter().flat_map(&corners) {
                let q = angle * (step1(v) - min1);
                qmin = qmin.min(q);
                qmax = qmax.max(q);
            }
        })
        .await;
        Some(Frame {
            rotation: r,
            scale,
            min1,
            max1,
            angle,
            qmin,
            qmax,
        })
    }

    /// The 4×4 matrix (column-major) of the whole transform with the final move `place`:
    /// model coordinates → plate coordinates.
    pub fn matrix(&self, place: [f64; 2]) -> [f64; 16] {
        let l = self.angle * DMat3::from_diagonal(self.scale) * self.rotation;
        let t = self.angle * (-self.min1) + DVec3::new(place[0], place[1], 0.0);
        let c = l.to_cols_array();
        [
            c[0], c[1], c[2], 0.0, c[3], c[4], c[5], 0.0, c[6], c[7], c[8], 0.0, t.x, t.y, t.z, 1.0,
        ]
    }
}

/// Which copy of which part: how a job names one of its instances.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify))]
pub struct InstanceId {
    /// The part's index in the job's `parts` (from 0).
    pub part: usize,
    /// The copy's index (from 0).
    pub copy: usize,
}

/// One copy of a part on the plate.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct Instance {
    /// Which part, which copy (`part`, `copy` in the JSON).
    #[serde(flatten)]
    pub id: InstanceId,
    /// How many copies the part has.
    pub copies: usize,
    /// The name the page and the header show: the part's `name`, else its name in its file
    /// (one line, at most [`crate::model::spec::MAX_NAME_CHARS`] characters).
    pub name: String,
    /// The part's `file` as the job names it (one line, shortened as `name`).
    pub file: String,
    /// The 3MF build item (from 0), `None`: the whole file.
    pub item: Option<usize>,
    /// For a 3MF item, the object it refers to.
    pub object: Option<String>,
    /// The part's `rotate_x`, `rotate_y`, `rotate_z`: degrees about x, then y, then z.
    pub rotate: [f64; 3],
    /// The part's `scale_x`, `scale_y`, `scale_z` (1: the file's size; before the shrinkage
    /// compensation).
    pub scale: [f64; 3],
    /// Mirrored along the plate's x, y, z (the part's `mirror_*`).
    #[serde(default)]
    pub mirror: [bool; 3],
    /// The part's `place_angle`: degrees about z on the plate, after the rotation and scale.
    pub place_angle: f64,
    /// Placed by the job (`place_x`, `place_y`) rather than arranged.
    pub placed: bool,
    /// The final move: `place_x`, `place_y` when placed; else where the arrangement put the
    /// bounding box minimum.
    pub at: [f64; 2],
    /// The discharge unit that prints it (the part's `unit`, 0 … `units` − 1).
    pub unit: u8,
    /// Column-major 4×4: the part's model coordinates (after import) → plate coordinates, the
    /// exact transform applied before slicing.
    pub matrix: [f64; 16],
    /// The placed copy's bounding box minimum on the plate, mm (its z is 0: every part
    /// stands on the plate).
    pub min: [f64; 3],
    /// The placed copy's bounding box maximum on the plate, mm (its z: the part's height).
    pub max: [f64; 3],
    /// The part's size (mm) along the axes its `scale_*` and `mirror_*` act on: after the
    /// rotation, the scale and the shrinkage compensation, before `place_angle` (the page's
    /// size fields: scale_x × size_x / this = a part size_x wide).
    #[serde(default)]
    pub size: [f64; 3],
    /// The final move given to [`crate::model::mesh::Mesh::place`].
    #[serde(skip)]
    pub shift: [f64; 2],
}

impl Instance {
    /// Puts it where the final move `at` takes it, its mesh moved by `shift` (its part's
    /// frame `f`): the matrix and the bounds on the plate follow.
    pub fn place(&mut self, f: &Frame, at: [f64; 2], shift: [f64; 2]) {
        self.at = at;
        self.shift = shift;
        self.matrix = f.matrix(shift);
        self.min = [f.qmin.x + shift[0], f.qmin.y + shift[1], f.qmin.z];
        self.max = [f.qmax.x + shift[0], f.qmax.y + shift[1], f.qmax.z];
    }
}
