//! Calibrating the droplet size from a printed part (docs/spec.md "Calibrating the droplet
//! size from a printed part").
//!
//! A part's measured mass m (g), its droplet count N and the material density ρ (g/cm³) give
//! the effective droplet volume V = m / (N ρ) · 1000 mm³/cm³. The code's lattice gives each
//! droplet a cell of B² H (B = droplet_aspect · H); the filling degree is V / (B² H), and the
//! aspect whose cell holds exactly V is √(V/H) / H. The count comes from the code's header
//! (`; droplets total = N`) or, where the header has none, from its commands
//! ([`crate::output::gcode_read`]).
//!
//! Every input is checked: a mass that is not a positive finite number, a density outside the
//! settings' range, a filling degree outside [`FILLING_RANGE`] (the mass cannot belong to this
//! code) and a suggestion outside `droplet_aspect`'s range are refused with a message that says
//! what to check.

use crate::base::error::grouped;
use crate::base::error::number;
use crate::base::settings::{Settings, schema};
use crate::output::gcode_read::GcodeReader;
use serde::Serialize;

/// Filling degrees outside this range are refused as impossible (a droplet holding a fifth of
/// its cell, or five cells' worth, is not a miscalibration but a wrong mass, density or file).
pub const FILLING_RANGE: (f64, f64) = (0.2, 5.0);

/// Where the droplet count came from.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CountSource {
    /// The header's `; droplets total = N`.
    Header,
    /// Counted from the G25/G26 commands (the header has no total).
    Commands,
    /// Given by the caller (e.g. the page's summary of a slice).
    Given,
}

/// The figures and the suggestion.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Calibration {
    pub droplets: u64,
    pub count_source: CountSource,
    pub mass_g: f64,
    pub density_g_cm3: f64,
    pub layer_height: f64,
    /// V = m / (N ρ), mm³.
    pub droplet_volume_mm3: f64,
    /// B² H of the code's lattice, mm³.
    pub cell_volume_mm3: f64,
    /// V / (B² H).
    pub filling_degree: f64,
    /// √(V/H) / H: the aspect whose cell holds exactly V.
    pub suggested_droplet_aspect: f64,
    pub current_droplet_aspect: f64,
    /// One line for people, e.g. "Your part weighs 12.3 g: 412,000 droplets of 0.0287 mm³
    /// each, 97 % of a B²H cell — set droplet_aspect to 1.02 (now 1.04)".
    pub explanation: String,
}

crate::base::error::message_error! {
    /// Why a calibration was refused (the message says what to check).
    CalibrationError
}

fn err<T>(msg: String) -> Result<T, CalibrationError> {
    Err(CalibrationError(msg))
}

fn range(name: &str) -> (f64, f64) {
    let spec = schema()
        .into_iter()
        .find(|s| s.name == name)
        .expect("a setting of the schema");
    (
        spec.domain.min.unwrap_or(f64::NEG_INFINITY),
        spec.domain.max.unwrap_or(f64::INFINITY),
    )
}

/// The calibration from a droplet count, the code's droplet size, a mass and a density.
pub fn calibrate(
    droplets: u64,
    count_source: CountSource,
    layer_height: f64,
    droplet_aspect: f64,
    mass_g: f64,
    density_g_cm3: f64,
) -> Result<Calibration, CalibrationError> {
    if droplets == 0 {
        return err("the code sets no droplets: nothing was printed from it".into());
    }
    if !(mass_g.is_finite() && mass_g > 0.0) {
        return err(format!(
            "the mass must be a positive number of grams, got {}",
            number(mass_g)
        ));
    }
    let (lo, hi) = range("material_density");
    if !(density_g_cm3.is_finite() && density_g_cm3 > lo && density_g_cm3 <= hi) {
        return err(format!(
            "the density must be greater than {lo} and at most {hi} g/cm³, got {}",
            number(density_g_cm3)
        ));
    }
    let (h_lo, h_hi) = range("layer_height");
    let (a_lo, a_hi) = range("droplet_aspect");
    if !(layer_height >= h_lo && layer_height <= h_hi) {
        return err(format!(
            "the code's layer_height = {} mm is out of range ({h_lo} … {h_hi} mm)",
            number(layer_height)
        ));
    }
    if !(droplet_aspect >= a_lo && droplet_aspect <= a_hi) {
        return err(format!(
            "the code's droplet_aspect = {} is out of range ({a_lo} … {a_hi})",
            number(droplet_aspect)
        ));
    }
    let h = layer_height;
    let b = droplet_aspect * h;
    let volume = mass_g / (droplets as f64 * density_g_cm3) * 1000.0;
    let cell = b * b * h;
    let filling = volume / cell;
    let suggested = (volume / h).sqrt() / h;
    if !(filling >= FILLING_RANGE.0 && filling <= FILLING_RANGE.1) {
        return err(format!(
            "impossible: check the mass, the density ({} g/cm³) and that the file is the printed part's code ({} g over {} droplets is {} % of a droplet's B²H cell; sane: {:.0} … {:.0} %)",
            number(density_g_cm3),
            number(mass_g),
            grouped(droplets),
            if filling < 1e12 {
                format!("{:.0}", 100.0 * filling)
            } else {
                number(100.0 * filling)
            },
            100.0 * FILLING_RANGE.0,
            100.0 * FILLING_RANGE.1
        ));
    }
    if !(suggested > a_lo && suggested <= a_hi) {
        return err(format!(
            "the droplet_aspect this mass implies, {suggested:.3}, is outside its range ({a_lo} … {a_hi}); check the mass and the density"
        ));
    }
    let source = match count_source {
        CountSource::Header => "",
        CountSource::Commands => " (counted from the code; its header gives no total)",
        CountSource::Given => "",
    };
    let explanation = format!(
        "Your part weighs {mass_g} g: {} droplets{source} of {volume:.4} mm³ each, {:.0} % of a B²H cell — set droplet_aspect to {suggested:.3} (now {droplet_aspect})",
        grouped(droplets),
        100.0 * filling
    );
    Ok(Calibration {
        droplets,
        count_source,
        mass_g,
        density_g_cm3,
        layer_height: h,
        droplet_volume_mm3: volume,
        cell_volume_mm3: cell,
        filling_degree: filling,
        suggested_droplet_aspect: suggested,
        current_droplet_aspect: droplet_aspect,
        explanation,
    })
}

/// The calibration of a `.gco` read to its end by `reader` ([`GcodeReader::finish`] done):
/// the droplet size from its header, the count from its header or else its commands, the
/// density given or else the header's `material_density` or else the settings' default.
pub fn calibrate_read(
    reader: &GcodeReader,
    mass_g: f64,
    density_g_cm3: Option<f64>,
) -> Result<Calibration, CalibrationError> {
    let num = |name: &str| {
        reader
            .header_value(name)
            .map(|v| v.parse::<f64>().unwrap_or(f64::NAN))
    };
    let h = num("layer_height").unwrap_or(f64::NAN);
    if !h.is_finite() {
        return err("the code's header gives no layer_height: it is not a dropslice code".into());
    }
    let defaults = Settings::default();
    let aspect = num("droplet_aspect").unwrap_or(
        defaults
            .unit(crate::base::settings::UnitId::FIRST)
            .droplet_aspect,
    );
    let density = density_g_cm3.or_else(|| num("material_density")).unwrap_or(
        defaults
            .unit(crate::base::settings::UnitId::FIRST)
            .material_density,
    );
    let (droplets, source) = match reader.header_droplets() {
        Some(n) => (n, CountSource::Header),
        None => (reader.droplets(), CountSource::Commands),
    };
    if droplets == 0 {
        return err(
            "the code has no droplet count in its header and sets no droplets: nothing to calibrate from"
                .into(),
        );
    }
    calibrate(droplets, source, h, aspect, mass_g, density)
}

/// [`calibrate_read`] of a whole `.gco` text.
pub fn calibrate_gcode(
    text: &str,
    mass_g: f64,
    density_g_cm3: Option<f64>,
) -> Result<Calibration, CalibrationError> {
    let mut r = GcodeReader::counting();
    r.feed(text)
        .and_then(|()| r.finish())
        .map_err(|e| CalibrationError(e.0))?;
    while r.take_layer().is_some() {}
    calibrate_read(&r, mass_g, density_g_cm3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula() {
        // H 0.2, aspect 1.04: cell 0.208² · 0.2 = 0.0086528 mm³. 1000 droplets of exactly one
        // cell, density 1.25: m = 1000 · 0.0086528 mm³ · 1.25 g/cm³ / 1000 = 0.010816 g.
        let c = calibrate(1000, CountSource::Given, 0.2, 1.04, 0.010816, 1.25).unwrap();
        assert!((c.droplet_volume_mm3 - 0.0086528).abs() < 1e-12);
        assert!((c.filling_degree - 1.0).abs() < 1e-9);
        assert!((c.suggested_droplet_aspect - 1.04).abs() < 1e-9);
        assert!(c.explanation.contains("100 %"), "{}", c.explanation);
    }
}
