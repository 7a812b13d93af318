//! The boolean engine's operations on regions (i_overlay, non-zero rule): difference,
//! intersection, union and the outward outline, every result without slivers of rounding
//! (loops under [`MIN_AREA_MM2`]).

use crate::base::geom::{DVec2, Shape, Shapes, shapes_from_overlay, signed_area};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay::ShapeType;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::overlay::FloatOverlay;
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::i_float::adapter::FloatPointAdapter;
use i_overlay::i_float::int::point::IntPoint;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};

/// Loops enclosing less than this are slivers of rounding, not geometry.
pub const MIN_AREA_MM2: f64 = 1e-6;

/// A region in the boolean engine's nested form (each shape: outer boundary, then holes).
pub fn nested(region: &Shapes) -> Vec<Vec<Vec<[f64; 2]>>> {
    region
        .iter()
        .map(|s| {
            s.contours()
                .map(|c| c.iter().map(|p| p.to_array()).collect())
                .collect()
        })
        .collect()
}

/// Shapes from the engine, without loops of less than [`MIN_AREA_MM2`].
pub fn cleaned(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Shapes {
    shapes_from_overlay(shapes)
        .into_iter()
        .filter_map(without_slivers)
        .collect()
}

/// A shape without its loops of less than [`MIN_AREA_MM2`] (`None` when its outer loop is one).
pub fn without_slivers(s: Shape) -> Option<Shape> {
    if signed_area(&s.outer).abs() < MIN_AREA_MM2 {
        return None;
    }
    let holes = s
        .holes
        .into_iter()
        .filter(|h| signed_area(h).abs() >= MIN_AREA_MM2)
        .collect();
    Some(Shape::new(s.outer, holes))
}

/// The region moved outward by `d` mm, round joins with chords within `tolerance` of the arcs (the chords lie inside the arcs: the
/// region grows by between d − tolerance and d).
pub fn grow_within(region: &Shapes, d: f64, tolerance: f64) -> Shapes {
    if region.is_empty() || d <= 0.0 {
        return region.clone();
    }
    let angle = 2.0 * (1.0 - (tolerance / d).min(1.0)).acos();
    let style = OutlineStyle::default()
        .outer_offset(d)
        .inner_offset(d)
        .line_join(LineJoin::Round(angle));
    cleaned(nested(region).outline(&style))
}

/// a − b.
pub fn difference(a: &Shapes, b: &Shapes) -> Shapes {
    if a.is_empty() || b.is_empty() {
        return a.clone();
    }
    cleaned(nested(a).overlay(&nested(b), OverlayRule::Difference, FillRule::NonZero))
}

/// a ∩ b.
pub fn intersection(a: &Shapes, b: &Shapes) -> Shapes {
    if a.is_empty() || b.is_empty() {
        return Shapes::new();
    }
    cleaned(nested(a).overlay(&nested(b), OverlayRule::Intersect, FillRule::NonZero))
}

/// a ∪ b.
pub fn union(a: &Shapes, b: &Shapes) -> Shapes {
    if a.is_empty() {
        return b.clone();
    }
    if b.is_empty() {
        return a.clone();
    }
    cleaned(nested(a).overlay(&nested(b), OverlayRule::Union, FillRule::NonZero))
}

/// The bounding box of a shape (of its outer loop).
pub fn bounds(s: &Shape) -> (DVec2, DVec2) {
    box_of(s.outer.iter().copied())
}

/// The bounding box of points (infinite and empty for none).
fn box_of(points: impl Iterator<Item = DVec2>) -> (DVec2, DVec2) {
    points.fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

/// The bounding box of each item's paths, the boxes [`apart_groups`] takes.
fn paths_boxes(items: &[Paths]) -> Vec<(DVec2, DVec2)> {
    items
        .iter()
        .map(|paths| box_of(paths.iter().flatten().map(|p| DVec2::from(*p))))
        .collect()
}

/// Whether two bounding boxes overlap (touching counts).
pub fn overlap(a: (DVec2, DVec2), b: (DVec2, DVec2)) -> bool {
    a.0.x <= b.1.x && b.0.x <= a.1.x && a.0.y <= b.1.y && b.0.y <= a.1.y
}

/// Closed paths in the engine's point type.
pub type Paths = Vec<Vec<[f64; 2]>>;

/// Boxes nearer than this (mm) put their items in one group of [`simplify_apart`]: far more
/// than the engine's rounding (a unit of its integer grid is under 10⁻⁵ mm for a plate).
const APART_MM: f64 = 0.01;

/// The engine's simplification (the union under `fill_rule`) of all paths of all `items`,
/// exactly as one pass over them all gives it — the same points, loops and shapes in the
/// same order — made per group of items whose paths' bounding boxes lie apart
/// ([`apart_groups`]): a layer of 10⁴ separate islands costs as many small passes, not one
/// pass whose sorting and sweeps grow faster than the islands.
///
/// Why it is the same: every point goes to the engine's integer grid by one adapter, made
/// from all points as the single pass makes it; paths of different groups neither cross nor
/// touch, so the engine splits and joins within a group only; and the single pass emits its
/// shapes in the order of their lowest-leftmost vertex on that grid, which sorting the groups'
/// shapes by that vertex restores (shapes of different groups never share it). Tested against
/// [`simplify_together`] on random island sets.
pub fn simplify_apart(items: &[Paths], fill_rule: FillRule) -> Paths3 {
    simplify_apart_known(items, fill_rule, |_| false)
}

/// [`simplify_apart`] told which items are known to give no shape of more than
/// [`MIN_AREA_MM2`] alone (`vanishes(i)`; e.g. the raw offset curve of an island thinner than
/// twice the offset): a group of such items only is not passed to the engine. Their points
/// still make the adapter, so every other group's points go to the same grid as before, and
/// the result differs from [`simplify_apart`]'s only by loops under [`MIN_AREA_MM2`] (which
/// every caller drops) — none, where the caller's claim holds with a margin over the grid.
pub fn simplify_apart_known(
    items: &[Paths],
    fill_rule: FillRule,
    vanishes: impl Fn(usize) -> bool,
) -> Paths3 {
    if items.len() < 2 {
        if items.len() == 1 && vanishes(0) {
            return Paths3::new();
        }
        return simplify_together(items, fill_rule);
    }
    let points = items.iter().flatten().flatten();
    let adapter = FloatPointAdapter::<[f64; 2], i32>::with_iter_conservative(points);
    let boxes = paths_boxes(items);
    let groups = apart_groups(&boxes, APART_MM);
    if groups.len() < 2 {
        if groups.iter().flatten().all(|&i| vanishes(i)) {
            return Paths3::new();
        }
        return simplify_together(items, fill_rule);
    }
    let mut keyed: Vec<([f64; 2], Paths)> = Vec::new();
    let mut overlay = FloatOverlay::<[f64; 2], i32>::with_adapter(adapter.clone(), 0);
    let mut grid: Vec<IntPoint<i32>> = Vec::new();
    for group in groups {
        if group.iter().all(|&i| vanishes(i)) {
            continue;
        }
        if let [i] = group[..]
            && let [path] = &items[i][..]
            && convex_on_grid(path, &adapter, &mut grid)
        {
            // One convex loop counter-clockwise: the engine returns it as it is on its grid.
            if fill_rule != FillRule::Negative {
                let shape = vec![engine_order(&grid, &adapter)];
                keyed.push((lowest_left(&shape[0]), shape));
            }
            continue;
        }
        overlay.clear();
        for &i in &group {
            overlay = overlay.unsafe_add_source(&items[i], ShapeType::Subject);
        }
        for shape in overlay.overlay(OverlayRule::Subject, fill_rule) {
            let key = shape
                .first()
                .map_or([f64::INFINITY; 2], |outer| lowest_left(outer));
            keyed.push((key, shape));
        }
    }
    keyed.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]).then(a.0[1].total_cmp(&b.0[1])));
    keyed.into_iter().map(|(_, s)| s).collect()
}

/// Shapes in the engine's nested form (each shape: outer boundary, then holes).
pub type Paths3 = Vec<Vec<Vec<[f64; 2]>>>;

/// [`simplify_apart`] in one pass of the engine over all paths.
pub fn simplify_together(items: &[Paths], fill_rule: FillRule) -> Paths3 {
    let all: Paths = items.iter().flatten().cloned().collect();
    all.simplify_shape(fill_rule)
}

/// Whether `path` on the engine's grid (into `grid`, repeated points once) is a strictly
/// convex loop turning counter-clockwise once: every corner turns left and the points run
/// up then down in (x, y) order exactly once (a loop turning left twice round runs so twice).
fn convex_on_grid(
    path: &[[f64; 2]],
    adapter: &FloatPointAdapter<[f64; 2], i32>,
    grid: &mut Vec<IntPoint<i32>>,
) -> bool {
    grid.clear();
    for p in path {
        let q = adapter.float_to_int(p);
        if grid.last() != Some(&q) {
            grid.push(q);
        }
    }
    while grid.len() > 1 && grid.first() == grid.last() {
        grid.pop();
    }
    let n = grid.len();
    if n < 3 {
        return false;
    }
    let up = |a: IntPoint<i32>, b: IntPoint<i32>| (b.x, b.y) > (a.x, a.y);
    let mut changes = 0;
    for k in 0..n {
        let (a, b, c) = (grid[k], grid[(k + 1) % n], grid[(k + 2) % n]);
        let cross = (i64::from(b.x) - i64::from(a.x)) * (i64::from(c.y) - i64::from(b.y))
            - (i64::from(b.y) - i64::from(a.y)) * (i64::from(c.x) - i64::from(b.x));
        if cross <= 0 {
            return false;
        }
        changes += usize::from(up(a, b) != up(b, c));
    }
    changes == 2
}

/// A convex loop on the grid as the engine emits it: counter-clockwise, from the point before
/// its lowest-leftmost one, back in floats.
fn engine_order(
    grid: &[IntPoint<i32>],
    adapter: &FloatPointAdapter<[f64; 2], i32>,
) -> Vec<[f64; 2]> {
    let n = grid.len();
    let low = (0..n).min_by_key(|&k| (grid[k].x, grid[k].y)).unwrap_or(0);
    let start = (low + n - 1) % n;
    (0..n)
        .map(|k| adapter.int_to_float(&grid[(start + k) % n]))
        .collect()
}

/// The lowest of the leftmost points of a path (x, then y).
fn lowest_left(path: &[[f64; 2]]) -> [f64; 2] {
    path.iter().fold([f64::INFINITY; 2], |m, p| {
        if p[0] < m[0] || (p[0] == m[0] && p[1] < m[1]) {
            *p
        } else {
            m
        }
    })
}

/// Items in groups such that no box of one group, grown by `margin` on every side, meets a
/// box of another (touching counts as meeting): the connected components of "grown boxes
/// meet", by a union-find. Boxes are binned to square cells of about twice the median box
/// (a box in every cell it covers, unless that makes over 16 entries per box: then one cell),
/// and the boxes of each cell swept along x. Each group's items in increasing order, the
/// groups in the order of their first item. An empty box (no points) is a group alone.
pub fn apart_groups(boxes: &[(DVec2, DVec2)], margin: f64) -> Vec<Vec<usize>> {
    let n = boxes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let grown: Vec<(DVec2, DVec2)> = boxes
        .iter()
        .map(|&(lo, hi)| (lo - DVec2::splat(margin), hi + DVec2::splat(margin)))
        .collect();
    let live: Vec<usize> = (0..n)
        .filter(|&i| grown[i].0.x <= grown[i].1.x && grown[i].0.y <= grown[i].1.y)
        .collect();
    let mut entries = cell_entries(&grown, &live);
    let mut cell: Vec<usize> = Vec::new();
    // The components do not depend on the order the cells are visited in (every root is its
    // set's smallest item), so the entries need only be gathered by cell.
    for run in by_cell(&mut entries).chunk_by(|a, b| a.0 == b.0) {
        cell.clear();
        cell.extend(run.iter().map(|e| e.1));
        sweep_unite(&grown, &mut cell, &mut parent);
    }
    let mut slot = vec![usize::MAX; n];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        if slot[r] == usize::MAX {
            slot[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[slot[r]].push(i);
    }
    groups
}

/// The root of `i` in a union-find whose roots are their sets' smallest items.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// (cell, item) for every cell of a grid that each live box covers; all in one cell when
/// that would make too many.
fn cell_entries(grown: &[(DVec2, DVec2)], live: &[usize]) -> Vec<((i64, i64), usize)> {
    let one_cell = || live.iter().map(|&i| ((0, 0), i)).collect();
    if live.len() < 2 {
        return one_cell();
    }
    let mut extents: Vec<f64> = live
        .iter()
        .map(|&i| (grown[i].1 - grown[i].0).max_element())
        .collect();
    let mid = extents.len() / 2;
    let median = *extents.select_nth_unstable_by(mid, f64::total_cmp).1;
    let origin = live
        .iter()
        .fold(DVec2::splat(f64::INFINITY), |m, &i| m.min(grown[i].0));
    let size = (2.0 * median).max(1e-6);
    let budget = 16 * live.len();
    let mut out = Vec::with_capacity(live.len() * 2);
    for &i in live {
        let (lo, hi) = grown[i];
        let a = ((lo - origin) / size).floor();
        let b = ((hi - origin) / size).floor();
        // Cells beyond the budget (or beyond i64) mean one cell for all.
        if !(b.x - a.x + 1.0).is_finite() || (b.x - a.x + 1.0) * (b.y - a.y + 1.0) > budget as f64 {
            return one_cell();
        }
        for x in a.x as i64..=b.x as i64 {
            for y in a.y as i64..=b.y as i64 {
                out.push(((x, y), i));
                if out.len() > budget {
                    return one_cell();
                }
            }
        }
    }
    out
}

/// The entries gathered by cell: by a counting sort where the cells' range is dense (at most
/// four cells per entry), else by a sort.
fn by_cell(entries: &mut Vec<((i64, i64), usize)>) -> &[((i64, i64), usize)] {
    let Some(first) = entries.first() else {
        return entries;
    };
    let (mut lo, mut hi) = (first.0, first.0);
    for &((x, y), _) in entries.iter() {
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    let (w, h) = (hi.0 - lo.0 + 1, hi.1 - lo.1 + 1);
    if w.checked_mul(h)
        .is_none_or(|cells| cells > 4 * entries.len() as i64)
    {
        entries.sort_unstable_by_key(|e| e.0);
        return entries;
    }
    let index = |(x, y): (i64, i64)| ((y - lo.1) * w + (x - lo.0)) as usize;
    let mut start = vec![0usize; (w * h) as usize + 1];
    for e in entries.iter() {
        start[index(e.0) + 1] += 1;
    }
    for k in 1..start.len() {
        start[k] += start[k - 1];
    }
    let mut sorted = vec![((0, 0), 0); entries.len()];
    for &e in entries.iter() {
        let at = &mut start[index(e.0)];
        sorted[*at] = e;
        *at += 1;
    }
    *entries = sorted;
    entries
}

/// Unites the items of `cell` whose boxes meet: sorted by the start of their x range, each
/// compared with those whose x range still reaches it.
fn sweep_unite(grown: &[(DVec2, DVec2)], cell: &mut [usize], parent: &mut [usize]) {
    if cell.len() < 2 {
        return;
    }
    cell.sort_unstable_by(|&a, &b| grown[a].0.x.total_cmp(&grown[b].0.x).then(a.cmp(&b)));
    let mut active: Vec<usize> = Vec::new();
    for &i in cell.iter() {
        let (lo, hi) = grown[i];
        active.retain(|&j| grown[j].1.x >= lo.x);
        for &j in &active {
            if grown[j].0.y <= hi.y && lo.y <= grown[j].1.y {
                let (a, b) = (root(parent, i), root(parent, j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
        active.push(i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::testing::random;

    /// A closed path of `k` points around `c` at radii in [r/3, r], in order of angle or, with
    /// `tangled`, in random order (a path crossing itself).
    fn path(seed: &mut u64, c: [f64; 2], r: f64, k: usize, tangled: bool) -> Vec<[f64; 2]> {
        let mut angles: Vec<f64> = (0..k)
            .map(|_| random(seed) * std::f64::consts::TAU)
            .collect();
        if !tangled {
            angles.sort_by(f64::total_cmp);
        }
        angles
            .into_iter()
            .map(|a| {
                let rr = r * (1.0 + 2.0 * random(seed)) / 3.0;
                [c[0] + rr * a.cos(), c[1] + rr * a.sin()]
            })
            .collect()
    }

    /// Islands on a jittered grid: most apart, some overlapping, some touching at a point,
    /// some inside-out or crossing themselves, a few with a second path (a hole or an overlap).
    fn islands(seed: &mut u64) -> Vec<Paths> {
        let n = 2 + (random(seed) * 80.0) as usize;
        let pitch = 1.0 + random(seed) * 2.0;
        let side = (n as f64).sqrt().ceil() as usize;
        let mut items: Vec<Paths> = Vec::new();
        for i in 0..n {
            let c = [
                (i % side) as f64 * pitch + (random(seed) - 0.5) * pitch,
                (i / side) as f64 * pitch + (random(seed) - 0.5) * pitch,
            ];
            let r = pitch * (0.2 + 0.6 * random(seed));
            let k = 3 + (random(seed) * 9.0) as usize;
            let tangled = random(seed) < 0.2;
            let mut p = path(seed, c, r, k, tangled);
            if random(seed) < 0.4 {
                // Convex: the points on one circle (some nearly in line, some repeated).
                p = (0..k)
                    .map(|j| {
                        let a = (j as f64 + 0.3 * random(seed)) / k as f64 * std::f64::consts::TAU;
                        [c[0] + r * a.cos(), c[1] + r * a.sin()]
                    })
                    .collect();
                if random(seed) < 0.2 {
                    p.push(p[p.len() - 1]);
                }
            }
            if random(seed) < 0.2 {
                p.reverse();
            }
            let mut item = vec![p];
            if random(seed) < 0.3 {
                let k = 3 + (random(seed) * 5.0) as usize;
                let mut hole = path(seed, c, r * 0.3, k, false);
                hole.reverse();
                item.push(hole);
            }
            if random(seed) < 0.1 {
                // A square touching the next grid cell's corner exactly.
                let (x, y) = (c[0] + pitch * 0.5, c[1] + pitch * 0.5);
                item.push(vec![[x - 0.3, y - 0.3], [x, y - 0.3], [x, y], [x - 0.3, y]]);
                items.push(vec![vec![
                    [x, y],
                    [x + 0.3, y],
                    [x + 0.3, y + 0.3],
                    [x, y + 0.3],
                ]]);
            }
            items.push(item);
        }
        if random(seed) < 0.3 {
            items.push(Vec::new());
        }
        items
    }

    #[test]
    fn apart_equals_one_pass_on_random_islands() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut grouped = 0;
        for case in 0..400 {
            let items = islands(&mut seed);
            for rule in [FillRule::Positive, FillRule::NonZero, FillRule::EvenOdd] {
                let one = simplify_together(&items, rule);
                let apart = simplify_apart(&items, rule);
                assert_eq!(apart, one, "case {case}, {rule:?}");
            }
            grouped += usize::from(apart_groups(&paths_boxes(&items), APART_MM).len() > 1);
        }
        // The cases do exercise the grouped path.
        assert!(grouped > 300, "{grouped}");
    }

    #[test]
    fn apart_groups_are_the_components_of_meeting_boxes() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..300 {
            let n = (random(&mut seed) * 60.0) as usize;
            let boxes: Vec<(DVec2, DVec2)> = (0..n)
                .map(|_| {
                    let lo = DVec2::new(random(&mut seed) * 10.0, random(&mut seed) * 10.0);
                    let size = DVec2::new(random(&mut seed), random(&mut seed)) * 2.0;
                    (lo, lo + size)
                })
                .collect();
            let margin = random(&mut seed) * 0.2;
            let groups = apart_groups(&boxes, margin);
            let mut group_of = vec![usize::MAX; n];
            for (g, items) in groups.iter().enumerate() {
                assert!(items.windows(2).all(|w| w[0] < w[1]));
                for &i in items {
                    assert_eq!(group_of[i], usize::MAX);
                    group_of[i] = g;
                }
            }
            assert!(group_of.iter().all(|&g| g != usize::MAX));
            assert!(groups.windows(2).all(|w| w[0][0] < w[1][0]));
            // Boxes that meet share a group; every group is connected by meeting boxes.
            let meet = |a: usize, b: usize| {
                let (p, q) = (boxes[a], boxes[b]);
                p.0.x - margin <= q.1.x + margin
                    && q.0.x - margin <= p.1.x + margin
                    && p.0.y - margin <= q.1.y + margin
                    && q.0.y - margin <= p.1.y + margin
            };
            for a in 0..n {
                for b in 0..n {
                    if meet(a, b) {
                        assert_eq!(group_of[a], group_of[b]);
                    }
                }
            }
            for items in &groups {
                let mut reached = vec![items[0]];
                let mut k = 0;
                while k < reached.len() {
                    let a = reached[k];
                    for &b in items {
                        if !reached.contains(&b) && meet(a, b) {
                            reached.push(b);
                        }
                    }
                    k += 1;
                }
                assert_eq!(reached.len(), items.len());
            }
        }
    }
}
