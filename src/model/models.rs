//! The files of a job as read ([`Model`]: a name, its format and its parts), what a file
//! holds for the page ([`ModelInfo`]) and the models of a job's parts ([`models_of`]).

use crate::base::error::Error;
use crate::base::steps::{self, Budget};
use crate::model::import::stl::{self, Format};
use crate::model::import::{self, Part};
use crate::model::mesh::Bounds;
use crate::model::spec::{JobSpec, clean_name};
use crate::model::weld::keeps_facet;
use serde::Serialize;
use std::borrow::Cow;

/// One imported model file of a job.
#[derive(Clone, Debug)]
pub struct Model {
    /// The job's key for the file (its name).
    pub name: String,
    pub format: Format,
    /// Its parts: one for STL and OBJ, one per build item for 3MF.
    pub parts: Vec<Part>,
}

impl Model {
    /// Imports a file (see [`import::read_parts`]).
    pub fn read(bytes: &[u8], name: &str) -> Result<Model, Error> {
        steps::now(Model::read_in_steps(bytes, name, &steps::UNLIMITED))
    }

    /// [`Model::read`] as a pass of `budget`'s budget: an STL file in runs of triangles
    /// ([`stl::parse_in_steps`]: the page's short calls), an OBJ or 3MF file at once. The
    /// same model, or the same refusal.
    pub async fn read_in_steps(bytes: &[u8], name: &str, budget: &Budget) -> Result<Model, Error> {
        let format = match import::detect(bytes, name) {
            Format::Binary | Format::Ascii => {
                let (triangles, format) = stl::parse_in_steps(bytes, budget).await?;
                return Ok(Model {
                    name: name.to_string(),
                    format,
                    parts: vec![Part {
                        name: import::stem(name),
                        triangles,
                        transform_applied: import::IDENTITY,
                        source_object: None,
                    }],
                });
            }
            f => f,
        };
        let parts = import::read_parts(bytes, name)?;
        if parts.is_empty() {
            return Err(Error::Import(format!("{} has no parts", clean_name(name))));
        }
        Ok(Model {
            name: name.to_string(),
            format,
            parts,
        })
    }

    /// The triangles of one item, or of all (in the file's order: as [`import::read_merged`]).
    pub fn triangles(&self, item: Option<usize>) -> Result<Cow<'_, [[[f32; 3]; 3]]>, Error> {
        match item {
            Some(i) => self
                .parts
                .get(i)
                .map(|p| Cow::Borrowed(&p.triangles[..]))
                .ok_or_else(|| {
                    Error::Job(format!(
                        "{} has {} build item{}; item {i} does not exist (items count from 0)",
                        clean_name(&self.name),
                        self.parts.len(),
                        if self.parts.len() == 1 { "" } else { "s" }
                    ))
                }),
            None if self.parts.len() == 1 => Ok(Cow::Borrowed(&self.parts[0].triangles[..])),
            None => {
                let n: usize = self.parts.iter().map(|p| p.triangles.len()).sum();
                let mut all = Vec::with_capacity(n);
                for p in &self.parts {
                    all.extend_from_slice(&p.triangles);
                }
                Ok(Cow::Owned(all))
            }
        }
    }

    /// A name for an item (or the whole file).
    pub fn part_name(&self, item: Option<usize>) -> String {
        match item {
            Some(i) if i < self.parts.len() => self.parts[i].name.clone(),
            _ => import::stem(&self.name),
        }
    }
}

/// What a file holds, for the page: `{name, format, triangles, bounds, items, warnings,
/// suggested_scale}`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct ModelInfo {
    /// The file's name (one line, at most [`crate::model::spec::MAX_NAME_CHARS`] characters).
    pub name: String,
    /// Binary or ASCII STL, OBJ or 3MF, as the file's bytes (for OBJ also its name) say.
    pub format: Format,
    /// The triangles of all its items as read, before welding (degenerate ones included).
    pub triangles: usize,
    /// In the file's coordinates (mm, after its units and 3MF transforms).
    pub bounds: Bounds,
    /// The 3MF build items (one item for STL and OBJ).
    pub items: Vec<ItemInfo>,
    /// Sentences for the page: a size that suggests other units than mm (see
    /// `suggested_scale`); empty when nothing looks wrong.
    pub warnings: Vec<String>,
    /// See [`crate::model::prepare::suggested_scale`].
    pub suggested_scale: Option<f64>,
}

/// One build item of a [`ModelInfo`].
#[derive(Clone, Debug, PartialEq, Serialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct ItemInfo {
    /// The item's name in its file (an STL's or OBJ's: the file's stem), one line.
    pub name: String,
    /// Its triangles as read, before welding.
    pub triangles: usize,
    /// Its triangles' bounding box in the file's coordinates, mm.
    pub bounds: Bounds,
}

/// The bounding box of triangles.
pub fn bounds_of(tris: &[[[f32; 3]; 3]]) -> Bounds {
    let mut b = Bounds::EMPTY;
    crate::base::parallel::in_runs(tris.len(), &mut |r| {
        for p in corners(&tris[r]) {
            b.grow(p, p);
        }
    });
    b
}

impl Model {
    /// What the file holds.
    pub fn info(&self) -> ModelInfo {
        let items: Vec<ItemInfo> = self
            .parts
            .iter()
            .map(|p| ItemInfo {
                name: clean_name(&p.name),
                triangles: p.triangles.len(),
                bounds: bounds_of(&p.triangles),
            })
            .collect();
        let mut bounds = Bounds::EMPTY;
        for i in &items {
            bounds.grow(i.bounds.min, i.bounds.max);
        }
        let size = bounds.size();
        let suggested_scale = crate::model::prepare::suggested_scale(&size);
        let warnings = crate::model::prepare::scale_warning(&size)
            .map(|(text, _)| text)
            .into_iter()
            .collect();
        ModelInfo {
            name: clean_name(&self.name),
            format: self.format,
            triangles: items.iter().map(|i| i.triangles).sum(),
            bounds,
            items,
            warnings,
            suggested_scale,
        }
    }
}

/// The models of `spec`'s parts, in its order, found by file name.
pub fn models_of<'a>(models: &'a [Model], spec: &JobSpec) -> Result<Vec<&'a Model>, Error> {
    spec.parts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            models.iter().find(|m| m.name == p.file).ok_or_else(|| {
                Error::Job(format!(
                    "parts[{i}].file: '{}' is not among the job's files ({})",
                    clean_name(&p.file),
                    models
                        .iter()
                        .map(|m| clean_name(&m.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
        })
        .collect()
}

/// The corners of a list of triangles as f64 points.
pub fn corners(tris: &[[[f32; 3]; 3]]) -> impl Iterator<Item = [f64; 3]> + Clone + '_ {
    tris.iter().flatten().map(|p| p.map(f64::from))
}

/// Most triangles a job holds in all (its parts' welded facets × copies): as many as one file
/// may hold.
pub const MAX_JOB_TRIANGLES: usize = import::MAX_TRIANGLES;

/// The refusal of a job of more than [`MAX_JOB_TRIANGLES`] triangles (slicing's and orient's).
pub fn too_many_triangles() -> Error {
    Error::Job(format!(
        "the job has more than {MAX_JOB_TRIANGLES} triangles in all (parts × copies); print fewer copies or simplify the models"
    ))
}

/// Refuses, before any work on them, a job whose parts hold more than [`MAX_JOB_TRIANGLES`]
/// facets in all: each part's facets as [`Mesh::weld`](crate::model::mesh::Mesh::weld) keeps
/// them (its triangles whose corners differ) × its copies, the count
/// [`Job::from_models`](crate::pipeline::Job) refuses, found without welding. The triangles
/// as read bound it from above, so they are only counted when those exceed the bound; then
/// each file's item once, stopping at the bound.
pub fn check_job_triangles(models: &[Model], spec: &JobSpec) -> Result<(), Error> {
    let by_part = models_of(models, spec)?;
    // (an item that does not exist counts none: the caller's own reading of it says so)
    fn read(m: &Model, item: Option<usize>) -> &[Part] {
        match item {
            Some(i) => m.parts.get(i..=i).unwrap_or(&[]),
            None => &m.parts,
        }
    }
    let mut upper = 0usize;
    for (p, m) in spec.parts.iter().zip(&by_part) {
        let n: usize = read(m, p.item).iter().map(|q| q.triangles.len()).sum();
        upper = upper.saturating_add(n.saturating_mul(p.copies as usize));
    }
    if upper <= MAX_JOB_TRIANGLES {
        return Ok(());
    }
    let mut counted: Vec<(&str, Option<usize>, usize)> = Vec::new();
    let mut total = 0usize;
    for (p, m) in spec.parts.iter().zip(&by_part) {
        let facets = match counted
            .iter()
            .find(|(name, item, _)| *name == m.name && *item == p.item)
        {
            Some(&(_, _, n)) => n,
            None => {
                let mut n = 0usize;
                for q in read(m, p.item) {
                    // In chunks on all cores (natively): 20 M triangles are read once.
                    const CHUNK: usize = 1 << 20;
                    let chunks: Vec<&[[[f32; 3]; 3]]> = q.triangles.chunks(CHUNK).collect();
                    let kept = crate::base::parallel::par_map(chunks.len(), &|c| {
                        chunks[c].iter().filter(|t| keeps_facet(t)).count()
                    });
                    n += kept.iter().sum::<usize>();
                }
                counted.push((&m.name, p.item, n));
                n
            }
        };
        total = total.saturating_add(facets.saturating_mul(p.copies as usize));
        if total > MAX_JOB_TRIANGLES {
            return Err(too_many_triangles());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ASCII STL of one triangle `size` mm across.
    fn triangle(size: f64) -> Vec<u8> {
        format!(
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex {size} 0 0\nvertex 0 {size} 1\nendloop\nendfacet\nendsolid t\n"
        )
        .into_bytes()
    }

    #[test]
    fn a_files_info_warns_of_a_size_in_inches_or_micrometres_without_the_command_line() {
        let info = |size: f64| Model::read(&triangle(size), "t.stl").unwrap().info();
        let inches = info(1.0);
        assert_eq!(inches.suggested_scale, Some(25.4));
        assert_eq!(
            inches.warnings,
            ["the part is only 1.000 mm across: if the file is in inches, scale it by 25.4"]
        );
        let micrometres = info(3000.0);
        assert_eq!(micrometres.suggested_scale, Some(0.001));
        assert_eq!(
            micrometres.warnings,
            ["the part is 3000 mm across: if the file is in micrometres, scale it by 0.001"]
        );
        let mm = info(20.0);
        assert_eq!((mm.suggested_scale, mm.warnings.len()), (None, 0));
        assert_eq!((mm.triangles, mm.items.len()), (1, 1));
    }
}
