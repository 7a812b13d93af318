//! The `.gco` reader ([`crate::output::gcode_read`]) for the page: a streaming [`GcodeStream`] fed
//! with decoded text, giving finished layers as flat typed arrays.

use crate::output::gcode_read::{GcodeReader, ReadLayer};
use js_sys::{Float32Array, Float64Array, Uint8Array};
use wasm_bindgen::prelude::*;

/// A `.gco` file being read: `feed` pieces of text, `take_layer` the finished layers, then
/// `finish`. Errors are the reader's messages ("line 5: …").
#[wasm_bindgen]
pub struct GcodeStream {
    reader: GcodeReader,
}

/// One layer read from a file.
#[wasm_bindgen]
pub struct GcodeLayer {
    layer: ReadLayer,
}

#[wasm_bindgen]
impl GcodeStream {
    #[wasm_bindgen(constructor)]
    pub fn new() -> GcodeStream {
        GcodeStream {
            reader: GcodeReader::new(),
        }
    }

    /// A reader that only counts (layers without droplet positions, roles or travel): for
    /// [`GcodeStream::calibrate`], which needs the header and the droplet count only.
    pub fn counting() -> GcodeStream {
        GcodeStream {
            reader: GcodeReader::counting(),
        }
    }

    /// Reads a piece of the file (lines may be split across pieces).
    pub fn feed(&mut self, text: &str) -> Result<(), JsError> {
        self.reader.feed(text).map_err(|e| JsError::new(&e.0))
    }

    /// After the last piece.
    pub fn finish(&mut self) -> Result<(), JsError> {
        self.reader.finish().map_err(|e| JsError::new(&e.0))
    }

    /// The next finished layer, if any.
    pub fn take_layer(&mut self) -> Option<GcodeLayer> {
        self.reader.take_layer().map(|layer| GcodeLayer { layer })
    }

    #[wasm_bindgen(getter)]
    pub fn droplet_width(&self) -> f64 {
        self.reader.droplet_width()
    }

    #[wasm_bindgen(getter)]
    pub fn layers(&self) -> usize {
        self.reader.layers()
    }

    #[wasm_bindgen(getter)]
    pub fn line_number(&self) -> usize {
        self.reader.line_number()
    }

    /// The header's `name = value` lines as a plain object `{name: value}` (a typed value,
    /// as everything else that crosses the boundary; a later line of the same name wins).
    #[wasm_bindgen(unchecked_return_type = "Record<string, string>")]
    pub fn header(&self) -> Result<JsValue, JsValue> {
        let map: std::collections::BTreeMap<&str, &str> = self
            .reader
            .header
            .iter()
            .map(|(n, v)| (n.as_str(), v.as_str()))
            .collect();
        crate::wasm::to_js(&map, "the .gco header")
    }
}

#[wasm_bindgen]
impl GcodeStream {
    /// After `finish`: the calibration of this file for a measured `mass` (g) and `density`
    /// (g/cm³; `undefined`: the header's material_density, else the default) as a plain
    /// `Calibration` object. Throws the refusal's message (calibrate.rs).
    #[wasm_bindgen(unchecked_return_type = "Calibration")]
    pub fn calibrate(&self, mass: f64, density: Option<f64>) -> Result<JsValue, JsValue> {
        let c = crate::output::calibrate::calibrate_read(&self.reader, mass, density)
            .map_err(|e| JsValue::from(JsError::new(&e.0)))?;
        crate::wasm::to_js(&c, "the calibration")
    }

    /// After `finish`: the file's figures (droplets, material, mass, print time) with its
    /// header's settings, as a plain `Figures` object. Throws the reason when the header does
    /// not give them (not a dropslice code, a setting out of range).
    #[wasm_bindgen(unchecked_return_type = "Figures")]
    pub fn figures(&self) -> Result<JsValue, JsValue> {
        let f = self.reader.figures().map_err(crate::wasm::js_error)?;
        crate::wasm::to_js(&f, "the figures")
    }

    /// After `finish`: why `figures()` are computed from the commands rather than the
    /// header's own (`undefined` when they are the header's: the slice's, exactly).
    pub fn figures_note(&self) -> Option<String> {
        self.reader.figures_note()
    }

    /// The settings the header names, as typed values (`{droplet_aspect: 1.3, …}`), checked
    /// as `--set` values; throws the reason (`{kind, message}`) when they do not pass.
    #[wasm_bindgen(unchecked_return_type = "Record<string, number | boolean | string>")]
    pub fn header_settings(&self) -> Result<JsValue, JsValue> {
        let values = self
            .reader
            .header_setting_values()
            .map_err(crate::wasm::js_error)?;
        crate::wasm::to_js(&values, "the header's settings")
    }
}

/// The calibration from a slice's droplet count (its summary) and settings: `droplets`,
/// `layer_height`, `droplet_aspect`, a measured `mass` (g) and `density` (g/cm³).
#[wasm_bindgen(unchecked_return_type = "Calibration")]
pub fn calibrate(
    droplets: f64,
    layer_height: f64,
    droplet_aspect: f64,
    mass: f64,
    density: f64,
) -> Result<JsValue, JsValue> {
    if !(droplets.is_finite() && droplets >= 0.0 && droplets <= u64::MAX as f64) {
        return Err(JsError::new("the droplet count must be a whole number ≥ 0").into());
    }
    let c = crate::output::calibrate::calibrate(
        droplets as u64,
        crate::output::calibrate::CountSource::Given,
        layer_height,
        droplet_aspect,
        mass,
        density,
    )
    .map_err(|e| JsValue::from(JsError::new(&e.0)))?;
    crate::wasm::to_js(&c, "the calibration")
}

impl Default for GcodeStream {
    fn default() -> GcodeStream {
        GcodeStream::new()
    }
}

#[wasm_bindgen]
impl GcodeLayer {
    #[wasm_bindgen(getter)]
    pub fn index(&self) -> usize {
        self.layer.index
    }

    #[wasm_bindgen(getter)]
    pub fn z(&self) -> f64 {
        self.layer.z
    }

    /// Droplets by role: outer, inner, fill.
    pub fn counts(&self) -> Vec<f64> {
        let c = &self.layer.counts;
        vec![c.outer as f64, c.inner as f64, c.fill as f64]
    }

    #[wasm_bindgen(getter)]
    pub fn travel_mm(&self) -> f64 {
        self.layer.travel_mm
    }

    pub fn droplets(&self) -> Float32Array {
        Float32Array::from(&self.layer.preview.droplets[..])
    }

    pub fn roles(&self) -> Uint8Array {
        Uint8Array::from(&self.layer.preview.roles[..])
    }

    /// Discharge unit per droplet (0 … 3; `T2` selects unit 2), in the order of `roles`.
    pub fn units(&self) -> Uint8Array {
        Uint8Array::from(&self.layer.units[..])
    }

    /// Droplets each unit prints, indexed by unit (`MAX_UNITS` entries).
    #[wasm_bindgen(getter)]
    pub fn unit_droplets(&self) -> Float64Array {
        let n: Vec<f64> = self.layer.counts.units.iter().map(|&n| n as f64).collect();
        Float64Array::from(&n[..])
    }

    pub fn travel(&self) -> Float32Array {
        Float32Array::from(&self.layer.preview.travel[..])
    }
}
