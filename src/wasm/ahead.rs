//! A layer made in short calls: its section and its overhang figure ahead of its plan
//! ([`Session::layer_ahead`], then [`Session::slice_layer`]), so that no call of the page's
//! holds a whole layer (docs/page.md, *Short calls*).

use super::Session;
use wasm_bindgen::prelude::*;

/// Layer `layer`'s section, and once made its overhang figure, ahead of its plan
/// ([`Session::layer_ahead`]).
pub(super) struct Ahead {
    pub(super) layer: usize,
    pub(super) section: crate::slicing::slice::Section,
    pub(super) unsupported: Option<f64>,
}

#[wasm_bindgen]
impl Session {
    /// Makes the next part of layer `i` ahead of [`Session::slice_layer`] (or
    /// [`Session::slice_layer_analysed`]) of it, so that a layer is made in three short calls
    /// rather than one: its section, then its overhang figure; `true` once nothing more is
    /// made ahead (then slice it). The layer and everything the page sees of it are the same
    /// with or without these calls; with support on (the plans made by the supported pass)
    /// there is nothing to make ahead.
    pub fn layer_ahead(&self, i: usize) -> Result<bool, JsValue> {
        self.check_layer(i)?;
        if !self.job.needs_below() {
            return Ok(true);
        }
        let mut ahead = self.ahead.borrow_mut();
        match ahead.as_mut().filter(|a| a.layer == i) {
            None => {
                *ahead = Some(Ahead {
                    layer: i,
                    section: self.job.section(i),
                    unsupported: None,
                });
                Ok(false)
            }
            Some(a) if a.unsupported.is_none() => {
                let last = self.last_section.borrow();
                let below = (last.as_ref()).filter(|(j, _)| j + 1 == i).map(|(_, r)| r);
                a.unsupported = Some(self.job.overhang_of(i, &a.section, below));
                Ok(true)
            }
            Some(_) => Ok(true),
        }
    }
}
