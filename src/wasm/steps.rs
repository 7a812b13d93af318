//! The page's short calls that are objects of their own: a job being prepared
//! ([`Preparing`]), a prepared job being written as bytes ([`Writing`]) or taken from them
//! ([`Taking`]), and the buffers outside the module's memory they write and read
//! ([`JsBytes`], [`JsDraft`]). [`super::Session`] makes them (`begin`, `begin_prepared`,
//! `begin_take`) and takes their results; each step works through about the number of items
//! the page asks for (docs/page.md, *Short calls*).

use super::js_error;
use crate::Job;
use crate::base::error::Error;
use crate::base::stages::{self, Stage};
use crate::base::steps::{Budget, Stepped};
use js_sys::Uint8Array;
use wasm_bindgen::prelude::*;

/// A buffer outside the module's memory, as the hand-off's sink and source.
pub(super) struct JsBytes(pub(super) Uint8Array);

impl crate::pipeline::handoff::Sink for JsBytes {
    fn write(&mut self, at: usize, bytes: &[u8]) {
        self.0
            .subarray(at as u32, (at + bytes.len()) as u32)
            .copy_from(bytes);
    }
}

impl crate::pipeline::handoff::Source for JsBytes {
    fn size(&self) -> usize {
        self.0.length() as usize
    }
    fn read(&self, at: usize, out: &mut [u8]) {
        self.0
            .subarray(at as u32, (at + out.len()) as u32)
            .copy_to(out);
    }
}

/// The draft's buffer outside the module's memory, written in steps
/// ([`Session::begin_drafted`]); handed to `out` once whole.
pub(super) struct JsDraft {
    pub(super) buf: Option<JsBytes>,
    pub(super) out: std::rc::Rc<std::cell::RefCell<Option<Uint8Array>>>,
}

impl crate::pipeline::DraftSink for JsDraft {
    fn open(&mut self, size: usize) {
        self.buf = Some(JsBytes(Uint8Array::new_with_length(size as u32)));
    }
    fn as_sink(&mut self) -> &mut dyn crate::pipeline::handoff::Sink {
        self.buf
            .get_or_insert_with(|| JsBytes(Uint8Array::new_with_length(0)))
    }
    fn done(&mut self) {
        *self.out.borrow_mut() = self.buf.take().map(|b| b.0);
    }
}

/// The prepared job being written as bytes in short calls ([`Session::begin_prepared`]).
#[wasm_bindgen]
pub struct Writing {
    pub(super) budget: std::rc::Rc<Budget>,
    /// `None` once written.
    pub(super) pass: Option<Stepped<Uint8Array>>,
    pub(super) bytes: Option<Uint8Array>,
}

#[wasm_bindgen]
impl Writing {
    /// Writes about `items` items (vertices, facets, the index' entries): true once every
    /// byte is written (then [`Writing::take`]).
    pub fn step(&mut self, items: u32) -> bool {
        if let Some(pass) = self.pass.as_mut() {
            self.budget.refill(items as usize);
            self.bytes = pass.step();
            if self.bytes.is_some() {
                self.pass = None;
            }
        }
        self.pass.is_none()
    }

    /// The bytes once written, as [`Session::prepared`] gives them (then `undefined`).
    pub fn take(&mut self) -> Option<Uint8Array> {
        self.bytes.take()
    }
}

/// A job being prepared in short calls ([`Session::begin`]).
#[wasm_bindgen]
pub struct Preparing {
    pub(super) prep: crate::pipeline::Preparation,
    /// The job, once the last step made it.
    pub(super) job: Option<Job>,
    /// The draft's bytes ([`Session::begin_drafted`]), once made and until taken.
    pub(super) draft: std::rc::Rc<std::cell::RefCell<Option<Uint8Array>>>,
}

#[wasm_bindgen]
impl Preparing {
    /// Works through about `items` items of the preparation (facets, corners, vertices: the
    /// page picks a number that keeps a call short): true once the job is made (then
    /// [`Session::from_preparation`]). Throws `{kind, message, setting?}` as `from_models`
    /// does when the job is refused.
    pub fn step(&mut self, items: u32) -> Result<bool, JsValue> {
        if self.job.is_some() {
            return Ok(true);
        }
        let made =
            stages::time(Stage::Prepare, || self.prep.step(items as usize)).map_err(js_error)?;
        self.job = made;
        Ok(self.job.is_some())
    }

    /// The passes the last [`Preparing::step`] worked in, for the page's profile: `"weld"`,
    /// or `"weld → frame"` when it went on into the next.
    pub fn pass(&self) -> String {
        match self.prep.passes() {
            (a, b) if a == b || a.is_empty() => b.to_string(),
            (a, b) => format!("{a} → {b}"),
        }
    }

    /// The draft's bytes ([`Session::begin_drafted`]: the job as its parts were merged, for
    /// [`Session::from_draft`] in the other workers) once a step made it, then `undefined`:
    /// each draft is handed out once.
    pub fn take_draft(&self) -> Option<Uint8Array> {
        self.draft.borrow_mut().take()
    }
}

/// A job another worker prepared, or its draft, being taken in short calls
/// ([`Session::begin_take`]).
#[wasm_bindgen]
pub struct Taking {
    pub(super) budget: std::rc::Rc<Budget>,
    /// `None` once the job was read (or refused).
    pub(super) pass: Option<Stepped<Result<Job, Error>>>,
    /// The job once read, or why it was refused (thrown again by every later step).
    pub(super) job: Option<Result<Job, Error>>,
    pub(super) draft: bool,
}

#[wasm_bindgen]
impl Taking {
    /// Reads about `items` items of the job (vertices, facets, the index' entries): true
    /// once it is read (then [`Session::from_taken`]). Throws `{kind: "internal", message}`
    /// as [`Session::from_prepared`] does if the bytes are damaged.
    pub fn step(&mut self, items: u32) -> Result<bool, JsValue> {
        if let Some(pass) = self.pass.as_mut() {
            self.budget.refill(items as usize);
            self.job = stages::time(Stage::Prepare, || pass.step());
            if self.job.is_some() {
                self.pass = None;
            }
        }
        match &self.job {
            None => Ok(false),
            Some(Ok(_)) => Ok(true),
            Some(Err(e)) => Err(js_error(e.clone())),
        }
    }
}
