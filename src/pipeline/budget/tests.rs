//! Tests of the droplet estimate.
use super::*;
use crate::base::settings::{Support, UnitId};

/// No parts of units other than 0.
const NONE: PartsByUnit = [None; MAX_UNITS];

fn setting(r: Result<(), Error>) -> String {
    match r {
        Err(Error::Setting { name, .. }) => name,
        other => panic!("{other:?}"),
    }
}

/// A closed box from `lo` to `hi`, facets facing out.
fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> Mesh {
    let vertices = (0..8)
        .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] }))
        .collect();
    let quads = [
        [0, 2, 3, 1], // z = lo, facing down
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let facets = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    Mesh { vertices, facets }
}

fn zs(s: &Settings) -> Vec<f64> {
    crate::slicing::slice::layer_heights(20.0, s.layer_height, s.slice_plane)
}

#[test]
fn the_facet_sums_of_a_box() {
    let s = Settings::default();
    // On the plate: its bottom reaches no plane, no support.
    let o = Overhangs::of(&cuboid([0.0; 3], [20.0; 3]), &zs(&s));
    assert_eq!((o.area, o.perimeter, o.pieces), (0.0, 0.0, 0.0));
    // Lifted to z = 10: one piece of 400 mm² with 80 mm of edge under 50 layers.
    let o = Overhangs::of(&cuboid([0.0, 0.0, 10.0], [20.0; 3]), &zs(&s));
    let n = zs(&s).iter().filter(|&&z| z <= 10.0).count() as f64;
    assert_eq!(n, 50.0);
    assert!((o.area - 400.0 * n).abs() < 1e-6, "{o:?}");
    assert!((o.perimeter - 80.0 * n).abs() < 1e-6, "{o:?}");
    assert_eq!(o.pieces, n);
    // The bound holds the hatch of that column: 400 mm² × 50 layers of B₁ = B.
    let b1 = s.unit_width(crate::base::settings::UnitId(1));
    assert!(o.droplets(&s) >= 400.0 * n / (b1 * b1));
}

/// [`Overhangs::of`] as it was written first, the edges in a map: the figures the
/// counting sort must give.
fn of_by_map(mesh: &Mesh, zs: &[f64]) -> Overhangs {
    let count = |top: f64| zs.partition_point(|&z| z <= top) as u32;
    let mut o = Overhangs::default();
    let mut down: Vec<([u32; 3], u32)> = Vec::new();
    for f in &mesh.facets {
        let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
        let twice = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        let n = count(a[2].max(b[2]).max(c[2]));
        if twice < 0.0 && n > 0 {
            o.area += -0.5 * twice * n as f64;
            down.push((*f, n));
        }
    }
    let mut edges = std::collections::BTreeMap::<(u32, u32), ([(u32, bool); 2], u32)>::new();
    for (k, (f, _)) in down.iter().enumerate() {
        for j in 0..3 {
            let (p, q) = (f[j], f[(j + 1) % 3]);
            let e = edges
                .entry((p.min(q), p.max(q)))
                .or_insert(([(0, false); 2], 0));
            if e.1 < 2 {
                e.0[e.1 as usize] = (k as u32, p < q);
            }
            e.1 += 1;
        }
    }
    let top = down.iter().map(|d| d.1).max().unwrap_or(0) as usize;
    let mut joins: Vec<Vec<(u32, u32)>> = vec![Vec::new(); top + 1];
    let mut fresh = vec![0u32; top + 1];
    for &(_, n) in &down {
        fresh[n as usize] += 1;
    }
    for (&(p, q), &(users, used)) in &edges {
        let (a, b) = (mesh.vertices[p as usize], mesh.vertices[q as usize]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = |u: (u32, bool)| down[u.0 as usize].1;
        if used == 2 && users[0].1 != users[1].1 {
            o.perimeter += len * n(users[0]).abs_diff(n(users[1])) as f64;
        } else {
            let stored: u32 = users[..used.min(2) as usize].iter().map(|&u| n(u)).sum();
            o.perimeter += len * (stored as f64 + used.saturating_sub(2) as f64 * top as f64);
        }
        if used >= 2 {
            let level = n(users[0]).min(n(users[1]));
            joins[level as usize].push((users[0].0, users[1].0));
        }
    }
    // Pieces: the facets joined through their shared edges, from the highest N down.
    let mut parent: Vec<usize> = (0..down.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            i = parent[i];
        }
        i
    }
    let mut pieces = 0i64;
    for level in (1..=top).rev() {
        pieces += fresh[level] as i64;
        for &(a, b) in &joins[level] {
            let (ra, rb) = (root(&mut parent, a as usize), root(&mut parent, b as usize));
            if ra != rb {
                parent[ra] = rb;
                pieces -= 1;
            }
        }
        o.pieces += pieces as f64;
    }
    o
}

/// A closed sphere of `rings` × `rings` quads around `c`, facets facing out.
fn sphere(c: [f64; 3], r: f64, rings: u32) -> Mesh {
    let mut vertices = vec![[c[0], c[1], c[2] - r], [c[0], c[1], c[2] + r]];
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..rings {
            let a = std::f64::consts::TAU * j as f64 / rings as f64;
            let (st, ct) = t.sin_cos();
            vertices.push([
                c[0] + r * st * a.cos(),
                c[1] + r * st * a.sin(),
                c[2] - r * ct,
            ]);
        }
    }
    let at = |i: u32, j: u32| 2 + (i - 1) * rings + j % rings;
    let mut facets = Vec::new();
    for j in 0..rings {
        facets.push([0, at(1, j + 1), at(1, j)]);
        facets.push([1, at(rings - 1, j), at(rings - 1, j + 1)]);
        for i in 1..rings - 1 {
            facets.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            facets.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    Mesh { vertices, facets }
}

#[test]
fn the_edges_grouped_by_vertex_give_the_figures_of_a_map() {
    let s = Settings::default();
    let zs = zs(&s);
    let same = |m: &Mesh| {
        let (o, r) = (Overhangs::of(m, &zs), of_by_map(m, &zs));
        assert_eq!((o.area, o.pieces), (r.area, r.pieces), "{o:?} {r:?}");
        assert!(
            (o.perimeter - r.perimeter).abs() <= 1e-9 * r.perimeter,
            "{o:?} {r:?}"
        );
        o
    };
    // Closed and oriented: a lifted sphere is one piece per layer under its lower half.
    let ball = sphere([10.0, 10.0, 10.0], 6.0, 24);
    let o = same(&ball);
    assert!(o.area > 0.0 && o.perimeter > 0.0 && o.pieces > 0.0, "{o:?}");
    // A facet turned (an edge used twice in one direction), two balls sharing vertices
    // (edges of more than two facets) and a lifted box beside a ball.
    let mut turned = ball.clone();
    turned.facets[3].swap(1, 2);
    same(&turned);
    let mut twice = ball.clone();
    let shift = twice.facets.clone();
    twice
        .facets
        .extend(shift.iter().map(|f| [f[0], f[2], f[1]]));
    twice.facets.extend(shift);
    same(&twice);
    let mut both = cuboid([0.0, 0.0, 12.0], [5.0, 5.0, 15.0]);
    let base = both.vertices.len() as u32;
    both.vertices.extend(&ball.vertices);
    both.facets
        .extend(ball.facets.iter().map(|f| f.map(|i| i + base)));
    let o = same(&both);
    assert!(o.pieces > same(&ball).pieces);
}

#[test]
fn a_vertex_shared_by_many_facets_is_grouped_as_a_map_does() {
    // A lifted cone of 30,000 facets facing down from one apex (and a cap): one vertex with
    // 30,000 edges (sorted per vertex; an insertion sort would take quadratic time there).
    let k = 30_000u32;
    let mut vertices = vec![[10.0, 10.0, 5.0], [10.0, 10.0, 12.0]];
    for j in 0..k {
        let a = std::f64::consts::TAU * j as f64 / k as f64;
        vertices.push([10.0 + 8.0 * a.cos(), 10.0 + 8.0 * a.sin(), 12.0]);
    }
    let rim = |j: u32| 2 + j % k;
    let mut facets = Vec::new();
    for j in 0..k {
        facets.push([0, rim(j + 1), rim(j)]);
        facets.push([1, rim(j), rim(j + 1)]);
    }
    let cone = Mesh { vertices, facets };
    let zs = zs(&Settings::default());
    let (o, r) = (Overhangs::of(&cone, &zs), of_by_map(&cone, &zs));
    assert_eq!((o.area, o.pieces), (r.area, r.pieces), "{o:?} {r:?}");
    assert!(
        (o.perimeter - r.perimeter).abs() <= 1e-9 * r.perimeter,
        "{o:?} {r:?}"
    );
    assert!(o.area > 0.0 && o.pieces > 0.0, "{o:?}");
}

#[test]
fn each_unit_and_the_support_count_with_their_own_droplets() {
    let size = [20.0, 20.0, 20.0];
    let s = Settings::default();
    let none = Overhangs::default();
    // The 20 mm cube by unit 0, with and without support: well within every limit.
    let cube_check =
        |s: &Settings| Estimate::new(8000.0, &NONE, false, &size, &[], &none, s).check(s);
    let with_support = |s: &Settings| Settings {
        support: Support::Unit(UnitId(1)),
        ..s.clone()
    };
    let e = Estimate::new(8000.0, &NONE, false, &size, &[], &none, &s);
    assert!(e.check(&s).is_ok());
    let on = with_support(&s);
    assert!(cube_check(&on).is_ok());
    // A tiny B₁ does not matter without unit 1, and is refused for the support with it.
    let tiny = {
        let mut t = s.clone();
        t.unit_mut(UnitId(1)).droplet_aspect = 1e-3;
        t
    };
    assert!(e.check(&tiny).is_ok());
    let tiny_on = with_support(&tiny);
    // With no overhang, the cube needs no support: a B₁ = 0.01 mm whose hatch under the
    // whole footprint would be 4·10⁸ droplets is fine.
    let fine_on = {
        let mut t = on.clone();
        t.unit_mut(UnitId(1)).droplet_aspect = 0.05;
        t
    };
    let flat = Overhangs::of(&cuboid([0.0; 3], size), &zs(&s));
    let e = Estimate::new(8000.0, &NONE, false, &size, &[], &flat, &fine_on);
    assert!(e.check(&fine_on).is_ok());
    // An open mesh keeps the footprint bound.
    let e = Estimate::new(8000.0, &NONE, true, &size, &[], &flat, &fine_on);
    assert_eq!(setting(e.check(&fine_on)), "unit1_droplet_aspect");
    // A box lifted 10 mm off the plate: support under its bottom, refused with a tiny B₁.
    let lifted = Overhangs::of(&cuboid([0.0, 0.0, 10.0], [20.0, 20.0, 20.0]), &zs(&s));
    let e = Estimate::new(4000.0, &NONE, false, &size, &[], &lifted, &tiny_on);
    assert_eq!(setting(e.check(&tiny_on)), "support");
    let e = Estimate::new(4000.0, &NONE, false, &size, &[], &lifted, &on);
    assert!(e.check(&on).is_ok());
    // A unit-1 part of the whole cube: its droplets are of B₁.
    let cube = UnitParts {
        signed_volume: 8000.0,
        min: [0.0; 3],
        max: size,
    };
    let mut parts = NONE;
    parts[1] = Some(cube);
    let e = Estimate::new(8000.0, &parts, false, &size, &[], &none, &tiny);
    assert_eq!(e.unit_volumes[0], 0.0);
    assert_eq!(setting(e.check(&tiny)), "unit1_droplet_aspect");
    // The same cube as a part of unit 2 (of three): its droplets are of B₂, and a tiny B₁
    // that nothing prints is never checked.
    let mut three = Settings {
        units: 3,
        ..tiny.clone()
    };
    three.unit_mut(UnitId(2)).droplet_aspect = three.unit(UnitId(1)).droplet_aspect;
    three.unit_mut(UnitId(1)).droplet_aspect = 1.0;
    let mut parts = NONE;
    parts[2] = Some(cube);
    let e = Estimate::new(8000.0, &parts, false, &size, &[], &none, &three);
    assert_eq!(setting(e.check(&three)), "unit2_droplet_aspect");
    three.unit_mut(UnitId(1)).droplet_aspect = tiny.unit(UnitId(1)).droplet_aspect;
    three.unit_mut(UnitId(2)).droplet_aspect = 1.0;
    assert!(e.check(&three).is_ok());
    // Support from unit 3 with a tiny B₃ under a lifted box: refused naming unit 3.
    let mut four = Settings {
        units: 4,
        support: Support::Unit(UnitId(3)),
        ..Settings::default()
    };
    four.unit_mut(UnitId(3)).droplet_aspect = tiny.unit(UnitId(1)).droplet_aspect;
    let e = Estimate::new(4000.0, &NONE, false, &size, &[], &lifted, &four);
    assert_eq!(setting(e.check(&four)), "support");
    four.unit_mut(UnitId(3)).droplet_aspect = 1.0;
    let e = Estimate::new(4000.0, &NONE, false, &size, &[], &lifted, &four);
    assert!(e.check(&four).is_ok());
    assert!(e.check(&s).is_ok());
    // A small unit-0 B: fine alone, too many for the support's pass.
    let small = {
        let mut t = s.clone();
        t.unit_mut(UnitId::FIRST).droplet_aspect = 0.09;
        t
    };
    assert!(cube_check(&small).is_ok());
    assert_eq!(setting(cube_check(&with_support(&small))), "droplet_aspect");
}

#[test]
fn a_b1_whose_square_underflows_counts_nothing_where_unit_1_prints_nothing() {
    // B₁ = 2·10⁻³⁰¹ mm: B₁² is 0, and 0 droplets / 0 was NaN, which refused every job ("0.0e0
    // droplets … NaN"). The range refuses such a B₁ now; the count holds without it too.
    let size = [20.0, 20.0, 20.0];
    let s = {
        let mut t = Settings::default();
        t.unit_mut(UnitId(1)).droplet_aspect = 1e-300;
        t
    };
    let e = Estimate::new(8000.0, &NONE, false, &size, &[], &Overhangs::default(), &s);
    assert!(e.check(&s).is_ok(), "{:?}", e.check(&s));
    assert!(s.validate().is_err());
}
