//! Plan, stage 5b: a layer's region → its [`LayerPlan`], every move in print order
//! (`contour_order`, `print_order`: docs/spec.md "Order within a layer").

use crate::base::geom::{DVec2, Point, Shapes, dist, line_droplet_count, round_output};
use crate::base::nearest::nearest_walk;
use crate::base::settings::{ContourOrder, PrintOrder, Settings};
use crate::slicing::contours::{Loop, contours};
use crate::slicing::droplets::loop_droplets_spaced;
use crate::slicing::fill::{FillParams, FillPattern};
pub use crate::slicing::fill::{hatch_angle, hatch_shifted};
use crate::slicing::hatch::order_greedy;
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
    /// Support under overhangs (discharge unit 1, see [`crate::support`]).
    Support = 3,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    pub kind: MoveKind,
    pub role: Role,
    pub to: Point,
    /// The discharge unit that prints it (0 or 1; docs/spec.md "Two discharge units"). A travel
    /// belongs to the unit whose droplets follow it.
    pub unit: u8,
}

/// Droplet counts by role (the roles partition the droplets), and how many of them discharge
/// unit 1 prints.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    pub outer: u64,
    pub inner: u64,
    pub fill: u64,
    /// Support droplets (all printed by unit 1).
    #[serde(default)]
    pub support: u64,
    /// Droplets of any role printed by unit 1 (its parts' and the support).
    #[serde(default)]
    pub unit1: u64,
}

impl Counts {
    pub fn total(&self) -> u64 {
        self.outer + self.inner + self.fill + self.support
    }

    /// Droplets printed by unit 0.
    pub fn unit0(&self) -> u64 {
        self.total() - self.unit1
    }

    pub fn add(&mut self, o: &Counts) {
        self.outer += o.outer;
        self.inner += o.inner;
        self.fill += o.fill;
        self.support += o.support;
        self.unit1 += o.unit1;
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
    /// The layer's overhang area, mm² (its region farther than `overhang_limit`·B from the
    /// region below, [`crate::support::overhang`]).
    pub unsupported_area: f64,
    /// Droplet width B₁ of the unit-1 moves (0 when there are none).
    pub unit1_width: f64,
    /// The region unit 1 prints as parts (a second material) in this layer; empty in a job
    /// without unit-1 parts. The analysis measures it as it measures unit 0's.
    pub unit1_region: Shapes,
}

impl LayerPlan {
    /// The droplet width of a move's unit.
    pub fn width_of(&self, m: &Move, b: f64) -> f64 {
        if m.unit == 1 { self.unit1_width } else { b }
    }

    /// The unit of the first move, if any.
    pub fn first_unit(&self) -> Option<u8> {
        self.moves.first().map(|m| m.unit)
    }

    /// The unit selected after this layer, given the one selected before it.
    pub fn unit_after(&self, before: u8) -> u8 {
        self.moves.last().map_or(before, |m| m.unit)
    }
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

/// Plans one layer from its region (unit 0, starting at the origin).
pub fn plan_layer(region: &Shapes, index: usize, s: &Settings) -> LayerPlan {
    plan_layer_from(region, index, s, Point::ZERO)
}

/// Plans one layer's region with the droplet width of `s`, starting at `start`; every move is
/// unit 0's (see [`plan_unit1_layer`]).
pub fn plan_layer_from(region: &Shapes, index: usize, s: &Settings, start: Point) -> LayerPlan {
    let b = s.droplet_width();
    let layer = contours(region, s);
    let mut plan = LayerPlan {
        index,
        z: (index + 1) as f64 * s.layer_height,
        ..LayerPlan::default()
    };
    let mut at = start;
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
            let starts: Vec<Point> = pending.iter().map(|(d, _)| d[0]).collect();
            let order = nearest_walk(&starts, *at, |i| pending[i].0[pending[i].0.len() - 1]);
            for i in order {
                let (drops, role) = (std::mem::take(&mut pending[i].0), pending[i].1);
                for p in drops {
                    plan.travel_mm += dist(*at, p);
                    plan.moves.push(Move {
                        kind: MoveKind::Droplet,
                        role,
                        to: p,
                        unit: 0,
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
        let lines = FillPattern::Lines
            .new_from_type()
            .fill(&layer.fill_region, &FillParams::from_settings(s, index));
        for l in order_greedy(lines, *at) {
            plan.travel_mm += dist(*at, l.a);
            plan.moves.push(Move {
                kind: MoveKind::Travel,
                role: Role::Fill,
                to: l.a,
                unit: 0,
            });
            plan.moves.push(Move {
                kind: MoveKind::Line,
                role: Role::Fill,
                to: l.b,
                unit: 0,
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

/// Droplet counts of a move list of one droplet width.
pub fn count(moves: &[Move], b: f64) -> Counts {
    count_units(moves, b, b)
}

/// Droplet counts of a move list: unit 0's droplets `b` apart on `G25` lines, unit 1's `b1`.
pub fn count_units(moves: &[Move], b: f64, b1: f64) -> Counts {
    let mut c = Counts::default();
    let mut at = DVec2::ZERO;
    for m in moves {
        let w = if m.unit == 1 { b1 } else { b };
        let n = match m.kind {
            MoveKind::Travel => 0,
            MoveKind::Droplet => 1,
            MoveKind::Line => line_droplet_count(dist(at, m.to), w),
        };
        match m.role {
            Role::Outer => c.outer += n,
            Role::Inner => c.inner += n,
            Role::Fill => c.fill += n,
            Role::Support => c.support += n,
        }
        if m.unit == 1 {
            c.unit1 += n;
        }
        at = m.to;
    }
    c
}

/// The settings unit 1 prints a support region with: droplet width B₁
/// (`unit1_droplet_aspect`), one contour loop by the same rules as unit 0's, and hatch fill
/// at `support_density`.
pub fn support_settings(s: &Settings) -> Settings {
    Settings {
        fill_density: s.support_density,
        contours: 1,
        ..s.for_unit(s.support_unit())
    }
}

/// The settings unit 1 prints its parts with (docs/spec.md "Two discharge units"): the same
/// contour and fill rules as unit 0, with unit 1's droplet width B₁ (`unit1_droplet_aspect`).
pub fn unit1_part_settings(s: &Settings) -> Settings {
    s.for_unit(crate::base::settings::UnitId(1))
}

/// Adds unit 1's moves to a planned layer, in the order `unit_order` gives: first the region
/// of its parts (`parts`, contours and fill as unit 0's with B₁, roles outer/inner/fill),
/// then `support` (one loop and hatch at `support_density`, [`support_settings`], as
/// `support_role`). Unit 0's droplets stay exactly as planned; only the travel between the
/// two units' moves changes.
pub fn plan_unit1_layer(
    plan: &mut LayerPlan,
    parts: &Shapes,
    support: &Shapes,
    support_role: Role,
    s: &Settings,
) {
    if parts.is_empty() && support.is_empty() {
        return;
    }
    let b1 = s.unit_width(crate::base::settings::UnitId(1));
    let unit0_first = s.unit_order.rank(crate::base::settings::UnitId::FIRST)
        < s.unit_order.rank(crate::base::settings::UnitId(1));
    let start = if unit0_first {
        plan.moves.last().map_or(Point::ZERO, |m| m.to)
    } else {
        Point::ZERO
    };
    let mut moves: Vec<Move> = Vec::new();
    let mut travel = 0.0;
    let mut at = start;
    for (region, role, s1) in [
        (parts, None, unit1_part_settings(s)),
        (support, Some(support_role), support_settings(s)),
    ] {
        if region.is_empty() {
            continue;
        }
        let p1 = plan_layer_from(region, plan.index, &s1, at);
        travel += p1.travel_mm;
        for mut m in p1.moves {
            m.unit = 1;
            if let Some(r) = role {
                m.role = r;
            }
            moves.push(m);
        }
        at = moves.last().map_or(at, |m| m.to);
    }
    if moves.is_empty() {
        return;
    }
    let c1 = count_units(&moves, b1, b1);
    plan.counts.add(&c1);
    plan.unit1_width = b1;
    plan.travel_mm += travel;
    if unit0_first {
        plan.moves.extend(moves);
    } else {
        // Unit 0 was planned from the origin; it now starts where unit 1 ends.
        let end = moves.last().map_or(Point::ZERO, |m| m.to);
        if let Some(first) = plan.moves.first() {
            plan.travel_mm += dist(end, first.to) - dist(Point::ZERO, first.to);
        }
        moves.append(&mut plan.moves);
        plan.moves = moves;
    }
}

/// Where unit 1 starts in a layer whose unit-0 moves are planned: after them, or at the origin
/// with `unit_order = unit1_first`.
pub fn unit1_start(plan: &LayerPlan, s: &Settings) -> Point {
    if s.unit_order.rank(crate::base::settings::UnitId::FIRST)
        < s.unit_order.rank(crate::base::settings::UnitId(1))
    {
        plan.moves.last().map_or(Point::ZERO, |m| m.to)
    } else {
        Point::ZERO
    }
}

/// Adds unit-1 moves (planned from [`unit1_start`]) to a layer planned for unit 0, in the
/// order `unit_order` gives: the counts, B₁ and the travel follow. Unit 0's moves stay
/// exactly as planned; only the travel between the two units' moves changes.
pub fn add_unit1(plan: &mut LayerPlan, mut moves: Vec<Move>, s: &Settings) {
    if moves.is_empty() {
        return;
    }
    let b1 = support_settings(s).droplet_width();
    let unit0_first = s.unit_order.rank(crate::base::settings::UnitId::FIRST)
        < s.unit_order.rank(crate::base::settings::UnitId(1));
    let mut at = unit1_start(plan, s);
    for m in &mut moves {
        m.unit = 1;
        if m.kind != MoveKind::Line {
            plan.travel_mm += dist(at, m.to);
        }
        at = m.to;
    }
    let c1 = count_units(&moves, b1, b1);
    plan.counts.add(&c1);
    plan.unit1_width = b1;
    if unit0_first {
        plan.moves.extend(moves);
    } else {
        // Unit 0 was planned from the origin; it now starts where unit 1 ends.
        if let Some(first) = plan.moves.first() {
            plan.travel_mm += dist(at, first.to) - dist(Point::ZERO, first.to);
        }
        moves.append(&mut plan.moves);
        plan.moves = moves;
    }
}
