//! Wavefront OBJ → triangles, with `tobj` (default features off; `load_obj_buf` reads from
//! bytes, so it works the same natively and in wasm).
//!
//! * Polygon faces become triangles (tobj's `triangulate`: a fan from the first corner — right
//!   for the convex and planar faces exporters write).
//! * Negative (relative) indices are resolved by tobj; `vt`/`vn` and materials are ignored
//!   (`mtllib` is not followed: there is no file system here).
//! * Points (`p`, one-corner faces) and lines (`l`, two-corner faces) are ignored.
//! * All objects and groups (`o`, `g`) form one part (see [`crate::model::import`]).
//! * Errors name the line: tobj reports only the kind of error, so on an error the bytes are
//!   scanned once more for the first line of that kind.

use crate::base::error::Error;
use crate::model::import::stl::{MAX_TRIANGLES, Triangles};

/// True when the first statement lines (after comments and blank lines) are OBJ statements.
pub fn looks_like_obj(bytes: &[u8]) -> bool {
    let mut seen = 0;
    for line in bytes.split(|&c| c == b'\n').take(200) {
        let Some(kw) = words(line).next() else {
            continue;
        };
        if kw[0] == b'#' {
            continue;
        }
        let ok = matches!(
            kw,
            b"v" | b"vt"
                | b"vn"
                | b"vp"
                | b"f"
                | b"o"
                | b"g"
                | b"s"
                | b"l"
                | b"p"
                | b"usemtl"
                | b"mtllib"
        );
        if !ok {
            return false;
        }
        seen += 1;
        if seen >= 3 || kw == b"v" || kw == b"f" {
            return true;
        }
    }
    seen > 0
}

/// Parses an OBJ file into one triangle list.
pub fn parse(bytes: &[u8]) -> Result<Triangles, Error> {
    if bytes.is_empty() {
        return Err(Error::Import(
            "the OBJ file is empty (0 bytes); choose a model file".into(),
        ));
    }
    // Count the triangles before tobj allocates them, with tobj's own splitting into words.
    let mut n: u64 = 0;
    for line in bytes.split(|&c| c == b'\n') {
        let mut toks = words(line);
        if toks.next() == Some(b"f") {
            n += (toks.count() as u64).saturating_sub(2);
        }
    }
    if n > MAX_TRIANGLES as u64 {
        return Err(Error::Import(format!(
            "the OBJ file has {n} triangles (after splitting polygons); at most {MAX_TRIANGLES} are accepted — simplify the model"
        )));
    }
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = bytes;
    let (models, _) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| Error::Import(describe(bytes, e)))?;
    let n: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    if n > MAX_TRIANGLES {
        return Err(Error::Internal(format!(
            "OBJ reader: {n} triangles built after {MAX_TRIANGLES} were counted at most"
        )));
    }
    let mut tris = Triangles::with_capacity(n);
    for m in &models {
        let p = &m.mesh.positions;
        for t in m.mesh.indices.chunks_exact(3) {
            let mut tri = [[0f32; 3]; 3];
            for (k, &i) in t.iter().enumerate() {
                let i = i as usize;
                let Some(c) = p.get(3 * i..3 * i + 3) else {
                    return Err(Error::Internal(format!(
                        "OBJ reader: vertex {i} of {} out of range",
                        p.len() / 3
                    )));
                };
                tri[k] = [c[0], c[1], c[2]];
            }
            tris.push(tri);
        }
    }
    if tris.is_empty() {
        return Err(Error::Import(
            "the OBJ file has no faces (no 'f' lines with three or more corners); it may hold only points or lines, which cannot be printed"
                .into(),
        ));
    }
    // tobj parses "nan" and "inf" as numbers: refuse them with the line that holds them.
    if tris.iter().flatten().flatten().any(|c| !c.is_finite()) {
        let line = first_line(bytes, |kw, rest, _| {
            kw == b"v"
                && rest
                    .iter()
                    .take(3)
                    .any(|t| !parse_f32(t).is_some_and(f32::is_finite))
        });
        return Err(Error::Import(format!(
            "{}a vertex has a coordinate that is not a finite number (NaN or infinity); the file is damaged — export it again",
            at(line)
        )));
    }
    Ok(tris)
}

fn at(line: Option<usize>) -> String {
    match line {
        Some(l) => format!("OBJ line {l}: "),
        None => "OBJ file: ".into(),
    }
}

/// A message for a tobj error, with the first offending line found by a second scan.
fn describe(bytes: &[u8], e: tobj::LoadError) -> String {
    use tobj::LoadError as E;
    match e {
        E::ReadError | E::UnrecognizedCharacter => {
            let line = bytes
                .split(|&c| c == b'\n')
                .position(|l| std::str::from_utf8(l).is_err())
                .map(|i| i + 1);
            format!(
                "{}the text is not UTF-8 (or not text at all); is this an OBJ file?",
                at(line)
            )
        }
        E::PositionParseError => {
            let line = first_line(bytes, |kw, rest, _| {
                kw == b"v"
                    && (rest.len() < 3 || rest.iter().take(3).any(|t| parse_f32(t).is_none()))
            });
            format!(
                "{}a vertex ('v') needs three numbers x y z; the file is damaged",
                at(line)
            )
        }
        E::NormalParseError | E::TexcoordParseError => {
            let kw_bad: &[u8] = if matches!(e, E::NormalParseError) {
                b"vn"
            } else {
                b"vt"
            };
            let line = first_line(bytes, |kw, rest, _| {
                kw == kw_bad && rest.iter().any(|t| parse_f32(t).is_none())
            });
            format!(
                "{}a '{}' line has a value that is not a number; the file is damaged",
                at(line),
                String::from_utf8_lossy(kw_bad)
            )
        }
        E::FaceParseError | E::InvalidPolygon => {
            let line = first_line(bytes, |kw, rest, _| {
                (kw == b"f" || kw == b"l")
                    && rest.iter().any(|t| {
                        t.split(|&c| c == b'/')
                            .any(|s| !s.is_empty() && parse_index(s).is_none())
                    })
            });
            format!(
                "{}a face ('f') has a corner that is not a vertex number (v, v/vt, v//vn or v/vt/vn); the file is damaged",
                at(line)
            )
        }
        E::FaceVertexOutOfBounds
        | E::FaceTexCoordOutOfBounds
        | E::FaceNormalOutOfBounds
        | E::FaceColorOutOfBounds => {
            let total = count_kw(bytes, b"v");
            let line = first_line(bytes, |kw, rest, counts| {
                kw == b"f"
                    && rest.iter().any(|t| {
                        let s = t.split(|&c| c == b'/').next().unwrap_or(&[]);
                        match parse_index(s) {
                            Some(i) if i > 0 => i as u64 > total,
                            Some(i) if i < 0 => i.unsigned_abs() > counts,
                            _ => true,
                        }
                    })
            });
            let what = match e {
                E::FaceVertexOutOfBounds => "a vertex",
                E::FaceTexCoordOutOfBounds => "a texture coordinate",
                E::FaceNormalOutOfBounds => "a normal",
                _ => "a vertex colour",
            };
            format!(
                "{}a face refers to {what} that does not exist (index 0, or beyond the {total} vertices defined); the file is damaged — export it again",
                at(line)
            )
        }
        other => format!("the OBJ file cannot be read ({other}); export it again"),
    }
}

/// Count of lines whose keyword is `kw`.
fn count_kw(bytes: &[u8], kw: &[u8]) -> u64 {
    let mut n = 0;
    for line in bytes.split(|&c| c == b'\n') {
        if words(line).next() == Some(kw) {
            n += 1;
        }
    }
    n
}

/// The 1-based number of the first line for which `bad(keyword, other tokens, number of
/// `v` lines before it)` holds.
fn first_line(bytes: &[u8], bad: impl Fn(&[u8], &[&[u8]], u64) -> bool) -> Option<usize> {
    let mut vs = 0u64;
    for (i, line) in bytes.split(|&c| c == b'\n').enumerate() {
        let mut toks = words(line);
        let Some(kw) = toks.next() else { continue };
        let rest: Vec<&[u8]> = toks.collect();
        if bad(kw, &rest, vs) {
            return Some(i + 1);
        }
        if kw == b"v" {
            vs += 1;
        }
    }
    None
}

/// The words of one line (split at `\n`) as tobj splits them: `str::split_whitespace`, i.e. at
/// Unicode white space (vertical tab, form feed, no-break space … as well as space and tab),
/// so that every count here sees the faces tobj builds. tobj refuses a line that is not UTF-8;
/// its valid beginning is split.
fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    let text = match std::str::from_utf8(line) {
        Ok(s) => s,
        Err(e) => std::str::from_utf8(&line[..e.valid_up_to()]).unwrap_or(""),
    };
    text.split_whitespace().map(str::as_bytes)
}

fn parse_f32(t: &[u8]) -> Option<f32> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

fn parse_index(t: &[u8]) -> Option<i64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}
