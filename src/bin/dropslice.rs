//! The command-line tool: `dropslice MODEL.stl [-o OUT.gco] [--set name=value]... [--settings FILE.json]`.
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
    use dropslice::analysis::{JobAnalysis, Raster};
    use dropslice::{Error, Job, Settings, write_gcode_with};
    use std::io::{BufWriter, IsTerminal, Seek, SeekFrom, Write};
    use std::path::{Path, PathBuf};
    use std::process::ExitCode;
    use std::time::Instant;

    const USAGE: &str = "\
usage: dropslice MODEL.stl [-o OUT.gco] [--set name=value]... [--settings FILE.json] [-q]

Slices an STL file (binary or ASCII) into droplet machine code (.gco: G01 travel,
G25 droplet line, G26 droplet).

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

Exit codes: 0 done, 2 bad input or settings (the message says what to fix), 1 other errors.";

    struct Args {
        model: PathBuf,
        output: Option<PathBuf>,
        settings: Settings,
        quiet: bool,
        report: Option<PathBuf>,
    }

    enum Parsed {
        Run(Box<Args>),
        Exit(String),
    }

    pub fn main() -> ExitCode {
        let argv: Vec<String> = std::env::args().skip(1).collect();
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
        match run(&args) {
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
        let mut model = None;
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
                        .ok_or_else(|| format!("--set expects name=value, got '{kv}'"))?;
                    settings.set(k.trim(), v).map_err(|e| e.to_string())?;
                }
                "--settings" => {
                    let path = value(&mut it, a)?;
                    let text = std::fs::read_to_string(&path)
                        .map_err(|e| format!("cannot read the settings file {path}: {e}"))?;
                    settings = Settings::from_json(&text).map_err(|e| format!("{path}: {e}"))?;
                }
                s if s.starts_with('-') && s.len() > 1 => {
                    return Err(format!("unknown option '{s}'\n\n{USAGE}"));
                }
                s => {
                    if model.replace(PathBuf::from(s)).is_some() {
                        return Err(format!("give one model file only ('{s}' is a second one)"));
                    }
                }
            }
        }
        let model = model.ok_or_else(|| format!("no model file given\n\n{USAGE}"))?;
        settings.validate().map_err(|e| e.to_string())?;
        Ok(Parsed::Run(Box::new(Args {
            model,
            output,
            settings,
            quiet,
            report,
        })))
    }

    fn list_settings() -> String {
        let mut out = String::new();
        for s in dropslice::settings::schema() {
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

    fn run(args: &Args) -> Result<(), Error> {
        let t0 = Instant::now();
        let bytes = std::fs::read(&args.model)
            .map_err(|e| Error::Import(format!("cannot open {}: {e}", args.model.display())))?;
        let name = args
            .model
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let job = Job::new(&bytes, &name, args.settings.clone())?;
        drop(bytes);
        for w in &job.info().warnings {
            eprintln!("dropslice: warning: {w}");
        }
        let output = args.output.clone().unwrap_or_else(|| {
            let stem = args
                .model
                .file_stem()
                .map(|s| s.to_os_string())
                .unwrap_or_else(|| "out".into());
            PathBuf::from(stem).with_extension("gco")
        });
        // Written next to the target first, so a failed run never destroys an existing file.
        let partial = partial_path(&output);
        let io = |what: &str, p: &Path, e: std::io::Error| {
            Error::Io(format!("cannot {what} {}: {e}", p.display()))
        };
        let file = std::fs::File::create(&partial).map_err(|e| io("create", &partial, e))?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        let quiet = args.quiet;
        let mut last = Instant::now();
        let terminal = std::io::stderr().is_terminal();
        // Progress after the first second: in place on a terminal, a line every 2 s in a log.
        let every_ms = if terminal { 250 } else { 2000 };
        let mut shown = false;
        // With --report, each layer is analysed by the worker that planned it.
        let mut analysis = args.report.as_ref().map(|_| JobAnalysis::new(&job));
        let stage = analysis.as_ref().map(|a| a.stage());
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
        let summary = write_gcode_with(
            &job,
            &mut w,
            progress,
            Raster::empty,
            |raster, _, region, plan| stage.as_ref().map(|st| st.analyse(raster, region, plan)),
            |_, layer| {
                if let (Some(a), Some(l)) = (analysis.as_mut(), layer) {
                    a.push(l);
                }
            },
        );
        let summary = match summary {
            Ok(s) => s,
            Err(e) => {
                drop(w);
                let _ = std::fs::remove_file(&partial);
                return Err(e);
            }
        };
        let finish = || -> std::io::Result<dropslice::Summary> {
            let mut file = w.into_inner().map_err(|e| e.into_error())?;
            // Fill in the header's droplet counts (same length as the placeholders).
            let header = job.header(Some(&summary));
            debug_assert_eq!(header.len(), job.header(None).len());
            file.seek(SeekFrom::Start(0))?;
            file.write_all(header.as_bytes())?;
            Ok(summary)
        };
        let summary = match finish() {
            Ok(s) => s,
            Err(e) => {
                let _ = std::fs::remove_file(&partial);
                return Err(io("write", &partial, e));
            }
        };
        if summary.counts.total() == 0 {
            let _ = std::fs::remove_file(&partial);
            return Err(Error::NothingToPrint(format!(
                "no droplet fits in the part: every wall is thinner than the droplet width B = {:.3} mm; scale the part up or use smaller droplets (layer_height, droplet_aspect)",
                job.settings().droplet_width()
            )));
        }
        std::fs::rename(&partial, &output).map_err(|e| io("write", &output, e))?;
        for r in summary.repairs() {
            eprintln!("dropslice: repaired: {r}");
        }
        let mut voids = String::new();
        if let (Some(path), Some(analysis)) = (&args.report, analysis) {
            let report = analysis.finish();
            let text = serde_json::to_string_pretty(&report)
                .map_err(|e| Error::Internal(format!("the report does not serialize: {e}")))?;
            std::fs::write(path, text + "\n").map_err(|e| io("write", path, e))?;
            voids = format!(
                ", void fraction {:.1} % (coverage {:.1} %; report {})",
                100.0 * report.part.void_fraction,
                100.0 * report.part.coverage,
                path.display()
            );
        }
        if !args.quiet {
            let c = summary.counts;
            eprintln!(
                "dropslice: {} → {}: {} layers, {} droplets ({} outer, {} inner, {} fill){voids}, {:.2} s",
                name,
                output.display(),
                summary.layers,
                c.total(),
                c.outer,
                c.inner,
                c.fill,
                t0.elapsed().as_secs_f64()
            );
        }
        Ok(())
    }

    fn partial_path(output: &Path) -> PathBuf {
        let mut name = output
            .file_name()
            .map(|n| n.to_os_string())
            .unwrap_or_else(|| "out.gco".into());
        name.push(".partial");
        output.with_file_name(name)
    }
}
