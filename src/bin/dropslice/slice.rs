//! `dropslice [slice] MODEL... [OPTIONS]`, `dropslice [slice] JOB.json [OPTIONS]`: the code
//! (and the report) of one model, several models (a build job) or a job file.

use crate::cli::{SettingsArg, SliceArgs};
use crate::files::{
    check_destination, is_job_file, parent_dir, read_regular, same_file, shown_path,
};
use crate::staged::{self, Staged};
use dropslice::analysis::JobAnalysis;
use dropslice::base::error::quote;
use dropslice::base::settings::{MAX_PROFILE_BYTES, MAX_UNITS, Profile, UnitId};
use dropslice::base::stages;
use dropslice::model::models::Model;
use dropslice::model::models_job::{SettingsOverride, models_job_spec, override_settings};
use dropslice::model::spec::{self as job, JobSpec};
use dropslice::pipeline::writer_threads;
use dropslice::{Error, Job, Settings, write_gcode_with};
use std::io::{BufWriter, IsTerminal, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// A slicing run's arguments, checked.
struct Args {
    models: Vec<PathBuf>,
    output: Option<PathBuf>,
    /// The defaults with the settings options applied.
    settings: Settings,
    /// The settings options in order (applied again to a job file's settings).
    overrides: Vec<SettingsOverride>,
    quiet: bool,
    report: Option<PathBuf>,
    /// The profiles applied, as the header names them.
    profiles: Vec<String>,
}

pub fn main(cli: SliceArgs, settings: Vec<SettingsArg>) -> ExitCode {
    if cli.list_settings {
        println!("{}", list_settings());
        return ExitCode::SUCCESS;
    }
    let args = match Args::new(cli, settings) {
        Ok(a) => a,
        Err(msg) => {
            eprintln!("dropslice: {msg}");
            return ExitCode::from(2);
        }
    };
    // Before any file is created: SIGINT, SIGTERM and SIGHUP remove the temporary files.
    staged::remove_on_signals();
    let (output, out, report) = match prepare(&args) {
        Ok(p) => p,
        Err(msg) => {
            eprintln!("dropslice: {msg}");
            return ExitCode::from(2);
        }
    };
    finish("dropslice", run(&args, &output, out, report))
}

/// The message of a failed command and its exit code: 1 for I/O and internal errors, else 2.
pub fn finish(who: &str, result: Result<(), Error>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{who}: {e}");
            match e {
                Error::Io(_) | Error::Internal(_) => ExitCode::from(1),
                _ => ExitCode::from(2),
            }
        }
    }
}

impl Args {
    /// The settings options applied in order (a settings file replaces what came before it),
    /// the models counted, the settings checked.
    fn new(cli: SliceArgs, options: Vec<SettingsArg>) -> Result<Args, String> {
        let mut settings = Settings::default();
        let mut overrides = Vec::new();
        let mut profiles = Vec::new();
        for path in &cli.profile {
            let (profile, label) = read_profile(path)?;
            profile.apply(&mut settings).map_err(|e| e.to_string())?;
            profiles.push(label);
            overrides.push(SettingsOverride::Profile(profile));
        }
        // What a settings file starts from: the defaults with the profiles.
        let base = settings.clone();
        for option in options {
            match option {
                SettingsArg::Set(kv) => {
                    let (k, v) = kv
                        .split_once('=')
                        .ok_or_else(|| format!("--set expects name=value, got '{}'", quote(&kv)))?;
                    settings.set(k.trim(), v).map_err(|e| e.to_string())?;
                    overrides.push(SettingsOverride::Set {
                        name: k.trim().to_string(),
                        value: v.to_string(),
                    });
                }
                SettingsArg::File(path) => {
                    let shown = path.display();
                    let bytes = read_regular(
                        &path,
                        dropslice::base::settings::MAX_SETTINGS_FILE_BYTES as u64,
                        "a settings file",
                    )
                    .map_err(|e| format!("the settings file: {e}"))?;
                    let text = String::from_utf8(bytes).map_err(|_| {
                        format!("the settings file {shown} is not text (UTF-8): it is not a JSON settings file")
                    })?;
                    Settings::from_json(&text).map_err(|e| format!("{shown}: {e}"))?;
                    if let Ok(serde_json::Value::Object(values)) = serde_json::from_str(&text) {
                        settings = base.clone();
                        for (k, v) in &values {
                            settings
                                .set_value(k, v.clone())
                                .map_err(|e| format!("{shown}: {e}"))?;
                        }
                        overrides.push(SettingsOverride::File {
                            file: shown.to_string(),
                            values,
                        });
                    }
                }
            }
        }
        if cli.models.len() > job::MAX_PARTS {
            return Err(format!(
                "more than {} model files given; a job has at most {} parts",
                job::MAX_PARTS,
                job::MAX_PARTS
            ));
        }
        if cli.models.is_empty() {
            return Err(
                "no model file given (usage: dropslice MODEL... [OPTIONS]); see dropslice --help"
                    .into(),
            );
        }
        settings.validate().map_err(|e| e.to_string())?;
        Ok(Args {
            models: cli.models,
            output: cli.output,
            settings,
            overrides,
            quiet: cli.quiet,
            report: cli.report,
            profiles,
        })
    }
}

/// Reads and checks a profile given to `--profile`: `FILE.json`, or `unitN=FILE.json` (a
/// material for unit N, its keys moved to unit N's names, [`Profile::to_unit`]); the
/// message names the file. With its label for the header.
pub fn read_profile(arg: &Path) -> Result<(Profile, String), String> {
    let (unit, path) = match arg.to_str().and_then(|t| t.split_once('=')) {
        Some((word, file)) if word.starts_with("unit") => {
            let n = (word[4..].parse::<usize>().ok())
                .filter(|&n| n < MAX_UNITS && word == format!("unit{n}"))
                .ok_or_else(|| {
                    format!(
                        "--profile {}: '{}' is not a unit: give unit0 … unit{}=FILE.json, or the file alone",
                        quote(&arg.display().to_string()),
                        quote(word),
                        MAX_UNITS - 1
                    )
                })?;
            (Some(UnitId(n as u8)), Path::new(file))
        }
        _ => (None, arg),
    };
    let profile = read_profile_file(path)?;
    let Some(u) = unit else {
        let label = profile.label();
        return Ok((profile, label));
    };
    let moved = profile
        .to_unit(u)
        .map_err(|e| format!("--profile {}: {e}", quote(&arg.display().to_string())))?;
    let label = format!("{} (material, unit {u})", profile.name);
    Ok((moved, label))
}

/// Reads and checks a profile file; the message names the file.
fn read_profile_file(path: &Path) -> Result<Profile, String> {
    let shown = path.display();
    let bytes = read_regular(path, MAX_PROFILE_BYTES as u64, "a profile")
        .map_err(|e| format!("the profile: {e}"))?;
    Profile::from_bytes(&bytes).map_err(|e| format!("the profile {shown}: {e}"))
}

fn list_settings() -> String {
    let mut out = String::new();
    for s in dropslice::base::settings::schema() {
        let range = match (s.domain.min, s.domain.max) {
            (Some(lo), Some(hi)) => {
                format!(
                    " [{}{lo} … {hi}]",
                    if s.domain.min_exclusive { ">" } else { "" }
                )
            }
            _ if !s.domain.choices.is_empty() => format!(" [{}]", s.domain.choices.join(" | ")),
            _ => String::new(),
        };
        out.push_str(&format!(
            "{:<18} = {:<16} {:<6}{range}\n    {}\n",
            s.name,
            s.default.to_string().trim_matches('"'),
            s.domain.unit,
            s.description
        ));
    }
    out
}

/// The G-code's path: `-o`, else the model's name with `.gco` in the current directory.
fn output_path(args: &Args) -> PathBuf {
    args.output.clone().unwrap_or_else(|| {
        let stem = args.models[0]
            .file_stem()
            .map(|s| s.to_os_string())
            .unwrap_or_else(|| "out".into());
        PathBuf::from(stem).with_extension("gco")
    })
}

/// Where each file goes, checked and with its temporary file created, before any slicing.
fn prepare(args: &Args) -> Result<(PathBuf, Staged, Option<Staged>), String> {
    let output = output_path(args);
    let stem = args.models[0].file_stem().unwrap_or("model".as_ref());
    let example = Path::new(stem);
    check_destination(&output, "-o", &example.with_extension("gco"))?;
    if args.models.iter().any(|m| same_file(&output, m)) {
        return Err(format!(
            "-o {}: that is the model file; give another name for the code",
            output.display()
        ));
    }
    if let Some(report) = &args.report {
        check_destination(report, "--report", &example.with_extension("json"))?;
        let model = args.models.iter().any(|m| same_file(report, m));
        if same_file(report, &output) || model {
            return Err(format!(
                "--report {}: that is the {} file; give another name for the report",
                report.display(),
                if same_file(report, &output) {
                    "output"
                } else {
                    "model"
                }
            ));
        }
    }
    let staged = |path: &Path| {
        Staged::create(path).map_err(|e| {
            format!(
                "cannot write in the folder {} (for {}): {e}",
                parent_dir(path).display(),
                path.display()
            )
        })
    };
    let out = staged(&output)?;
    let report = args.report.as_deref().map(staged).transpose()?;
    Ok((output, out, report))
}

fn run(args: &Args, output: &Path, mut out: Staged, report: Option<Staged>) -> Result<(), Error> {
    let t0 = Instant::now();
    let (mut job, name) = load(args)?;
    job.set_profiles(args.profiles.clone());
    for w in &job.info().warnings {
        eprintln!("dropslice: warning: {w}");
    }
    if !args.quiet {
        for p in &job.info().instances {
            eprintln!("dropslice: {}", dropslice::output::gcode::part_line(p));
        }
    }
    // Written to a temporary file beside the target (`out`), put in place only at the end:
    // a failed or interrupted run never destroys an existing file nor leaves a partial one.
    let io = |what: &str, p: &Path, e: std::io::Error| {
        Error::Io(format!("cannot {what} {}: {e}", p.display()))
    };
    let mut w = BufWriter::with_capacity(1 << 20, out.file());
    let quiet = args.quiet;
    let mut last = Instant::now();
    let terminal = std::io::stderr().is_terminal();
    // Progress after the first second: in place on a terminal, a line every 2 s in a log.
    let every_ms = if terminal { 250 } else { 2000 };
    let mut shown = false;
    // With --report, each layer is analysed by the worker that planned it; a job whose layers
    // would take too much memory to analyse is sliced without (the refusal comes at the end).
    let grid = job.analysis_grid();
    let refused = report
        .as_ref()
        .and_then(|_| grid.check(job.settings()).err());
    let mut analysis = report
        .as_ref()
        .filter(|_| refused.is_none())
        .map(|_| JobAnalysis::new(&grid, job.settings()));
    let progress = |done: usize, total: usize| {
        let due = last.elapsed().as_millis() >= every_ms || (done == total && shown);
        if quiet || t0.elapsed().as_secs_f64() < 1.0 || !due {
            return;
        }
        shown = true;
        last = Instant::now();
        let pct = 100 * done / total.max(1);
        if terminal {
            eprint!("\rdropslice: layer {done}/{total} ({pct} %)");
            if done == total {
                eprintln!();
            }
        } else {
            eprintln!("dropslice: layer {done}/{total} ({pct} %)");
        }
    };
    let summary = timed_stages(job.layer_count(), || {
        write_gcode_with(&job, &mut w, progress, &mut analysis)
    })?;
    let finish = || -> std::io::Result<()> {
        let file = w.into_inner().map_err(|e| e.into_error())?;
        // Fill in the header's droplet counts (same length as the placeholders).
        let header = job.header(Some(&summary));
        debug_assert_eq!(header.len(), job.header(None).len());
        file.seek(SeekFrom::Start(0))?;
        file.write_all(header.as_bytes())
    };
    finish().map_err(|e| io("write", output, e))?;
    summary.printable(job.settings())?;
    let mut voids = String::new();
    let mut density = None;
    let mut report_done = None;
    if let (Some(mut staged), Some(analysis)) = (report, analysis) {
        let path = staged.target().to_path_buf();
        let report = analysis.finish();
        let text = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::Internal(format!("the report does not serialize: {e}")))?;
        let file = staged.file();
        file.write_all(text.as_bytes())
            .and_then(|()| file.write_all(b"\n"))
            .map_err(|e| io("write", &path, e))?;
        voids = format!(
            ", void fraction {:.1} % (coverage {:.1} %; report {})",
            100.0 * report.part.estimate.void_fraction,
            100.0 * report.part.coverage,
            path.display()
        );
        density = Some(report.part.unit_densities(job.settings().units as usize));
        report_done = Some(staged);
    }
    // Everything is written: only now are the files put in place.
    out.commit().map_err(|e| io("write", output, e))?;
    if let Some(staged) = report_done {
        let path = staged.target().to_path_buf();
        staged.commit().map_err(|e| io("write", &path, e))?;
    }
    for r in summary.repairs() {
        eprintln!("dropslice: repaired: {r}");
    }
    if !args.quiet {
        let f = summary.figures(job.settings());
        let c = f.counts;
        eprintln!(
            "dropslice: {} → {}: {} layers, {} droplets ({} outer, {} inner, {} fill){voids}, {:.2} cm³, {:.2} g, print time {}, {:.2} s",
            name,
            output.display(),
            f.layers,
            f.droplets,
            c.outer,
            c.inner,
            c.fill,
            f.units[0].volume_mm3 / 1000.0,
            f.units[0].mass_g,
            duration(f.print_seconds),
            t0.elapsed().as_secs_f64()
        );
        eprintln!("dropslice: {}", overhang_line(&f));
        match density {
            Some(by_unit) => {
                if let Some(line) = density_line(&by_unit) {
                    eprintln!("dropslice: {line}");
                }
            }
            None if refused.is_some() => {}
            None => eprintln!(
                "dropslice: predicted density: not estimated (--report FILE.json runs the 3D void analysis, about 3 times the slicing's time)"
            ),
        }
        let support = job.settings().support.unit();
        for (u, unit) in UnitId::all(f.units.len()).zip(&f.units).skip(1) {
            let n = unit.droplets;
            if n == 0 {
                continue;
            }
            let s = if support == Some(u) {
                f.counts.support
            } else {
                0
            };
            eprintln!(
                "dropslice: unit {u}: {n} droplets ({s} support), {:.2} cm³, {:.2} g, {} of unit {u} and {} of unit 0",
                unit.volume_mm3 / 1000.0,
                unit.mass_g,
                duration(unit.seconds),
                duration(f.units[0].seconds)
            );
        }
    }
    match refused {
        // The code is in place; the report was not written (an older file there is kept).
        Some(Error::Analysis(m)) => Err(Error::Analysis(format!(
            "{m}. {} was written, without the report",
            output.display()
        ))),
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// The summary's predicted density, per unit that prints parts (`None` without a figure).
/// `write` with the per-stage counters on when the environment has `DROPSLICE_STAGES=1`: the
/// time of each stage, summed over the writer's threads, to stderr at the end
/// (docs/performance.md).
fn timed_stages<T>(layers: usize, write: impl FnOnce() -> T) -> T {
    if std::env::var_os("DROPSLICE_STAGES").is_none_or(|v| v != "1") {
        return write();
    }
    stages::enable(true);
    let started = Instant::now();
    let result = write();
    let parts: Vec<String> = stages::read()
        .iter()
        .map(|(name, ms)| format!("{name} {ms:.0}"))
        .collect();
    eprintln!(
        "stages (ms, summed over {} threads): {}; the writer's wall {:.0}",
        writer_threads(layers),
        parts.join(", "),
        started.elapsed().as_secs_f64() * 1e3
    );
    result
}

/// The predicted density line of the summary, of each unit's parts (`by_unit`, indexed by
/// unit; `None` where a unit has no parts or no figure).
fn density_line(by_unit: &[Option<f64>]) -> Option<String> {
    const WHAT: &str = "100 % − the 3D void fraction: a geometric estimate from the droplet model, not a measured density";
    let known: Vec<(usize, f64)> = (by_unit.iter().enumerate())
        .filter_map(|(u, d)| Some((u, (*d)?)))
        .collect();
    Some(match known[..] {
        [] => return None,
        [(0, d)] => format!("predicted density {d:.1} % ({WHAT})"),
        _ => {
            let parts: Vec<String> = (known.iter())
                .map(|(u, d)| format!("unit {u}'s parts {d:.1} %"))
                .collect();
            format!("predicted density: {} ({WHAT})", parts.join(", "))
        }
    })
}

/// The job to slice and its name for the summary: one model ([`Job::new`], as always),
/// several models (one part each, arranged) or a job file.
fn load(args: &Args) -> Result<(Job, String), Error> {
    let file_name = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let read = |p: &Path| {
        read_regular(p, dropslice::model::import::MAX_FILE_BYTES, "a model file")
            .map_err(Error::Import)
    };
    if let [one] = &args.models[..] {
        if is_job_file(one).map_err(Error::Import)? {
            return Ok((job_file(one, &args.overrides)?, file_name(one)));
        }
        let bytes = read(one)?;
        let name = file_name(one);
        return Ok((Job::new(&bytes, &name, args.settings.clone())?, name));
    }
    // Several models: one part each, arranged; the part keys go to every part.
    let keys: Vec<String> = args
        .models
        .iter()
        .map(|m| m.to_string_lossy().into_owned())
        .collect();
    let spec = models_job_spec(&keys, &args.settings)?;
    let mut models: Vec<Model> = Vec::new();
    for (m, key) in args.models.iter().zip(&keys) {
        if !models.iter().any(|x| &x.name == key) {
            let bytes = read(m)?;
            models.push(Model::read(&bytes, key).map_err(|e| named(key, e))?);
        }
    }
    let names: Vec<String> = args.models.iter().map(|m| file_name(m)).collect();
    Ok((Job::from_models(&models, &spec)?, names.join(" + ")))
}

/// An import error naming the file it is about.
pub fn named(file: &str, e: Error) -> Error {
    match e {
        Error::Import(m) => Error::Import(format!("{}: {m}", job::clean_name(file))),
        e => e,
    }
}

/// Reads a job file (at most [`job::MAX_JOB_FILE_BYTES`]) and its parts' files (relative
/// to its folder); `overrides` (the settings options) override its settings.
fn job_file(path: &Path, overrides: &[SettingsOverride]) -> Result<Job, Error> {
    let (spec, models) = read_job_file(path, overrides)?;
    Job::from_models(&models, &spec).map_err(|e| in_job_file(path, e))
}

/// A job error with the job file named.
pub fn in_job_file(path: &Path, e: Error) -> Error {
    match e {
        Error::Job(m) => Error::Job(format!("{}: {m}", shown_path(path))),
        e => e,
    }
}

/// A job file's spec (with `overrides`) and the models its parts name, read.
pub fn read_job_file(
    path: &Path,
    overrides: &[SettingsOverride],
) -> Result<(JobSpec, Vec<Model>), Error> {
    let shown = shown_path(path);
    let bytes = read_regular(path, job::MAX_JOB_FILE_BYTES as u64, "a job file")
        .map_err(|e| Error::Job(format!("the job file: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|_| {
        Error::Job(format!(
            "the job file {shown} is not text (UTF-8): it is not a JSON job file"
        ))
    })?;
    let mut spec = JobSpec::from_json(&text).map_err(|e| in_job_file(path, e))?;
    override_settings(&mut spec, overrides)?;
    spec.validate()?;
    let dir = parent_dir(path);
    let mut models: Vec<Model> = Vec::new();
    for (i, p) in spec.parts.iter().enumerate() {
        if models.iter().any(|m| m.name == p.file) {
            continue;
        }
        // Any path is read, also outside the job file's folder (docs/security.md).
        let file = dir.join(&p.file);
        let bytes = read_regular(
            &file,
            dropslice::model::import::MAX_FILE_BYTES,
            "a model file",
        )
        .map_err(|e| Error::Import(format!("parts[{i}].file: {e} (named in {shown})")))?;
        models.push(Model::read(&bytes, &p.file).map_err(|e| named(&p.file, e))?);
    }
    Ok((spec, models))
}

/// The unsupported area (support on or off): total and the worst layer.
fn overhang_line(f: &dropslice::Figures) -> String {
    match f.worst_overhang {
        Some(w) => format!(
            "unsupported (overhang) area {:.1} mm² over all layers; worst layer {}: {:.1} mm²",
            f.unsupported_area,
            w.index + 1,
            w.area
        ),
        None => "no overhangs (every layer rests on the one below)".into(),
    }
}

/// A print time as the page shows it: "1 h 5 min", "3 min 2 s", "40 s".
fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "–".into();
    }
    let s = seconds.round() as u64;
    let (h, m, s) = (s / 3600, s / 60 % 60, s % 60);
    if h > 0 {
        format!("{h} h {m} min")
    } else if m > 0 {
        format!("{m} min {s} s")
    } else {
        format!("{s} s")
    }
}
