//! 3MF packages → parts (SPEC.md "Build jobs: several parts"), with `zip` (deflate through
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

use std::collections::{HashMap, HashSet};
use std::io::{BufRead, BufReader, Cursor, Read};

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use quick_xml::name::ResolveResult;

use super::{MAX_TRIANGLES, Part};
use crate::base::error::{Error, quote};
use crate::model::import::stl::Triangles;

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

const CORE_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";
const PRODUCTION_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06";
const MODEL_REL: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel";

fn err(m: impl Into<String>) -> Error {
    Error::Import(m.into())
}

/// An affine map of row vectors: p' = p·m + t, in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Affine {
    m: [[f64; 3]; 3],
    t: [f64; 3],
}

impl Affine {
    const ID: Affine = Affine {
        m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let mut o = self.t;
        for (j, oj) in o.iter_mut().enumerate() {
            *oj += p[0] * self.m[0][j] + p[1] * self.m[1][j] + p[2] * self.m[2][j];
        }
        o
    }

    /// `self` first, then `then`.
    fn then(&self, then: &Affine) -> Affine {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| self.m[i][k] * then.m[k][j]).sum();
            }
        }
        Affine {
            m,
            t: then.apply(self.t),
        }
    }

    /// Rows of the column-vector form (see [`Part::transform_applied`]).
    fn rows(&self) -> [[f64; 4]; 3] {
        let mut r = [[0.0; 4]; 3];
        for (j, row) in r.iter_mut().enumerate() {
            *row = [self.m[0][j], self.m[1][j], self.m[2][j], self.t[j]];
        }
        r
    }
}

#[derive(Debug)]
struct Component {
    path: Option<String>,
    id: u32,
    transform: Affine,
}

#[derive(Debug)]
enum Content {
    Mesh {
        vertices: Vec<[f32; 3]>,
        triangles: Vec<[u32; 3]>,
        beams: bool,
    },
    Components(Vec<Component>),
    None(Option<String>),
}

#[derive(Debug)]
struct Object {
    name: Option<String>,
    printable: bool,
    content: Content,
}

struct Item {
    path: Option<String>,
    id: u32,
    transform: Affine,
}

/// One parsed model part.
#[derive(Default)]
struct Model {
    objects: HashMap<u32, Object>,
    items: Vec<Item>,
}

/// Totals across the whole package.
#[derive(Default)]
struct Totals {
    inflated: u64,
    vertices: usize,
    triangles: usize,
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
    let mut models: HashMap<String, Model> = HashMap::new();
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
fn part_key(name: &str) -> String {
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
struct Limited<R> {
    inner: R,
    left: u64,
    since_lt: usize,
    exceeded: Option<String>,
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

type Zip<'a> = zip::ZipArchive<Cursor<&'a [u8]>>;
/// A ZIP entry being inflated, bounded.
type EntryReader<'z, 'a> = BufReader<Limited<zip::read::ZipFile<'z, Cursor<&'a [u8]>>>>;

/// Opens entry `index` for streaming, mapping ZIP errors (encryption, methods) to messages.
fn open_entry<'z, 'a>(
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

fn attr(attrs: &[(String, String, String)], name: &str) -> Option<String> {
    attrs
        .iter()
        .find(|(ns, l, _)| ns.is_empty() && l == name)
        .map(|(_, _, v)| v.clone())
}

fn attr_ns(attrs: &[(String, String, String)], ns: &str, name: &str) -> Option<String> {
    attrs
        .iter()
        .find(|(n, l, _)| n == ns && l == name)
        .map(|(_, _, v)| v.clone())
}

enum XmlEvent {
    /// A start or empty element: its namespace (empty when unbound), local name and
    /// attributes (namespace, local name, unescaped value).
    Start {
        ns: String,
        local: String,
        attrs: Vec<(String, String, String)>,
        empty: bool,
    },
    End,
}

/// A bounded, namespace-resolving XML event reader over a ZIP entry. Names are resolved
/// (and namespace scopes kept) only for the elements [`Xml::next`] gives, not for those
/// [`Xml::skip`] passes over.
struct Xml<R: BufRead> {
    r: Reader<R>,
    ns: quick_xml::name::NamespaceResolver,
    buf: Vec<u8>,
    depth: usize,
    /// Namespace declarations per open element.
    ns_stack: Vec<usize>,
    roots: usize,
    pending_end: bool,
}

impl<R: BufRead> Xml<R> {
    fn new(r: R) -> Self {
        let mut r = Reader::from_reader(r);
        r.config_mut().trim_text(true);
        Xml {
            r,
            ns: Default::default(),
            buf: Vec::new(),
            depth: 0,
            ns_stack: Vec::new(),
            roots: 0,
            pending_end: false,
        }
    }
}

impl<R: Read> Xml<BufReader<Limited<R>>> {
    fn left(&self) -> u64 {
        self.r.get_ref().get_ref().left
    }

    /// A read error as a message: the inflation bound's own message when it was passed.
    fn read_error(&self, e: quick_xml::Error, part: &str) -> Error {
        if let Some(m) = self.r.get_ref().get_ref().exceeded.clone() {
            return err(m);
        }
        let pos = self.r.buffer_position();
        err(format!(
            "the 3MF part '/{part}' is not well-formed XML (at byte {pos}: {}); the file is damaged — export it again",
            quote(&e.to_string())
        ))
    }

    /// An element opens, with `decls` namespace declarations: the depth and namespace bounds.
    fn open(&mut self, decls: usize, part: &str) -> Result<(), Error> {
        self.depth += 1;
        self.ns_stack.push(decls);
        if self.depth > MAX_XML_DEPTH {
            return Err(too_deep(part));
        }
        if decls > 0 && self.ns_stack.iter().sum::<usize>() > MAX_NAMESPACES {
            return Err(err(format!(
                "the 3MF part '/{part}' declares more than {MAX_NAMESPACES} XML namespaces at once; it is not a 3MF model"
            )));
        }
        Ok(())
    }

    /// Skips the content of the element [`next`](Self::next) just gave (a start, not an
    /// empty element) up to and including its end, for elements nothing is read from: no
    /// names are resolved, no attributes read and no namespace scopes kept (so the namespace
    /// bound has nothing to count), but the depth bound, the ban on DOCTYPE and
    /// well-formedness still hold.
    fn skip(&mut self, part: &str) -> Result<(), Error> {
        let mut depth = self.depth;
        let end = depth - 1;
        while depth > end {
            self.buf.clear();
            let ev = match self.r.read_event_into(&mut self.buf) {
                Ok(ev) => ev,
                Err(e) => return Err(self.read_error(e, part)),
            };
            match ev {
                Event::Start(_) => {
                    depth += 1;
                    if depth > MAX_XML_DEPTH {
                        return Err(too_deep(part));
                    }
                }
                Event::Empty(_) if depth + 1 > MAX_XML_DEPTH => return Err(too_deep(part)),
                Event::End(_) => depth -= 1,
                Event::DocType(_) => return Err(doctype(part)),
                Event::Eof => return Err(truncated(part)),
                _ => {}
            }
        }
        if self.close() > 0 {
            self.ns.pop();
        }
        Ok(())
    }

    /// The next event; the attributes of a start are read only if `want(namespace, local
    /// name)`.
    fn next(
        &mut self,
        part: &str,
        want: impl Fn(&str, &str) -> bool,
    ) -> Result<Option<XmlEvent>, Error> {
        if self.pending_end {
            self.pending_end = false;
            if self.close() > 0 {
                self.ns.pop();
            }
            return Ok(Some(XmlEvent::End));
        }
        loop {
            self.buf.clear();
            let ev = match self.r.read_event_into(&mut self.buf) {
                Ok(ev) => ev,
                Err(e) => return Err(self.read_error(e, part)),
            };
            // A namespace scope is kept only for elements that declare namespaces.
            let mut decls = 0;
            if let Event::Start(s) | Event::Empty(s) = &ev {
                decls = declarations(s, part)?;
                if decls > 0 {
                    self.ns.push(s).map_err(|e| {
                        err(format!(
                            "the 3MF part '/{part}' has a bad namespace declaration ({}); the file is damaged",
                            quote(&e.to_string())
                        ))
                    })?;
                }
            }
            let ns = match &ev {
                Event::Start(s) | Event::Empty(s) => self.ns.resolve_element(s.name()).0,
                _ => ResolveResult::Unbound,
            };
            // The core namespace as "" (as unbound names): no text made for most elements.
            let ns: String = match ns {
                ResolveResult::Bound(n) if n.0 == CORE_NS => String::new(),
                ResolveResult::Bound(n) => n.0.to_string(),
                ResolveResult::Unbound => String::new(),
                ResolveResult::Unknown(p) => {
                    return Err(err(format!(
                        "the 3MF part '/{part}' uses the XML prefix '{}' without declaring it; the file is damaged",
                        quote(&p.to_string())
                    )));
                }
            };
            let start = match ev {
                Event::Start(s) => Some((s, false)),
                Event::Empty(s) => Some((s, true)),
                other => {
                    match other {
                        Event::End(_) => {
                            if self.close() > 0 {
                                self.ns.pop();
                            }
                            return Ok(Some(XmlEvent::End));
                        }
                        Event::DocType(_) => return Err(doctype(part)),
                        Event::Eof => {
                            if self.depth > 0 {
                                return Err(truncated(part));
                            }
                            return Ok(None);
                        }
                        Event::Text(_) | Event::CData(_) if self.depth == 0 && self.roots > 0 => {
                            return Err(err(format!(
                                "the 3MF part '/{part}' has content after its root element; the file is damaged"
                            )));
                        }
                        _ => {}
                    }
                    None
                }
            };
            if let Some((s, empty)) = start {
                {
                    let local = s.local_name().as_ref().to_string();
                    let attrs = if want(&ns, &local) {
                        attributes(&self.ns, &s, &local, part)?
                    } else {
                        Vec::new()
                    };
                    if self.depth == 0 {
                        self.roots += 1;
                        if self.roots > 1 {
                            return Err(err(format!(
                                "the 3MF part '/{part}' has more than one root element (e.g. two <model>s); a model part holds exactly one — the file is damaged"
                            )));
                        }
                    }
                    self.open(decls, part)?;
                    if empty {
                        self.pending_end = true;
                    }
                    return Ok(Some(XmlEvent::Start {
                        ns,
                        local,
                        attrs,
                        empty,
                    }));
                }
            }
        }
    }

    /// An element closes: returns its number of namespace declarations.
    fn close(&mut self) -> usize {
        self.depth = self.depth.saturating_sub(1);
        self.ns_stack.pop().unwrap_or(0)
    }
}

fn too_deep(part: &str) -> Error {
    err(format!(
        "the 3MF part '/{part}' nests XML elements more than {MAX_XML_DEPTH} deep; it is not a 3MF model"
    ))
}

fn doctype(part: &str) -> Error {
    err(format!(
        "the 3MF part '/{part}' has a document type definition (<!DOCTYPE>), which 3MF forbids; the file is not a valid 3MF model — export it again"
    ))
}

fn truncated(part: &str) -> Error {
    err(format!(
        "the 3MF part '/{part}' ends in the middle of the XML (unclosed elements); it is truncated — export it again"
    ))
}

fn broken_attribute(local: &str, e: impl std::fmt::Display, part: &str) -> Error {
    err(format!(
        "the 3MF part '/{part}' has a broken attribute in <{}> ({}); the file is damaged",
        quote(local),
        quote(&e.to_string())
    ))
}

/// The number of namespace declarations (`xmlns`, `xmlns:p`) of an element; its attributes
/// are looked at only when their text holds "xmlns".
fn declarations(s: &BytesStart, part: &str) -> Result<usize, Error> {
    let raw: &[u8] = s.attributes_raw().as_bytes();
    let mut rest = raw;
    let mut any = false;
    while let Some(i) = rest.iter().position(|&c| c == b'x') {
        if rest[i..].starts_with(b"xmlns") {
            any = true;
            break;
        }
        rest = &rest[i + 1..];
    }
    if !any {
        return Ok(0);
    }
    let mut decls = 0;
    for a in s.attributes().with_checks(false) {
        let a = a.map_err(|e| broken_attribute(s.local_name().as_ref(), e, part))?;
        let key: &str = a.key.0;
        if key == "xmlns" || key.starts_with("xmlns:") {
            decls += 1;
        }
    }
    Ok(decls)
}

/// The attributes of an element (namespace, local name, unescaped value), namespace
/// declarations left out.
#[allow(clippy::type_complexity)]
fn attributes(
    resolver: &quick_xml::name::NamespaceResolver,
    s: &BytesStart,
    local: &str,
    part: &str,
) -> Result<Vec<(String, String, String)>, Error> {
    let mut attrs = Vec::new();
    for a in s.attributes().with_checks(false) {
        let a = a.map_err(|e| broken_attribute(local, e, part))?;
        let key: &str = a.key.0;
        if key == "xmlns" || key.starts_with("xmlns:") {
            continue;
        }
        let (ns, l) = resolver.resolve_attribute(a.key);
        let ns = match ns {
            ResolveResult::Bound(n) => n.0.to_string(),
            _ => String::new(),
        };
        let v = a
            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .map(|v| v.into_owned())
            .unwrap_or_else(|_| a.value.to_string());
        attrs.push((ns, l.as_ref().to_string(), v));
        if attrs.len() > 10_000 {
            return Err(err(format!(
                "the 3MF part '/{part}' has an element with more than 10000 attributes; it is not a 3MF model"
            )));
        }
    }
    Ok(attrs)
}

fn unit_scale(u: &str) -> Option<f64> {
    Some(match u {
        "micron" => 0.001,
        "millimeter" => 1.0,
        "centimeter" => 10.0,
        "inch" => 25.4,
        "foot" => 304.8,
        "meter" => 1000.0,
        _ => return None,
    })
}

fn number(v: &str, what: &str, part: &str) -> Result<f64, Error> {
    match v.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(err(format!(
            "the 3MF part '/{part}' has {what} that is not a finite number ('{}'); the file is damaged — export it again",
            quote(v)
        ))),
        Err(_) => Err(err(format!(
            "the 3MF part '/{part}' has {what} that is not a number ('{}'); the file is damaged",
            quote(v)
        ))),
    }
}

fn index(v: Option<String>, what: &str, part: &str) -> Result<u32, Error> {
    let v = v.ok_or_else(|| {
        err(format!(
            "the 3MF part '/{part}' has {what} without its required attribute; the file is damaged"
        ))
    })?;
    v.trim().parse::<u32>().map_err(|_| {
        err(format!(
            "the 3MF part '/{part}' has {what} '{}' that is not a whole number ≥ 0; the file is damaged",
            quote(&v)
        ))
    })
}

/// A 3MF transform: 12 numbers, row vectors, translation last; its translation scaled by the
/// model's unit.
fn transform(v: Option<String>, scale: f64, part: &str) -> Result<Affine, Error> {
    let Some(v) = v else { return Ok(Affine::ID) };
    let nums: Vec<&str> = v.split_ascii_whitespace().collect();
    if nums.len() != 12 {
        return Err(err(format!(
            "the 3MF part '/{part}' has a transform with {} numbers instead of 12; the file is damaged",
            nums.len()
        )));
    }
    let mut a = Affine::ID;
    for (k, s) in nums.iter().enumerate() {
        let x = number(s, "a transform", part)?;
        if k < 9 {
            a.m[k / 3][k % 3] = x;
        } else {
            a.t[k - 9] = x * scale;
        }
    }
    Ok(a)
}

/// Namespaces of required extensions that do not change the geometry read here.
fn known_extension(ns: &str) -> bool {
    ns.starts_with("http://schemas.microsoft.com/3dmanufacturing/material/")
        || ns.starts_with("http://schemas.microsoft.com/3dmanufacturing/production/")
        || ns.starts_with("http://schemas.microsoft.com/3dmanufacturing/beamlattice/")
        || ns.starts_with("http://schemas.microsoft.com/3dmanufacturing/slice/")
        || ns == CORE_NS
}

/// The core elements whose children [`parse_model`] reads (everything else is skipped).
const READ_INSIDE: [&str; 8] = [
    "model",
    "resources",
    "object",
    "mesh",
    "vertices",
    "triangles",
    "components",
    "build",
];

/// Parses one model part.
fn parse_model(
    zip: &mut Zip,
    index_in_zip: usize,
    part: &str,
    is_root: bool,
    totals: &mut Totals,
) -> Result<Model, Error> {
    let r = open_entry(zip, index_in_zip, part, totals)?;
    let mut x = Xml::new(r);
    let mut model = Model::default();
    let mut scale = 1.0;
    let mut resource_ids: HashSet<u32> = HashSet::new();
    // Path of open elements (local names of core elements; "" for others).
    let mut path: Vec<String> = Vec::new();
    // The object being read.
    let mut cur: Option<(u32, Object)> = None;
    let mut saw_model = false;
    let is_core = |ns: &str| ns.is_empty() || ns == CORE_NS;
    let p = part;
    loop {
        // Attributes are read only where they are used.
        let want = |ns: &str, local: &str| {
            let parent = path.last().map(String::as_str).unwrap_or("");
            path.is_empty()
                || parent == "resources"
                || (is_core(ns)
                    && matches!(
                        (parent, local),
                        ("vertices", "vertex")
                            | ("triangles", "triangle")
                            | ("components", "component")
                            | ("build", "item")
                    ))
        };
        let Some(ev) = x.next(part, want)? else {
            break;
        };
        let (ns, local, attrs, empty) = match ev {
            XmlEvent::End => {
                let closed = path.pop().unwrap_or_default();
                if closed == "object"
                    && let Some((id, obj)) = cur.take()
                {
                    model.objects.insert(id, obj);
                }
                continue;
            }
            XmlEvent::Start {
                ns,
                local,
                attrs,
                empty,
            } => (ns, local, attrs, empty),
        };
        let parent = path.last().map(String::as_str).unwrap_or("");
        let core = is_core(&ns);
        let name = if core { local.clone() } else { String::new() };
        match (parent, name.as_str()) {
            ("", "model") if path.is_empty() => {
                saw_model = true;
                let unit = attr(&attrs, "unit").unwrap_or_else(|| "millimeter".into());
                scale = unit_scale(&unit).ok_or_else(|| {
                    err(format!(
                        "the 3MF model's unit '{}' is unknown (micron, millimeter, centimeter, inch, foot and meter are); the file is damaged",
                        quote(&unit)
                    ))
                })?;
                if let Some(req) = attr(&attrs, "requiredextensions") {
                    for prefix in req.split_ascii_whitespace() {
                        let ns =
                            x.ns.resolve_element(quick_xml::name::QName(&format!("{prefix}:x")))
                                .0;
                        let ns = match ns {
                            ResolveResult::Bound(n) => n.0.to_string(),
                            _ => prefix.to_string(),
                        };
                        if ns.contains("securecontent") {
                            return Err(err(
                                "the 3MF file has encrypted content (3MF secure content extension); dropslice cannot read encrypted models — export the model without encryption",
                            ));
                        }
                        if !known_extension(&ns) {
                            return Err(err(format!(
                                "the 3MF file requires the extension '{}', which dropslice does not read; export the model as plain 3MF (core), STL or OBJ",
                                quote(&ns)
                            )));
                        }
                    }
                }
            }
            (_, "model") | ("", _) if path.is_empty() => {
                return Err(err(format!(
                    "the 3MF part '/{p}' is not a 3D model (its root element is <{}>, not <model>); the file is damaged",
                    quote(&local)
                )));
            }
            ("model", "resources") | ("model", "build") => {}
            ("resources", _) => {
                // Any resource (objects, materials, …): ids are unique within a model part.
                // (Another extension's resource with an id that is not a number is ignored.)
                let id = match attr(&attrs, "id") {
                    Some(v) if core => Some(index(Some(v), &format!("a <{local}> id"), p)?),
                    Some(v) => v.trim().parse::<u32>().ok(),
                    None => None,
                };
                if let Some(id) = id {
                    if !resource_ids.insert(id) {
                        return Err(err(format!(
                            "the 3MF part '/{p}' has two resources with id {id}; ids must be unique — the file is damaged"
                        )));
                    }
                    if name == "object" {
                        let ty = attr(&attrs, "type").unwrap_or_else(|| "model".into());
                        cur = Some((
                            id,
                            Object {
                                name: attr(&attrs, "name"),
                                printable: matches!(ty.as_str(), "model" | "solidsupport"),
                                content: Content::None(None),
                            },
                        ));
                    }
                } else if name == "object" {
                    return Err(err(format!(
                        "the 3MF part '/{p}' has an <object> without an id; the file is damaged"
                    )));
                }
            }
            ("object", "mesh") => {
                if let Some((_, o)) = cur.as_mut() {
                    o.content = Content::Mesh {
                        vertices: Vec::new(),
                        triangles: Vec::new(),
                        beams: false,
                    };
                }
            }
            ("object", "components") => {
                if let Some((_, o)) = cur.as_mut() {
                    o.content = Content::Components(Vec::new());
                }
            }
            ("object", "") => {
                // Another extension's object content (volumetric, boolean, displacement…).
                if let Some((_, o)) = cur.as_mut()
                    && matches!(o.content, Content::None(None))
                    && !local.eq_ignore_ascii_case("metadatagroup")
                {
                    o.content = Content::None(Some(local.clone()));
                }
            }
            ("mesh", "") if local == "beamlattice" => {
                if let Some((
                    _,
                    Object {
                        content: Content::Mesh { beams, .. },
                        ..
                    },
                )) = cur.as_mut()
                {
                    *beams = true;
                }
            }
            ("vertices", "vertex") => {
                totals.vertices += 1;
                if totals.vertices > MAX_VERTICES {
                    return Err(err(format!(
                        "the 3MF file has more than {MAX_VERTICES} vertices; at most that many are accepted — simplify the model"
                    )));
                }
                let mut v = [0f32; 3];
                for (k, n) in ["x", "y", "z"].iter().enumerate() {
                    let s = attr(&attrs, n).ok_or_else(|| {
                        err(format!(
                            "the 3MF part '/{p}' has a <vertex> without '{n}'; the file is damaged"
                        ))
                    })?;
                    let c = (number(&s, "a vertex coordinate", p)? * scale) as f32;
                    if !c.is_finite() {
                        return Err(err(format!(
                            "the 3MF part '/{p}' has a vertex coordinate too large for single precision ('{}'); the file is damaged",
                            quote(&s)
                        )));
                    }
                    v[k] = c;
                }
                if let Some((
                    _,
                    Object {
                        content: Content::Mesh { vertices, .. },
                        ..
                    },
                )) = cur.as_mut()
                {
                    vertices.push(v);
                }
            }
            ("triangles", "triangle") => {
                totals.triangles += 1;
                if totals.triangles > MAX_TRIANGLES {
                    return Err(err(format!(
                        "the 3MF file has more than {MAX_TRIANGLES} triangles; at most that many are accepted — simplify the model"
                    )));
                }
                let t = [
                    index(attr(&attrs, "v1"), "a triangle's v1", p)?,
                    index(attr(&attrs, "v2"), "a triangle's v2", p)?,
                    index(attr(&attrs, "v3"), "a triangle's v3", p)?,
                ];
                if let Some((
                    id,
                    Object {
                        content:
                            Content::Mesh {
                                vertices,
                                triangles,
                                ..
                            },
                        ..
                    },
                )) = cur.as_mut()
                {
                    // 3MF lists the vertices before the triangles.
                    if let Some(&bad) = t.iter().find(|&&i| i as usize >= vertices.len()) {
                        return Err(err(format!(
                            "the 3MF part '/{p}': object {id}'s triangle {} refers to vertex {bad}, but the mesh has {} vertices; the file is damaged — export it again",
                            triangles.len() + 1,
                            vertices.len()
                        )));
                    }
                    triangles.push(t);
                }
            }
            ("components", "component") => {
                let id = index(attr(&attrs, "objectid"), "a <component> objectid", p)?;
                let tr = transform(attr(&attrs, "transform"), scale, p)?;
                let path = attr_ns(&attrs, PRODUCTION_NS, "path").map(|s| part_key(&s));
                if let Some((
                    _,
                    Object {
                        content: Content::Components(cs),
                        ..
                    },
                )) = cur.as_mut()
                {
                    if cs.len() >= MAX_ITEMS {
                        return Err(err(format!(
                            "the 3MF part '/{p}' has an object with more than {MAX_ITEMS} components; at most that many are accepted"
                        )));
                    }
                    cs.push(Component {
                        path,
                        id,
                        transform: tr,
                    });
                }
            }
            ("build", "item") if is_root => {
                if model.items.len() >= MAX_ITEMS {
                    return Err(err(format!(
                        "the 3MF build has more than {MAX_ITEMS} items; at most that many are accepted"
                    )));
                }
                model.items.push(Item {
                    id: index(attr(&attrs, "objectid"), "a build <item> objectid", p)?,
                    transform: transform(attr(&attrs, "transform"), scale, p)?,
                    path: attr_ns(&attrs, PRODUCTION_NS, "path").map(|s| part_key(&s)),
                });
            }
            _ => {}
        }
        // Nothing inside an element is read unless it is one whose children are: skip the rest.
        if !empty && !READ_INSIDE.contains(&name.as_str()) {
            x.skip(p)?;
            continue;
        }
        path.push(name);
    }
    totals.inflated = MAX_UNCOMPRESSED - x.left();
    if !saw_model {
        return Err(err(format!(
            "the 3MF part '/{p}' is empty (no <model>); the file is damaged — export it again"
        )));
    }
    Ok(model)
}

/// Most object instances the build may visit (components included), so that components of
/// empty meshes cannot make the resolution run for hours.
pub const MAX_INSTANCES: u64 = MAX_TRIANGLES as u64;

/// What an object instantiates: triangles, object instances (itself included) and the
/// height of its component tree (a mesh: 1).
#[derive(Clone, Copy)]
struct Size {
    triangles: u64,
    instances: u64,
    height: usize,
}

/// Resolves the build: one part per printable build item with triangles.
fn build(
    models: &HashMap<String, Model>,
    root: &str,
    stem: &str,
    shown: &HashMap<String, String>,
) -> Result<Vec<Part>, Error> {
    let items = &models[root].items;
    if items.is_empty() {
        return Err(err(
            "the 3MF file's build is empty (no <item>): there is nothing to print; place the objects on the plate in your modelling program and export again",
        ));
    }
    // Sizes first (with cycle, depth and size checks, memoised), so that nothing is
    // instantiated before the whole build is known to be within bounds.
    let mut memo: HashMap<(String, u32), Size> = HashMap::new();
    let (mut triangles, mut instances) = (0u64, 0u64);
    let mut wanted = Vec::new();
    let mut skipped = 0;
    for item in items {
        let path = item.path.clone().unwrap_or_else(|| root.to_string());
        let obj = lookup(models, &path, item.id, "a build item")?;
        if !obj.printable {
            skipped += 1;
            continue;
        }
        let mut stack = Vec::new();
        let size = measure(models, &path, item.id, 1, &mut stack, &mut memo)?;
        triangles = triangles.saturating_add(size.triangles);
        instances = instances.saturating_add(size.instances);
        if triangles > MAX_TRIANGLES as u64 {
            return Err(err(format!(
                "the 3MF build places more than {MAX_TRIANGLES} triangles (counting every instance of every component); at most that many are accepted — simplify the model or print fewer copies"
            )));
        }
        if instances > MAX_INSTANCES {
            return Err(err(format!(
                "the 3MF build places more than {MAX_INSTANCES} objects (counting every instance of every component); at most that many are accepted"
            )));
        }
        if size.triangles > 0 {
            wanted.push((item, path, obj, size.triangles));
        }
    }
    if wanted.is_empty() {
        return Err(err(if skipped > 0 {
            "the 3MF build has no mesh to print: its items are support, surface or 'other' objects (which dropslice does not print) or have no triangles"
        } else {
            "the 3MF build has no mesh to print: its objects have no triangles"
        }));
    }
    let mut parts = Vec::with_capacity(wanted.len());
    let mut seen_names: HashMap<String, usize> = HashMap::new();
    for (item, path, obj, n) in wanted {
        let mut tris = Triangles::with_capacity(n as usize);
        emit(models, &path, item.id, &item.transform, &mut tris)?;
        let base = obj
            .name
            .clone()
            .filter(|s| !s.trim().is_empty())
            .unwrap_or_else(|| format!("{stem} object {}", item.id));
        let k = seen_names.entry(base.clone()).or_insert(0);
        *k += 1;
        let name = if *k > 1 {
            format!("{base} ({k})")
        } else {
            base
        };
        parts.push(Part {
            name,
            triangles: tris,
            transform_applied: item.transform.rows(),
            source_object: Some(if path == root {
                item.id.to_string()
            } else {
                format!("/{}#{}", shown.get(&path).unwrap_or(&path), item.id)
            }),
        });
    }
    Ok(parts)
}

fn lookup<'m>(
    models: &'m HashMap<String, Model>,
    path: &str,
    id: u32,
    who: &str,
) -> Result<&'m Object, Error> {
    models
        .get(path)
        .and_then(|m| m.objects.get(&id))
        .ok_or_else(|| {
            err(format!(
                "{who} refers to object {id}, which the 3MF part '/{}' does not define; the file is damaged — export it again",
                quote(path)
            ))
        })
}

/// What object `id` of model `path` instantiates (saturating), referred to at nesting level
/// `depth` (a build item's object is level 1).
fn measure(
    models: &HashMap<String, Model>,
    path: &str,
    id: u32,
    depth: usize,
    stack: &mut Vec<(String, u32)>,
    memo: &mut HashMap<(String, u32), Size>,
) -> Result<Size, Error> {
    let too_deep = || {
        err(format!(
            "the 3MF file nests components more than {MAX_COMPONENT_DEPTH} deep; at most that many levels are read"
        ))
    };
    let key = (path.to_string(), id);
    if let Some(&s) = memo.get(&key) {
        if depth - 1 + s.height > MAX_COMPONENT_DEPTH {
            return Err(too_deep());
        }
        return Ok(s);
    }
    if stack.contains(&key) {
        return Err(err(format!(
            "the 3MF file's components form a cycle (object {id} contains itself through its components); the file is damaged — export it again"
        )));
    }
    if depth > MAX_COMPONENT_DEPTH {
        return Err(too_deep());
    }
    let obj = lookup(models, path, id, "a component")?;
    let size = match &obj.content {
        Content::Mesh {
            triangles, beams, ..
        } => {
            if triangles.is_empty() && *beams {
                return Err(err(format!(
                    "object {id} of the 3MF file is a beam lattice without triangles; dropslice prints meshes only — export the lattice as a mesh"
                )));
            }
            Size {
                triangles: triangles.len() as u64,
                instances: 1,
                height: 1,
            }
        }
        Content::Components(cs) => {
            stack.push(key.clone());
            let mut s = Size {
                triangles: 0,
                instances: 1,
                height: 1,
            };
            for c in cs {
                let cp = c.path.as_deref().unwrap_or(path);
                let cs = measure(models, cp, c.id, depth + 1, stack, memo)?;
                s.triangles = s.triangles.saturating_add(cs.triangles);
                s.instances = s.instances.saturating_add(cs.instances);
                s.height = s.height.max(cs.height + 1);
            }
            stack.pop();
            s
        }
        Content::None(what) => {
            return Err(err(match what {
                Some(w) => format!(
                    "object {id} of the 3MF file has no mesh but <{w}> (a 3MF extension dropslice does not read); export the model as a mesh"
                ),
                None => format!(
                    "object {id} of the 3MF file has neither a mesh nor components; there is nothing to print in it"
                ),
            }));
        }
    };
    memo.insert(key, size);
    Ok(size)
}

/// Appends the triangles of object `id` placed by `at` (counted beforehand: bounded).
fn emit(
    models: &HashMap<String, Model>,
    path: &str,
    id: u32,
    at: &Affine,
    out: &mut Triangles,
) -> Result<(), Error> {
    let obj = lookup(models, path, id, "a component")?;
    match &obj.content {
        Content::Mesh {
            vertices,
            triangles,
            ..
        } => {
            for t in triangles {
                let mut tri = [[0f32; 3]; 3];
                for (k, &i) in t.iter().enumerate() {
                    let v = vertices[i as usize];
                    let q = at.apply([v[0] as f64, v[1] as f64, v[2] as f64]);
                    tri[k] = [q[0] as f32, q[1] as f32, q[2] as f32];
                }
                if tri.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(err(format!(
                        "object {id} of the 3MF file lands beyond single-precision range after its transforms; the transforms are damaged"
                    )));
                }
                out.push(tri);
            }
        }
        Content::Components(cs) => {
            for c in cs {
                let cp = c.path.as_deref().unwrap_or(path);
                emit(models, cp, c.id, &c.transform.then(at), out)?;
            }
        }
        Content::None(_) => {}
    }
    Ok(())
}
