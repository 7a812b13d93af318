//! Profiles (docs/spec.md "Profiles"): a named set of settings of one kind, stored as JSON
//! `{"name": …, "kind": "machine" | "material", "settings": {…}}`.
//!
//! A machine profile holds the plate and the units' rates and speeds ([`MACHINE_KEYS`]); a
//! material profile a unit's droplet aspect, density and shrinkage ([`MATERIAL_KEYS`], with
//! `unit1_` names for unit 1). A key of the other kind, or of neither, is refused: a profile
//! is meant to be swapped for another of its kind without touching the rest of the settings
//! (the layer height, the contours, the support… belong to the job, `--set` or a settings
//! file). Every value is checked by the schema as `--set` checks it.

use super::{Settings, schema};
use crate::base::error::{Error, quote};
use serde::{Deserialize, Serialize};

/// Largest profile file read (a profile holds at most a dozen settings).
pub const MAX_PROFILE_BYTES: usize = 64 << 10;
/// Longest profile name, in characters.
pub const MAX_PROFILE_NAME_CHARS: usize = 100;

/// The settings a machine profile may hold.
pub const MACHINE_KEYS: [&str; 6] = [
    "plate_x",
    "plate_y",
    "plate_z",
    "droplet_rate",
    "unit1_droplet_rate",
    "travel_speed",
];

/// The settings a material profile may hold.
pub const MATERIAL_KEYS: [&str; 8] = [
    "droplet_aspect",
    "material_density",
    "shrink_xy",
    "shrink_z",
    "unit1_droplet_aspect",
    "unit1_material_density",
    "unit1_shrink_xy",
    "unit1_shrink_z",
];

/// What a profile describes.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProfileKind {
    Machine,
    Material,
}

impl ProfileKind {
    /// The settings a profile of this kind may hold.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            ProfileKind::Machine => &MACHINE_KEYS,
            ProfileKind::Material => &MATERIAL_KEYS,
        }
    }

    fn word(self) -> &'static str {
        match self {
            ProfileKind::Machine => "machine",
            ProfileKind::Material => "material",
        }
    }
}

/// A checked profile: every key of its kind, every value in the schema's range.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Profile {
    pub name: String,
    pub kind: ProfileKind,
    #[cfg_attr(
        target_arch = "wasm32",
        tsify(type = "Record<string, number | boolean | string>")
    )]
    pub settings: serde_json::Map<String, serde_json::Value>,
}

/// The profile as written, before the checks.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    name: String,
    kind: ProfileKind,
    settings: serde_json::Map<String, serde_json::Value>,
}

fn bad(message: String) -> Error {
    Error::Setting {
        name: String::new(),
        message,
    }
}

impl Profile {
    /// Parses and checks a profile's JSON text (at most [`MAX_PROFILE_BYTES`]).
    pub fn from_json(text: &str) -> Result<Profile, Error> {
        if text.len() > MAX_PROFILE_BYTES {
            return Err(bad(format!(
                "the profile is {} bytes, more than the {MAX_PROFILE_BYTES} a profile may have",
                text.len()
            )));
        }
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| bad(format!("not JSON: {}", quote(&e.to_string()))))?;
        Profile::from_value(value)
    }

    /// A profile from a parsed JSON value (e.g. from the page), checked.
    pub fn from_value(value: serde_json::Value) -> Result<Profile, Error> {
        let raw: Raw = serde_json::from_value(value).map_err(|e| {
            bad(format!(
                "not a profile ({{\"name\": …, \"kind\": \"machine\" | \"material\", \"settings\": {{…}}}}): {}",
                quote(&e.to_string())
            ))
        })?;
        Profile::checked(raw)
    }

    fn checked(raw: Raw) -> Result<Profile, Error> {
        let name = raw.name.trim();
        if name.is_empty() || name.chars().count() > MAX_PROFILE_NAME_CHARS {
            return Err(bad(format!(
                "a profile's name must have 1 to {MAX_PROFILE_NAME_CHARS} characters"
            )));
        }
        if name.chars().any(char::is_control) {
            return Err(bad(
                "a profile's name must not hold control characters (line breaks, tabs)".into(),
            ));
        }
        let kind = raw.kind;
        let known = schema::names();
        for (key, value) in &raw.settings {
            if !kind.keys().contains(&key.as_str()) {
                let other = match kind {
                    ProfileKind::Machine => ProfileKind::Material,
                    ProfileKind::Material => ProfileKind::Machine,
                };
                let why = if other.keys().contains(&key.as_str()) {
                    format!("it belongs in a {} profile", other.word())
                } else if known.contains(&key.as_str()) {
                    "it belongs to the job (give it with --set or a settings file)".into()
                } else {
                    "there is no such setting".into()
                };
                return Err(Error::Setting {
                    name: quote(key),
                    message: format!(
                        "a {} profile holds only {}; {why}",
                        kind.word(),
                        kind.keys().join(", ")
                    ),
                });
            }
            let mut s = Settings::default();
            s.set_value(key, value.clone())?;
            s.validate()?;
        }
        Ok(Profile {
            name: name.to_string(),
            kind,
            settings: raw.settings,
        })
    }

    /// Sets the profile's values in `settings` (checked when the profile was made).
    pub fn apply(&self, settings: &mut Settings) -> Result<(), Error> {
        for (key, value) in &self.settings {
            settings.set_value(key, value.clone())?;
        }
        Ok(())
    }

    /// How the header names it: `name (kind)`.
    pub fn label(&self) -> String {
        format!("{} ({})", self.name, self.kind.word())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_profile_applies_its_values() {
        let p = Profile::from_json(
            r#"{"name": "PC", "kind": "material", "settings": {"shrink_xy": 0.8, "material_density": 1.2}}"#,
        )
        .unwrap();
        let mut s = Settings::default();
        p.apply(&mut s).unwrap();
        assert_eq!((s.shrink_xy, s.material_density), (0.8, 1.2));
        assert_eq!(p.label(), "PC (material)");
    }

    #[test]
    fn bad_profiles_are_refused_with_the_key_named() {
        let cases = [
            (
                r#"{"name": "m", "kind": "machine", "settings": {"shrink_xy": 1}}"#,
                "material profile",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"layer_height": 0.2}}"#,
                "belongs to the job",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"colour": 1}}"#,
                "no such setting",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"shrink_z": 9}}"#,
                "out of range",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"shrink_z": "a"}}"#,
                "finite number",
            ),
            (
                r#"{"name": "", "kind": "material", "settings": {}}"#,
                "name",
            ),
            (r#"{"name": "m", "kind": "tool", "settings": {}}"#, "kind"),
            (
                r#"{"name": "m", "kind": "machine", "settings": {}, "x": 1}"#,
                "not a profile",
            ),
            ("[1, 2]", "not a profile"),
        ];
        for (text, expected) in cases {
            let e = Profile::from_json(text).unwrap_err().to_string();
            assert!(e.contains(expected), "{text}: {e}");
        }
        let big = format!(
            r#"{{"name": "{}", "kind": "machine", "settings": {{}}}}"#,
            "a".repeat(MAX_PROFILE_BYTES)
        );
        assert!(
            Profile::from_json(&big)
                .unwrap_err()
                .to_string()
                .contains("bytes")
        );
    }
}
