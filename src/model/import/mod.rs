//! Import for build jobs (issue #12): a model file → the **parts** of a job.
//!
//! * **STL** ([`crate::model::import::stl::parse`]): one part, the whole file.
//! * **OBJ** ([`obj`]): one part, the whole file. `o`/`g` groups are *not* split into parts:
//!   exporters use groups for materials and smoothing groups of one body, and parts are
//!   arranged on the plate independently (docs/spec.md "Build jobs"), which would tear such a body
//!   apart. Polygon faces are split into triangles (a fan per face).
//! * **3MF** ([`threemf`]): one part per build item (an object referenced by several items
//!   gives several parts), with the item's transform, its components' transforms and the
//!   model's unit applied: the items keep their relative positions.
//!
//! The format is recognised by content: a ZIP (`PK\x03\x04`) is a 3MF package; a file named
//! `*.obj`, or whose first non-comment lines are OBJ statements (`v `, `f `, `o `, …), is an
//! OBJ; everything else goes to the STL reader (which names other formats it recognises).
//!
//! Every input is untrusted: sizes, counts, nesting and instantiation are bounded (see the
//! constants here and in [`threemf`]); nothing panics or runs unbounded on a hostile file.

pub mod obj;
pub mod stl;
pub mod threemf;

use crate::base::error::Error;
use stl::{Format, Triangles};

/// Most triangles a job may have after import, counting every instance (the STL bound).
pub const MAX_TRIANGLES: usize = stl::MAX_TRIANGLES;

/// Largest model file the command-line tool reads (bytes), checked before reading: 6 GiB,
/// the size of an ASCII STL of [`MAX_TRIANGLES`] triangles written with full-precision numbers
/// (about 300 bytes a facet); a binary STL of that many triangles is 1 GB. A file too large to
/// hold that many triangles cannot be a model dropslice accepts.
pub const MAX_FILE_BYTES: u64 = 6 << 30;

/// The identity as a 3×4 affine matrix (see [`Part::transform_applied`]).
pub const IDENTITY: [[f64; 4]; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// One part of a build job: a triangle soup in millimetres, already placed as the file
/// placed it (for 3MF: build item, components and unit applied).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// A name for messages and the header: the 3MF object's `name`, else the file name
    /// (with `object <id>` for 3MF).
    pub name: String,
    /// Triangles in mm, three float32 corners each, in the file's vertex order.
    pub triangles: Triangles,
    /// The transform the file applied to this part, in mm, as rows of an affine map with
    /// column vectors: `x' = r[0][0]·x + r[0][1]·y + r[0][2]·z + r[0][3]`, etc. For 3MF this
    /// is the build item's transform (with the model's unit applied to its translation;
    /// components' transforms are applied to the triangles but not listed here); identity
    /// for STL and OBJ.
    pub transform_applied: [[f64; 4]; 3],
    /// For 3MF: the object the build item refers to, `"<id>"` (or `"<model part>#<id>"`
    /// when the item names another model part through the production extension's
    /// `p:path`). `None` for STL and OBJ.
    pub source_object: Option<String>,
}

/// What a file is, decided from its content (and, for OBJ, its name).
pub fn detect(bytes: &[u8], file_name: &str) -> Format {
    if bytes.starts_with(b"PK\x03\x04") {
        return Format::ThreeMf;
    }
    let lower = file_name.to_ascii_lowercase();
    if lower.ends_with(".obj") || (!lower.ends_with(".stl") && obj::looks_like_obj(bytes)) {
        return Format::Obj;
    }
    // STL: binary or ASCII is decided by the STL reader.
    Format::Binary
}

/// Reads a model file into the parts of a job. See the module documentation.
pub fn read_parts(bytes: &[u8], file_name: &str) -> Result<Vec<Part>, Error> {
    let stem = stem(file_name);
    match detect(bytes, file_name) {
        Format::ThreeMf => threemf::parse(bytes, &stem),
        Format::Obj => Ok(vec![Part {
            name: stem,
            triangles: obj::parse(bytes)?,
            transform_applied: IDENTITY,
            source_object: None,
        }]),
        Format::Binary | Format::Ascii => {
            let (triangles, _) = stl::parse(bytes)?;
            Ok(vec![Part {
                name: stem,
                triangles,
                transform_applied: IDENTITY,
                source_object: None,
            }])
        }
    }
}

/// All parts of a file as one triangle list (3MF items keep their relative positions), and
/// the format it was read as — for the single-mesh pipeline.
pub fn read_merged(bytes: &[u8], file_name: &str) -> Result<(Triangles, Format), Error> {
    match detect(bytes, file_name) {
        Format::Binary | Format::Ascii => stl::parse(bytes),
        format => {
            let parts = read_parts(bytes, file_name)?;
            let n: usize = parts.iter().map(|p| p.triangles.len()).sum();
            let mut all = Triangles::with_capacity(n);
            for p in parts {
                all.extend(p.triangles);
            }
            Ok((all, format))
        }
    }
}

/// The file name without folders and extension (`"part"` if nothing is left).
pub fn stem(file_name: &str) -> String {
    let base = file_name.rsplit(['/', '\\']).next().unwrap_or(file_name);
    let s = match base.rfind('.') {
        Some(i) if i > 0 => &base[..i],
        _ => base,
    };
    if s.is_empty() {
        "part".into()
    } else {
        s.into()
    }
}
