//! The slicing job: a prepared mesh, its plane heights and a facet index per layer; any layer
//! planned on any thread ([`Job::plan_layer`]), with both discharge units and the support.

use crate::base::geom;
use crate::base::settings::{Settings, UnitId};
use crate::base::stages::{self, Stage};
use crate::model::mesh::Mesh;
use crate::model::prepare::JobInfo;
use crate::output::gcode;
use crate::output::summary::Summary;
use crate::pipeline::SupportedPlans;
use crate::slicing::plan::{self, LayerPlan};
use crate::slicing::slice::{self, FacetBuckets, Section};
use crate::support::overhang;

/// One prepared slicing job: the placed mesh, its plane heights and a facet index per layer.
pub struct Job {
    pub(crate) settings: Settings,
    pub(crate) mesh: Mesh,
    pub(crate) buckets: FacetBuckets,
    pub(crate) zs: Vec<f64>,
    pub(crate) info: JobInfo,
    /// The facet runs of [`JobInfo::groups`] as ranges of facet numbers (empty: all unit 0).
    pub(crate) groups: Vec<(std::ops::Range<u32>, u8)>,
    /// Every layer's plan with support (`support = unitN`), computed on first use: the
    /// droplet-level pass needs all layers' droplets (see [`Job::supported_plans`]).
    pub(crate) supported: std::sync::OnceLock<SupportedPlans>,
    /// The mesh's open boundary, found when a layer first has an open section.
    pub(crate) rims: std::sync::OnceLock<slice::Rims>,
}

impl Job {
    /// The discharge units that print in this job, by number: unit 0, the support's unit
    /// when support is on, and the unit of every part.
    pub fn units_used(&self) -> Vec<UnitId> {
        let mut used = vec![UnitId::FIRST];
        used.extend(self.settings.support.unit());
        used.extend(self.part_units());
        used.sort();
        used.dedup();
        used
    }

    /// Whether a unit other than 0 prints in this job (support, or parts of another unit).
    pub fn uses_other_units(&self) -> bool {
        self.units_used().len() > 1
    }

    /// The units other than 0 that print parts in this job, by number.
    pub fn part_units(&self) -> Vec<UnitId> {
        let mut units: Vec<UnitId> = (self.groups.iter())
            .map(|(_, u)| UnitId(*u))
            .filter(|&u| u != UnitId::FIRST)
            .collect();
        units.sort();
        units.dedup();
        units
    }

    /// The unit selected when layer `i` starts: the unit of the last move of the nearest
    /// layer below that has moves (0 at the start of the file). With unit 0 alone, 0 at once;
    /// otherwise that layer is planned again (the page's workers ask this once per run of
    /// layers, [`crate::wasm`]).
    pub fn unit_before(&self, i: usize) -> u8 {
        if !self.uses_other_units() {
            return 0;
        }
        for j in (0..i.min(self.layer_count())).rev() {
            if let Some(m) = self.plan_layer(j).moves.last() {
                return m.unit;
            }
        }
        0
    }

    /// The placed, repaired mesh that is sliced.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    pub fn info(&self) -> &JobInfo {
        &self.info
    }

    pub fn layer_count(&self) -> usize {
        self.zs.len()
    }

    /// What the job's analysis needs of it besides the settings
    /// ([`crate::analysis::JobAnalysis::new`]).
    pub fn analysis_grid(&self) -> crate::analysis::AnalysisGrid {
        let min = self.info.bounds.min;
        let (lo, hi) = (self.info.bounds.min, self.info.bounds.max);
        let mut boxes: Vec<[geom::Point; 2]> = (self.info.instances.iter())
            .map(|i| [i.min, i.max].map(|p| geom::DVec2::new(p[0], p[1])))
            .collect();
        if boxes.is_empty() {
            boxes.push([lo, hi].map(|p| geom::DVec2::new(p[0], p[1])));
        }
        crate::analysis::AnalysisGrid {
            min: geom::DVec2::new(min[0], min[1]),
            boxes,
            volume: self.info.mesh.signed_volume.abs(),
            layers: self.layer_count(),
            part_units: self.part_units(),
            file_name: self.info.file_name.clone(),
        }
    }

    /// Plane height of layer `i` above the part's bottom.
    pub fn plane_z(&self, i: usize) -> f64 {
        self.zs[i]
    }

    /// The cross-section of layer `i`.
    pub fn section(&self, i: usize) -> Section {
        stages::time(Stage::Section, || {
            slice::slice_layer(&self.mesh, self.buckets.layer(i), self.zs[i], &self.rims)
        })
    }

    /// The closed loops of layer `i` before their union (for diagnostics).
    pub fn section_loops(&self, i: usize) -> Vec<geom::Contour> {
        slice::section_loops(&self.mesh, self.buckets.layer(i), self.zs[i], &self.rims).0
    }

    /// Every move of layer `i`.
    pub fn plan_layer(&self, i: usize) -> LayerPlan {
        self.plan_layer_and_region(i).0
    }

    /// [`plan_layer`](Self::plan_layer) and the region unit 0 prints in the layer (its section
    /// in a job without unit-1 parts), which the analysis needs.
    pub fn plan_layer_and_region(&self, i: usize) -> (LayerPlan, geom::Shapes) {
        if self.settings.support.is_on() {
            return self.supported_plans()[i].clone();
        }
        self.plan_layer_with(i, self.section(i), None)
    }

    /// Layer `i`'s plan for the analysis of the layers next to it (its moves and the other
    /// units' part regions, without the overhang figure, which needs the section below) and the region of
    /// unit 0's parts the analysis bands.
    pub fn plan_and_region_for_analysis(&self, i: usize) -> (LayerPlan, geom::Shapes) {
        if self.settings.support.is_on() {
            return self.supported_plans()[i].clone();
        }
        self.plan_parts(i, &self.section(i))
    }

    /// Whether planning a layer needs the section of the layer below (for the overhang
    /// figure: with support off; with support on it comes from [`Job::supported_plans`]).
    pub fn needs_below(&self) -> bool {
        !self.settings.support.is_on()
    }

    /// [`plan_layer_and_region`](Self::plan_layer_and_region) given the layer's section and,
    /// when known, the region of layer i − 1's section (else it is sliced again when
    /// [`Job::needs_below`]): the native writer hands it from layer to layer.
    pub fn plan_layer_with(
        &self,
        i: usize,
        section: Section,
        below: Option<&geom::Shapes>,
    ) -> (LayerPlan, geom::Shapes) {
        if self.settings.support.is_on() {
            return self.supported_plans()[i].clone();
        }
        let unsupported = self.overhang_of(i, &section, below);
        self.plan_layer_overhang(i, section, unsupported)
    }

    /// The overhang figure of layer `i` (its plan's `unsupported_area`) given its section and,
    /// when known, the region of layer i − 1's section (else it is sliced again).
    pub fn overhang_of(&self, i: usize, section: &Section, below: Option<&geom::Shapes>) -> f64 {
        // Layers stay independent: the overhang needs only the section below.
        let sliced;
        let below = match (i.checked_sub(1), below) {
            (None, _) => None,
            (Some(_), Some(b)) => Some(b),
            (Some(j), None) => {
                sliced = self.section(j).region;
                Some(&sliced)
            }
        };
        stages::time(Stage::Overhang, || {
            overhang::overhang_area(&section.region, below, &self.settings)
        })
    }

    /// [`plan_layer_with`](Self::plan_layer_with) given the overhang figure as
    /// [`overhang_of`](Self::overhang_of) made it (the page makes a layer's section, its
    /// overhang figure and its plan in calls of their own).
    pub fn plan_layer_overhang(
        &self,
        i: usize,
        section: Section,
        unsupported: f64,
    ) -> (LayerPlan, geom::Shapes) {
        if self.settings.support.is_on() {
            return self.supported_plans()[i].clone();
        }
        let (mut plan, region) = stages::time(Stage::Plan, || self.plan_parts(i, &section));
        plan.unsupported_area = unsupported;
        (plan, region)
    }

    /// Layer `i`'s plan without support: unit 0's region, then the other units' parts (each
    /// with its B_u, in the order `unit_order` gives), and the region unit 0 prints.
    pub(crate) fn plan_parts(&self, i: usize, section: &Section) -> (LayerPlan, geom::Shapes) {
        let (mut plan, own) = if self.groups.is_empty() {
            (plan::plan_layer(&section.region, i, &self.settings), None)
        } else {
            let mut regions = self.unit_regions(i);
            let r0 = std::mem::take(&mut regions[0]);
            (
                plan::plan_layer(&r0, i, &self.settings),
                Some((r0, regions)),
            )
        };
        plan.open_chains = section.open_chains;
        plan.reoriented_loops = section.reoriented_loops;
        match own {
            None => (plan, section.region.clone()),
            Some((r0, regions)) => {
                plan::plan_unit_parts(&mut plan, regions, &self.settings);
                (plan, r0)
            }
        }
    }

    /// The region each unit prints as parts in layer `i`, indexed by unit (docs/spec.md
    /// "Discharge units"): each run of consecutive parts of one unit ([`JobInfo::groups`]) is
    /// sliced on its own, and keeps its section less the sections of the runs listed before it
    /// (where parts of different units overlap, the part listed first keeps the overlap). A job
    /// whose parts are all unit 0's: unit 0 prints the whole section.
    pub fn unit_regions(&self, i: usize) -> Vec<geom::Shapes> {
        let units = (self.settings.units as usize).max(1);
        if self.groups.is_empty() {
            let mut regions = vec![geom::Shapes::new(); units];
            regions[0] = self.section(i).region;
            return regions;
        }
        let facets = self.buckets.layer(i);
        let mut regions = vec![geom::Shapes::new(); units];
        let mut covered = geom::Shapes::new();
        for (k, (range, unit)) in self.groups.iter().enumerate() {
            let mine: Vec<u32> = facets
                .iter()
                .copied()
                .filter(|f| range.contains(f))
                .collect();
            if mine.is_empty() {
                continue;
            }
            let section = slice::slice_layer(&self.mesh, &mine, self.zs[i], &self.rims).region;
            let own = crate::base::boolean::difference(&section, &covered);
            if k + 1 < self.groups.len() {
                covered = crate::base::boolean::union(&covered, &section);
            }
            let r = &mut regions[usize::from(*unit).min(units - 1)];
            *r = crate::base::boolean::union(r, &own);
        }
        regions
    }

    /// Names the profiles applied to the settings (`name (kind)`, in order) in the header.
    pub fn set_profiles(&mut self, profiles: Vec<String>) {
        self.info.profiles = profiles;
    }

    /// The header; with `None` the droplet counts are fixed-width placeholders.
    pub fn header(&self, summary: Option<&Summary>) -> String {
        let b = &self.info.bounds;
        gcode::header(
            &self.settings,
            &gcode::HeaderInput {
                file_name: &self.info.file_name,
                facets: self.info.mesh.facets_in_file,
                layers: self.zs.len(),
                bounds: (b.min, b.max),
                warnings: &self.info.warnings,
                instances: &self.info.instances,
                units_used: &self.units_used(),
                profiles: &self.info.profiles,
            },
            summary,
        )
    }
}
