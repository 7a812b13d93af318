//! The command-line tool: `dropslice MODEL... [-o OUT.gco] [--set name=value]... [--settings FILE.json]`,
//! or `dropslice JOB.json` (a build job file, SPEC.md "Build jobs").
//!
//! The tool is native only: built for wasm32 (as a side effect of building the wasm tests)
//! it is an empty program.

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    cli::main()
}

#[cfg(target_arch = "wasm32")]
fn main() {}

#[cfg(not(target_arch = "wasm32"))]
mod cli {
    use dropslice::analysis::JobAnalysis;
    use dropslice::base::error::quote;
    use dropslice::model::models::Model;
    use dropslice::model::spec::{self as job, JobSpec, PartSpec};
    use dropslice::{Error, Job, Settings, write_gcode_with};
    use staged::Staged;
    use std::io::{BufWriter, IsTerminal, Seek, SeekFrom, Write};
    use std::path::{Path, PathBuf};
    use std::process::ExitCode;
    use std::time::Instant;

    const USAGE: &str = "\
usage: dropslice MODEL... [-o OUT.gco] [--set name=value]... [--settings FILE.json] [-q]
       dropslice JOB.json [-o OUT.gco] [--set name=value]... [--settings FILE.json] [-q]
       dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]

Slices a model (STL, binary or ASCII; OBJ; or a 3MF build, all its items in their
places) into droplet machine code (.gco: G01 travel, G25 droplet line, G26 droplet).

Several models make a build job: one part each, arranged on the plate (plate_x, plate_y,
part_spacing); rotate_* and scale_* then apply to every part, place_* is refused (give the
parts' places in a job file). A job file (JSON: named *.json, or not named .stl/.obj/.3mf
and starting with '{') lists
the settings and the parts:
  {\"settings\": {\"layer_height\": 0.2},
   \"parts\": [{\"file\": \"a.stl\", \"rotate_z\": 90, \"place_x\": 30, \"place_y\": 5},
             {\"file\": \"gear.3mf\", \"item\": 0, \"copies\": 3}]}
Part keys: file (relative to the job file's folder), item (a 3MF build item, from 0;
none: the whole build), rotate_x/y/z, scale_x/y/z, place_x + place_y (none: arranged),
place_angle, copies (1..100), unit (0 or 1: the discharge unit; where parts of
different units overlap, the part listed first keeps the overlap). --set and --settings
override the job file's settings (not the parts').

  -o, --output FILE      where to write the code (default: MODEL.gco in the current directory)
  --set name=value       change one setting (repeatable; see --list-settings)
  --settings FILE.json   read settings from a JSON object {\"name\": value, ...}
                         (--set options given later override it)
  --list-settings        print every setting with its default, unit, range and meaning
  --report FILE.json     also analyse the droplets: coverage, voids, overfill, boundary
                         deviation per layer and for the part, and the part's 3D void
                         fraction (model: docs/quality.md); the summary line shows the latter
  -q, --quiet            no progress, only errors
  -h, --help             this text
  -V, --version          the version

dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]: from a printed part's mass, its
code's droplet count (header, else counted) and the material density (default: the header's
material_density) prints the droplet volume, the filling degree of the B²H cells and the
droplet_aspect that fills them exactly.

The code (and the report) are written to a temporary file beside the target and put in
place only when the run succeeds: a failed or interrupted run leaves no partial file and
does not touch an existing one.

Exit codes: 0 done, 2 bad input or settings (the message says what to fix), 1 other errors,
130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP.";

    struct Args {
        models: Vec<PathBuf>,
        output: Option<PathBuf>,
        /// The defaults with `ops` applied.
        settings: Settings,
        /// `--set` and `--settings` in order (applied again to a job file's settings).
        ops: Vec<Op>,
        quiet: bool,
        report: Option<PathBuf>,
    }

    /// A settings option.
    enum Op {
        Set(String, String),
        /// A settings file's object.
        File(String, serde_json::Map<String, serde_json::Value>),
    }

    enum Parsed {
        Run(Box<Args>),
        Exit(String),
    }

    pub fn main() -> ExitCode {
        let argv: Vec<String> = std::env::args().skip(1).collect();
        if argv.first().is_some_and(|a| a == "calibrate") {
            return match calibrate(&argv[1..]) {
                Ok(text) => {
                    println!("{text}");
                    ExitCode::SUCCESS
                }
                Err(msg) => {
                    eprintln!("dropslice calibrate: {msg}");
                    ExitCode::from(2)
                }
            };
        }
        let args = match parse_args(&argv) {
            Ok(Parsed::Run(a)) => a,
            Ok(Parsed::Exit(text)) => {
                println!("{text}");
                return ExitCode::SUCCESS;
            }
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
        match run(&args, &output, out, report) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("dropslice: {e}");
                match e {
                    Error::Io(_) | Error::Internal(_) => ExitCode::from(1),
                    _ => ExitCode::from(2),
                }
            }
        }
    }

    fn parse_args(argv: &[String]) -> Result<Parsed, String> {
        let mut models = Vec::new();
        let mut ops = Vec::new();
        let mut output = None;
        let mut settings = Settings::default();
        let mut quiet = false;
        let mut report = None;
        let mut it = argv.iter();
        let value = |it: &mut std::slice::Iter<String>, opt: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{opt} needs a value\n\n{USAGE}"))
        };
        while let Some(a) = it.next() {
            match a.as_str() {
                "-h" | "--help" => return Ok(Parsed::Exit(USAGE.into())),
                "-V" | "--version" => {
                    return Ok(Parsed::Exit(format!("dropslice {}", dropslice::VERSION)));
                }
                "--list-settings" => return Ok(Parsed::Exit(list_settings())),
                "-q" | "--quiet" => quiet = true,
                "-o" | "--output" => output = Some(PathBuf::from(value(&mut it, a)?)),
                "--report" => report = Some(PathBuf::from(value(&mut it, a)?)),
                "--set" => {
                    let kv = value(&mut it, a)?;
                    let (k, v) = kv
                        .split_once('=')
                        .ok_or_else(|| format!("--set expects name=value, got '{}'", quote(&kv)))?;
                    settings.set(k.trim(), v).map_err(|e| e.to_string())?;
                    ops.push(Op::Set(k.trim().to_string(), v.to_string()));
                }
                "--settings" => {
                    let path = value(&mut it, a)?;
                    let bytes = read_regular(
                        Path::new(&path),
                        dropslice::base::settings::MAX_SETTINGS_FILE_BYTES as u64,
                        "a settings file",
                    )
                    .map_err(|e| format!("the settings file: {e}"))?;
                    let text = String::from_utf8(bytes).map_err(|_| {
                        format!("the settings file {path} is not text (UTF-8): it is not a JSON settings file")
                    })?;
                    settings = Settings::from_json(&text).map_err(|e| format!("{path}: {e}"))?;
                    if let Ok(serde_json::Value::Object(map)) = serde_json::from_str(&text) {
                        ops.push(Op::File(path, map));
                    }
                }
                s if s.starts_with('-') && s.len() > 1 => {
                    return Err(format!("unknown option '{}'\n\n{USAGE}", quote(s)));
                }
                s => {
                    if models.len() >= job::MAX_PARTS {
                        return Err(format!(
                            "more than {} model files given; a job has at most {} parts",
                            job::MAX_PARTS,
                            job::MAX_PARTS
                        ));
                    }
                    models.push(PathBuf::from(s));
                }
            }
        }
        if models.is_empty() {
            return Err(format!("no model file given\n\n{USAGE}"));
        }
        settings.validate().map_err(|e| e.to_string())?;
        Ok(Parsed::Run(Box::new(Args {
            models,
            output,
            settings,
            ops,
            quiet,
            report,
        })))
    }

    /// `dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]`: the figures, or why not.
    fn calibrate(argv: &[String]) -> Result<String, String> {
        const CAL_USAGE: &str =
            "usage: dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]";
        let (mut file, mut mass, mut density) = (None, None, None);
        let mut it = argv.iter();
        let number = |it: &mut std::slice::Iter<String>, opt: &str| -> Result<f64, String> {
            let v = it
                .next()
                .ok_or_else(|| format!("{opt} needs a value\n\n{CAL_USAGE}"))?;
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{opt} {}: not a number", quote(v)))
        };
        while let Some(a) = it.next() {
            match a.as_str() {
                "-h" | "--help" => return Ok(CAL_USAGE.into()),
                "--mass" => mass = Some(number(&mut it, a)?),
                "--density" => density = Some(number(&mut it, a)?),
                s if s.starts_with('-') && s.len() > 1 => {
                    return Err(format!("unknown option '{}'\n\n{CAL_USAGE}", quote(s)));
                }
                s => {
                    if file.replace(PathBuf::from(s)).is_some() {
                        return Err(format!(
                            "give one .gco file only ('{}' is a second one)",
                            quote(s)
                        ));
                    }
                }
            }
        }
        let file = file.ok_or_else(|| format!("no .gco file given\n\n{CAL_USAGE}"))?;
        let mass = mass.ok_or_else(|| format!("--mass GRAMS is needed\n\n{CAL_USAGE}"))?;
        let reader = read_counting(&file)?;
        let c = dropslice::output::calibrate::calibrate_read(&reader, mass, density)
            .map_err(|e| format!("{}: {e}", file.display()))?;
        Ok(format!(
            "{}\n  droplets          {} ({})\n  droplet volume    {:.5} mm³ (m / (N ρ), ρ = {} g/cm³)\n  cell B²H          {:.5} mm³ (H = {} mm, droplet_aspect = {})\n  filling degree    {:.3}\n  droplet_aspect    {:.3} suggested (now {})",
            c.explanation,
            c.droplets,
            match c.count_source {
                dropslice::output::calibrate::CountSource::Header => "from the header",
                _ => "counted from the commands",
            },
            c.droplet_volume_mm3,
            c.density_g_cm3,
            c.cell_volume_mm3,
            c.layer_height,
            c.current_droplet_aspect,
            c.filling_degree,
            c.suggested_droplet_aspect,
            c.current_droplet_aspect
        ))
    }

    /// A path for a message: as given, cut to 240 characters (a job file may name anything).
    fn shown_path(path: &Path) -> String {
        let s = path.display().to_string();
        match s.char_indices().nth(240) {
            Some((at, _)) => format!("{}…", &s[..at]),
            None => s,
        }
    }

    /// Opens `path` for reading if it is a regular file: a device (`/dev/zero`, `/dev/stdin`),
    /// a FIFO, a socket or a folder is refused. The file is opened without blocking (a FIFO
    /// swapped in after a check cannot hang the open) and checked on the open handle. Returns
    /// the file and its size.
    fn open_regular(path: &Path) -> Result<(std::fs::File, u64), String> {
        let shown = shown_path(path);
        let mut options = std::fs::OpenOptions::new();
        options.read(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            options.custom_flags(libc::O_NONBLOCK);
        }
        let f = options
            .open(path)
            .map_err(|e| format!("cannot open {shown}: {e}"))?;
        let meta = f
            .metadata()
            .map_err(|e| format!("cannot open {shown}: {e}"))?;
        if meta.is_dir() {
            return Err(format!(
                "cannot open {shown}: it is a directory, not a file"
            ));
        }
        if !meta.is_file() {
            return Err(format!(
                "cannot read {shown}: it is not a regular file (a device, a pipe or a socket); dropslice reads files only — save the data to a file first"
            ));
        }
        Ok((f, meta.len()))
    }

    /// Reads a regular file ([`open_regular`]) of at most `max` bytes, checked before reading
    /// (and again while reading, should the file grow); `what` names it in the message
    /// ("a model file").
    fn read_regular(path: &Path, max: u64, what: &str) -> Result<Vec<u8>, String> {
        use std::io::Read;
        let (f, len) = open_regular(path)?;
        let too_big = |n: u64| {
            format!(
                "cannot read {}: it is {n} bytes, and {what} is read only up to {max} bytes",
                shown_path(path)
            )
        };
        if len > max {
            return Err(too_big(len));
        }
        let mut bytes = Vec::with_capacity(len as usize);
        f.take(max + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| format!("cannot read {}: {e}", shown_path(path)))?;
        if bytes.len() as u64 > max {
            return Err(too_big(bytes.len() as u64));
        }
        Ok(bytes)
    }

    /// Reads a `.gco` file through the core's reader (counting only), in pieces of whole lines.
    fn read_counting(path: &Path) -> Result<dropslice::output::gcode_read::GcodeReader, String> {
        use std::io::Read;
        let shown = path.display();
        let (mut f, _) = open_regular(path)?;
        let mut r = dropslice::output::gcode_read::GcodeReader::counting();
        let mut buf: Vec<u8> = Vec::new();
        let mut chunk = vec![0u8; 1 << 20];
        loop {
            let n = f
                .read(&mut chunk)
                .map_err(|e| format!("cannot read {shown}: {e}"))?;
            if n == 0 {
                break;
            }
            buf.extend_from_slice(&chunk[..n]);
            let Some(nl) = buf.iter().rposition(|&c| c == b'\n') else {
                if buf.len() > 4 * dropslice::output::gcode_read::MAX_LINE_CHARS {
                    return Err(format!(
                        "{shown}: a line is longer than {} characters: not a G-code file",
                        dropslice::output::gcode_read::MAX_LINE_CHARS
                    ));
                }
                continue;
            };
            let text = std::str::from_utf8(&buf[..=nl])
                .map_err(|_| format!("{shown}: not a text file (a .gco file is ASCII text)"))?;
            r.feed(text).map_err(|e| format!("{shown}: {e}"))?;
            while r.take_layer().is_some() {}
            buf.drain(..=nl);
        }
        let rest = std::str::from_utf8(&buf)
            .map_err(|_| format!("{shown}: not a text file (a .gco file is ASCII text)"))?;
        r.feed(rest).map_err(|e| format!("{shown}: {e}"))?;
        r.finish().map_err(|e| format!("{shown}: {e}"))?;
        while r.take_layer().is_some() {}
        Ok(r)
    }

    fn list_settings() -> String {
        let mut out = String::new();
        for s in dropslice::base::settings::schema() {
            let range = match (s.min, s.max) {
                (Some(lo), Some(hi)) => {
                    format!(" [{}{lo} … {hi}]", if s.min_exclusive { ">" } else { "" })
                }
                _ if !s.choices.is_empty() => format!(" [{}]", s.choices.join(" | ")),
                _ => String::new(),
            };
            out.push_str(&format!(
                "{:<18} = {:<16} {:<6}{range}\n    {}\n",
                s.name,
                s.default.to_string().trim_matches('"'),
                s.unit,
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

    /// Checks, before any slicing, that `path` (given with `option`) can be written: not a
    /// directory or a device, in a folder that exists. Whether the folder is writable is
    /// checked by creating the temporary file there ([`Staged::create`]).
    fn check_destination(path: &Path, option: &str, example: &Path) -> Result<(), String> {
        let shown = path.display();
        let text = path.as_os_str().to_string_lossy();
        if text.is_empty() {
            return Err(format!("{option} needs a file name"));
        }
        let is_dir = || {
            let dir = Path::new(text.trim_end_matches('/'));
            format!(
                "{option} {shown}: is a directory, not a file name (give a file in it, e.g. {})",
                dir.join(example).display()
            )
        };
        if text.ends_with('/') || path.file_name().is_none() {
            return Err(is_dir());
        }
        match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => return Err(is_dir()),
            Ok(m) if !m.is_file() => {
                return Err(format!(
                    "{option} {shown}: exists and is not a regular file; give the name of a file"
                ));
            }
            _ => {}
        }
        let dir = parent_dir(path);
        match std::fs::metadata(&dir) {
            Ok(m) if m.is_dir() => Ok(()),
            Ok(_) => Err(format!(
                "{option} {shown}: {} is not a folder",
                dir.display()
            )),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(format!(
                "{option} {shown}: the folder {} does not exist; create it first",
                dir.display()
            )),
            Err(e) => Err(format!(
                "{option} {shown}: cannot use the folder {}: {e}",
                dir.display()
            )),
        }
    }

    /// The folder a file is written in ("." for a bare name).
    fn parent_dir(path: &Path) -> PathBuf {
        match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        }
    }

    /// The same file, as far as can be told before it exists: the folder resolved, same name.
    fn same_file(a: &Path, b: &Path) -> bool {
        let resolve = |p: &Path| {
            std::fs::canonicalize(p).ok().or_else(|| {
                let dir = std::fs::canonicalize(parent_dir(p)).ok()?;
                Some(dir.join(p.file_name()?))
            })
        };
        matches!((resolve(a), resolve(b)), (Some(x), Some(y)) if x == y)
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

    fn run(
        args: &Args,
        output: &Path,
        mut out: Staged,
        report: Option<Staged>,
    ) -> Result<(), Error> {
        let t0 = Instant::now();
        let (job, name) = load(args)?;
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
        // With --report, each layer is analysed by the worker that planned it.
        let mut analysis = report.as_ref().map(|_| JobAnalysis::new(&job));
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
        let summary = write_gcode_with(&job, &mut w, progress, &mut analysis)?;
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
                100.0 * report.part.void_fraction,
                100.0 * report.part.coverage,
                path.display()
            );
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
                f.volume_mm3 / 1000.0,
                f.mass_g,
                duration(f.print_seconds),
                t0.elapsed().as_secs_f64()
            );
            eprintln!("dropslice: {}", overhang_line(&f));
            if f.unit1_droplets > 0 {
                eprintln!(
                    "dropslice: unit 1: {} droplets ({} support), {:.2} cm³, {:.2} g, {} of unit 1 and {} of unit 0",
                    f.unit1_droplets,
                    f.counts.support,
                    f.unit1_volume_mm3 / 1000.0,
                    f.unit1_mass_g,
                    duration(f.unit1_seconds),
                    duration(f.unit0_seconds)
                );
            }
        }
        Ok(())
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
            if is_job_file(one)? {
                return Ok((job_file(one, &args.ops)?, file_name(one)));
            }
            let bytes = read(one)?;
            let name = file_name(one);
            return Ok((Job::new(&bytes, &name, args.settings.clone())?, name));
        }
        // Several models: one part each, arranged; the part keys go to every part.
        let s = &args.settings;
        if s.place_x != 0.0 || s.place_y != 0.0 || s.place_angle != 0.0 {
            return Err(Error::Job(
                "place_x, place_y and place_angle cannot be given for several models at once: write a job file with each part's place (see --help), or leave them out and the parts are arranged".into(),
            ));
        }
        let mut models: Vec<Model> = Vec::new();
        let mut parts = Vec::new();
        for m in &args.models {
            let key = m.to_string_lossy().into_owned();
            if !models.iter().any(|x| x.name == key) {
                let bytes = read(m)?;
                models.push(Model::read(&bytes, &key).map_err(|e| named(&key, e))?);
            }
            parts.push(PartSpec {
                rotate_x: s.rotate_x,
                rotate_y: s.rotate_y,
                rotate_z: s.rotate_z,
                scale_x: s.scale_x,
                scale_y: s.scale_y,
                scale_z: s.scale_z,
                ..PartSpec::new(&key)
            });
        }
        let spec = JobSpec {
            settings: without_part_keys(s),
            parts,
        };
        let names: Vec<String> = args.models.iter().map(|m| file_name(m)).collect();
        Ok((Job::from_models(&models, &spec)?, names.join(" + ")))
    }

    /// An import error naming the file it is about.
    fn named(file: &str, e: Error) -> Error {
        match e {
            Error::Import(m) => Error::Import(format!("{}: {m}", job::clean_name(file))),
            e => e,
        }
    }

    /// The settings with the part keys at their defaults (they went to the parts).
    fn without_part_keys(s: &Settings) -> Settings {
        let d = Settings::default();
        Settings {
            rotate_x: d.rotate_x,
            rotate_y: d.rotate_y,
            rotate_z: d.rotate_z,
            scale_x: d.scale_x,
            scale_y: d.scale_y,
            scale_z: d.scale_z,
            place_x: d.place_x,
            place_y: d.place_y,
            place_angle: d.place_angle,
            ..s.clone()
        }
    }

    /// A job file: named `*.json`, or not named as a model (`.stl`, `.obj`, `.3mf`) and its
    /// first non-blank byte is `{` (a model file holding JSON gets the model reader's message).
    fn is_job_file(path: &Path) -> Result<bool, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("json") => return Ok(true),
            Some("stl" | "obj" | "3mf") => return Ok(false),
            _ => {}
        }
        use std::io::Read;
        let mut start = [0u8; 64];
        let (mut f, _) = open_regular(path).map_err(Error::Import)?;
        let n = f
            .read(&mut start)
            .map_err(|e| Error::Import(format!("cannot read {}: {e}", shown_path(path))))?;
        Ok(start[..n]
            .iter()
            .find(|b| !b.is_ascii_whitespace())
            .is_some_and(|&b| b == b'{'))
    }

    /// Reads a job file (at most [`job::MAX_JOB_FILE_BYTES`]) and its parts' files (relative
    /// to its folder); `ops` override its settings.
    fn job_file(path: &Path, ops: &[Op]) -> Result<Job, Error> {
        let shown = shown_path(path);
        let bytes = read_regular(path, job::MAX_JOB_FILE_BYTES as u64, "a job file")
            .map_err(|e| Error::Job(format!("the job file: {e}")))?;
        let text = String::from_utf8(bytes).map_err(|_| {
            Error::Job(format!(
                "the job file {shown} is not text (UTF-8): it is not a JSON job file"
            ))
        })?;
        let in_file = |e: Error| match e {
            Error::Job(m) => Error::Job(format!("{shown}: {m}")),
            e => e,
        };
        let mut spec = JobSpec::from_json(&text).map_err(in_file)?;
        let base = spec.settings.clone();
        let part_key = |k: &str| {
            Error::Job(format!(
                "{k} belongs to a part: give it in the job file's parts, not with --set or --settings"
            ))
        };
        for op in ops {
            match op {
                Op::Set(k, v) => {
                    if job::PART_KEYS.contains(&k.as_str()) {
                        return Err(part_key(k));
                    }
                    spec.settings.set(k, v)?;
                }
                Op::File(file, map) => {
                    spec.settings = base.clone();
                    for (k, v) in map {
                        if job::PART_KEYS.contains(&k.as_str()) {
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
        Job::from_models(&models, &spec).map_err(in_file)
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

    /// Files written beside their destination and put in place only when complete.
    ///
    /// On Linux the file is first unnamed (`O_TMPFILE` in the destination's folder): if the
    /// process dies in any way, even by SIGKILL or the OOM killer, nothing is left. At the end
    /// it is linked under a fresh temporary name (`linkat` of `/proc/self/fd/N`) and renamed
    /// over the destination. Where that is not available (another system, a file system
    /// without `O_TMPFILE`, no `/proc`), or with `DROPSLICE_NAMED_TEMP=1` (for the tests), it
    /// is a named file `.NAME.XXXXXX.partial` created exclusively (never through an existing
    /// link), removed on every error and, by the signal handler, on SIGINT, SIGTERM and SIGHUP.
    mod staged {
        use std::fs::File;
        use std::io;
        use std::path::{Path, PathBuf};
        use std::sync::{Mutex, MutexGuard};
        use tempfile::TempPath;

        /// Named temporary files that exist now: the signal handler removes them. Held while a
        /// file is created, put in place or removed, so the handler never races with that.
        static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

        fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
            PENDING.lock().unwrap_or_else(|e| e.into_inner())
        }

        /// Starts a thread that, on SIGINT, SIGTERM or SIGHUP, removes the pending temporary
        /// files and exits with 128 + the signal's number (130, 143, 129).
        pub fn remove_on_signals() {
            use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
            let mut signals = match signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!(
                        "dropslice: warning: cannot handle signals ({e}); an interrupted run may leave a .partial file"
                    );
                    return;
                }
            };
            std::thread::spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    // Kept locked until the exit: a file being put in place is finished first,
                    // and none is created after this.
                    let files = pending();
                    for f in files.iter() {
                        let _ = std::fs::remove_file(f);
                    }
                    let name = match signal {
                        SIGINT => "SIGINT",
                        SIGTERM => "SIGTERM",
                        _ => "SIGHUP",
                    };
                    // After an in-place progress line, start a new line.
                    let nl = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
                        "\n"
                    } else {
                        ""
                    };
                    eprintln!("{nl}dropslice: interrupted ({name}); unfinished files removed");
                    std::process::exit(128 + signal);
                }
            });
        }

        /// `.NAME.` for the temporary names of `target`.
        fn prefix(target: &Path) -> std::ffi::OsString {
            let mut prefix = std::ffi::OsString::from(".");
            prefix.push(target.file_name().unwrap_or_default());
            prefix.push(".");
            prefix
        }

        /// Temporary names `.NAME.XXXXXX.partial`, files readable as a plain new file is.
        fn builder(prefix: &std::ffi::OsStr) -> tempfile::Builder<'_, 'static> {
            let mut b = tempfile::Builder::new();
            b.prefix(prefix).suffix(".partial");
            #[cfg(unix)]
            b.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
            b
        }

        pub struct Staged {
            file: File,
            dir: PathBuf,
            target: PathBuf,
            /// The file's temporary name; `None` while it is unnamed (`O_TMPFILE`).
            named: Option<TempPath>,
        }

        impl Staged {
            /// A new empty temporary file in `target`'s folder (which must exist).
            pub fn create(target: &Path) -> io::Result<Staged> {
                let dir = super::parent_dir(target);
                let target = target.to_path_buf();
                #[cfg(target_os = "linux")]
                if let Some(file) = unnamed_in(&dir) {
                    return Ok(Staged {
                        file,
                        dir,
                        target,
                        named: None,
                    });
                }
                let mut list = pending();
                let prefix = prefix(&target);
                let (file, path) = builder(&prefix)
                    .tempfile_in(&dir)
                    .map_err(without_path)?
                    .into_parts();
                list.push(path.to_path_buf());
                Ok(Staged {
                    file,
                    dir,
                    target,
                    named: Some(path),
                })
            }

            pub fn file(&mut self) -> &mut File {
                &mut self.file
            }

            pub fn target(&self) -> &Path {
                &self.target
            }

            /// Puts the file in place (replacing any file there); on error nothing is left.
            pub fn commit(mut self) -> io::Result<()> {
                // Locked throughout: a signal now waits until the file is in place (or gone).
                let mut list = pending();
                let path = match self.named.take() {
                    Some(path) => {
                        forget(&mut list, &path);
                        path
                    }
                    None => self.link().map_err(without_path)?,
                };
                // On error the temporary name is dropped, which removes it.
                path.persist(&self.target)
                    .map_err(|e| without_path(e.error))
            }

            /// Gives the unnamed file a fresh temporary name in its folder.
            #[cfg(target_os = "linux")]
            fn link(&self) -> io::Result<TempPath> {
                use std::os::fd::AsRawFd;
                let fd = format!("/proc/self/fd/{}", self.file.as_raw_fd());
                let prefix = prefix(&self.target);
                let named = builder(&prefix).make_in(&self.dir, |p| link_to(&fd, p))?;
                Ok(named.into_temp_path())
            }

            #[cfg(not(target_os = "linux"))]
            fn link(&self) -> io::Result<TempPath> {
                unreachable!("unnamed temporary files are only made on Linux")
            }
        }

        impl Drop for Staged {
            fn drop(&mut self) {
                if let Some(path) = self.named.take() {
                    let mut list = pending();
                    forget(&mut list, &path);
                    drop(path); // removes the file
                }
            }
        }

        /// tempfile's error without its ` at path ".X.XXXXXX.partial"` (the caller names the
        /// target, not the temporary name).
        fn without_path(e: io::Error) -> io::Error {
            let text = e.to_string();
            match text.rfind(" at path \"") {
                Some(i) => io::Error::new(e.kind(), &text[..i]),
                None => e,
            }
        }

        fn forget(list: &mut Vec<PathBuf>, path: &Path) {
            list.retain(|p| p != path);
        }

        /// An unnamed file in `dir`, if this system and file system have them.
        #[cfg(target_os = "linux")]
        fn unnamed_in(dir: &Path) -> Option<File> {
            use std::os::unix::fs::OpenOptionsExt;
            if std::env::var_os("DROPSLICE_NAMED_TEMP").is_some_and(|v| v == "1")
                || !Path::new("/proc/self/fd").is_dir()
            {
                return None;
            }
            std::fs::OpenOptions::new()
                .write(true)
                .mode(0o666)
                .custom_flags(libc::O_TMPFILE)
                .open(dir)
                .ok()
        }

        /// `linkat(AT_FDCWD, from, AT_FDCWD, to, AT_SYMLINK_FOLLOW)`: `from` is a
        /// `/proc/self/fd/N` link; `to` must not exist (an existing link there is not followed).
        #[cfg(target_os = "linux")]
        fn link_to(from: &str, to: &Path) -> io::Result<()> {
            use std::ffi::CString;
            use std::os::unix::ffi::OsStrExt;
            let from = CString::new(from)?;
            let to = CString::new(to.as_os_str().as_bytes())?;
            // SAFETY: both are valid NUL-terminated strings that outlive the call.
            let r = unsafe {
                libc::linkat(
                    libc::AT_FDCWD,
                    from.as_ptr(),
                    libc::AT_FDCWD,
                    to.as_ptr(),
                    libc::AT_SYMLINK_FOLLOW,
                )
            };
            if r == 0 {
                Ok(())
            } else {
                Err(io::Error::last_os_error())
            }
        }
    }
}
