//! The supported pass (`support = unitN`): every layer's plan with the support, computed
//! once per job because the droplet-level pass needs all layers' droplets.

use crate::base::geom;
use crate::base::parallel::{both, par_map, par_map_owned};
use crate::base::stages::{self, Stage};
use crate::base::steps::Budget;
use crate::pipeline::Job;
use crate::slicing::plan::{self, LayerPlan};
use crate::support::{self, droplets as support_droplets};

/// Every layer's plan and region with support on, and what the droplet-level pass added
/// ([`Job::supported_pass`]).
pub struct SupportedPlans {
    pub layers: Vec<(LayerPlan, geom::Shapes)>,
    pub figures: support_droplets::PassFigures,
}

impl Job {
    /// Every layer's plan with support on (`support = unitN`), computed once per job on first
    /// use: each layer's part planned as without support, its support region hatched by unit N
    /// ([`moves::support_moves`]), then the droplet-level pass over all layers
    /// ([`support_droplets::complete`]) adds the support unit's droplets under every droplet the layer
    /// below leaves unsupported. Natively the layers are planned in parallel; in the page each
    /// worker's job plans them all once (docs/support.md).
    pub fn supported_plans(&self) -> &[(LayerPlan, geom::Shapes)] {
        &self.supported_pass().layers
    }

    /// Whether the supported pass was made (support on: before it, a layer's plan makes it).
    pub fn supported_made(&self) -> bool {
        self.supported.get().is_some()
    }

    /// [`Job::supported_pass`] in resumable steps (the page's short calls): the same plans,
    /// each layer's section, part plan, hatch and final plan a step's item, one layer after
    /// the other; the support regions' pass and the droplet-level pass about a layer an item
    /// ([`support::support_layers_in_steps`], [`support_droplets::complete_in_steps`]). Keeps the plans in the job (as [`Job::supported_pass`] would),
    /// unless it already has them.
    pub async fn supported_in_steps(&self, b: &Budget) {
        if self.supported_made() {
            return;
        }
        let n = self.layer_count();
        let s = &self.settings;
        let mut sections = Vec::with_capacity(n);
        for i in 0..n {
            sections.push(self.section(i));
            b.spend(1).await;
        }
        let regions: Vec<geom::Shapes> = sections.iter().map(|x| x.region.clone()).collect();
        let mut parts = Vec::with_capacity(n);
        for (i, section) in sections.iter().enumerate() {
            parts.push(stages::time(Stage::Plan, || self.plan_parts(i, section)));
            b.spend(1).await;
        }
        drop(sections);
        let layers = support::support_layers_in_steps(&regions, s, b).await;
        let mut hatches = Vec::with_capacity(n);
        for i in 0..n {
            let start = plan::support_start(&parts[i].0, s);
            hatches.push(stages::time(Stage::Support, || {
                support::moves::support_moves(&layers[i].lines, &regions[i], &[], i, s, start)
            }));
            b.spend(1).await;
        }
        let planned = with_hatches(parts, hatches, &layers);
        drop(layers);
        let (extra, figures) = support_droplets::complete_in_steps(
            &|i| [&planned[i].0.moves, &planned[i].2],
            &regions,
            s,
            b,
        )
        .await;
        let mut plans = Vec::with_capacity(n);
        for (i, layer) in planned.into_iter().enumerate() {
            plans.push(final_plan(i, layer, &extra, s));
            b.spend(1).await;
        }
        let _ = self.supported.set(SupportedPlans {
            layers: plans,
            figures,
        });
    }

    /// [`Job::supported_plans`] and what the droplet-level pass added.
    pub fn supported_pass(&self) -> &SupportedPlans {
        self.supported.get_or_init(|| {
            let n = self.layer_count();
            let s = &self.settings;
            let sections = par_map(n, &|i| self.section(i));
            let regions: Vec<geom::Shapes> = sections.iter().map(|x| x.region.clone()).collect();
            // The support regions (their top-down union is sequential) beside the parts' own
            // plans, which do not depend on them.
            let (layers, parts) = both(
                || stages::time(Stage::Support, || support::support_layers(&regions, s)),
                || {
                    par_map(n, &|i| {
                        stages::time(Stage::Plan, || self.plan_parts(i, &sections[i]))
                    })
                },
            );
            drop(sections);
            // The support's hatch moves of each layer, after its part plan.
            let hatches = par_map(n, &|i| {
                let start = plan::support_start(&parts[i].0, s);
                stages::time(Stage::Support, || {
                    support::moves::support_moves(&layers[i].lines, &regions[i], &[], i, s, start)
                })
            });
            let planned = with_hatches(parts, hatches, &layers);
            drop(layers);
            let (extra, figures) = droplet_pass(&planned, &regions, s);
            // Each layer's added droplets and the support's moves into its plan (on all cores).
            let plans = par_map_owned(planned, &|i, layer| final_plan(i, layer, &extra, s));
            SupportedPlans {
                layers: plans,
                figures,
            }
        })
    }
}

/// A layer's part plan, its own region and the support's hatch moves.
type Planned = (LayerPlan, geom::Shapes, Vec<plan::Move>);

/// Each layer's part plan with its overhang figure and the support's hatch moves.
fn with_hatches(
    parts: Vec<(LayerPlan, geom::Shapes)>,
    hatches: Vec<Vec<plan::Move>>,
    layers: &[support::LayerSupport],
) -> Vec<Planned> {
    parts
        .into_iter()
        .zip(hatches)
        .zip(layers)
        .map(|(((mut p, own), moves), layer)| {
            p.unsupported_area = layer.unsupported_area;
            (p, own, moves)
        })
        .collect()
}

/// The droplet-level pass: it reads each layer's droplets from its moves when it needs them
/// (no list of all droplets is kept).
fn droplet_pass(
    planned: &[Planned],
    regions: &[geom::Shapes],
    s: &crate::base::settings::Settings,
) -> (
    Vec<Vec<crate::base::geom::DVec2>>,
    support_droplets::PassFigures,
) {
    stages::time(Stage::Support, || {
        support_droplets::complete(&|i| [&planned[i].0.moves, &planned[i].2], regions, s)
    })
}

/// Layer `i`'s added droplets and the support's moves into its plan.
fn final_plan(
    i: usize,
    (mut p, region, mut moves): Planned,
    extra: &[Vec<crate::base::geom::DVec2>],
    s: &crate::base::settings::Settings,
) -> (LayerPlan, geom::Shapes) {
    if !extra[i].is_empty() {
        let start = moves.last().map_or(plan::support_start(&p, s), |m| m.to);
        let none = geom::Shapes::new();
        moves.extend(support::moves::support_moves(
            &[],
            &none,
            &extra[i],
            i,
            s,
            start,
        ));
    }
    plan::add_support(&mut p, moves, s);
    (p, region)
}
