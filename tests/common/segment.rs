//! The nearest point of a segment, computed here rather than by the library, for the tests'
//! own geometry (`common::deep_inside`, the loop paths of `seams.rs`).

/// The point of segment a–c nearest to p, and where it lies along the segment (0 … 1).
pub fn project(p: [f64; 2], a: [f64; 2], c: [f64; 2]) -> (f64, [f64; 2]) {
    let (dx, dy) = (c[0] - a[0], c[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, [a[0] + t * dx, a[1] + t * dy])
}
