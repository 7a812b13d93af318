//! Plan, stage 5b: a layer's region → its [`LayerPlan`], every move in print order
//! (`contour_order`, `print_order`: docs/spec.md "Order within a layer").

use crate::base::geom::{DVec2, Point, Shapes, dist, line_droplet_count, round_output};
use crate::base::nearest::nearest_walk;
use crate::base::settings::{ContourOrder, MAX_UNITS, PrintOrder, Settings, UnitId};
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
    /// Support under overhangs (by the unit `support` names, see [`crate::support`]).
    Support = 3,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    pub kind: MoveKind,
    pub role: Role,
    pub to: Point,
    /// The discharge unit that prints it (0 … `units` − 1; docs/spec.md "Discharge units"). A
    /// travel belongs to the unit whose droplets follow it.
    pub unit: u8,
}

/// Droplet counts by role and by discharge unit (each partitions the droplets).
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    pub outer: u64,
    pub inner: u64,
    pub fill: u64,
    /// Support droplets (all printed by the support's unit).
    #[serde(default)]
    pub support: u64,
    /// Droplets of any role by the unit that prints them (its parts' and, for the support's
    /// unit, the support), indexed by unit.
    #[serde(default)]
    pub units: [u64; MAX_UNITS],
}

impl Counts {
    pub fn total(&self) -> u64 {
        self.outer + self.inner + self.fill + self.support
    }

    /// Droplets printed by unit `u`.
    pub fn unit(&self, u: UnitId) -> u64 {
        self.units[u.index()]
    }

    pub fn add(&mut self, o: &Counts) {
        self.outer += o.outer;
        self.inner += o.inner;
        self.fill += o.fill;
        self.support += o.support;
        for (mine, theirs) in self.units.iter_mut().zip(o.units) {
            *mine += theirs;
        }
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
    /// The droplet width B_u of each unit's moves but unit 0's (0 where a unit has none).
    pub unit_widths: [f64; MAX_UNITS],
    /// The regions the units but unit 0 print as parts (another material) in this layer,
    /// indexed by unit (unit 0's place empty; none in a job whose parts are all unit 0's).
    /// The analysis measures them as it measures unit 0's.
    pub unit_regions: Vec<Shapes>,
}

impl LayerPlan {
    /// The droplet width of a move's unit (`b`: unit 0's).
    pub fn width_of(&self, m: &Move, b: f64) -> f64 {
        self.widths(b)[usize::from(m.unit)]
    }

    /// Every unit's droplet width, unit 0's `b`.
    pub fn widths(&self, b: f64) -> [f64; MAX_UNITS] {
        let mut w = self.unit_widths;
        w[0] = b;
        w
    }

    /// The region unit `u` (not 0) prints as parts in this layer, if any.
    pub fn unit_region(&self, u: UnitId) -> Option<&Shapes> {
        self.unit_regions.get(u.index()).filter(|r| !r.is_empty())
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
/// unit 0's (see [`plan_unit_parts`]).
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
    count_units(moves, &[b; MAX_UNITS])
}

/// Droplet counts of a move list: each unit's droplets `widths[unit]` apart on `G25` lines.
pub fn count_units(moves: &[Move], widths: &[f64; MAX_UNITS]) -> Counts {
    let mut c = Counts::default();
    let mut at = DVec2::ZERO;
    for m in moves {
        let n = match m.kind {
            MoveKind::Travel => 0,
            MoveKind::Droplet => 1,
            MoveKind::Line => line_droplet_count(dist(at, m.to), widths[usize::from(m.unit)]),
        };
        match m.role {
            Role::Outer => c.outer += n,
            Role::Inner => c.inner += n,
            Role::Fill => c.fill += n,
            Role::Support => c.support += n,
        }
        c.units[usize::from(m.unit)] += n;
        at = m.to;
    }
    c
}

/// The settings the support's unit prints a support region with: its droplet width B_s, one
/// contour loop by the same rules as unit 0's, and hatch fill at `support_density`.
pub fn support_settings(s: &Settings) -> Settings {
    Settings {
        fill_density: s.support_density,
        contours: 1,
        ..s.for_unit(s.support_unit())
    }
}

/// The settings unit `u` prints its parts with (docs/spec.md "Discharge units"): the same
/// contour and fill rules as unit 0, with the unit's own droplet width B_u
/// (`unitN_droplet_aspect`).
pub fn part_settings(s: &Settings, u: UnitId) -> Settings {
    s.for_unit(u)
}

/// Adds the moves of the units other than 0 to a layer whose unit-0 moves are planned (from
/// the origin), in the order `unit_order` gives. `plan_unit(u, start)` plans unit `u`'s moves
/// from `start` (the end of the unit before it in the order, the origin for the first) and
/// gives them with their travel, or nothing. Unit 0's moves stay exactly as planned; only the
/// travel into them changes. Each unit's moves are counted with its width `widths[u]`.
fn add_units(
    plan: &mut LayerPlan,
    s: &Settings,
    widths: &[f64; MAX_UNITS],
    mut plan_unit: impl FnMut(UnitId, Point) -> Option<(Vec<Move>, f64)>,
) {
    let mut unit0 = Some(std::mem::take(&mut plan.moves));
    let mut at = Point::ZERO;
    for &u in s.unit_order.units() {
        if u.index() >= s.units as usize && u != UnitId::FIRST {
            continue;
        }
        if u == UnitId::FIRST {
            let own = unit0.take().unwrap_or_default();
            if let Some(first) = own.first()
                && at != Point::ZERO
            {
                // Unit 0 was planned from the origin; it now starts where the unit before ends.
                plan.travel_mm += dist(at, first.to) - dist(Point::ZERO, first.to);
            }
            at = own.last().map_or(at, |m| m.to);
            plan.moves.extend(own);
            continue;
        }
        let Some((mut moves, travel)) = plan_unit(u, at) else {
            continue;
        };
        if moves.is_empty() {
            continue;
        }
        for m in &mut moves {
            m.unit = u.0;
        }
        plan.counts.add(&count_units(&moves, widths));
        plan.unit_widths[u.index()] = widths[u.index()];
        plan.travel_mm += travel;
        at = moves.last().map_or(at, |m| m.to);
        plan.moves.extend(moves);
    }
}

/// Adds the parts of the units other than 0 to a planned layer (unit 0's, from the origin), in
/// the order `unit_order` gives: each unit's region `regions[u]` (contours and fill as unit
/// 0's, with its own B_u; roles outer/inner/fill). Unit 0's droplets stay exactly as planned;
/// only the travel between the units' moves changes. The regions are kept in the plan (unit
/// 0's place empty: its region is planned by the caller).
pub fn plan_unit_parts(plan: &mut LayerPlan, regions: Vec<Shapes>, s: &Settings) {
    let mut widths = [0.0; MAX_UNITS];
    for u in UnitId::all(s.units as usize) {
        widths[u.index()] = s.unit_width(u);
    }
    let index = plan.index;
    add_units(plan, s, &widths, |u, at| {
        let region = regions.get(u.index()).filter(|r| !r.is_empty())?;
        let p = plan_layer_from(region, index, &part_settings(s, u), at);
        Some((p.moves, p.travel_mm))
    });
    plan.unit_regions = regions;
}

/// Where the support starts in a layer whose parts are planned (docs/spec.md "Overhangs and
/// support"): the support's unit prints it at the start of the layer when it is the first
/// unit of `unit_order`, else after its own parts, where the units before it in the order
/// end (the origin when none of them has moves).
pub fn support_start(plan: &LayerPlan, s: &Settings) -> Point {
    support_at(plan, s).1
}

/// Where the support's moves go in the layer's moves, and the point they start from.
fn support_at(plan: &LayerPlan, s: &Settings) -> (usize, Point) {
    let su = s.support_unit();
    if s.unit_order.units().first() == Some(&su) {
        return (0, Point::ZERO);
    }
    let rank = s.unit_order.rank(su);
    let n = plan
        .moves
        .iter()
        .rposition(|m| s.unit_order.rank(UnitId(m.unit)) <= rank)
        .map_or(0, |k| k + 1);
    let at = n.checked_sub(1).map_or(Point::ZERO, |k| plan.moves[k].to);
    (n, at)
}

/// Adds the support's moves (planned from [`support_start`]) to a layer whose parts are
/// planned: the counts, the support unit's width and the travel follow. The parts' moves stay
/// exactly as planned; only the travel into the moves after the support changes.
pub fn add_support(plan: &mut LayerPlan, mut moves: Vec<Move>, s: &Settings) {
    if moves.is_empty() {
        return;
    }
    let su = s.support_unit();
    let bs = support_settings(s).droplet_width();
    let (n, start) = support_at(plan, s);
    let mut at = start;
    for m in &mut moves {
        m.unit = su.0;
        if m.kind != MoveKind::Line {
            plan.travel_mm += dist(at, m.to);
        }
        at = m.to;
    }
    plan.counts.add(&count_units(&moves, &[bs; MAX_UNITS]));
    plan.unit_widths[su.index()] = bs;
    if let Some(next) = plan.moves.get(n) {
        // The moves after the support were planned from where it starts; they now start where
        // it ends.
        plan.travel_mm += dist(at, next.to) - dist(start, next.to);
    }
    plan.moves.splice(n..n, moves);
}
