//! The 2D analysis of one layer: its droplets rasterised against its region (coverage, voids,
//! overfill, boundary deviation) and the coverage mask for the page's overlay.

use super::droplet::{droplet_centres, footprint_diameter};
use crate::base::geom::{DVec2, Point, Shapes, all_contours, dist, region_area, scanline_spans};
use crate::base::settings::Settings;
use crate::base::spatial::{EdgeIndex, Row, Spot, Tiles};
use crate::slicing::plan::LayerPlan;
use serde::Serialize;

/// Grid rows per droplet width B.
pub const ROWS_PER_B: f64 = 10.0;
/// Grid columns per row height (columns every B/40).
pub const COLS_PER_ROW: f64 = 4.0;
/// Void runs in neighbouring rows connect when they overlap by at least this many columns.
pub const MIN_PASSAGE_COLS: u32 = 2;
/// Steps of the table of band-averaged half-widths (a droplet's offset within its first row).
const PHASES: usize = 256;

/// One connected void of a layer.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
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
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
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

/// A rectangle of a [`CoverageMask`]: cells (col + i, row + j) for i < width, j < height, the
/// shares of cell (col + i, row + j) at index j·width + i.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MaskTile {
    pub col: usize,
    pub row: usize,
    pub width: usize,
    pub height: usize,
    pub void: Vec<u8>,
    pub overfill: Vec<u8>,
    pub covered: Vec<u8>,
}

impl CoverageMask {
    /// Where tile `t`'s cell (0, 0) starts, in mm.
    pub fn tile_origin(&self, t: &MaskTile) -> Point {
        DVec2::new(
            self.origin[0] + t.col as f64 * self.cell,
            self.origin[1] + t.row as f64 * self.cell,
        )
    }

    /// The shares [void, overfill, covered] of cell (col, row); zero outside the tiles.
    pub fn shares(&self, col: usize, row: usize) -> [u8; 3] {
        self.tiles
            .iter()
            .find(|t| {
                (t.col..t.col + t.width).contains(&col) && (t.row..t.row + t.height).contains(&row)
            })
            .map_or([0; 3], |t| {
                let i = (row - t.row) * t.width + col - t.col;
                [t.void[i], t.overfill[i], t.covered[i]]
            })
    }

    /// Cells (width, height) from the origin to the far corner of the last tiles.
    pub fn size(&self) -> (usize, usize) {
        self.tiles.iter().fold((0, 0), |(w, h), t| {
            (w.max(t.col + t.width), h.max(t.row + t.height))
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

/// Rows of the 2D grid per band of the sparse raster, and words (of 64 columns) per tile: tiles
/// of 64 × 256 cells, 1.33 mm square with the default B.
const BAND_ROWS: usize = 64;
const TILE_WORDS: usize = 4;
/// Mask cells of at most this many grid rows are counted by 4-bit groups
/// ([`Raster::count_by_nibbles`]).
const NIBBLE_ROWS: usize = 3;
/// Mask rows per band of a [`CoverageMask`]'s tiles.
const MASK_BAND_ROWS: usize = 64;

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
}

/// Buffers of [`Raster::voids_fast`].
#[derive(Default)]
struct Scratch {
    runs: Vec<(u32, u32, u32, u32)>,
    bnd: Vec<bool>,
    parent: Vec<u32>,
    cells: Vec<u64>,
    root: Vec<u32>,
    /// The region rows above and below, when copied from another band.
    around: (Vec<u64>, Vec<u64>),
}

/// Which labelling [`Raster::analysis_with`] runs.
#[derive(Clone, Copy)]
enum Path {
    /// The labelling before the fast paths, a union-find node per run.
    Reference,
    /// The one-pass labelling, natively with the popcount instruction when the CPU has it.
    Fast,
    /// The one-pass labelling without it.
    Portable,
}

/// A void run's label before the labelling gives it one.
const NO_LABEL: u32 = u32::MAX;

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

fn set_range(row: &mut [u64], c0: usize, c1: usize) {
    let (w0, w1) = (c0 >> 6, c1 >> 6);
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

/// Band-averaged half-widths of a disc of radius `r` on rows of height `gy`: entry
/// [phase][j] for the j-th row from the one holding the disc's lowest point, when that point
/// lies `(phase + ½)/PHASES` of a row above the row's bottom.
fn half_width_table(r: f64, gy: f64) -> (usize, Vec<f64>) {
    let rows = (2.0 * r / gy).ceil() as usize + 2;
    let g = |t: f64| {
        let t = t.clamp(-r, r);
        0.5 * (t * (r * r - t * t).max(0.0).sqrt() + r * r * (t / r).clamp(-1.0, 1.0).asin())
    };
    let mut table = vec![0.0; PHASES * rows];
    for ph in 0..PHASES {
        let phi = (ph as f64 + 0.5) / PHASES as f64;
        for j in 0..rows {
            // Band j relative to the disc's centre.
            let lo = (j as f64 - phi) * gy - r;
            let hi = lo + gy;
            table[ph * rows + j] = (g(hi) - g(lo)) / gy;
        }
    }
    (rows, table)
}

/// The cells of word `w` of a row's region words `bits` (its segment starting at word `at`,
/// ending before `end`) whose four neighbours (left, right, above in `up`, below in `down`)
/// all lie in the region: a region cell not among them is an edge cell.
#[inline(always)]
fn interior(
    bits: &[u64],
    w: usize,
    at: usize,
    end: usize,
    up: Option<&[u64]>,
    down: Option<&[u64]>,
) -> u64 {
    let r = bits[w];
    let left = (r << 1) | if w > at { bits[w - 1] >> 63 } else { 0 };
    let right = (r >> 1) | if w + 1 < end { bits[w + 1] << 63 } else { 0 };
    left & right & up.map_or(0, |x| x[w]) & down.map_or(0, |x| x[w])
}

impl Raster {
    /// Rasterises a layer's region and droplets.
    pub fn new(plan: &LayerPlan, region: &Shapes, s: &Settings) -> Raster {
        let b = s.droplet_width();
        let centres = droplet_centres(plan, b);
        Raster::from_centres(plan.index, plan.z, &centres, region, s)
    }

    /// Rasterises droplets at `centres` against `region`.
    pub fn from_centres(
        index: usize,
        z: f64,
        centres: &[Point],
        region: &Shapes,
        s: &Settings,
    ) -> Raster {
        let mut r = Raster::empty();
        r.rebuild(index, z, centres, region, s);
        r
    }

    /// A raster of nothing, to [`rebuild`](Self::rebuild) (reusing its memory).
    pub fn empty() -> Raster {
        Raster {
            index: 0,
            z: 0.0,
            droplets: 0,
            region_area: 0.0,
            b: 1.0,
            grid: Grid {
                x0: 0.0,
                y0: 0.0,
                gx: 1.0,
                gy: 1.0,
                nx: 0,
                ny: 0,
            },
            tiles: Tiles::default(),
            region_bits: Vec::new(),
            drop_bits: Vec::new(),
            extent: Vec::new(),
            edges: Vec::new(),
            spans: Vec::new(),
            places: Vec::new(),
            scratch: Default::default(),
        }
    }

    /// [`from_centres`](Self::from_centres) into this raster's memory.
    pub fn rebuild(
        &mut self,
        index: usize,
        z: f64,
        centres: &[Point],
        region: &Shapes,
        s: &Settings,
    ) {
        let b = s.droplet_width();
        let r = footprint_diameter(s) / 2.0;
        let gy = b / ROWS_PER_B;
        let gx = gy / COLS_PER_ROW;
        let mut min = [f64::INFINITY; 2];
        let mut max = [f64::NEG_INFINITY; 2];
        for p in all_contours(region).flatten() {
            for k in 0..2 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        for p in centres {
            for k in 0..2 {
                min[k] = min[k].min(p[k] - r);
                max[k] = max[k].max(p[k] + r);
            }
        }
        self.edges.clear();
        for c in all_contours(region) {
            for i in 0..c.len() {
                self.edges.push((c[i], c[(i + 1) % c.len()]));
            }
        }
        if !min[0].is_finite() {
            min = [0.0, 0.0];
            max = [0.0, 0.0];
        }
        let margin = 2.0 * gy;
        let x0 = min[0] - margin;
        let y0 = min[1] - margin;
        let nx = ((max[0] + margin - x0) / gx).ceil() as usize + 1;
        let ny = ((max[1] + margin - y0) / gy).ceil() as usize + 1;
        let nw = nx.div_ceil(64);
        let grid = Grid {
            x0,
            y0,
            gx,
            gy,
            nx,
            ny,
        };
        // First the tiles the region and the droplets touch, then their bits.
        let tiles = &mut self.tiles;
        tiles.reset(ny, nw, BAND_ROWS, TILE_WORDS);
        let spans = &mut self.spans;
        spans.clear();
        region_spans(region, y0, gy, ny, |k, xa, xb| {
            if let Some((c0, c1)) = grid.cols(xa, xb) {
                spans.push((k as u32, c0 as u32, c1 as u32));
            }
        });
        for &(k, c0, c1) in spans.iter() {
            let k = k as usize;
            tiles.mark(k, k, c0 as usize >> 6, c1 as usize >> 6);
        }
        let (rows, table) = half_width_table(r, gy);
        // Per phase and row, the columns covered (n, and (n − 1)/2): the rounding carry
        // depends only on the phase, not on the droplet.
        let spans: Vec<(i64, f64)> = table
            .chunks(rows)
            .flat_map(|widths| {
                let mut carry = 0.0;
                widths.iter().map(move |&w| {
                    let want = 2.0 * w / gx + carry;
                    // Rounding by truncation: every value here is ≥ 0.
                    let n = (want + 0.5) as i64;
                    carry = want - n as f64;
                    (n, (n - 1) as f64 / 2.0)
                })
            })
            .collect();
        // Per phase, the widest row: a droplet's columns in every row lie within its columns.
        let widest: Vec<(i64, f64)> = spans
            .chunks(rows)
            .map(|c| c.iter().copied().max_by_key(|s| s.0).unwrap_or((0, 0.0)))
            .collect();
        // A droplet's first row, phase, and centre in column units (column c's centre at u = c).
        let place = |p: &Point| {
            let v = (p[1] - r - y0) / gy;
            let k0 = v.floor();
            let ph = (((v - k0) * PHASES as f64) as usize).min(PHASES - 1);
            (k0 as usize, ph, (p[0] - x0) / gx - 0.5)
        };
        let places = &mut self.places;
        places.clear();
        places.extend(centres.iter().map(place));
        for &(k0, ph, u) in places.iter() {
            let (n, half) = widest[ph];
            if n >= 1 {
                let c0 = (u - half + 0.5) as i64;
                // A column to spare on each side.
                let w0 = (c0 - 1).max(0) as usize >> 6;
                let w1 = (c0 + n).max(0) as usize >> 6;
                tiles.mark(k0, k0 + rows - 1, w0, w1);
            }
        }
        let len = tiles.build();
        self.region_bits.clear();
        self.region_bits.resize(len, 0);
        self.drop_bits.clear();
        self.drop_bits.resize(len, 0);
        self.extent.clear();
        self.extent.resize(tiles.row_slots(), (u32::MAX, 0));
        let (region_bits, drop_bits, extent) =
            (&mut self.region_bits, &mut self.drop_bits, &mut self.extent);
        // Columns c0..=c1 of a row's slice are set.
        let mut mark = |slot: usize, c0: usize, c1: usize| {
            let e = &mut extent[slot];
            e.0 = e.0.min((c0 >> 6) as u32);
            e.1 = e.1.max((c1 >> 6) as u32 + 1);
        };
        // Where the last span or droplet row was stored (mostly where the next one is).
        let mut spot: Option<Spot> = None;
        for &(k, c0, c1) in self.spans.iter() {
            let (k, c0, c1) = (k as usize, c0 as usize, c1 as usize);
            let Some(sp) = tiles.spot_cached(&mut spot, k, c0 >> 6, c1 >> 6) else {
                debug_assert!(false, "region span outside the tiles");
                continue;
            };
            let (c0, c1) = (c0 - 64 * sp.shift, c1 - 64 * sp.shift);
            let at = 64 * sp.index(k);
            set_range(region_bits, at + c0, at + c1);
            mark(sp.slot(k), c0, c1);
        }
        for &(k0, ph, u) in self.places.iter() {
            let rows_of = &spans[ph * rows..(ph + 1) * rows];
            // Mostly the whole droplet lies in the grid and in one band and segment: its rows
            // are then one step apart in the storage.
            let (n, half) = widest[ph];
            let (w0, k1) = ((u - half + 0.5) as i64, k0 + rows - 1);
            let whole = n >= 1 && w0 >= 0 && w0 + n <= nx as i64 && k1 < ny;
            let (w0, w1) = (w0.max(0) as usize, (w0 + n - 1).max(0) as usize);
            if let Some(sp) = whole
                .then(|| tiles.spot_cached(&mut spot, k0, w0 >> 6, w1 >> 6))
                .flatten()
                .filter(|sp| k1 < sp.end_row)
            {
                let shift = 64 * sp.shift;
                let mut at = 64 * sp.index(k0);
                for (slot, &(n, half)) in (sp.slot(k0)..).zip(rows_of) {
                    if n >= 1 {
                        // Within the widest row's columns: ≥ w0 ≥ 0, so the value is above −1
                        // and `as i64` truncates it as `as usize` would (one instruction on
                        // baseline x86-64; `as usize` takes a dozen).
                        let c0 = (u - half + 0.5) as i64 as usize - shift;
                        let c1 = c0 + n as usize - 1;
                        set_range(drop_bits, at + c0, at + c1);
                        mark(slot, c0, c1);
                    }
                    at += 64 * sp.row_len;
                }
                continue;
            }
            for (j, &(n, half)) in rows_of.iter().enumerate() {
                let k = k0 + j;
                if n < 1 || k >= ny {
                    continue;
                }
                let c0 = (u - half + 0.5) as i64;
                let c1 = c0 + n - 1;
                if c0 < 0 || c1 >= nx as i64 {
                    continue;
                }
                let (c0, c1) = (c0 as usize, c1 as usize);
                let Some(sp) = tiles.spot_cached(&mut spot, k, c0 >> 6, c1 >> 6) else {
                    debug_assert!(false, "droplet outside the tiles");
                    continue;
                };
                let (c0, c1) = (c0 - 64 * sp.shift, c1 - 64 * sp.shift);
                let at = 64 * sp.index(k);
                set_range(drop_bits, at + c0, at + c1);
                mark(sp.slot(k), c0, c1);
            }
        }
        self.index = index;
        self.z = z;
        self.droplets = centres.len() as u64;
        self.region_area = region_area(region);
        self.b = b;
        self.grid = grid;
    }

    /// Words of memory its bitmaps take (for tests of the memory it needs).
    pub fn stored_words(&self) -> usize {
        self.region_bits.len() + self.drop_bits.len()
    }

    /// Runs [start, end) of set bits of `mask(region word, droplet word)` in `row`, in grid
    /// columns, appended to `out`.
    fn runs(&self, row: &Row, mask: impl Fn(u64, u64) -> u64, out: &mut Vec<(u32, u32)>) {
        let (r, d) = (&self.region_bits[row.range()], &self.drop_bits[row.range()]);
        let (lo, hi) = self.extent[row.slot];
        for seg in row.segs {
            let (a, e) = (seg.at.max(lo as usize), seg.end().min(hi as usize));
            if a >= e {
                continue;
            }
            // Grid column of the slice's column 0 in this segment.
            let shift = (64 * seg.shift()) as u32;
            let mut carry = 0u64;
            // Starts are pushed as they come, ends fill the runs in order (`open` the first
            // run without its end): no branch on which comes first.
            let mut open = out.len();
            for w in a..e {
                let v = mask(r[w], d[w]);
                let prev = (v << 1) | carry;
                let mut starts = v & !prev;
                let mut ends = !v & prev;
                let base = (w * 64) as u32 + shift;
                while starts != 0 {
                    out.push((base + starts.trailing_zeros(), 0));
                    starts &= starts - 1;
                }
                while ends != 0 {
                    out[open].1 = base + ends.trailing_zeros();
                    open += 1;
                    ends &= ends - 1;
                }
                carry = v >> 63;
            }
            // The segment's next word is not stored (zero) or beyond the row's bits.
            if carry != 0 {
                out[open].1 = (e * 64) as u32 + shift;
            }
        }
    }

    /// The region words of the rows above and below row `k`, laid out as `row`'s slice
    /// ([`region_row_as`](Self::region_row_as); `None` where there is no such row or it holds
    /// nothing).
    fn neighbour_rows<'a>(
        &'a self,
        row: &Row,
        k: usize,
        (up_buf, down_buf): (&'a mut Vec<u64>, &'a mut Vec<u64>),
    ) -> (Option<&'a [u64]>, Option<&'a [u64]>) {
        let up = (k + 1 < self.grid.ny)
            .then(|| self.region_row_as(row, k + 1, up_buf))
            .flatten();
        let down = (k > 0)
            .then(|| self.region_row_as(row, k - 1, down_buf))
            .flatten();
        (up, down)
    }

    /// The region words of row `k` laid out as `row`'s slice (its own slice when both are in
    /// the same band, else copied into `buf`); `None` when row `k` holds nothing.
    fn region_row_as<'a>(
        &'a self,
        row: &Row,
        k: usize,
        buf: &'a mut Vec<u64>,
    ) -> Option<&'a [u64]> {
        let other = self.tiles.row(k)?;
        if other.band == row.band {
            return Some(&self.region_bits[other.range()]);
        }
        buf.clear();
        buf.resize(row.len, 0);
        for s in row.segs {
            for o in other.segs {
                let (c0, c1) = (s.c0.max(o.c0), s.c1.min(o.c1));
                if c0 < c1 {
                    let from = other.offset + c0 - o.shift();
                    buf[c0 - s.shift()..c1 - s.shift()]
                        .copy_from_slice(&self.region_bits[from..from + c1 - c0]);
                }
            }
        }
        Some(buf)
    }

    /// The figures of the layer.
    pub fn analysis(&self) -> LayerAnalysis {
        self.analysis_with(Path::Fast)
    }

    /// [`analysis`](Self::analysis) as it was before the fast paths (for tests comparing both).
    #[doc(hidden)]
    pub fn analysis_reference(&self) -> LayerAnalysis {
        self.analysis_with(Path::Reference)
    }

    /// [`analysis`](Self::analysis) compiled without the popcount instruction, whichever CPU
    /// runs it (for tests: natively the fast path takes the instruction when the CPU has it).
    #[doc(hidden)]
    pub fn analysis_portable(&self) -> LayerAnalysis {
        self.analysis_with(Path::Portable)
    }

    /// Adds the cells of the region, covered region and overfill to `counts`, and the rows
    /// holding overfill to `over_rows` (the reference's pass; the fast path counts them as it
    /// labels).
    fn count_cells(&self, counts: &mut [u64; 3], over_rows: &mut Vec<usize>) {
        let tiles = &self.tiles;
        for (bi, band) in tiles.bands().iter().enumerate() {
            for k in band.first_row..band.end_row {
                let row = tiles.row_in(bi, k);
                let (lo, hi) = self.extent[row.slot];
                if lo >= hi {
                    continue;
                }
                let range = row.offset + lo as usize..row.offset + hi as usize;
                let before = counts[2];
                for (r, d) in self.region_bits[range.clone()]
                    .iter()
                    .zip(&self.drop_bits[range])
                {
                    counts[0] += r.count_ones() as u64;
                    counts[1] += (r & d).count_ones() as u64;
                    counts[2] += (d & !r).count_ones() as u64;
                }
                if counts[2] > before {
                    over_rows.push(k);
                }
            }
        }
    }

    fn analysis_with(&self, path: Path) -> LayerAnalysis {
        let g = self.grid;
        let tiles = &self.tiles;
        let cell = g.gx * g.gy;
        let index = EdgeIndex::new(&self.edges, self.b);
        let mut counts = [0u64; 3];
        let mut over_rows = Vec::new();
        let v = match path {
            Path::Reference => {
                self.count_cells(&mut counts, &mut over_rows);
                self.voids_reference(&index)
            }
            Path::Fast => self.voids_fast(&index, &mut counts, &mut over_rows),
            Path::Portable => self.voids_fast_with(&index, &mut counts, &mut over_rows),
        };
        let [n_region, n_covered, n_over] = counts;
        let dev_in = v.dev_in;
        // Outward deviation: overfill runs.
        let mut dev_out = Deviation::default();
        let mut buf = Vec::new();
        for &k in &over_rows {
            buf.clear();
            if let Some(row) = tiles.row(k) {
                self.runs(&row, |r, d| d & !r, &mut buf);
            }
            for &(s, e) in &buf {
                probe(&g, &index, &mut dev_out, k, s, e);
            }
        }
        let coverage = if n_region > 0 {
            n_covered as f64 / n_region as f64
        } else {
            0.0
        };
        let (boundary_deviation, deviation_at) = if dev_out.max > dev_in.max {
            (dev_out.max, dev_out.at)
        } else {
            (dev_in.max, dev_in.at)
        };
        LayerAnalysis {
            index: self.index,
            z: self.z,
            droplets: self.droplets,
            region_area: self.region_area,
            covered_area: n_covered as f64 * cell,
            coverage,
            void_area: (n_region - n_covered) as f64 * cell,
            enclosed_void_area: v.enclosed as f64 * cell,
            voids: v.count,
            largest_void: v.largest,
            overfill_area: n_over as f64 * cell,
            deviation_inward: dev_in.max,
            deviation_outward: dev_out.max,
            boundary_deviation,
            deviation_at,
            unsupported_area: 0.0,
        }
    }

    /// Sets `edge` to the cells of row `k` (laid out as `row`) in the region with a
    /// neighbour (left, right, above, below) outside it, over the row's extent.
    fn edge_row(
        &self,
        row: &Row,
        k: usize,
        edge: &mut [u64],
        up_buf: &mut Vec<u64>,
        down_buf: &mut Vec<u64>,
    ) {
        let (lo, hi) = self.extent[row.slot];
        let bits = &self.region_bits[row.range()];
        let (up, down) = self.neighbour_rows(row, k, (up_buf, down_buf));
        for seg in row.segs {
            let end = seg.end();
            for w in seg.at.max(lo as usize)..end.min(hi as usize) {
                edge[w] = bits[w] & !interior(bits, w, seg.at, end, up, down);
            }
        }
    }

    /// The voids by one union-find node per void run, components summed after the
    /// labelling (the labelling as it was before the fast path, for tests comparing both).
    fn voids_reference(&self, index: &EdgeIndex) -> Voids {
        let g = self.grid;
        let tiles = &self.tiles;
        // Voids: runs of region & !droplets, joined across rows.
        let mut runs: Vec<(u32, u32, u32)> = Vec::new(); // (row, start, end)
        let mut touches: Vec<bool> = Vec::new();
        let mut uf = UnionFind::new(0);
        let mut buf = Vec::new();
        // The runs of the row before, and the row after the last one looked at.
        let mut prev = 0..0;
        let mut next_k = 0;
        let widest = tiles.bands().iter().map(|b| b.row_len).max().unwrap_or(0);
        let mut edge = vec![0u64; widest];
        let (mut up_buf, mut down_buf) = (Vec::new(), Vec::new());
        for (bi, band) in tiles.bands().iter().enumerate() {
            for k in band.first_row..band.end_row {
                if k != next_k {
                    prev = runs.len()..runs.len();
                }
                next_k = k + 1;
                let row = tiles.row_in(bi, k);
                buf.clear();
                self.runs(&row, |r, d| r & !d, &mut buf);
                if buf.is_empty() {
                    prev = runs.len()..runs.len();
                    continue;
                }
                self.edge_row(&row, k, &mut edge, &mut up_buf, &mut down_buf);
                let first = runs.len();
                let mut seg = 0;
                for &(s, e) in &buf {
                    while row.segs[seg].c1 * 64 <= s as usize {
                        seg += 1;
                    }
                    let shift = 64 * row.segs[seg].shift();
                    let (c0, c1) = (s as usize - shift, e as usize - 1 - shift);
                    runs.push((k as u32, s, e));
                    touches.push(count_range(&edge, c0, c1) > 0);
                    uf.parent.push(uf.parent.len() as u32);
                }
                let cur = first..runs.len();
                let (mut i, mut j) = (prev.start, cur.start);
                while i < prev.end && j < cur.end {
                    let (_, s1, e1) = runs[i];
                    let (_, s2, e2) = runs[j];
                    if e1.min(e2) >= s1.max(s2) + MIN_PASSAGE_COLS {
                        uf.union(i, j);
                    }
                    if e1 < e2 { i += 1 } else { j += 1 }
                }
                prev = cur;
            }
        }
        // Components, numbered in order of their first run (a root precedes its members).
        let mut comp = vec![0u32; runs.len()];
        let mut accs: Vec<Acc> = Vec::new();
        for (i, &(k, s, e)) in runs.iter().enumerate() {
            let root = uf.find(i);
            let id = if root == i {
                accs.push(Acc::default());
                accs.len() - 1
            } else {
                comp[root] as usize
            };
            comp[i] = id as u32;
            accs[id].add(k, s, e, touches[i]);
        }
        // Inward deviation: runs of voids that reach the boundary.
        let mut dev_in = Deviation::default();
        for (i, &(k, s, e)) in runs.iter().enumerate() {
            if accs[comp[i] as usize].boundary {
                probe(&g, index, &mut dev_in, k as usize, s, e);
            }
        }
        Voids::of(&g, accs.iter(), dev_in)
    }

    /// The void runs of row `k` (laid out as `row`) appended to `runs` as (row, start, end,
    /// `NO_LABEL`), and to `bnd` whether each touches a region cell with a neighbour (left,
    /// right, above, below) outside the region: the runs of [`runs`](Self::runs) with the
    /// boundary test of [`edge_row`](Self::edge_row), in one pass over the words. A run
    /// touches the edge when adding its edge cells to the void bits carries out of it: the
    /// row's void words plus their edge cells, added as one long number, set the bit just
    /// above each run holding an edge cell (where the run ends) and no other bit outside the
    /// void.
    #[inline(always)]
    fn void_runs(
        &self,
        row: &Row,
        k: usize,
        runs: &mut Vec<(u32, u32, u32, u32)>,
        bnd: &mut Vec<bool>,
        (up_buf, down_buf): &mut (Vec<u64>, Vec<u64>),
        counts: &mut [u64; 3],
    ) -> bool {
        let mut over = 0u64;
        let (lo, hi) = self.extent[row.slot];
        let range = row.range();
        let (bits, drops) = (&self.region_bits[range.clone()], &self.drop_bits[range]);
        let (up, down) = self.neighbour_rows(row, k, (up_buf, down_buf));
        let k = k as u32;
        for seg in row.segs {
            let end = seg.end();
            let (a, e) = (seg.at.max(lo as usize), end.min(hi as usize));
            if a >= e {
                continue;
            }
            let (bits, drops) = (&bits[..end], &drops[..end]);
            let (up, down) = (up.map(|x| &x[..end]), down.map(|x| &x[..end]));
            // Grid column of the slice's column 0 in this segment.
            let shift = (64 * seg.shift()) as u32;
            // The last word's top void bit, and the carry of the addition.
            let (mut carry, mut touch) = (0u64, false);
            // Starts are pushed as they come, ends fill the runs in order (`open` the first
            // run without its end).
            let mut open = runs.len();
            for w in a..e {
                let (r, dr) = (bits[w], drops[w]);
                counts[0] += r.count_ones() as u64;
                counts[1] += (r & dr).count_ones() as u64;
                counts[2] += (dr & !r).count_ones() as u64;
                over |= dr & !r;
                let v = r & !dr;
                if v | carry == 0 {
                    // No run here and none open (so no carry of the addition either).
                    continue;
                }
                let edge = v & !interior(bits, w, seg.at, end, up, down);
                let (sum, c1) = v.overflowing_add(edge);
                let (sum, c2) = sum.overflowing_add(touch as u64);
                touch = c1 | c2;
                let touched = sum & !v;
                let prev = (v << 1) | carry;
                let mut starts = v & !prev;
                let mut ends = !v & prev;
                let base = (w * 64) as u32 + shift;
                while starts != 0 {
                    runs.push((k, base + starts.trailing_zeros(), 0, NO_LABEL));
                    starts &= starts - 1;
                }
                while ends != 0 {
                    let t = ends.trailing_zeros();
                    runs[open].2 = base + t;
                    // Runs end in order: `bnd` has an entry per run ended.
                    bnd.push((touched >> t) & 1 != 0);
                    open += 1;
                    ends &= ends - 1;
                }
                carry = v >> 63;
            }
            // The segment's next word is not stored (zero) or beyond the row's bits.
            if carry != 0 {
                runs[open].2 = (e * 64) as u32 + shift;
                bnd.push(touch);
            }
        }
        over != 0
    }

    /// [`voids_reference`](Self::voids_reference) in one pass over the rows: a run takes the
    /// label of the first run above it joins (a new label when none), labels are joined by
    /// union-find, and each label's cell count and boundary flag are kept at its root as runs
    /// come in, so there are as many union-find nodes as runs that start a void, not as runs.
    /// The largest void's centroid and box are summed afterwards from its runs. Figures
    /// identical.
    /// Also adds the cells of the region, covered region and overfill to `counts` and the rows
    /// holding overfill to `over_rows`, as [`count_cells`](Self::count_cells) does, in the
    /// same pass over the words. Natively on a CPU with a popcount instruction, compiled for
    /// it (the baseline x86-64 target counts bits by shifts and adds).
    fn voids_fast(
        &self,
        index: &EdgeIndex,
        counts: &mut [u64; 3],
        over_rows: &mut Vec<usize>,
    ) -> Voids {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("popcnt") {
            // SAFETY: the CPU has the instruction, as the check above found.
            return unsafe { self.voids_popcnt(index, counts, over_rows) };
        }
        self.voids_fast_with(index, counts, over_rows)
    }

    /// [`voids_fast_with`](Self::voids_fast_with) compiled with the popcount instruction.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "popcnt")]
    fn voids_popcnt(
        &self,
        index: &EdgeIndex,
        counts: &mut [u64; 3],
        over_rows: &mut Vec<usize>,
    ) -> Voids {
        self.voids_fast_with(index, counts, over_rows)
    }

    #[inline(always)]
    fn voids_fast_with(
        &self,
        index: &EdgeIndex,
        counts: &mut [u64; 3],
        over_rows: &mut Vec<usize>,
    ) -> Voids {
        // A label's cells, with the boundary flag in the top bit.
        const TOP: u64 = 1 << 63;
        let g = self.grid;
        let tiles = &self.tiles;
        let mut scratch = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        let Scratch {
            runs,
            bnd,
            parent,
            cells,
            root,
            around,
        } = &mut *scratch;
        // (row, start, end, label)
        runs.clear();
        bnd.clear();
        cells.clear();
        parent.clear();
        let find = |parent: &mut Vec<u32>, mut i: usize| {
            while parent[i] as usize != i {
                let p = parent[i] as usize;
                parent[i] = parent[p];
                i = p;
            }
            i
        };
        let mut prev = 0..0;
        let mut next_k = 0;
        for (bi, band) in tiles.bands().iter().enumerate() {
            for k in band.first_row..band.end_row {
                if k != next_k {
                    prev = runs.len()..runs.len();
                }
                next_k = k + 1;
                let row = tiles.row_in(bi, k);
                let first = runs.len();
                if self.void_runs(&row, k, runs, bnd, around, counts) {
                    over_rows.push(k);
                }
                if runs.len() == first {
                    prev = first..first;
                    continue;
                }
                let (mut i, mut j) = (prev.start, first);
                while i < prev.end && j < runs.len() {
                    let (_, s1, e1, l1) = runs[i];
                    let (_, s2, e2, l2) = runs[j];
                    let joined = e1.min(e2) >= s1.max(s2) + MIN_PASSAGE_COLS;
                    // One branch, taken rarely (`joined &&` would branch on `joined`, which
                    // is as often true as not).
                    if joined & (l2 != NO_LABEL) {
                        // A second run above: rare.
                        let (a, b) = (find(parent, l1 as usize), find(parent, l2 as usize));
                        if a != b {
                            // The earlier label stays the root: roots in order of their
                            // component's first run, as the reference numbers them.
                            let (lo, hi) = (a.min(b), a.max(b));
                            parent[hi] = lo as u32;
                            let h = cells[hi];
                            cells[lo] = (cells[lo] + (h & !TOP)) | (h & TOP);
                        }
                    }
                    // Without branches on the data: the first run above gives its label.
                    runs[j].3 = if joined && l2 == NO_LABEL { l1 } else { l2 };
                    let step = (e1 < e2) as usize;
                    i += step;
                    j += 1 - step;
                }
                for (run, &b) in runs[first..].iter_mut().zip(&bnd[first..]) {
                    let l = if run.3 == NO_LABEL {
                        parent.push(cells.len() as u32);
                        cells.push(0);
                        cells.len() - 1
                    } else {
                        find(parent, run.3 as usize)
                    };
                    run.3 = l as u32;
                    cells[l] = (cells[l] + (run.2 - run.1) as u64) | ((b as u64) << 63);
                }
                prev = first..runs.len();
            }
        }
        // Each label's root (a label's parent precedes it), the voids and the largest: the
        // first of the largest roots, in label order, as `Voids::of` takes them.
        let cell = g.gx * g.gy;
        root.clear();
        let (mut count, mut enclosed) = (0, 0u64);
        let mut largest: Option<(usize, f64)> = None;
        for l in 0..cells.len() {
            let p = parent[l] as usize;
            if p != l {
                let r = root[p];
                root.push(r);
                continue;
            }
            root.push(l as u32);
            count += 1;
            let c = cells[l];
            if c & TOP == 0 {
                enclosed += c;
            }
            let area = (c & !TOP) as f64 * cell;
            if largest.is_none_or(|(_, a)| area > a) {
                largest = Some((l, area));
            }
        }
        // Inward deviation (runs of voids that reach the boundary) and the largest's sums.
        let mut dev_in = Deviation::default();
        let mut acc = Acc::default();
        let big = largest.map_or(u32::MAX, |(l, _)| l as u32);
        for &(k, s, e, l) in runs.iter() {
            let r = root[l as usize];
            if cells[r as usize] & TOP != 0 {
                probe(&g, index, &mut dev_in, k as usize, s, e);
            }
            if r == big {
                acc.add(k, s, e, false);
            }
        }
        acc.boundary = largest.is_some_and(|(l, _)| cells[l] & TOP != 0);
        Voids {
            count,
            enclosed,
            largest: largest.map(|_| acc.void(&g)),
            dev_in,
        }
    }

    /// A [`CoverageMask`] with square cells of about `cell` mm, in tiles over the raster's.
    pub fn mask(&self, cell: f64) -> CoverageMask {
        self.mask_with(cell, false, true)
    }

    /// [`mask`](Self::mask) with only the void and overfill shares, what the page draws: its
    /// tiles' `covered` are empty (a third less to count).
    pub fn page_mask(&self, cell: f64) -> CoverageMask {
        self.mask_with(cell, false, false)
    }

    /// [`mask`](Self::mask) counting each cell's bits range by range, as before the window
    /// counts (for tests comparing both).
    #[doc(hidden)]
    pub fn mask_reference(&self, cell: f64) -> CoverageMask {
        self.mask_with(cell, true, true)
    }

    /// Adds each mask cell's counts [void, overfill, covered] to `counts` (per tile of `out`,
    /// `groups` the tiles of each mask band), cell by cell in each grid row.
    fn count_by_windows(
        &self,
        rows: usize,
        reference: bool,
        out: &[MaskTile],
        groups: &[(usize, std::ops::Range<usize>)],
        counts: &mut [Vec<[u32; 3]>],
    ) {
        let g = self.grid;
        let tiles = &self.tiles;
        let cols = rows * COLS_PER_ROW as usize;
        let widest = tiles.bands().iter().map(|b| b.row_len).max().unwrap_or(0);
        let mut void = vec![0u64; widest];
        let mut over = vec![0u64; widest];
        let mut cov = vec![0u64; widest];
        let mut group = 0;
        for (bi, band) in tiles.bands().iter().enumerate() {
            for k in band.first_row..band.end_row {
                let row = tiles.row_in(bi, k);
                let (lo, hi) = self.extent[row.slot];
                if lo >= hi {
                    continue;
                }
                let (lo, hi) = (lo as usize, hi as usize);
                let my = k / rows;
                while groups[group].0 < my / MASK_BAND_ROWS {
                    group += 1;
                }
                let (r, d) = (&self.region_bits[row.range()], &self.drop_bits[row.range()]);
                if reference {
                    for w in lo..hi {
                        void[w] = r[w] & !d[w];
                        over[w] = d[w] & !r[w];
                        cov[w] = d[w] & r[w];
                    }
                }
                let mut t = groups[group].1.start;
                for seg in row.segs {
                    let (a, e) = (seg.at.max(lo), seg.end().min(hi));
                    if a >= e {
                        continue;
                    }
                    // Grid columns [gc0, gc1] of the segment's bits; column c at c − shift.
                    let shift = 64 * seg.shift();
                    let (gc0, gc1) = (64 * a + shift, (64 * e + shift).min(g.nx) - 1);
                    for cx in gc0 / cols..=gc1 / cols {
                        let (c0, c1) = ((cx * cols).max(gc0), ((cx + 1) * cols - 1).min(gc1));
                        while out[t].col + out[t].width <= cx {
                            t += 1;
                        }
                        let tile = &out[t];
                        let slot = &mut counts[t][(my - tile.row) * tile.width + cx - tile.col];
                        let (c0, c1) = (c0 - shift, c1 - shift);
                        if !reference && c1 - c0 < 64 {
                            // The cell's bits of both rows in one word each.
                            let (rw, dw) = (window(r, c0, c1), window(d, c0, c1));
                            slot[0] += (rw & !dw).count_ones();
                            slot[1] += (dw & !rw).count_ones();
                            slot[2] += (rw & dw).count_ones();
                        } else {
                            if !reference {
                                for w in c0 >> 6..=c1 >> 6 {
                                    void[w] = r[w] & !d[w];
                                    over[w] = d[w] & !r[w];
                                    cov[w] = d[w] & r[w];
                                }
                            }
                            slot[0] += count_range(&void, c0, c1);
                            slot[1] += count_range(&over, c0, c1);
                            slot[2] += count_range(&cov, c0, c1);
                        }
                    }
                }
            }
        }
    }

    /// [`count_by_windows`](Self::count_by_windows) for cells of at most [`NIBBLE_ROWS`] rows
    /// (the page's cells of B/4): a cell is `rows` × 4·`rows` columns, so its columns are
    /// whole 4-bit groups of the words, and a cell's bits in one row count at most 4 per
    /// group. Each grid row adds the bit counts of its 4-bit groups (SWAR, a word at a time)
    /// into the mask row's words, at most 4·`rows` ≤ 15 per group; when the mask row is
    /// done, each cell sums its `rows` groups. Counts identical, per cell once a mask row.
    ///
    /// `N` = 3 counts void, overfill and covered; `N` = 2 only void and overfill (the page's
    /// mask, [`page_mask`](Self::page_mask)).
    fn count_by_nibbles<const N: usize>(
        &self,
        rows: usize,
        out: &mut [MaskTile],
        groups: &[(usize, std::ops::Range<usize>)],
        table: &[u8],
    ) {
        debug_assert!((1..=NIBBLE_ROWS).contains(&rows));
        let tiles = &self.tiles;
        // Grid words [first, end) under tile t's cells: its 4-bit groups are
        // [col·rows, (col + width)·rows).
        let words = |t: &MaskTile| (t.col * rows / 16, ((t.col + t.width) * rows).div_ceil(16));
        // Per grid word under the current mask band's tiles (tile by tile, `at[t]` where tile
        // t's words start), the 4-bit counts of void, overfill, covered: memory for the
        // tiles, not for the grid's width.
        let mut acc: Vec<[u64; N]> = Vec::new();
        let mut at: Vec<usize> = Vec::new();
        // The current band's tiles' words [first, end).
        let mut spans: Vec<(usize, usize)> = Vec::new();
        let nibbles = |x: u64| {
            let x = x - ((x >> 1) & 0x5555_5555_5555_5555);
            (x & 0x3333_3333_3333_3333) + ((x >> 2) & 0x3333_3333_3333_3333)
        };
        // The cells of mask row `my` (tiles `range`, their words `spans`) from `acc`, their
        // shares (`table`: per count) into the tiles, then `acc` cleared: each tile's 4-bit
        // groups read in order along its words, `rows` of them per cell.
        let flush = |my: usize,
                     range: std::ops::Range<usize>,
                     acc: &mut [[u64; N]],
                     at: &[usize],
                     spans: &[(usize, usize)],
                     out: &mut [MaskTile]| {
            for ((t, &base_at), &(w0, w1)) in range.zip(at).zip(spans) {
                let tile = &mut out[t];
                let mine = &acc[base_at..base_at + (w1 - w0)];
                let base = (my - tile.row) * tile.width;
                // The tile's first group is (col·rows) mod 16 of its first word.
                let (mut w, mut sh) = (0, 4 * ((tile.col * rows) & 15));
                let mut a = mine.first().copied().unwrap_or([0; N]);
                for i in base..base + tile.width {
                    let mut sum = [0usize; N];
                    for _ in 0..rows {
                        for c in 0..N {
                            sum[c] += ((a[c] >> sh) & 15) as usize;
                        }
                        sh += 4;
                        if sh == 64 {
                            sh = 0;
                            w += 1;
                            a = mine.get(w).copied().unwrap_or([0; N]);
                        }
                    }
                    tile.void[i] = table[sum[0]];
                    tile.overfill[i] = table[sum[1]];
                    if N == 3 {
                        tile.covered[i] = table[sum[N - 1]];
                    }
                }
            }
            acc.fill([0; N]);
        };
        // The mask row being summed and its band's tiles.
        let mut current: Option<(usize, std::ops::Range<usize>)> = None;
        // The tiles `acc` is laid out for.
        let mut laid: Option<std::ops::Range<usize>> = None;
        let mut group = 0;
        for (bi, band) in tiles.bands().iter().enumerate() {
            for k in band.first_row..band.end_row {
                let row = tiles.row_in(bi, k);
                let (lo, hi) = self.extent[row.slot];
                if lo >= hi {
                    continue;
                }
                let my = k / rows;
                if current.as_ref().is_none_or(|c| c.0 != my) {
                    if let Some((c, range)) = current.take() {
                        flush(c, range, &mut acc, &at, &spans, out);
                    }
                    while groups[group].0 < my / MASK_BAND_ROWS {
                        group += 1;
                    }
                    let range = groups[group].1.clone();
                    if laid.as_ref() != Some(&range) {
                        at.clear();
                        spans.clear();
                        let mut n = 0;
                        for t in &out[range.clone()] {
                            at.push(n);
                            let (w0, w1) = words(t);
                            spans.push((w0, w1));
                            n += w1 - w0;
                        }
                        acc.clear();
                        acc.resize(n, [0; N]);
                        laid = Some(range.clone());
                    }
                    current = Some((my, range));
                }
                let range = current.as_ref().map_or(0..0, |c| c.1.clone());
                let (r, d) = (&self.region_bits[row.range()], &self.drop_bits[row.range()]);
                // The tiles' word ranges are in order along the row, as the words are.
                let mut t = range.start;
                for seg in row.segs {
                    let (a, e) = (seg.at.max(lo as usize), seg.end().min(hi as usize));
                    let shift = seg.shift();
                    for w in a..e {
                        let (rw, dw) = (r[w], d[w]);
                        if rw | dw == 0 {
                            continue;
                        }
                        let gw = w + shift;
                        while t < range.end && spans[t - range.start].1 <= gw {
                            t += 1;
                        }
                        let add: [u64; N] = std::array::from_fn(|c| match c {
                            0 => nibbles(rw & !dw),
                            1 => nibbles(dw & !rw),
                            _ => nibbles(rw & dw),
                        });
                        // Every tile whose words hold word gw (two when they are closer
                        // than a word); a set bit always lies under a tile.
                        let mut u = t;
                        while u < range.end && spans[u - range.start].0 <= gw {
                            let i = u - range.start;
                            let x = &mut acc[at[i] + gw - spans[i].0];
                            for (x, a) in x.iter_mut().zip(add) {
                                *x += a;
                            }
                            u += 1;
                        }
                        debug_assert!(u > t, "mask bits outside the mask's tiles");
                    }
                }
            }
        }
        if let Some((c, range)) = current {
            flush(c, range, &mut acc, &at, &spans, out);
        }
    }

    fn mask_with(&self, cell: f64, reference: bool, covered: bool) -> CoverageMask {
        let g = self.grid;
        let tiles = &self.tiles;
        let rows = ((cell / g.gy).round() as usize).max(1);
        let cols = rows * COLS_PER_ROW as usize;
        let height = g.ny.div_ceil(rows);
        // In each band of MASK_BAND_ROWS mask rows, the mask columns over the raster's segments
        // in those rows, merged: (mask band, first column, last column).
        let mut spans = Vec::new();
        for band in tiles.bands() {
            let mb0 = band.first_row / rows / MASK_BAND_ROWS;
            let mb1 = (band.end_row - 1) / rows / MASK_BAND_ROWS;
            for seg in tiles.segments(band) {
                let (c0, c1) = (64 * seg.c0 / cols, ((64 * seg.c1).min(g.nx) - 1) / cols);
                spans.extend((mb0..=mb1).map(|mb| (mb, c0, c1)));
            }
        }
        spans.sort_unstable();
        // The tiles, and per mask band the range of its tiles.
        let mut out: Vec<MaskTile> = Vec::new();
        let mut groups: Vec<(usize, std::ops::Range<usize>)> = Vec::new();
        let mut i = 0;
        while i < spans.len() {
            let mb = spans[i].0;
            let first = out.len();
            while i < spans.len() && spans[i].0 == mb {
                let (_, c0, mut c1) = spans[i];
                i += 1;
                while i < spans.len() && spans[i].0 == mb && spans[i].1 <= c1 + 1 {
                    c1 = c1.max(spans[i].2);
                    i += 1;
                }
                let row = mb * MASK_BAND_ROWS;
                out.push(MaskTile {
                    col: c0,
                    row,
                    width: c1 - c0 + 1,
                    height: MASK_BAND_ROWS.min(height - row),
                    ..MaskTile::default()
                });
            }
            groups.push((mb, first..out.len()));
        }
        let full = (rows * cols) as f64;
        let share_of = |n: u32| ((n as f64 / full) * 255.0).round().min(255.0) as u8;
        // The shares of every count a cell can hold, when there are not too many.
        let table: Vec<u8> = if reference || rows * cols > 1 << 16 {
            Vec::new()
        } else {
            (0..=(rows * cols) as u32).map(share_of).collect()
        };
        if !reference && rows <= NIBBLE_ROWS {
            // The shares written as each mask row is summed (every cell is, once).
            for t in &mut out {
                let n = t.width * t.height;
                t.void = vec![0; n];
                t.overfill = vec![0; n];
                if covered {
                    t.covered = vec![0; n];
                }
            }
            if covered {
                self.count_by_nibbles::<3>(rows, &mut out, &groups, &table);
            } else {
                self.count_by_nibbles::<2>(rows, &mut out, &groups, &table);
            }
        } else {
            let mut counts: Vec<Vec<[u32; 3]>> = out
                .iter()
                .map(|t| vec![[0; 3]; t.width * t.height])
                .collect();
            self.count_by_windows(rows, reference, &out, &groups, &mut counts);
            let share = |n: u32| match table.get(n as usize) {
                Some(&v) => v,
                None => share_of(n),
            };
            for (tile, counts) in out.iter_mut().zip(&counts) {
                tile.void = counts.iter().map(|c| share(c[0])).collect();
                tile.overfill = counts.iter().map(|c| share(c[1])).collect();
                if covered {
                    tile.covered = counts.iter().map(|c| share(c[2])).collect();
                }
            }
        }
        CoverageMask {
            origin: DVec2::new(g.x0, g.y0),
            cell: rows as f64 * g.gy,
            tiles: out,
        }
    }
}

/// A void's sums while labelling.
#[derive(Clone, Copy)]
struct Acc {
    cells: u64,
    /// Sums of column·cells (twice, to stay whole) and row·cells.
    sx2: u64,
    sy: u64,
    min: [u32; 2],
    max: [u32; 2],
    boundary: bool,
}

impl Default for Acc {
    fn default() -> Acc {
        Acc {
            cells: 0,
            sx2: 0,
            sy: 0,
            min: [u32::MAX; 2],
            max: [0; 2],
            boundary: false,
        }
    }
}

impl Acc {
    /// Adds the run [s, e) of row k.
    #[inline]
    fn add(&mut self, k: u32, s: u32, e: u32, boundary: bool) {
        let n = (e - s) as u64;
        self.cells += n;
        self.sx2 += n * (s + e - 1) as u64;
        self.sy += n * k as u64;
        self.min = [self.min[0].min(s), self.min[1].min(k)];
        self.max = [self.max[0].max(e), self.max[1].max(k + 1)];
        self.boundary |= boundary;
    }

    /// The void these sums describe.
    fn void(&self, g: &Grid) -> Void {
        let n = self.cells as f64;
        Void {
            area: self.cells as f64 * (g.gx * g.gy),
            centroid: DVec2::new(
                g.x0 + (self.sx2 as f64 / (2.0 * n) + 0.5) * g.gx,
                g.y0 + (self.sy as f64 / n + 0.5) * g.gy,
            ),
            min: DVec2::new(
                g.x0 + self.min[0] as f64 * g.gx,
                g.y0 + self.min[1] as f64 * g.gy,
            ),
            max: DVec2::new(
                g.x0 + self.max[0] as f64 * g.gx,
                g.y0 + self.max[1] as f64 * g.gy,
            ),
            at_boundary: self.boundary,
        }
    }
}

/// A layer's voids: how many, the cells of those that do not reach the boundary, the largest
/// (the first of equal ones in the order of their first runs) and the inward deviation.
struct Voids {
    count: usize,
    enclosed: u64,
    largest: Option<Void>,
    dev_in: Deviation,
}

impl Voids {
    fn of<'a>(g: &Grid, accs: impl Iterator<Item = &'a Acc>, dev_in: Deviation) -> Voids {
        let cell = g.gx * g.gy;
        let (mut count, mut enclosed) = (0, 0u64);
        let mut largest: Option<Void> = None;
        for a in accs {
            count += 1;
            if !a.boundary {
                enclosed += a.cells;
            }
            let area = a.cells as f64 * cell;
            if largest.is_none_or(|l| area > l.area) {
                largest = Some(a.void(g));
            }
        }
        Voids {
            count,
            enclosed,
            largest,
            dev_in,
        }
    }
}

/// Probes the run [s, e) of row k (its ends and middle) for a larger distance to the
/// boundary than `best`'s.
fn probe(g: &Grid, index: &EdgeIndex, best: &mut Deviation, k: usize, s: u32, e: u32) {
    let y = g.ry(k);
    for c in [s, (s + e - 1) / 2, e - 1] {
        let p = DVec2::new(g.cx(c as usize), y);
        // The distance to the boundary changes no faster than the point moves: a point
        // this close to the last one probed cannot beat the maximum.
        if best.last_d + dist(p, best.last) <= best.max {
            continue;
        }
        let d = index.distance(p, best.max);
        (best.last, best.last_d) = (p, d);
        if d > best.max {
            (best.max, best.at) = (d, Some(p));
        }
    }
}

/// The largest distance to the boundary found so far, where, and the last point probed with
/// an upper bound of its distance.
struct Deviation {
    max: f64,
    at: Option<Point>,
    last: Point,
    last_d: f64,
}

impl Default for Deviation {
    fn default() -> Deviation {
        Deviation {
            max: 0.0,
            at: None,
            last: DVec2::ZERO,
            last_d: f64::INFINITY,
        }
    }
}

struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] as usize != i {
            let p = self.parent[i] as usize;
            self.parent[i] = self.parent[p];
            i = p;
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo as u32;
        }
    }
}
