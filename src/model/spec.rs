//! Build jobs (SPEC.md "Build jobs: several parts"): the job file ([`JobSpec`], [`PartSpec`]),
//! the imported files of a job ([`Model`]), each instance's transform ([`Frame`]), the
//! arrangement on the plate ([`arrange`]) and the [`Layout`] the page draws. Also two helpers
//! for the page: [`lay_flat`] and [`display_mesh`].
//!
//! From one named type to the next: job-file JSON —[`JobSpec::from_json`]→ [`JobSpec`];
//! files —[`Model::read`]→ [`Model`]s; models + spec —[`layout`]→ [`Layout`] (one
//! [`Instance`] per copy of a part: its 4×4 matrix, bounds, where it went);
//! `Job::from_models` (lib.rs) then welds each part once, places every instance with
//! [`crate::model::mesh::Mesh::place`] (the very code of `Job::new`'s `Mesh::transform`) and slices
//! the merged mesh.

use crate::base::error::Error;
use crate::base::geom::{DMat3, DVec3};
use crate::base::settings::{self, Kind, SettingSpec, Settings};
use crate::model::import::stl::{self, Format};
use crate::model::import::{self, Part};
use crate::model::mesh::{Bounds, Placement, rot, rotation};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

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
/// Most discharge units (0 and 1).
pub const UNITS: u8 = 2;

/// The settings that belong to a part, not to the job (the settings schema flags them).
pub use crate::base::settings::PART_KEYS;

/// The keys of a part in the job file, in the order messages list them: the file, the 3MF
/// item, the [`PART_KEYS`], then copies, unit and name.
fn part_spec_keys() -> Vec<&'static str> {
    let mut keys = vec!["file", "item"];
    keys.extend(PART_KEYS);
    keys.extend(["copies", "unit", "name"]);
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
        kind: Kind::Integer,
        unit: "",
        min: Some(min.into()),
        max: Some(max.into()),
        min_exclusive: false,
        choices: &[],
        group: "Part",
        description,
        part: true,
        default: default.into(),
    };
    part_numbers.push(whole(
        "copies",
        1,
        MAX_COPIES,
        1,
        "Copies of the part on the plate",
    ));
    part_numbers.push(whole(
        "unit",
        0,
        u32::from(UNITS) - 1,
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

/// One part of a job file: a file (or one build item of a 3MF) and its transform.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// The file's name: in a job file a path relative to the job file's folder; on the page
    /// the key of the file in the job's [`Model`]s.
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
    /// Where the bounding box minimum goes (with `place_y`); `None`: arranged.
    #[serde(default)]
    pub place_x: Option<f64>,
    #[serde(default)]
    pub place_y: Option<f64>,
    #[serde(default)]
    pub place_angle: f64,
    #[serde(default = "one_copy")]
    pub copies: u32,
    /// The discharge unit that prints it (0 or 1).
    #[serde(default)]
    pub unit: u8,
    /// A name for the page and the header (default: the part's name in its file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
}

impl PartSpec {
    /// A part of `file` with no transform, arranged, one copy, unit 0.
    pub fn new(file: &str) -> PartSpec {
        PartSpec {
            file: file.to_string(),
            item: None,
            rotate_x: 0.0,
            rotate_y: 0.0,
            rotate_z: 0.0,
            scale_x: 1.0,
            scale_y: 1.0,
            scale_z: 1.0,
            place_x: None,
            place_y: None,
            place_angle: 0.0,
            copies: 1,
            unit: 0,
            name: None,
        }
    }

    /// Its transform with the bounding box minimum moved by `place`.
    pub fn placement(&self, place: [f64; 2]) -> Placement {
        Placement {
            rotate: [self.rotate_x, self.rotate_y, self.rotate_z],
            scale: [self.scale_x, self.scale_y, self.scale_z],
            place_angle: self.place_angle,
            place,
        }
    }

    /// The explicit placement, if any.
    pub fn place(&self) -> Option<[f64; 2]> {
        Some([self.place_x?, self.place_y?])
    }

    /// The value of a [`PART_KEYS`] key (`None` for an unplaced part's place, or another key).
    pub fn number(&self, key: &str) -> Option<f64> {
        match key {
            "rotate_x" => Some(self.rotate_x),
            "rotate_y" => Some(self.rotate_y),
            "rotate_z" => Some(self.rotate_z),
            "scale_x" => Some(self.scale_x),
            "scale_y" => Some(self.scale_y),
            "scale_z" => Some(self.scale_z),
            "place_x" => self.place_x,
            "place_y" => self.place_y,
            "place_angle" => Some(self.place_angle),
            _ => None,
        }
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
        let check = |key: &str, x: f64| match ranges.iter().find(|s| s.name == key) {
            Some(SettingSpec {
                min: Some(lo),
                max: Some(hi),
                min_exclusive,
                ..
            }) => check_range(i, key, x, *lo, *hi, *min_exclusive),
            _ => Err(Error::Internal(format!("no range for the part key {key}"))),
        };
        for key in PART_KEYS {
            if let Some(x) = self.number(key)
                && key != "place_x"
                && key != "place_y"
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
                format!("{} is not a discharge unit: 0 or 1", self.unit),
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

fn check_range(
    i: usize,
    key: &str,
    x: f64,
    lo: f64,
    hi: f64,
    exclusive: bool,
) -> Result<(), Error> {
    let below = if exclusive { x <= lo } else { x < lo };
    if !x.is_finite() || below || x > hi {
        let lower = if exclusive {
            "greater than"
        } else {
            "at least"
        };
        return Err(Error::Job(format!(
            "parts[{i}].{key}: {} is out of range: it must be a finite number {lower} {lo} and at most {hi}",
            crate::base::error::number(x)
        )));
    }
    Ok(())
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
        return bad("unit", &format!("{u} is not a discharge unit: 0 or 1"));
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
        let format = match import::detect(bytes, name) {
            Format::Binary | Format::Ascii => {
                let (triangles, format) = stl::parse(bytes)?;
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
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelInfo {
    pub name: String,
    pub format: Format,
    pub triangles: usize,
    /// In the file's coordinates (mm, after its units and 3MF transforms).
    pub bounds: Bounds,
    /// The 3MF build items (one item for STL and OBJ).
    pub items: Vec<ItemInfo>,
    pub warnings: Vec<String>,
    /// See [`crate::model::prepare::suggested_scale`].
    pub suggested_scale: Option<f64>,
}

/// One build item of a [`ModelInfo`].
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ItemInfo {
    pub name: String,
    pub triangles: usize,
    pub bounds: Bounds,
}

/// The bounding box of triangles.
pub fn bounds_of(tris: &[[[f32; 3]; 3]]) -> Bounds {
    let mut b = Bounds {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };
    for p in corners(tris) {
        grow(&mut b, p, p);
    }
    b
}

/// `b` grown to hold the box `lo`..`hi`.
fn grow(b: &mut Bounds, lo: [f64; 3], hi: [f64; 3]) {
    for (k, (l, h)) in lo.iter().zip(hi).enumerate() {
        b.min[k] = b.min[k].min(*l);
        b.max[k] = b.max[k].max(h);
    }
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
        let mut bounds = Bounds {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        for i in &items {
            grow(&mut bounds, i.bounds.min, i.bounds.max);
        }
        let size = bounds.size();
        let suggested_scale = crate::model::prepare::suggested_scale(&size);
        let largest = size[0].max(size[1]).max(size[2]);
        let warnings = match suggested_scale {
            Some(f) if f > 1.0 => vec![format!(
                "the part is only {largest:.3} mm across: if the file is in inches, scale it by {f}"
            )],
            Some(f) => vec![format!(
                "the part is {largest:.0} mm across: if the file is in micrometres, scale it by {f}"
            )],
            None => Vec::new(),
        };
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

/// An instance's transform before its last move: the rotation and scale of [`Placement`],
/// the bounding box minimum after them (`min1`, moved to the origin), the rotation on the
/// plate and the bounding box that gives (`qmin`, `qmax`; `qmin.z` = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub rotation: DMat3,
    pub scale: DVec3,
    pub min1: DVec3,
    pub angle: DMat3,
    pub qmin: DVec3,
    pub qmax: DVec3,
}

impl Frame {
    /// The frame of `points` (every vertex of the part) under `p` (its `place` is not used).
    /// The same arithmetic as [`crate::model::mesh::Mesh::place`], so `qmin + place` is exactly the
    /// placed mesh's bounding box.
    pub fn of<I: Iterator<Item = [f64; 3]> + Clone>(points: I, p: &Placement) -> Option<Frame> {
        let r = rotation(p.rotate);
        let scale = DVec3::from(p.scale);
        let step1 = |v: [f64; 3]| r * DVec3::from(v) * scale;
        let mut min1 = DVec3::INFINITY;
        let mut any = false;
        for v in points.clone() {
            min1 = min1.min(step1(v));
            any = true;
        }
        if !any {
            return None;
        }
        let angle = rot(2, p.place_angle);
        let (mut qmin, mut qmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for v in points {
            let q = angle * (step1(v) - min1);
            qmin = qmin.min(q);
            qmax = qmax.max(q);
        }
        Some(Frame {
            rotation: r,
            scale,
            min1,
            angle,
            qmin,
            qmax,
        })
    }

    /// The 4×4 matrix (column-major) of the whole transform with the final move `place`:
    /// model coordinates → plate coordinates.
    pub fn matrix(&self, place: [f64; 2]) -> [f64; 16] {
        let l = self.angle * DMat3::from_diagonal(self.scale) * self.rotation;
        let t = self.angle * (-self.min1) + DVec3::new(place[0], place[1], 0.0);
        let c = l.to_cols_array();
        [
            c[0], c[1], c[2], 0.0, c[3], c[4], c[5], 0.0, c[6], c[7], c[8], 0.0, t.x, t.y, t.z, 1.0,
        ]
    }
}

/// One copy of a part on the plate.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Instance {
    /// The part's index in the job's `parts` (from 0).
    pub part: usize,
    /// The copy's index (from 0).
    pub copy: usize,
    /// How many copies the part has.
    pub copies: usize,
    pub name: String,
    pub file: String,
    /// The 3MF build item (from 0), `None`: the whole file.
    pub item: Option<usize>,
    /// For a 3MF item, the object it refers to.
    pub object: Option<String>,
    pub rotate: [f64; 3],
    pub scale: [f64; 3],
    pub place_angle: f64,
    /// Placed by the job (`place_x`, `place_y`) rather than arranged.
    pub placed: bool,
    /// The final move: `place_x`, `place_y` when placed; else where the arrangement put the
    /// bounding box minimum.
    pub at: [f64; 2],
    pub unit: u8,
    /// Column-major 4×4: the part's model coordinates (after import) → plate coordinates, the
    /// exact transform applied before slicing.
    pub matrix: [f64; 16],
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// The final move given to [`crate::model::mesh::Mesh::place`].
    #[serde(skip)]
    pub shift: [f64; 2],
}

/// Where every instance goes.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Layout {
    pub instances: Vec<Instance>,
    pub bounds: Bounds,
    pub warnings: Vec<String>,
}

/// An axis-aligned rectangle on the plate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub min: [f64; 2],
    pub max: [f64; 2],
}

impl Rect {
    /// Whether the two come closer than `gap` (touching at exactly `gap` is allowed).
    pub fn too_close(&self, o: &Rect, gap: f64) -> bool {
        let eps = 1e-9 * (1.0 + gap);
        (0..2).all(|k| self.min[k] < o.max[k] + gap - eps && o.min[k] < self.max[k] + gap - eps)
    }
}

/// Bottom-left arrangement: every box of `sizes` (width, depth) gets a slot (its minimum
/// corner) on the plate [0, plate_x] × [0, plate_y], at least `gap` from every other box and
/// every `fixed` one; `None` where it does not fit. The boxes are taken largest footprint first
/// (stable); each goes to the lowest y, then lowest x, of the candidates: the origin, right of
/// and above every box already there, and those at x = 0 or y = 0.
pub fn arrange(
    fixed: &[Rect],
    sizes: &[[f64; 2]],
    plate: [f64; 2],
    gap: f64,
) -> Vec<Option<[f64; 2]>> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by(|&a, &b| {
        let area = |i: usize| sizes[i][0] * sizes[i][1];
        area(b).total_cmp(&area(a))
    });
    let mut there: Vec<Rect> = fixed.to_vec();
    let mut slots = vec![None; sizes.len()];
    let eps = 1e-9 * (1.0 + plate[0].max(plate[1]));
    for i in order {
        let [w, d] = sizes[i];
        if w > plate[0] + eps || d > plate[1] + eps {
            continue;
        }
        let mut candidates = vec![[0.0, 0.0]];
        for r in &there {
            let (x, y) = (r.max[0] + gap, r.max[1] + gap);
            candidates.extend([[x, r.min[1]], [r.min[0], y], [x, 0.0], [0.0, y]]);
        }
        candidates.retain(|c| {
            c[0] >= -eps && c[1] >= -eps && c[0] + w <= plate[0] + eps && c[1] + d <= plate[1] + eps
        });
        candidates.sort_by(|a, b| a[1].total_cmp(&b[1]).then(a[0].total_cmp(&b[0])));
        let found = candidates.into_iter().find(|c| {
            let r = Rect {
                min: *c,
                max: [c[0] + w, c[1] + d],
            };
            !there.iter().any(|o| r.too_close(o, gap))
        });
        if let Some(c) = found {
            there.push(Rect {
                min: c,
                max: [c[0] + w, c[1] + d],
            });
            slots[i] = Some(c);
        }
    }
    slots
}

/// Where every instance of `spec` goes, given each part's [`Frame`] (`frames[i]` for
/// `spec.parts[i]`). Refuses a job whose arranged instances do not fit the plate (but one
/// instance alone goes to the origin, with a warning, however large).
pub fn place_instances(
    models: &[&Model],
    spec: &JobSpec,
    frames: &[Frame],
) -> Result<Layout, Error> {
    let s = &spec.settings;
    let plate = [s.plate_x, s.plate_y];
    let gap = s.part_spacing;
    let mut warnings = Vec::new();
    let mut instances = Vec::new();
    let mut fixed = Vec::new();
    let mut free: Vec<(usize, usize)> = Vec::new();
    let total: usize = spec.parts.iter().map(|p| p.copies as usize).sum();
    for (i, p) in spec.parts.iter().enumerate() {
        let f = &frames[i];
        for copy in 0..p.copies as usize {
            match p.place() {
                Some(at) if copy == 0 => {
                    let r = Rect {
                        min: [f.qmin.x + at[0], f.qmin.y + at[1]],
                        max: [f.qmax.x + at[0], f.qmax.y + at[1]],
                    };
                    let eps = 1e-9 * (1.0 + plate[0].max(plate[1]));
                    if r.min[0] < -eps
                        || r.min[1] < -eps
                        || r.max[0] > plate[0] + eps
                        || r.max[1] > plate[1] + eps
                    {
                        warnings.push(format!(
                            "parts[{i}] ({}) reaches outside the plate ({} × {} mm): X{:.1}..{:.1} Y{:.1}..{:.1}",
                            clean_name(&part_label(models[i], p)),
                            plate[0],
                            plate[1],
                            r.min[0],
                            r.max[0],
                            r.min[1],
                            r.max[1]
                        ));
                    }
                    fixed.push(r);
                    instances.push(instance(models[i], i, copy, p, f, true, at, [at[0], at[1]]));
                }
                _ => {
                    free.push((i, copy));
                    // Filled in below.
                    instances.push(instance(
                        models[i],
                        i,
                        copy,
                        p,
                        f,
                        false,
                        [0.0, 0.0],
                        [0.0, 0.0],
                    ));
                }
            }
        }
    }
    let sizes: Vec<[f64; 2]> = free
        .iter()
        .map(|&(i, _)| {
            let f = &frames[i];
            [f.qmax.x - f.qmin.x, f.qmax.y - f.qmin.y]
        })
        .collect();
    let mut slots = arrange(&fixed, &sizes, plate, gap);
    if total == 1 && free.len() == 1 && slots[0].is_none() {
        let [w, d] = sizes[0];
        warnings.push(format!(
            "the part ({w:.1} × {d:.1} mm) is larger than the plate ({} × {} mm); it is placed at the origin",
            plate[0], plate[1]
        ));
        slots[0] = Some([0.0, 0.0]);
    }
    let missing: Vec<(usize, usize)> = free
        .iter()
        .zip(&slots)
        .filter(|(_, s)| s.is_none())
        .map(|(&ic, _)| ic)
        .collect();
    if !missing.is_empty() {
        let mut parts: Vec<String> = Vec::new();
        for (i, p) in spec.parts.iter().enumerate() {
            let n = missing.iter().filter(|m| m.0 == i).count();
            if n > 0 {
                let f = &frames[i];
                parts.push(format!(
                    "parts[{i}] ({}, {:.1} × {:.1} mm): {n} of {} cop{}",
                    clean_name(&part_label(models[i], p)),
                    f.qmax.x - f.qmin.x,
                    f.qmax.y - f.qmin.y,
                    p.copies,
                    if p.copies == 1 { "y" } else { "ies" }
                ));
            }
        }
        return Err(Error::Job(format!(
            "not every part fits on the plate ({} × {} mm, part_spacing {} mm); these do not: {}. Use a larger plate (plate_x, plate_y), fewer copies or a smaller part_spacing",
            plate[0],
            plate[1],
            gap,
            parts.join("; ")
        )));
    }
    let mut k = 0;
    for inst in instances.iter_mut() {
        if inst.placed {
            continue;
        }
        let slot = slots[k].expect("every instance has a slot");
        k += 1;
        let f = &frames[inst.part];
        let shift = [slot[0] - f.qmin.x, slot[1] - f.qmin.y];
        inst.at = slot;
        inst.shift = shift;
        inst.matrix = f.matrix(shift);
        inst.min = [f.qmin.x + shift[0], f.qmin.y + shift[1], f.qmin.z];
        inst.max = [f.qmax.x + shift[0], f.qmax.y + shift[1], f.qmax.z];
    }
    let mut bounds = Bounds {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };
    for inst in &instances {
        grow(&mut bounds, inst.min, inst.max);
    }
    Ok(Layout {
        instances,
        bounds,
        warnings,
    })
}

/// `name` of the spec, else the part's name in its file.
fn part_label(model: &Model, p: &PartSpec) -> String {
    p.name.clone().unwrap_or_else(|| model.part_name(p.item))
}

#[allow(clippy::too_many_arguments)]
fn instance(
    model: &Model,
    part: usize,
    copy: usize,
    p: &PartSpec,
    f: &Frame,
    placed: bool,
    at: [f64; 2],
    shift: [f64; 2],
) -> Instance {
    Instance {
        part,
        copy,
        copies: p.copies as usize,
        name: clean_name(&part_label(model, p)),
        file: clean_name(&p.file),
        item: p.item,
        object: p
            .item
            .and_then(|i| model.parts.get(i))
            .and_then(|x| x.source_object.clone())
            .map(|o| clean_name(&o)),
        rotate: [p.rotate_x, p.rotate_y, p.rotate_z],
        scale: [p.scale_x, p.scale_y, p.scale_z],
        place_angle: p.place_angle,
        placed,
        at,
        unit: p.unit,
        matrix: f.matrix(shift),
        min: [f.qmin.x + shift[0], f.qmin.y + shift[1], f.qmin.z],
        max: [f.qmax.x + shift[0], f.qmax.y + shift[1], f.qmax.z],
        shift,
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

/// The layout of a job from its imported files, without building the meshes (the page's 3D
/// view; [`crate::Job::from_models`] gives the same instances).
pub fn layout(models: &[Model], spec: &JobSpec) -> Result<Layout, Error> {
    spec.validate()?;
    let by_part = models_of(models, spec)?;
    let frames = spec
        .parts
        .iter()
        .zip(&by_part)
        .enumerate()
        .map(|(i, (p, m))| {
            let tris = m.triangles(p.item).map_err(|e| at_part(i, e))?;
            Frame::of(corners(&tris), &p.placement([0.0, 0.0]))
                .ok_or_else(|| Error::Job(format!("parts[{i}]: the part has no triangles")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    place_instances(&by_part, spec, &frames)
}

/// An error of part `i` with the part named.
pub fn at_part(i: usize, e: Error) -> Error {
    match e {
        Error::Job(m) if !m.starts_with("parts[") => Error::Job(format!("parts[{i}]: {m}")),
        e => e,
    }
}

/// Most facets [`lay_flat`] looks at for supporting planes (more are sampled evenly).
pub const LAY_FLAT_POINTS: usize = 300_000;
/// Largest planes [`lay_flat`] checks for being a supporting plane.
const LAY_FLAT_CANDIDATES: usize = 64;

/// `(rotate_x, rotate_y)` in degrees (SPEC's order: x first) that put the part's largest flat
/// face down: the largest set of coplanar mesh facets (facet normals within about 0.06° and
/// plane offsets within 1 µm·scale grouped) whose plane touches the part from outside (no
/// vertex beyond it), so the part rests on it. `(0, 0)` when no flat face supports the part
/// (e.g. a sphere or a torus). Cost: one pass over the facets and up to 64 passes over at most
/// [`LAY_FLAT_POINTS`] sampled corners.
pub fn lay_flat(tris: &[[[f32; 3]; 3]]) -> (f64, f64) {
    use std::collections::HashMap;
    if tris.is_empty() {
        return (0.0, 0.0);
    }
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in corners(tris) {
        lo = lo.min(DVec3::from(p));
        hi = hi.max(DVec3::from(p));
    }
    let extent = (hi - lo).max_element().max(1e-9);
    let centre = (lo + hi) / 2.0;
    // plane key → (area, area-weighted normal, area-weighted offset)
    let mut planes: HashMap<[i64; 4], (f64, DVec3, f64)> = HashMap::new();
    for t in tris {
        let [a, b, c] = t.map(|p| DVec3::from(p.map(f64::from)) - centre);
        let n2 = (b - a).cross(c - a);
        let len = n2.length();
        if len <= 1e-12 * extent * extent || !len.is_finite() {
            continue;
        }
        let n = n2 / len;
        let d = n.dot(a);
        let key = [
            (n.x * 1e3).round() as i64,
            (n.y * 1e3).round() as i64,
            (n.z * 1e3).round() as i64,
            (d / extent * 1e4).round() as i64,
        ];
        let e = planes.entry(key).or_insert((0.0, DVec3::ZERO, 0.0));
        let area = len / 2.0;
        e.0 += area;
        e.1 += n * area;
        e.2 += d * area;
    }
    let mut groups: Vec<(f64, DVec3, f64)> = planes.into_values().collect();
    groups.sort_by(|a, b| b.0.total_cmp(&a.0));
    groups.truncate(LAY_FLAT_CANDIDATES);
    let n_points = tris.len() * 3;
    let stride = n_points.div_ceil(LAY_FLAT_POINTS).max(1);
    let points: Vec<DVec3> = corners(tris)
        .step_by(stride)
        .map(|p| DVec3::from(p) - centre)
        .collect();
    let tol = 1e-4 * extent;
    // The supporting planes among the largest: (area, outward normal).
    let mut supporting: Vec<(f64, DVec3)> = Vec::new();
    for (area, nsum, dsum) in groups {
        let n = nsum.normalize_or_zero();
        if n == DVec3::ZERO {
            continue;
        }
        let d = dsum / area;
        let (mut below, mut above) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &points {
            let s = n.dot(*p);
            below = below.min(s);
            above = above.max(s);
        }
        // The facets' side of the part: outward normal n (nothing beyond the plane), or an
        // inside-out mesh's (nothing behind it).
        let outward = if above <= d + tol {
            n
        } else if below >= d - tol {
            -n
        } else {
            continue;
        };
        supporting.push((area, outward));
    }
    // The largest; of faces as large (a box's bottom and top), the one facing down most, so a
    // part already lying flat is not turned over.
    let Some(largest) = supporting.iter().map(|s| s.0).reduce(f64::max) else {
        return (0.0, 0.0);
    };
    supporting
        .iter()
        .filter(|s| s.0 >= largest * (1.0 - 1e-6))
        .min_by(|a, b| a.1.z.total_cmp(&b.1.z))
        .map_or((0.0, 0.0), |s| angles_down(s.1))
}

/// Angles (rotate x first, then y) that turn the unit vector `n` to −z.
pub fn angles_down(n: DVec3) -> (f64, f64) {
    // About x: n to (n.x, 0, −m); then about y: (n.x, 0, −m) to (0, 0, −1).
    let m = (n.y * n.y + n.z * n.z).sqrt();
    let a = if m < 1e-12 { 0.0 } else { (-n.y).atan2(-n.z) };
    let b = n.x.atan2(m);
    let clean = |r: f64| {
        let d = r.to_degrees();
        // Exact right angles stay exact (the trig of the transform is exact there).
        let q = (d / 90.0).round();
        if (d - q * 90.0).abs() < 1e-9 {
            q * 90.0 + 0.0
        } else {
            d
        }
    };
    (clean(a), clean(b))
}

/// A decimated copy of `tris` with at most `max_triangles` triangles, for drawing only (never
/// sliced): vertex clustering on a grid, each cell's corners moved to their mean, triangles
/// that collapse dropped (and repeats). 9 floats per triangle (x, y, z of three corners).
pub fn display_mesh(tris: &[[[f32; 3]; 3]], max_triangles: usize) -> Vec<f32> {
    if tris.len() <= max_triangles {
        return tris.iter().flatten().flatten().copied().collect();
    }
    if max_triangles == 0 {
        return Vec::new();
    }
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let mut area = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|p| DVec3::from(p.map(f64::from)));
        for p in [a, b, c] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        area += (b - a).cross(c - a).length() / 2.0;
    }
    let extent = (hi - lo).max_element();
    if !extent.is_finite() || extent <= 0.0 {
        return Vec::new();
    }
    // About two triangles per cell of the surface; grown until the result fits.
    let mut cell = (2.0 * area / max_triangles as f64)
        .sqrt()
        .max(extent * 1e-6);
    for _ in 0..200 {
        let out = cluster(tris, lo, cell, max_triangles);
        if let Some(out) = out {
            return out;
        }
        cell *= 1.25;
    }
    Vec::new()
}

/// One clustering with cells of `cell` mm; `None` if more than `max` triangles remain.
fn cluster(tris: &[[[f32; 3]; 3]], lo: DVec3, cell: f64, max: usize) -> Option<Vec<f32>> {
    use std::collections::{HashMap, HashSet};
    let key = |p: [f32; 3]| {
        let q = (DVec3::from(p.map(f64::from)) - lo) / cell;
        [q.x as i64, q.y as i64, q.z as i64]
    };
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut sums: Vec<(DVec3, u32)> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut seen: HashSet<[u32; 3]> = HashSet::new();
    for t in tris {
        let f = t.map(|p| {
            let k = key(p);
            let id = *ids.entry(k).or_insert_with(|| {
                sums.push((DVec3::ZERO, 0));
                (sums.len() - 1) as u32
            });
            let s = &mut sums[id as usize];
            s.0 += DVec3::from(p.map(f64::from));
            s.1 += 1;
            id
        });
        if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
            continue;
        }
        let mut sorted = f;
        sorted.sort_unstable();
        if seen.insert(sorted) {
            faces.push(f);
            if faces.len() > max {
                return None;
            }
        }
    }
    let mean: Vec<[f32; 3]> = sums
        .iter()
        .map(|(s, n)| (*s / *n as f64).to_array().map(|c| c as f32))
        .collect();
    Some(
        faces
            .iter()
            .flat_map(|f| f.iter().flat_map(|&i| mean[i as usize]))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ranges the page is given are the ones a job file's parts are held to: each bound
    /// is accepted, and a step past it is refused naming the key.
    #[test]
    fn published_part_ranges_are_the_checked_ones() {
        let schema = job_schema();
        let names: Vec<_> = schema.part_numbers.iter().map(|s| s.name).collect();
        assert_eq!(&names[..PART_KEYS.len()], PART_KEYS);
        assert_eq!(&names[PART_KEYS.len()..], ["copies", "unit"]);
        let part = |key: &str, x: f64| {
            let integer = schema
                .part_numbers
                .iter()
                .any(|s| s.name == key && s.kind == Kind::Integer);
            let x = if integer {
                serde_json::Value::from(x as i64)
            } else {
                x.into()
            };
            let mut v = serde_json::json!({"file": "a.stl", key: x});
            for (k, other) in [("place_x", "place_y"), ("place_y", "place_x")] {
                if key == k {
                    v[other] = 0.0.into();
                }
            }
            part_from_value(3, v)
        };
        for s in &schema.part_numbers {
            let (lo, hi) = (s.min.unwrap(), s.max.unwrap());
            let step = if s.kind == Kind::Integer { 1.0 } else { 1e-6 };
            part(s.name, hi).unwrap();
            if !s.min_exclusive {
                part(s.name, lo).unwrap();
            }
            let below = if s.min_exclusive { lo } else { lo - step };
            for x in [below, hi + step] {
                let e = part(s.name, x).unwrap_err().to_string();
                assert!(e.contains(&format!("parts[3].{}", s.name)), "{x}: {e}");
            }
        }
    }

    #[test]
    fn angles_turn_normals_down() {
        for n in [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::new(-0.7, 0.1, -0.2).normalize(),
        ] {
            let (a, b) = angles_down(n);
            let r = rotation([a, b, 0.0]);
            let down = r * n;
            assert!(
                (down - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12,
                "{n} → {down}"
            );
        }
    }
}
