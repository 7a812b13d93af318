//! Fill patterns behind one entry point (docs/spec.md 5.3.4): a pattern turns a layer's fill
//! region into unordered segments ([`HatchLine`], each a `G25` line) from a few values
//! ([`FillParams`]); the plan orders them ([`crate::slicing::hatch::order_greedy`]).
//! [`FillPattern::new_from_type`] gives the pattern of a kind. A new pattern is one new file
//! in this folder implementing [`Fill`], and its variant in [`FillPattern`].
//!
//! The patterns: [`lines`] (parallel lines at the layer's angle, today's only one; the
//! support's carried need on lattices, [`crate::support::lattice`], yields the same lines).

mod lines;

use crate::base::geom::Shapes;
use crate::base::settings::Settings;
use crate::slicing::hatch::HatchLine;

/// What a pattern needs to fill one region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FillParams {
    /// The direction of the lines, degrees.
    pub angle_deg: f64,
    /// The distance between lines, mm.
    pub spacing: f64,
    /// Lines at (j + `phase`)·`spacing` from the origin across their direction.
    pub phase: f64,
    /// With `Some((pitch, along, reach))`, segment ends on the points (k + along)·pitch along
    /// the lines, moved out by at most `reach` (see [`crate::slicing::hatch::hatch_at`]).
    pub lattice: Option<(f64, f64, f64)>,
}

impl FillParams {
    /// The part's fill of layer `index` (from 0): lines B / `fill_density` apart at the
    /// layer's angle ([`hatch_angle`]), on the layer's lattice with `stagger`
    /// ([`hatch_shifted`]).
    pub fn from_settings(s: &Settings, index: usize) -> FillParams {
        let shifted = hatch_shifted(s, index);
        let b = s.droplet_width();
        FillParams {
            angle_deg: hatch_angle(s, index),
            spacing: b / s.fill_density,
            phase: if shifted { 0.0 } else { 0.5 },
            lattice: s.stagger.then(|| {
                let along = if shifted { 0.5 } else { 0.0 };
                (b, along, fill_margin(s))
            }),
        }
    }
}

/// A fill pattern.
pub trait Fill: Sync {
    /// The unordered segments that fill `region`.
    fn fill(&self, region: &Shapes, p: &FillParams) -> Vec<HatchLine>;
}

/// The kinds of fill pattern.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FillPattern {
    /// Parallel lines ([`lines`]).
    #[default]
    Lines,
}

impl FillPattern {
    /// The pattern of this kind.
    pub fn new_from_type(self) -> &'static dyn Fill {
        match self {
            FillPattern::Lines => &lines::Lines,
        }
    }
}

/// Hatch angle of a layer (from 0): α_s + index·α_v.
pub fn hatch_angle(s: &Settings, index: usize) -> f64 {
    (s.hatch_angle + index as f64 * s.hatch_angle_step).rem_euclid(360.0)
}

/// Whether layer `index`'s hatch lattice is shifted by half a spacing across and half a
/// droplet along (`stagger`). With `stagger` every hatch line's droplets are set on a lattice
/// fixed to the origin: lines at (j + ½)·spacing across, droplets at k·B along (line ends
/// moved outward to lattice points, see [`crate::slicing::hatch::hatch_at`]), or (j + 0),
/// (k + ½) when shifted.
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
