//! The job's report: part figures, the analysis model, and the per-layer stage the slicing
//! workers run with its ordered half ([`JobAnalysis`], a [`crate::LayerSink`]).

use super::droplet::{droplet_centres, footprint_diameter, spheroid_half_height};
use super::estimate3d::{GRID3_PER_B, Grid3, HeightMap, slab_voids};
use super::raster::{COLS_PER_ROW, LayerAnalysis, ROWS_PER_B, Raster, Void};
use crate::geom::{DVec2, Shapes};
use crate::plan::LayerPlan;
use crate::settings::Settings;
use serde::Serialize;

/// Part-level figures. Areas in mm² summed over layers; volumes in mm³.
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
        self.void_fraction = if self.volume > 0.0 {
            self.void_volume / self.volume
        } else {
            0.0
        };
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
    pub footprint: crate::settings::Footprint,
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

/// One layer analysed by a [`LayerStage`], waiting for its neighbours' spheroid maps.
pub struct AnalysedLayer {
    analysis: LayerAnalysis,
    region: Shapes,
    map: HeightMap,
}

/// The 3D grid of a job's analysis (fixed to the part's bounds).
fn job_grid(job: &crate::Job) -> Grid3 {
    let s = job.settings();
    let d = footprint_diameter(s);
    let bounds = job.info().bounds;
    Grid3 {
        origin: DVec2::new(bounds.min[0] - d, bounds.min[1] - d),
        cell: s.droplet_width() / GRID3_PER_B,
    }
}

impl LayerStage {
    pub fn new(job: &crate::Job) -> LayerStage {
        LayerStage {
            settings: job.settings().clone(),
            grid: job_grid(job),
        }
    }

    /// Analyses layer `plan.index` against its `region`, in `raster`'s memory (one raster per
    /// worker, reused from layer to layer).
    pub fn analyse(&self, raster: &mut Raster, region: &Shapes, plan: &LayerPlan) -> AnalysedLayer {
        let s = &self.settings;
        let centres = droplet_centres(plan, s.droplet_width());
        raster.rebuild(plan.index, plan.z, &centres, region, s);
        let mut analysis = raster.analysis();
        analysis.unsupported_area = plan.unsupported_area;
        AnalysedLayer {
            analysis,
            region: region.clone(),
            map: HeightMap::new(&centres, &self.grid, footprint_diameter(s)),
        }
    }
}

/// The ordered half of the job analysis: takes every layer's [`AnalysedLayer`] in ascending
/// order, computes each slab's 3D estimate once its neighbours are in, and gives the
/// [`Report`]. Keeps two layers' maps at a time.
pub struct JobAnalysis {
    stage: LayerStage,
    file_name: String,
    part: PartAnalysis,
    layers: Vec<LayerAnalysis>,
    below: Option<HeightMap>,
    current: Option<AnalysedLayer>,
}

impl JobAnalysis {
    pub fn new(job: &crate::Job) -> JobAnalysis {
        JobAnalysis {
            stage: LayerStage::new(job),
            file_name: job.info().file_name.clone(),
            part: PartAnalysis::default(),
            layers: Vec::with_capacity(job.layer_count()),
            below: None,
            current: None,
        }
    }

    /// The stage for the workers.
    pub fn stage(&self) -> LayerStage {
        self.stage.clone()
    }

    /// The next layer (layers must come in ascending order, from 0).
    pub fn push(&mut self, layer: AnalysedLayer) {
        self.close(Some(&layer.map));
        self.below = self.current.take().map(|c| c.map);
        self.current = Some(layer);
    }

    /// The 3D estimate of the current layer, with `above` (the next layer's map, if any).
    fn close(&mut self, above: Option<&HeightMap>) {
        let Some(cur) = &self.current else { return };
        let s = &self.stage.settings;
        let (vol, void) = slab_voids(
            &cur.region,
            &self.stage.grid,
            self.below.as_ref(),
            &cur.map,
            above,
            s,
        );
        // The slab's exact volume, with the void share sampled on the grid.
        let exact = cur.analysis.region_area * s.layer_height;
        let void = if vol > 0.0 { void / vol * exact } else { 0.0 };
        self.part.add(&cur.analysis, exact, void);
        self.layers.push(cur.analysis.clone());
    }

    /// The report, after the last layer.
    pub fn finish(mut self) -> Report {
        self.close(None);
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
/// it plans in its own [`Raster`], and the layers are pushed in order.
impl crate::LayerSink for JobAnalysis {
    type State = (Raster, LayerStage);
    type Out = AnalysedLayer;

    fn init(&self) -> Self::State {
        (Raster::empty(), self.stage())
    }

    fn per_layer(
        (raster, stage): &mut Self::State,
        _: usize,
        region: &Shapes,
        plan: &LayerPlan,
    ) -> AnalysedLayer {
        stage.analyse(raster, region, plan)
    }

    fn ordered(&mut self, _: usize, layer: AnalysedLayer) {
        self.push(layer);
    }
}
