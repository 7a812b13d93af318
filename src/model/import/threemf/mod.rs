//! 3MF packages → parts (docs/spec.md "Build jobs"), with `zip` (deflate through
//! miniz_oxide) and `quick-xml`, streaming: a model part is parsed while it is inflated,
//! never held whole in memory.
//!
//! Read: `_rels/.rels` → the one 3D model part (the start part); its `<model unit>`;
//! `<resources>` `<object>`s with a `<mesh>` (`<vertices>`, `<triangles>`) or `<components>`
//! (`<component objectid transform>`, also in other model parts through the production
//! extension's `p:path`); `<build>` `<item objectid transform>` (also with `p:path`). Every
//! build item is one part; transforms are 3×4 matrices of row vectors (p' = p·M + t) and
//! compose child first; the unit is converted to mm. Materials, colours, textures,
//! metadata, thumbnails, beams of a beam lattice and slice stacks are ignored.
//!
//! Objects of type `support` (supports the producer made), `surface` and `other` are not
//! printed: a build item referring to one gives no part.
//!
//! Refused, with a message saying what and what to do: not a ZIP / damaged ZIP; encrypted
//! content (ZIP encryption, or the secure content extension's keystore); a required extension
//! dropslice does not read; XML with a DTD (`<!DOCTYPE`, forbidden by 3MF); several model
//! parts in `_rels/.rels` or several `<model>` roots; duplicate resource ids; an object with
//! neither a mesh nor components (e.g. beam lattice only, or volumetric/boolean objects);
//! component cycles; triangle indices out of range; non-finite numbers; a reference to a
//! missing object or model part; an empty build; and anything beyond the bounds below.

//!
//! Here: the package side (the ZIP, its bounds, `_rels/.rels`, the model parts to read) and
//! [`parse`]; `xml.rs` the bounded XML reader, `model.rs` one model part's elements,
//! `transform.rs` the matrices, `build.rs` the build items resolved into parts.

mod build;
mod model;
mod transform;
mod xml;

use std::collections::HashMap;
use std::io::{BufReader, Cursor, Read};

use super::{MAX_TRIANGLES, Part};
use crate::base::error::{Error, quote};
use build::build;
use model::{Content, Document, parse_model};
use xml::{Xml, XmlEvent, attr};

/// Most bytes inflated from the package in all (checked while inflating, whatever the ZIP
/// headers claim).
pub const MAX_UNCOMPRESSED: u64 = 1 << 30;
/// Most entries in the ZIP directory.
pub const MAX_ENTRIES: usize = 10_000;
/// Most model parts read (the start part and those named by `p:path`).
pub const MAX_MODEL_PARTS: usize = 1_000;
/// Deepest XML element nesting.
pub const MAX_XML_DEPTH: usize = 64;
/// Longest stretch of XML without a `<` (one text or tag), in bytes.
pub const MAX_XML_TOKEN: usize = 16 << 20;
/// Most namespace declarations in scope at once.
pub const MAX_NAMESPACES: usize = 64;
/// Most vertices in all meshes.
pub const MAX_VERTICES: usize = 3 * MAX_TRIANGLES;
/// Deepest component nesting (a build item's object is level 1).
pub const MAX_COMPONENT_DEPTH: usize = 32;
/// Most build items.
pub const MAX_ITEMS: usize = 100_000;
/// Most object instances the build may visit (components included), so that components of
/// empty meshes cannot make the resolution run for hours.
pub const MAX_INSTANCES: u64 = MAX_TRIANGLES as u64;

pub(super) const CORE_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";
pub(super) const PRODUCTION_NS: &str =
    "http://schemas.microsoft.com/3dmanufacturing/production/2015/06";
const MODEL_REL: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel";

pub(super) fn err(m: impl Into<String>) -> Error {
    Error::Import(m.into())
}

#[derive(Default)]
pub(super) struct Totals {
    pub(super) inflated: u64,
    pub(super) vertices: usize,
    pub(super) triangles: usize,
}

/// Reads a 3MF package into one part per build item.
pub fn parse(bytes: &[u8], file_stem: &str) -> Result<Vec<Part>, Error> {
    check_entry_count(bytes)?;
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| {
        err(format!(
            "the 3MF file is not a readable ZIP archive ({}); it is damaged or truncated — download or export it again",
            quote(&e.to_string())
        ))
    })?;
    if zip.len() > MAX_ENTRIES {
        return Err(err(format!(
            "the 3MF package has {} entries; at most {MAX_ENTRIES} are accepted",
            zip.len()
        )));
    }
    // Part names are case-insensitive (OPC); the ZIP holds them without the leading '/'.
    let mut names: HashMap<String, usize> = HashMap::new();
    // The names as the package spells them, for messages.
    let mut shown: HashMap<String, String> = HashMap::new();
    for i in 0..zip.len() {
        if let Some(Ok(n)) = zip.name_for_index(i) {
            let key = part_key(&n);
            if !names.contains_key(&key) {
                names.insert(key.clone(), i);
                shown.insert(key, n.trim_start_matches('/').to_string());
            }
        }
    }
    let mut totals = Totals::default();

    let root = start_part(&mut zip, &names, &mut totals)?;
    let mut models: HashMap<String, Document> = HashMap::new();
    let mut queue = vec![root.clone()];
    while let Some(path) = queue.pop() {
        if models.contains_key(&path) {
            continue;
        }
        if models.len() >= MAX_MODEL_PARTS {
            return Err(err(format!(
                "the 3MF package refers to more than {MAX_MODEL_PARTS} model parts; at most {MAX_MODEL_PARTS} are read"
            )));
        }
        let Some(&index) = names.get(&path) else {
            return Err(err(format!(
                "the 3MF package has no part '/{}', which {}; the file is damaged or incomplete",
                quote(&path),
                if path == root {
                    "its _rels/.rels names as the 3D model"
                } else {
                    "a component or build item refers to (p:path)"
                }
            )));
        };
        let model = parse_model(
            &mut zip,
            index,
            &quote(&shown[&path]),
            path == root,
            &mut totals,
        )?;
        for o in model.objects.values() {
            if let Content::Components(cs) = &o.content {
                queue.extend(cs.iter().filter_map(|c| c.path.clone()));
            }
        }
        queue.extend(model.items.iter().filter_map(|i| i.path.clone()));
        models.insert(path, model);
    }
    build(&models, &root, file_stem, &shown)
}

/// The key a part name is looked up by: no leading '/', ASCII lower case.
pub(super) fn part_key(name: &str) -> String {
    name.trim_start_matches('/').to_ascii_lowercase()
}

/// Refuses a directory with too many entries before the ZIP reader allocates for them.
fn check_entry_count(b: &[u8]) -> Result<(), Error> {
    // End of central directory: "PK\5\6", within the last 64 KiB + 22 bytes.
    let from = b.len().saturating_sub(65_557);
    let Some(pos) = b[from..]
        .windows(4)
        .rposition(|w| w == b"PK\x05\x06")
        .map(|p| p + from)
    else {
        return Ok(()); // the ZIP reader says what is wrong
    };
    let Some(eocd) = b.get(pos..pos + 22) else {
        return Ok(());
    };
    let mut n = u16::from_le_bytes([eocd[10], eocd[11]]) as u64;
    if n == 0xFFFF && pos >= 20 && &b[pos - 20..pos - 16] == b"PK\x06\x07" {
        // ZIP64: the locator points at the ZIP64 end record, which holds the count at +32.
        let off = u64::from_le_bytes(b[pos - 12..pos - 4].try_into().unwrap_or([0; 8]));
        let off = usize::try_from(off).unwrap_or(usize::MAX);
        if let Some(c) = off.checked_add(32).and_then(|s| b.get(s..s + 8)) {
            n = u64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
        }
    }
    if n > MAX_ENTRIES as u64 {
        return Err(err(format!(
            "the 3MF package has {n} entries; at most {MAX_ENTRIES} are accepted"
        )));
    }
    Ok(())
}

/// A reader of one ZIP entry that counts against the package's inflation budget and the
/// longest stretch without `<`.
pub(super) struct Limited<R> {
    inner: R,
    pub(super) left: u64,
    since_lt: usize,
    pub(super) exceeded: Option<String>,
}

impl<R: Read> Read for Limited<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if n as u64 > self.left {
            self.exceeded = Some(format!(
                "the 3MF package inflates to more than {} MB; at most that much is read (is it a ZIP bomb?)",
                MAX_UNCOMPRESSED >> 20
            ));
            return Err(std::io::Error::other("limit"));
        }
        self.left -= n as u64;
        match buf[..n].iter().rposition(|&c| c == b'<') {
            Some(i) => self.since_lt = n - 1 - i,
            None => self.since_lt += n,
        }
        if self.since_lt > MAX_XML_TOKEN {
            self.exceeded = Some(format!(
                "a model part has more than {} MB of text without markup; it is not a 3MF model (or a ZIP bomb)",
                MAX_XML_TOKEN >> 20
            ));
            return Err(std::io::Error::other("limit"));
        }
        Ok(n)
    }
}

pub(super) type Zip<'a> = zip::ZipArchive<Cursor<&'a [u8]>>;
/// A ZIP entry being inflated, bounded.
pub(super) type EntryReader<'z, 'a> = BufReader<Limited<zip::read::ZipFile<'z, Cursor<&'a [u8]>>>>;

/// Opens entry `index` for streaming, mapping ZIP errors (encryption, methods) to messages.
pub(super) fn open_entry<'z, 'a>(
    zip: &'z mut Zip<'a>,
    index: usize,
    path: &str,
    totals: &Totals,
) -> Result<EntryReader<'z, 'a>, Error> {
    let f = zip.by_index(index).map_err(|e| {
        let s = e.to_string();
        if s.to_ascii_lowercase().contains("password") || s.contains("ncrypt") {
            err(format!(
                "the 3MF part '/{path}' is encrypted; dropslice cannot read encrypted 3MF files — export the model without encryption"
            ))
        } else {
            err(format!(
                "the 3MF part '/{path}' cannot be unpacked ({}); export the file again (with standard 'deflate' compression)",
                quote(&s)
            ))
        }
    })?;
    Ok(BufReader::with_capacity(
        64 << 10,
        Limited {
            inner: f,
            left: MAX_UNCOMPRESSED - totals.inflated,
            since_lt: 0,
            exceeded: None,
        },
    ))
}

/// `_rels/.rels` → the key of the start part.
fn start_part(
    zip: &mut Zip,
    names: &HashMap<String, usize>,
    totals: &mut Totals,
) -> Result<String, Error> {
    let Some(&index) = names.get("_rels/.rels") else {
        if names.contains_key("3d/3dmodel.model") {
            return Ok("3d/3dmodel.model".into());
        }
        return Err(err(
            "this ZIP archive is not a 3MF package: it has no _rels/.rels and no 3D/3dmodel.model; choose a 3MF, STL or OBJ file",
        ));
    };
    let r = open_entry(zip, index, "_rels/.rels", totals)?;
    let mut x = Xml::new(r);
    let mut models = Vec::new();
    let mut keystore = false;
    while let Some(ev) = x.next("_rels/.rels", |_, local| local == "Relationship")? {
        if let XmlEvent::Start { local, attrs, .. } = ev
            && local == "Relationship"
        {
            let ty = attr(&attrs, "Type").unwrap_or_default();
            let target = attr(&attrs, "Target").unwrap_or_default();
            if ty == MODEL_REL || ty.ends_with("/3dmodel") {
                models.push(target);
            } else if ty.ends_with("/keystore") {
                keystore = true;
            }
        }
    }
    totals.inflated = MAX_UNCOMPRESSED - x.left();
    if keystore {
        return Err(err(
            "the 3MF file has encrypted content (3MF secure content extension: it has a keystore); dropslice cannot read encrypted models — export the model without encryption",
        ));
    }
    match models.as_slice() {
        [one] => Ok(part_key(one)),
        [] => Err(err(
            "the 3MF package's _rels/.rels names no 3D model part; the file is damaged — export it again",
        )),
        more => Err(err(format!(
            "the 3MF package's _rels/.rels names {} 3D model parts; a 3MF file has exactly one — the file is damaged, export it again",
            more.len()
        ))),
    }
}
