//! Jobs from the command line's forms: several model files given one after another (one part
//! each, arranged on the plate), and settings given on top of a job file's.

use crate::base::error::Error;
use crate::base::settings::Settings;
use crate::model::spec::{JobSpec, PART_KEYS, PartSpec};

/// Settings given on top of a job file's, in the order given.
#[derive(Clone, Debug, PartialEq)]
pub enum SettingsOverride {
    /// One setting as text (`--set name=value`).
    Set { name: String, value: String },
    /// A settings file's object (`--settings FILE.json`): the job file's settings with the
    /// file's values, replacing any override given before it.
    File {
        file: String,
        values: serde_json::Map<String, serde_json::Value>,
    },
    /// A profile (`--profile FILE.json`): its values set on the settings before it; a settings
    /// file given later keeps them.
    Profile(crate::base::settings::Profile),
}

/// The job of several model files (`files`: each one's key in the job's models; a file may
/// be given twice, giving two parts): one part each, arranged on the plate. The settings'
/// rotation and scale go to every part; a place (`place_x`, `place_y`, `place_angle`) is
/// refused, since it would put every part in the same spot.
pub fn models_job_spec(files: &[String], settings: &Settings) -> Result<JobSpec, Error> {
    let s = settings;
    if s.place_x != 0.0 || s.place_y != 0.0 || s.place_angle != 0.0 {
        return Err(Error::Job(
            "place_x, place_y and place_angle cannot be given for several models at once: write a job file with each part's place (see --help), or leave them out and the parts are arranged".into(),
        ));
    }
    let parts = files
        .iter()
        .map(|file| PartSpec::shaped_like(file, s))
        .collect();
    Ok(JobSpec {
        settings: without_part_keys(s),
        parts,
    })
}

/// The settings with the part keys at their defaults (they went to the parts).
fn without_part_keys(s: &Settings) -> Settings {
    let defaults = serde_json::to_value(Settings::default()).expect("settings serialise");
    let mut out = s.clone();
    for k in PART_KEYS {
        out.set_value(k, defaults[k].clone())
            .expect("a part key's default is a valid value");
    }
    out
}

/// Applies `overrides` in order to a job file's settings. A part key (rotate_*, scale_*,
/// place_*) is refused: it belongs to the job file's parts. Not validated; call
/// [`JobSpec::validate`].
pub fn override_settings(spec: &mut JobSpec, overrides: &[SettingsOverride]) -> Result<(), Error> {
    let mut base = spec.settings.clone();
    let part_key = |k: &str| {
        Error::Job(format!(
            "{k} belongs to a part: give it in the job file's parts, not with --set or --settings"
        ))
    };
    for o in overrides {
        match o {
            SettingsOverride::Set { name, value } => {
                if PART_KEYS.contains(&name.as_str()) {
                    return Err(part_key(name));
                }
                spec.settings.set(name, value)?;
            }
            SettingsOverride::Profile(p) => {
                p.apply(&mut spec.settings)?;
                p.apply(&mut base)?;
            }
            SettingsOverride::File { file, values } => {
                spec.settings = base.clone();
                for (k, v) in values {
                    if PART_KEYS.contains(&k.as_str()) {
                        return Err(part_key(k));
                    }
                    spec.settings.set_value(k, v.clone()).map_err(|e| match e {
                        Error::Setting { name, message } => Error::Setting {
                            name,
                            message: format!("{message} (in {file})"),
                        },
                        e => e,
                    })?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn several_models_share_rotation_and_scale_but_not_a_place() {
        let mut s = Settings::default();
        s.set("rotate_z", "90").unwrap();
        s.set("scale_x", "2").unwrap();
        s.set("layer_height", "0.25").unwrap();
        let files = ["a.stl".to_string(), "b.obj".into(), "a.stl".into()];
        let spec = models_job_spec(&files, &s).unwrap();
        assert_eq!(spec.parts.len(), 3);
        for (p, f) in spec.parts.iter().zip(&files) {
            assert_eq!((&p.file, p.rotate_z, p.scale_x), (f, 90.0, 2.0));
            assert_eq!((p.place_x, p.place_y, p.copies), (None, None, 1));
        }
        assert_eq!(spec.settings.rotate_z, 0.0);
        assert_eq!(spec.settings.scale_x, 1.0);
        assert_eq!(spec.settings.layer_height, 0.25);
        s.set("place_x", "10").unwrap();
        let e = models_job_spec(&files, &s).unwrap_err().to_string();
        assert!(e.contains("place_x"), "{e}");
    }

    #[test]
    fn a_settings_file_replaces_earlier_overrides_and_part_keys_are_refused() {
        let mut spec = JobSpec {
            settings: Settings::default(),
            parts: vec![PartSpec::new("a.stl")],
        };
        spec.settings.set("contours", "4").unwrap();
        let set = |name: &str, value: &str| SettingsOverride::Set {
            name: name.into(),
            value: value.into(),
        };
        let file = |json: &str| SettingsOverride::File {
            file: "s.json".into(),
            values: serde_json::from_str(json).unwrap(),
        };
        let ops = [set("layer_height", "0.3"), file(r#"{"contours": 3}"#)];
        override_settings(&mut spec, &ops).unwrap();
        // The file starts again from the job file's settings: the earlier --set is gone.
        assert_eq!(spec.settings.layer_height, Settings::default().layer_height);
        assert_eq!(spec.settings.contours, 3);
        override_settings(&mut spec, &[set("layer_height", "0.3")]).unwrap();
        assert_eq!(spec.settings.layer_height, 0.3);
        for ops in [vec![set("rotate_z", "5")], vec![file(r#"{"place_x": 1}"#)]] {
            let e = override_settings(&mut spec, &ops).unwrap_err().to_string();
            assert!(e.contains("belongs to a part"), "{e}");
        }
        let e = override_settings(&mut spec, &[file(r#"{"contours": -1}"#)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("(in s.json)"), "{e}");
    }
}
