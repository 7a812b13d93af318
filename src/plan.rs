//! Plan, stage 5b: a layer's region → its [`LayerPlan`], every move in print order
//! (SPEC.md `contour_order`, `print_order`).

use crate::contours::{Loop, contours};
use crate::droplets::loop_droplets_spaced;
use crate::geom::{DVec2, Point, Shapes, dist, line_droplet_count, round_output};
use crate::hatch::{hatch_at, order_greedy};
use crate::settings::{ContourOrder, PrintOrder, Settings};
use serde::{Deserialize, Serialize};

/// What a move does (the machine command it becomes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MoveKind {
    /// `G01`: travel, no material.
    Travel,
    /// `G26`: travel, then one droplet at the point.
    Droplet,
    /// `G25`: droplets every B on the line from the current position to the point.
    Line,
}

/// What a droplet belongs to (for the preview's colours and the statistics).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[repr(u8)]
pub enum Role {
    /// The outermost loop along a boundary (k = 0).
    Outer = 0,
    /// The other contour loops.
    Inner = 1,
    /// Hatch fill.
    Fill = 2,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    pub kind: MoveKind,
    pub role: Role,
    pub to: Point,
}

/// Droplet counts by role.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    pub outer: u64,
    pub inner: u64,
    pub fill: u64,
}

impl Counts {
    pub fn total(&self) -> u64 {
        self.outer + self.inner + self.fill
    }

    pub fn add(&mut self, o: &Counts) {
        self.outer += o.outer;
        self.inner += o.inner;
        self.fill += o.fill;
    }
}

/// Every move of one layer, in print order.
#[derive(Clone, Debug, Default)]
pub struct LayerPlan {
    /// Layer number from 0.
    pub index: usize,
    /// Z written in the code: the layer's top, (index + 1)·H.
    pub z: f64,
    pub moves: Vec<Move>,
    pub counts: Counts,
    /// Length of all moves without material (G01 and the travel part of G26), in mm.
    pub travel_mm: f64,
    /// Repairs the section needed: open chains joined across gaps, loops chained against
    /// the direction of some of their facets.
    pub open_chains: usize,
    pub reoriented_loops: usize,
}

/// Hatch angle of a layer (from 0): α_s + index·α_v.
pub fn hatch_angle(s: &Settings, index: usize) -> f64 {
    (s.hatch_angle + index as f64 * s.hatch_angle_step).rem_euclid(360.0)
}

/// How far each layer's loops start after the layer below's, in mm (arc length).
///
/// Without `stagger`: `start_jitter`. With it: `start_jitter` rounded to the nearest odd
/// multiple of B/2 (at least B/2), so the seam still moves every layer and every layer's
/// droplets lie half a droplet along the loop from the layer below's, over its gaps
/// (0.07 mm → 0.104 mm with the defaults). Adding B/2 on alternate layers to the unrounded
/// jitter instead would undo the stagger: 0.07 ± 0.104 mm is 0.034 mm from a whole B.
pub fn loop_start_step(s: &Settings) -> f64 {
    if !s.stagger {
        return s.start_jitter;
    }
    let b = s.droplet_width();
    ((s.start_jitter / b - 0.5).round().max(0.0) + 0.5) * b
}

/// Whether layer `index`'s hatch lattice is shifted by half a spacing across and half a
/// droplet along (`stagger`). With `stagger` every hatch line's droplets are set on a lattice
/// fixed to the origin: lines at (j + ½)·spacing across, droplets at k·B along (line ends
/// moved outward to lattice points, see [`crate::hatch::hatch_at`]), or (j + 0), (k + ½) when
/// shifted.
///
/// With a 90° step (the default), the next layer's lattice is this one turned by 90° about the
/// origin, and with spacing B its points are exactly the centres of this layer's lattice cells:
/// every layer already lies over the gaps of the layer below, and layer i + 2 over layer i's
/// droplets, with layer i + 1's droplets in between, so nothing is shifted (shifting layer
/// i + 2 by half a spacing, as for repeating angles, measured worse: docs/quality.md).
/// Otherwise layers whose lines run in the same direction (angle mod 180°) alternate between
/// shifted and not (a 0° step: every other layer); a step whose direction never repeats within
/// 360 layers shifts nothing.
pub fn hatch_shifted(s: &Settings, index: usize) -> bool {
    if !s.stagger {
        return false;
    }
    let quarter = (s.hatch_angle_step.rem_euclid(180.0) - 90.0).abs() < 1e-6;
    if quarter {
        return false;
    }
    let period = (1..=360usize).find(|&p| {
        let r = (p as f64 * s.hatch_angle_step).rem_euclid(180.0);
        r < 1e-6 || 180.0 - r < 1e-6
    });
    period.is_some_and(|p| (index / p) % 2 == 1)
}

/// The least distance between the fill region and the part's boundary (outer or hole), mm:
/// hatch ends may move out this far without a droplet centre leaving the part.
fn fill_margin(s: &Settings) -> f64 {
    let last = s.contours as f64 - 1.0;
    let extra = 1.0 - s.fill_overlap;
    let f = s.outer_offset.min(s.inner_offset);
    ((f + last + extra) * s.droplet_width()).max(0.0)
}

/// Plans one layer from its region.
pub fn plan_layer(region: &Shapes, index: usize, s: &Settings) -> LayerPlan {
    let b = s.droplet_width();
    let layer = contours(region, s);
    let mut plan = LayerPlan {
        index,
        z: (index + 1) as f64 * s.layer_height,
        ..LayerPlan::default()
    };
    let mut at = Point::ZERO;
    let add_contours = |plan: &mut LayerPlan, at: &mut Point| {
        let mut loops: Vec<&Loop> = layer.loops.iter().collect();
        loops.sort_by_key(|l| match s.contour_order {
            ContourOrder::InsideOut => u32::MAX - l.k,
            ContourOrder::OutsideIn => l.k,
        });
        let shift = index as f64 * loop_start_step(s);
        // Within one ring (same k), the loop whose start is nearest goes next.
        for ring in loops.chunk_by(|a, b| a.k == b.k) {
            let mut pending: Vec<(Vec<Point>, Role)> = ring
                .iter()
                .map(|l| {
                    let role = if l.k == 0 { Role::Outer } else { Role::Inner };
                    (
                        loop_droplets_spaced(&l.points, b, shift, s.close_loops, s.loop_spacing),
                        role,
                    )
                })
                .filter(|(d, _)| !d.is_empty())
                .collect();
            while !pending.is_empty() {
                let next = (0..pending.len())
                    .min_by(|&i, &j| {
                        dist(*at, pending[i].0[0]).total_cmp(&dist(*at, pending[j].0[0]))
                    })
                    .expect("non-empty");
                let (drops, role) = pending.swap_remove(next);
                for p in drops {
                    plan.travel_mm += dist(*at, p);
                    plan.moves.push(Move {
                        kind: MoveKind::Droplet,
                        role,
                        to: p,
                    });
                    *at = p;
                }
            }
        }
    };
    let add_fill = |plan: &mut LayerPlan, at: &mut Point| {
        if s.fill_density <= 0.0 {
            return;
        }
        let lines = hatch_at(
            &layer.fill_region,
            hatch_angle(s, index),
            b / s.fill_density,
            if hatch_shifted(s, index) { 0.0 } else { 0.5 },
            s.stagger.then(|| {
                let along = if hatch_shifted(s, index) { 0.5 } else { 0.0 };
                (b, along, fill_margin(s))
            }),
        );
        for l in order_greedy(lines, *at) {
            plan.travel_mm += dist(*at, l.a);
            plan.moves.push(Move {
                kind: MoveKind::Travel,
                role: Role::Fill,
                to: l.a,
            });
            plan.moves.push(Move {
                kind: MoveKind::Line,
                role: Role::Fill,
                to: l.b,
            });
            *at = l.b;
        }
    };
    match s.print_order {
        PrintOrder::ContoursFirst => {
            add_contours(&mut plan, &mut at);
            add_fill(&mut plan, &mut at);
        }
        PrintOrder::FillFirst => {
            add_fill(&mut plan, &mut at);
            add_contours(&mut plan, &mut at);
        }
    }
    // Positions as written, so counts, previews and the code agree exactly.
    for m in &mut plan.moves {
        m.to = round_output(m.to);
    }
    plan.counts = count(&plan.moves, b);
    plan
}

/// Droplet counts of a move list.
pub fn count(moves: &[Move], b: f64) -> Counts {
    let mut c = Counts::default();
    let mut at = DVec2::ZERO;
    for m in moves {
        let n = match m.kind {
            MoveKind::Travel => 0,
            MoveKind::Droplet => 1,
            MoveKind::Line => line_droplet_count(dist(at, m.to), b),
        };
        match m.role {
            Role::Outer => c.outer += n,
            Role::Inner => c.inner += n,
            Role::Fill => c.fill += n,
        }
        at = m.to;
    }
    c
}
