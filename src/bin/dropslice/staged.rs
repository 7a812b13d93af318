//! Files written beside their destination and put in place only when complete.
//!
//! On Linux the file is first unnamed (`O_TMPFILE` in the destination's folder): if the
//! process dies in any way, even by SIGKILL or the OOM killer, nothing is left. At the end
//! it is linked under a fresh temporary name (`linkat` of `/proc/self/fd/N`) and renamed
//! over the destination. Where that is not available (another system, a file system
//! without `O_TMPFILE`, no `/proc`), or with `DROPSLICE_NAMED_TEMP=1` (for the tests), it
//! is a named file `.NAME.XXXXXX.partial` created exclusively (never through an existing
//! link), removed on every error and, by the signal handler, on SIGINT, SIGTERM and SIGHUP.

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
        let dir = crate::files::parent_dir(target);
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
