//! The vertical cut's voids (src/analysis/cut.rs) against an independent computation: points
//! sampled along the line at each band's height, tested against every spheroid in 3D and the
//! region by a winding number of their own.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use common::Rng;
use dropslice::Settings;
use dropslice::analysis::{
    CUT_BANDS, CutLine, Near, footprint_diameter, slab_section_voids, spheroid_half_height,
};
use dropslice::base::geom::{DVec2, Shape, Shapes};

/// Winding number of `p` around the closed polygon `c` (non-zero = inside).
fn winding(c: &[DVec2], p: DVec2) -> i32 {
    let mut w = 0;
    for i in 0..c.len() {
        let (a, b) = (c[i], c[(i + 1) % c.len()]);
        let cross = (b - a).perp_dot(p - a);
        if a.y <= p.y && b.y > p.y && cross > 0.0 {
            w += 1;
        } else if a.y > p.y && b.y <= p.y && cross < 0.0 {
            w -= 1;
        }
    }
    w
}

fn inside(region: &Shapes, p: DVec2) -> bool {
    region
        .iter()
        .map(|s| winding(&s.outer, p) + s.holes.iter().map(|h| winding(h, p)).sum::<i32>())
        .sum::<i32>()
        != 0
}

/// A star-shaped polygon with a square hole.
fn region(rng: &mut Rng) -> Shapes {
    let n = 9;
    let outer: Vec<DVec2> = (0..n)
        .map(|i| {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 2.0 + rng.unit() * 1.5;
            DVec2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    let hole = vec![
        DVec2::new(-0.4, -0.4),
        DVec2::new(-0.4, 0.4),
        DVec2::new(0.4, 0.4),
        DVec2::new(0.4, -0.4),
    ];
    vec![Shape::new(outer, vec![hole])]
}

/// Droplets on a jittered lattice of pitch `pitch`, offset by `shift`.
fn lattice(rng: &mut Rng, pitch: f64, shift: f64) -> Vec<DVec2> {
    let mut out = Vec::new();
    let k = (4.0 / pitch) as i64;
    for i in -k..=k {
        for j in -k..=k {
            if rng.unit() < 0.1 {
                continue; // a missing droplet
            }
            let jitter = DVec2::new(rng.unit() - 0.5, rng.unit() - 0.5) * pitch * 0.2;
            out.push(DVec2::new(i as f64, j as f64) * pitch + shift + jitter);
        }
    }
    out
}

#[test]
fn cut_voids_match_points_sampled_in_3d() {
    let mut rng = Rng::new(14);
    for case in 0..12 {
        let s = Settings {
            footprint: if case % 2 == 0 {
                dropslice::base::settings::Footprint::Disc
            } else {
                dropslice::base::settings::Footprint::Spread
            },
            ..Settings::default()
        };
        let b = s.droplet_width();
        let h = s.layer_height;
        let r = footprint_diameter(&s) / 2.0;
        let c = spheroid_half_height(&s);
        let region = region(&mut rng);
        let pitch = b * (1.0 + 0.4 * rng.unit());
        let layers = [
            lattice(&mut rng, pitch, 0.0),
            lattice(&mut rng, pitch, pitch / 2.0),
            lattice(&mut rng, pitch, 0.0),
        ];
        let a = DVec2::new(-4.0 + rng.unit(), -3.0 + 6.0 * rng.unit());
        let e = DVec2::new(4.0 - rng.unit(), -3.0 + 6.0 * rng.unit());
        let line = CutLine::new(a, e).unwrap();
        let near: Vec<Vec<Near>> = layers
            .iter()
            .map(|l| {
                line.near(l.iter().copied(), r)
                    .into_iter()
                    .map(|(_, t, d)| Near { t, d })
                    .collect()
            })
            .collect();
        let spans = line.region_spans(&region);
        let voids = slab_section_voids(&spans, &near[0], &near[1], &near[2], &s);
        assert!(
            !voids.is_empty(),
            "case {case}: a loose lattice leaves voids"
        );
        // sample each band's height along the line
        let steps = 8_000;
        let step = line.length() / steps as f64;
        let dir = (e - a) / line.length();
        for band in 0..CUT_BANDS {
            let z = (band as f64 + 0.5) / CUT_BANDS as f64 * h;
            let (mut sampled, mut void_len, mut count) = (0.0, 0.0, 0);
            for v in voids.iter().filter(|v| v.band == band) {
                assert!(v.t1 > v.t0 && v.t0 >= 0.0 && v.t1 <= line.length());
                void_len += v.t1 - v.t0;
                count += 1;
            }
            for k in 0..steps {
                let t = (k as f64 + 0.5) / steps as f64 * line.length();
                let p = a + dir * t;
                if !inside(&region, p) {
                    continue;
                }
                let filled = layers
                    .iter()
                    .zip([-0.5 * h, 0.5 * h, 1.5 * h])
                    .any(|(l, z0)| {
                        l.iter().any(|q| {
                            (p - *q).length_squared() / (r * r) + (z - z0) * (z - z0) / (c * c)
                                <= 1.0
                        })
                    });
                let in_void = voids
                    .iter()
                    .any(|v| v.band == band && v.t0 <= t && t <= v.t1);
                if !filled {
                    sampled += step;
                }
                // away from an interval's ends, the two agree point by point
                let near_end = voids.iter().any(|v| {
                    v.band == band && ((v.t0 - t).abs() < step || (v.t1 - t).abs() < step)
                });
                if !near_end {
                    assert_eq!(!filled, in_void, "case {case} band {band} t {t}");
                }
            }
            // each interval's ends are sampled to within a step
            let tol = 2.0 * step * (count + 1) as f64;
            assert!(
                (sampled - void_len).abs() < tol,
                "case {case} band {band}: void {void_len} mm, sampled {sampled} mm"
            );
        }
    }
}

#[test]
fn a_dense_lattice_fills_the_middle_of_the_slab() {
    // Spread footprints (radius 0.564 B) on a square lattice of pitch 0.7 B cover the plane
    // (the farthest point from a centre is 0.495 B away) within ±H/4 of the mid-height, where
    // the spheroid's radius is above 0.53 B: the middle bands are filled wherever the line
    // goes; at the bottom band's middle (5H/12 below) the radius is 0.47 B: gaps.
    let s = Settings {
        footprint: dropslice::base::settings::Footprint::Spread,
        ..Settings::default()
    };
    let b = s.droplet_width();
    let mut grid = Vec::new();
    for i in -30..=30 {
        for j in -30..=30 {
            grid.push(DVec2::new(i as f64, j as f64) * 0.7 * b);
        }
    }
    let line = CutLine::new(DVec2::new(-5.0, 0.37), DVec2::new(5.0, -0.81)).unwrap();
    let near: Vec<Near> = line
        .near(grid.iter().copied(), footprint_diameter(&s) / 2.0)
        .into_iter()
        .map(|(_, t, d)| Near { t, d })
        .collect();
    let square: Shapes = vec![Shape::new(
        vec![
            DVec2::new(-4.0, -4.0),
            DVec2::new(4.0, -4.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(-4.0, 4.0),
        ],
        vec![],
    )];
    let spans = line.region_spans(&square);
    assert_eq!(spans.len(), 1);
    let voids = slab_section_voids(&spans, &[], &near, &[], &s);
    let middle = [1, 2, 3, 4];
    assert!(voids.iter().all(|v| !middle.contains(&v.band)), "{voids:?}");
    // without layers around it, the slab's bottom and top are left partly open
    assert!(voids.iter().any(|v| v.band == 0));
    assert!(voids.iter().any(|v| v.band == CUT_BANDS - 1));
}
