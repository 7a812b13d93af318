//! 3MF transforms: affine maps of row vectors (p' = p·M + t) and the `transform` attribute.

use super::err;
use super::xml::number;
use crate::base::error::Error;

/// An affine map of row vectors: p' = p·m + t, in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Affine {
    m: [[f64; 3]; 3],
    t: [f64; 3],
}

impl Affine {
    pub(super) const ID: Affine = Affine {
        m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    /// The image of `p`.
    pub(super) fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let mut o = self.t;
        for (j, oj) in o.iter_mut().enumerate() {
            *oj += p[0] * self.m[0][j] + p[1] * self.m[1][j] + p[2] * self.m[2][j];
        }
        o
    }

    /// `self` first, then `then`.
    pub(super) fn then(&self, then: &Affine) -> Affine {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| self.m[i][k] * then.m[k][j]).sum();
            }
        }
        Affine {
            m,
            t: then.apply(self.t),
        }
    }

    /// Rows of the column-vector form (see [`crate::model::import::Part::transform_applied`]).
    pub(super) fn rows(&self) -> [[f64; 4]; 3] {
        let mut r = [[0.0; 4]; 3];
        for (j, row) in r.iter_mut().enumerate() {
            *row = [self.m[0][j], self.m[1][j], self.m[2][j], self.t[j]];
        }
        r
    }
}

/// A 3MF transform: 12 numbers, row vectors, translation last; its translation scaled by the
/// model's unit.
pub(super) fn transform(v: Option<String>, scale: f64, part: &str) -> Result<Affine, Error> {
    let Some(v) = v else { return Ok(Affine::ID) };
    let nums: Vec<&str> = v.split_ascii_whitespace().collect();
    if nums.len() != 12 {
        return Err(err(format!(
            "the 3MF part '/{part}' has a transform with {} numbers instead of 12; the file is damaged",
            nums.len()
        )));
    }
    let mut a = Affine::ID;
    for (k, s) in nums.iter().enumerate() {
        let x = number(s, "a transform", part)?;
        if k < 9 {
            a.m[k / 3][k % 3] = x;
        } else {
            a.t[k - 9] = x * scale;
        }
    }
    Ok(a)
}
