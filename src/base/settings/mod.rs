//! Settings: the one source of truth for every parameter (docs/spec.md 5.4.1).
//!
//! The same names are used by the CLI (`--set name=value`), the page's form, the preview link
//! and the G-code header. [`schema()`] exports units, ranges and descriptions so the page can
//! build its form from them; [`Settings::validate`] checks every value against the same table.

mod profile;
mod schema;

pub use profile::{
    MACHINE_KEYS, MATERIAL_KEYS, MAX_PROFILE_BYTES, MAX_PROFILE_NAME_CHARS, Profile, ProfileKind,
    invisible, profile_name, profile_text,
};
pub use schema::{Kind, PART_KEYS, SettingSpec, names, schema, schema_json};

use crate::base::error::Error;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Order of the contour loops within a layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContourOrder {
    /// Inner loops before the outermost, so the outermost nestles against them (thesis default).
    InsideOut,
    /// Outermost loop first.
    OutsideIn,
}

/// Whether a layer's contours or its fill are printed first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PrintOrder {
    ContoursFirst,
    FillFirst,
}

/// Where within a layer the part is cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlicePlane {
    /// At the middle of the layer (default, more accurate).
    Middle,
    /// At the top of the layer (the thesis).
    Top,
}

/// The droplet's footprint in the coverage analysis ([`crate::analysis`]); no effect on the code.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Footprint {
    /// A disc of diameter B: the droplet as measured (thesis 4.2).
    Disc,
    /// A disc of diameter 2B/√π ≈ 1.13 B, whose area is a B × B cell: the droplet spread flat
    /// with the volume a dense part needs.
    Spread,
}

/// How droplets are spaced along a contour loop (docs/spec.md "Loop seams").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopSpacing {
    /// Centres B apart, the first droplet repeated at the end (the thesis).
    Exact,
    /// n = ⌈L/B⌉ droplets spaced L/n along the loop, none repeated.
    Even,
}

/// Whether support is printed under overhangs (docs/spec.md "Overhangs and support").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    Off,
    /// Support printed by discharge unit 1.
    Unit1,
}

/// Which discharge unit prints first within a layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnitOrder {
    Unit0First,
    Unit1First,
}

/// Every parameter of a slice. `Default` gives the defaults of docs/spec.md 5.4.1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    pub layer_height: f64,
    pub droplet_aspect: f64,
    pub contours: u32,
    pub outer_offset: f64,
    pub inner_offset: f64,
    pub fill_density: f64,
    pub fill_overlap: f64,
    pub hatch_angle: f64,
    pub hatch_angle_step: f64,
    pub start_jitter: f64,
    /// Set each layer's droplets over the gaps of the layer below (loops by B/2 along the loop,
    /// hatch lines by half the spacing where the hatch angle repeats).
    pub stagger: bool,
    pub contour_order: ContourOrder,
    pub print_order: PrintOrder,
    pub close_loops: bool,
    /// Droplet spacing along loops (`exact`: the thesis; `even`: no repeated seam droplet).
    pub loop_spacing: LoopSpacing,
    pub rotate_x: f64,
    pub rotate_y: f64,
    pub rotate_z: f64,
    pub scale_x: f64,
    pub scale_y: f64,
    pub scale_z: f64,
    pub place_x: f64,
    pub place_y: f64,
    pub place_angle: f64,
    pub slice_plane: SlicePlane,
    /// Droplets the discharge unit sets per second (for the time estimate).
    pub droplet_rate: f64,
    /// Table speed for travel moves (for the time estimate).
    pub travel_speed: f64,
    /// Density of the material (for the mass estimate).
    pub material_density: f64,
    /// Linear shrinkage of unit 0's material in x and y (%): its parts are sliced scaled by
    /// 1 / (1 − s/100) (docs/spec.md "Shrinkage compensation").
    pub shrink_xy: f64,
    /// Linear shrinkage of unit 0's material in z (%).
    pub shrink_z: f64,
    /// Droplet footprint model of the coverage analysis.
    pub footprint: Footprint,
    /// Build plate size in x and y (mm): parts are arranged on it.
    pub plate_x: f64,
    pub plate_y: f64,
    /// Height of the build chamber (mm): a taller job is refused before slicing.
    pub plate_z: f64,
    /// Gap between the bounding boxes of arranged parts (mm).
    pub part_spacing: f64,
    /// Slice a job with a part larger than the plate or reaching past its edges (refused
    /// unless set; docs/jobs.md "The plate rule").
    pub allow_off_plate: bool,
    /// A droplet is supported when the layer below has material within this many B.
    pub overhang_limit: f64,
    /// Support under overhangs, printed by discharge unit 1.
    pub support: Support,
    /// Support is kept this many B (of unit 0) away from the part within a layer.
    pub support_gap_xy: f64,
    /// Support ends this many layers below the overhang it carries.
    pub support_gap_z: u32,
    /// Hatch spacing of the support = B₁ / support_density.
    pub support_density: f64,
    /// Droplet width of unit 1 divided by the layer height (B₁ = aspect × H).
    pub unit1_droplet_aspect: f64,
    /// Droplets unit 1 sets per second (time estimate).
    pub unit1_droplet_rate: f64,
    /// Density of unit 1's material (mass estimate).
    pub unit1_material_density: f64,
    /// Linear shrinkage of unit 1's material in x and y (%), for unit 1's parts.
    pub unit1_shrink_xy: f64,
    /// Linear shrinkage of unit 1's material in z (%).
    pub unit1_shrink_z: f64,
    /// Which unit prints first within a layer.
    pub unit_order: UnitOrder,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            layer_height: 0.20,
            droplet_aspect: 1.04,
            contours: 2,
            outer_offset: 0.5,
            inner_offset: 0.5,
            fill_density: 1.0,
            fill_overlap: 0.5,
            hatch_angle: 45.0,
            hatch_angle_step: 90.0,
            start_jitter: 0.07,
            stagger: false,
            contour_order: ContourOrder::InsideOut,
            print_order: PrintOrder::ContoursFirst,
            close_loops: true,
            loop_spacing: LoopSpacing::Exact,
            rotate_x: 0.0,
            rotate_y: 0.0,
            rotate_z: 0.0,
            scale_x: 1.0,
            scale_y: 1.0,
            scale_z: 1.0,
            place_x: 0.0,
            place_y: 0.0,
            place_angle: 0.0,
            slice_plane: SlicePlane::Middle,
            droplet_rate: 100.0,
            travel_speed: 50.0,
            material_density: 1.04,
            shrink_xy: 0.0,
            shrink_z: 0.0,
            footprint: Footprint::Disc,
            plate_x: 154.0,
            plate_y: 134.0,
            plate_z: 230.0,
            part_spacing: 5.0,
            allow_off_plate: false,
            overhang_limit: 0.5,
            support: Support::Off,
            support_gap_xy: 0.5,
            support_gap_z: 0,
            support_density: 1.0,
            unit1_droplet_aspect: 1.04,
            unit1_droplet_rate: 100.0,
            unit1_material_density: 1.04,
            unit1_shrink_xy: 0.0,
            unit1_shrink_z: 0.0,
            unit_order: UnitOrder::Unit0First,
        }
    }
}

/// Largest settings file the command-line tool reads (`--settings FILE.json`), checked before
/// reading: 1 MiB, as a job file ([`crate::model::spec::MAX_JOB_FILE_BYTES`]); every setting with a
/// long value takes a few kB.
pub const MAX_SETTINGS_FILE_BYTES: usize = 1 << 20;

impl Settings {
    /// Parses settings from a JSON object `{"name": value, ...}`; missing names take their
    /// defaults. The result is validated.
    pub fn from_json(text: &str) -> Result<Settings, Error> {
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| Error::Setting {
            name: String::new(),
            message: format!(
                "the settings are not valid JSON: {}",
                crate::base::error::quote(&e.to_string())
            ),
        })?;
        Settings::from_value(value)
    }

    /// Settings from an object `{"name": value, ...}` (parsed JSON, or a JS object from the
    /// page); missing names take their defaults. The result is validated.
    pub fn from_value(value: serde_json::Value) -> Result<Settings, Error> {
        let serde_json::Value::Object(map) = value else {
            return Err(Error::Setting {
                name: String::new(),
                message: "the settings must be a JSON object like {\"layer_height\": 0.2}".into(),
            });
        };
        let mut settings = Settings::default();
        for (name, v) in map {
            settings.set_value(&name, v)?;
        }
        settings.validate()?;
        Ok(settings)
    }

    /// Sets one value given as text (`--set name=value`). Not validated; call [`validate`](Self::validate).
    pub fn set(&mut self, name: &str, value: &str) -> Result<(), Error> {
        let t = value.trim();
        // An enum's choices are words even where they look like booleans (`support = off`).
        let is_enum = schema()
            .iter()
            .any(|spec| spec.name == name && spec.kind == Kind::Enum);
        let v = match t {
            _ if is_enum => serde_json::Value::String(t.to_string()),
            "true" | "yes" | "on" => serde_json::Value::Bool(true),
            "false" | "no" | "off" => serde_json::Value::Bool(false),
            _ => match t.parse::<f64>() {
                Ok(x) if x.is_finite() => serde_json::Number::from_f64(x)
                    .map(serde_json::Value::Number)
                    .unwrap_or(serde_json::Value::Null),
                Ok(_) => serde_json::Value::Null,
                Err(_) => serde_json::Value::String(t.to_string()),
            },
        };
        self.set_value(name, v)
    }

    /// Sets one value given as JSON, with a message naming the setting when it does not fit.
    pub fn set_value(&mut self, name: &str, value: serde_json::Value) -> Result<(), Error> {
        use serde_json::Value;
        let mut map = serde_json::to_value(&*self).expect("settings serialize");
        let Some(spec) = schema().into_iter().find(|s| s.name == name) else {
            let name = crate::base::error::quote(name);
            return Err(Error::Setting {
                message: format!(
                    "there is no setting named '{name}'; known settings: {}",
                    names().join(", ")
                ),
                name,
            });
        };
        let shown = match &value {
            Value::String(s) => crate::base::error::quote(s),
            other => crate::base::error::quote(&other.to_string()),
        };
        let bad = |what: String| Error::Setting {
            name: name.to_string(),
            message: format!("'{shown}' is not {what}"),
        };
        let value = match (spec.kind, value) {
            (Kind::Bool, Value::Bool(b)) => Value::Bool(b),
            (Kind::Bool, Value::Number(n)) if n.as_f64() == Some(1.0) => Value::Bool(true),
            (Kind::Bool, Value::Number(n)) if n.as_f64() == Some(0.0) => Value::Bool(false),
            (Kind::Bool, _) => return Err(bad("true or false".into())),
            (Kind::Enum, Value::String(s)) if spec.choices.contains(&s.as_str()) => {
                Value::String(s)
            }
            (Kind::Enum, _) => return Err(bad(format!("one of: {}", spec.choices.join(", ")))),
            (Kind::Integer, Value::Number(n)) => match n.as_f64() {
                Some(x) if x.fract() == 0.0 && x >= 0.0 && x <= u32::MAX as f64 => {
                    Value::from(x as u64)
                }
                _ => return Err(bad("a whole number (0, 1, 2 …)".into())),
            },
            (Kind::Number, Value::Number(n)) if n.as_f64().is_some_and(f64::is_finite) => {
                Value::Number(n)
            }
            (Kind::Integer | Kind::Number, _) => return Err(bad("a finite number".into())),
        };
        map[name] = value;
        *self = serde_json::from_value(map).map_err(|e| {
            bad(format!(
                "allowed: {}",
                crate::base::error::quote(&e.to_string())
            ))
        })?;
        Ok(())
    }

    /// Checks every value against the schema's range.
    pub fn validate(&self) -> Result<(), Error> {
        let map = serde_json::to_value(self).expect("settings serialize");
        for spec in schema() {
            if !matches!(spec.kind, Kind::Number | Kind::Integer) {
                continue;
            }
            // NaN and infinity serialize as null.
            let Some(x) = map[spec.name].as_f64() else {
                return Err(Error::Setting {
                    name: spec.name.to_string(),
                    message: "is not a finite number".into(),
                });
            };
            let (Some(min), Some(max)) = (spec.min, spec.max) else {
                continue;
            };
            let below = if spec.min_exclusive {
                x <= min
            } else {
                x < min
            };
            if !x.is_finite() || below || x > max {
                let lower = if spec.min_exclusive {
                    "greater than"
                } else {
                    "at least"
                };
                return Err(Error::Setting {
                    name: spec.name.to_string(),
                    message: format!(
                        "{} is out of range: it must be {lower} {min} and at most {max}{} ({})",
                        crate::base::error::number(x),
                        if spec.unit.is_empty() {
                            String::new()
                        } else {
                            format!(" {}", spec.unit)
                        },
                        spec.description
                    ),
                });
            }
        }
        Ok(())
    }

    /// Droplet width B in mm.
    pub fn droplet_width(&self) -> f64 {
        self.layer_height * self.droplet_aspect
    }

    /// Droplet width B₁ of discharge unit 1 in mm.
    pub fn unit1_droplet_width(&self) -> f64 {
        self.layer_height * self.unit1_droplet_aspect
    }

    /// The scale that compensates the shrinkage of discharge unit `unit`'s material: a part
    /// of shrinkage s (%) is sliced scaled by 1 / (1 − s/100) in that axis (exactly 1 for 0).
    pub fn shrink_factors(&self, unit: u8) -> [f64; 3] {
        let (xy, z) = if unit == 1 {
            (self.unit1_shrink_xy, self.unit1_shrink_z)
        } else {
            (self.shrink_xy, self.shrink_z)
        };
        let f = |s: f64| 1.0 / (1.0 - s / 100.0);
        [f(xy), f(xy), f(z)]
    }

    /// The settings as `(name, value)` pairs in schema order, values as they appear in the header.
    pub fn entries(&self) -> Vec<(&'static str, String, &'static str)> {
        self.entries_with(true)
    }

    /// [`entries`](Self::entries) for the header: the settings of discharge unit 1 (those only
    /// unit 1 uses, [`is_unit1_setting`]) only when unit 1 is used.
    pub fn entries_with(&self, unit1_used: bool) -> Vec<(&'static str, String, &'static str)> {
        let map = serde_json::to_value(self).expect("settings serialize");
        schema()
            .into_iter()
            .filter(|spec| unit1_used || !is_unit1_setting(spec.name))
            .map(|spec| {
                let v = &map[spec.name];
                let text = match v {
                    serde_json::Value::String(s) => s.clone(),
                    other => other.to_string(),
                };
                (spec.name, text, spec.unit)
            })
            .collect()
    }
}

/// Settings that only discharge unit 1 uses (listed in the header when unit 1 is used).
pub fn is_unit1_setting(name: &str) -> bool {
    // The four shrinkage values are always listed (docs/spec.md "Shrinkage compensation").
    (name.starts_with("unit1_") && !name.starts_with("unit1_shrink_"))
        || name == "unit_order"
        || matches!(name, "support_gap_xy" | "support_gap_z" | "support_density")
}

impl fmt::Display for Settings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}",
            serde_json::to_string(self).map_err(|_| fmt::Error)?
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schema_covers_every_field() {
        let map = serde_json::to_value(Settings::default()).unwrap();
        let fields: Vec<_> = map.as_object().unwrap().keys().cloned().collect();
        let names = names();
        assert_eq!(fields.len(), names.len());
        for f in fields {
            assert!(names.contains(&f.as_str()), "{f} missing in schema");
        }
        Settings::default().validate().unwrap();
    }

    #[test]
    fn schema_flags_the_part_keys() {
        let flagged: Vec<_> = schema()
            .into_iter()
            .filter(|s| s.part)
            .map(|s| s.name)
            .collect();
        assert_eq!(flagged, PART_KEYS);
        for s in schema().into_iter().filter(|s| s.part) {
            assert_eq!(s.kind, Kind::Number, "{}", s.name);
            assert!(s.min.is_some() && s.max.is_some(), "{}", s.name);
        }
    }

    #[test]
    fn set_parses_and_validates() {
        let mut s = Settings::default();
        for (k, v) in [
            ("contours", "3"),
            ("contour_order", "outside_in"),
            ("close_loops", "false"),
            ("layer_height", "0.265"),
        ] {
            s.set(k, v).unwrap();
        }
        assert_eq!(s.contours, 3);
        assert_eq!(s.contour_order, ContourOrder::OutsideIn);
        assert!(!s.close_loops);
        assert!(s.set("contours", "2.5").is_err());
        assert!(s.set("nonsense", "1").is_err());
        assert!(s.set("contour_order", "sideways").is_err());
        s.set("support", "off").unwrap();
        assert_eq!(s.support, Support::Off);
        s.set("support", "unit1").unwrap();
        assert_eq!(s.support, Support::Unit1);
        s.set("layer_height", "-1").unwrap();
        let e = s.validate().unwrap_err().to_string();
        assert!(
            e.contains("layer_height") && e.contains("at least 0.0001"),
            "{e}"
        );
    }
}
