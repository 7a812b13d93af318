//! Building a [`Job`]: from one file, from a build job's parts, or from a mesh another job
//! prepared; the checks that need the plane heights and the facet index (the width in
//! droplets, the droplet estimate).

use crate::base::error::Error;
use crate::base::parallel::both;
use crate::base::settings::Settings;
use crate::base::steps::{self, Budget};
use crate::model::fit;
use crate::model::layout::{Frame, Instance, at_part, place_instances, shown_name};
use crate::model::mesh::{self, Mesh, MeshStats};
use crate::model::models::{
    MAX_JOB_TRIANGLES, Model, check_job_triangles, models_of, too_many_triangles,
};
use crate::model::prepare::{
    Bodies, FacetGroup, Imported, Input, JobInfo, bodies_warning, check_chamber, check_height,
    check_surface, check_volume, close_cracks, import, keep_groups, part_bodies, suggested_scale,
    warnings,
};
use crate::model::shells::{ShellOrientation, Shells};
use crate::model::spec as job;
use crate::pipeline::handoff::{Draft, DraftTo};
use crate::pipeline::{Job, budget};
use crate::slicing::slice::{self, FacetBuckets};
use std::cell::Cell;

impl Job {
    /// Reads the model (STL, OBJ or a 3MF build, see [`import`]), validates the settings and
    /// places the part: import → checks → mesh repair → facet index. A 3MF build's items keep
    /// their relative positions and are sliced together.
    pub fn new(model_bytes: &[u8], file_name: &str, settings: Settings) -> Result<Job, Error> {
        settings.validate()?;
        let part: Imported = import(model_bytes, file_name, &settings)?;
        let input = Input {
            file_name: file_name.to_string(),
            format: part.format,
            facets_in_file: part.facets_in_file,
            degenerate: part.degenerate,
            instances: vec![part.instance],
            warnings: Vec::new(),
            misfits: part.misfit.into_iter().collect(),
            hint: fit::Hint::Set,
            bodies: Bodies::Whole(job::clean_name(file_name)),
            groups: Vec::new(),
        };
        Job::build(part.mesh, input, settings)
    }

    /// A build job (docs/spec.md "Build jobs"): reads each file of `files` (name, bytes) once and
    /// builds the job of `spec` from them (see [`Job::from_models`]).
    pub fn from_parts(files: &[(&str, &[u8])], spec: &job::JobSpec) -> Result<Job, Error> {
        let models = files
            .iter()
            .map(|(name, bytes)| Model::read(bytes, name))
            .collect::<Result<Vec<_>, _>>()?;
        Job::from_models(&models, spec)
    }

    /// A build job from imported files: every part welded once, each instance placed (the
    /// arrangement of [`place_instances`]) with [`Mesh::place`] — the very transform of
    /// [`Job::new`] — the instances merged into one mesh and prepared as [`Job::new`] does
    /// (checks, shells, repair, facet index). The job's settings are `spec.settings`.
    pub fn from_models(models: &[Model], spec: &job::JobSpec) -> Result<Job, Error> {
        let (mesh, input, settings) = steps::now(Job::merged(models, spec, &steps::UNLIMITED))?;
        Job::build(mesh, input, settings)
    }

    /// [`Job::from_models`] as a pass of `b`'s budget: the passes of [`Job::build`] one after
    /// the other (not side by side), each in runs of items; the draft handed to `draft`, and
    /// whether the job is the draft's set into `drafted` at the end.
    pub(super) async fn build_in_steps(
        models: &[Model],
        spec: &job::JobSpec,
        b: &Budget,
        draft: Option<DraftTo>,
        drafted: &Cell<Option<bool>>,
    ) -> Result<Job, Error> {
        let (mesh, input, settings) = Job::merged(models, spec, b).await?;
        b.enter("bounds and planes");
        let mut building = Building::new(mesh, input, settings)?;
        // The facet index of the mesh as merged (dropped below if facets are); with it the
        // draft: the mesh, its planes, index and units' facet runs. The passes below change
        // the mesh only where they drop repeated facets, close cracks or turn shells.
        let mut draft_of = None;
        if let Ok(zs) = &building.made.zs {
            let m = &building.made;
            b.enter("facet index");
            let index = FacetBuckets::new_in_steps(&m.mesh, zs, b).await;
            if let Some(to) = draft {
                // the draft handed out in steps of its own
                b.end_step().await;
                b.enter("draft");
                let d = Draft {
                    settings: &m.settings,
                    info: m.provisional_info(zs.len()),
                    mesh: &m.mesh,
                    zs,
                    index: &index,
                };
                d.hand_to(to, b).await;
                draft_of = Some((zs.clone(), m.groups.clone()));
                b.end_step().await;
            }
            building.made.index = Some(index);
        }
        let mut changed = false;
        b.enter("repeated facets");
        let kept = building.made.mesh.unrepeated_in_steps(b).await;
        changed |= kept.iter().any(|&k| !k);
        let all = kept.iter().all(|&k| k);
        let shells = match all {
            true => {
                b.enter("shells");
                Some(building.made.mesh.shells_in_steps(b).await)
            }
            false => None,
        };
        building.unrepeated_in_steps(kept, shells, b).await;
        b.enter("cracks");
        building.close_cracks();
        changed |= building.made.weld != (0, 0);
        let shells = building.shells.as_ref().expect("the shells were found");
        b.enter("orientation");
        let orientation = building.made.mesh.orientation_in_steps(shells, b).await;
        changed |= orientation.1.iter().any(|&f| f);
        if orientation.1.is_empty() {
            b.enter("statistics");
            let (facets_in_file, dropped) =
                (building.made.input.facets_in_file, building.dropped());
            building.made.stats = Some(
                building
                    .made
                    .mesh
                    .stats_in_steps(facets_in_file, dropped, b)
                    .await,
            );
        }
        building.orientation = Some(orientation);
        b.enter("checks");
        let mut checked = building.checked()?;
        b.enter("overhangs");
        let overhangs = checked.overhangs_in_steps(b).await;
        let (made_stats, made_index) = (checked.made.stats.take(), checked.made.index.take());
        let repaired = match checked.made.zs.as_ref() {
            Ok(zs) => {
                let (mesh, input) = (&checked.made.mesh, &checked.made.input);
                let stats = match made_stats {
                    Some(s) => s,
                    None => {
                        b.enter("statistics");
                        let dropped = input.degenerate + checked.made.weld.1;
                        mesh.stats_in_steps(input.facets_in_file, dropped, b).await
                    }
                };
                let buckets = match made_index {
                    Some(index) => index,
                    None => {
                        b.enter("facet index");
                        FacetBuckets::new_in_steps(mesh, zs, b).await
                    }
                };
                Some((buckets, stats))
            }
            Err(_) => None,
        };
        b.enter("estimate");
        let job = checked.conclude(overhangs, repaired)?;
        if let Some((zs, groups)) = draft_of {
            drafted.set(Some(!changed && job.zs == zs && job.info.groups == groups));
        }
        Ok(job)
    }

    /// The parts of `spec` welded, placed and merged into one mesh: what [`Job::build`]
    /// prepares. The weld in runs of `budget` (natively, of no limit: in two halves side by
    /// side where [`Mesh::weld`] does).
    async fn merged(
        models: &[Model],
        spec: &job::JobSpec,
        budget: &Budget,
    ) -> Result<(Mesh, Input, Settings), Error> {
        budget.enter("job");
        spec.validate()?;
        let settings = spec.settings.clone();
        let by_part = models_of(models, spec)?;
        // Before any part is welded: a small 3MF may instance millions of triangles per part.
        check_job_triangles(models, spec)?;
        // Runs of consecutive parts of one unit (docs/spec.md "Discharge units": where
        // parts of different units overlap, the part listed first keeps the overlap).
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
            let tris = m.triangles(p.item).map_err(|e| at_part(i, e))?;
            budget.enter("weld");
            let (mesh, dropped) = match budget.limited() {
                true => Mesh::weld_in_steps(&tris, budget).await,
                false => Mesh::weld(&tris),
            };
            let copies = p.copies as usize;
            facets = facets.saturating_add(mesh.facets.len().saturating_mul(copies));
            if facets > MAX_JOB_TRIANGLES {
                return Err(too_many_triangles());
            }
            budget.enter("frame");
            let frame = Frame::of_in_steps(
                &mesh.vertices,
                |v| [*v],
                &p.placement([0.0, 0.0], &settings),
                budget,
            )
            .await;
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
        budget.enter("layout and merge");
        let layout = place_instances(&by_part, spec, &frames)?;
        // A job of one instance counts the bodies of its prepared mesh; a job of several, each
        // part's own (two files are two parts, not one part of two bodies).
        let bodies = if layout.instances.len() == 1 {
            let p = &spec.parts[0];
            Bodies::Whole(shown_name(by_part[0], p))
        } else {
            let mut named: Vec<(String, usize)> = Vec::new();
            for (i, p) in spec.parts.iter().enumerate() {
                let name = shown_name(by_part[i], p);
                if !named.iter().any(|(n, _)| *n == name) {
                    named.push((name, part_bodies(&welded[i])));
                }
            }
            Bodies::Parts(named)
        };
        // The instances run by run (a job of unit 0 alone: one run, in the layout's order).
        let mut order: Vec<&Instance> = layout.instances.iter().collect();
        order.sort_by_key(|inst| run_of[inst.id.part]);
        // Each instance's vertices are placed where they land in the merged mesh; a job of
        // one instance takes its part's welded mesh as it is: no copy of the mesh, which on a
        // million facets is 24 MB a copy (a page worker's memory never shrinks).
        let mut groups: Vec<FacetGroup> = Vec::new();
        let mut add_to_run = |part: usize, count: usize| {
            // Runs are numbered from 0 in order: run r is the (r + 1)-th group.
            match groups.get_mut(run_of[part]) {
                Some(g) => g.facets += count,
                None => groups.push(FacetGroup {
                    facets: count,
                    unit: spec.parts[part].unit,
                }),
            }
        };
        let mesh = if let [only] = order[..] {
            let mut mesh = std::mem::take(&mut welded[only.id.part]);
            let placement = spec.parts[only.id.part].placement(only.shift, &settings);
            mesh::place_vertices_in_steps(&mut mesh.vertices, &placement, budget).await;
            if placement.mirrors() {
                mesh::turn_facets(&mut mesh.facets);
            }
            add_to_run(only.id.part, mesh.facets.len());
            mesh
        } else {
            let vertices: usize = order.iter().map(|x| welded[x.id.part].vertices.len()).sum();
            let mut mesh = Mesh {
                vertices: Vec::with_capacity(vertices),
                facets: Vec::with_capacity(facets),
            };
            for inst in order {
                let part = &welded[inst.id.part];
                let base = mesh.vertices.len();
                let first = mesh.facets.len();
                mesh.vertices.extend_from_slice(&part.vertices);
                mesh.facets
                    .extend(part.facets.iter().map(|f| f.map(|v| v + base as u32)));
                let placement = spec.parts[inst.id.part].placement(inst.shift, &settings);
                mesh::place_vertices_in_steps(&mut mesh.vertices[base..], &placement, budget).await;
                if placement.mirrors() {
                    mesh::turn_facets(&mut mesh.facets[first..]);
                }
                add_to_run(inst.id.part, part.facets.len());
            }
            mesh
        };
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
            misfits: layout.misfits,
            hint: fit::Hint::Parts,
            bodies,
            groups,
        };
        Ok((mesh, input, settings))
    }

    /// The common tail of [`Job::new`] and [`Job::from_models`]: checks → shells → mesh repair
    /// → facet index.
    fn build(mesh: Mesh, input: Input, settings: Settings) -> Result<Job, Error> {
        let mut b = Building::new(mesh, input, settings)?;
        // Repeated facets first (they would make a shell's edges look non-manifold), then
        // cracks (a tolerance weld, kept if it closes some), then every shell as its author
        // meant it (inside-out shells turned outward, cavities kept), so the volume below
        // counts what will be printed: shells of opposite orientation can no longer cancel.
        // The facet index beside the repeated facets and the shells, and the statistics
        // beside the shells' orientation: each reads the mesh as it is then, which the steps
        // beside it leave as it is on a sound mesh (the index needs only the vertices and the
        // facets' numbers, which turning a shell keeps). Where facets are dropped, the cracks
        // closed or a shell is turned, they are made again from the changed mesh (the job is
        // checked before the index is used). [`Preparation`] runs the same passes one by one.
        let mesh = &b.made.mesh;
        let zs = &b.made.zs;
        let ((kept, mesh_shells), index) = both(
            || {
                let kept = mesh.unrepeated_facets();
                let shells = kept.iter().all(|&k| k).then(|| mesh.shells());
                (kept, shells)
            },
            || zs.as_ref().ok().map(|zs| FacetBuckets::new(mesh, zs)),
        );
        b.made.index = index;
        b.unrepeated(kept, mesh_shells);
        b.close_cracks();
        let shells = b.shells.as_ref().expect("the shells were found");
        let mesh = &b.made.mesh;
        let dropped = b.dropped();
        let facets_in_file = b.made.input.facets_in_file;
        let (orientation, stats) = both(
            || mesh.orientation(shells),
            || mesh.stats(facets_in_file, dropped),
        );
        b.made.stats = (orientation.1.is_empty()).then_some(stats);
        b.orientation = Some(orientation);
        b.finish()
    }

    /// The common tail of [`Job::new`] and [`Job::from_models`].
    pub(super) fn assemble(
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
            rims: std::sync::OnceLock::new(),
        }
    }
}

/// What a job being prepared carries through [`Building`] and [`Checked`]: the merged mesh,
/// the job's input and settings, and what the passes found of them.
struct Made {
    mesh: Mesh,
    input: Input,
    settings: Settings,
    groups: Vec<FacetGroup>,
    bounds: mesh::Bounds,
    size: [f64; 3],
    zs: Result<Vec<f64>, Error>,
    /// Facets dropped as repeats.
    duplicates: usize,
    /// The facet index of the mesh as it is (dropped when the mesh changes).
    index: Option<FacetBuckets>,
    /// What the tolerance weld did (see [`close_cracks`]).
    weld: (usize, usize),
    /// The statistics of the mesh as it is, when no shell is to be turned.
    stats: Option<MeshStats>,
}

impl Made {
    /// The info of a [`Draft`] of `layers` layers: what its layers need (the box, the
    /// instances, the units' facet runs); no mesh statistics, warnings or profiles yet.
    fn provisional_info(&self, layers: usize) -> JobInfo {
        JobInfo {
            file_name: self.input.file_name.clone(),
            format: self.input.format,
            warnings: Vec::new(),
            suggested_scale: None,
            mesh: MeshStats::default(),
            bounds: self.bounds,
            layers,
            droplet_width: self.settings.droplet_width(),
            instances: self.input.instances.clone(),
            groups: self.groups.clone(),
            profiles: Vec::new(),
        }
    }

    /// The job of this mesh with its facet index and statistics (`buckets`, `stats`), once
    /// the plate rule and the chamber allow it (checked after the job's size and droplets, so
    /// those speak first): its info with every warning.
    fn into_job(self, buckets: FacetBuckets, stats: MeshStats) -> Result<Job, Error> {
        let zs = self.zs?;
        let (input, settings, size) = (self.input, self.settings, self.size);
        if let Some(e) = fit::refusal(&input.misfits, &settings, input.hint) {
            return Err(e);
        }
        check_chamber(&size, &settings)?;
        let mut all_warnings = input.warnings;
        all_warnings.extend(input.misfits.into_iter().map(|m| m.message));
        let bodies = match input.bodies {
            Bodies::Whole(name) => vec![(name, stats.bodies)],
            Bodies::Parts(parts) => parts,
        };
        all_warnings.extend(bodies.iter().filter_map(|(n, b)| bodies_warning(n, *b)));
        all_warnings.extend(warnings(&stats, &size));
        let info = JobInfo {
            file_name: input.file_name,
            format: input.format,
            warnings: all_warnings,
            suggested_scale: suggested_scale(&size),
            mesh: stats,
            bounds: self.bounds,
            layers: zs.len(),
            droplet_width: settings.droplet_width(),
            instances: input.instances,
            groups: self.groups,
            profiles: Vec::new(),
        };
        Ok(Job::assemble(settings, self.mesh, buckets, zs, info))
    }
}

/// A job being prepared: the merged mesh and what the passes of [`Job::build`] found so far.
struct Building {
    made: Made,
    shells: Option<Shells>,
    orientation: Option<(ShellOrientation, Vec<bool>)>,
}

impl Building {
    /// The checks of the mesh's size; the plane heights (an error that the checks of the
    /// droplets should speak before is kept for later).
    fn new(mesh: Mesh, mut input: Input, settings: Settings) -> Result<Building, Error> {
        let bounds = mesh.bounds();
        let size = bounds.size();
        check_height(&size, &settings)?;
        let zs = budget::plane_heights(&size, &settings);
        let groups = std::mem::take(&mut input.groups);
        Ok(Building {
            made: Made {
                mesh,
                input,
                settings,
                groups,
                bounds,
                size,
                zs,
                duplicates: 0,
                index: None,
                weld: (0, 0),
                stats: None,
            },
            shells: None,
            orientation: None,
        })
    }

    /// Takes the repeated facets' pass (`kept`) and the shells found beside it (only when
    /// nothing was repeated); else drops the repeats and finds the shells of what is left.
    fn unrepeated(&mut self, kept: Vec<bool>, shells: Option<Shells>) {
        steps::now(self.unrepeated_in_steps(kept, shells, &steps::UNLIMITED))
    }

    /// [`Building::unrepeated`] in resumable steps.
    async fn unrepeated_in_steps(&mut self, kept: Vec<bool>, shells: Option<Shells>, b: &Budget) {
        self.made.duplicates = kept.iter().filter(|&&k| !k).count();
        self.shells = Some(match shells {
            Some(shells) => shells,
            None => {
                self.made.index = None;
                self.made.mesh.keep_facets(&kept);
                keep_groups(&mut self.made.groups, &kept);
                self.made.mesh.shells_in_steps(b).await
            }
        });
    }

    fn close_cracks(&mut self) {
        let shells = self.shells.take().expect("the shells were found");
        let (shells, weld) = close_cracks(&mut self.made.mesh, shells, &mut self.made.groups);
        self.shells = Some(shells);
        self.made.weld = weld;
        if weld != (0, 0) {
            self.made.index = None;
        }
    }

    /// Facets dropped: degenerate ones and those the weld dropped.
    fn dropped(&self) -> usize {
        self.made.input.degenerate + self.made.weld.1
    }

    /// Turns the shells, checks the volume and the droplets, and makes what was not made
    /// (or was made of a mesh that changed since): the job.
    fn finish(self) -> Result<Job, Error> {
        let mut c = self.checked()?;
        // The support's overhang figures for the estimate beside what is left of the
        // statistics and the facet index.
        let (stats, index) = (c.made.stats.take(), c.made.index.take());
        let (overhangs, repaired) = both(
            || c.overhangs(),
            || {
                let zs = c.made.zs.as_ref().ok()?;
                let dropped = c.made.input.degenerate + c.made.weld.1;
                let mesh = &c.made.mesh;
                let facets_in_file = c.made.input.facets_in_file;
                let (stats, buckets) = both(
                    || stats.unwrap_or_else(|| mesh.stats(facets_in_file, dropped)),
                    || index.unwrap_or_else(|| FacetBuckets::new(mesh, zs)),
                );
                Some((buckets, stats))
            },
        );
        c.conclude(overhangs, repaired)
    }

    /// Turns the shells and checks the volume and the surface: what [`Checked::conclude`]
    /// finishes.
    fn checked(self) -> Result<Checked, Error> {
        let Building {
            mut made,
            shells: mesh_shells,
            orientation,
        } = self;
        let mesh_shells = mesh_shells.expect("the shells were found");
        let open_edges = mesh_shells.open_edges;
        let (shells, flip) = orientation.expect("the shells were oriented");
        made.mesh.turn(&mesh_shells, &flip);
        drop(mesh_shells);
        let volume = check_volume(&made.mesh, &shells, &made.size)?;
        // A triangle soup is refused before any section of it is made.
        check_surface(open_edges, made.mesh.facets.len())?;
        Ok(Checked {
            made,
            shells,
            volume,
        })
    }
}

/// A job whose mesh is turned and checked ([`Building::checked`]): what is left to make is
/// the overhang figures, the statistics and the facet index (those not made yet).
struct Checked {
    made: Made,
    shells: ShellOrientation,
    volume: f64,
}

impl Checked {
    /// The support's overhang figures for the estimate (none when the support is off or the
    /// mesh is open).
    fn overhangs(&self) -> budget::Overhangs {
        steps::now(self.overhangs_in_steps(&steps::UNLIMITED))
    }

    /// [`Checked::overhangs`] in resumable steps.
    async fn overhangs_in_steps(&self, b: &Budget) -> budget::Overhangs {
        let support = self.shells.open == 0
            && self.made.settings.support != crate::base::settings::Support::Off;
        if support {
            let h = self.made.settings.layer_height;
            budget::Overhangs::of_in_steps(
                &self.made.mesh,
                &slice::layer_heights(self.made.size[2], h, self.made.settings.slice_plane),
                b,
            )
            .await
        } else {
            budget::Overhangs::default()
        }
    }

    /// Checks the droplets and the plate, and makes the job of the facet index and the
    /// statistics (`repaired`, none when the layers are not known).
    fn conclude(
        self,
        overhangs: budget::Overhangs,
        repaired: Option<(FacetBuckets, MeshStats)>,
    ) -> Result<Job, Error> {
        let Checked {
            made,
            shells,
            volume,
        } = self;
        let repaired = repaired.map(|(b, s)| {
            let s = with_repairs(s, &shells, made.weld, made.duplicates);
            (b, s)
        });
        // One droplet estimate for the whole job: every unit and the support.
        let (mesh, settings, size) = (&made.mesh, &made.settings, &made.size);
        let parts = budget::UnitParts::of(mesh, &made.groups);
        let open = shells.open > 0;
        let instances = &made.input.instances;
        let mut estimate =
            budget::Estimate::new(volume, &parts, open, size, instances, &overhangs, settings);
        estimate.check(settings)?;
        let zs = made.zs.as_ref().map_err(Error::clone)?;
        let (buckets, stats) = repaired.ok_or_else(|| {
            Error::Internal("the facet index was not built though the layers are known".into())
        })?;
        if shells.open > 0 {
            // Open shells enclose no definite volume: estimate what will be printed from the
            // sliced area of sampled layers (the slicer closes open sections the same way).
            let h = settings.layer_height;
            estimate.unit_volumes[0] = budget::sampled_volume(mesh, &buckets, zs, h);
            estimate.check(settings)?;
        }
        made.into_job(buckets, stats)
    }
}

/// The mesh statistics with what the repair did.
fn with_repairs(
    stats: MeshStats,
    shells: &ShellOrientation,
    (welded, _): (usize, usize),
    duplicates: usize,
) -> MeshStats {
    MeshStats {
        duplicate_facets: duplicates,
        tolerance_welded: welded,
        flipped_shells: shells.flipped,
        flipped_open_shells: shells.flipped_open,
        cavity_shells: shells.cavities,
        unchecked_shells: shells.unchecked,
        ..stats
    }
}
