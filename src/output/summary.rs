//! Every figure about a slice, computed once, here: the CLI prints them and the page shows
//! them (it computes none of its own).
//!
//! A [`Summary`] is built per unit of work (a layer, a run of layers, a worker's share) and
//! merged with [`Summary::merge`]; units may arrive in any order and from several workers, and
//! merging them gives the same figures as one summary over all layers. [`Summary::figures`]
//! turns it into what is shown: droplets by role, material volume and mass, print time, part
//! coverage, void area, the worst layer and what slicing repaired. [`Summary::printable`] is
//! the one "nothing to print" check of the CLI and the page.

use crate::analysis::{LayerAnalysis, PartAnalysis};
use crate::base::error::Error;
use crate::base::settings::{Settings, UnitId};
use crate::slicing::plan::{Counts, LayerPlan};
use serde::{Deserialize, Serialize};

/// Totals of some layers of a slice (all of them once every unit is merged).
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Layers planned (added with [`Summary::add`]).
    pub layers: usize,
    pub counts: Counts,
    /// Length of all moves without material, in mm.
    pub travel_mm: f64,
    /// Layers whose section had open chains that were joined across gaps.
    pub layers_with_open_chains: usize,
    /// Loops chained against the direction of some of their facets (flipped facets).
    pub reoriented_loops: usize,
    /// The void analysis of the layers analysed (added with [`Summary::add_analysis`];
    /// `analysis.layers` of them), in 2D (no slab volumes).
    #[serde(default)]
    pub analysis: PartAnalysis,
    /// Overhang area summed over the layers, mm² (support on or off).
    #[serde(default)]
    pub unsupported_area: f64,
    /// The layer with the largest overhang area (none without overhangs).
    #[serde(default)]
    pub worst_overhang: Option<WorstLayer>,
}

/// The worst layer by some area: the largest connected void, or the largest overhang.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorstLayer {
    /// Layer number from 0.
    pub index: usize,
    /// Its area (of the largest void, or of the overhang), mm².
    pub area: f64,
}

/// The estimated print time, s: each unit's droplets / its `…droplet_rate`, summed over the
/// units, + travel / travel_speed. The one estimate of the job's figures
/// ([`Figures::print_seconds`]) and of each layer ([`layer_seconds`]), so the layers' times
/// add up to the job's.
pub fn print_seconds(counts: &Counts, travel_mm: f64, settings: &Settings) -> f64 {
    let droplets: f64 = UnitId::all(settings.units.max(1) as usize)
        .map(|u| droplet_seconds(counts, settings, u))
        .sum();
    droplets + travel_mm / settings.travel_speed
}

/// Unit `u`'s droplet time, s: its droplets / its `…droplet_rate`.
fn droplet_seconds(counts: &Counts, settings: &Settings, u: UnitId) -> f64 {
    counts.unit(u) as f64 / settings.unit(u).droplet_rate
}

/// The estimated print time of one planned layer, s (the page's per-layer plot).
pub fn layer_seconds(plan: &LayerPlan, settings: &Settings) -> f64 {
    print_seconds(&plan.counts, plan.travel_mm, settings)
}

impl WorstLayer {
    /// The worse of two (larger area; of equal areas the lower layer, so merges commute).
    fn worse(a: Option<WorstLayer>, b: Option<WorstLayer>) -> Option<WorstLayer> {
        match (a, b) {
            (Some(x), Some(y)) => Some(
                if y.area > x.area || (y.area == x.area && y.index < x.index) {
                    y
                } else {
                    x
                },
            ),
            (x, None) => x,
            (None, y) => y,
        }
    }
}

/// What the CLI prints and the page shows about a slice.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Figures {
    pub layers: usize,
    pub counts: Counts,
    /// Every unit's droplets (parts and support).
    pub droplets: u64,
    /// Each discharge unit's figures, indexed by unit, one entry per unit the machine has
    /// (`units`); unit 0's are the parts of unit 0.
    pub units: Vec<UnitFigures>,
    /// Each unit's droplets / its `…droplet_rate`, summed, + travel / travel_speed, s
    /// ([`print_seconds`]).
    pub print_seconds: f64,
    /// Overhang area summed over the layers, mm² (support on or off: what would be printed
    /// in the air without support).
    pub unsupported_area: f64,
    /// The layer with the largest overhang area.
    pub worst_overhang: Option<WorstLayer>,
    pub travel_mm: f64,
    /// Layers with a void analysis.
    pub analysed_layers: usize,
    /// Area-weighted coverage of the analysed layers (0 … 1); `None` without analysis.
    pub coverage: Option<f64>,
    /// Uncovered area summed over the analysed layers, mm².
    pub void_area: Option<f64>,
    pub worst_layer: Option<WorstLayer>,
    /// What slicing repaired, in plain language.
    pub repairs: Vec<String>,
}

/// One discharge unit's figures ([`Figures::units`]).
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct UnitFigures {
    /// The droplets it prints: its parts' and, for the support's unit, the support.
    pub droplets: u64,
    /// droplets × B_u²H, mm³.
    pub volume_mm3: f64,
    /// volume × its `…material_density`, g.
    pub mass_g: f64,
    /// droplets / its `…droplet_rate`, s.
    pub seconds: f64,
    /// The predicted density of its parts, % (100 × (1 − the 3D void fraction)); `None`
    /// without parts of the unit or without the 3D estimate. A geometric estimate from the
    /// droplet model, not a measured density.
    pub predicted_density: Option<f64>,
}

/// A layer's travel on a grid of 2⁻²⁰ mm (about 1 nm). Sums of such numbers below 2³³ mm are
/// exact in f64, so a job's travel (and the print time made from it) is the same whatever
/// runs of layers it was summed in: the CLI's one pass and the page's workers, which merge
/// their runs as they end, write the same figures into the header (docs/gcode.md).
pub fn travel_step(mm: f64) -> f64 {
    const GRID: f64 = 1_048_576.0;
    (mm * GRID).round() / GRID
}

impl Summary {
    /// Adds one planned layer.
    pub fn add(&mut self, plan: &LayerPlan) {
        self.layers += 1;
        self.counts.add(&plan.counts);
        self.travel_mm += travel_step(plan.travel_mm);
        self.layers_with_open_chains += usize::from(plan.open_chains > 0);
        self.reoriented_loops += plan.reoriented_loops;
        self.unsupported_area += plan.unsupported_area;
        if plan.unsupported_area > 0.0 {
            self.worst_overhang = WorstLayer::worse(
                self.worst_overhang,
                Some(WorstLayer {
                    index: plan.index,
                    area: plan.unsupported_area,
                }),
            );
        }
    }

    /// A summary of one planned layer.
    pub fn of_layer(plan: &LayerPlan) -> Summary {
        let mut s = Summary::default();
        s.add(plan);
        s
    }

    /// Adds one layer's void analysis (a layer may be analysed without being counted again,
    /// e.g. when the analysis is made after the slice).
    pub fn add_analysis(&mut self, layer: &LayerAnalysis) {
        self.analysis.add_2d(layer);
    }

    /// Adds a slab's 3D figures (the page's workers compute them for their runs of layers,
    /// [`crate::analysis::SlabRun`]).
    pub fn add_slab(&mut self, f: &crate::analysis::SlabFigures) {
        self.analysis.add_slab(*f);
    }

    /// Adds the layers of another summary (disjoint from this one's).
    pub fn merge(&mut self, other: &Summary) {
        self.layers += other.layers;
        self.counts.add(&other.counts);
        self.travel_mm += other.travel_mm;
        self.layers_with_open_chains += other.layers_with_open_chains;
        self.reoriented_loops += other.reoriented_loops;
        self.analysis.merge(&other.analysis);
        self.unsupported_area += other.unsupported_area;
        self.worst_overhang = WorstLayer::worse(self.worst_overhang, other.worst_overhang);
    }

    /// The merge of `parts`.
    pub fn merged<'a>(parts: impl IntoIterator<Item = &'a Summary>) -> Summary {
        let mut s = Summary::default();
        for p in parts {
            s.merge(p);
        }
        s
    }

    /// Plain-language notes on what slicing repaired.
    pub fn repairs(&self) -> Vec<String> {
        let mut r = Vec::new();
        if self.layers_with_open_chains > 0 {
            r.push(format!(
                "{} layers had open sections (holes in the mesh), closed by joining their ends",
                self.layers_with_open_chains
            ));
        }
        if self.reoriented_loops > 0 {
            r.push(format!(
                "{} loops crossed flipped facets and were oriented by the majority",
                self.reoriented_loops
            ));
        }
        r
    }

    /// The figures shown to the user, with the estimates of `settings`.
    pub fn figures(&self, settings: &Settings) -> Figures {
        let h = settings.layer_height;
        let a = &self.analysis;
        let n = settings.units.max(1) as usize;
        let density = a.unit_densities(n);
        let units = UnitId::all(n)
            .map(|u| {
                let b = settings.unit_width(u);
                let droplets = self.counts.unit(u);
                let volume_mm3 = droplets as f64 * b * b * h;
                UnitFigures {
                    droplets,
                    volume_mm3,
                    mass_g: volume_mm3 / 1000.0 * settings.unit(u).material_density,
                    seconds: droplet_seconds(&self.counts, settings, u),
                    predicted_density: density[u.index()],
                }
            })
            .collect();
        let analysed = a.layers > 0;
        Figures {
            layers: self.layers,
            counts: self.counts,
            droplets: self.counts.total(),
            units,
            print_seconds: print_seconds(&self.counts, self.travel_mm, settings),
            unsupported_area: self.unsupported_area,
            worst_overhang: self.worst_overhang,
            travel_mm: self.travel_mm,
            analysed_layers: a.layers,
            coverage: analysed.then_some(a.coverage),
            void_area: analysed.then_some(a.void_area),
            worst_layer: match (a.largest_void, a.largest_void_layer) {
                (Some(v), Some(index)) => Some(WorstLayer {
                    index,
                    area: v.area,
                }),
                _ => None,
            },
            repairs: self.repairs(),
        }
    }

    /// "Nothing to print": a finished slice without a single droplet (every wall thinner than
    /// a droplet). The CLI writes no file and the page offers no download.
    pub fn printable(&self, settings: &Settings) -> Result<(), Error> {
        if self.counts.total() > 0 {
            return Ok(());
        }
        Err(Error::NothingToPrint(format!(
            "no droplet fits in the part: every wall is thinner than the droplet width B = {:.3} mm; scale the part up or use smaller droplets (layer_height, droplet_aspect)",
            settings.droplet_width()
        )))
    }
}
