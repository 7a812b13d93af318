//! Settings: the one source of truth for every parameter (docs/spec.md 5.4.1).
//!
//! The same names are used by the CLI (`--set name=value`), the page's form, the preview link
//! and the G-code header. [`schema()`] exports units, ranges and descriptions so the page can
//! build its form from them; [`Settings::validate`] checks every value against the same table.

mod profile;
mod schema;
mod table;
mod units;

pub use profile::{
    MAX_PROFILE_BYTES, MAX_PROFILE_NAME_CHARS, Profile, ProfileKind, invisible, profile_name,
    profile_text,
};
pub use schema::{
    Domain, Entry, Kind, SettingSpec, Shown, Slot, entries, entry, names, schema, schema_json,
};
pub use table::{MAX_UNITS, PART_KEYS, Settings, UnitSettings};
pub use units::{Support, UnitId, UnitOrder};

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
        let is_enum = schema::entry(name)
            .is_some_and(|e| matches!(e.spec.domain.kind, Kind::Enum | Kind::Order));
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
        let Some(entry) = schema::entry(name) else {
            let name = crate::base::error::quote(name);
            return Err(Error::Setting {
                message: format!(
                    "there is no setting named '{name}'; known settings: {}; and of each unit N = 1 … {}: {}",
                    (entries().iter())
                        .filter(|e| !matches!(e.slot, Slot::Unit(u, _) if u.0 > 0))
                        .map(|e| e.spec.name)
                        .collect::<Vec<_>>()
                        .join(", "),
                    MAX_UNITS - 1,
                    (entries().iter())
                        .filter_map(|e| match e.slot {
                            Slot::Unit(UnitId::FIRST, base) => Some(format!("unitN_{base}")),
                            _ => None,
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                name,
            });
        };
        let spec = &entry.spec;
        let shown = match &value {
            Value::String(s) => crate::base::error::quote(s),
            other => crate::base::error::quote(&other.to_string()),
        };
        let bad = |what: String| Error::Setting {
            name: name.to_string(),
            message: format!("'{shown}' is not {what}"),
        };
        let value = match (spec.domain.kind, value) {
            (Kind::Bool, Value::Bool(b)) => Value::Bool(b),
            (Kind::Bool, Value::Number(n)) if n.as_f64() == Some(1.0) => Value::Bool(true),
            (Kind::Bool, Value::Number(n)) if n.as_f64() == Some(0.0) => Value::Bool(false),
            (Kind::Bool, _) => return Err(bad("true or false".into())),
            // A word of the choices, or what the setting's own type reads (a `unit_order` list).
            (Kind::Enum | Kind::Order, Value::String(s)) => Value::String(s),
            (Kind::Enum | Kind::Order, _) => {
                return Err(bad(format!("one of: {}", spec.domain.choices.join(", "))));
            }
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
        let put = match entry.slot {
            Slot::Job => self.put_job(name, value),
            Slot::Unit(u, base) => self.per_unit[u.index()].put(base, value),
        };
        match put {
            Some(Ok(())) => Ok(()),
            Some(Err(e)) if matches!(spec.domain.kind, Kind::Enum | Kind::Order) => {
                Err(bad(format!(
                    "one of: {}{}",
                    spec.domain.choices.join(", "),
                    if e.to_string().contains("list") {
                        ", or a list of units such as 2,0,1"
                    } else {
                        ""
                    }
                )))
            }
            Some(Err(e)) => Err(bad(format!(
                "allowed: {}",
                crate::base::error::quote(&e.to_string())
            ))),
            None => Err(Error::Internal(format!("the setting {name} has no field"))),
        }
    }

    /// The value of the setting at `slot` (named `name`) as JSON.
    fn value_at(&self, slot: Slot, name: &str) -> serde_json::Value {
        match slot {
            Slot::Job => self.job_value(name),
            Slot::Unit(u, base) => self.per_unit[u.index()].value(base),
        }
        .expect("every entry has a field")
    }

    /// The value of the setting `name` as JSON (`None`: no such setting).
    pub fn value(&self, name: &str) -> Option<serde_json::Value> {
        schema::entry(name).map(|e| self.value_at(e.slot, name))
    }

    /// Checks every value against the schema's range, and every unit named (by `support`,
    /// `unit_order`) against `units`.
    pub fn validate(&self) -> Result<(), Error> {
        for entry in entries() {
            let spec = &entry.spec;
            if !matches!(spec.domain.kind, Kind::Number | Kind::Integer) {
                continue;
            }
            // NaN and infinity serialize as null.
            let Some(x) = self.value_at(entry.slot, spec.name).as_f64() else {
                return Err(Error::Setting {
                    name: spec.name.to_string(),
                    message: "is not a finite number".into(),
                });
            };
            if let Some(range) = spec.domain.range_words()
                && !spec.domain.admits(x)
            {
                return Err(Error::Setting {
                    name: spec.name.to_string(),
                    message: format!(
                        "{} is out of range: it must be {range}{} ({})",
                        crate::base::error::number(x),
                        if spec.domain.unit.is_empty() {
                            String::new()
                        } else {
                            format!(" {}", spec.domain.unit)
                        },
                        spec.description
                    ),
                });
            }
        }
        let named = self.support.unit().into_iter().map(|u| ("support", u));
        let ordered = self
            .unit_order
            .named()
            .into_iter()
            .map(|u| ("unit_order", u));
        for (name, u) in named.chain(ordered) {
            self.check_unit(u, name)?;
        }
        // A unit's own setting set for a unit the machine does not have is a mistake (a
        // material for unit 2 on a machine of two units).
        for e in entries() {
            if let Slot::Unit(u, _) = e.slot
                && u.index() >= self.units as usize
                && self.value_at(e.slot, e.spec.name) != e.spec.default
            {
                self.check_unit(u, e.spec.name)?;
            }
        }
        Ok(())
    }

    /// Refuses a unit the machine does not have (`what` names where it was given).
    pub fn check_unit(&self, u: UnitId, what: &str) -> Result<(), Error> {
        if u.index() < self.units as usize {
            return Ok(());
        }
        Err(Error::Setting {
            name: what.to_string(),
            message: format!(
                "names discharge unit {u}, but the machine has {} (units = {}: units 0 … {}); set units = {} or more",
                self.units,
                self.units,
                self.units.saturating_sub(1),
                u.0 + 1
            ),
        })
    }

    /// The settings of discharge unit `u`.
    pub fn unit(&self, u: UnitId) -> &UnitSettings {
        &self.per_unit[u.index()]
    }

    pub fn unit_mut(&mut self, u: UnitId) -> &mut UnitSettings {
        &mut self.per_unit[u.index()]
    }

    /// These settings as unit `u` prints with them: unit `u`'s own settings in unit 0's place
    /// (the droplet width B_u, the rate, the density).
    pub fn for_unit(&self, u: UnitId) -> Settings {
        let mut s = self.clone();
        s.per_unit[0] = self.per_unit[u.index()].clone();
        s
    }

    /// Droplet width B in mm (unit 0's).
    pub fn droplet_width(&self) -> f64 {
        self.unit_width(UnitId::FIRST)
    }

    /// Droplet width B_u of discharge unit `u` in mm.
    pub fn unit_width(&self, u: UnitId) -> f64 {
        self.layer_height * self.unit(u).droplet_aspect
    }

    /// The unit that prints the support: `support`'s (unit 1 while support is off, so the
    /// support's figures keep a width).
    pub fn support_unit(&self) -> UnitId {
        self.support.unit().unwrap_or(UnitId(1))
    }

    /// Droplet width of the support's unit, mm.
    pub fn support_width(&self) -> f64 {
        self.unit_width(self.support_unit())
    }

    /// The scale that compensates the shrinkage of discharge unit `unit`'s material: a part
    /// of shrinkage s (%) is sliced scaled by 1 / (1 − s/100) in that axis (exactly 1 for 0).
    pub fn shrink_factors(&self, unit: UnitId) -> [f64; 3] {
        let u = self.unit(unit);
        let f = |s: f64| 1.0 / (1.0 - s / 100.0);
        [f(u.shrink_xy), f(u.shrink_xy), f(u.shrink_z)]
    }

    /// The settings as `(name, value, unit)` in schema order, values as they appear in the
    /// header.
    pub fn entries(&self) -> Vec<(&'static str, String, &'static str)> {
        self.entries_with(|_| true)
    }

    /// [`entries`](Self::entries) for the header of a job whose units `used` print: a unit's
    /// own settings only when it prints, the settings of support and the unit order only when
    /// a unit other than 0 prints, `units` only when one beyond unit 1 does ([`Shown`]).
    pub fn entries_with(
        &self,
        used: impl Fn(UnitId) -> bool,
    ) -> Vec<(&'static str, String, &'static str)> {
        let second = UnitId::all(MAX_UNITS).skip(1).any(&used);
        let beyond = UnitId::all(MAX_UNITS).skip(2).any(&used);
        entries()
            .iter()
            .filter(|e| shown(e, &used, second, beyond))
            .map(|e| {
                let text = match self.value_at(e.slot, e.spec.name) {
                    serde_json::Value::String(s) => s,
                    other => other.to_string(),
                };
                (e.spec.name, text, e.spec.domain.unit)
            })
            .collect()
    }
}

/// The page's TypeScript of the settings, `www/core/settings.gen.ts`, made from the table: the
/// `Settings` type, every name (`SETTING_NAMES`), the part keys, the units' own keys and every
/// default, so that the page lists no setting itself (a test fails when the file is stale;
/// `DROPSLICE_WRITE_GENERATED=1 cargo test --lib settings` writes it).
pub fn typescript() -> String {
    let mut out = String::from(
        "// Generated from the core's settings table (src/base/settings/table.rs): do not edit.\n\
         // `cargo test --release --lib settings` fails when it is stale; with\n\
         // DROPSLICE_WRITE_GENERATED=1 it writes it again.\n\n",
    );
    out.push_str(&format!(
        "/** The most discharge units a machine may have (the setting `units`). */\nexport const MAX_UNITS = {MAX_UNITS};\n\n"
    ));
    let list = |names: &[&str]| {
        names
            .iter()
            .map(|n| format!("\"{n}\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    out.push_str(&format!(
        "/** The settings a part of a job carries itself. */\nexport const PART_KEYS = [{}] as const;\nexport type PartKey = (typeof PART_KEYS)[number];\n\n",
        list(PART_KEYS)
    ));
    let unit_base: Vec<&str> = (entries().iter())
        .filter_map(|e| match e.slot {
            Slot::Unit(UnitId::FIRST, base) => Some(base),
            _ => None,
        })
        .collect();
    out.push_str(&format!(
        "/** The settings each unit has (unit 0's names; unit N's are `unitN_` + the name). */\nexport const UNIT_KEYS = [{}] as const;\nexport type UnitKey = (typeof UNIT_KEYS)[number];\n\n",
        list(&unit_base)
    ));
    let all: Vec<&str> = entries().iter().map(|e| e.spec.name).collect();
    out.push_str(&format!(
        "/** Every setting's name, in the table's (the form's) order. */\nexport const SETTING_NAMES = [{}] as const;\nexport type SettingName = (typeof SETTING_NAMES)[number];\n\n",
        list(&all)
    ));
    // A type, not an interface: a `Settings` is then also a `{name: value}` record (what the
    // core's functions and a job file take).
    out.push_str("/** Every setting (docs/spec.md 5.4.1). */\nexport type Settings = {\n");
    for e in entries() {
        let spec = &e.spec;
        let ty = match spec.domain.kind {
            Kind::Number | Kind::Integer => "number".to_string(),
            Kind::Bool => "boolean".to_string(),
            // a list of units ("2,0,1") as well as the choices
            Kind::Order => "string".to_string(),
            Kind::Enum => spec
                .domain
                .choices
                .iter()
                .map(|c| format!("\"{c}\""))
                .collect::<Vec<_>>()
                .join(" | "),
        };
        let unit = if spec.domain.unit.is_empty() {
            String::new()
        } else {
            format!(" ({})", spec.domain.unit)
        };
        let doc = format!("{}{unit}", spec.description).replace("*/", "* /");
        out.push_str(&format!("  /** {doc} */\n  {}: {ty};\n", spec.name));
    }
    out.push_str("};\n\n");
    let defaults: Vec<String> = (entries().iter())
        .map(|e| format!("  {}: {},\n", e.spec.name, e.spec.default))
        .collect();
    out.push_str(&format!(
        "/** Every setting's default (the core's `Settings::default()`). */\nexport const DEFAULTS: Readonly<Settings> = {{\n{}}};\n",
        defaults.concat()
    ));
    out
}

/// Whether the header of a job whose units `used` print lists the setting of `e` (`second`:
/// a unit other than 0 prints, `beyond`: one beyond unit 1).
fn shown(e: &Entry, used: &impl Fn(UnitId) -> bool, second: bool, beyond: bool) -> bool {
    match (e.shown, e.slot) {
        (Shown::SecondUnit, _) => second,
        (Shown::BeyondTwo, _) => beyond,
        (_, Slot::Job) => true,
        (Shown::Always, Slot::Unit(u, _)) if u.0 < 2 => true,
        (_, Slot::Unit(u, _)) => u.0 == 0 || used(u),
    }
}

/// Whether a setting is one of those only a machine of more than two units has (`units`, the
/// settings of units 2 and up): written only when they differ from their defaults, so
/// settings written before read and write as they did.
fn beyond_two(e: &Entry) -> bool {
    e.shown == Shown::BeyondTwo || matches!(e.slot, Slot::Unit(u, _) if u.0 >= 2)
}

/// Written as one flat object `{"name": value, …}` in schema order.
impl Serialize for Settings {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        for e in entries() {
            let v = self.value_at(e.slot, e.spec.name);
            if beyond_two(e) && v == e.spec.default {
                continue;
            }
            map.serialize_entry(e.spec.name, &v)?;
        }
        map.end()
    }
}

/// Read from a flat object; missing names take their defaults, an unknown name is refused.
/// Not range-checked ([`Settings::validate`]).
impl<'de> Deserialize<'de> for Settings {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let map = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
        let mut s = Settings::default();
        for (k, v) in map {
            s.set_value(&k, v).map_err(serde::de::Error::custom)?;
        }
        Ok(s)
    }
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
        // Every name reads and writes its own field, and a settings object round-trips.
        let names = names();
        let mut s = Settings::default();
        for (i, name) in names.iter().enumerate() {
            assert_eq!(names.iter().filter(|n| *n == name).count(), 1, "{name}");
            let spec = entry(name).unwrap();
            let v = match spec.spec.domain.kind {
                Kind::Number => serde_json::json!(spec.spec.domain.max.unwrap() - 1e-3 * i as f64),
                Kind::Integer => serde_json::json!(spec.spec.domain.max.unwrap() as u64),
                _ => s.value(name).unwrap(),
            };
            s.set_value(name, v.clone()).unwrap();
            assert_eq!(s.value(name).unwrap(), v, "{name}");
        }
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<Settings>(&text).unwrap(), s);
        assert_eq!(
            serde_json::to_value(&s).unwrap().as_object().unwrap().len(),
            names.len()
        );
        Settings::default().validate().unwrap();
        // The settings of units 2 and up, and `units`, are written only when set.
        let d = serde_json::to_value(Settings::default()).unwrap();
        assert!(d.get("units").is_none() && d.get("unit2_droplet_aspect").is_none());
        assert!(d.get("unit1_droplet_aspect").is_some());
    }

    #[test]
    fn the_pages_settings_type_is_up_to_date() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/www/core/settings.gen.ts");
        let made = typescript();
        if std::env::var_os("DROPSLICE_WRITE_GENERATED").is_some() {
            std::fs::write(path, &made).unwrap();
        }
        let file = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            file == made,
            "www/core/settings.gen.ts is stale: run DROPSLICE_WRITE_GENERATED=1 cargo test --release --lib settings"
        );
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
            assert_eq!(s.domain.kind, Kind::Number, "{}", s.name);
            assert!(
                s.domain.min.is_some() && s.domain.max.is_some(),
                "{}",
                s.name
            );
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
        assert_eq!(s.support, Support::Unit(UnitId(1)));
        s.set("layer_height", "-1").unwrap();
        let e = s.validate().unwrap_err().to_string();
        assert!(
            e.contains("layer_height") && e.contains("at least 0.0001"),
            "{e}"
        );
    }
}
