//! The 3D estimate layer by layer: a slab (layer i's region × its height) needs the spheroid
//! maps of layers i − 1, i and i + 1. [`SlabRun`] computes the slabs of consecutive layers
//! analysed one after another (the report's writing thread, a page worker's run of layers);
//! [`Slabs`] lets the native slicing workers compute them in any order.

use super::estimate3d::{HeightMap, UnitMap};
use super::raster::LayerAnalysis;
use crate::base::geom::Shapes;
use crate::base::settings::MAX_UNITS;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, MutexGuard};

/// The regions of a layer each unit prints as parts: unit 0's and, in a job with parts of
/// other units (other materials), theirs, in the order of the analysis' part units.
#[derive(Clone, Debug, Default)]
pub struct UnitRegions {
    pub unit0: Shapes,
    pub others: Vec<Shapes>,
}

/// A layer's droplet spheroids on the 3D grid: unit 0's and, in a job with parts of other
/// units, theirs (each on its own grid, of its B_u), in the order of the part units.
pub struct LayerMaps {
    /// Unit 0's, without the droplets deep in a banded layer's interior (kept aside).
    pub unit0: UnitMap,
    pub others: Vec<HeightMap>,
}

/// One slab's 3D figures, mm³: its exact volume and its void volume, for unit 0 and (in a job
/// with parts of other units) for each of them, indexed by unit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SlabFigures {
    pub volume: f64,
    pub void_volume: f64,
    pub units: [Option<(f64, f64)>; MAX_UNITS],
}

impl SlabFigures {
    /// The sum of two (disjoint) slabs' figures.
    pub fn plus(self, o: SlabFigures) -> SlabFigures {
        let mut units = self.units;
        for (mine, theirs) in units.iter_mut().zip(o.units) {
            *mine = match (*mine, theirs) {
                (Some(a), Some(b)) => Some((a.0 + b.0, a.1 + b.1)),
                (a, b) => a.or(b),
            };
        }
        SlabFigures {
            volume: self.volume + o.volume,
            void_volume: self.void_volume + o.void_volume,
            units,
        }
    }
}

/// What computes one slab's figures from its layer's 2D analysis and regions and the maps of
/// the layers below, of its own and above (the report's per-layer stage).
pub trait SlabStage: Send + Sync {
    fn slab(
        &self,
        analysis: &LayerAnalysis,
        regions: &UnitRegions,
        maps: [Option<&LayerMaps>; 3],
    ) -> SlabFigures;
}

/// A layer of a [`SlabRun`] whose slab is not done yet.
struct Held {
    index: usize,
    analysis: LayerAnalysis,
    regions: UnitRegions,
    maps: Arc<LayerMaps>,
}

/// The 3D estimate over a run of consecutive layers pushed in ascending order (from any layer
/// on): each slab is done as soon as the map above it is in. The slabs at the run's ends need
/// the maps of the layers just outside it (below its first layer unless that is layer 0, above
/// its last unless that is the job's last), given at [`SlabRun::finish`]. A run holds four
/// layers' maps at most.
pub struct SlabRun {
    stage: Arc<dyn SlabStage>,
    /// The run's first layer.
    first: Option<usize>,
    /// The run's first layer while its slab waits for the map below the run (not layer 0),
    /// with the map above it.
    head: Option<(Held, Arc<LayerMaps>)>,
    /// The map of the layer below `last`.
    below: Option<Arc<LayerMaps>>,
    /// The last layer pushed (its slab waits for the map above it).
    last: Option<Held>,
}

impl SlabRun {
    pub fn new(stage: Arc<dyn SlabStage>) -> SlabRun {
        SlabRun {
            stage,
            first: None,
            head: None,
            below: None,
            last: None,
        }
    }

    /// The run's layers [first, last + 1), once one is pushed.
    pub fn span(&self) -> Option<(usize, usize)> {
        Some((self.first?, self.last.as_ref()?.index + 1))
    }

    /// Pushes layer `index` (the run's first, or the one after the last pushed); returns the
    /// figures of the slab this completes, if any.
    pub fn push(
        &mut self,
        index: usize,
        analysis: LayerAnalysis,
        regions: UnitRegions,
        maps: LayerMaps,
    ) -> Option<SlabFigures> {
        let maps = Arc::new(maps);
        let held = Held {
            index,
            analysis,
            regions,
            maps: maps.clone(),
        };
        let Some(prev) = self.last.replace(held) else {
            self.first = Some(index);
            return None;
        };
        debug_assert_eq!(prev.index + 1, index, "a run's layers come in order");
        let below = self.below.replace(prev.maps.clone());
        if Some(prev.index) == self.first && prev.index > 0 {
            self.head = Some((prev, maps));
            return None;
        }
        Some(self.stage.slab(
            &prev.analysis,
            &prev.regions,
            [below.as_deref(), Some(&prev.maps), Some(&maps)],
        ))
    }

    /// The figures of the slabs left, given the maps of the layers just below the run and just
    /// above it (`None` where the job has no such layer).
    pub fn finish(self, below: Option<LayerMaps>, above: Option<LayerMaps>) -> SlabFigures {
        let mut out = SlabFigures::default();
        if let Some((h, after)) = &self.head {
            out = self.stage.slab(
                &h.analysis,
                &h.regions,
                [below.as_ref(), Some(&h.maps), Some(after)],
            );
        }
        if let Some(last) = &self.last {
            let under = if Some(last.index) == self.first {
                below.as_ref()
            } else {
                self.below.as_deref()
            };
            let f = self.stage.slab(
                &last.analysis,
                &last.regions,
                [under, Some(&last.maps), above.as_ref()],
            );
            out = out.plus(f);
        }
        out
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
    pub(super) maps: Vec<Option<Arc<LayerMaps>>>,
    /// Each layer's region and 2D figures, until its slab is done.
    pub(super) layers: Vec<Option<(UnitRegions, LayerAnalysis)>>,
    claimed: Vec<bool>,
    /// Slabs not yet done that use each map.
    uses: Vec<u8>,
    /// Slabs done and not yet taken: layer → (volume, void volume).
    pub(super) done: BTreeMap<usize, SlabFigures>,
}

/// What a worker claims: a slab, its layer's region and figures and the three maps.
pub(super) type Claim = (
    usize,
    UnitRegions,
    LayerAnalysis,
    [Option<Arc<LayerMaps>>; 3],
);

impl Slabs {
    pub(super) fn new(n: usize) -> Slabs {
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
    pub(super) fn publish(
        &mut self,
        i: usize,
        region: UnitRegions,
        analysis: LayerAnalysis,
        map: LayerMaps,
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
    pub(super) fn complete(&mut self, j: usize, figures: SlabFigures) {
        self.done.insert(j, figures);
        for k in self.around(j) {
            self.uses[k] = self.uses[k].saturating_sub(1);
            if self.uses[k] == 0 {
                self.maps[k] = None;
            }
        }
    }
}

pub(super) fn lock(m: &Mutex<Slabs>) -> MutexGuard<'_, Slabs> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}
