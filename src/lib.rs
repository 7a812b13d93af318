//! dropslice: a slicer for droplet-based plastic 3D printing.
//!
//! The pipeline (SPEC.md 5.3), one module per stage, each a plain function from one named
//! type to the next:
//!
//! `&[u8]` —[`stl::parse`]→ triangles —[`mesh::Mesh::weld`], [`mesh::Mesh::transform`]→
//! [`mesh::Mesh`] —[`slice::slice_layer`]→ [`slice::Section`] (region: outer CCW + holes CW)
//! —[`contours::contours`] (via [`offset::inset`])→ loops + fill region
//! —[`droplets::loop_droplets`], [`hatch::hatch`]→ droplet centres + hatch segments
//! —[`plan::plan_layer`]→ [`plan::LayerPlan`] —[`gcode::layer_text`]→ `.gco` text, and
//! [`preview::PreviewLayer`] for the canvas.
//!
//! Layers are independent: [`Job::plan_layer`] plans any layer on any thread. Natively,
//! [`write_gcode`] plans them in parallel and writes them in ascending order, a window at a
//! time, so memory stays bounded however tall the part is.

pub mod analysis;
pub mod base;
pub mod model;
pub mod output;
pub mod slicing;
pub mod support;
#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use base::error::Error;
pub use base::settings::Settings;
pub use output::summary::{Figures, Summary};

use base::{geom, settings};
use model::mesh::{Bounds, Mesh, MeshStats};
use model::{import, import::stl, mesh, spec as job};
use output::gcode;
use slicing::plan::LayerPlan;
use slicing::slice::{FacetBuckets, Section};
use slicing::{plan, slice};
use support::droplets as support_droplets;
use support::overhang;

pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Most layers a job may have (a guard against settings that would run for hours).
pub const MAX_LAYERS: usize = 200_000;
/// Most droplets a job may set (volume / B²H): beyond this the code would not fit on a disk.
pub const MAX_DROPLETS: f64 = 2e9;
/// Largest part extent in x or y, in droplet widths (hatch lines per layer).
pub const MAX_WIDTH_IN_DROPLETS: f64 = 2_000_000.0;

/// What the import found, for the CLI summary, the header and the page.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JobInfo {
    pub file_name: String,
    pub format: stl::Format,
    pub mesh: MeshStats,
    /// Bounding box of the placed part, in mm.
    pub bounds: Bounds,
    pub layers: usize,
    /// Droplet width B in mm.
    pub droplet_width: f64,
    /// Problems found in the mesh and what was done about them.
    pub warnings: Vec<String>,
    /// A scale factor for all three axes when the part's size suggests the file is not in
    /// millimetres (25.4: inches; 0.001: micrometres); never applied silently.
    pub suggested_scale: Option<f64>,
    /// Every copy of every part: its file, transform, placement, matrix and bounds.
    #[serde(default)]
    pub instances: Vec<job::Instance>,
    /// Which discharge unit prints which facets of the prepared mesh: runs of facets in mesh
    /// order, each the instances of consecutive parts of one unit, in the order the parts are
    /// listed (the order that decides who keeps an overlap). Empty: every facet is unit 0's
    /// (every job without unit-1 parts).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<FacetGroup>,
}

/// A run of facets of the prepared mesh printed by one discharge unit ([`JobInfo::groups`]).
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FacetGroup {
    /// How many facets (they follow the run before).
    pub facets: usize,
    /// The discharge unit, 0 or 1.
    pub unit: u8,
}

/// Drops the facets that were not kept from the runs' counts.
fn keep_groups(groups: &mut [FacetGroup], kept: &[bool]) {
    let mut at = 0;
    for g in groups {
        let end = (at + g.facets).min(kept.len());
        let n = kept[at.min(end)..end].iter().filter(|&&k| k).count();
        at = end;
        g.facets = n;
    }
}

/// Vertices closer than this are merged when exact welding leaves the surface open.
pub const WELD_TOLERANCE_MM: f64 = 1e-4;

/// The unit rule: a part whose largest extent is under 10 mm is probably in inches; one over
/// 2 m probably in micrometres.
pub fn suggested_scale(size: &[f64; 3]) -> Option<f64> {
    let largest = size[0].max(size[1]).max(size[2]);
    if largest < 10.0 {
        Some(25.4)
    } else if largest > 2000.0 {
        Some(0.001)
    } else {
        None
    }
}

/// Every layer's plan and region with support on, and what the droplet-level pass added
/// ([`Job::supported_pass`]).
pub struct SupportedPlans {
    pub layers: Vec<(LayerPlan, geom::Shapes)>,
    pub figures: support_droplets::PassFigures,
}

/// One prepared slicing job: the placed mesh, its plane heights and a facet index per layer.
pub struct Job {
    settings: Settings,
    mesh: Mesh,
    buckets: FacetBuckets,
    zs: Vec<f64>,
    info: JobInfo,
    /// The facet runs of [`JobInfo::groups`] as ranges of facet numbers (empty: all unit 0).
    groups: Vec<(std::ops::Range<u32>, u8)>,
    /// Every layer's plan with support (`support = unit1`), computed on first use: the
    /// droplet-level pass needs all layers' droplets (see [`Job::supported_plans`]).
    supported: std::sync::OnceLock<SupportedPlans>,
}

impl Job {
    /// Reads the model (STL, OBJ or a 3MF build, see [`import`]), validates the settings and
    /// places the part: import → checks → mesh repair → facet index. A 3MF build's items keep
    /// their relative positions and are sliced together.
    pub fn new(model_bytes: &[u8], file_name: &str, settings: Settings) -> Result<Job, Error> {
        settings.validate()?;
        let Imported {
            mesh,
            format,
            facets_in_file,
            degenerate,
            instance,
        } = import(model_bytes, file_name, &settings)?;
        let input = Input {
            file_name: file_name.to_string(),
            format,
            facets_in_file,
            degenerate,
            instances: vec![instance],
            warnings: Vec::new(),
            groups: Vec::new(),
        };
        Job::build(mesh, input, settings)
    }

    /// A build job (SPEC.md "Build jobs"): reads each file of `files` (name, bytes) once and
    /// builds the job of `spec` from them (see [`Job::from_models`]).
    pub fn from_parts(files: &[(&str, &[u8])], spec: &job::JobSpec) -> Result<Job, Error> {
        let models = files
            .iter()
            .map(|(name, bytes)| job::Model::read(bytes, name))
            .collect::<Result<Vec<_>, _>>()?;
        Job::from_models(&models, spec)
    }

    /// A build job from imported files: every part welded once, each instance placed (the
    /// arrangement of [`job::place_instances`]) with [`Mesh::place`] — the very transform of
    /// [`Job::new`] — the instances merged into one mesh and prepared as [`Job::new`] does
    /// (checks, shells, repair, facet index). The job's settings are `spec.settings`.
    pub fn from_models(models: &[job::Model], spec: &job::JobSpec) -> Result<Job, Error> {
        spec.validate()?;
        let settings = spec.settings.clone();
        let by_part = job::models_of(models, spec)?;
        // Runs of consecutive parts of one unit (SPEC.md: where parts of different units
        // overlap, the part listed first keeps the overlap).
        let mut run_of = Vec::with_capacity(spec.parts.len());
        for (i, p) in spec.parts.iter().enumerate() {
            let run = match i.checked_sub(1) {
                Some(j) if spec.parts[j].unit == p.unit => run_of[j],
                Some(j) => run_of[j] + 1,
                None => 0,
            };
            run_of.push(run);
        }
        let mut welded = Vec::with_capacity(spec.parts.len());
        let mut frames = Vec::with_capacity(spec.parts.len());
        let (mut facets_in_file, mut degenerate, mut facets) = (0usize, 0usize, 0usize);
        for (i, (p, m)) in spec.parts.iter().zip(&by_part).enumerate() {
            let tris = m.triangles(p.item).map_err(|e| job::at_part(i, e))?;
            let (mesh, dropped) = Mesh::weld(&tris);
            let copies = p.copies as usize;
            facets = facets.saturating_add(mesh.facets.len().saturating_mul(copies));
            if facets > import::MAX_TRIANGLES {
                return Err(Error::Job(format!(
                    "the job has more than {} triangles in all (parts × copies); print fewer copies or simplify the models",
                    import::MAX_TRIANGLES
                )));
            }
            let frame = job::Frame::of(mesh.vertices.iter().copied(), &p.placement([0.0, 0.0]));
            let Some(frame) = frame.filter(|_| !mesh.facets.is_empty()) else {
                return Err(Error::Import(format!(
                    "parts[{i}] ({}): all {} triangles are degenerate (their corners coincide): the part has no surface",
                    job::clean_name(&m.part_name(p.item)),
                    tris.len()
                )));
            };
            facets_in_file += tris.len() * copies;
            degenerate += dropped * copies;
            welded.push(mesh);
            frames.push(frame);
        }
        let layout = job::place_instances(&by_part, spec, &frames)?;
        let vertices: usize = layout
            .instances
            .iter()
            .map(|x| welded[x.part].vertices.len())
            .sum();
        let mut mesh = Mesh {
            vertices: Vec::with_capacity(vertices),
            facets: Vec::with_capacity(facets),
        };
        // The instances run by run (a job of unit 0 alone: one run, in the layout's order).
        let mut order: Vec<&job::Instance> = layout.instances.iter().collect();
        order.sort_by_key(|inst| run_of[inst.part]);
        let mut groups: Vec<FacetGroup> = Vec::new();
        for inst in order {
            let mut m = welded[inst.part].clone();
            m.place(&spec.parts[inst.part].placement(inst.shift));
            let base = mesh.vertices.len() as u32;
            mesh.vertices.extend_from_slice(&m.vertices);
            mesh.facets
                .extend(m.facets.iter().map(|f| f.map(|v| v + base)));
            // Runs are numbered from 0 in order: run r is the (r + 1)-th group.
            match groups.get_mut(run_of[inst.part]) {
                Some(g) => g.facets += m.facets.len(),
                None => groups.push(FacetGroup {
                    facets: m.facets.len(),
                    unit: spec.parts[inst.part].unit,
                }),
            }
        }
        drop(welded);
        if groups.iter().all(|g| g.unit == 0) {
            groups.clear();
        }
        let mut names: Vec<String> = Vec::new();
        for p in &spec.parts {
            let n = job::clean_name(&p.file);
            if !names.contains(&n) {
                names.push(n);
            }
        }
        let mut file_name = names.join(", ");
        if file_name.chars().count() > 4 * job::MAX_NAME_CHARS {
            file_name = format!(
                "{}… ({} files)",
                file_name
                    .chars()
                    .take(4 * job::MAX_NAME_CHARS)
                    .collect::<String>(),
                names.len()
            );
        }
        let input = Input {
            file_name,
            format: by_part[0].format,
            facets_in_file,
            degenerate,
            instances: layout.instances,
            warnings: layout.warnings,
            groups,
        };
        Job::build(mesh, input, settings)
    }

    /// The common tail of [`Job::new`] and [`Job::from_models`]: checks → shells → mesh repair
    /// → facet index.
    fn build(mut mesh: Mesh, input: Input, settings: Settings) -> Result<Job, Error> {
        let bounds = mesh.bounds();
        let size = bounds.size();
        check_height(&size, &settings)?;
        // Repeated facets first (they would make a shell's edges look non-manifold), then every
        // closed shell as its author meant it (inside-out shells turned outward, cavities kept),
        // so the volume below counts what will be printed: shells of opposite orientation can
        // no longer cancel.
        let mut groups = input.groups;
        let kept = mesh.remove_duplicate_facets_kept();
        let duplicates = kept.iter().filter(|&&k| !k).count();
        keep_groups(&mut groups, &kept);
        let shells = mesh.orient_shells();
        check_volume(&mesh, &shells, &size, &settings)?;
        let zs = plane_heights(&size, &settings)?;
        let (mesh, buckets, stats) = repair(
            mesh,
            &zs,
            shells.clone(),
            duplicates,
            input.facets_in_file,
            input.degenerate,
            &mut groups,
        );
        if shells.open > 0 {
            // Open shells enclose no definite volume: estimate what will be printed from the
            // sliced area of sampled layers (the slicer closes open sections the same way).
            let h = settings.layer_height;
            check_droplets(sampled_volume(&mesh, &buckets, &zs, h), &settings)?;
        }
        let mut all_warnings = input.warnings;
        all_warnings.extend(warnings(&stats, &size));
        let info = JobInfo {
            file_name: input.file_name,
            format: input.format,
            warnings: all_warnings,
            suggested_scale: suggested_scale(&size),
            mesh: stats,
            bounds,
            layers: zs.len(),
            droplet_width: settings.droplet_width(),
            instances: input.instances,
            groups,
        };
        Ok(Job::assemble(settings, mesh, buckets, zs, info))
    }

    /// A job from a mesh another [`Job`] prepared (its [`Job::mesh`] and [`Job::info`], with
    /// the same settings): no import, checks or repair, only the facet index. Slices exactly
    /// as that job does.
    pub fn from_prepared(mesh: Mesh, info: JobInfo, settings: Settings) -> Result<Job, Error> {
        settings.validate()?;
        let zs = slice::layer_heights(
            info.bounds.size()[2],
            settings.layer_height,
            settings.slice_plane,
        );
        let bad = |what: String| Error::Internal(format!("prepared mesh: {what}"));
        if zs.len() != info.layers {
            return Err(bad(format!(
                "{} layers, but the settings give {} (prepared with other settings?)",
                info.layers,
                zs.len()
            )));
        }
        if info.mesh.facets != mesh.facets.len() {
            return Err(bad(format!(
                "{} facets, but the info says {}",
                mesh.facets.len(),
                info.mesh.facets
            )));
        }
        let n = mesh.vertices.len();
        if mesh.facets.iter().flatten().any(|&v| v as usize >= n) {
            return Err(bad("a facet refers to a vertex that does not exist".into()));
        }
        if !info.groups.is_empty() {
            let total = info
                .groups
                .iter()
                .try_fold(0usize, |t, g| t.checked_add(g.facets));
            if total != Some(mesh.facets.len())
                || info.groups.len() > job::MAX_INSTANCES
                || info.groups.iter().any(|g| g.unit > 1)
            {
                return Err(bad(
                    "the facet groups do not cover the facets, or name a unit other than 0 or 1"
                        .into(),
                ));
            }
        }
        let buckets = FacetBuckets::new(&mesh, &zs);
        Ok(Job::assemble(settings, mesh, buckets, zs, info))
    }

    /// The common tail of [`Job::new`] and [`Job::from_prepared`].
    fn assemble(
        settings: Settings,
        mesh: Mesh,
        buckets: FacetBuckets,
        zs: Vec<f64>,
        info: JobInfo,
    ) -> Job {
        let mut groups = Vec::with_capacity(info.groups.len());
        let mut at = 0u32;
        for g in &info.groups {
            let end = at + g.facets as u32;
            groups.push((at..end, g.unit));
            at = end;
        }
        Job {
            settings,
            mesh,
            buckets,
            zs,
            info,
            groups,
            supported: std::sync::OnceLock::new(),
        }
    }

    /// Whether discharge unit 1 prints in this job: support is on, or a part is unit 1's.
    pub fn uses_unit1(&self) -> bool {
        self.settings.support == settings::Support::Unit1 || self.has_unit1_parts()
    }

    /// Whether a part of this job is printed by unit 1.
    pub fn has_unit1_parts(&self) -> bool {
        self.groups.iter().any(|(_, u)| *u == 1)
    }

    /// Every layer's plan with support on (`support = unit1`), computed once per job on first
    /// use: each layer's part planned as without support, its support region hatched by unit 1
    /// ([`moves::support_moves`]), then the droplet-level pass over all layers
    /// ([`support_droplets::complete`]) adds unit-1 droplets under every droplet the layer
    /// below leaves unsupported. Natively the layers are planned in parallel; in the page each
    /// worker's job plans them all once (docs/support.md).
    pub fn supported_plans(&self) -> &[(LayerPlan, geom::Shapes)] {
        &self.supported_pass().layers
    }

    /// [`Job::supported_plans`] and what the droplet-level pass added.
    pub fn supported_pass(&self) -> &SupportedPlans {
        self.supported.get_or_init(|| {
            let n = self.layer_count();
            let s = &self.settings;
            let sections = support::par_map(n, &|i| self.section(i));
            let regions: Vec<geom::Shapes> = sections.iter().map(|x| x.region.clone()).collect();
            // The support regions (their top-down union is sequential) beside the parts' own
            // plans, which do not depend on them.
            let (layers, parts) = both(
                || support::support_layers(&regions, s),
                || support::par_map(n, &|i| self.plan_parts(i, &sections[i])),
            );
            drop(sections);
            // Unit 1's hatch moves of each layer, after its part plan.
            let hatches = support::par_map(n, &|i| {
                let start = plan::unit1_start(&parts[i].0, s);
                support::moves::support_moves(&layers[i].lines, &regions[i], &[], i, s, start)
            });
            let planned: Vec<(LayerPlan, geom::Shapes, Vec<plan::Move>)> = parts
                .into_iter()
                .zip(hatches)
                .zip(&layers)
                .map(|(((mut p, own), moves), layer)| {
                    p.unsupported_area = layer.unsupported_area;
                    (p, own, moves)
                })
                .collect();
            drop(layers);
            // The droplet-level pass reads each layer's droplets from its moves when it needs
            // them (no list of all droplets is kept).
            let (b, b1) = (s.droplet_width(), s.unit1_droplet_width());
            let (extra, figures) = support_droplets::complete(
                &|i, within, out: &mut Vec<support_droplets::Droplet>| {
                    support_droplets::droplets_of(&planned[i].0.moves, b, b1, within, out);
                    support_droplets::droplets_of(&planned[i].2, b, b1, within, out);
                },
                &regions,
                s,
            );
            let plans = planned
                .into_iter()
                .enumerate()
                .map(|(i, (mut p, region, mut moves))| {
                    if !extra[i].is_empty() {
                        let start = moves.last().map_or(plan::unit1_start(&p, s), |m| m.to);
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
                    plan::add_unit1(&mut p, moves, s);
                    (p, region)
                })
                .collect();
            SupportedPlans {
                layers: plans,
                figures,
            }
        })
    }

    /// The unit selected when layer `i` starts: the unit of the last move of the nearest
    /// layer below that has moves (0 at the start of the file). Without unit 1, 0 at once;
    /// otherwise that layer is planned again (the page's workers ask this once per run of
    /// layers, [`crate::wasm`]).
    pub fn unit_before(&self, i: usize) -> u8 {
        if !self.uses_unit1() {
            return 0;
        }
        for j in (0..i.min(self.layer_count())).rev() {
            if let Some(m) = self.plan_layer(j).moves.last() {
                return m.unit;
            }
        }
        0
    }

    /// The placed, repaired mesh that is sliced (for [`Job::from_prepared`]).
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

    /// Plane height of layer `i` above the part's bottom.
    pub fn plane_z(&self, i: usize) -> f64 {
        self.zs[i]
    }

    /// The cross-section of layer `i`.
    pub fn section(&self, i: usize) -> Section {
        slice::slice_layer(&self.mesh, self.buckets.layer(i), self.zs[i])
    }

    /// The closed loops of layer `i` before their union (for diagnostics).
    pub fn section_loops(&self, i: usize) -> Vec<geom::Contour> {
        slice::section_loops(&self.mesh, self.buckets.layer(i), self.zs[i]).0
    }

    /// Every move of layer `i`.
    pub fn plan_layer(&self, i: usize) -> LayerPlan {
        self.plan_layer_and_region(i).0
    }

    /// [`plan_layer`](Self::plan_layer) and the region unit 0 prints in the layer (its section
    /// in a job without unit-1 parts), which the analysis needs.
    pub fn plan_layer_and_region(&self, i: usize) -> (LayerPlan, geom::Shapes) {
        if self.settings.support == settings::Support::Unit1 {
            return self.supported_plans()[i].clone();
        }
        self.plan_layer_with(i, self.section(i), None)
    }

    /// Whether planning a layer needs the section of the layer below (for the overhang
    /// figure: with support off; with support on it comes from [`Job::supported_plans`]).
    pub fn needs_below(&self) -> bool {
        self.settings.support != settings::Support::Unit1
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
        if self.settings.support == settings::Support::Unit1 {
            return self.supported_plans()[i].clone();
        }
        let (mut plan, region) = self.plan_parts(i, &section);
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
        plan.unsupported_area = overhang::overhang_area(&section.region, below, &self.settings);
        (plan, region)
    }

    /// Layer `i`'s plan without support: unit 0's region, then unit 1's parts (with B₁, in
    /// the order `unit_order` gives), and the region unit 0 prints.
    fn plan_parts(&self, i: usize, section: &Section) -> (LayerPlan, geom::Shapes) {
        let (mut plan, own) = if self.groups.is_empty() {
            (plan::plan_layer(&section.region, i, &self.settings), None)
        } else {
            let [r0, r1] = self.unit_regions(i);
            (plan::plan_layer(&r0, i, &self.settings), Some((r0, r1)))
        };
        plan.open_chains = section.open_chains;
        plan.reoriented_loops = section.reoriented_loops;
        match own {
            None => (plan, section.region.clone()),
            Some((r0, r1)) => {
                plan::plan_unit1_layer(
                    &mut plan,
                    &r1,
                    &geom::Shapes::new(),
                    plan::Role::Support,
                    &self.settings,
                );
                (plan, r0)
            }
        }
    }

    /// The regions units 0 and 1 print in layer `i` (SPEC.md "Two discharge units"): each
    /// run of consecutive parts of one unit ([`JobInfo::groups`]) is sliced on its own, and
    /// keeps its section less the sections of the runs listed before it (where parts of
    /// different units overlap, the part listed first keeps the overlap). A job without
    /// unit-1 parts: unit 0 prints the whole section.
    pub fn unit_regions(&self, i: usize) -> [geom::Shapes; 2] {
        if self.groups.is_empty() {
            return [self.section(i).region, geom::Shapes::new()];
        }
        let facets = self.buckets.layer(i);
        let mut regions = [geom::Shapes::new(), geom::Shapes::new()];
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
            let section = slice::slice_layer(&self.mesh, &mine, self.zs[i]).region;
            let own = support::difference(&section, &covered);
            if k + 1 < self.groups.len() {
                covered = support::union(&covered, &section);
            }
            let r = &mut regions[usize::from(*unit).min(1)];
            *r = support::union(r, &own);
        }
        regions
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
                unit1_used: self.uses_unit1(),
            },
            summary,
        )
    }
}

/// What [`import`] read.
struct Imported {
    mesh: Mesh,
    format: stl::Format,
    facets_in_file: usize,
    degenerate: usize,
    instance: job::Instance,
}

/// What [`Job::build`] needs besides the mesh.
struct Input {
    file_name: String,
    format: stl::Format,
    facets_in_file: usize,
    degenerate: usize,
    instances: Vec<job::Instance>,
    warnings: Vec<String>,
    /// [`JobInfo::groups`] of the merged mesh (before the repair drops facets).
    groups: Vec<FacetGroup>,
}

/// Import: STL bytes → triangles → welded mesh → rotated, scaled, placed.
fn import(bytes: &[u8], file_name: &str, settings: &Settings) -> Result<Imported, Error> {
    let (tris, format) = import::read_merged(bytes, file_name)?;
    let (mut mesh, degenerate) = Mesh::weld(&tris);
    if mesh.facets.is_empty() {
        return Err(Error::Import(format!(
            "all {} triangles are degenerate (their corners coincide): the mesh has no surface",
            tris.len()
        )));
    }
    let facets_in_file = tris.len();
    drop(tris);
    let placement = mesh::Placement::of_settings(settings);
    let frame = job::Frame::of(mesh.vertices.iter().copied(), &placement)
        .ok_or_else(|| Error::Internal("a mesh with facets has no vertices".into()))?;
    let place = placement.place;
    let name = job::clean_name(&import::stem(file_name));
    let instance = job::Instance {
        part: 0,
        copy: 0,
        copies: 1,
        name,
        file: job::clean_name(file_name),
        item: None,
        object: None,
        rotate: placement.rotate,
        scale: placement.scale,
        place_angle: placement.place_angle,
        placed: true,
        at: place,
        unit: 0,
        matrix: frame.matrix(place),
        min: [
            frame.qmin.x + place[0],
            frame.qmin.y + place[1],
            frame.qmin.z,
        ],
        max: [
            frame.qmax.x + place[0],
            frame.qmax.y + place[1],
            frame.qmax.z,
        ],
        shift: place,
    };
    mesh.transform(settings);
    Ok(Imported {
        mesh,
        format,
        facets_in_file,
        degenerate,
        instance,
    })
}

/// Checks: the part has a height, and not too many layers of it.
fn check_height(size: &[f64; 3], settings: &Settings) -> Result<(), Error> {
    let h = settings.layer_height;
    if size[2] <= 0.0 {
        return Err(Error::NothingToPrint(
            "the part is flat (0 mm tall after rotation): check rotate_x/rotate_y".into(),
        ));
    }
    let layers_needed = size[2] / h;
    if layers_needed > MAX_LAYERS as f64 {
        return Err(Error::Setting {
            name: "layer_height".into(),
            message: format!(
                "the part is {:.1} mm tall: {:.0} layers of {h} mm are more than the {MAX_LAYERS} allowed; check scale_z and layer_height (is the file in micrometres?)",
                size[2], layers_needed
            ),
        });
    }
    Ok(())
}

/// Checks: the mesh encloses a volume, and not one of too many droplets.
fn check_volume(
    mesh: &Mesh,
    shells: &mesh::ShellOrientation,
    size: &[f64; 3],
    settings: &Settings,
) -> Result<(), Error> {
    let volume = mesh.signed_volume().abs().max(shells.closed_volume);
    if size[0] <= 0.0 || size[1] <= 0.0 || volume <= 1e-9 * size[0] * size[1] * size[2] {
        return Err(Error::NothingToPrint(
            "the mesh encloses no volume (a surface without thickness): export the part as a solid"
                .into(),
        ));
    }
    check_droplets(volume, settings)
}

/// Checks the width in droplets; the plane heights of the layers (at least one).
fn plane_heights(size: &[f64; 3], settings: &Settings) -> Result<Vec<f64>, Error> {
    let b = settings.droplet_width();
    let h = settings.layer_height;
    if size[0].max(size[1]) / b > MAX_WIDTH_IN_DROPLETS {
        return Err(Error::Setting {
            name: "scale_x".into(),
            message: format!(
                "the part is {:.0} mm wide, more than {MAX_WIDTH_IN_DROPLETS} droplets of {b:.4} mm; check the scale (is the file in micrometres?)",
                size[0].max(size[1])
            ),
        });
    }
    let zs = slice::layer_heights(size[2], h, settings.slice_plane);
    if zs.is_empty() {
        return Err(Error::NothingToPrint(format!(
            "the part is {:.4} mm tall, less than half a layer ({} mm): scale it up or lower layer_height",
            size[2],
            h / 2.0
        )));
    }
    Ok(zs)
}

/// Mesh repair and index: duplicate facets removed, statistics, the facet index per layer,
/// and a tolerance weld kept if it closes cracks.
fn repair(
    mut mesh: Mesh,
    zs: &[f64],
    mut shells: mesh::ShellOrientation,
    duplicates: usize,
    facets_in_file: usize,
    degenerate: usize,
    groups: &mut [FacetGroup],
) -> (Mesh, FacetBuckets, MeshStats) {
    // The statistics and the facet index are independent: build them side by side.
    let (stats, mut buckets) = both(
        || mesh.stats(facets_in_file, degenerate),
        || FacetBuckets::new(&mesh, zs),
    );
    let mut stats = MeshStats {
        duplicate_facets: duplicates,
        ..stats
    };
    if stats.open_edges > 0 {
        // Cracks between near-coincident corners: try a tolerance weld, keep it if it helps.
        let mut welded = mesh.clone();
        let (merged, kept) = welded.weld_tolerance_kept(WELD_TOLERANCE_MM);
        let dropped = mesh.facets.len() - welded.facets.len();
        let better = welded.stats(facets_in_file, degenerate + dropped);
        if merged > 0 && better.open_edges < stats.open_edges {
            mesh = welded;
            keep_groups(groups, &kept);
            // Shells the weld closed can now be oriented too (the facet index does not depend
            // on the facets' orientation).
            let again = mesh.orient_shells();
            shells.flipped += again.flipped;
            shells.cavities += again.cavities;
            shells.unchecked = shells.unchecked.max(again.unchecked);
            buckets = FacetBuckets::new(&mesh, zs);
            stats = MeshStats {
                tolerance_welded: merged,
                duplicate_facets: duplicates,
                ..better
            };
            if again.flipped > 0 {
                // `better` was measured before these shells were turned.
                stats.signed_volume = mesh.signed_volume();
            }
        }
    }
    stats.flipped_shells = shells.flipped;
    stats.cavity_shells = shells.cavities;
    stats.unchecked_shells = shells.unchecked;
    (mesh, buckets, stats)
}

/// Refuses a job whose estimated volume would take more than [`MAX_DROPLETS`] droplets.
fn check_droplets(volume: f64, settings: &Settings) -> Result<(), Error> {
    let b = settings.droplet_width();
    let droplets = volume / (b * b * settings.layer_height);
    if droplets > MAX_DROPLETS || !droplets.is_finite() {
        return Err(Error::Setting {
            name: "layer_height".into(),
            message: format!(
                "the part ({volume:.0} mm³) would take about {droplets:.1e} droplets of {b:.4} mm, more than the {MAX_DROPLETS:.0e} allowed (the code would be hundreds of gigabytes); use larger droplets (layer_height) or check the scale"
            ),
        });
    }
    Ok(())
}

/// Layers sampled by [`sampled_volume`].
const VOLUME_SAMPLES: usize = 24;

/// The volume the slicer will print, estimated from the sliced area of up to
/// [`VOLUME_SAMPLES`] evenly spaced layers (their mean area × the part's height).
fn sampled_volume(mesh: &Mesh, buckets: &FacetBuckets, zs: &[f64], h: f64) -> f64 {
    let n = zs.len();
    let samples = n.min(VOLUME_SAMPLES);
    let total: f64 = (0..samples)
        .map(|k| {
            let i = (2 * k + 1) * n / (2 * samples);
            geom::region_area(&slice::slice_layer(mesh, buckets.layer(i), zs[i]).region)
        })
        .sum();
    total / samples as f64 * n as f64 * h
}

/// Runs two computations, on two threads natively (wasm workers are single-threaded).
fn both<A: Send, B: Send>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B + Send) -> (A, B) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        std::thread::scope(|scope| {
            let other = scope.spawn(b);
            let first = a();
            (
                first,
                other
                    .join()
                    .unwrap_or_else(|p| std::panic::resume_unwind(p)),
            )
        })
    }
    #[cfg(target_arch = "wasm32")]
    {
        (a(), b())
    }
}

/// Plain-language warnings about the mesh.
fn warnings(m: &MeshStats, size: &[f64; 3]) -> Vec<String> {
    let counted: [(usize, &str, String); 7] = [
        (m.open_edges, "the mesh is not closed: ", " open edges (holes in the surface); open sections are closed by joining their ends".into()),
        (m.nonmanifold_edges, "", " non-manifold edges (shared by more than two facets); overlapping parts are printed as their union".into()),
        (m.misoriented_edges, "", " edges between facets of opposite orientation (flipped facets); loops are oriented by the majority".into()),
        (m.duplicate_facets, "", " duplicate facets were ignored".into()),
        (m.degenerate_facets, "", " degenerate facets (zero area) were ignored".into()),
        (m.tolerance_welded, "", format!(" near-coincident vertices (closer than {WELD_TOLERANCE_MM} mm) were merged to close cracks in the surface")),
        (if m.bodies > 1 { m.bodies } else { 0 }, "", " separate bodies; where they overlap they are printed as one".into()),
    ];
    let mut w: Vec<String> = counted
        .into_iter()
        .filter(|(n, _, _)| *n > 0)
        .map(|(n, before, after)| format!("{before}{n}{after}"))
        .collect();
    if m.flipped_shells > 0 {
        w.push(format!(
            "{} closed shell{} inside out (facets facing inward) and outside every other shell: turned outward and printed as solid",
            m.flipped_shells,
            if m.flipped_shells == 1 { " was" } else { "s were" }
        ));
    }
    if m.cavity_shells > 0 {
        w.push(format!(
            "{} inside-out closed shell{} inside another shell: kept as cavities (hollow inside the part)",
            m.cavity_shells,
            if m.cavity_shells == 1 { " lies" } else { "s lie" }
        ));
    }
    if m.unchecked_shells > 0 {
        w.push(format!(
            "{} inside-out shells were not checked (too many to check quickly) and are sliced as they are",
            m.unchecked_shells
        ));
    }
    if m.signed_volume < 0.0 && m.flipped_shells == 0 {
        w.push("the mesh is inside out (its facets face inward); it is sliced as the solid it encloses".into());
    }
    let largest = size[0].max(size[1]).max(size[2]);
    match suggested_scale(size) {
        Some(f) if f > 1.0 => w.push(format!(
            "the part is only {largest:.3} mm across: if the file is in inches, scale it by {f} (--set scale_x={f} --set scale_y={f} --set scale_z={f})"
        )),
        Some(f) => w.push(format!(
            "the part is {largest:.0} mm across: if the file is in micrometres, scale it by {f} (--set scale_x={f} --set scale_y={f} --set scale_z={f})"
        )),
        None => {}
    }
    w
}

/// Plans every layer in parallel and writes header, layers (ascending) and footer to `out`.
/// The header carries placeholders for the droplet counts (see [`gcode::header`]).
///
/// Worker threads take layers in order from a shared counter and may run at most a window of
/// layers ahead of the writer, so memory is bounded by the mesh plus that window, however tall
/// the part. `progress(done, total)` is called after each written layer.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_gcode<W: std::io::Write + ?Sized>(
    job: &Job,
    out: &mut W,
    progress: impl FnMut(usize, usize),
) -> Result<Summary, Error> {
    write_gcode_with(job, out, progress, &mut ())
}

/// A stage that [`write_gcode_with`] runs on every layer: [`per_layer`](Self::per_layer) on
/// the worker that planned the layer, with the layer's region and its full plan (before the
/// plan's moves are dropped), then [`ordered`](Self::ordered) with its result on the writing
/// thread, in ascending layer order, after the layer's text is written.
pub trait LayerSink {
    /// A worker's own state (one per worker, reused from layer to layer).
    type State: Send;
    /// What a layer hands from its worker to the writing thread.
    type Out: Send;
    /// A new worker's state (made on the writing thread before the workers start).
    fn init(&self) -> Self::State;
    /// On the worker that planned layer `i`.
    fn per_layer(
        state: &mut Self::State,
        i: usize,
        region: &geom::Shapes,
        plan: &LayerPlan,
    ) -> Self::Out;
    /// On the writing thread, layer by layer in ascending order.
    fn ordered(&mut self, i: usize, out: Self::Out);
}

/// No stage.
impl LayerSink for () {
    type State = ();
    type Out = ();
    fn init(&self) {}
    fn per_layer(_: &mut (), _: usize, _: &geom::Shapes, _: &LayerPlan) {}
    fn ordered(&mut self, _: usize, _: ()) {}
}

/// A stage or none (`--report` or not).
impl<S: LayerSink> LayerSink for Option<S> {
    type State = Option<S::State>;
    type Out = Option<S::Out>;
    fn init(&self) -> Self::State {
        self.as_ref().map(S::init)
    }
    fn per_layer(
        state: &mut Self::State,
        i: usize,
        region: &geom::Shapes,
        plan: &LayerPlan,
    ) -> Self::Out {
        state.as_mut().map(|st| S::per_layer(st, i, region, plan))
    }
    fn ordered(&mut self, i: usize, out: Self::Out) {
        if let (Some(s), Some(o)) = (self.as_mut(), out) {
            s.ordered(i, o);
        }
    }
}

/// [`write_gcode`] with a [`LayerSink`] run on every layer. The code written is the same as
/// [`write_gcode`]'s.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_gcode_with<W, K>(
    job: &Job,
    out: &mut W,
    mut progress: impl FnMut(usize, usize),
    sink: &mut K,
) -> Result<Summary, Error>
where
    W: std::io::Write + ?Sized,
    K: LayerSink,
{
    use std::collections::{BTreeMap, HashMap};
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::{Condvar, Mutex, MutexGuard};

    fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
        m.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// A layer's text, plan (without its moves), sink output, and first and last unit.
    type Done<T> = Result<(String, LayerPlan, T, Option<u8>, Option<u8>), String>;
    struct Shared<T> {
        done: BTreeMap<usize, Done<T>>,
        written: usize,
    }
    let io = |e: std::io::Error| Error::Io(format!("cannot write the code: {e}"));
    out.write_all(job.header(None).as_bytes()).map_err(io)?;
    let n = job.layer_count();
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(n.max(1));
    let window = 4 * threads + 4;
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let shared = Mutex::new(Shared {
        done: BTreeMap::new(),
        written: 0,
    });
    let changed = Condvar::new();
    // Each layer's region, from its worker to the worker of the layer above (the overhang
    // needs it; slicing it again cost about a fifth of the time). `None`: its worker failed.
    let regions: Mutex<HashMap<usize, Option<std::sync::Arc<geom::Shapes>>>> =
        Mutex::new(HashMap::new());
    let published = Condvar::new();
    let needs_below = job.needs_below();
    let mut summary = Summary::default();
    // The unit selected after the layers written so far (a file starts with unit 0).
    let mut unit = 0u8;
    let states: Vec<K::State> = (0..threads).map(|_| sink.init()).collect();
    std::thread::scope(|scope| -> Result<(), Error> {
        for mut state in states {
            let (next, stop, shared, changed) = (&next, &stop, &shared, &changed);
            let (regions, published) = (&regions, &published);
            scope.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= n {
                        break;
                    }
                    {
                        let mut g = shared.lock().unwrap_or_else(|p| p.into_inner());
                        while i >= g.written + window && !stop.load(Ordering::Relaxed) {
                            g = changed.wait(g).unwrap_or_else(|p| p.into_inner());
                        }
                    }
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    // With support on, the plan comes from the supported pass, which sliced
                    // every layer already: no section here.
                    let section = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        if needs_below {
                            job.section(i)
                        } else {
                            Section::default()
                        }
                    }));
                    if needs_below {
                        let mine = section
                            .as_ref()
                            .ok()
                            .map(|s| std::sync::Arc::new(s.region.clone()));
                        lock(regions).insert(i, mine);
                        published.notify_all();
                    }
                    // The region below from its worker (it took its layer before this one and
                    // publishes it first thing); sliced here if that worker failed or stopped.
                    let below = match i.checked_sub(1) {
                        Some(j) if needs_below => {
                            let mut g = lock(regions);
                            loop {
                                if let Some(r) = g.remove(&j) {
                                    break r;
                                }
                                if stop.load(Ordering::Relaxed) {
                                    break None;
                                }
                                g = published
                                    .wait_timeout(g, std::time::Duration::from_millis(20))
                                    .map_or_else(|p| p.into_inner().0, |r| r.0);
                            }
                        }
                        _ => None,
                    };
                    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        let section = section.unwrap_or_else(|p| std::panic::resume_unwind(p));
                        let (mut p, region) = job.plan_layer_with(i, section, below.as_deref());
                        let text = gcode::layer_text(&p);
                        let extra = K::per_layer(&mut state, i, &region, &p);
                        let units = (p.first_unit(), p.moves.last().map(|m| m.unit));
                        p.moves = Vec::new();
                        (text, p, extra, units.0, units.1)
                    }))
                    .map_err(|e| {
                        e.downcast_ref::<&str>()
                            .map(|s| s.to_string())
                            .or_else(|| e.downcast_ref::<String>().cloned())
                            .unwrap_or_else(|| "a layer could not be planned".into())
                    });
                    let mut g = shared.lock().unwrap_or_else(|p| p.into_inner());
                    g.done.insert(i, result);
                    changed.notify_all();
                }
            });
        }
        let result = (|| {
            for i in 0..n {
                let done = {
                    let mut g = shared.lock().unwrap_or_else(|p| p.into_inner());
                    loop {
                        if let Some(d) = g.done.remove(&i) {
                            g.written = i + 1;
                            changed.notify_all();
                            break d;
                        }
                        g = changed.wait(g).unwrap_or_else(|p| p.into_inner());
                    }
                };
                let (mut text, plan, extra, first, last) =
                    done.map_err(|m| Error::Internal(format!("layer {}: {m}", i + 1)))?;
                // The layer's text has `T` lines only within it; the unit change at its start
                // depends on the layers below.
                if let Some(u) = first
                    && u != unit
                {
                    gcode::insert_unit_line(&mut text, u);
                }
                unit = last.unwrap_or(unit);
                out.write_all(text.as_bytes()).map_err(io)?;
                summary.add(&plan);
                sink.ordered(i, extra);
                progress(i + 1, n);
            }
            Ok(())
        })();
        stop.store(true, Ordering::Relaxed);
        changed.notify_all();
        result
    })?;
    out.write_all(gcode::footer(&summary).as_bytes())
        .map_err(io)?;
    Ok(summary)
}
