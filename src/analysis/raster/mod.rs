//! The 2D analysis of one layer: its droplets rasterised against its region (coverage, voids,
//! overfill, boundary deviation) and the coverage mask for the page's overlay.
//!
//! - [`build`]: the rasterisation (region and droplet bitmaps in sparse tiles);
//! - [`voids`]: the figures (the one-pass void labelling, the boundary deviation);
//! - [`mask`]: the coverage mask;
//! - `reference` (tests and the `reference` feature only): the labelling and mask counts the
//!   fast paths replaced, which tests/analysis_fast.rs compares them with.

use super::droplet::droplet_centres;
use crate::base::geom::{DVec2, Point, Shapes, scanline_spans};
use crate::base::settings::Settings;
use crate::base::spatial::{Row, Tiles};
use crate::slicing::plan::LayerPlan;
use serde::Serialize;

mod band;
pub(in crate::analysis) use band::dilate2;
mod build;
mod mask;
#[cfg(any(test, feature = "reference"))]
mod reference;
mod voids;

/// Grid rows per droplet width B.
pub const ROWS_PER_B: f64 = 10.0;
/// Grid columns per row height (columns every B/40).
pub const COLS_PER_ROW: f64 = 4.0;
/// Void runs in neighbouring rows connect when they overlap by at least this many columns.
pub const MIN_PASSAGE_COLS: u32 = 2;

/// One connected void of a layer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct Void {
    /// mm².
    pub area: f64,
    pub centroid: Point,
    /// Bounding box.
    pub min: Point,
    pub max: Point,
    /// Whether it reaches the region's boundary (a gap in the outline rather than enclosed).
    pub at_boundary: bool,
}

/// What one layer's droplets cover of its region. Areas in mm², lengths in mm.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct LayerAnalysis {
    /// Layer number from 0.
    pub index: usize,
    /// Z written in the code (the layer's top).
    pub z: f64,
    pub droplets: u64,
    /// The region's exact area.
    pub region_area: f64,
    /// Region area covered by droplets (on the grid).
    pub covered_area: f64,
    /// Share of the region covered by droplets (0 … 1).
    pub coverage: f64,
    /// Uncovered area inside the region.
    pub void_area: f64,
    /// The part of `void_area` in voids that do not reach the boundary (enclosed air).
    pub enclosed_void_area: f64,
    /// Connected voids.
    pub voids: usize,
    pub largest_void: Option<Void>,
    /// Droplet area outside the region.
    pub overfill_area: f64,
    /// Largest distance from the boundary of an uncovered point connected to it.
    pub deviation_inward: f64,
    /// Largest distance from the region of a covered point outside it.
    pub deviation_outward: f64,
    /// max(inward, outward).
    pub boundary_deviation: f64,
    /// Where the larger deviation was found.
    pub deviation_at: Option<Point>,
    /// The layer's overhang area, mm² (from its plan: [`crate::support::overhang`]).
    #[serde(default)]
    pub unsupported_area: f64,
}

/// A coarse picture of a layer for an overlay: per square cell the share (0 … 255) of it that
/// is void (region, uncovered), overfill (covered, outside the region) and covered region.
/// Only tiles of cells near the layer's region and droplets are kept (parts far apart cost no
/// memory for the space between them); every cell outside the tiles is empty (shares 0).
/// Cell (col, row) of the mask spans x = origin.x + col·cell …, y = origin.y + row·cell ….
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CoverageMask {
    pub origin: Point,
    pub cell: f64,
    /// Disjoint, by rows then columns.
    pub tiles: Vec<MaskTile>,
}

/// A rectangle of mask cells: (col + i, row + j) for i < width, j < height; in a row-major
/// array of its cells, cell (col + i, row + j) is at index j·width + i ([`CellRect::index`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct CellRect {
    /// The mask column (from 0, counted from the mask's origin) of the first cells.
    pub col: usize,
    /// The mask row (from 0) of the first cells.
    pub row: usize,
    /// Cells across.
    pub width: usize,
    /// Cells down.
    pub height: usize,
}

impl CellRect {
    /// How many cells it holds.
    pub fn cells(&self) -> usize {
        self.width * self.height
    }

    /// The column after its last.
    pub fn end_col(&self) -> usize {
        self.col + self.width
    }

    /// The row after its last.
    pub fn end_row(&self) -> usize {
        self.row + self.height
    }

    /// Whether cell (col, row) is in it.
    pub fn contains(&self, col: usize, row: usize) -> bool {
        (self.col..self.end_col()).contains(&col) && (self.row..self.end_row()).contains(&row)
    }

    /// The index of its cell (col, row) in a row-major array of its cells.
    pub fn index(&self, col: usize, row: usize) -> usize {
        (row - self.row) * self.width + col - self.col
    }
}

/// A rectangle of a [`CoverageMask`] and the shares of its cells, each indexed as
/// [`CellRect::index`] says.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MaskTile {
    /// Its cells: at least 1 across; 64 down (the mask rows a tile band holds), or fewer in
    /// the last band of the mask, from a multiple of 64 (`col`, `row`, `width`, `height` in
    /// the JSON).
    #[serde(flatten)]
    pub rect: CellRect,
    /// Per cell, the share of it that is region no droplet covers: 0 (none) … 255 (all).
    pub void: Vec<u8>,
    /// Per cell, the share of it that droplets cover outside the region: 0 … 255.
    pub overfill: Vec<u8>,
    /// Per cell, the share of it that is region covered by droplets: 0 … 255; empty in the
    /// page's mask, which draws only void and overfill.
    pub covered: Vec<u8>,
}

impl CoverageMask {
    /// Where tile `t`'s cell (0, 0) starts, in mm.
    pub fn tile_origin(&self, t: &MaskTile) -> Point {
        DVec2::new(
            self.origin[0] + t.rect.col as f64 * self.cell,
            self.origin[1] + t.rect.row as f64 * self.cell,
        )
    }

    /// The shares [void, overfill, covered] of cell (col, row); zero outside the tiles.
    pub fn shares(&self, col: usize, row: usize) -> [u8; 3] {
        self.tiles
            .iter()
            .find(|t| t.rect.contains(col, row))
            .map_or([0; 3], |t| {
                let i = t.rect.index(col, row);
                [t.void[i], t.overfill[i], t.covered[i]]
            })
    }

    /// Cells (width, height) from the origin to the far corner of the last tiles.
    pub fn size(&self) -> (usize, usize) {
        self.tiles.iter().fold((0, 0), |(w, h), t| {
            (w.max(t.rect.end_col()), h.max(t.rect.end_row()))
        })
    }
}

/// Analyses one layer: its plan against its region (the section, before any offset).
pub fn analyse_layer(plan: &LayerPlan, region: &Shapes, s: &Settings) -> LayerAnalysis {
    LayerAnalysis {
        unsupported_area: plan.unsupported_area,
        ..Raster::new(plan, region, s).analysis()
    }
}

/// [`analyse_layer`] and a [`CoverageMask`] with square cells of about `mask_cell` mm (at least
/// B/10; rounded to whole grid rows).
pub fn analyse_layer_with_mask(
    plan: &LayerPlan,
    region: &Shapes,
    s: &Settings,
    mask_cell: f64,
) -> (LayerAnalysis, CoverageMask) {
    let r = Raster::new(plan, region, s);
    let a = LayerAnalysis {
        unsupported_area: plan.unsupported_area,
        ..r.analysis()
    };
    (a, r.mask(mask_cell))
}

/// What the page's worker needs of a layer: [`analyse_layer_with_mask`]'s figures and its mask
/// without the covered shares ([`Raster::page_mask`]), rasterised into `r`: a worker keeps one
/// raster from layer to layer, so its bitmaps and the labelling's buffers are allocated (and
/// first touched) once, not per layer.
pub fn analyse_layer_for_page(
    r: &mut Raster,
    plan: &LayerPlan,
    region: &Shapes,
    s: &Settings,
    mask_cell: f64,
) -> (LayerAnalysis, CoverageMask) {
    let b = s.droplet_width();
    r.rebuild(plan.index, plan.z, &droplet_centres(plan, b), region, s);
    let a = LayerAnalysis {
        unsupported_area: plan.unsupported_area,
        ..r.analysis()
    };
    (a, r.page_mask(mask_cell))
}

/// The rasterised layer: region and droplet bitmaps on one grid over the layer, stored only in
/// the tiles its region and droplets touch ([`Tiles`], counted in words of 64 columns), so parts
/// far apart cost no memory for the space between them.
pub struct Raster {
    index: usize,
    z: f64,
    droplets: u64,
    region_area: f64,
    b: f64,
    grid: Grid,
    /// Which words of the grid are stored, and where.
    tiles: Tiles,
    region_bits: Vec<u64>,
    drop_bits: Vec<u64>,
    /// Per stored row ([`Row::slot`]), the words [lo, hi) of its slice holding any bit.
    extent: Vec<(u32, u32)>,
    edges: Vec<(Point, Point)>,
    /// The region's spans (row, first column, last column) and each droplet's first row,
    /// phase and centre column, between marking and setting.
    spans: Vec<(u32, u32, u32)>,
    places: Vec<(usize, usize, f64)>,
    /// The labelling's buffers, kept from layer to layer (a worker analyses many layers).
    scratch: std::sync::Mutex<Scratch>,
    /// What a banded rebuild ([`Raster::rebuild_banded`]) left out and counted instead.
    banding: Option<band::Banding>,
}

/// Buffers of [`Raster::voids_fast`].
#[derive(Default)]
struct Scratch {
    runs: Vec<(u32, u32, u32, u32)>,
    parent: Vec<u32>,
    cells: Vec<u64>,
    root: Vec<u32>,
    /// The region rows above and below, when copied from another band.
    around: (Vec<u64>, Vec<u64>),
}

impl Raster {
    /// The stored rows, in order: (row number, row).
    fn stored_rows(&self) -> impl Iterator<Item = (usize, Row<'_>)> + '_ {
        let tiles = &self.tiles;
        let bands = tiles.bands().iter().enumerate();
        bands.flat_map(move |(bi, band)| {
            (band.first_row..band.end_row).map(move |k| (k, tiles.row_in(bi, k)))
        })
    }

    /// The stored rows holding any bit, in order: (row number, row, the words [lo, hi) of its
    /// slice holding any).
    fn filled_rows(&self) -> impl Iterator<Item = (usize, Row<'_>, usize, usize)> + '_ {
        self.stored_rows().filter_map(|(k, row)| {
            let (lo, hi) = self.extent[row.slot];
            (lo < hi).then_some((k, row, lo as usize, hi as usize))
        })
    }
}

#[derive(Clone, Copy, Debug)]
struct Grid {
    x0: f64,
    y0: f64,
    gx: f64,
    gy: f64,
    nx: usize,
    ny: usize,
}

impl Grid {
    fn cx(&self, c: usize) -> f64 {
        self.x0 + (c as f64 + 0.5) * self.gx
    }

    fn ry(&self, k: usize) -> f64 {
        self.y0 + (k as f64 + 0.5) * self.gy
    }

    /// Columns whose centres lie in [xa, xb], clamped to the grid.
    fn cols(&self, xa: f64, xb: f64) -> Option<(usize, usize)> {
        let c0 = ((xa - self.x0) / self.gx - 0.5).ceil().max(0.0);
        let c1 = ((xb - self.x0) / self.gx - 0.5)
            .floor()
            .min(self.nx as f64 - 1.0);
        (c0 <= c1).then_some((c0 as usize, c1 as usize))
    }
}

/// Sets bits c0..=c1 of `row`. Bit positions are u64: a raster's bits are numbered across
/// all its stored words, past 2³² in a 32-bit build (the page's wasm) once it holds 512 MB.
fn set_range(row: &mut [u64], c0: u64, c1: u64) {
    let (w0, w1) = ((c0 >> 6) as usize, (c1 >> 6) as usize);
    let m0 = !0u64 << (c0 & 63);
    let m1 = !0u64 >> (63 - (c1 & 63));
    if w0 == w1 {
        row[w0] |= m0 & m1;
    } else {
        row[w0] |= m0;
        for w in &mut row[w0 + 1..w1] {
            *w = !0;
        }
        row[w1] |= m1;
    }
}

fn count_range(row: &[u64], c0: usize, c1: usize) -> u32 {
    if c0 > c1 {
        return 0;
    }
    let (w0, w1) = (c0 >> 6, c1 >> 6);
    let m0 = !0u64 << (c0 & 63);
    let m1 = !0u64 >> (63 - (c1 & 63));
    if w0 == w1 {
        (row[w0] & m0 & m1).count_ones()
    } else {
        (row[w0] & m0).count_ones()
            + row[w0 + 1..w1].iter().map(|w| w.count_ones()).sum::<u32>()
            + (row[w1] & m1).count_ones()
    }
}

/// Bits c0..=c1 of `row` (c1 − c0 < 64) shifted down to bit 0.
#[inline]
fn window(row: &[u64], c0: usize, c1: usize) -> u64 {
    let (w, o) = (c0 >> 6, c0 & 63);
    let mut v = row[w] >> o;
    if o != 0 && (c1 >> 6) != w {
        v |= row[w + 1] << (64 - o);
    }
    let n = c1 - c0 + 1;
    if n < 64 { v & ((1u64 << n) - 1) } else { v }
}

/// Calls `span(row, xa, xb)` for every inside span (non-zero rule) of `region` on rows at
/// y0 + (k + ½)·gy, k < ny.
pub(super) fn region_spans(
    region: &Shapes,
    y0: f64,
    gy: f64,
    ny: usize,
    mut span: impl FnMut(usize, f64, f64),
) {
    scanline_spans(
        region,
        |p| p,
        y0,
        gy,
        0.5,
        0..ny as i64,
        |k, xa, xb| span(k as usize, xa, xb),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bit_positions_past_2_to_the_32_set_their_own_words() {
        // A raster of more than 512 MB numbers its bits past 2³²: a 32-bit build (the page's
        // wasm) once wrapped them ("slice index starts at 67105945 but ends at 84"). Zeroed
        // memory the test does not touch is not taken.
        let words = (1usize << 26) + 4;
        let mut bits = vec![0u64; words];
        let base = 64 * (1u64 << 26);
        assert!(base + 3 > u32::MAX as u64);
        set_range(&mut bits, base + 3, base + 70);
        let w = 1 << 26;
        assert_eq!(bits[w], !0u64 << 3);
        assert_eq!(bits[w + 1], (1u64 << 7) - 1);
        assert_eq!(bits[w - 1], 0);
        assert_eq!(bits[w + 2], 0);
        assert_eq!(count_range(&bits[w..], 3, 70), 68);
        // Within one word, and across three.
        set_range(&mut bits, base + 64 * 2 + 5, base + 64 * 2 + 5);
        assert_eq!(bits[w + 2], 1 << 5);
        set_range(&mut bits, base - 2, base + 129);
        assert_eq!(bits[w - 1], 3 << 62);
        assert_eq!((bits[w], bits[w + 1], bits[w + 2]), (!0, !0, 3 | 1 << 5));
    }
}
