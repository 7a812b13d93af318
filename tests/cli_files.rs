//! The files the CLI leaves behind. The code and the report are written to temporary files in
//! their target's folder (unnamed on Linux, else `.NAME.XXXXXX.partial`, created exclusively)
//! and put in place only when the run succeeds: a failed, interrupted (SIGINT, SIGTERM,
//! SIGHUP) or, on Linux, killed run leaves nothing new, an existing output is untouched, an
//! existing `OUT.partial` link is never followed, and a directory given as the output is
//! refused before slicing. Each case runs with the unnamed temporary file (the default) and
//! with the named one (`DROPSLICE_NAMED_TEMP=1`).
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

const TIMEOUT: Duration = Duration::from_secs(120);

/// The two kinds of temporary file: env value of `DROPSLICE_NAMED_TEMP`.
const MODES: [&str; 2] = ["0", "1"];

struct Out {
    code: Option<i32>,
    stderr: String,
}

/// Starts the CLI in `cwd`; its stdout and stderr go to files in `logs` (not in `cwd`).
fn spawn(args: &[&str], cwd: &Path, named: &str, logs: &Path) -> Child {
    spawn_with(args, cwd, named, logs, Command::new(common::bin()))
}

fn spawn_with(args: &[&str], cwd: &Path, named: &str, logs: &Path, mut cmd: Command) -> Child {
    cmd.args(args)
        .current_dir(cwd)
        .env("DROPSLICE_NAMED_TEMP", named)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(logs.join("stdout")).unwrap())
        .stderr(std::fs::File::create(logs.join("stderr")).unwrap())
        .spawn()
        .expect("spawn dropslice")
}

fn wait(mut child: Child, logs: &Path) -> (ExitStatus, Out) {
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if t0.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("dropslice did not finish in {TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = std::fs::read_to_string(logs.join("stderr")).unwrap_or_default();
    (
        status,
        Out {
            code: status.code(),
            stderr,
        },
    )
}

fn cli(args: &[&str], cwd: &Path, named: &str) -> Out {
    let logs = tempfile::tempdir().unwrap();
    wait(spawn(args, cwd, named, logs.path()), logs.path()).1
}

/// The cube sliced to `out.gco` with the report `r.json`, then `extra`.
fn cube_to_out<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let cube: &'static str = Box::leak(model("cube_20mm_ascii.stl").into_boxed_str());
    let mut args = vec![cube, "-o", "out.gco", "--report", "r.json"];
    args.extend_from_slice(extra);
    args
}

/// Names in a directory (hidden ones too), sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn model(name: &str) -> String {
    common::model(name).display().to_string()
}

/// The cube's G-code as the library makes it (header counts filled in), without the CLI.
fn expected_cube_gcode() -> Vec<u8> {
    let name = "cube_20mm_ascii.stl";
    let bytes = std::fs::read(common::model(name)).unwrap();
    let job = dropslice::Job::new(&bytes, name, dropslice::Settings::default()).unwrap();
    let mut code = Vec::new();
    let summary = dropslice::write_gcode(&job, &mut code, |_, _| {}).unwrap();
    let header = job.header(Some(&summary));
    assert_eq!(header.len(), job.header(None).len());
    code[..header.len()].copy_from_slice(header.as_bytes());
    code
}

#[test]
fn a_directory_or_a_missing_folder_as_output_is_refused_before_slicing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("sub")).unwrap();
    std::fs::write(d.join("file"), "a file\n").unwrap();
    let before = listing(d);
    // A model that would take minutes to slice: the refusal must come before.
    let benchy = model("3DBenchy.stl");
    let slow = ["--set", "layer_height=0.05", "-q"];
    let mut cases: Vec<(&[&str], &[&str])> = vec![
        (&["-o", "sub"], &["directory"]),
        (&["-o", "sub/"], &["directory"]),
        (&["-o", "."], &["directory"]),
        (&["-o", "x.gco", "--report", "sub"], &["directory"]),
        (&["-o", "missing/x.gco"], &["does not exist"]),
        (
            &["-o", "x.gco", "--report", "missing/r.json"],
            &["does not exist"],
        ),
        (&["-o", "file/x.gco"], &["not a folder"]),
        (&["-o", "x.gco", "--report", "x.gco"], &["output"]),
        (&["-o", "/dev/null"], &["not a regular file"]),
    ];
    // A folder nobody, not even root, can create files in.
    if Path::new("/proc/self").is_dir() {
        cases.push((
            &["-o", "/proc/dropslice.gco"],
            &["cannot write in the folder"],
        ));
        cases.push((
            &["-o", "x.gco", "--report", "/proc/dropslice.json"],
            &["cannot write in the folder"],
        ));
    }
    for named in MODES {
        for &(args, keywords) in &cases {
            let mut all: Vec<&str> = vec![&benchy];
            all.extend(args);
            all.extend(slow);
            let t0 = Instant::now();
            let r = cli(&all, d, named);
            let seconds = t0.elapsed().as_secs_f64();
            assert_eq!(r.code, Some(2), "{args:?}: {}", r.stderr);
            let line = r.stderr.trim();
            assert!(
                line.starts_with("dropslice: ") && !line.contains('\n'),
                "{args:?}: one line expected: {line}"
            );
            assert!(
                keywords.iter().any(|k| line.contains(k)),
                "{args:?}: the message should say {keywords:?}: {line}"
            );
            assert!(
                seconds < 10.0,
                "{args:?}: refused after {seconds:.1} s, not before slicing"
            );
            assert_eq!(listing(d), before, "{args:?}: files left in the folder");
            assert!(
                listing(&d.join("sub")).is_empty(),
                "{args:?}: files left in sub"
            );
        }
    }
}

#[test]
fn an_existing_partial_link_is_not_followed() {
    let expected = expected_cube_gcode();
    for named in MODES {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let victim = d.join("victim.txt");
        std::fs::write(&victim, "not to be overwritten\n").unwrap();
        // The old fixed name, and a dangling link that following would create a file through.
        std::os::unix::fs::symlink(&victim, d.join("out.gco.partial")).unwrap();
        std::os::unix::fs::symlink(d.join("created.txt"), d.join(".out.gco.partial")).unwrap();
        std::os::unix::fs::symlink(&victim, d.join("r.json.partial")).unwrap();
        let before = listing(d);
        let r = cli(&cube_to_out(&["-q"]), d, named);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        assert_eq!(
            std::fs::read_to_string(&victim).unwrap(),
            "not to be overwritten\n"
        );
        assert!(!d.join("created.txt").exists());
        assert!(std::fs::read_link(d.join("out.gco.partial")).is_ok());
        assert_eq!(std::fs::read(d.join("out.gco")).unwrap(), expected);
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join("r.json")).unwrap()).unwrap();
        assert!(report.get("part").is_some());
        let mut after = before.clone();
        after.extend(["out.gco".to_string(), "r.json".to_string()]);
        after.sort();
        assert_eq!(listing(d), after, "DROPSLICE_NAMED_TEMP={named}");
    }
}

/// Where the running process `pid` has its temporary output in `dir`: a named
/// `.out.gco.*.partial` there, or an unnamed file there open in the process (Linux).
fn temp_output(pid: u32, dir: &Path) -> Option<PathBuf> {
    for name in listing(dir) {
        if name.starts_with(".out.gco.") && name.ends_with(".partial") {
            return Some(dir.join(name));
        }
    }
    let fds = std::fs::read_dir(format!("/proc/{pid}/fd")).ok()?;
    for fd in fds.flatten() {
        if let Ok(target) = std::fs::read_link(fd.path())
            && target.starts_with(dir)
            && target.to_string_lossy().ends_with("(deleted)")
        {
            return Some(fd.path());
        }
    }
    None
}

/// Starts a slow run (3DBenchy at H = 0.1 mm with a report) writing `out.gco` and `r.json` in
/// a new folder, and returns once its temporary output has code in it (mid-write).
fn start_slow_run(named: &str) -> (tempfile::TempDir, tempfile::TempDir, Child, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let logs = tempfile::tempdir().unwrap();
    let child = spawn(
        &[
            &model("3DBenchy.stl"),
            "-o",
            "out.gco",
            "--report",
            "r.json",
            "--set",
            "layer_height=0.1",
        ],
        dir.path(),
        named,
        logs.path(),
    );
    let t0 = Instant::now();
    let dir_path = std::fs::canonicalize(dir.path()).unwrap();
    let temp = loop {
        if let Some(p) = temp_output(child.id(), &dir_path)
            && std::fs::metadata(&p).is_ok_and(|m| m.len() > 0)
        {
            break p;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "no temporary output appeared"
        );
        std::thread::sleep(Duration::from_millis(2));
    };
    (dir, logs, child, temp)
}

#[test]
fn sigint_sigterm_and_sighup_leave_nothing() {
    for named in MODES {
        for (signal, name) in [
            (libc::SIGINT, "SIGINT"),
            (libc::SIGTERM, "SIGTERM"),
            (libc::SIGHUP, "SIGHUP"),
        ] {
            let (dir, logs, child, _) = start_slow_run(named);
            // SAFETY: kill(2) on our own child's pid.
            assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
            let (_, r) = wait(child, logs.path());
            let what = format!("{name}, DROPSLICE_NAMED_TEMP={named}");
            assert_eq!(r.code, Some(128 + signal), "{what}: {}", r.stderr);
            assert!(r.stderr.contains("interrupted"), "{what}: {}", r.stderr);
            assert!(
                listing(dir.path()).is_empty(),
                "{what}: left {:?}",
                listing(dir.path())
            );
        }
    }
}

#[test]
fn sigkill_leaves_nothing_where_unnamed_files_exist() {
    let (dir, logs, mut child, temp) = start_slow_run("0");
    let unnamed = temp.starts_with("/proc");
    child.kill().unwrap();
    let (status, _) = wait(child, logs.path());
    assert_eq!(status.code(), None);
    if unnamed {
        assert!(
            listing(dir.path()).is_empty(),
            "left {:?}",
            listing(dir.path())
        );
    } else {
        // No O_TMPFILE here: a killed run leaves its named temporary file (only that).
        eprintln!("no unnamed temporary files on this file system; SIGKILL not checked");
        for name in listing(dir.path()) {
            assert!(name.ends_with(".partial"), "left {name}");
        }
    }
}

/// What `out.gco` holds before a run that must leave it alone.
const EXISTING: &str = "; existing code\n";

/// `out.gco` still holds [`EXISTING`] and the folder lists what it listed `before`.
fn assert_left_alone(d: &Path, before: &[String], what: &str) {
    assert_eq!(
        std::fs::read_to_string(d.join("out.gco")).unwrap(),
        EXISTING,
        "{what}"
    );
    assert_eq!(listing(d), before, "{what}");
}

#[test]
fn a_failed_run_leaves_the_existing_output_and_nothing_else() {
    for named in MODES {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("out.gco"), EXISTING).unwrap();
        std::fs::write(d.join("r.json"), "{\"existing\": true}\n").unwrap();
        std::fs::write(d.join("bad.stl"), "solid x\nfacet normal 0 0 1\nendsolid\n").unwrap();
        let before = listing(d);
        let cube = model("cube_20mm_ascii.stl");
        let out = ["-o", "out.gco", "--report", "r.json"];
        // Nothing to print: found only after the whole code was written.
        let thin = [
            cube.as_str(),
            "--set",
            "scale_x=0.005",
            "--set",
            "scale_y=0.005",
        ];
        // Bad model; bad setting.
        let bad_model = ["bad.stl"];
        let bad_setting = [cube.as_str(), "--set", "contours=-1"];
        for (args, code) in [(&thin[..], 2), (&bad_model[..], 2), (&bad_setting[..], 2)] {
            let mut all = args.to_vec();
            all.extend(out);
            let r = cli(&all, d, named);
            assert_eq!(r.code, Some(code), "{args:?}: {}", r.stderr);
            assert_eq!(
                std::fs::read_to_string(d.join("r.json")).unwrap(),
                "{\"existing\": true}\n"
            );
            assert_left_alone(
                d,
                &before,
                &format!("{args:?}, DROPSLICE_NAMED_TEMP={named}"),
            );
        }
    }
}

#[test]
fn an_error_mid_write_leaves_the_existing_output_and_nothing_else() {
    use std::os::unix::process::CommandExt;
    for named in MODES {
        let dir = tempfile::tempdir().unwrap();
        let logs = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("out.gco"), EXISTING).unwrap();
        let before = listing(d);
        let mut cmd = Command::new(common::bin());
        // Files may not grow past 256 KB (the cube's code is ~3 MB): a write fails with EFBIG
        // (SIGXFSZ ignored, as it is inherited through exec).
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            cmd.pre_exec(|| {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let limit = libc::rlimit {
                    rlim_cur: 256 * 1024,
                    rlim_max: 256 * 1024,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = spawn_with(
            &[&model("cube_20mm_ascii.stl"), "-o", "out.gco", "-q"],
            d,
            named,
            logs.path(),
            cmd,
        );
        let (_, r) = wait(child, logs.path());
        assert_eq!(r.code, Some(1), "{}", r.stderr);
        assert!(r.stderr.contains("cannot write"), "{}", r.stderr);
        assert_left_alone(d, &before, &format!("DROPSLICE_NAMED_TEMP={named}"));
    }
}

#[test]
fn a_successful_run_writes_the_same_code_as_the_library_with_the_usual_mode() {
    use std::os::unix::fs::PermissionsExt;
    let expected = expected_cube_gcode();
    let mut reports = Vec::new();
    for named in MODES {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("out.gco"), "; replaced\n").unwrap();
        let r = cli(&cube_to_out(&[]), d, named);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        assert!(r.stderr.contains("→ out.gco"), "{}", r.stderr);
        assert_eq!(listing(d), ["out.gco", "r.json"]);
        let code = std::fs::read(d.join("out.gco")).unwrap();
        assert!(code.starts_with(b"; "), "the header comes first");
        assert!(
            code == expected,
            "DROPSLICE_NAMED_TEMP={named}: code differs"
        );
        reports.push(std::fs::read(d.join("r.json")).unwrap());
        // Permissions as for any new file (0666 less the umask), not a temp file's 0600.
        std::fs::write(d.join("plain"), "").unwrap();
        let mode = |p: &str| std::fs::metadata(d.join(p)).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode("out.gco"), mode("plain"));
        assert_eq!(mode("r.json"), mode("plain"));
    }
    assert_eq!(reports[0], reports[1]);
    // Without -o: MODEL.gco in the current directory.
    let dir = tempfile::tempdir().unwrap();
    let r = cli(&[&model("cube_20mm_ascii.stl"), "-q"], dir.path(), "0");
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(listing(dir.path()), ["cube_20mm_ascii.gco"]);
    assert!(std::fs::read(dir.path().join("cube_20mm_ascii.gco")).unwrap() == expected);
}
