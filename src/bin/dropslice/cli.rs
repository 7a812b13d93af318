//! The command line: clap's types and help texts, the settings options in the order given,
//! and clap's usage errors as the tool's one-line messages.

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{ArgMatches, Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use dropslice::base::error::quote;
use std::ffi::OsString;
use std::path::PathBuf;

const USAGE: &str = "dropslice [slice] MODEL... [OPTIONS]
       dropslice [slice] JOB.json [OPTIONS]
       dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]
       dropslice orient MODEL_OR_JOB [--apply] [--profile FILE.json]... [--set NAME=VALUE]...";

const ABOUT: &str =
    "Slices models into droplet machine code (.gco) for droplet-based plastic 3D printing";

const LONG_ABOUT: &str = "\
Slices a model (STL, binary or ASCII; OBJ; or a 3MF build, all its items in their places)
into droplet machine code (.gco: G01 travel, G25 droplet line, G26 droplet). `slice` is the
default command: `dropslice MODEL` is `dropslice slice MODEL`.";

const AFTER_LONG_HELP: &str = "\
Build jobs:
  Several models make a build job: one part each, arranged on the plate (plate_x, plate_y,
  part_spacing); rotate_* and scale_* then apply to every part, place_* is refused (give the
  parts' places in a job file). A job file (JSON: named *.json, or not named .stl/.obj/.3mf
  and starting with '{') lists the settings and the parts:
    {\"settings\": {\"layer_height\": 0.2},
     \"parts\": [{\"file\": \"a.stl\", \"rotate_z\": 90, \"place_x\": 30, \"place_y\": 5},
               {\"file\": \"gear.3mf\", \"item\": 0, \"copies\": 3}]}
  Part keys: file (relative to the job file's folder), item (a 3MF build item, from 0;
  none: the whole build), rotate_x/y/z, scale_x/y/z, mirror_x/y/z (true: mirrored along
  that plate axis), place_x + place_y (none: arranged),
  place_angle, copies (1..100), unit (0 or 1: the discharge unit; where parts of
  different units overlap, the part listed first keeps the overlap). --set and --settings
  override the job file's settings (not the parts').

Output:
  The code (and the report) are written to a temporary file beside the target and put in
  place only when the run succeeds: a failed or interrupted run leaves no partial file and
  does not touch an existing one.

Exit codes:
  0 done, 2 bad input or settings (the message says what to fix), 1 other errors,
  130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP.";

#[derive(Parser, Debug)]
#[command(
    name = "dropslice",
    version,
    about = ABOUT,
    long_about = LONG_ABOUT,
    override_usage = USAGE,
    after_long_help = AFTER_LONG_HELP,
    args_conflicts_with_subcommands = true,
    args_override_self = true,
    disable_help_subcommand = true,
    propagate_version = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    slice: SliceArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Slice models or a job file into droplet machine code (the default command)
    #[command(
        override_usage = "dropslice [slice] MODEL... [OPTIONS]\n       dropslice [slice] JOB.json [OPTIONS]",
        long_about = LONG_ABOUT,
        after_long_help = AFTER_LONG_HELP,
        args_override_self = true,
        display_name = "dropslice"
    )]
    Slice(SliceArgs),
    /// Droplet size from a printed part's mass and its code
    ///
    /// From a printed part's mass, its code's droplet count (the header's, else counted from
    /// the commands) and the material density (default: the header's material_density),
    /// prints the droplet volume, the filling degree of the B²H cells and the droplet_aspect
    /// that fills them exactly.
    #[command(
        override_usage = "dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]",
        args_override_self = true,
        display_name = "dropslice",
        verbatim_doc_comment
    )]
    Calibrate(CalibrateArgs),
    /// The rotation of each part that needs the least support
    ///
    /// Compares the part's orientations (its largest flat faces down, and its right-angle
    /// turns) by the overhang rule, from the facets: the projected area of the facets
    /// facing down more steeply than overhang_limit allows; ties go to the lower height.
    /// Prints the chosen rotate_x/y/z and the area before and after. --apply writes them
    /// into the job file (only those values change: its other text, key order, mode, owner
    /// and links are kept; a symlink's target is written; a read-only file is refused), or
    /// for a model a new job file MODEL.job.json beside it.
    #[command(
        override_usage = "dropslice orient MODEL_OR_JOB [--apply] [--profile FILE.json]... [--set NAME=VALUE]...",
        args_override_self = true,
        display_name = "dropslice",
        verbatim_doc_comment
    )]
    Orient(OrientArgs),
}

/// `dropslice orient ...`.
#[derive(Args, Debug, Clone)]
pub struct OrientArgs {
    /// A model (STL, OBJ, 3MF) or a job file (JSON)
    #[arg(value_name = "MODEL_OR_JOB")]
    pub file: Option<PathBuf>,
    /// Write the chosen rotation into the job file (for a model: a new MODEL.job.json)
    #[arg(long)]
    pub apply: bool,
    /// Change one setting (overhang_limit, layer_height, droplet_aspect decide the rule;
    /// for a model also its rotate_* and scale_*)
    #[arg(long, value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub set: Vec<String>,
    /// Apply a machine or material profile (JSON; repeatable, in order, before --set), as
    /// slicing does (unitN=FILE.json: a material for unit N): a material's droplet_aspect
    /// and shrinkage change the rule and the scale
    #[arg(long, value_name = "[unitN=]FILE.json", allow_hyphen_values = true)]
    pub profile: Vec<PathBuf>,
}

/// `dropslice [slice] ...`.
#[derive(Args, Debug, Clone)]
pub struct SliceArgs {
    /// Model files (STL, OBJ, 3MF; several make a build job), or one job file (JSON)
    #[arg(value_name = "MODEL")]
    pub models: Vec<PathBuf>,
    /// Where to write the code [default: MODEL.gco in the current directory]
    #[arg(short = 'o', long, value_name = "OUT.gco", allow_hyphen_values = true)]
    pub output: Option<PathBuf>,
    /// Change one setting (repeatable; see --list-settings)
    #[arg(long, value_name = "NAME=VALUE", allow_hyphen_values = true)]
    set: Vec<String>,
    /// Read settings from a JSON object {"name": value, ...}
    ///
    /// The others keep their defaults; --set options given later override it (and it
    /// replaces --set options given before it).
    #[arg(
        long,
        value_name = "FILE.json",
        allow_hyphen_values = true,
        verbatim_doc_comment
    )]
    settings: Vec<PathBuf>,
    /// Apply a machine or material profile (JSON; repeatable, in order, before --set)
    ///
    /// {"name": "...", "kind": "machine" | "material", "settings": {...}}: a machine
    /// profile holds plate_x/y/z, units, droplet_rate, unitN_droplet_rate, travel_speed; a
    /// material profile one material: droplet_aspect, material_density, shrink_xy,
    /// shrink_z. unitN=FILE.json gives the material to unit N (--profile unit2=pva.json);
    /// FILE.json alone sets the values as its keys name them (unit 0's, and in a profile
    /// saved before, unit1_ keys unit 1's). The header names the profiles used.
    #[arg(
        long,
        value_name = "[unitN=]FILE.json",
        allow_hyphen_values = true,
        verbatim_doc_comment
    )]
    pub profile: Vec<PathBuf>,
    /// Print every setting with its default, unit, range and meaning
    #[arg(long)]
    pub list_settings: bool,
    /// Also analyse the droplets and write the report (JSON)
    ///
    /// The report: coverage, voids, overfill, boundary deviation per layer and for the
    /// part, and the part's 3D void fraction (model: docs/quality.md); the summary line
    /// shows the latter. Layers are numbered from 1. A job whose layers would take more
    /// than 1 GB each to analyse is sliced without the report (exit code 2).
    #[arg(
        long,
        value_name = "FILE.json",
        allow_hyphen_values = true,
        verbatim_doc_comment
    )]
    pub report: Option<PathBuf>,
    /// No progress, only errors
    #[arg(short, long)]
    pub quiet: bool,
}

/// `dropslice calibrate ...`. The numbers are read as text and checked by the command, for
/// its own messages.
#[derive(Args, Debug, Clone)]
pub struct CalibrateArgs {
    /// The printed part's code (.gco)
    #[arg(value_name = "PART.gco")]
    pub file: Option<PathBuf>,
    /// The printed part's mass in grams
    #[arg(long, value_name = "GRAMS", allow_hyphen_values = true)]
    pub mass: Option<String>,
    /// The material's density in g/cm³ [default: the code header's material_density]
    #[arg(long, value_name = "G_CM3", allow_hyphen_values = true)]
    pub density: Option<String>,
}

/// A settings option, in the order given on the command line.
#[derive(Debug, Clone)]
pub enum SettingsArg {
    /// `--set NAME=VALUE`, as given.
    Set(String),
    /// `--settings FILE.json`.
    File(PathBuf),
}

/// What the command line asks for.
pub enum Action {
    Slice(SliceArgs, Vec<SettingsArg>),
    Calibrate(CalibrateArgs),
    Orient(OrientArgs),
}

/// Parses the command line (`argv` with the program's name first). The error is clap's: help
/// and version requests as well as usage errors; [`exit`] shows it.
pub fn parse(argv: impl IntoIterator<Item = OsString>) -> Result<Action, clap::Error> {
    let matches = Cli::command().try_get_matches_from(argv)?;
    let cli = Cli::from_arg_matches(&matches)?;
    Ok(match (cli.command, matches.subcommand()) {
        (Some(Command::Calibrate(c)), _) => Action::Calibrate(c),
        (Some(Command::Orient(o)), _) => Action::Orient(o),
        (Some(Command::Slice(s)), Some((_, m))) => Action::Slice(s, settings_in_order(m)),
        _ => Action::Slice(cli.slice, settings_in_order(&matches)),
    })
}

/// `--set` and `--settings` in the order given: a settings file replaces what came before it.
fn settings_in_order(m: &ArgMatches) -> Vec<SettingsArg> {
    let mut all: Vec<(usize, SettingsArg)> = Vec::new();
    if let (Some(at), Some(values)) = (m.indices_of("set"), m.get_many::<String>("set")) {
        all.extend(at.zip(values.map(|v| SettingsArg::Set(v.clone()))));
    }
    if let (Some(at), Some(values)) = (m.indices_of("settings"), m.get_many::<PathBuf>("settings"))
    {
        all.extend(at.zip(values.map(|v| SettingsArg::File(v.clone()))));
    }
    all.sort_by_key(|(at, _)| *at);
    all.into_iter().map(|(_, a)| a).collect()
}

/// Shows a help or version request on stdout (exit 0), or a usage error as one short line on
/// stderr (exit 2). `argv` tells which command the error is about.
pub fn exit(e: clap::Error, argv: &[OsString]) -> std::process::ExitCode {
    if !e.use_stderr() {
        // --help, --version: clap's text.
        let _ = e.print();
        return std::process::ExitCode::SUCCESS;
    }
    let calibrate = argv.get(1).is_some_and(|a| a == "calibrate");
    let orient = argv.get(1).is_some_and(|a| a == "orient");
    let (who, help) = if calibrate {
        ("dropslice calibrate", "dropslice calibrate --help")
    } else if orient {
        ("dropslice orient", "dropslice orient --help")
    } else {
        ("dropslice", "dropslice --help")
    };
    eprintln!("{who}: {}; see {help}", usage_error(&e, calibrate));
    std::process::ExitCode::from(2)
}

/// A usage error in the tool's words, on one line and short whatever the arguments.
fn usage_error(e: &clap::Error, calibrate: bool) -> String {
    let context = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.as_str()),
        _ => None,
    };
    // "--output <OUT.gco>" → "--output".
    let option = || context(ContextKind::InvalidArg).and_then(|a| a.split(' ').next());
    match e.kind() {
        ErrorKind::UnknownArgument => match context(ContextKind::InvalidArg) {
            Some(a) if a.starts_with('-') => {
                let mut m = format!("unknown option '{}'", quote(a));
                if let Some(s) = context(ContextKind::SuggestedArg) {
                    m += &format!(" (did you mean '{}'?)", quote(s));
                }
                m
            }
            Some(a) if calibrate => {
                format!("give one .gco file only ('{}' is a second one)", quote(a))
            }
            Some(a) => format!("unexpected argument '{}'", quote(a)),
            None => first_line(e),
        },
        ErrorKind::InvalidValue if context(ContextKind::InvalidValue) == Some("") => {
            match option() {
                Some(o) => format!("{o} needs a value"),
                None => first_line(e),
            }
        }
        ErrorKind::InvalidUtf8 => {
            "an argument is not text (UTF-8); give the names of files and settings as text".into()
        }
        _ => first_line(e),
    }
}

/// The first line of clap's message, without its "error: ", cut short.
fn first_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let line = text.lines().next().unwrap_or_default();
    let line = line.strip_prefix("error: ").unwrap_or(line);
    match line.char_indices().nth(300) {
        Some((at, _)) => format!("{}…", &line[..at]),
        None => line.to_string(),
    }
}
