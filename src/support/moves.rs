//! The support unit's moves for a support region (docs/spec.md "Overhangs and support"): the region's hatch
//! segments on the support unit's lattice, split where the part is within `support_gap_xy`·B, then the
//! single droplets of the droplet-level pass, nearest first.

use crate::base::geom::{
    DVec2, Point, Shapes, dist, line_droplet_count, round_output, sin_cos_deg,
};
use crate::base::nearest::nearest_walk;
use crate::base::settings::Settings;
use crate::slicing::hatch::HatchLine;
use crate::slicing::plan::{Move, MoveKind, Role, hatch_angle, support_settings};

/// The support unit's moves for a support region (docs/spec.md "Overhangs and support": hatch only, lines
/// B₁ / `support_density` apart), from `start`: the region's hatch segments `lines` (lines
/// B₁ / `support_density` apart at the layer's hatch angle, every line's droplets on a
/// lattice of pitch B₁ along it, [`crate::support::support_layers`]), without the droplets
/// closer than `support_gap_xy`·B to the part's region `part` (a line is split there); then
/// single droplets at `extra` (the droplet-level pass, [`crate::support::droplets`]), nearest
/// first. No offsets. Positions are rounded as written.
pub fn support_moves(
    lines: &[HatchLine],
    part: &Shapes,
    extra: &[Point],
    index: usize,
    s: &Settings,
    start: Point,
) -> Vec<Move> {
    let s1 = support_settings(s);
    let b1 = s1.droplet_width();
    let su = s.support_unit().0;
    let mut moves = Vec::new();
    let mut at = start;
    if s1.fill_density > 0.0 && !lines.is_empty() {
        let edges = super::droplets::edges_of(part);
        let (angle, spacing) = (hatch_angle(s, index), b1 / s1.fill_density);
        let gaps = super::droplets::LineGaps::new(
            &edges,
            s.support_gap_xy * s.droplet_width(),
            angle,
            spacing,
        );
        let mut runs = Vec::with_capacity(lines.len());
        let mut near = Vec::new();
        // Droplet j of a line lies at t = j·B₁ along it (as `line_droplets` sets them); the
        // first j at or after t, the last at or before t (exact in the products).
        let first_at = |t: f64| {
            let mut j = (t / b1).ceil().max(0.0);
            while j > 0.0 && (j - 1.0) * b1 >= t {
                j -= 1.0;
            }
            while j * b1 < t {
                j += 1.0;
            }
            j
        };
        let last_at = |t: f64| {
            let mut j = (t / b1).floor();
            while (j + 1.0) * b1 <= t {
                j += 1.0;
            }
            while j >= 0.0 && j * b1 > t {
                j -= 1.0;
            }
            j
        };
        for &l in lines {
            // Where along the line the part is within the gap (sorted intervals): the
            // droplets there are left out, the runs between them kept.
            gaps.intervals(l.a, l.b, &mut near);
            let len = dist(l.a, l.b);
            let count = line_droplet_count(len, b1) as f64;
            let at_j = |j: f64| {
                let t = if len > 0.0 { j * b1 / len } else { 0.0 };
                DVec2::new(
                    l.a[0] + t * (l.b[0] - l.a[0]),
                    l.a[1] + t * (l.b[1] - l.a[1]),
                )
            };
            let mut next = 0.0;
            for &(t0, t1) in &near {
                let (d0, d1) = (first_at(t0), last_at(t1).min(count - 1.0));
                if d0 > d1 {
                    continue;
                }
                if d0 > next {
                    runs.push(HatchLine {
                        a: at_j(next),
                        b: at_j(d0 - 1.0),
                    });
                }
                next = next.max(d1 + 1.0);
            }
            if next < count {
                runs.push(HatchLine {
                    a: at_j(next),
                    b: at_j(count - 1.0),
                });
            }
        }
        // The greedy nearest-end order, found through the lattice's rows the runs lie on.
        let (sin, cos) = sin_cos_deg(angle);
        for l in super::order::order_by_rows(runs, at, sin, cos, spacing) {
            if dist(l.a, l.b) < 0.5 * b1 {
                moves.push(Move {
                    kind: MoveKind::Droplet,
                    role: Role::Support,
                    to: round_output(l.a),
                    unit: su,
                });
            } else {
                moves.push(Move {
                    kind: MoveKind::Travel,
                    role: Role::Support,
                    to: round_output(l.a),
                    unit: su,
                });
                moves.push(Move {
                    kind: MoveKind::Line,
                    role: Role::Support,
                    to: round_output(l.b),
                    unit: su,
                });
            }
            at = l.b;
        }
    }
    for i in nearest_walk(extra, at, |i| extra[i]) {
        let p = extra[i];
        moves.push(Move {
            kind: MoveKind::Droplet,
            role: Role::Support,
            to: round_output(p),
            unit: su,
        });
    }
    moves
}
