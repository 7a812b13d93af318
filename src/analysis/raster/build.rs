//! The rasterisation: a layer's region and droplets as bitmaps on the grid, in the tiles they
//! touch.

use super::{COLS_PER_ROW, Grid, ROWS_PER_B, Raster, region_spans, set_range};
use crate::analysis::droplet::{droplet_centres, footprint_diameter};
use crate::base::geom::{Point, Shapes, all_contours, region_area};
use crate::base::settings::Settings;
use crate::base::spatial::{Spot, Tiles};
use crate::slicing::plan::LayerPlan;

/// Steps of the table of band-averaged half-widths (a droplet's offset within its first row).
const PHASES: usize = 256;
/// Rows of the 2D grid per band of the sparse raster, and words (of 64 columns) per tile: tiles
/// of 64 × 256 cells, 1.33 mm square with the default B.
pub(super) const BAND_ROWS: usize = 64;
pub(super) const TILE_WORDS: usize = 4;

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
            banding: None,
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
        let prep = self.prepare(centres, region, s);
        let grid = prep.grid;
        // First the tiles the region and the droplets touch, then their bits.
        let tiles = &mut self.tiles;
        for &(k, c0, c1) in self.spans.iter() {
            let k = k as usize;
            tiles.mark(k, k, c0 as usize >> 6, c1 as usize >> 6);
        }
        for &place in self.places.iter() {
            let d = prep.droplet(place);
            if d.n >= 1 {
                // A column to spare on each side.
                let w0 = (d.c0 - 1).max(0) as usize >> 6;
                let w1 = (d.c1 + 1).max(0) as usize >> 6;
                tiles.mark(d.k0, d.k1, w0, w1);
            }
        }
        self.allocate();
        let (region_bits, drop_bits) = (&mut self.region_bits, &mut self.drop_bits);
        let mut store = Store::new(&self.tiles, &mut self.extent);
        for &(k, c0, c1) in self.spans.iter() {
            let (k, c0, c1) = (k as usize, c0 as usize, c1 as usize);
            store.set_cols(region_bits, k, c0, c1);
        }
        for &place in self.places.iter() {
            let d = prep.droplet(place);
            if d.in_grid(&grid) && d.set_in_one_segment(&mut store, drop_bits) {
                continue;
            }
            for (k, c0, c1) in d.rows_in(&grid) {
                store.set_cols(drop_bits, k, c0, c1);
            }
        }
        self.finish(index, z, centres.len(), region, s, grid);
    }

    /// The first half of a rebuild: the grid over the region and the droplets, the region's
    /// edges, its spans (row, first column, last column) in `spans` and each droplet's place
    /// in `places`, and the tables of columns a droplet covers per row; the tiles reset.
    pub(super) fn prepare(&mut self, centres: &[Point], region: &Shapes, s: &Settings) -> Prep {
        let mut bounds = None;
        for &p in centres {
            let (lo, hi) = bounds.get_or_insert((p, p));
            (*lo, *hi) = (lo.min(p), hi.max(p));
        }
        let prep = self.prepare_grid(bounds, region, s);
        let places = &mut self.places;
        places.clear();
        places.extend(centres.iter().map(|&p| prep.place(p)));
        prep
    }

    /// [`prepare`](Self::prepare) but the droplets' places: the grid over the region and the
    /// droplets' centres within `bounds` (least, greatest corner).
    pub(super) fn prepare_grid(
        &mut self,
        bounds: Option<(Point, Point)>,
        region: &Shapes,
        s: &Settings,
    ) -> Prep {
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
        for p in bounds.into_iter().flat_map(|(lo, hi)| [lo, hi]) {
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
        self.tiles.reset(ny, nw, BAND_ROWS, TILE_WORDS);
        let spans = &mut self.spans;
        spans.clear();
        region_spans(region, y0, gy, ny, |k, xa, xb| {
            if let Some((c0, c1)) = grid.cols(xa, xb) {
                spans.push((k as u32, c0 as u32, c1 as u32));
            }
        });
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
        self.places.clear();
        self.banding = None;
        Prep {
            grid,
            rows,
            spans,
            widest,
            r,
        }
    }

    /// Lays out the marked tiles and clears the bitmaps and extents over them.
    pub(super) fn allocate(&mut self) {
        let len = self.tiles.build();
        self.region_bits.clear();
        self.region_bits.resize(len, 0);
        self.drop_bits.clear();
        self.drop_bits.resize(len, 0);
        self.extent.clear();
        self.extent.resize(self.tiles.row_slots(), (u32::MAX, 0));
    }

    /// The last of a rebuild: the layer's own figures.
    pub(super) fn finish(
        &mut self,
        index: usize,
        z: f64,
        droplets: usize,
        region: &Shapes,
        s: &Settings,
        grid: Grid,
    ) {
        self.index = index;
        self.z = z;
        self.droplets = droplets as u64;
        self.region_area = region_area(region);
        self.b = s.droplet_width();
        self.grid = grid;
    }

    /// The most bytes the bitmaps of a raster take over a `w` × `h` mm box that holds a layer's
    /// region and droplets (settings `s`): every tile over the box and the grid's margin
    /// stored, and a tile more on each side (a box seldom starts at a tile's edge); two words
    /// of 64 columns per stored word place, and a row's extent. For
    /// [`crate::analysis::AnalysisGrid::layer_bytes`], before anything is allocated.
    pub fn box_bytes(w: f64, h: f64, s: &Settings) -> f64 {
        let b = s.droplet_width();
        let r = footprint_diameter(s) / 2.0;
        let gy = b / ROWS_PER_B;
        let gx = gy / COLS_PER_ROW;
        // The droplets' reach and the grid's margin on both sides.
        let reach = 2.0 * (r + 3.0 * gy);
        let band = BAND_ROWS as f64;
        let rows = (((h + reach) / gy + 2.0) / band).ceil() * band + band;
        let tile = TILE_WORDS as f64;
        let words = (((w + reach) / gx / 64.0 + 2.0) / tile).ceil() * tile + tile;
        rows * (16.0 * words + 8.0)
    }

    /// Words of memory its bitmaps take (for tests of the memory it needs).
    pub fn stored_words(&self) -> usize {
        self.region_bits.len() + self.drop_bits.len()
    }
}

/// What [`Raster::prepare`] gives: the grid, the rows a droplet spans, per phase and row the
/// columns it covers (n, (n − 1)/2), and per phase its widest row's.
pub(super) struct Prep {
    pub(super) grid: Grid,
    pub(super) rows: usize,
    pub(super) spans: Vec<(i64, f64)>,
    pub(super) widest: Vec<(i64, f64)>,
    /// The footprint's radius.
    pub(super) r: f64,
}

impl Prep {
    /// A droplet's first row, phase, and centre in column units (column c's centre at u = c).
    #[inline]
    pub(super) fn place(&self, p: Point) -> (usize, usize, f64) {
        let g = &self.grid;
        let v = (p[1] - self.r - g.y0) / g.gy;
        let k0 = v.floor();
        let ph = (((v - k0) * PHASES as f64) as usize).min(PHASES - 1);
        (k0 as usize, ph, (p[0] - g.x0) / g.gx - 0.5)
    }
}

/// A droplet on the grid ([`Prep::droplet`]): its rows k0..=k1, its phase, its centre `u` in
/// column units, per row from k0 the columns it covers (n, (n − 1)/2), and its widest row's
/// n columns c0..=c1 (c1 = c0 + n − 1): every row's columns lie within them.
pub(super) struct Droplet<'a> {
    pub(super) k0: usize,
    pub(super) k1: usize,
    pub(super) ph: usize,
    u: f64,
    rows: &'a [(i64, f64)],
    pub(super) n: i64,
    pub(super) c0: i64,
    pub(super) c1: i64,
}

impl Prep {
    /// The droplet at `place` ([`Prep::place`]).
    #[inline]
    pub(super) fn droplet(&self, (k0, ph, u): (usize, usize, f64)) -> Droplet<'_> {
        let (n, half) = self.widest[ph];
        let c0 = (u - half + 0.5) as i64;
        Droplet {
            k0,
            k1: k0 + self.rows - 1,
            ph,
            u,
            rows: &self.spans[ph * self.rows..(ph + 1) * self.rows],
            n,
            c0,
            c1: c0 + n - 1,
        }
    }
}

impl Droplet<'_> {
    /// Whether it covers any cell and lies wholly in `grid`.
    #[inline]
    pub(super) fn in_grid(&self, grid: &Grid) -> bool {
        self.n >= 1 && self.c0 >= 0 && self.c1 < grid.nx as i64 && self.k1 < grid.ny
    }

    /// Sets its rows' columns in `bits` and widens the rows' extents, when it lies in one
    /// band and segment of the storage: its rows are then one step apart. Whether it did;
    /// mostly it does. Only for a droplet [`in_grid`](Self::in_grid).
    #[inline(always)]
    pub(super) fn set_in_one_segment(&self, store: &mut Store, bits: &mut [u64]) -> bool {
        let (c0, c1) = (self.c0 as usize, self.c1 as usize);
        let Some(sp) = store
            .tiles
            .spot_cached(&mut store.spot, self.k0, c0 >> 6, c1 >> 6)
            .filter(|sp| self.k1 < sp.end_row)
        else {
            return false;
        };
        let shift = 64 * sp.shift;
        // Bit positions in u64: past 2³² bits (512 MB of words) in a 32-bit build.
        let mut at = 64 * sp.index(self.k0) as u64;
        for (slot, &(n, half)) in (sp.slot(self.k0)..).zip(self.rows) {
            if n >= 1 {
                // Within the widest row's columns: ≥ c0 ≥ 0, so the value is above −1 and
                // `as i64` truncates it as `as usize` would (one instruction on baseline
                // x86-64; `as usize` takes a dozen).
                let c0 = (self.u - half + 0.5) as i64 as usize - shift;
                let c1 = c0 + n as usize - 1;
                set_range(bits, at + c0 as u64, at + c1 as u64);
                widen(&mut store.extent[slot], c0, c1);
            }
            at += 64 * sp.row_len as u64;
        }
        true
    }

    /// Its rows that cover any cell and lie wholly in `grid`: (row, first column, last
    /// column).
    #[inline]
    pub(super) fn rows_in(&self, grid: &Grid) -> impl Iterator<Item = (usize, usize, usize)> {
        let (nx, ny, u) = (grid.nx as i64, grid.ny, self.u);
        (self.k0..)
            .zip(self.rows)
            .filter_map(move |(k, &(n, half))| {
                let c0 = (u - half + 0.5) as i64;
                let c1 = c0 + n - 1;
                (n >= 1 && k < ny && c0 >= 0 && c1 < nx).then_some((k, c0 as usize, c1 as usize))
            })
    }
}

/// Widens a row's extent (the words of its slice holding any bit) to columns c0..=c1.
#[inline]
pub(super) fn widen(e: &mut (u32, u32), c0: usize, c1: usize) {
    e.0 = e.0.min((c0 >> 6) as u32);
    e.1 = e.1.max((c1 >> 6) as u32 + 1);
}

/// Where a rebuild sets its bits: the tiles' layout, each stored row's extent, and where the
/// last row set was stored (mostly where the next one is).
pub(super) struct Store<'a> {
    pub(super) tiles: &'a Tiles,
    pub(super) extent: &'a mut [(u32, u32)],
    pub(super) spot: Option<Spot>,
}

impl<'a> Store<'a> {
    pub(super) fn new(tiles: &'a Tiles, extent: &'a mut [(u32, u32)]) -> Store<'a> {
        Store {
            tiles,
            extent,
            spot: None,
        }
    }

    /// Sets grid columns c0..=c1 of row `k` in `bits` (laid out by the tiles; the columns
    /// stored in one segment) and widens the row's extent.
    #[inline]
    pub(super) fn set_cols(&mut self, bits: &mut [u64], k: usize, c0: usize, c1: usize) {
        let Some(sp) = self.tiles.spot_cached(&mut self.spot, k, c0 >> 6, c1 >> 6) else {
            debug_assert!(false, "bits outside the tiles");
            return;
        };
        let (c0, c1) = (c0 - 64 * sp.shift, c1 - 64 * sp.shift);
        let at = 64 * sp.index(k) as u64;
        set_range(bits, at + c0 as u64, at + c1 as u64);
        widen(&mut self.extent[sp.slot(k)], c0, c1);
    }
}
