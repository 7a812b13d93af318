//! `dropslice orient MODEL_OR_JOB [--apply] [--profile FILE.json]... [--set NAME=VALUE]...`:
//! the rotation of each part with the least unsupported area by the overhang rule
//! (`dropslice::support::orient`).
//!
//! For a job file each part is oriented in place (its rotation, scale and unit's shrinkage as
//! sliced), after the job's triangle bound is checked as slicing checks it (a small 3MF can
//! instance millions of triangles per part). The settings are slicing's: the job file's, then
//! the profiles, then `--set`. `--apply` writes the chosen rotate_x/y/z into the job file's
//! parts, changing only those values in its text (docs/process.md "Orientation"):
//!
//! * a symlink is followed: its target is written, the link stays a link;
//! * a read-only file (no write permission) is refused before any work, untouched (exit 2);
//! * the file is written to a temporary file beside it with its mode (and owner, where the
//!   owner can be given) and put in place when complete; a file of several hard links is
//!   instead rewritten in place once the new text is complete and checked, so that every
//!   name keeps seeing the one file (and so is one whose owner cannot be given);
//! * keys, their order, spacing and every other value keep their text; a rotation equal to
//!   the chosen one is not rewritten, a missing one is added after the part's last key;
//! * a file changed while orienting is not written (run again).
//!
//! For a model, `--apply` writes a new job file `MODEL.job.json` beside it (the model as its
//! one part, the chosen rotation, the settings that differ from the defaults) and refuses to
//! replace one that exists.

use crate::cli::OrientArgs;
use crate::files::{is_job_file, read_regular, shown_path};
use crate::slice::{in_job_file, named, read_job_file, read_profile};
use crate::staged::Staged;
use dropslice::base::error::quote;
use dropslice::base::settings::PART_KEYS;
use dropslice::model::models::{Model, check_job_triangles};
use dropslice::model::models_job::SettingsOverride;
use dropslice::model::spec::{JobSpec, MAX_JOB_FILE_BYTES, clean_name};
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
    // Before a temporary file is created: SIGINT, SIGTERM and SIGHUP remove it.
    crate::staged::remove_on_signals();
    let setup = match Setup::new(&path, &args) {
        Ok(s) => s,
        Err(msg) => {
            eprintln!("dropslice orient: {msg}");
            return ExitCode::from(2);
        }
    };
    crate::slice::finish("dropslice orient", run(&path, setup))
}

/// The command's arguments checked before any model is read.
struct Setup {
    /// The defaults with the profiles and the `--set` options: a model's settings.
    settings: Settings,
    /// The profiles, then the `--set` options: applied to a job file's settings.
    overrides: Vec<SettingsOverride>,
    job_file: bool,
    apply: bool,
    /// `--apply` on a job file: the file to write, checked writable.
    target: Option<JobTarget>,
}

impl Setup {
    /// The profiles read and applied in order, then `--set` (as slicing does: the same
    /// reading and messages); for `--apply` on a job file, the file checked writable.
    fn new(path: &Path, args: &OrientArgs) -> Result<Setup, String> {
        let mut settings = Settings::default();
        let mut overrides = Vec::new();
        for p in &args.profile {
            let (profile, _) = read_profile(p)?;
            profile.apply(&mut settings).map_err(|e| e.to_string())?;
            overrides.push(SettingsOverride::Profile(profile));
        }
        for kv in &args.set {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| format!("--set expects name=value, got '{}'", quote(kv)))?;
            settings.set(k.trim(), v).map_err(|e| e.to_string())?;
            overrides.push(SettingsOverride::Set {
                name: k.trim().to_string(),
                value: v.to_string(),
            });
        }
        settings.validate().map_err(|e| e.to_string())?;
        let job_file = is_job_file(path).map_err(|e| Error::Import(e).to_string())?;
        let target = match args.apply && job_file {
            true => Some(JobTarget::new(path)?),
            false => None,
        };
        Ok(Setup {
            settings,
            overrides,
            job_file,
            apply: args.apply,
            target,
        })
    }
}

fn run(path: &Path, setup: Setup) -> Result<(), Error> {
    if setup.job_file {
        let (spec, models) = read_job_file(path, &setup.overrides)?;
        // Slicing's bound, before any part is oriented (one pass over a part of 20 M
        // triangles per candidate takes seconds and gigabytes).
        check_job_triangles(&models, &spec).map_err(|e| in_job_file(path, e))?;
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
        if let Some(target) = setup.target {
            target.write(path, &chosen)?;
        }
        return Ok(());
    }
    let settings = setup.settings;
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
    check_job_triangles(std::slice::from_ref(&model), &spec)?;
    let o = orient_part(&model, &spec.parts[0], &spec.settings)?;
    print(&clean_name(&name), &o);
    if setup.apply {
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
        "  unsupported area {} mm² → {} mm², height {} mm → {} mm (now {}; {} orientations compared)",
        figure(now.unsupported_area, 1),
        figure(best.unsupported_area, 1),
        figure(now.height, 2),
        figure(best.height, 2),
        rotation_text(&now),
        o.candidates.len()
    );
    for (k, c) in o.candidates.iter().take(SHOWN).enumerate() {
        println!(
            "  {}. {}: {} mm², {} mm tall",
            k + 1,
            rotation_text(c),
            figure(c.unsupported_area, 1),
            figure(c.height, 2)
        );
    }
}

/// An area or a height as printed: `decimals` decimals; from 10⁹ on (a part far larger than
/// any plate: its file's units are wrong) 4 significant digits with a power of ten, never a
/// line of digits.
fn figure(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return "(too large to compute)".into();
    }
    if x.abs() >= 1e9 {
        return format!("{x:.3e}");
    }
    format!("{:.*}", decimals, x + 0.0)
}

/// The rotation rounded as written (1e-4 degrees), as a JSON number.
fn angle(x: f64) -> serde_json::Value {
    serde_json::json!((x * 1e4).round() / 1e4 + 0.0)
}

/// The job file `--apply` writes, checked before any work.
struct JobTarget {
    /// The file: the job file with every symlink resolved.
    path: PathBuf,
    /// Its bytes as read before orienting: written over only if still the same.
    bytes: Vec<u8>,
    /// Its mode and owner, kept.
    meta: std::fs::Metadata,
    /// The new file beside it, put in place when complete; `None`: written in place.
    staged: Option<Staged>,
}

impl JobTarget {
    /// The job file `path` for `--apply`: its target if a symlink; refused if it cannot be
    /// written (read-only); the temporary file created beside it (a file of one link).
    fn new(path: &Path) -> Result<JobTarget, String> {
        let shown = shown_path(path);
        let bytes = read_regular(path, MAX_JOB_FILE_BYTES as u64, "a job file")
            .map_err(|e| format!("the job file: {e}"))?;
        let resolved =
            std::fs::canonicalize(path).map_err(|e| format!("cannot open {shown}: {e}"))?;
        let meta = std::fs::metadata(&resolved).map_err(|e| format!("cannot open {shown}: {e}"))?;
        let refuse = |why: &str| {
            format!(
                "{shown} {why}; --apply writes the chosen rotations into the job file: make it writable (chmod u+w {shown}) or orient without --apply"
            )
        };
        if meta.permissions().readonly() {
            return Err(refuse(&format!("is read-only{}", mode_text(&meta))));
        }
        if !writable(&resolved) {
            return Err(refuse(&format!(
                "cannot be written by this user{}",
                mode_text(&meta)
            )));
        }
        let staged = match links(&meta) {
            1 => {
                let staged = Staged::create(&resolved).map_err(|e| {
                    format!(
                        "cannot write in the folder {} (for {shown}): {e}",
                        crate::files::parent_dir(&resolved).display()
                    )
                })?;
                same_owner(staged, &meta)
            }
            _ => None,
        };
        Ok(JobTarget {
            path: resolved,
            bytes,
            meta,
            staged,
        })
    }

    /// Writes the chosen rotations into the job file (`given`: its name as given).
    fn write(self, given: &Path, chosen: &[Orientation]) -> Result<(), Error> {
        let shown = shown_path(given);
        let now = read_regular(&self.path, MAX_JOB_FILE_BYTES as u64, "a job file")
            .map_err(|e| Error::Job(format!("the job file: {e}")))?;
        if now != self.bytes {
            return Err(Error::Job(format!(
                "{shown} changed while orienting; nothing was written (run dropslice orient again)"
            )));
        }
        let text = std::str::from_utf8(&self.bytes)
            .map_err(|_| Error::Internal("the job file read is not text".into()))?;
        let new = with_rotations(text, chosen)?;
        let linked = if self.path != given
            && std::fs::symlink_metadata(given).is_ok_and(|m| m.is_symlink())
        {
            format!(" (the file it links to, {})", shown_path(&self.path))
        } else {
            String::new()
        };
        if new == text {
            println!("unchanged: {shown}{linked} (every part has its chosen rotation)");
            return Ok(());
        }
        let io = |e: std::io::Error| Error::Io(format!("cannot write {shown}: {e}"));
        match self.staged {
            Some(mut staged) => {
                let file = staged.file();
                file.write_all(new.as_bytes()).map_err(io)?;
                file.set_permissions(self.meta.permissions()).map_err(io)?;
                staged.commit().map_err(io)?;
            }
            None => {
                // Complete and checked: written over the file itself, then cut to its length.
                let mut file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&self.path)
                    .map_err(io)?;
                file.write_all(new.as_bytes())
                    .and_then(|()| file.set_len(new.len() as u64))
                    .and_then(|()| file.sync_all())
                    .map_err(io)?;
            }
        }
        println!("written: {shown}{linked}");
        Ok(())
    }
}

/// " (mode 0444)" on Unix.
fn mode_text(meta: &std::fs::Metadata) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        format!(" (mode {:04o})", meta.permissions().mode() & 0o7777)
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        String::new()
    }
}

/// Whether this process may write `path` (on Unix `access(W_OK)`: the permissions, a
/// read-only file system).
fn writable(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
            return false;
        };
        // SAFETY: a valid NUL-terminated string that outlives the call.
        unsafe { libc::access(c.as_ptr(), libc::W_OK) == 0 }
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        true
    }
}

/// The file's hard links.
fn links(meta: &std::fs::Metadata) -> u64 {
    #[cfg(unix)]
    {
        std::os::unix::fs::MetadataExt::nlink(meta)
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        1
    }
}

/// The temporary file given the job file's owner and group, if they differ from its own
/// (a file another user owns, writable by this one's group); `None` if that is not allowed:
/// the job file is then written in place, which keeps its owner.
fn same_owner(mut staged: Staged, meta: &std::fs::Metadata) -> Option<Staged> {
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        use std::os::unix::fs::MetadataExt;
        let own = staged.file().metadata().ok()?;
        if (own.uid(), own.gid()) != (meta.uid(), meta.gid()) {
            // SAFETY: the file's descriptor is open for the call.
            let r = unsafe { libc::fchown(staged.file().as_raw_fd(), meta.uid(), meta.gid()) };
            if r != 0 {
                return None;
            }
        }
    }
    #[cfg(not(unix))]
    let _ = meta;
    Some(staged)
}

/// The job file's text with each part's rotation set to the chosen one (rounded as written),
/// nothing else changed: a value equal to it keeps its text, another is replaced where it
/// stands (every occurrence of the key), a missing one (the default 0) is added after the
/// part's last member with that member's spacing. Checked: the new text reads as the old
/// one with the new rotations.
fn with_rotations(text: &str, chosen: &[Orientation]) -> Result<String, Error> {
    let odd = || Error::Internal("the job file's text could not be followed to its parts".into());
    let mut top = Scanner {
        s: text.as_bytes(),
        i: 0,
    };
    let (members, _) = top.members().ok_or_else(odd)?;
    // (of keys given twice, the last counts)
    let parts = members
        .iter()
        .rev()
        .find(|m| m.key.0 == "parts")
        .ok_or_else(odd)?;
    let objects = Scanner {
        s: text.as_bytes(),
        i: parts.value.0,
    }
    .objects()
    .ok_or_else(odd)?;
    if objects.len() != chosen.len() {
        return Err(odd());
    }
    // (start, end, new text), in no order; never overlapping.
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    for (fields, o) in objects.iter().zip(chosen) {
        let mut added = String::new();
        for (key, v) in rotations(o) {
            let present: Vec<&Member> = fields.iter().filter(|m| m.key.0 == key).collect();
            if present.is_empty() {
                let Some(last) = fields.last() else {
                    return Err(odd());
                };
                if v != 0.0 {
                    let lead = &text[text[..last.key.1].trim_end().len()..last.key.1];
                    let colon = &text[last.key.2..last.value.0];
                    added += &format!(",{lead}\"{key}\"{colon}{}", deg(v));
                }
                continue;
            }
            for m in present {
                let old: Option<f64> = serde_json::from_str(&text[m.value.0..m.value.1]).ok();
                if old != Some(v) {
                    edits.push((m.value.0, m.value.1, deg(v)));
                }
            }
        }
        if !added.is_empty() {
            let at = fields.last().map(|m| m.value.1).ok_or_else(odd)?;
            edits.push((at, at, added));
        }
    }
    edits.sort_by_key(|e| std::cmp::Reverse(e.0));
    let mut out = text.to_string();
    for (start, end, new) in edits {
        out.replace_range(start..end, &new);
    }
    check_rotations(text, &out, chosen)?;
    Ok(out)
}

/// The three keys with the rotation of `o` as written (rounded to 1e-4 degrees).
fn rotations(o: &Orientation) -> [(&'static str, f64); 3] {
    let r = |x: f64| (x * 1e4).round() / 1e4 + 0.0;
    [
        ("rotate_x", r(o.rotate_x)),
        ("rotate_y", r(o.rotate_y)),
        ("rotate_z", r(o.rotate_z)),
    ]
}

/// `new` reads as `old` with each part's rotation the chosen one, every other value equal.
fn check_rotations(old: &str, new: &str, chosen: &[Orientation]) -> Result<(), Error> {
    let bad = |why: &str| {
        Error::Internal(format!(
            "the job file's new text {why}; nothing was written"
        ))
    };
    let read = |t: &str| serde_json::from_str::<serde_json::Value>(t);
    let (Ok(mut old), Ok(mut new)) = (read(old), read(new)) else {
        return Err(bad("is not JSON"));
    };
    let parts =
        |v: &mut serde_json::Value| -> Option<Vec<serde_json::Map<String, serde_json::Value>>> {
            v.get_mut("parts")?
                .as_array_mut()?
                .iter_mut()
                .map(|p| p.as_object_mut().map(std::mem::take))
                .collect()
        };
    let (Some(mut before), Some(mut after)) = (parts(&mut old), parts(&mut new)) else {
        return Err(bad("has no parts"));
    };
    if before.len() != chosen.len() || after.len() != chosen.len() {
        return Err(bad("has another number of parts"));
    }
    for ((b, a), o) in before.iter_mut().zip(&mut after).zip(chosen) {
        for (key, v) in rotations(o) {
            b.remove(key);
            let got = a.remove(key).map(|x| x.as_f64());
            if got.unwrap_or(Some(0.0)) != Some(v) {
                return Err(bad(&format!("has {key} {got:?}, not {v}")));
            }
        }
    }
    if (old, before) != (new, after) {
        return Err(bad("changed more than the rotations"));
    }
    Ok(())
}

/// A member of a JSON object: its key (decoded), the key's span (start, end) and the
/// value's span.
struct Member {
    key: (String, usize, usize),
    value: (usize, usize),
}

/// Follows a JSON text (already read as valid JSON) to the spans [`with_rotations`] edits.
/// `None` where the text is not as expected.
struct Scanner<'a> {
    s: &'a [u8],
    i: usize,
}

impl Scanner<'_> {
    fn ws(&mut self) {
        while self
            .s
            .get(self.i)
            .is_some_and(|b| matches!(b, b' ' | b'\t' | b'\n' | b'\r'))
        {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.ws();
        self.s.get(self.i).copied()
    }

    fn eat(&mut self, b: u8) -> Option<()> {
        (self.peek()? == b).then(|| self.i += 1)
    }

    /// A string from its opening quote to after its closing one.
    fn string(&mut self) -> Option<()> {
        self.eat(b'"')?;
        loop {
            let b = *self.s.get(self.i)?;
            self.i += 1;
            match b {
                b'\\' => self.i += 1,
                b'"' => return Some(()),
                _ => {}
            }
        }
    }

    /// Skips one value: its span.
    fn value(&mut self) -> Option<(usize, usize)> {
        let first = self.peek()?;
        let start = self.i;
        match first {
            b'"' => self.string()?,
            b'{' | b'[' => {
                // Brackets counted, strings skipped (their brackets do not count).
                let mut depth = 0usize;
                loop {
                    match *self.s.get(self.i)? {
                        b'"' => {
                            self.string()?;
                            continue;
                        }
                        b'{' | b'[' => depth += 1,
                        b'}' | b']' => {
                            depth = depth.checked_sub(1)?;
                            if depth == 0 {
                                self.i += 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                    self.i += 1;
                }
            }
            _ => {
                while self.s.get(self.i).is_some_and(|b| {
                    !matches!(b, b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r')
                }) {
                    self.i += 1;
                }
                if self.i == start {
                    return None;
                }
            }
        }
        Some((start, self.i))
    }

    /// An object's members, from its `{` to after its `}`.
    fn members(&mut self) -> Option<(Vec<Member>, usize)> {
        self.eat(b'{')?;
        let mut out = Vec::new();
        if self.eat(b'}').is_some() {
            return Some((out, self.i));
        }
        loop {
            self.peek()?;
            let start = self.i;
            self.string()?;
            let end = self.i;
            let key: String = serde_json::from_slice(&self.s[start..end]).ok()?;
            self.eat(b':')?;
            let value = self.value()?;
            out.push(Member {
                key: (key, start, end),
                value,
            });
            match self.peek()? {
                b',' => self.i += 1,
                b'}' => {
                    self.i += 1;
                    return Some((out, self.i));
                }
                _ => return None,
            }
        }
    }

    /// The members of each object of an array of objects, from its `[`.
    fn objects(&mut self) -> Option<Vec<Vec<Member>>> {
        self.eat(b'[')?;
        let mut out = Vec::new();
        if self.eat(b']').is_some() {
            return Some(out);
        }
        loop {
            out.push(self.members()?.0);
            match self.peek()? {
                b',' => self.i += 1,
                b']' => return Some(out),
                _ => return None,
            }
        }
    }
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
