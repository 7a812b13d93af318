//! The part-level figures of a job's analysis ([`PartAnalysis`]): areas summed over layers,
//! the 3D estimate's volumes and predicted density, per unit that prints parts.

use super::raster::{LayerAnalysis, Void};
use super::slabs::SlabFigures;
use serde::Serialize;

/// Part-level figures. Areas in mm² summed over layers; volumes in mm³.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct PartAnalysis {
    /// How many layers' figures were added (0: nothing analysed yet).
    pub layers: usize,
    /// Unit 0's droplets over those layers (the support's and unit 1's are not counted).
    pub droplets: u64,
    /// The part's sections (unit 0's region, exact) summed over the layers, mm².
    pub region_area: f64,
    /// Area-weighted coverage over all layers.
    pub coverage: f64,
    /// Region no droplet covers, summed over the layers, mm² (on the analysis grid).
    pub void_area: f64,
    /// The part of `void_area` in voids that do not reach a layer's boundary (enclosed air).
    pub enclosed_void_area: f64,
    /// Droplet area outside the region, summed over the layers, mm².
    pub overfill_area: f64,
    /// The largest connected void of any layer, and its layer (from 0).
    pub largest_void: Option<Void>,
    /// The layer of `largest_void` (from 0; the written report counts from 1); `None`: no
    /// layer has a void.
    pub largest_void_layer: Option<usize>,
    /// The largest boundary deviation of any layer, mm: the farther of an uncovered point
    /// inside the boundary and a covered point outside it.
    pub max_boundary_deviation: f64,
    /// The layer of `max_boundary_deviation` (from 0; written from 1); `None`: every layer's
    /// deviation is 0.
    pub max_deviation_layer: Option<usize>,
    /// Unit 0's parts' 3D estimate: their volume (each layer's region, exact area, times H),
    /// the volume no droplet spheroid fills (each slab's void share, sampled on the 3D grid,
    /// times its exact volume), the void fraction and the predicted density (`None` for a 2D
    /// analysis alone: a geometric estimate from the droplet model, docs/process.md, not a
    /// measured density).
    #[serde(flatten)]
    pub estimate: DensityEstimate,
    /// Overhang area summed over the layers, mm².
    #[serde(default)]
    pub unsupported_area: f64,
    /// The largest overhang area of a layer, mm², and its layer (from 0).
    #[serde(default)]
    pub max_unsupported_area: f64,
    /// The layer of `max_unsupported_area` (from 0; written from 1); `None`: no layer has an
    /// overhang.
    #[serde(default)]
    pub max_unsupported_area_layer: Option<usize>,
    /// The 3D estimate of the parts of each other unit (other materials, droplets of B_u),
    /// indexed by unit; `None` for unit 0 (`estimate` is its own) and for a unit without parts; empty in a job whose parts are
    /// all unit 0's. The support is not a part and is not measured.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub units: Vec<Option<DensityEstimate>>,
}

impl PartAnalysis {
    /// Adds one layer's figures and its 3D slab's.
    pub fn add(&mut self, l: &LayerAnalysis, slab: SlabFigures) {
        self.add_2d(l);
        self.add_slab(slab);
    }

    /// Adds one layer's 2D figures.
    pub fn add_2d(&mut self, l: &LayerAnalysis) {
        self.merge(&PartAnalysis::of_layer(l));
    }

    /// One layer's 2D figures.
    fn of_layer(l: &LayerAnalysis) -> PartAnalysis {
        let at = |some: bool| some.then_some(l.index);
        PartAnalysis {
            layers: 1,
            droplets: l.droplets,
            region_area: l.region_area,
            coverage: l.coverage,
            void_area: l.void_area,
            enclosed_void_area: l.enclosed_void_area,
            overfill_area: l.overfill_area,
            largest_void: l.largest_void,
            largest_void_layer: at(l.largest_void.is_some()),
            max_boundary_deviation: l.boundary_deviation,
            max_deviation_layer: at(l.boundary_deviation > 0.0),
            unsupported_area: l.unsupported_area,
            max_unsupported_area: l.unsupported_area,
            max_unsupported_area_layer: at(l.unsupported_area > 0.0),
            ..PartAnalysis::default()
        }
    }

    /// Adds the layers of another part analysis (disjoint layers), as if each of its layers
    /// had been [`add`](PartAnalysis::add)ed here. Of equal largest voids (or deviations) the
    /// lower layer wins, so the order of the merges does not matter.
    pub fn merge(&mut self, o: &PartAnalysis) {
        if o.layers == 0 {
            return;
        }
        let covered = self.coverage * self.region_area + o.coverage * o.region_area;
        self.layers += o.layers;
        self.droplets += o.droplets;
        self.region_area += o.region_area;
        self.coverage = if self.region_area > 0.0 {
            covered / self.region_area
        } else {
            0.0
        };
        self.void_area += o.void_area;
        self.enclosed_void_area += o.enclosed_void_area;
        self.overfill_area += o.overfill_area;
        let better = |a: f64, ai: Option<usize>, b: f64, bi: Option<usize>| {
            a > b || (a == b && ai.unwrap_or(usize::MAX) < bi.unwrap_or(usize::MAX))
        };
        if let Some(v) = o.largest_void
            && self.largest_void.is_none_or(|mine| {
                better(
                    v.area,
                    o.largest_void_layer,
                    mine.area,
                    self.largest_void_layer,
                )
            })
        {
            self.largest_void = Some(v);
            self.largest_void_layer = o.largest_void_layer;
        }
        // The larger figure of the two and its layer (ties: the lower layer).
        let keep_max = |mine: (&mut f64, &mut Option<usize>), theirs: (f64, Option<usize>)| {
            if theirs.1.is_some()
                && (mine.1.is_none() || better(theirs.0, theirs.1, *mine.0, *mine.1))
            {
                (*mine.0, *mine.1) = theirs;
            }
        };
        keep_max(
            (
                &mut self.max_boundary_deviation,
                &mut self.max_deviation_layer,
            ),
            (o.max_boundary_deviation, o.max_deviation_layer),
        );
        self.unsupported_area += o.unsupported_area;
        keep_max(
            (
                &mut self.max_unsupported_area,
                &mut self.max_unsupported_area_layer,
            ),
            (o.max_unsupported_area, o.max_unsupported_area_layer),
        );
        self.add_estimates(o);
    }

    /// Adds a slab's 3D figures (of any layer, in any order).
    pub fn add_slab(&mut self, f: SlabFigures) {
        self.estimate.add(f.volume, f.void_volume);
        for (k, figures) in f.units.iter().enumerate() {
            if let Some((volume, void_volume)) = *figures {
                self.unit_mut(k).add(volume, void_volume);
            }
        }
    }

    /// Adds the 3D estimates of another part analysis (disjoint layers).
    fn add_estimates(&mut self, o: &PartAnalysis) {
        self.estimate.add(o.estimate.volume, o.estimate.void_volume);
        for (k, theirs) in o.units.iter().enumerate() {
            if let Some(theirs) = theirs {
                self.unit_mut(k).add(theirs.volume, theirs.void_volume);
            }
        }
    }

    /// Unit `k`'s 3D estimate, made (empty) if it is not there yet.
    pub fn unit_mut(&mut self, k: usize) -> &mut DensityEstimate {
        if self.units.len() <= k {
            self.units.resize(k + 1, None);
        }
        self.units[k].get_or_insert_default()
    }

    /// The predicted density of each unit's parts, indexed by unit, for a machine of `units`
    /// units (unit 0's: `estimate`'s).
    pub fn unit_densities(&self, units: usize) -> Vec<Option<f64>> {
        (0..units.max(1))
            .map(|k| match k {
                0 => self.estimate.predicted_density,
                _ => self.units.get(k).copied().flatten()?.predicted_density,
            })
            .collect()
    }
}

/// The 3D estimate of some parts (unit 0's in [`PartAnalysis::estimate`], another unit's in
/// [`PartAnalysis::units`]).
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct DensityEstimate {
    /// The parts' volume, mm³.
    pub volume: f64,
    /// Volume no droplet spheroid fills, mm³.
    pub void_volume: f64,
    /// void_volume / volume.
    pub void_fraction: f64,
    /// 100 × (1 − void_fraction), %; `None` without a volume.
    #[serde(default)]
    pub predicted_density: Option<f64>,
}

impl DensityEstimate {
    /// Adds a volume and its void volume; the fraction and density follow (no density
    /// without a volume).
    pub fn add(&mut self, volume: f64, void_volume: f64) {
        self.volume += volume;
        self.void_volume += void_volume;
        let some = self.volume > 0.0;
        self.void_fraction = if some {
            self.void_volume / self.volume
        } else {
            0.0
        };
        self.predicted_density = some.then_some(100.0 * (1.0 - self.void_fraction));
    }
}
