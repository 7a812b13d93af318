//! The job's report: part figures, the analysis model, and the per-layer stage the slicing
//! workers run with its ordered half ([`JobAnalysis`], a [`crate::slicing::sink::LayerSink`]).

use super::droplet::{footprint_diameter, spheroid_half_height, unit_part_centres};
use super::estimate3d::{
    Blocks, GRID3_PER_B, Grid3, HeightMap, Samples, UnitMap, slab_voids, slab_voids_banded,
};
use super::interior::InteriorCache;
use super::lines::DropletLines;
use super::part::PartAnalysis;
use super::raster::{COLS_PER_ROW, LayerAnalysis, ROWS_PER_B, Raster};
use super::slabs::{self, LayerMaps, SlabFigures, SlabRun, Slabs, UnitRegions};
use crate::base::geom::{DVec2, Point, Shapes, region_area};
use crate::base::settings::{MAX_UNITS, Settings, UnitId};
use crate::slicing::plan::LayerPlan;
use crate::slicing::plan::part_settings;
use serde::Serialize;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// The whole report of a job: settings, model, part figures and every layer's figures.
///
/// In memory its layers are numbered from 0 (as [`LayerAnalysis::index`]); written
/// (`Serialize`, the CLI's `--report`) every layer number — `layers[].index`,
/// `part.largest_void_layer`, `part.max_deviation_layer`, `part.max_unsupported_area_layer` —
/// counts from 1, as the G-code's layer comments, the summary line and the page do
/// (docs/quality.md, *The report*).
#[derive(Clone, Debug)]
pub struct Report {
    pub file_name: String,
    pub settings: Settings,
    pub model: Model,
    pub part: PartAnalysis,
    pub layers: Vec<LayerAnalysis>,
}

impl Serialize for Report {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Written<'a> {
            file_name: &'a str,
            settings: &'a Settings,
            model: &'a Model,
            part: PartAnalysis,
            layers: Vec<LayerAnalysis>,
        }
        let from_1 = |l: Option<usize>| l.map(|l| l + 1);
        let p = &self.part;
        Written {
            file_name: &self.file_name,
            settings: &self.settings,
            model: &self.model,
            part: PartAnalysis {
                largest_void_layer: from_1(p.largest_void_layer),
                max_deviation_layer: from_1(p.max_deviation_layer),
                max_unsupported_area_layer: from_1(p.max_unsupported_area_layer),
                ..p.clone()
            },
            layers: self
                .layers
                .iter()
                .map(|l| LayerAnalysis {
                    index: l.index + 1,
                    ..l.clone()
                })
                .collect(),
        }
        .serialize(serializer)
    }
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
/// spheroid maps; [`JobAnalysis`] takes them in layer order and adds the 3D estimate, so no
/// layer is planned twice. In a job with parts of other units (other materials), each unit's
/// parts get their own 3D estimate (droplets of B_N on a grid of B_N / 3); the 2D figures are
/// unit 0's.
#[derive(Clone, Debug)]
pub struct LayerStage {
    settings: Settings,
    grid: Grid3,
    /// The other units that print parts: each one's number, part settings and grid.
    others: Vec<(UnitId, Settings, Grid3)>,
    /// Whether the 2D analysis rasterises only a band around each layer's boundary
    /// ([`Raster::rebuild_banded`]), and the 3D estimate fills only the cells near a
    /// boundary of the slab's three layers ([`slab_voids_banded`]); the whole layer (the
    /// reference) when not.
    banded: bool,
    /// What the fill's lattice gives the interior, per kind of layer.
    interior: Arc<InteriorCache>,
    /// Which blocks of the 3D grid sample the interior of the job's layers.
    samples: Samples,
}

/// One layer analysed by a [`LayerStage`]: its 2D figures, and its regions and spheroid maps
/// waiting for its neighbours' maps (none when the workers compute the slabs, [`Slabs`]).
pub struct AnalysedLayer {
    analysis: LayerAnalysis,
    own: Option<(UnitRegions, LayerMaps)>,
}

/// What a job's analysis needs of the job besides its settings: where the part lies (the 3D
/// grid is fixed to it), how many layers it has, which other units print parts, and the model's
/// name for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisGrid {
    /// The least x and y of the placed part's bounding box, mm.
    pub min: Point,
    /// The xy boxes (least, greatest corner) of the job's parts on the plate, mm: every
    /// layer's region and droplets lie within them. They bound a layer's memory
    /// ([`layer_bytes`](Self::layer_bytes)).
    pub boxes: Vec<[Point; 2]>,
    /// The job's volume, mm³ (0 if unknown): a layer's region holds at most about volume / H,
    /// so bodies far apart in one box are not taken as filling it.
    pub volume: f64,
    pub layers: usize,
    /// The units other than 0 that print parts (another material), each measured on its own.
    pub part_units: Vec<UnitId>,
    pub file_name: String,
}

/// The most memory the analysis of one layer may take, bytes, by its estimate
/// ([`AnalysisGrid::layer_bytes`]): a job above it is not analysed
/// ([`AnalysisGrid::check`]). With it the CLI's analysis (two workers, the spheroid maps of
/// the layers around theirs) stays within a few GB, a page worker's within its 32-bit memory.
pub const MAX_LAYER_BYTES: f64 = 1e9;

/// Bytes the analysis keeps per droplet of a layer besides the grids: its centre (16), its
/// place on the raster (24) and its cells on the 3D grid (32).
const BYTES_PER_DROPLET: f64 = 72.0;

/// Droplets per B² of a layer filled at `fill_density` 1, about: the fill's lattice (1) and
/// the loops over it where they meet.
const DROPLETS_PER_B2: f64 = 1.25;

impl AnalysisGrid {
    /// Whether unit `u` prints parts in the job.
    pub fn has_unit(&self, u: UnitId) -> bool {
        self.part_units.contains(&u)
    }

    /// An estimate of the most memory one layer's analysis takes, bytes, before any of it is
    /// taken: each part's box as if a layer filled it — the raster's bitmaps over the box
    /// ([`Raster::box_bytes`], a bound), its droplets' buffers, and its spheroid maps
    /// ([`HeightMap::box_bytes`], a bound; unit 1's too in a job with unit-1 parts). The
    /// boxes are grown by the largest shrinkage compensation.
    pub fn layer_bytes(&self, s: &Settings) -> f64 {
        let grow = 1.0
            / (1.0
                - s.per_unit
                    .iter()
                    .fold(0.0_f64, |m, u| m.max(u.shrink_xy))
                    .clamp(0.0, 50.0)
                    / 100.0);
        let b = s.droplet_width();
        let d = footprint_diameter(s);
        let per_mm2 = DROPLETS_PER_B2 * s.fill_density.max(1.0) / (b * b);
        let others: Vec<Settings> = (self.part_units.iter())
            .map(|&u| part_settings(s, u))
            .collect();
        let boxes_area = self.boxes_area() * grow * grow;
        let cap = self.volume / s.layer_height;
        let k = if cap.is_finite() && cap > 0.0 && boxes_area > cap {
            (cap / boxes_area).sqrt()
        } else {
            1.0
        };
        self.boxes
            .iter()
            .map(|[lo, hi]| {
                let w = (hi[0] - lo[0]).max(0.0) * grow * k;
                let h = (hi[1] - lo[1]).max(0.0) * grow * k;
                let maps = HeightMap::box_bytes(w, h, b / GRID3_PER_B, d)
                    + (others.iter())
                        .map(|su| {
                            let du = footprint_diameter(su);
                            HeightMap::box_bytes(w, h, su.droplet_width() / GRID3_PER_B, du)
                        })
                        .sum::<f64>();
                Raster::box_bytes(w, h, s) + BYTES_PER_DROPLET * per_mm2 * w * h + maps
            })
            .sum()
    }

    /// Refuses the analysis of a job whose layers would take more than [`MAX_LAYER_BYTES`]
    /// each ([`layer_bytes`](Self::layer_bytes)): what it would take, what it may take, and
    /// what to do. The slice is not affected.
    pub fn check(&self, s: &Settings) -> Result<(), crate::Error> {
        let bytes = self.layer_bytes(s);
        if bytes <= MAX_LAYER_BYTES {
            return Ok(());
        }
        let area: f64 = self
            .boxes
            .iter()
            .map(|[lo, hi]| (hi[0] - lo[0]).max(0.0) * (hi[1] - lo[1]).max(0.0))
            .sum();
        let b = s.droplet_width();
        let gb = |x: f64| crate::base::error::rounded(x / 1e9);
        let mm = crate::base::error::rounded;
        Err(crate::Error::Analysis(format!(
            "a layer of this job would take about {} GB to analyse, more than the {} GB \
             allowed (a grid of {} × {} mm cells, B/40 × B/10 with B = {} mm, over {} mm² of \
             parts); analyse a smaller part, or larger droplets (layer_height, droplet_aspect)",
            gb(bytes),
            gb(MAX_LAYER_BYTES),
            mm(b / ROWS_PER_B / COLS_PER_ROW),
            mm(b / ROWS_PER_B),
            mm(b),
            mm(area),
        )))
    }

    /// The mean area of a layer's region, mm²: the job's volume over its height, or the
    /// boxes' area when the volume is not known.
    fn mean_layer_area(&self, s: &Settings) -> f64 {
        let height = self.layers as f64 * s.layer_height;
        if self.volume > 0.0 && height > 0.0 {
            self.volume / height
        } else {
            self.boxes_area()
        }
    }

    /// The parts' boxes' area, mm².
    fn boxes_area(&self) -> f64 {
        (self.boxes.iter())
            .map(|[lo, hi]| (hi[0] - lo[0]).max(0.0) * (hi[1] - lo[1]).max(0.0))
            .sum()
    }

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
        let others = (grid.part_units.iter())
            .map(|&u| {
                let su = part_settings(settings, u);
                let gu = grid.grid3(&su);
                (u, su, gu)
            })
            .collect();
        let grid3 = grid.grid3(settings);
        LayerStage {
            settings: settings.clone(),
            grid: grid3,
            others,
            banded: true,
            interior: Arc::default(),
            samples: Samples::for_area(grid.mean_layer_area(settings), &grid3),
        }
    }

    /// The stage rasterising every layer whole: the reference the banded analysis is held
    /// to (tests, profiles).
    #[cfg(any(test, feature = "reference"))]
    pub fn reference(grid: &AnalysisGrid, settings: &Settings) -> LayerStage {
        LayerStage {
            banded: false,
            ..LayerStage::new(grid, settings)
        }
    }

    /// Analyses layer `plan.index` against its `region` (unit 0's), in `raster`'s memory (one
    /// raster per worker, reused from layer to layer).
    pub fn analyse(&self, raster: &mut Raster, region: &Shapes, plan: &LayerPlan) -> AnalysedLayer {
        let (analysis, maps) = self.analyse_2d(raster, region, plan);
        AnalysedLayer {
            analysis,
            own: Some((self.regions(region, plan), maps)),
        }
    }

    /// The regions of the layer the units print as parts (`region`: unit 0's).
    pub fn regions(&self, region: &Shapes, plan: &LayerPlan) -> UnitRegions {
        UnitRegions {
            unit0: region.clone(),
            others: (self.others.iter())
                .map(|(u, _, _)| plan.unit_region(*u).cloned().unwrap_or_default())
                .collect(),
        }
    }

    /// The layer's 2D figures and its spheroid maps.
    pub(super) fn analyse_2d(
        &self,
        raster: &mut Raster,
        region: &Shapes,
        plan: &LayerPlan,
    ) -> (LayerAnalysis, LayerMaps) {
        let s = &self.settings;
        let lines = DropletLines::of(plan, s.droplet_width());
        if self.banded && Raster::can_band(s) {
            let width = band_width(s);
            let rate = self
                .interior
                .rates(s, plan.index, &self.grid, width)
                .void_rate;
            raster.rebuild_banded(plan.index, plan.z, &lines, region, s, width, rate);
        } else {
            raster.rebuild(plan.index, plan.z, &lines.centres(), region, s);
        }
        let mut analysis = raster.analysis();
        analysis.unsupported_area = plan.unsupported_area;
        (analysis, self.maps_with(&lines, plan, Some(region)))
    }

    /// A layer's spheroid maps given unit 0's droplets (banded with its `region`).
    fn maps_with(
        &self,
        centres: &DropletLines,
        plan: &LayerPlan,
        region: Option<&Shapes>,
    ) -> LayerMaps {
        let blocks = region.filter(|_| self.banded).and_then(|r| {
            let s = &self.settings;
            Blocks::new(r, &self.grid, band_width(s), self.samples)
        });
        let d = footprint_diameter(&self.settings);
        let unit0 = UnitMap::new(centres, &self.grid, d, blocks);
        let others = (self.others.iter())
            .map(|(u, su, gu)| {
                HeightMap::new(&unit_part_centres(plan, *u), gu, footprint_diameter(su))
            })
            .collect();
        LayerMaps { unit0, others }
    }

    /// A layer's spheroid maps alone, banded with its unit-0 `region` as the report's are (the
    /// page's layers, and the layers next to a run of them whose own figures are not wanted,
    /// [`SlabRun::finish`]: the same slabs, so the same predicted density).
    pub fn maps_in(&self, plan: &LayerPlan, region: &Shapes) -> LayerMaps {
        self.maps_with(
            &DropletLines::of(plan, self.settings.droplet_width()),
            plan,
            Some(region),
        )
    }

    /// Slab `i`'s 3D estimate: per unit, its exact volume and its void volume (the void share
    /// sampled on the grid).
    pub(super) fn slab(
        &self,
        analysis: &LayerAnalysis,
        regions: &UnitRegions,
        maps: [Option<&LayerMaps>; 3],
    ) -> SlabFigures {
        let s = &self.settings;
        let unit0 = maps.map(|m| m.map(|m| &m.unit0));
        let (volume, void_volume) = slab_of(analysis.region_area, &regions.unit0, s, |r| {
            let this = unit0[1]?;
            Some(if self.banded {
                let width = band_width(s);
                let share = self
                    .interior
                    .rates(s, analysis.index, &self.grid, width)
                    .share;
                slab_voids_banded(r, &self.grid, unit0, s, share)
            } else {
                let (below, above) = (unit0[0].map(|m| &m.map), unit0[2].map(|m| &m.map));
                slab_voids(r, &self.grid, below, &this.map, above, s)
            })
        });
        let mut units = [None; MAX_UNITS];
        for (k, (u, su, gu)) in self.others.iter().enumerate() {
            let empty = Shapes::new();
            let region = regions.others.get(k).unwrap_or(&empty);
            let area = if region.is_empty() {
                0.0
            } else {
                region_area(region)
            };
            let theirs = maps.map(|m| m.and_then(|m| m.others.get(k)));
            units[u.index()] = Some(slab_of(area, region, su, |r| {
                Some(slab_voids(r, gu, theirs[0], theirs[1]?, theirs[2], su))
            }));
        }
        SlabFigures {
            volume,
            void_volume,
            units,
        }
    }
}

impl slabs::SlabStage for LayerStage {
    fn slab(
        &self,
        analysis: &LayerAnalysis,
        regions: &UnitRegions,
        maps: [Option<&LayerMaps>; 3],
    ) -> SlabFigures {
        LayerStage::slab(self, analysis, regions, maps)
    }
}

/// The width of the band a banded raster keeps around a layer's boundary, mm: the contours
/// and the fill's margin (where the hatch ends), and 3 B more for the gaps around the hatch
/// ends and the droplets' reach.
fn band_width(s: &Settings) -> f64 {
    let b = s.droplet_width();
    let last = s.contours as f64 - 1.0;
    let margin = s.outer_offset.max(s.inner_offset) + last + 1.0 - s.fill_overlap;
    (margin.max(0.0) + 3.0) * b
}

/// A slab's (exact volume, void volume): `area` × H, and the void share of the region sampled
/// on `grid` between the maps of the layers below, of its own and above.
fn slab_of(
    area: f64,
    region: &Shapes,
    s: &Settings,
    voids: impl FnOnce(&Shapes) -> Option<(f64, f64)>,
) -> (f64, f64) {
    let exact = area * s.layer_height;
    if region.is_empty() {
        return (exact, 0.0);
    }
    let Some((vol, void)) = voids(region) else {
        return (exact, 0.0);
    };
    let void = if vol > 0.0 { void / vol * exact } else { 0.0 };
    (exact, void)
}

/// The ordered half of the job analysis: takes every layer's [`AnalysedLayer`] in ascending
/// order, adds each slab's 3D estimate once its neighbours are in (computing it here with a
/// [`SlabRun`], or taking it from the workers, [`Slabs`]), and gives the [`Report`].
pub struct JobAnalysis {
    stage: Arc<LayerStage>,
    file_name: String,
    part: PartAnalysis,
    layers: Vec<LayerAnalysis>,
    run: SlabRun,
    /// The slabs the workers compute, and the layers waiting for theirs, in order.
    slabs: Arc<Mutex<Slabs>>,
    waiting: VecDeque<LayerAnalysis>,
}

impl JobAnalysis {
    /// The analysis of a job of `grid.layers` layers, sliced with `settings`.
    pub fn new(grid: &AnalysisGrid, settings: &Settings) -> JobAnalysis {
        JobAnalysis::with_stage(grid, LayerStage::new(grid, settings))
    }

    /// The analysis with every layer rasterised whole ([`LayerStage::reference`]).
    #[cfg(any(test, feature = "reference"))]
    pub fn reference(grid: &AnalysisGrid, settings: &Settings) -> JobAnalysis {
        JobAnalysis::with_stage(grid, LayerStage::reference(grid, settings))
    }

    fn with_stage(grid: &AnalysisGrid, stage: LayerStage) -> JobAnalysis {
        let stage = Arc::new(stage);
        JobAnalysis {
            run: SlabRun::new(stage.clone()),
            stage,
            file_name: grid.file_name.clone(),
            part: PartAnalysis::default(),
            layers: Vec::with_capacity(grid.layers),
            slabs: Arc::new(Mutex::new(Slabs::new(grid.layers))),
            waiting: VecDeque::new(),
        }
    }

    /// The stage for the workers.
    pub fn stage(&self) -> LayerStage {
        (*self.stage).clone()
    }

    /// The next layer (layers must come in ascending order, from 0).
    pub fn push(&mut self, layer: AnalysedLayer) {
        match layer.own {
            Some((regions, maps)) => {
                let i = self.layers.len();
                self.part.add_2d(&layer.analysis);
                self.layers.push(layer.analysis.clone());
                if let Some(f) = self.run.push(i, layer.analysis, regions, maps) {
                    self.part.add_slab(f);
                }
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
        let mut board = slabs::lock(&slabs);
        while let Some(analysis) = self.waiting.front() {
            let j = self.layers.len();
            let figures = match board.done.remove(&j) {
                Some(f) => f,
                None if all => {
                    let map = |k: usize| board.maps.get(k).cloned().flatten();
                    let maps = [j.checked_sub(1).and_then(map), map(j), map(j + 1)];
                    let regions = board.layers.get_mut(j).and_then(Option::take);
                    let regions = regions.map(|r| r.0).unwrap_or_default();
                    self.stage.slab(
                        analysis,
                        &regions,
                        [maps[0].as_deref(), maps[1].as_deref(), maps[2].as_deref()],
                    )
                }
                None => break,
            };
            let analysis = self.waiting.pop_front().expect("a waiting layer");
            self.part.add(&analysis, figures);
            self.layers.push(analysis);
        }
    }

    /// The report, after the last layer.
    pub fn finish(mut self) -> Report {
        let run = std::mem::replace(&mut self.run, SlabRun::new(self.stage.clone()));
        if run.span().is_some() {
            self.part.add_slab(run.finish(None, None));
        }
        self.take_slabs(true);
        Report {
            file_name: self.file_name,
            model: Model::new(&self.stage.settings),
            settings: self.stage.settings.clone(),
            part: self.part,
            layers: self.layers,
        }
    }
}

/// The job analysis as a stage of [`crate::write_gcode_with`]: each worker analyses the layers
/// it plans in its own [`Raster`] and computes the slabs its layer completes ([`Slabs`]); the
/// layers are pushed in order.
impl crate::slicing::sink::LayerSink for JobAnalysis {
    type State = (Raster, Arc<LayerStage>, Arc<Mutex<Slabs>>);
    type Out = AnalysedLayer;

    fn init(&self) -> Self::State {
        (Raster::empty(), self.stage.clone(), self.slabs.clone())
    }

    fn per_layer(
        (raster, stage, slabs): &mut Self::State,
        i: usize,
        region: &Shapes,
        plan: &LayerPlan,
    ) -> AnalysedLayer {
        let (analysis, maps) = stage.analyse_2d(raster, region, plan);
        let regions = stage.regions(region, plan);
        let claims = slabs::lock(slabs).publish(i, regions, analysis.clone(), maps);
        for (j, regions, analysis, maps) in claims {
            let maps = [maps[0].as_deref(), maps[1].as_deref(), maps[2].as_deref()];
            let figures = stage.slab(&analysis, &regions, maps);
            slabs::lock(slabs).complete(j, figures);
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
