//! One 3MF model part's XML → a [`Document`]: its objects (meshes, components) and, in the
//! start part, its build items. [`parse_model`] walks the elements; each kind the parser
//! reads has its own handler (the `<model>` root, resources and objects, vertices,
//! triangles, components, build items); every other element is skipped unread.

use std::collections::{HashMap, HashSet};

use quick_xml::name::{NamespaceResolver, QName, ResolveResult};

use super::transform::{Affine, transform};
use super::xml::{Attr, Xml, XmlEvent, attr, attr_ns, index, number};
use super::{
    CORE_NS, MAX_ITEMS, MAX_UNCOMPRESSED, MAX_VERTICES, PRODUCTION_NS, Totals, Zip, err,
    open_entry, part_key,
};
use crate::base::error::{Error, quote};
use crate::model::import::MAX_TRIANGLES;

/// A `<component>` or a build `<item>`: an object (in this model part, or in the part `path`)
/// and its transform.
#[derive(Debug)]
pub(super) struct ObjectRef {
    pub(super) path: Option<String>,
    pub(super) id: u32,
    pub(super) transform: Affine,
}

/// What an `<object>` holds.
#[derive(Debug)]
pub(super) enum Content {
    Mesh {
        vertices: Vec<[f32; 3]>,
        triangles: Vec<[u32; 3]>,
        beams: bool,
    },
    Components(Vec<ObjectRef>),
    /// Neither: the other extension's element it holds instead, if any.
    None(Option<String>),
}

/// An `<object>` resource.
#[derive(Debug)]
pub(super) struct Object {
    pub(super) name: Option<String>,
    pub(super) printable: bool,
    pub(super) content: Content,
}

/// One parsed model part (the XML document of one `.model` entry).
#[derive(Default)]
pub(super) struct Document {
    pub(super) objects: HashMap<u32, Object>,
    pub(super) items: Vec<ObjectRef>,
}

/// Millimetres per unit of a `<model unit>`.
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

/// Parses one model part (`part`: its name, quoted, for messages).
pub(super) fn parse_model(
    zip: &mut Zip,
    index_in_zip: usize,
    part: &str,
    is_root: bool,
    totals: &mut Totals,
) -> Result<Document, Error> {
    let r = open_entry(zip, index_in_zip, part, totals)?;
    let mut x = Xml::new(r);
    let mut reader = Reader {
        part,
        is_root,
        doc: Document::default(),
        scale: 1.0,
        resource_ids: HashSet::new(),
        cur: None,
        saw_model: false,
    };
    // Path of open elements (local names of core elements; "" for others).
    let mut path: Vec<String> = Vec::new();
    // Attributes are read only where they are used.
    while let Some(ev) = x.next(part, |ns, local| wanted(&path, ns, local))? {
        match ev {
            XmlEvent::End => {
                let closed = path.pop().unwrap_or_default();
                reader.end(&closed);
            }
            XmlEvent::Start {
                ns,
                local,
                attrs,
                empty,
            } => {
                let parent = path.last().map(String::as_str).unwrap_or("");
                let core = is_core(&ns);
                let name = if core { local.clone() } else { String::new() };
                let el = Element {
                    core,
                    name: &name,
                    local: &local,
                    attrs: &attrs,
                };
                reader.start(parent, path.is_empty(), &el, &x.ns, totals)?;
                // Nothing inside an element is read unless it is one whose children are: skip
                // the rest.
                if !empty && !READ_INSIDE.contains(&name.as_str()) {
                    x.skip(part)?;
                    continue;
                }
                path.push(name);
            }
        }
    }
    totals.inflated = MAX_UNCOMPRESSED - x.left();
    if !reader.saw_model {
        return Err(err(format!(
            "the 3MF part '/{part}' is empty (no <model>); the file is damaged — export it again"
        )));
    }
    Ok(reader.doc)
}

fn is_core(ns: &str) -> bool {
    ns.is_empty() || ns == CORE_NS
}

/// Whether the attributes of element `local` (namespace `ns`) are read, with `path` open.
fn wanted(path: &[String], ns: &str, local: &str) -> bool {
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
}

/// An element that starts.
struct Element<'e> {
    /// In the core namespace.
    core: bool,
    /// The local name of a core element, "" for others.
    name: &'e str,
    local: &'e str,
    attrs: &'e [Attr],
}

/// The state of [`parse_model`] between elements.
struct Reader<'p> {
    /// The model part's name (quoted) for messages.
    part: &'p str,
    /// The start part: the only one whose build is read.
    is_root: bool,
    doc: Document,
    /// The model's unit in mm.
    scale: f64,
    resource_ids: HashSet<u32>,
    /// The object being read.
    cur: Option<(u32, Object)>,
    saw_model: bool,
}

impl Reader<'_> {
    /// An element starts (`at_root`: it is the root element), below `parent`.
    fn start(
        &mut self,
        parent: &str,
        at_root: bool,
        el: &Element,
        resolver: &NamespaceResolver,
        totals: &mut Totals,
    ) -> Result<(), Error> {
        match (parent, el.name) {
            ("", "model") if at_root => self.model(el.attrs, resolver),
            (_, "model") | ("", _) if at_root => Err(err(format!(
                "the 3MF part '/{}' is not a 3D model (its root element is <{}>, not <model>); the file is damaged",
                self.part,
                quote(el.local)
            ))),
            ("model", "resources") | ("model", "build") => Ok(()),
            ("resources", _) => self.resource(el),
            ("object", "mesh") => {
                if let Some((_, o)) = self.cur.as_mut() {
                    o.content = Content::Mesh {
                        vertices: Vec::new(),
                        triangles: Vec::new(),
                        beams: false,
                    };
                }
                Ok(())
            }
            ("object", "components") => {
                if let Some((_, o)) = self.cur.as_mut() {
                    o.content = Content::Components(Vec::new());
                }
                Ok(())
            }
            ("object", "") => {
                // Another extension's object content (volumetric, boolean, displacement…).
                if let Some((_, o)) = self.cur.as_mut()
                    && matches!(o.content, Content::None(None))
                    && !el.local.eq_ignore_ascii_case("metadatagroup")
                {
                    o.content = Content::None(Some(el.local.to_string()));
                }
                Ok(())
            }
            ("mesh", "") if el.local == "beamlattice" => {
                if let Some((
                    _,
                    Object {
                        content: Content::Mesh { beams, .. },
                        ..
                    },
                )) = self.cur.as_mut()
                {
                    *beams = true;
                }
                Ok(())
            }
            ("vertices", "vertex") => self.vertex(el.attrs, totals),
            ("triangles", "triangle") => self.triangle(el.attrs, totals),
            ("components", "component") => self.component(el.attrs),
            ("build", "item") if self.is_root => self.item(el.attrs),
            _ => Ok(()),
        }
    }

    /// An element ends (`closed`: its name as in [`Element::name`]).
    fn end(&mut self, closed: &str) {
        if closed == "object"
            && let Some((id, obj)) = self.cur.take()
        {
            self.doc.objects.insert(id, obj);
        }
    }

    /// The root `<model>`: its unit and required extensions.
    fn model(&mut self, attrs: &[Attr], resolver: &NamespaceResolver) -> Result<(), Error> {
        self.saw_model = true;
        let unit = attr(attrs, "unit").unwrap_or_else(|| "millimeter".into());
        self.scale = unit_scale(&unit).ok_or_else(|| {
            err(format!(
                "the 3MF model's unit '{}' is unknown (micron, millimeter, centimeter, inch, foot and meter are); the file is damaged",
                quote(&unit)
            ))
        })?;
        let Some(req) = attr(attrs, "requiredextensions") else {
            return Ok(());
        };
        for prefix in req.split_ascii_whitespace() {
            let ns = resolver.resolve_element(QName(&format!("{prefix}:x"))).0;
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
        Ok(())
    }

    /// Any resource (objects, materials, …): ids are unique within a model part. (Another
    /// extension's resource with an id that is not a number is ignored.) An `<object>` becomes
    /// the object being read.
    fn resource(&mut self, el: &Element) -> Result<(), Error> {
        let p = self.part;
        let id = match attr(el.attrs, "id") {
            Some(v) if el.core => Some(index(Some(v), &format!("a <{}> id", el.local), p)?),
            Some(v) => v.trim().parse::<u32>().ok(),
            None => None,
        };
        let Some(id) = id else {
            if el.name == "object" {
                return Err(err(format!(
                    "the 3MF part '/{p}' has an <object> without an id; the file is damaged"
                )));
            }
            return Ok(());
        };
        if !self.resource_ids.insert(id) {
            return Err(err(format!(
                "the 3MF part '/{p}' has two resources with id {id}; ids must be unique — the file is damaged"
            )));
        }
        if el.name == "object" {
            let ty = attr(el.attrs, "type").unwrap_or_else(|| "model".into());
            self.cur = Some((
                id,
                Object {
                    name: attr(el.attrs, "name"),
                    printable: matches!(ty.as_str(), "model" | "solidsupport"),
                    content: Content::None(None),
                },
            ));
        }
        Ok(())
    }

    /// A `<vertex>` of the object's mesh, in mm.
    fn vertex(&mut self, attrs: &[Attr], totals: &mut Totals) -> Result<(), Error> {
        let p = self.part;
        count(&mut totals.vertices, MAX_VERTICES, "vertices")?;
        let mut v = [0f32; 3];
        for (k, n) in ["x", "y", "z"].iter().enumerate() {
            let s = attr(attrs, n).ok_or_else(|| {
                err(format!(
                    "the 3MF part '/{p}' has a <vertex> without '{n}'; the file is damaged"
                ))
            })?;
            let c = (number(&s, "a vertex coordinate", p)? * self.scale) as f32;
            if !c.is_finite() {
                return Err(err(format!(
                    "the 3MF part '/{p}' has a vertex coordinate too large for single precision ('{}'); the file is damaged",
                    quote(&s)
                )));
            }
            v[k] = c;
        }
        if let Some((_, vertices, _)) = self.mesh() {
            vertices.push(v);
        }
        Ok(())
    }

    /// The object being read, if it is a mesh: its id, vertices and triangles.
    #[allow(clippy::type_complexity)]
    fn mesh(&mut self) -> Option<(u32, &mut Vec<[f32; 3]>, &mut Vec<[u32; 3]>)> {
        match self.cur.as_mut() {
            Some((
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
            )) => Some((*id, vertices, triangles)),
            _ => None,
        }
    }

    /// A `<triangle>` of the object's mesh: three indices of vertices listed before it.
    fn triangle(&mut self, attrs: &[Attr], totals: &mut Totals) -> Result<(), Error> {
        let p = self.part;
        count(&mut totals.triangles, MAX_TRIANGLES, "triangles")?;
        let t = [
            index(attr(attrs, "v1"), "a triangle's v1", p)?,
            index(attr(attrs, "v2"), "a triangle's v2", p)?,
            index(attr(attrs, "v3"), "a triangle's v3", p)?,
        ];
        if let Some((id, vertices, triangles)) = self.mesh() {
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
        Ok(())
    }

    /// A `<component>` of the object.
    fn component(&mut self, attrs: &[Attr]) -> Result<(), Error> {
        let p = self.part;
        let id = index(attr(attrs, "objectid"), "a <component> objectid", p)?;
        let tr = transform(attr(attrs, "transform"), self.scale, p)?;
        let path = attr_ns(attrs, PRODUCTION_NS, "path").map(|s| part_key(&s));
        if let Some((
            _,
            Object {
                content: Content::Components(cs),
                ..
            },
        )) = self.cur.as_mut()
        {
            if cs.len() >= MAX_ITEMS {
                return Err(err(format!(
                    "the 3MF part '/{p}' has an object with more than {MAX_ITEMS} components; at most that many are accepted"
                )));
            }
            cs.push(ObjectRef {
                path,
                id,
                transform: tr,
            });
        }
        Ok(())
    }

    /// A build `<item>` (of the start part).
    fn item(&mut self, attrs: &[Attr]) -> Result<(), Error> {
        let p = self.part;
        if self.doc.items.len() >= MAX_ITEMS {
            return Err(err(format!(
                "the 3MF build has more than {MAX_ITEMS} items; at most that many are accepted"
            )));
        }
        self.doc.items.push(ObjectRef {
            id: index(attr(attrs, "objectid"), "a build <item> objectid", p)?,
            transform: transform(attr(attrs, "transform"), self.scale, p)?,
            path: attr_ns(attrs, PRODUCTION_NS, "path").map(|s| part_key(&s)),
        });
        Ok(())
    }
}

/// Counts one more of `what` in the file, refused beyond `max`.
fn count(n: &mut usize, max: usize, what: &str) -> Result<(), Error> {
    *n += 1;
    if *n > max {
        return Err(err(format!(
            "the 3MF file has more than {max} {what}; at most that many are accepted — simplify the model"
        )));
    }
    Ok(())
}
