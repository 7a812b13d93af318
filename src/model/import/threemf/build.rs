//! Resolving a 3MF build: every printable build item's object, its components followed
//! (across model parts through `p:path`) and their transforms composed, into one part per
//! item. Sizes, nesting and cycles are checked for the whole build before anything is
//! instantiated.

use std::collections::HashMap;

use super::model::{Content, Document, Object};
use super::transform::Affine;
use super::{MAX_COMPONENT_DEPTH, MAX_INSTANCES, err};
use crate::base::error::{Error, quote};
use crate::model::import::stl::Triangles;
use crate::model::import::{MAX_TRIANGLES, Part};

/// What an object instantiates: triangles, object instances (itself included) and the
/// height of its component tree (a mesh: 1).
#[derive(Clone, Copy)]
struct Size {
    triangles: u64,
    instances: u64,
    height: usize,
}

/// Resolves the build: one part per printable build item with triangles.
pub(super) fn build(
    models: &HashMap<String, Document>,
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
    models: &'m HashMap<String, Document>,
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
    models: &HashMap<String, Document>,
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
    models: &HashMap<String, Document>,
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
