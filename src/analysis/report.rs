//! The job's report: part figures, the analysis model, and the per-layer stage the slicing
//! workers run with its ordered half ([`JobAnalysis`], a [`crate::slicing::sink::LayerSink`]).

use super::droplet::{droplet_centres, footprint_diameter, spheroid_half_height};
use super::estimate3d::{GRID3_PER_B, Grid3, HeightMap, slab_voids};
use super::raster::{COLS_PER_ROW, LayerAnalysis, ROWS_PER_B, Raster, Void};
use crate::base::geom::{DVec2, Point, Shapes};
use crate::base::settings::Settings;
use crate::slicing::plan::LayerPlan;
use serde::Serialize;
use std::collections::{BTreeMap, VecDeque};
use std::sync::{Arc, Mutex, MutexGuard};

/// Part-level figures. Areas in mm² summed over layers; volumes in mm³.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct PartAnalysis {
    pub layers: usize,
    pub droplets: u64,
    pub region_area: f64,
    /// Area-weighted coverage over all layers.
    pub coverage: f64,
    pub void_area: f64,
    pub enclosed_void_area: f64,
    pub overfill_area: f64,
    /// The largest connected void of any layer, and its layer (from 0).
    pub largest_void: Option<Void>,
    pub largest_void_layer: Option<usize>,
    pub max_boundary_deviation: f64,
    pub max_deviation_layer: Option<usize>,
    /// The part's volume: each layer's region (exact area) times H.
    pub volume: f64,
    /// Volume of the part no droplet spheroid fills (3D estimate: each slab's void share, sampled
    /// on the 3D grid, times its exact volume).
    pub void_volume: f64,
    /// void_volume / volume.
    pub void_fraction: f64,
    /// The predicted density, %: 100 × (1 − void_fraction), once the 3D estimate has a
    /// volume (`None` for a 2D analysis alone). A geometric estimate from the droplet model
    /// (docs/process.md), not a measured density.
    #[serde(default)]
    pub predicted_density: Option<f64>,
    /// Overhang area summed over the layers, mm².
    #[serde(default)]
    pub unsupported_area: f64,
    /// The largest overhang area of a layer, mm², and its layer (from 0).
    #[serde(default)]
    pub max_unsupported_area: f64,
    #[serde(default)]
    pub max_unsupported_area_layer: Option<usize>,
}

impl PartAnalysis {
    /// Adds one layer's figures (its 3D slab: `slab_volume`, `slab_void`).
    pub fn add(&mut self, l: &LayerAnalysis, slab_volume: f64, slab_void: f64) {
        self.layers += 1;
        self.droplets += l.droplets;
        let covered = self.coverage * self.region_area + l.coverage * l.region_area;
        self.region_area += l.region_area;
        self.coverage = if self.region_area > 0.0 {
            covered / self.region_area
        } else {
            0.0
        };
        self.void_area += l.void_area;
        self.enclosed_void_area += l.enclosed_void_area;
        self.overfill_area += l.overfill_area;
        if let Some(v) = l.largest_void
            && self.largest_void.is_none_or(|b| v.area > b.area)
        {
            self.largest_void = Some(v);
            self.largest_void_layer = Some(l.index);
        }
        if l.boundary_deviation > self.max_boundary_deviation {
            self.max_boundary_deviation = l.boundary_deviation;
            self.max_deviation_layer = Some(l.index);
        }
        self.unsupported_area += l.unsupported_area;
        if l.unsupported_area > self.max_unsupported_area {
            self.max_unsupported_area = l.unsupported_area;
            self.max_unsupported_area_layer = Some(l.index);
        }
        self.volume += slab_volume;
        self.void_volume += slab_void;
        self.update_fraction();
    }

    /// `void_fraction` and `predicted_density` from the volumes.
    pub fn update_fraction(&mut self) {
        let some = self.volume > 0.0;
        self.void_fraction = if some {
            self.void_volume / self.volume
        } else {
            0.0
        };
        self.predicted_density = some.then_some(100.0 * (1.0 - self.void_fraction));
    }
}

/// The whole report of a job: settings, model, part figures and every layer's figures.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub file_name: String,
    pub settings: Settings,
    pub model: Model,
    pub part: PartAnalysis,
    pub layers: Vec<LayerAnalysis>,
}

/// The analysis model as used, for the report.
#[derive(Clone, Debug, Serialize)]
pub struct Model {
    pub footprint: crate::base::settings::Footprint,
    /// Droplet width B, footprint diameter D, spheroid height, mm.
    pub droplet_width: f64,
    pub footprint_diameter: f64,
    pub spheroid_height: f64,
    /// Grid rows and columns, mm; 3D cells, mm.
    pub grid_row: f64,
    pub grid_column: f64,
    pub grid_3d: f64,
    pub description: &'static str,
}

impl Model {
    pub fn new(s: &Settings) -> Model {
        let b = s.droplet_width();
        Model {
            footprint: s.footprint,
            droplet_width: b,
            footprint_diameter: footprint_diameter(s),
            spheroid_height: 2.0 * spheroid_half_height(s),
            grid_row: b / ROWS_PER_B,
            grid_column: b / ROWS_PER_B / COLS_PER_ROW,
            grid_3d: b / GRID3_PER_B,
            description: "2D: each droplet covers a disc of diameter D centred on it; 3D: an oblate spheroid of diameter D and volume B*B*H centred at its layer's mid-height (see docs/quality.md)",
        }
    }
}

/// The per-layer half of the job analysis, for the workers that plan the layers (see
/// [`crate::write_gcode_with`]): [`analyse`](Self::analyse) gives a layer's 2D figures and its
/// spheroid map; [`JobAnalysis`] takes them in layer order and adds the 3D estimate, so no
/// layer is planned twice.
#[derive(Clone, Debug)]
pub struct LayerStage {
    settings: Settings,
    grid: Grid3,
}

/// One layer analysed by a [`LayerStage`]: its 2D figures, and its region and spheroid map
/// waiting for its neighbours' maps (none when the workers compute the slabs, [`Slabs`]).
pub struct AnalysedLayer {
    analysis: LayerAnalysis,
    own: Option<(Shapes, HeightMap)>,
}

/// What a job's analysis needs of the job besides its settings: where the part lies (the 3D
/// grid is fixed to it), how many layers it has, and the model's name for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisGrid {
    /// The least x and y of the placed part's bounding box, mm.
    pub min: Point,
    pub layers: usize,
    pub file_name: String,
}

impl AnalysisGrid {
    /// The 3D grid of the analysis with settings `s`.
    fn grid3(&self, s: &Settings) -> Grid3 {
        let d = footprint_diameter(s);
        Grid3 {
            origin: DVec2::new(self.min[0] - d, self.min[1] - d),
            cell: s.droplet_width() / GRID3_PER_B,
        }
    }
}

impl LayerStage {
    pub fn new(grid: &AnalysisGrid, settings: &Settings) -> LayerStage {
        LayerStage {
            settings: settings.clone(),
            grid: grid.grid3(settings),
        }
    }

    /// Analyses layer `plan.index` against its `region`, in `raster`'s memory (one raster per
    /// worker, reused from layer to layer).
    pub fn analyse(&self, raster: &mut Raster, region: &Shapes, plan: &LayerPlan) -> AnalysedLayer {
        let (analysis, map) = self.analyse_2d(raster, region, plan);
        AnalysedLayer {
            analysis,
            own: Some((region.clone(), map)),
        }
    }

    /// The layer's 2D figures and its spheroid map.
    fn analyse_2d(
        &self,
        raster: &mut Raster,
        region: &Shapes,
        plan: &LayerPlan,
    ) -> (LayerAnalysis, HeightMap) {
        let s = &self.settings;
        let centres = droplet_centres(plan, s.droplet_width());
        raster.rebuild(plan.index, plan.z, &centres, region, s);
        let mut analysis = raster.analysis();
        analysis.unsupported_area = plan.unsupported_area;
        let map = HeightMap::new(&centres, &self.grid, footprint_diameter(s));
        (analysis, map)
    }

    /// Slab `i`'s 3D estimate: (its exact volume, its void volume), the void share sampled on
    /// the grid.
    fn slab(
        &self,
        analysis: &LayerAnalysis,
        region: &Shapes,
        maps: [Option<&HeightMap>; 3],
    ) -> (f64, f64) {
        let s = &self.settings;
        let Some(this) = maps[1] else {
            return (analysis.region_area * s.layer_height, 0.0);
        };
        let (vol, void) = slab_voids(region, &self.grid, maps[0], this, maps[2], s);
        let exact = analysis.region_area * s.layer_height;
        let void = if vol > 0.0 { void / vol * exact } else { 0.0 };
        (exact, void)
    }
}

/// The slabs' 3D estimate in the slicing workers (natively, with [`crate::write_gcode_with`]):
/// each worker publishes its layer's region and spheroid map here, and the worker that
/// publishes the last of the three maps a slab needs (layers i − 1, i, i + 1) computes it,
/// so the writing thread only adds the figures up. A map is dropped once its three slabs are
/// done; the workers run at most a window of layers ahead of the writing thread, so only
/// that many maps are held.
#[derive(Default)]
pub struct Slabs {
    n: usize,
    maps: Vec<Option<Arc<HeightMap>>>,
    /// Each layer's region and 2D figures, until its slab is done.
    layers: Vec<Option<(Shapes, LayerAnalysis)>>,
    claimed: Vec<bool>,
    /// Slabs not yet done that use each map.
    uses: Vec<u8>,
    /// Slabs done and not yet taken: layer → (volume, void volume).
    done: BTreeMap<usize, (f64, f64)>,
}

/// What a worker claims: a slab, its layer's region and figures and the three maps.
type Claim = (usize, Shapes, LayerAnalysis, [Option<Arc<HeightMap>>; 3]);

impl Slabs {
    fn new(n: usize) -> Slabs {
        Slabs {
            n,
            maps: (0..n).map(|_| None).collect(),
            layers: (0..n).map(|_| None).collect(),
            claimed: vec![false; n],
            uses: (0..n)
                .map(|k| (k.saturating_sub(1)..(k + 2).min(n)).len() as u8)
                .collect(),
            done: BTreeMap::new(),
        }
    }

    /// The layers of slab `j` (those in the job).
    fn around(&self, j: usize) -> std::ops::Range<usize> {
        j.saturating_sub(1)..(j + 2).min(self.n)
    }

    /// Publishes layer `i`; returns the slabs it completes, claimed for the caller.
    fn publish(
        &mut self,
        i: usize,
        region: Shapes,
        analysis: LayerAnalysis,
        map: HeightMap,
    ) -> Vec<Claim> {
        if i >= self.n {
            return Vec::new();
        }
        self.maps[i] = Some(Arc::new(map));
        self.layers[i] = Some((region, analysis));
        let mut claims = Vec::new();
        for j in self.around(i) {
            let ready = !self.claimed[j] && self.around(j).all(|k| self.maps[k].is_some());
            if !ready {
                continue;
            }
            let Some((region, analysis)) = self.layers[j].take() else {
                continue;
            };
            self.claimed[j] = true;
            let map =
                |k: Option<usize>| k.filter(|&k| k < self.n).and_then(|k| self.maps[k].clone());
            claims.push((
                j,
                region,
                analysis,
                [map(j.checked_sub(1)), map(Some(j)), map(Some(j + 1))],
            ));
        }
        claims
    }

    /// Slab `j` is done: keeps its figures, drops the maps no slab needs any more.
    fn complete(&mut self, j: usize, figures: (f64, f64)) {
        self.done.insert(j, figures);
        for k in self.around(j) {
            self.uses[k] = self.uses[k].saturating_sub(1);
            if self.uses[k] == 0 {
                self.maps[k] = None;
            }
        }
    }
}

fn lock(m: &Mutex<Slabs>) -> MutexGuard<'_, Slabs> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// The ordered half of the job analysis: takes every layer's [`AnalysedLayer`] in ascending
/// order, adds each slab's 3D estimate once its neighbours are in (computing it here, or
/// taking it from the workers, [`Slabs`]), and gives the [`Report`]. Keeps two layers' maps
/// at a time when it computes the slabs itself.
pub struct JobAnalysis {
    stage: LayerStage,
    file_name: String,
    part: PartAnalysis,
    layers: Vec<LayerAnalysis>,
    below: Option<HeightMap>,
    current: Option<AnalysedLayer>,
    /// The slabs the workers compute, and the layers waiting for theirs, in order.
    slabs: Arc<Mutex<Slabs>>,
    waiting: VecDeque<LayerAnalysis>,
}

impl JobAnalysis {
    /// The analysis of a job of `grid.layers` layers, sliced with `settings`.
    pub fn new(grid: &AnalysisGrid, settings: &Settings) -> JobAnalysis {
        JobAnalysis {
            stage: LayerStage::new(grid, settings),
            file_name: grid.file_name.clone(),
            part: PartAnalysis::default(),
            layers: Vec::with_capacity(grid.layers),
            below: None,
            current: None,
            slabs: Arc::new(Mutex::new(Slabs::new(grid.layers))),
            waiting: VecDeque::new(),
        }
    }

    /// The stage for the workers.
    pub fn stage(&self) -> LayerStage {
        self.stage.clone()
    }

    /// The next layer (layers must come in ascending order, from 0).
    pub fn push(&mut self, layer: AnalysedLayer) {
        match &layer.own {
            Some((_, map)) => {
                self.close(Some(map));
                self.below = self.current.take().and_then(|c| c.own.map(|o| o.1));
                self.current = Some(layer);
            }
            // Its slab comes from the workers.
            None => {
                self.waiting.push_back(layer.analysis);
                self.take_slabs(false);
            }
        }
    }

    /// Adds the waiting layers whose slabs the workers have done, in order; with `all`, every
    /// waiting layer (after the last one: a slab no worker did, which only a failed layer
    /// leaves, is computed here from the maps there are).
    fn take_slabs(&mut self, all: bool) {
        let slabs = self.slabs.clone();
        let mut board = lock(&slabs);
        while let Some(analysis) = self.waiting.front() {
            let j = self.layers.len();
            let figures = match board.done.remove(&j) {
                Some(f) => f,
                None if all => {
                    let map = |k: usize| board.maps.get(k).cloned().flatten();
                    let maps = [j.checked_sub(1).and_then(map), map(j), map(j + 1)];
                    let region = board.layers.get_mut(j).and_then(Option::take);
                    let region = region.map(|r| r.0).unwrap_or_default();
                    self.stage.slab(
                        analysis,
                        &region,
                        [maps[0].as_deref(), maps[1].as_deref(), maps[2].as_deref()],
                    )
                }
                None => break,
            };
            let analysis = self.waiting.pop_front().expect("a waiting layer");
            self.part.add(&analysis, figures.0, figures.1);
            self.layers.push(analysis);
        }
    }

    /// The 3D estimate of the current layer, with `above` (the next layer's map, if any).
    fn close(&mut self, above: Option<&HeightMap>) {
        let Some(cur) = &self.current else { return };
        let Some((region, map)) = &cur.own else {
            return;
        };
        let (exact, void) = self.stage.slab(
            &cur.analysis,
            region,
            [self.below.as_ref(), Some(map), above],
        );
        self.part.add(&cur.analysis, exact, void);
        self.layers.push(cur.analysis.clone());
    }

    /// The report, after the last layer.
    pub fn finish(mut self) -> Report {
        self.close(None);
        self.take_slabs(true);
        Report {
            file_name: self.file_name,
            model: Model::new(&self.stage.settings),
            settings: self.stage.settings,
            part: self.part,
            layers: self.layers,
        }
    }
}

/// The job analysis as a stage of [`crate::write_gcode_with`]: each worker analyses the layers
/// it plans in its own [`Raster`] and computes the slabs its layer completes ([`Slabs`]); the
/// layers are pushed in order.
impl crate::slicing::sink::LayerSink for JobAnalysis {
    type State = (Raster, LayerStage, Arc<Mutex<Slabs>>);
    type Out = AnalysedLayer;

    fn init(&self) -> Self::State {
        (Raster::empty(), self.stage(), self.slabs.clone())
    }

    fn per_layer(
        (raster, stage, slabs): &mut Self::State,
        i: usize,
        region: &Shapes,
        plan: &LayerPlan,
    ) -> AnalysedLayer {
        let (analysis, map) = stage.analyse_2d(raster, region, plan);
        let claims = lock(slabs).publish(i, region.clone(), analysis.clone(), map);
        for (j, region, analysis, maps) in claims {
            let maps = [maps[0].as_deref(), maps[1].as_deref(), maps[2].as_deref()];
            let figures = stage.slab(&analysis, &region, maps);
            lock(slabs).complete(j, figures);
        }
        AnalysedLayer {
            analysis,
            own: None,
        }
    }

    fn ordered(&mut self, _: usize, layer: AnalysedLayer) {
        self.push(layer);
    }
}
