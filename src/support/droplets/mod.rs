//! The support's droplet-level pass (docs/spec.md "Overhangs and support"; docs/support.md):
//! after every layer is planned with its support region, find the droplets the layer below does
//! not support by the overhang rule and add single droplets of the support's unit under them,
//! top-down, so that the rule holds for every droplet of the code (the added droplets need
//! support too).
//!
//! The region form ([`crate::support`]) leaves a few droplets unsupported: where a support
//! region is a sliver, or where a part droplet lies beyond the edge of the part below by less
//! than the limit but the droplets below sit B/2 inside that edge. The pass works on droplet
//! centres only, so it is cheap: each layer's droplets are listed from its moves once, the
//! support's hatch lines as runs of their lattice (looked up by row and column), the rest in a hash grid
//! ([`index`]). It runs in resumable steps ([`complete_in_steps`], the page's short calls):
//! a layer an item.

use crate::base::geom::{
    DVec2, Point, Shapes, dist, line_droplets, line_droplets_in, round_output,
};
use crate::base::parallel::par_map;
use crate::base::settings::{MAX_UNITS, Settings, UnitId};
use crate::base::steps::{Budget, UNLIMITED, now};
use crate::slicing::plan::{Move, MoveKind};
use gaps::inside;
use grid::{Added, Below};
use index::{Frame, Frames, Index, Listed};

/// A droplet centre and its width (its unit's B_u).
pub type Droplet = (Point, f64);

/// An axis-aligned box: its least and greatest corners.
pub type Bounds = (Point, Point);

/// `f(i)`: layer i's planned moves, each list from the origin (the part's, both units, then
/// the support (of the unit `support` names)); their droplets are [`droplets_of`] each list.
pub type LayerMoves<'a> = &'a (dyn Fn(usize) -> [&'a [Move]; 2] + Sync);

/// Centres kept this much inside the rule's distance, so rounding the written positions
/// cannot break it (positions are rounded to 0.05 µm).
pub(crate) const MARGIN_MM: f64 = 1e-3;

mod cover;
mod gaps;
mod grid;
mod index;

pub use gaps::{Clearance, LineGaps, edges_of};

/// Every droplet a layer's moves set, with its width (its unit's, `widths[unit]`), in the
/// order they are set; with `within = Some((lo, hi))` only those in that box (a line whose
/// box misses it is not walked).
pub fn droplets_of(
    moves: &[Move],
    widths: &[f64; MAX_UNITS],
    within: Option<Bounds>,
    out: &mut Vec<Droplet>,
) {
    let mut at = Point::ZERO;
    let inside = |p: Point| within.is_none_or(|(lo, hi)| p.cmpge(lo).all() && p.cmple(hi).all());
    for m in moves {
        let w = widths[usize::from(m.unit)];
        match m.kind {
            MoveKind::Droplet if inside(m.to) => out.push((m.to, w)),
            MoveKind::Line => match within {
                None => out.extend(line_droplets(at, m.to, w).map(|p| (p, w))),
                // only the droplets near the box are computed (a long line, a small box)
                Some((lo, hi)) => {
                    if at.min(m.to).cmple(hi).all() && at.max(m.to).cmpge(lo).all() {
                        out.extend(line_droplets_in(at, m.to, w, lo, hi).map(|p| (p, w)));
                    }
                }
            },
            _ => {}
        }
        at = m.to;
    }
}

/// Candidate places for a support droplet under `c`: c itself, then rings around it out to
/// `r` (nearest first).
fn candidates(c: Point, r: f64) -> impl Iterator<Item = Point> {
    std::iter::once(c).chain((1..=4).flat_map(move |ring| {
        let rr = r * ring as f64 / 4.0;
        let n = 8 * ring;
        (0..n).map(move |k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            c + rr * DVec2::new(a.cos(), a.sin())
        })
    }))
}

/// What the pass did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PassFigures {
    /// Unit-1 droplets added.
    pub added: usize,
    /// Droplets left unsupported: no place within the rule outside the part and its gap.
    pub unplaceable: usize,
}

/// The support's droplets to add to each layer so that every droplet above the first layer is
/// supported: `moves(i)` gives layer i's planned moves ([`LayerMoves`]: their droplets are
/// listed from them, about once per layer, in runs of layers on all cores; again near added
/// droplets), so that no layer's droplets need be kept; `regions[i]` is its part's region.
/// Works top-down; an added droplet needs support from the layer below as any other. Support
/// droplets keep `support_gap_xy`·B from the part's region; a droplet with no such place
/// within the rule stays unsupported (counted). With `support_gap_z` > 0 the support
/// deliberately stops below overhangs, and the pass adds nothing.
pub fn complete(
    moves: LayerMoves,
    regions: &[Shapes],
    s: &Settings,
) -> (Vec<Vec<Point>>, PassFigures) {
    now(complete_in_steps(moves, regions, s, &UNLIMITED))
}

/// [`complete`] in resumable steps (the page's short calls, [`crate::base::steps`]): each
/// layer's check against the layer below, then each layer's placing, one item of `budget`
/// each, one after the other; with [`UNLIMITED`], the checks on all cores. The same result
/// whatever the budget.
pub async fn complete_in_steps(
    moves: LayerMoves<'_>,
    regions: &[Shapes],
    s: &Settings,
    budget: &Budget,
) -> (Vec<Vec<Point>>, PassFigures) {
    let n = regions.len();
    let mut extra: Vec<Vec<Point>> = vec![Vec::new(); n];
    let mut figures = PassFigures::default();
    if n < 2 || s.support_gap_z > 0 {
        return (extra, figures);
    }
    let rule = Rule::new(s);
    // Each layer's hatch rows: the part's fill and the support (of the unit `support` names).
    let frames: Vec<Frames> = (0..n)
        .map(|i| {
            let fill = crate::slicing::fill::FillParams::from_settings(s, i);
            let angle = crate::slicing::plan::hatch_angle(s, i);
            Frames::new(
                Frame::new(fill.angle_deg, fill.spacing, fill.phase, rule.b),
                Frame::new(angle, rule.spacing, 0.5, rule.b1),
                s.support_unit().0,
            )
        })
        .collect();
    let open = unsupported_by_planned(moves, &frames, &rule, budget).await;
    let mut buf = Vec::new();
    // Top-down: layer i's unsupported droplets (planned or added) get droplets in layer i − 1.
    for i in (1..n).rev() {
        super::timed(budget, || {
            let mut todo: Vec<Droplet> = open[i].clone();
            if !extra[i].is_empty() {
                unsupported_added(moves, i, &extra[i], &rule, &mut buf, &mut todo);
            }
            if !todo.is_empty() {
                place_under(
                    &todo,
                    &regions[i - 1],
                    &rule,
                    &mut extra[i - 1],
                    &mut figures,
                );
            }
        });
        budget.spend(1).await;
    }
    (extra, figures)
}

/// The overhang rule's distances for the pass.
struct Rule {
    /// Unit 0's droplet width B.
    b: f64,
    /// The support's unit's droplet width (its droplets added here are of it).
    b1: f64,
    /// Every unit's droplet width B_u (of a unit the machine lacks: B).
    widths: [f64; MAX_UNITS],
    /// The least and the greatest of them.
    narrow: f64,
    wide: f64,
    /// `overhang_limit`·B.
    limit: f64,
    /// The grids' cells: the reach of the wider droplets.
    cell: f64,
    /// `support_gap_xy`·B.
    gap: f64,
    /// How far from a droplet to support an added droplet may be placed.
    place: f64,
    /// The spacing of the support's hatch lines.
    spacing: f64,
}

impl Rule {
    fn new(s: &Settings) -> Rule {
        let b = s.droplet_width();
        let b1 = s.support_width();
        let limit = s.overhang_limit * b;
        let s1 = crate::slicing::plan::support_settings(s);
        let mut widths = [b; MAX_UNITS];
        for u in UnitId::all(s.units as usize) {
            widths[u.index()] = s.unit_width(u);
        }
        let narrow = widths.iter().copied().fold(f64::INFINITY, f64::min);
        let wide = widths.iter().copied().fold(0.0, f64::max);
        let mut rule = Rule {
            b,
            b1,
            widths,
            narrow,
            wide,
            limit,
            cell: 0.0,
            gap: s.support_gap_xy * b,
            place: 0.0,
            spacing: s1.droplet_width() / s1.fill_density,
        };
        rule.cell = rule.reach(wide);
        rule.place = rule.reach(b1) - MARGIN_MM;
        rule
    }

    /// How far a droplet of width `w` supports: w/2 + the limit.
    fn reach(&self, w: f64) -> f64 {
        w / 2.0 + self.limit
    }
}

/// Each layer's planned droplets that the layer below's planned droplets leave unsupported
/// (none for layer 0), in the order they are listed: natively runs of consecutive layers on
/// all cores, each layer's droplets listed and indexed once within a run (the index of layer
/// i then checks layer i + 1); with a limited budget one layer an item, one after the other.
async fn unsupported_by_planned(
    moves: LayerMoves<'_>,
    frames: &[Frames],
    rule: &Rule,
    budget: &Budget,
) -> Vec<Vec<Droplet>> {
    const RUN: usize = 8;
    let n = frames.len();
    let mut out = vec![Vec::new()];
    if budget.limited() {
        let mut pass = Pass::new(moves, frames, rule, 0);
        for i in 1..n {
            out.push(super::timed(budget, || pass.next(i + 1 < n)));
            budget.spend(1).await;
        }
        return out;
    }
    let runs = par_map((n - 1).div_ceil(RUN), &|r| {
        let (first, end) = (1 + r * RUN, (1 + (r + 1) * RUN).min(n));
        let mut pass = Pass::new(moves, frames, rule, first - 1);
        (first..end)
            .map(|i| pass.next(i + 1 < end))
            .collect::<Vec<_>>()
    });
    out.extend(runs.into_iter().flatten());
    out
}

/// Consecutive layers checked against the layer below ([`Pass::next`]).
struct Pass<'a, 'm> {
    moves: LayerMoves<'m>,
    frames: &'a [Frames],
    rule: &'a Rule,
    /// The layer `below` holds.
    layer: usize,
    below: Index,
    listed: Listed,
}

impl<'a, 'm> Pass<'a, 'm> {
    /// A pass holding layer `layer`.
    fn new(
        moves: LayerMoves<'m>,
        frames: &'a [Frames],
        rule: &'a Rule,
        layer: usize,
    ) -> Pass<'a, 'm> {
        let reach = |w: f64| rule.reach(w);
        let mut pass = Pass {
            moves,
            frames,
            rule,
            layer,
            below: Index::new(rule.narrow, rule.wide, reach),
            listed: Listed::default(),
        };
        pass.listed
            .list(moves(layer), &frames[layer], &rule.widths, None);
        pass.below.fill(&pass.listed, &frames[layer], reach);
        pass
    }

    /// The droplets of the next layer that the layer held leaves unsupported; then holds that
    /// layer if `keep`.
    fn next(&mut self, keep: bool) -> Vec<Droplet> {
        let rule = self.rule;
        let reach = |w: f64| rule.reach(w);
        let i = self.layer + 1;
        // Consecutive droplets are neighbours: the droplet below that supported the last one
        // looked for most often supports the next.
        let mut last: Option<Droplet> = None;
        let mut open = Vec::new();
        let below = &self.below;
        self.listed.list(
            (self.moves)(i),
            &self.frames[i],
            &rule.widths,
            Some((below, &mut |at, which| {
                look_below(below, at, which, rule, &mut last, &mut open)
            })),
        );
        if keep {
            self.below.fill(&self.listed, &self.frames[i], reach);
        }
        self.layer = i;
        open
    }
}

/// Whether a droplet `at` (of frame `which`) that the layer below's raster does not cover has
/// a droplet of that layer within reach (`last` first, the one found last); else appends it
/// to `open`.
fn look_below(
    below: &Index,
    at: &index::At,
    which: u8,
    rule: &Rule,
    last: &mut Option<Droplet>,
    open: &mut Vec<Droplet>,
) {
    let reach = |w: f64| rule.reach(w);
    let p = at.exact();
    if let Some((q, wq)) = *last {
        let r = reach(wq);
        if (p - q).length_squared() <= r * r {
            return;
        }
    }
    match below.find_within(p, which, reach) {
        Some(d) => *last = Some(d),
        None => open.push((p, at.w)),
    }
}

/// Appends to `todo` the droplets `added` to layer i that layer i − 1's planned droplets leave
/// unsupported. They are few: each asks for that layer's droplets within reach of itself
/// (listed into `buf`; a walk of the layer's moves each, cheaper than listing and scanning the
/// droplets of the box of all of them, which may span the layer); more than 16 list the
/// droplets of their common box once, in a grid.
fn unsupported_added(
    moves: LayerMoves,
    i: usize,
    added: &[Point],
    rule: &Rule,
    buf: &mut Vec<Droplet>,
    todo: &mut Vec<Droplet>,
) {
    let reach = |w: f64| rule.reach(w);
    let droplets = |within: Option<Bounds>, out: &mut Vec<Droplet>| {
        for list in moves(i - 1) {
            droplets_of(list, &rule.widths, within, out);
        }
    };
    let adds: Vec<Droplet> = added.iter().map(|&p| (p, rule.b1)).collect();
    let cell = DVec2::splat(rule.cell);
    let held: Vec<bool> = if adds.len() <= 16 {
        // Few: each asks for the droplets in its own box (a line crossing it gives only the
        // droplets near the box), not the box of all of them, which may span the layer.
        adds.iter()
            .map(|&(p, _)| {
                buf.clear();
                droplets(Some((p - cell, p + cell)), buf);
                buf.iter().any(|&(q, w)| {
                    let r = reach(w);
                    (p - q).length_squared() <= r * r
                })
            })
            .collect()
    } else {
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for (p, _) in &adds {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        buf.clear();
        droplets(Some((lo - cell, hi + cell)), buf);
        let below = Below::new(rule.narrow, rule.wide, reach, buf);
        adds.iter()
            .map(|&(p, _)| below.find_within(p, reach).is_some())
            .collect()
    };
    todo.extend(
        adds.iter()
            .zip(&held)
            .filter(|(_, h)| !**h)
            .map(|(d, _)| *d),
    );
}

/// Places a droplet of the support's unit in the layer below (whose part's region is `region`) under each
/// droplet of `todo` that no droplet placed so far supports, appending it to `out`: outside
/// the part and its gap, failing that outside the part (in the gap); counted in `figures`.
fn place_under(
    todo: &[Droplet],
    region: &Shapes,
    rule: &Rule,
    out: &mut Vec<Point>,
    figures: &mut PassFigures,
) {
    let (gap, place) = (rule.gap, rule.place);
    // The gap is kept from the part's edges near the candidates only (within the rule's
    // reach and the gap of the droplets to support).
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for (p, _) in todo {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let margin = DVec2::splat(place + gap.max(0.0) + MARGIN_MM);
    let (lo, hi) = (lo - margin, hi + margin);
    let mut edges = edges_of(region);
    edges.retain(|&(a, e)| a.min(e).cmple(hi).all() && a.max(e).cmpge(lo).all());
    let clear = Clearance::new(&edges, gap, rule.b);
    let mut added = Added::new(rule.cell);
    for &(c, _) in todo {
        // Within the rule of an added droplet: within B₁/2 + limit.
        if added.any_within(c, rule.reach(rule.b1) - MARGIN_MM) {
            continue;
        }
        let found = candidates(c, place)
            .find(|&p| clear.keeps(p) && !inside(region, p))
            .or_else(|| candidates(c, place).find(|&p| !inside(region, p)));
        // As written: the layer below checks the rounded position.
        match found.map(round_output) {
            Some(p) => {
                debug_assert!(dist(p, c) <= rule.reach(rule.b1));
                added.add(p);
                out.push(p);
                figures.added += 1;
            }
            None => figures.unplaceable += 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::square;

    fn run(
        droplets: &[Vec<Droplet>],
        regions: &[Shapes],
        s: &Settings,
    ) -> (Vec<Vec<Point>>, PassFigures) {
        assert_eq!(droplets.len(), regions.len());
        // Each droplet a move of its own (unit 1 for B₁ where it differs from B).
        let moves: Vec<Vec<Move>> = droplets
            .iter()
            .map(|l| {
                l.iter()
                    .map(|&(to, w)| Move {
                        kind: MoveKind::Droplet,
                        role: crate::slicing::plan::Role::Fill,
                        to,
                        unit: (w != s.droplet_width()) as u8,
                    })
                    .collect()
            })
            .collect();
        complete(&|i| [&moves[i][..], &[][..]], regions, s)
    }

    #[test]
    fn a_droplet_over_nothing_gets_a_column_down_to_the_plate() {
        let s = Settings::default();
        let b = s.droplet_width();
        // Three layers: a droplet at (5, 5) on layer 2, a part (a square far away) on each.
        let part = square(0.0, 0.0, 2.0);
        let far = (DVec2::new(1.0, 1.0), b);
        let droplets = vec![vec![far], vec![far], vec![far, (DVec2::new(5.0, 5.0), b)]];
        let regions = vec![part.clone(), part.clone(), part];
        let (extra, figures) = run(&droplets, &regions, &s);
        assert_eq!(figures.unplaceable, 0);
        // One droplet under it on layer 1 and one under that on layer 0.
        assert_eq!(extra[2].len(), 0);
        assert_eq!(extra[1], vec![DVec2::new(5.0, 5.0)]);
        assert_eq!(extra[0], vec![DVec2::new(5.0, 5.0)]);
    }

    #[test]
    fn added_droplets_keep_the_gap_from_the_part() {
        let s = Settings::default();
        let b = s.droplet_width();
        let gap = s.support_gap_xy * b;
        // Layer 0: a 2 mm square; layer 1: a droplet just beyond its edge, unsupported by the
        // droplet far inside the square.
        let part = square(0.0, 0.0, 2.0);
        let c = DVec2::new(2.0 + 0.2 * b, 1.0);
        let droplets = vec![vec![(DVec2::new(0.5, 1.0), b)], vec![(c, b)]];
        let regions = vec![part.clone(), Shapes::new()];
        let (extra, figures) = run(&droplets, &regions, &s);
        assert_eq!(figures.added, 1);
        let p = extra[0][0];
        assert!(p.x >= 2.0 + gap - 1e-9, "{p}");
        assert!(dist(p, c) <= b1_reach(&s), "{p}");
    }

    fn b1_reach(s: &Settings) -> f64 {
        s.support_width() / 2.0 + s.overhang_limit * s.droplet_width()
    }

    #[test]
    fn supported_droplets_need_nothing_and_a_gap_z_adds_nothing() {
        let s = Settings::default();
        let b = s.droplet_width();
        let d = |x: f64| (DVec2::new(x, 0.0), b);
        let droplets = vec![vec![d(0.0)], vec![d(0.9 * b)], vec![d(1.8 * b)]];
        let regions = vec![Shapes::new(); 3];
        let (extra, figures) = run(&droplets, &regions, &s);
        assert!(extra.iter().all(|e| e.is_empty()));
        assert_eq!(figures, PassFigures::default());
        let far = vec![vec![d(0.0)], vec![d(5.0)]];
        let gap_z = Settings {
            support_gap_z: 1,
            ..s
        };
        let (extra, _) = run(&far, &regions[..2], &gap_z);
        assert!(extra.iter().all(|e| e.is_empty()));
    }
}
