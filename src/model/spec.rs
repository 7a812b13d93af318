//! The job file (docs/spec.md "Build jobs"): [`JobSpec`] (the settings of the
//! layers and the parts) and [`PartSpec`] (a file or one 3MF build item, its transform, copies,
//! unit), their validation with messages naming the part and the key, and the names as
//! messages and the header show them ([`clean_name`]).
//!
//! From one named type to the next: job-file JSON —[`JobSpec::from_json`]→ [`JobSpec`];
//! files —[`Model::read`]→ [`Model`]s; models + spec —[`layout`]→ [`Layout`] (one
//! [`Instance`] per copy of a part: its 4×4 matrix, bounds, where it went);
//! `Job::from_models` (pipeline/build.rs) then welds each part once, places every instance
//! with [`crate::model::mesh::Mesh::place`] (the very code of `Job::new`'s `Mesh::transform`)
//! and slices the merged mesh. The page's helpers: [`lay_flat`] and [`display_mesh`].
//!
//! [`Model::read`]: crate::model::models::Model::read
//! [`Model`]: crate::model::models::Model
//! [`layout`]: crate::model::layout::layout
//! [`Layout`]: crate::model::layout::Layout
//! [`Instance`]: crate::model::layout::Instance
//! [`lay_flat`]: crate::model::layout::lay_flat
//! [`display_mesh`]: crate::model::display::display_mesh

use crate::base::error::Error;
use crate::base::settings::{self, Domain, SettingSpec, Settings};
use crate::model::mesh::Placement;
use serde::{Deserialize, Serialize};

/// Most parts a job file may list.
pub const MAX_PARTS: usize = 256;
/// Most instances (parts × copies) a job may have.
pub const MAX_INSTANCES: usize = 500;
/// Most copies of one part.
pub const MAX_COPIES: u32 = 100;
/// Largest job file read (bytes).
pub const MAX_JOB_FILE_BYTES: usize = 1 << 20;
/// Longest name kept for messages and the header (characters).
pub const MAX_NAME_CHARS: usize = 80;
/// Most discharge units a part may name (the setting `units` may allow fewer).
pub const UNITS: u8 = crate::base::settings::MAX_UNITS as u8;

/// The settings that belong to a part, not to the job (the settings schema flags them).
pub use crate::base::settings::PART_KEYS;

/// The keys of a part in the job file, in the order messages list them: the file, the 3MF
/// item, the [`PART_KEYS`], then the mirrors, copies, unit and name.
fn part_spec_keys() -> Vec<&'static str> {
    let mut keys = vec!["file", "item"];
    keys.extend(PART_KEYS);
    keys.extend(["mirror_x", "mirror_y", "mirror_z", "copies", "unit", "name"]);
    keys
}

/// What the page needs to check a job's parts: every number a part carries with its range
/// (the settings the schema flags [`SettingSpec::part`], then `copies` and `unit`) and the
/// job's counts. Published to the page as the core's `job_schema`.
#[derive(Clone, Debug, Serialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct JobSchema {
    pub part_numbers: Vec<SettingSpec>,
    /// [`MAX_PARTS`].
    pub max_parts: usize,
    /// [`MAX_INSTANCES`].
    pub max_instances: usize,
    /// [`MAX_JOB_FILE_BYTES`].
    pub max_job_file_bytes: usize,
}

/// The job schema the page is given (the core's `job_schema`): the part keys' rows of the
/// settings schema, then `copies` and `unit`, and the job's limits.
pub fn job_schema() -> JobSchema {
    let mut part_numbers: Vec<SettingSpec> =
        settings::schema().into_iter().filter(|s| s.part).collect();
    let whole = |name, min: u32, max: u32, default: u32, description| SettingSpec {
        name,
        domain: Domain::whole("", min.into(), max.into()),
        group: "Part",
        description,
        part: true,
        profile: None,
        layout: false,
        default: default.into(),
    };
    part_numbers.push(whole(
        "copies",
        1,
        MAX_COPIES,
        1,
        "Copies of the part on the plate",
    ));
    // Any unit up to the most a machine may have; the job's `units` bounds it further.
    part_numbers.push(whole(
        "unit",
        0,
        crate::base::settings::MAX_UNITS as u32 - 1,
        0,
        "The discharge unit that prints the part",
    ));
    JobSchema {
        part_numbers,
        max_parts: MAX_PARTS,
        max_instances: MAX_INSTANCES,
        max_job_file_bytes: MAX_JOB_FILE_BYTES,
    }
}

/// A job: the settings of the layers and the parts to print.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JobSpec {
    pub settings: Settings,
    pub parts: Vec<PartSpec>,
}

fn one() -> f64 {
    1.0
}
fn one_copy() -> u32 {
    1
}
fn is_false(b: &bool) -> bool {
    !*b
}

/// One part of a job file: a file (or one build item of a 3MF) and its transform.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// The file's name: in a job file a path relative to the job file's folder; on the page
    /// the key of the file in the job's [`Model`](crate::model::models::Model)s.
    pub file: String,
    /// For a 3MF: one build item by 0-based index; `None`: the whole build, its items in their
    /// relative positions, placed as one group.
    #[serde(default)]
    pub item: Option<usize>,
    #[serde(default)]
    pub rotate_x: f64,
    #[serde(default)]
    pub rotate_y: f64,
    #[serde(default)]
    pub rotate_z: f64,
    #[serde(default = "one")]
    pub scale_x: f64,
    #[serde(default = "one")]
    pub scale_y: f64,
    #[serde(default = "one")]
    pub scale_z: f64,
    /// Mirrored along the plate's x, y, z (after the rotation and the scale, before the
    /// bounding box minimum goes to the origin); its facets turned so that they face out.
    #[serde(default, skip_serializing_if = "is_false")]
    pub mirror_x: bool,
    #[serde(default, skip_serializing_if = "is_false")]
    pub mirror_y: bool,
    #[serde(default, skip_serializing_if = "is_false")]
    pub mirror_z: bool,
    /// Where the bounding box minimum goes (with `place_y`); `None`: arranged.
    #[serde(default)]
    pub place_x: Option<f64>,
    #[serde(default)]
    pub place_y: Option<f64>,
    #[serde(default)]
    pub place_angle: f64,
    #[serde(default = "one_copy")]
    pub copies: u32,
    /// The discharge unit that prints it (0 … `units` − 1).
    #[serde(default)]
    pub unit: u8,
    /// A name for the page and the header (default: the part's name in its file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
}

impl PartSpec {
    /// A part of `file` with no transform, arranged, one copy, unit 0.
    pub fn new(file: &str) -> PartSpec {
        PartSpec::shaped_like(file, &Settings::default())
    }

    /// A part of `file` rotated and scaled as `s` says, arranged, one copy, unit 0.
    pub fn shaped_like(file: &str, s: &Settings) -> PartSpec {
        PartSpec {
            file: file.to_string(),
            item: None,
            rotate_x: s.rotate_x,
            rotate_y: s.rotate_y,
            rotate_z: s.rotate_z,
            scale_x: s.scale_x,
            scale_y: s.scale_y,
            scale_z: s.scale_z,
            mirror_x: false,
            mirror_y: false,
            mirror_z: false,
            place_x: None,
            place_y: None,
            place_angle: 0.0,
            copies: 1,
            unit: 0,
            name: None,
        }
    }

    /// Its transform with the bounding box minimum moved by `place`, its scale compensating
    /// the shrinkage of its unit's material (`settings`' `shrink_*` or `unitN_shrink_*`); a
    /// mirrored axis is a negative scale ([`Placement::mirrors`]).
    pub fn placement(&self, place: [f64; 2], settings: &Settings) -> Placement {
        let sign = |m: bool| if m { -1.0 } else { 1.0 };
        Placement {
            rotate: [self.rotate_x, self.rotate_y, self.rotate_z],
            scale: [
                self.scale_x * sign(self.mirror_x),
                self.scale_y * sign(self.mirror_y),
                self.scale_z * sign(self.mirror_z),
            ],
            place_angle: self.place_angle,
            place,
        }
        .compensated(settings.shrink_factors(crate::base::settings::UnitId(self.unit)))
    }

    /// The explicit placement, if any.
    pub fn place(&self) -> Option<[f64; 2]> {
        Some([self.place_x?, self.place_y?])
    }

    /// The value of a [`PART_KEYS`] key (`None` for an unplaced part's place, or another key).
    pub fn number(&self, key: &str) -> Option<f64> {
        if !PART_KEYS.contains(&key) {
            return None;
        }
        // The fields are named as the keys (a place not given is `null`).
        serde_json::to_value(self).ok()?.get(key)?.as_f64()
    }

    /// Checks every value (`i` names the part in messages).
    pub fn validate(&self, i: usize) -> Result<(), Error> {
        let bad = |key: &str, what: String| Err(Error::Job(format!("parts[{i}].{key}: {what}")));
        if self.file.trim().is_empty() {
            return bad("file", "is empty: give the model file's name".into());
        }
        if self.file.len() > 4096 {
            return bad("file", "is longer than 4096 bytes".into());
        }
        // The ranges of the settings of the same name (the schema's part keys); the place
        // after the others, as a pair.
        let ranges: Vec<SettingSpec> = settings::schema().into_iter().filter(|s| s.part).collect();
        let check = |key: &str, x: f64| {
            let domain = ranges.iter().find(|s| s.name == key).map(|s| &s.domain);
            match domain.and_then(|d| Some((d, d.range_words()?))) {
                Some((d, _)) if d.admits(x) => Ok(()),
                Some((_, range)) => Err(Error::Job(format!(
                    "parts[{i}].{key}: {} is out of range: it must be a finite number {range}",
                    crate::base::error::number(x)
                ))),
                None => Err(Error::Internal(format!("no range for the part key {key}"))),
            }
        };
        for key in PART_KEYS {
            if let Some(x) = self.number(key)
                && *key != "place_x"
                && *key != "place_y"
            {
                check(key, x)?;
            }
        }
        match (self.place_x, self.place_y) {
            (Some(x), Some(y)) => {
                check("place_x", x)?;
                check("place_y", y)?;
            }
            (None, None) => {}
            (Some(_), None) => {
                return bad(
                    "place_y",
                    "is missing: give place_x and place_y together, or neither (the part is then arranged)".into(),
                );
            }
            (None, Some(_)) => {
                return bad(
                    "place_x",
                    "is missing: give place_x and place_y together, or neither (the part is then arranged)".into(),
                );
            }
        }
        if !(1..=MAX_COPIES).contains(&self.copies) {
            return bad(
                "copies",
                format!("{} is out of range: 1 to {MAX_COPIES}", self.copies),
            );
        }
        if self.unit >= UNITS {
            return bad(
                "unit",
                format!("{} is not a discharge unit: 0 … {}", self.unit, UNITS - 1),
            );
        }
        if let Some(n) = &self.name
            && n.len() > 1000
        {
            return bad("name", "is longer than 1000 bytes".into());
        }
        Ok(())
    }
}

impl JobSpec {
    /// A job file's text (at most [`MAX_JOB_FILE_BYTES`]).
    pub fn from_json(text: &str) -> Result<JobSpec, Error> {
        if text.len() > MAX_JOB_FILE_BYTES {
            return Err(Error::Job(format!(
                "the job file is {} bytes; at most {MAX_JOB_FILE_BYTES} are read",
                text.len()
            )));
        }
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| {
            Error::Job(format!(
                "the job file is not valid JSON: {}",
                crate::base::error::quote(&e.to_string())
            ))
        })?;
        JobSpec::from_value(value)
    }

    /// A job from parsed JSON (or a JS object from the page):
    /// `{"settings": {…}, "parts": [{"file": "a.stl", …}, …]}`.
    pub fn from_value(value: serde_json::Value) -> Result<JobSpec, Error> {
        use serde_json::Value;
        let Value::Object(mut top) = value else {
            return Err(Error::Job(
                "a job must be an object {\"settings\": {…}, \"parts\": [{\"file\": \"a.stl\"}, …]}".into(),
            ));
        };
        if let Some(k) = top.keys().find(|k| *k != "settings" && *k != "parts") {
            return Err(Error::Job(format!(
                "unknown key '{}': a job has only \"settings\" and \"parts\"",
                crate::base::error::quote(k)
            )));
        }
        let settings = match top.remove("settings") {
            None | Some(Value::Null) => Settings::default(),
            Some(Value::Object(map)) => {
                if let Some(k) = map.keys().find(|k| PART_KEYS.contains(&k.as_str())) {
                    return Err(Error::Job(format!(
                        "settings.{k} belongs to a part: give it in the parts, e.g. {{\"file\": \"a.stl\", \"{k}\": …}}"
                    )));
                }
                Settings::from_value(Value::Object(map))?
            }
            Some(_) => {
                return Err(Error::Job(
                    "\"settings\" must be an object {\"name\": value, …}".into(),
                ));
            }
        };
        let parts = match top.remove("parts") {
            Some(Value::Array(a)) => a,
            _ => {
                return Err(Error::Job(
                    "\"parts\" must be a list of parts [{\"file\": \"a.stl\"}, …]".into(),
                ));
            }
        };
        if parts.is_empty() {
            return Err(Error::Job(
                "the job has no parts: list at least one in \"parts\"".into(),
            ));
        }
        if parts.len() > MAX_PARTS {
            return Err(Error::Job(format!(
                "the job lists {} parts; at most {MAX_PARTS} are allowed",
                parts.len()
            )));
        }
        let parts = parts
            .into_iter()
            .enumerate()
            .map(|(i, v)| part_from_value(i, v))
            .collect::<Result<Vec<_>, _>>()?;
        let spec = JobSpec { settings, parts };
        spec.validate()?;
        Ok(spec)
    }

    /// Checks every part and the counts.
    pub fn validate(&self) -> Result<(), Error> {
        self.settings.validate()?;
        if self.parts.is_empty() {
            return Err(Error::Job("the job has no parts".into()));
        }
        if self.parts.len() > MAX_PARTS {
            return Err(Error::Job(format!(
                "the job lists {} parts; at most {MAX_PARTS} are allowed",
                self.parts.len()
            )));
        }
        for (i, p) in self.parts.iter().enumerate() {
            p.validate(i)?;
            let u = crate::base::settings::UnitId(p.unit);
            let at = format!("parts[{i}].unit");
            self.settings.check_unit(u, &at)?;
        }
        let total: u64 = self.parts.iter().map(|p| p.copies as u64).sum();
        if total > MAX_INSTANCES as u64 {
            return Err(Error::Job(format!(
                "the job has {total} instances (parts × copies); at most {MAX_INSTANCES} are allowed: print fewer copies"
            )));
        }
        if Placement::of_settings(&self.settings) != Placement::of_settings(&Settings::default()) {
            return Err(Error::Job(
                "the job's settings carry a part transform (rotate_*, scale_*, place_*): give it in the parts instead".into(),
            ));
        }
        Ok(())
    }
}

/// One part from JSON, with messages naming the part and the key.
fn part_from_value(i: usize, v: serde_json::Value) -> Result<PartSpec, Error> {
    use serde_json::Value;
    let bad = |key: &str, what: &str| Err(Error::Job(format!("parts[{i}].{key}: {what}")));
    let Value::Object(map) = v else {
        return Err(Error::Job(format!(
            "parts[{i}] must be an object {{\"file\": \"a.stl\", …}}"
        )));
    };
    for (k, v) in &map {
        match k.as_str() {
            "file" | "name" => {
                if !v.is_string() {
                    return bad(k, "must be a text");
                }
            }
            "item" => {
                if !(v.is_null() || v.is_u64()) {
                    return bad(k, "must be a build item's index (0, 1, 2 …) or null");
                }
            }
            "copies" | "unit" => {
                if !v.is_u64() {
                    return bad(k, "must be a whole number");
                }
            }
            "mirror_x" | "mirror_y" | "mirror_z" => {
                if !v.is_boolean() {
                    return bad(k, "must be true (mirrored along that axis) or false");
                }
            }
            "place_x" | "place_y" => {
                if !(v.is_null() || v.as_f64().is_some_and(f64::is_finite)) {
                    return bad(k, "must be a finite number (mm) or null");
                }
            }
            k if PART_KEYS.contains(&k) => {
                if !v.as_f64().is_some_and(f64::is_finite) {
                    return bad(k, "must be a finite number");
                }
            }
            k => {
                return Err(Error::Job(format!(
                    "parts[{i}]: unknown key '{}'; a part has: {}",
                    crate::base::error::quote(k),
                    part_spec_keys().join(", ")
                )));
            }
        }
    }
    if !map.contains_key("file") {
        return bad("file", "is missing: name the model file of the part");
    }
    if let Some(c) = map.get("copies").and_then(Value::as_u64)
        && c > MAX_COPIES as u64
    {
        return bad("copies", &format!("{c} is out of range: 1 to {MAX_COPIES}"));
    }
    if let Some(u) = map.get("unit").and_then(Value::as_u64)
        && u >= UNITS as u64
    {
        return bad(
            "unit",
            &format!("{u} is not a discharge unit: 0 … {}", UNITS - 1),
        );
    }
    let part: PartSpec = serde_json::from_value(Value::Object(map)).map_err(|e| {
        Error::Job(format!(
            "parts[{i}]: {}",
            crate::base::error::quote(&e.to_string())
        ))
    })?;
    part.validate(i)?;
    Ok(part)
}

/// Names as the header and messages show them: one line, at most [`MAX_NAME_CHARS`].
pub fn clean_name(name: &str) -> String {
    let one_line: String = name
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let t = one_line.trim();
    if t.chars().count() > MAX_NAME_CHARS {
        let mut s: String = t.chars().take(MAX_NAME_CHARS - 1).collect();
        s.push('…');
        s
    } else {
        t.to_string()
    }
}
