//! Display meshes for the page's 3D view: a part's triangles decimated to a budget by vertex
//! clustering ([`display_mesh`]), for drawing only (never sliced).

use crate::base::geom::DVec3;

/// A decimated copy of `tris` with at most `max_triangles` triangles, for drawing only (never
/// sliced): vertex clustering on a grid, each cell's corners moved to their mean, triangles
/// that collapse dropped (and repeats). 9 floats per triangle (x, y, z of three corners).
pub fn display_mesh(tris: &[[[f32; 3]; 3]], max_triangles: usize) -> Vec<f32> {
    if tris.len() <= max_triangles {
        return tris.iter().flatten().flatten().copied().collect();
    }
    if max_triangles == 0 {
        return Vec::new();
    }
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let mut area = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|p| DVec3::from(p.map(f64::from)));
        for p in [a, b, c] {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        area += (b - a).cross(c - a).length() / 2.0;
    }
    let extent = (hi - lo).max_element();
    if !extent.is_finite() || extent <= 0.0 {
        return Vec::new();
    }
    // About two triangles per cell of the surface; grown until the result fits.
    let mut cell = (2.0 * area / max_triangles as f64)
        .sqrt()
        .max(extent * 1e-6);
    for _ in 0..200 {
        let out = cluster(tris, lo, cell, max_triangles);
        if let Some(out) = out {
            return out;
        }
        cell *= 1.25;
    }
    Vec::new()
}

/// One clustering with cells of `cell` mm; `None` if more than `max` triangles remain.
fn cluster(tris: &[[[f32; 3]; 3]], lo: DVec3, cell: f64, max: usize) -> Option<Vec<f32>> {
    use std::collections::{HashMap, HashSet};
    let key = |p: [f32; 3]| {
        let q = (DVec3::from(p.map(f64::from)) - lo) / cell;
        [q.x as i64, q.y as i64, q.z as i64]
    };
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut sums: Vec<(DVec3, u32)> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut seen: HashSet<[u32; 3]> = HashSet::new();
    for t in tris {
        let f = t.map(|p| {
            let k = key(p);
            let id = *ids.entry(k).or_insert_with(|| {
                sums.push((DVec3::ZERO, 0));
                (sums.len() - 1) as u32
            });
            let s = &mut sums[id as usize];
            s.0 += DVec3::from(p.map(f64::from));
            s.1 += 1;
            id
        });
        if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
            continue;
        }
        let mut sorted = f;
        sorted.sort_unstable();
        if seen.insert(sorted) {
            faces.push(f);
            if faces.len() > max {
                return None;
            }
        }
    }
    let mean: Vec<[f32; 3]> = sums
        .iter()
        .map(|(s, n)| (*s / *n as f64).to_array().map(|c| c as f32))
        .collect();
    Some(
        faces
            .iter()
            .flat_map(|f| f.iter().flat_map(|&i| mean[i as usize]))
            .collect(),
    )
}
