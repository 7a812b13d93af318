//! `dropslice orient MODEL_OR_JOB [--apply] [--set NAME=VALUE]...`: the rotation of each part
//! with the least unsupported area by the overhang rule (`dropslice::support::orient`).
//!
//! For a job file each part is oriented in place (its rotation, scale and unit's shrinkage as
//! sliced); `--apply` writes the chosen rotate_x/y/z into the job file's parts (written to a
//! temporary file and put in place when complete; the file's other fields are kept). For a
//! model, `--apply` writes a new job file `MODEL.job.json` beside it (the model as its one
//! part, the chosen rotation, the `--set` settings) and refuses to replace one that exists.

use crate::cli::OrientArgs;
use crate::files::{is_job_file, read_regular, shown_path};
use crate::slice::{in_job_file, named, read_job_file};
use crate::staged::Staged;
use dropslice::base::error::quote;
use dropslice::base::settings::PART_KEYS;
use dropslice::model::models::Model;
use dropslice::model::models_job::SettingsOverride;
use dropslice::model::spec::{JobSpec, clean_name};
use dropslice::support::orient::{Orientation, Orientations, orient_part};
use dropslice::{Error, Settings};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Candidates listed after the choice.
const SHOWN: usize = 3;

pub fn main(args: OrientArgs) -> ExitCode {
    let Some(path) = args.file.clone() else {
        eprintln!(
            "dropslice orient: no model or job file given (usage: dropslice orient MODEL_OR_JOB [--apply]); see dropslice orient --help"
        );
        return ExitCode::from(2);
    };
    crate::slice::finish("dropslice orient", run(&path, &args))
}

fn run(path: &Path, args: &OrientArgs) -> Result<(), Error> {
    let mut overrides = Vec::new();
    for kv in &args.set {
        let (k, v) = kv.split_once('=').ok_or_else(|| Error::Setting {
            name: String::new(),
            message: format!("--set expects name=value, got '{}'", quote(kv)),
        })?;
        overrides.push(SettingsOverride::Set {
            name: k.trim().to_string(),
            value: v.to_string(),
        });
    }
    if is_job_file(path).map_err(Error::Import)? {
        let (spec, models) = read_job_file(path, &overrides)?;
        let mut chosen = Vec::with_capacity(spec.parts.len());
        for (i, p) in spec.parts.iter().enumerate() {
            let model = models
                .iter()
                .find(|m| m.name == p.file)
                .ok_or_else(|| Error::Internal(format!("parts[{i}]: its model was not read")))?;
            let label = format!(
                "parts[{i}] ({})",
                clean_name(&p.name.clone().unwrap_or_else(|| model.part_name(p.item)))
            );
            let o = orient_part(model, p, &spec.settings).map_err(|e| in_job_file(path, e))?;
            print(&label, &o);
            chosen.push(o.best());
        }
        if args.apply {
            apply_to_job_file(path, &chosen)?;
            println!("written: {}", shown_path(path));
        }
        return Ok(());
    }
    let mut settings = Settings::default();
    for o in &overrides {
        if let SettingsOverride::Set { name, value } = o {
            settings.set(name, value)?;
        }
    }
    settings.validate()?;
    let bytes = read_regular(
        path,
        dropslice::model::import::MAX_FILE_BYTES,
        "a model file",
    )
    .map_err(Error::Import)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let model = Model::read(&bytes, &name).map_err(|e| named(&name, e))?;
    let spec = JobSpec::from_value(new_job(&name, &settings, None))?;
    let o = orient_part(&model, &spec.parts[0], &spec.settings)?;
    print(&clean_name(&name), &o);
    if args.apply {
        let target = job_path_for(path);
        write_new_job(&target, &new_job(&name, &settings, Some(o.best())))?;
        println!("written: {}", shown_path(&target));
    }
    Ok(())
}

/// Degrees as written: whole degrees without decimals, else up to 4 decimals.
fn deg(x: f64) -> String {
    let r = (x * 1e4).round() / 1e4;
    format!("{}", r + 0.0)
}

fn rotation_text(o: &Orientation) -> String {
    format!(
        "rotate_x = {}, rotate_y = {}, rotate_z = {}",
        deg(o.rotate_x),
        deg(o.rotate_y),
        deg(o.rotate_z)
    )
}

fn print(label: &str, o: &Orientations) {
    let (now, best) = (o.current, o.best());
    println!("{label}: {}", rotation_text(&best));
    println!(
        "  unsupported area {:.1} mm² → {:.1} mm², height {:.2} mm → {:.2} mm (now {}; {} orientations compared)",
        now.unsupported_area,
        best.unsupported_area,
        now.height,
        best.height,
        rotation_text(&now),
        o.candidates.len()
    );
    for (k, c) in o.candidates.iter().take(SHOWN).enumerate() {
        println!(
            "  {}. {}: {:.1} mm², {:.2} mm tall",
            k + 1,
            rotation_text(c),
            c.unsupported_area,
            c.height
        );
    }
}

/// The rotation rounded as written (1e-4 degrees), as a JSON number.
fn angle(x: f64) -> serde_json::Value {
    serde_json::json!((x * 1e4).round() / 1e4 + 0.0)
}

/// The job file with each part's chosen rotation, the rest of the file kept.
fn apply_to_job_file(path: &Path, chosen: &[Orientation]) -> Result<(), Error> {
    let bytes = read_regular(
        path,
        dropslice::model::spec::MAX_JOB_FILE_BYTES as u64,
        "a job file",
    )
    .map_err(|e| Error::Job(format!("the job file: {e}")))?;
    let mut value: serde_json::Value = serde_json::from_slice(&bytes)
        .map_err(|e| Error::Job(format!("{}: {}", shown_path(path), quote(&e.to_string()))))?;
    let parts = value
        .get_mut("parts")
        .and_then(|p| p.as_array_mut())
        .filter(|p| p.len() == chosen.len())
        .ok_or_else(|| Error::Internal("the job file's parts changed while reading".into()))?;
    for (part, o) in parts.iter_mut().zip(chosen) {
        let Some(map) = part.as_object_mut() else {
            return Err(Error::Internal("a part is not an object".into()));
        };
        map.insert("rotate_x".into(), angle(o.rotate_x));
        map.insert("rotate_y".into(), angle(o.rotate_y));
        map.insert("rotate_z".into(), angle(o.rotate_z));
    }
    write_json(path, &value)
}

/// `MODEL.job.json` beside the model.
fn job_path_for(model: &Path) -> PathBuf {
    let stem = model.file_stem().unwrap_or("model".as_ref());
    let mut name = stem.to_os_string();
    name.push(".job.json");
    model.with_file_name(name)
}

/// A job of the model `file` as its one part: the settings that differ from the defaults
/// (part keys but the rotation go to the part), and the rotation of `o` if given.
fn new_job(file: &str, s: &Settings, o: Option<Orientation>) -> serde_json::Value {
    let all = serde_json::to_value(s).expect("settings serialize");
    let defaults = serde_json::to_value(Settings::default()).expect("settings serialize");
    let mut settings = serde_json::Map::new();
    let mut part = serde_json::Map::new();
    part.insert("file".into(), file.into());
    for (k, v) in all.as_object().expect("an object") {
        if PART_KEYS.contains(&k.as_str()) {
            if !k.starts_with("place_") && v != &defaults[k] {
                part.insert(k.clone(), v.clone());
            }
        } else if v != &defaults[k] {
            settings.insert(k.clone(), v.clone());
        }
    }
    if let Some(o) = o {
        part.insert("rotate_x".into(), angle(o.rotate_x));
        part.insert("rotate_y".into(), angle(o.rotate_y));
        part.insert("rotate_z".into(), angle(o.rotate_z));
    }
    serde_json::json!({"settings": settings, "parts": [part]})
}

/// Writes a new job file; refuses to replace one.
fn write_new_job(target: &Path, value: &serde_json::Value) -> Result<(), Error> {
    if target.exists() {
        return Err(Error::Job(format!(
            "{} exists; orient that job file instead (dropslice orient {} --apply), or remove it",
            shown_path(target),
            shown_path(target)
        )));
    }
    write_json(target, value)
}

/// Writes `value` to `target` through a temporary file put in place when complete.
fn write_json(target: &Path, value: &serde_json::Value) -> Result<(), Error> {
    let io = |e: std::io::Error| Error::Io(format!("cannot write {}: {e}", shown_path(target)));
    let mut staged = Staged::create(target).map_err(io)?;
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| Error::Internal(format!("the job does not serialize: {e}")))?;
    let file = staged.file();
    file.write_all(text.as_bytes())
        .and_then(|()| file.write_all(b"\n"))
        .map_err(io)?;
    staged.commit().map_err(io)
}
