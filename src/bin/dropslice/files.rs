//! Files read and written: regular files only, read up to a size cap; output paths checked
//! before any work.

use std::path::{Path, PathBuf};

/// A path for a message: as given, cut to 240 characters (a job file may name anything).
pub fn shown_path(path: &Path) -> String {
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
pub fn open_regular(path: &Path) -> Result<(std::fs::File, u64), String> {
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
pub fn read_regular(path: &Path, max: u64, what: &str) -> Result<Vec<u8>, String> {
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

/// A job file: named `*.json`, or not named as a model (`.stl`, `.obj`, `.3mf`) and its
/// first non-blank byte is `{` (a model file holding JSON gets the model reader's message).
pub fn is_job_file(path: &Path) -> Result<bool, String> {
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
    let (mut f, _) = open_regular(path)?;
    let n = f
        .read(&mut start)
        .map_err(|e| format!("cannot read {}: {e}", shown_path(path)))?;
    Ok(start[..n]
        .iter()
        .find(|b| !b.is_ascii_whitespace())
        .is_some_and(|&b| b == b'{'))
}

/// Checks, before any slicing, that `path` (given with `option`) can be written: not a
/// directory or a device, in a folder that exists. Whether the folder is writable is
/// checked by creating the temporary file there ([`crate::staged::Staged::create`]).
pub fn check_destination(path: &Path, option: &str, example: &Path) -> Result<(), String> {
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
pub fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The same file, as far as can be told before it exists: the folder resolved, same name.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let resolve = |p: &Path| {
        std::fs::canonicalize(p).ok().or_else(|| {
            let dir = std::fs::canonicalize(parent_dir(p)).ok()?;
            Some(dir.join(p.file_name()?))
        })
    };
    matches!((resolve(a), resolve(b)), (Some(x), Some(y)) if x == y)
}
