//! The XML side of a 3MF model part: a bounded, namespace-resolving event reader ([`Xml`])
//! over a ZIP entry, and the attribute helpers of the parser (values, numbers, indices).

use std::io::{BufRead, BufReader, Read};

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use quick_xml::name::ResolveResult;

use super::{CORE_NS, Limited, MAX_NAMESPACES, MAX_XML_DEPTH, err};
use crate::base::error::{Error, quote};

/// An attribute of an element: its namespace (empty when unbound), local name and unescaped
/// value.
pub(super) type Attr = (String, String, String);

/// An attribute without a namespace.
pub(super) fn attr(attrs: &[Attr], name: &str) -> Option<String> {
    attrs
        .iter()
        .find(|(ns, l, _)| ns.is_empty() && l == name)
        .map(|(_, _, v)| v.clone())
}

/// An attribute in namespace `ns`.
pub(super) fn attr_ns(attrs: &[Attr], ns: &str, name: &str) -> Option<String> {
    attrs
        .iter()
        .find(|(n, l, _)| n == ns && l == name)
        .map(|(_, _, v)| v.clone())
}

pub(super) enum XmlEvent {
    /// A start or empty element: its namespace (empty when unbound), local name and
    /// attributes.
    Start {
        ns: String,
        local: String,
        attrs: Vec<Attr>,
        empty: bool,
    },
    End,
}

/// A bounded, namespace-resolving XML event reader over a ZIP entry. Names are resolved
/// (and namespace scopes kept) only for the elements [`Xml::next`] gives, not for those
/// [`Xml::skip`] passes over.
pub(super) struct Xml<R: BufRead> {
    r: Reader<R>,
    pub(super) ns: quick_xml::name::NamespaceResolver,
    buf: Vec<u8>,
    depth: usize,
    /// Namespace declarations per open element.
    ns_stack: Vec<usize>,
    roots: usize,
    pending_end: bool,
}

impl<R: BufRead> Xml<R> {
    pub(super) fn new(r: R) -> Self {
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
    /// What is left of the package's inflation budget.
    pub(super) fn left(&self) -> u64 {
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
    pub(super) fn skip(&mut self, part: &str) -> Result<(), Error> {
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
    pub(super) fn next(
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
            let (decls, ns) = scope(&mut self.ns, &ev, part)?;
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

/// For a start or empty element: its namespace declarations (a scope is pushed only for
/// elements that declare some) and its namespace, the core namespace as "" (as unbound
/// names: no text made for most elements). `(0, "")` for other events.
fn scope(
    resolver: &mut quick_xml::name::NamespaceResolver,
    ev: &Event,
    part: &str,
) -> Result<(usize, String), Error> {
    let (Event::Start(s) | Event::Empty(s)) = ev else {
        return Ok((0, String::new()));
    };
    let decls = declarations(s, part)?;
    if decls > 0 {
        resolver.push(s).map_err(|e| {
            err(format!(
                "the 3MF part '/{part}' has a bad namespace declaration ({}); the file is damaged",
                quote(&e.to_string())
            ))
        })?;
    }
    let ns = match resolver.resolve_element(s.name()).0 {
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
    Ok((decls, ns))
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

/// The attributes of an element, namespace declarations left out.
fn attributes(
    resolver: &quick_xml::name::NamespaceResolver,
    s: &BytesStart,
    local: &str,
    part: &str,
) -> Result<Vec<Attr>, Error> {
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

/// A finite number (`what` names it in messages).
pub(super) fn number(v: &str, what: &str, part: &str) -> Result<f64, Error> {
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

/// A required index: a whole number ≥ 0.
pub(super) fn index(v: Option<String>, what: &str, part: &str) -> Result<u32, Error> {
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
