//! The imported files of a build job in the page's job worker ([`Models`]).

use super::{js_error, to_js};
use crate::base::error::Error;
use crate::base::steps::{Budget, Stepped};
use crate::model::models::Model;
use crate::model::spec::{self as job, JobSpec};
use crate::model::{display, layout};
use js_sys::{Float32Array, Uint8Array};
use serde::Serialize;
use std::rc::Rc;
use wasm_bindgen::prelude::*;

pub(super) fn job_of(value: JsValue) -> Result<JobSpec, JsValue> {
    let value: serde_json::Value = serde_wasm_bindgen::from_value(value).map_err(|e| {
        js_error(Error::Job(format!(
            "the job is not a plain object {{settings, parts}}: {e}"
        )))
    })?;
    JobSpec::from_value(value).map_err(js_error)
}

/// Reads a `File` in the worker (`FileReaderSync`).
pub(super) fn read_file(file: &web_sys::File) -> Result<Vec<u8>, JsValue> {
    read_blob(file, &file.name())
}

/// Reads a `Blob` (a file `name` or a slice of it) in the worker (`FileReaderSync`).
fn read_blob(blob: &web_sys::Blob, name: &str) -> Result<Vec<u8>, JsValue> {
    let unreadable = |e: JsValue| {
        js_error(Error::Import(format!(
            "the browser could not read {}: {}",
            job::clean_name(name),
            describe(&e)
        )))
    };
    let reader = web_sys::FileReaderSync::new().map_err(unreadable)?;
    let buffer = reader.read_as_array_buffer(blob).map_err(unreadable)?;
    Ok(Uint8Array::new(&buffer).to_vec())
}

/// A thrown JS value as text.
fn describe(e: &JsValue) -> String {
    e.as_string()
        .or_else(|| e.dyn_ref::<js_sys::Error>().map(|e| e.message().into()))
        .unwrap_or_else(|| format!("{e:?}"))
}

/// The imported files of a build job, kept in one worker: the page adds and removes files,
/// asks for their display meshes, the job's layout and lay-flat angles, and builds the merged
/// job with [`Session::from_models`].
#[wasm_bindgen]
#[derive(Default)]
pub struct Models {
    /// Shared with a preparation in steps while it runs ([`Session::begin`]; a file added or
    /// removed meanwhile leaves the preparation's files as they were).
    pub(super) models: std::sync::Arc<Vec<Model>>,
}

#[wasm_bindgen]
impl Models {
    #[wasm_bindgen(constructor)]
    pub fn new() -> Models {
        Models::default()
    }

    /// Reads and imports a `File` under `name` (the job's key for it; a file of the same name
    /// is replaced). Returns `ModelInfo {name, format, triangles, bounds {min, max}, items:
    /// [{name, triangles, bounds}], warnings, suggested_scale}`.
    #[wasm_bindgen(unchecked_return_type = "ModelInfo")]
    pub fn add(&mut self, file: web_sys::File, name: &str) -> Result<JsValue, JsValue> {
        let bytes = read_file(&file)?;
        self.add_bytes(&bytes, name)
    }

    /// [`Models::add`] from bytes.
    #[wasm_bindgen(unchecked_return_type = "ModelInfo")]
    pub fn add_bytes(&mut self, bytes: &[u8], name: &str) -> Result<JsValue, JsValue> {
        let model = Model::read(bytes, name).map_err(js_error)?;
        self.put(model)
    }

    /// [`Models::add`] in short calls: this call only takes the file; [`Adding::step`] reads
    /// it a slice a call, then imports it a budget of triangles a call (an STL file; an OBJ
    /// or 3MF file in one call) until it returns true; [`Models::finish_add`] adds it. The
    /// same model and info as `add`.
    pub fn begin_add(file: web_sys::File, name: &str) -> Adding {
        Adding::new(name, Some(file), Vec::new())
    }

    /// [`Models::begin_add`] from bytes (tests and Node; copied once into the module).
    pub fn begin_add_bytes(bytes: Vec<u8>, name: &str) -> Adding {
        Adding::new(name, None, bytes)
    }

    /// Adds the file an [`Adding`] imported (a file of the same name is replaced): its
    /// `ModelInfo`, as [`Models::add`]. `internal` if the import has not ended.
    #[wasm_bindgen(unchecked_return_type = "ModelInfo")]
    pub fn finish_add(&mut self, adding: Adding) -> Result<JsValue, JsValue> {
        let model = adding
            .model
            .ok_or_else(|| js_error(Error::Internal("the file's import has not ended".into())))?;
        self.put(model)
    }

    /// Forgets a file; whether it was there.
    pub fn remove(&mut self, name: &str) -> bool {
        let before = self.models.len();
        std::sync::Arc::make_mut(&mut self.models).retain(|m| m.name != name);
        self.models.len() != before
    }

    /// The files' names, in the order they were added.
    #[wasm_bindgen(unchecked_return_type = "string[]")]
    pub fn names(&self) -> Result<JsValue, JsValue> {
        let names: Vec<&str> = self.models.iter().map(|m| m.name.as_str()).collect();
        to_js(&names, "the file names")
    }

    /// A decimated copy of a file's triangles (one build item, or all) for the 3D view, at
    /// most `max_triangles`: 9 floats per triangle, model coordinates in mm. Never sliced.
    pub fn display_mesh(
        &self,
        name: &str,
        item: Option<usize>,
        max_triangles: u32,
    ) -> Result<Float32Array, JsValue> {
        let tris = self.model(name)?.triangles(item).map_err(js_error)?;
        Ok(Float32Array::from(
            &display::display_mesh(&tris, max_triangles as usize)[..],
        ))
    }

    /// Where every copy of every part goes: `Layout {instances: [{part, copy, copies, name,
    /// file, item, object, rotate, scale, mirror, place_angle, placed, at, unit, matrix, min,
    /// max, size}],
    /// bounds, warnings}` (`matrix`: column-major 4×4, model → plate coordinates, exactly
    /// the transform sliced). `job`: `{settings, parts}` as in a job file. Throws
    /// `{kind: "job" | "setting", message, setting?}`.
    #[wasm_bindgen(unchecked_return_type = "Layout")]
    pub fn layout(&self, job: JsValue) -> Result<JsValue, JsValue> {
        let spec = job_of(job)?;
        let layout = layout::layout(&self.models, &spec).map_err(js_error)?;
        to_js(&layout, "the layout")
    }

    /// `{rotate_x, rotate_y}` (degrees) that put a file's (or item's) largest flat face down.
    #[wasm_bindgen(unchecked_return_type = "Angles")]
    pub fn lay_flat(&self, name: &str, item: Option<usize>) -> Result<JsValue, JsValue> {
        let tris = self.model(name)?.triangles(item).map_err(js_error)?;
        let (rotate_x, rotate_y) = layout::lay_flat(&tris);
        #[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
        #[derive(Serialize)]
        struct Angles {
            rotate_x: f64,
            rotate_y: f64,
        }
        to_js(&Angles { rotate_x, rotate_y }, "the angles")
    }

    /// The orientations of `job.parts[part]` (docs/spec.md "Orientation"; its rotation, scale and
    /// unit's shrinkage as sliced, the rule of `job.settings`): `{current, candidates}`, each
    /// `{rotate_x, rotate_y, rotate_z, unsupported_area (mm²), height (mm)}`, the candidates
    /// best first. A job past slicing's triangle bound is refused first, in slicing's words.
    /// Throws `{kind: "job" | "setting", message}`.
    #[wasm_bindgen(unchecked_return_type = "Orientations")]
    pub fn orient(&self, job: JsValue, part: usize) -> Result<JsValue, JsValue> {
        let spec = job_of(job)?;
        let p = spec.parts.get(part).ok_or_else(|| {
            js_error(Error::Job(format!(
                "parts[{part}] asked for, but the job has {} parts",
                spec.parts.len()
            )))
        })?;
        let model = self.model(&p.file)?;
        // Slicing's bound on the whole job, before any work: a part instanced millions of
        // times over would keep the job worker busy for minutes.
        crate::model::models::check_job_triangles(&self.models, &spec).map_err(js_error)?;
        let o = crate::support::orient::orient_part(model, p, &spec.settings)
            .map_err(|e| js_error(layout::at_part(part, e)))?;
        to_js(&o, "the orientations")
    }
}

/// A profile's JSON text (an imported file, or one the page kept) checked: `{name, kind,
/// settings}` with every key of its kind and every value in range. Throws `{kind: "setting",
/// message, setting?}` naming the key.
#[wasm_bindgen(unchecked_return_type = "Profile")]
pub fn check_profile(bytes: &[u8]) -> Result<JsValue, JsValue> {
    let profile = crate::base::settings::Profile::from_bytes(bytes).map_err(js_error)?;
    to_js(&profile, "the profile")
}

impl Models {
    /// Adds `model` in place of a file of its name: its info.
    fn put(&mut self, model: Model) -> Result<JsValue, JsValue> {
        let info = model.info();
        let models = std::sync::Arc::make_mut(&mut self.models);
        models.retain(|m| m.name != model.name);
        models.push(model);
        to_js(&info, "the model info")
    }

    fn model(&self, name: &str) -> Result<&Model, JsValue> {
        self.models.iter().find(|m| m.name == name).ok_or_else(|| {
            js_error(Error::Job(format!(
                "no file named '{}' was added",
                job::clean_name(name)
            )))
        })
    }
}

/// Bytes of the file read a call ([`Adding::step`]): a copy of a few milliseconds.
const READ_BYTES: f64 = 1024.0 * 1024.0;

/// A file being imported in short calls ([`Models::begin_add`]).
#[wasm_bindgen]
pub struct Adding {
    name: String,
    /// The file while it is read, a slice a step.
    file: Option<web_sys::File>,
    bytes: Vec<u8>,
    budget: Rc<Budget>,
    /// The import, once the file is read; `None` again when it ended.
    pass: Option<Stepped<Result<Model, Error>>>,
    /// The model, once imported.
    model: Option<Model>,
}

#[wasm_bindgen]
impl Adding {
    /// Reads the next slice of the file, or imports about `items` triangles of it: true once
    /// the model is imported (then [`Models::finish_add`]). Throws `{kind: "import",
    /// message}` as [`Models::add`] does.
    pub fn step(&mut self, items: u32) -> Result<bool, JsValue> {
        if self.model.is_some() {
            return Ok(true);
        }
        if let Some(file) = &self.file {
            let at = self.bytes.len() as f64;
            let end = file.size().min(at + READ_BYTES);
            if at < end {
                let slice = file.slice_with_f64_and_f64(at, end).map_err(js_error_of)?;
                self.bytes.extend(read_blob(&slice, &self.name)?);
                return Ok(false);
            }
            self.file = None;
        }
        let pass = self.pass.get_or_insert_with(|| {
            let (bytes, name) = (std::mem::take(&mut self.bytes), self.name.clone());
            let b = self.budget.clone();
            Stepped::new(async move { Model::read_in_steps(&bytes, &name, &b).await })
        });
        self.budget.refill(items as usize);
        match pass.step() {
            None => Ok(false),
            Some(read) => {
                self.pass = None;
                self.model = Some(read.map_err(js_error)?);
                Ok(true)
            }
        }
    }
}

impl Adding {
    fn new(name: &str, file: Option<web_sys::File>, bytes: Vec<u8>) -> Adding {
        Adding {
            name: name.to_string(),
            file,
            bytes,
            budget: Rc::new(Budget::new(0)),
            pass: None,
            model: None,
        }
    }
}

/// A `Blob` (a file or a slice of it) method's failure as an import error.
fn js_error_of(e: JsValue) -> JsValue {
    js_error(Error::Import(format!(
        "the browser could not read the file: {}",
        describe(&e)
    )))
}
