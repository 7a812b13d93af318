//! Analysis: see the print before printing. A layer's droplets are rasterised against the
//! layer's true region, giving coverage, voids, overfill and how far the printed outline strays
//! from the boundary; over adjacent layers, a 3D estimate gives the part's void fraction.
//!
//! # The droplet model
//! - **Footprint** (setting `footprint`): in the layer's plane a droplet covers a disc centred
//!   on its position, of diameter D = B (`disc`, the droplet as measured, thesis 4.2) or
//!   D = 2B/√π ≈ 1.13 B (`spread`: the disc whose area is a B × B cell, i.e. a droplet that
//!   flattens with the volume a dense part needs). Discs of diameter B on a lattice of pitch B
//!   only touch, so `disc` leaves at least 1 − π/4 ≈ 21 % of a filled area uncovered: its
//!   figures are a pessimistic bound and best used to compare settings; real droplets flow
//!   into part of those gaps.
//! - **Volume** (3D estimate): a droplet is an oblate spheroid of horizontal diameter D, centred
//!   at its layer's mid-height, whose volume is the cell a droplet must fill, B·B·H. Its height
//!   is therefore 6B²H/(πD²) (1.91 H for `disc`): it reaches about 0.45 H into the layers above
//!   and below, into their gaps, which is what staggering (setting `stagger`) exploits. A
//!   point of the part (layer i's region × its slab) is filled when a spheroid of layer i − 1,
//!   i or i + 1 contains it. Flow, surface tension and the shape of the surface a droplet lands
//!   on are not modelled; spheroids below the first layer are cut by the bed.
//!
//! # The vertical cut
//! [`cut`] gives the same 3D estimate on a vertical plane through a line: per slab, the
//! intervals along the line, at a few heights, that no spheroid fills (exact along the line).
//!
//! # The grid
//! Rows every B/10 ([`ROWS_PER_B`]), columns every B/40 ([`COLS_PER_ROW`] per row). A droplet
//! covers, in each row, as many columns around its centre as the average width of its disc
//! over the row's band, rounded with the remainder carried from row to row (so one disc covers
//! its exact area within half a cell, wherever it lies on the grid); the region covers the
//! columns whose centres lie inside it at the row's centre (non-zero rule). Voids are the
//! region's cells no droplet covers; two void cells in neighbouring rows are connected when
//! their runs overlap by at least [`MIN_PASSAGE_COLS`] columns (B/20), so the voids on both
//! sides of two touching droplets stay apart. The 3D estimate samples the part at cell centres
//! every B/3 ([`GRID3_PER_B`]).
//!
//! # Boundary deviation
//! The printed outline is the droplets' envelope with its enclosed voids filled. Its deviation
//! from the region's boundary is measured one-sidedly: inward, the largest distance from the
//! boundary of an uncovered point connected to the boundary (the depth of the scallops
//! between droplets, or of a wall too thin for any droplet); outward, the largest distance from
//! the region of a covered point outside it. Both are sampled at the ends and the middle of
//! each run of cells, so they are exact to about a grid step.
//!
//! # Speed
//! The voids are labelled in one pass over the rows: a void run takes the label of the first
//! run above it joins, labels (one per run that starts a void) are joined by union-find and
//! keep their sums at the root. The page's coverage mask (cells of at most 3 rows, B/4 in
//! the page) adds each row's bit counts per group of 4 columns, a word at a time, and sums a
//! cell's groups once per mask row; a cell's share comes from a table of the counts it can
//! hold. The page's worker keeps one raster from layer to layer (its memory allocated once)
//! and counts only the void and overfill shares ([`analyse_layer_for_page`]). The figures and
//! masks are those of the paths they replaced, kept as `Raster::analysis_reference` and
//! `Raster::mask_reference` for tests (tests/analysis_fast.rs; built for tests and with the
//! `reference` feature only). docs/quality.md (*Analysis speed*) has the profile, and why the
//! periodic interior of the hatch does not help on this axis-aligned grid.
//!
//! # The band (`--report`)
//! The job analysis ([`JobAnalysis`], [`LayerStage`]) works in a band around each layer's
//! boundary and counts the interior, so that its cost grows with the boundary, not the
//! volume. Away from the contours the droplets are the fill's lines, B apart, and the
//! figures there depend only on the settings and the kind of layer:
//! - **2D** ([`Raster::rebuild_banded`]): blocks of 16 rows × 64 columns (1.6 B) within the
//!   band's width (the contours, the fill's margin and 3 B) of a boundary edge are rasterised
//!   and labelled as before; the interior blocks are not. Their cells and their droplets'
//!   cells are counted (discs of diameter B on lines B apart do not overlap, so their cells
//!   add up; with `footprint = spread` or a fill density other than 1 the whole layer is
//!   rasterised); interior blocks inside the stored tiles are stored as covered region, so
//!   the band's voids end there as at a droplet. The droplets come as the plan's lines
//!   ([`DropletLines`]): a walk along each (`lines.rs`) passes over a stretch of droplets at a
//!   time where they lie 2 blocks or more inside the interior (counted, the cells of an
//!   average droplet each) and places the others one by one. Coverage, void and enclosed areas, overfill
//!   and the boundary deviation are so computed; the interior's void count is estimated at
//!   the rate measured on a patch ([`InteriorCache`]: a disc of radius 32 B planned as the
//!   job's layer, its voids by the whole raster against the band's); the **largest void is
//!   the band's**: the whole raster joins the channels between the fill's lines through the
//!   interior into networks of several mm² that the band does not see.
//! - **3D** ([`slab_voids_banded`]): blocks of 8 × 8 cells of the 3D grid, fixed to the job;
//!   a layer's droplets whose cells all lie in its deep interior (2 blocks beyond the band)
//!   are left out of its map ([`UnitMap`]; walked over along their lines as in 2D). A slab's
//!   cells in blocks that are interior in its own layer and both neighbours take the void
//!   share measured on the slab's own sample blocks (one block in 8 to 256 spread over rows
//!   and columns as a lattice, fewer the larger the job's layers, so that a layer of the
//!   job's mean area has about 64 of them: [`Samples`]; their droplets every map keeps and
//!   their cells are filled exactly; the patch's share when fewer than 256 cells are
//!   sampled); every other cell is filled exactly, from maps
//!   with every droplet that reaches it (where a left-out droplet reaches a block that is
//!   deep in one layer but not interior in a neighbour, the slab reads a patch of that
//!   layer's map there, built from the droplets of the lines near those blocks).
//!
//! The whole raster and the exact fill stay as the reference ([`JobAnalysis::reference`],
//! built for tests and with the `reference` feature); tests/analysis_band.rs holds the banded
//! report to it. The page's per-layer figures and void overlay use the whole raster
//! ([`analyse_layer_for_page`]); its slabs take unit 0's maps without a region, so whole.
//!
//! # Memory
//! The grids span the layer's bounding box, but only tiles near its region and droplets are
//! stored ([`Tiles`]): the 2D bitmaps in tiles of 64 rows × 256 columns (1.3 mm square with the
//! default B), the spheroid maps in tiles of 32 × 32 cells (2.2 mm), the coverage mask in tiles
//! over those. Parts a metre apart take the memory each takes alone, and the figures are those
//! of a dense grid: the same grid, its rows and runs visited in the same order.

mod cut;
mod droplet;
mod estimate3d;
mod interior;
mod lines;
mod part;
mod raster;
mod report;
mod slabs;

pub use cut::{CUT_BANDS, CutLine, CutVoid, MAX_CUT_LENGTH, Near, slab_section_voids};
pub use droplet::{droplet_centres, footprint_diameter, spheroid_half_height, unit_part_centres};
#[cfg(any(test, feature = "reference"))]
pub use estimate3d::slab_voids_reference;
pub use estimate3d::{
    Blocks, GRID3_PER_B, Grid3, HeightMap, Samples, UnitMap, slab_voids, slab_voids_banded,
};
pub use interior::{InteriorCache, InteriorRates};
pub use lines::DropletLines;
pub use part::{DensityEstimate, PartAnalysis};
pub use raster::{
    COLS_PER_ROW, CellRect, CoverageMask, LayerAnalysis, MIN_PASSAGE_COLS, MaskTile, ROWS_PER_B,
    Raster, Void, analyse_layer, analyse_layer_for_page, analyse_layer_with_mask,
};
pub use report::{AnalysedLayer, AnalysisGrid, JobAnalysis, LayerStage, Model, Report};
pub use slabs::{LayerMaps, SlabFigures, SlabRun, UnitRegions};
