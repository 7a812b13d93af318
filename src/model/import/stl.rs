//! Import, stage 1a: STL bytes → triangle soup ([`Triangles`]).
//!
//! Binary STL is recognised by its size (84 + 50·n bytes, n read at offset 80), whatever its
//! header says — many binary files begin with `solid`. Everything else is read as ASCII, which
//! tolerates CRLF, tabs, exponents, a missing solid name and a missing `endsolid`.

use crate::base::error::Error;
use crate::base::steps::{self, Budget, runs};

/// Triangles as read from the file, three float32 corners each (stored normals are ignored:
/// they are often wrong or zero; orientation comes from the vertex order).
pub type Triangles = Vec<[[f32; 3]; 3]>;

/// Most triangles a file may hold (1 GB of binary STL); the import of every format keeps to it.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// The format a model file was read as: one of the two STL encodings, or OBJ / 3MF
/// ([`crate::model::import`]). Serialised as `"binary"`, `"ascii"`, `"obj"`, `"3mf"`.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Format {
    Binary,
    Ascii,
    Obj,
    #[serde(rename = "3mf")]
    ThreeMf,
}

/// Parses an STL file. Every coordinate is checked to be finite.
pub fn parse(bytes: &[u8]) -> Result<(Triangles, Format), Error> {
    steps::now(parse_in_steps(bytes, &steps::UNLIMITED))
}

/// [`parse`] as a pass of `budget`'s budget: a binary file's records and every file's check
/// of the coordinates in runs of triangles (the page's short calls); an ASCII file is read
/// at once. The same triangles, or the same refusal.
pub async fn parse_in_steps(bytes: &[u8], budget: &Budget) -> Result<(Triangles, Format), Error> {
    if bytes.is_empty() {
        return Err(Error::Import(
            "the file is empty (0 bytes); choose an STL, OBJ or 3MF file".into(),
        ));
    }
    let (tris, format) = if let Some(n) = binary_count(bytes) {
        (parse_binary(bytes, n, budget).await, Format::Binary)
    } else if looks_ascii(bytes) {
        (parse_ascii(bytes)?, Format::Ascii)
    } else if let Some(kind) = other_format(bytes) {
        return Err(Error::Import(format!(
            "this is not an STL file but {kind}; choose an STL, OBJ or 3MF file (export one from your modelling program)"
        )));
    } else if bytes.len() >= 84 {
        let n = u32::from_le_bytes(bytes[80..84].try_into().expect("4 bytes")) as u64;
        let expected = 84 + 50 * n;
        // Real files rarely hold more than 20 million triangles (1 GB); a count beyond that
        // is text or another format read as a binary header.
        let msg = if n > MAX_TRIANGLES as u64 {
            format!(
                "this is not an STL file: it does not start with 'solid' (ASCII STL), and as a binary STL it would declare {n} triangles ({expected} bytes) in a file of {} bytes; choose an STL, OBJ or 3MF file",
                bytes.len()
            )
        } else if (bytes.len() as u64) < expected {
            format!(
                "it looks like a binary STL declaring {n} triangles ({expected} bytes), but the file has only {} bytes: it is truncated; download or export it again",
                bytes.len()
            )
        } else {
            format!(
                "it is neither ASCII STL nor binary STL: a binary STL declaring {n} triangles would be {expected} bytes, this file has {}; check that it is an STL file",
                bytes.len()
            )
        };
        return Err(Error::Import(msg));
    } else {
        return Err(Error::Import(format!(
            "the file is too short ({} bytes) to be a binary STL and is not ASCII STL; choose an STL, OBJ or 3MF file",
            bytes.len()
        )));
    };
    if tris.is_empty() {
        return Err(Error::Import("the file contains no triangles".into()));
    }
    let mut bad = None;
    runs(tris.len(), budget, &mut |r| {
        if bad.is_none() {
            bad = tris[r.clone()]
                .iter()
                .position(|t| t.iter().flatten().any(|c| !c.is_finite()))
                .map(|k| r.start + k);
        }
    })
    .await;
    if let Some(i) = bad {
        return Err(Error::Import(format!(
            "triangle {} has a coordinate that is not a finite number (NaN or infinity); the file is damaged — export it again from the modelling program",
            i + 1
        )));
    }
    Ok((tris, format))
}

/// A binary STL of the given triangles (zero normals; the header is cut to 80 bytes).
pub fn write_binary(header: &[u8], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    let n = header.len().min(80);
    b[..n].copy_from_slice(&header[..n]);
    b.reserve(4 + 50 * tris.len());
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend([0u8; 12]);
        for c in t.iter().flatten() {
            b.extend(c.to_le_bytes());
        }
        b.extend([0u8; 2]);
    }
    b
}

/// Names a few common non-STL formats by their first bytes.
fn other_format(bytes: &[u8]) -> Option<&'static str> {
    let start = bytes
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(0);
    let b = &bytes[start..];
    let kinds: [(&[u8], &str); 8] = [
        (b"\x89PNG", "a PNG image"),
        (b"\xFF\xD8\xFF", "a JPEG image"),
        (b"%PDF", "a PDF document"),
        (
            b"PK\x03\x04",
            "a ZIP archive (a 3MF file is one: export STL instead)",
        ),
        (b"{", "a JSON document"),
        (b"[", "a JSON document"),
        (
            b"<",
            "an XML or HTML document (AMF and X3D are not supported)",
        ),
        (b"ply", "a PLY mesh"),
    ];
    kinds
        .iter()
        .find(|(magic, _)| b.starts_with(magic))
        .map(|(_, kind)| *kind)
}

/// The triangle count if the size matches the binary layout exactly.
fn binary_count(bytes: &[u8]) -> Option<usize> {
    if bytes.len() < 84 {
        return None;
    }
    let n = u32::from_le_bytes(bytes[80..84].try_into().ok()?) as u64;
    (84 + 50 * n == bytes.len() as u64).then_some(n as usize)
}

async fn parse_binary(bytes: &[u8], n: usize, budget: &Budget) -> Triangles {
    let n = n.min((bytes.len() - 84) / 50);
    let records = &bytes[84..84 + 50 * n];
    let mut tris = Vec::with_capacity(n);
    // In runs of records ([`runs`]: the page's engine compiles the later runs well).
    runs(n, budget, &mut |r| {
        tris.extend(
            records[50 * r.start..50 * r.end]
                .chunks_exact(50)
                .map(|rec| {
                    // A record as an array: the offsets below are checked when compiled, not per byte.
                    let rec: &[u8; 50] = rec.try_into().expect("chunks of 50 bytes");
                    let f =
                        |o: usize| f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]);
                    let v = |k: usize| {
                        let o = 12 + 12 * k;
                        [f(o), f(o + 4), f(o + 8)]
                    };
                    [v(0), v(1), v(2)]
                }),
        )
    })
    .await;
    tris
}

/// ASCII STL starts (after optional whitespace or a UTF-8 BOM) with `solid`.
fn looks_ascii(bytes: &[u8]) -> bool {
    let b = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let start = b
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(b.len());
    b[start..].len() >= 5 && b[start..start + 5].eq_ignore_ascii_case(b"solid")
}

fn parse_ascii(bytes: &[u8]) -> Result<Triangles, Error> {
    let mut tris = Triangles::new();
    let mut corners: Vec<[f32; 3]> = Vec::with_capacity(3);
    let mut in_facet = false;
    let mut line = 1usize;
    let mut tokens = Tokens {
        bytes,
        pos: 0,
        line: &mut line,
    };
    while let Some(tok) = tokens.next() {
        if tok.eq_ignore_ascii_case(b"facet") {
            if in_facet && !corners.is_empty() {
                return Err(facet_error(tokens.line(), corners.len()));
            }
            in_facet = true;
            corners.clear();
        } else if tok.eq_ignore_ascii_case(b"vertex") {
            let mut p = [0f32; 3];
            for c in &mut p {
                let Some(t) = tokens.next() else {
                    return Err(Error::Import(format!(
                        "the file ends in the middle of a vertex (line {}): it is truncated",
                        tokens.line()
                    )));
                };
                *c = parse_f32(t).ok_or_else(|| {
                    Error::Import(format!(
                        "line {}: '{}' is not a number",
                        tokens.line(),
                        crate::base::error::quote(&String::from_utf8_lossy(t))
                    ))
                })?;
            }
            if corners.len() == 3 {
                return Err(facet_error(tokens.line(), 4));
            }
            corners.push(p);
        } else if tok.eq_ignore_ascii_case(b"endfacet") {
            if corners.len() != 3 {
                return Err(facet_error(tokens.line(), corners.len()));
            }
            tris.push([corners[0], corners[1], corners[2]]);
            corners.clear();
            in_facet = false;
        }
        // Everything else (solid, name, normal, outer, loop, endloop, endsolid) carries no geometry.
    }
    if in_facet {
        if corners.len() == 3 {
            // A missing `endfacet` at the very end: keep the complete triangle.
            tris.push([corners[0], corners[1], corners[2]]);
        } else {
            return Err(Error::Import(format!(
                "the file ends in the middle of a facet (line {}): it is truncated; download or export it again",
                line
            )));
        }
    }
    if tris.is_empty() {
        return Err(Error::Import(
            "the file starts like an ASCII STL ('solid') but contains no facets; is it empty or truncated?"
                .into(),
        ));
    }
    Ok(tris)
}

fn facet_error(line: usize, n: usize) -> Error {
    Error::Import(format!(
        "line {line}: a facet has {n} vertices instead of 3; the file is damaged"
    ))
}

fn parse_f32(t: &[u8]) -> Option<f32> {
    std::str::from_utf8(t).ok()?.parse::<f32>().ok()
}

/// Whitespace-separated tokens with a line counter.
struct Tokens<'a, 'l> {
    bytes: &'a [u8],
    pos: usize,
    line: &'l mut usize,
}

impl<'a> Tokens<'a, '_> {
    fn next(&mut self) -> Option<&'a [u8]> {
        let b = self.bytes;
        while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
            if b[self.pos] == b'\n' {
                *self.line += 1;
            }
            self.pos += 1;
        }
        if self.pos >= b.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Some(&b[start..self.pos])
    }

    fn line(&self) -> usize {
        *self.line
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::write_binary as binary;

    const T: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]];

    #[test]
    fn binary_with_solid_header() {
        let b = binary(b"solid part\n", &[T, T]);
        let (t, f) = parse(&b).unwrap();
        assert_eq!(f, Format::Binary);
        assert_eq!(t.len(), 2);
        assert_eq!(t[0], T);
    }

    #[test]
    fn ascii_variants() {
        let crlf = "solid\r\nfacet normal 0 0 0\r\n\touter loop\r\n\t\tvertex 0 0 0\r\n\t\tvertex 1e0 0 0\r\n\t\tvertex 0 1.0E+00 1\r\n\tendloop\r\nendfacet\r\n";
        let (t, f) = parse(crlf.as_bytes()).unwrap();
        assert_eq!(f, Format::Ascii);
        assert_eq!(t, vec![T]);
    }

    #[test]
    fn errors() {
        assert!(parse(b"").unwrap_err().to_string().contains("empty"));
        let b = binary(b"x", &[T, T, T]);
        let e = parse(&b[..b.len() - 7]).unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        let e = parse(b"solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0")
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated"), "{e}");
        let nan = binary(
            b"x",
            &[[[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]],
        );
        assert!(parse(&nan).unwrap_err().to_string().contains("NaN"));
    }
}
