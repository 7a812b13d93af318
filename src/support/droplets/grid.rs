//! Hash grids of a layer's droplets for the droplet-level pass: "is there a droplet of the
//! layer below within reach" ([`Grid`], [`Below`]) and the few droplets added to a layer
//! ([`Added`]).

use super::Droplet;
use crate::base::geom::{DVec2, Point};
use std::collections::HashMap;

/// Droplets of a layer in cells over their bounding box (counts, then the droplets sorted by
/// cell), cells at least the rule's distance.
struct Grid {
    /// 1 / the cell's side: a cell's index by a product, not a division (both per droplet).
    inv: f64,
    min: Point,
    nx: i64,
    ny: i64,
    offsets: Vec<u32>,
    items: Vec<Droplet>,
    /// Each droplet's cell while the grid is filled (kept for the next fill).
    keys: Vec<u32>,
}

impl Grid {
    fn new(cell: f64, droplets: &[Droplet]) -> Grid {
        let mut g = Grid {
            inv: 1.0 / cell,
            min: DVec2::ZERO,
            nx: 0,
            ny: 0,
            offsets: Vec::new(),
            items: Vec::new(),
            keys: Vec::new(),
        };
        g.fill(cell, droplets);
        g
    }

    /// The grid of `droplets` in place of this one's (its buffers reused).
    fn fill(&mut self, cell: f64, droplets: &[Droplet]) {
        self.fill_where(cell, droplets, |_| true);
    }

    /// The grid of the droplets `keep` accepts in place of this one's.
    fn fill_where(&mut self, cell: f64, droplets: &[Droplet], keep: impl Fn(&Droplet) -> bool) {
        let mut min = DVec2::INFINITY;
        let mut max = DVec2::NEG_INFINITY;
        let mut count = 0usize;
        for d in droplets.iter().filter(|d| keep(d)) {
            min = min.min(d.0);
            max = max.max(d.0);
            count += 1;
        }
        if count == 0 {
            (min, max) = (DVec2::ZERO, DVec2::ZERO);
        }
        // About one cell per droplet at most, however large the layer: memory stays
        // proportional to the droplets (larger cells still hold every droplet within reach).
        let spread = ((max.x - min.x) * (max.y - min.y) / count.max(1) as f64).sqrt();
        // Cells a hair wider than asked: two points at most `cell` apart then lie in the same
        // or neighbouring cells whatever the rounding of the differences and products that
        // place them, so the search of the 3 × 3 cells around a point misses none.
        self.inv = 1.0 / (cell.max(spread) * (1.0 + 1e-9));
        self.min = min;
        // The cell of the greatest coordinates as `key` places it.
        let (x, y) = self.key(max);
        (self.nx, self.ny) = (x + 1, y + 1);
        let nx = self.nx;
        self.offsets.clear();
        self.offsets.resize((nx * self.ny) as usize + 1, 0);
        self.items.clear();
        self.items.resize(count, (DVec2::ZERO, 0.0));
        let mut keys = std::mem::take(&mut self.keys);
        keys.clear();
        keys.extend(droplets.iter().filter(|d| keep(d)).map(|(p, _)| {
            let (x, y) = self.key(*p);
            (y * nx + x) as u32
        }));
        for &k in &keys {
            self.offsets[k as usize + 1] += 1;
        }
        for i in 1..self.offsets.len() {
            self.offsets[i] += self.offsets[i - 1];
        }
        // Each cell's droplets in their order, filled from the cell's start (moved along as
        // they are placed, then moved back).
        for (d, &k) in droplets.iter().filter(|d| keep(d)).zip(&keys) {
            let slot = &mut self.offsets[k as usize];
            self.items[*slot as usize] = *d;
            *slot += 1;
        }
        for i in (1..self.offsets.len()).rev() {
            self.offsets[i] = self.offsets[i - 1];
        }
        self.offsets[0] = 0;
        self.keys = keys;
    }

    fn key(&self, p: Point) -> (i64, i64) {
        (
            floor((p.x - self.min.x) * self.inv),
            floor((p.y - self.min.y) * self.inv),
        )
    }

    /// A droplet d within `reach(d's width)` of `p` (reach ≤ the cell), if any.
    /// The cells are searched from p's own outwards (the question is whether there is one).
    fn find_within(&self, p: Point, reach: impl Fn(f64) -> f64) -> Option<Droplet> {
        let (cx, cy) = self.key(p);
        let search = |x: i64, y: i64| {
            let c = (y * self.nx + x) as usize;
            let cell = &self.items[self.offsets[c] as usize..self.offsets[c + 1] as usize];
            cell.iter()
                .find(|&&(q, w)| {
                    let r = reach(w);
                    (p - q).length_squared() <= r * r
                })
                .copied()
        };
        // p's own cell lies in the grid (the grid covers every droplet, p may lie outside).
        let own = (0..self.nx).contains(&cx) && (0..self.ny).contains(&cy);
        if own && let Some(d) = search(cx, cy) {
            return Some(d);
        }
        for y in (cy - 1).max(0)..=(cy + 1).min(self.ny - 1) {
            for x in (cx - 1).max(0)..=(cx + 1).min(self.nx - 1) {
                if own && x == cx && y == cy {
                    continue;
                }
                if let Some(d) = search(x, y) {
                    return Some(d);
                }
            }
        }
        None
    }
}

/// A layer's droplets for "is there one within reach": one [`Grid`] when B and B₁ differ by at
/// most twice, else one grid per width, each in cells of its own reach (in one grid with cells
/// of the wider droplets' reach, each cell would hold (B₁/B)² of the narrow ones, all scanned by
/// every query). The answer is the same either way.
pub(super) struct Below {
    grids: Vec<Grid>,
    narrow: f64,
    wide: f64,
}

impl Below {
    pub(super) fn new(b: f64, b1: f64, reach: impl Fn(f64) -> f64, droplets: &[Droplet]) -> Below {
        let (narrow, wide) = (b.min(b1), b.max(b1));
        let split = wide > 2.0 * narrow;
        let grids = if split {
            vec![Grid::new(reach(narrow), &[]), Grid::new(reach(wide), &[])]
        } else {
            vec![Grid::new(reach(wide), &[])]
        };
        let mut below = Below {
            grids,
            narrow,
            wide,
        };
        below.fill(&reach, droplets);
        below
    }

    /// The index of `droplets` in place of this one's (its buffers reused).
    pub(super) fn fill(&mut self, reach: impl Fn(f64) -> f64, droplets: &[Droplet]) {
        if self.grids.len() == 1 {
            self.grids[0].fill(reach(self.wide), droplets);
            return;
        }
        // Each grid's cells are at least the reach of every droplet in it.
        let narrow = self.narrow;
        let wide = droplets
            .iter()
            .filter(|d| d.1 > narrow)
            .fold(reach(self.wide), |c, d| c.max(reach(d.1)));
        self.grids[0].fill_where(reach(narrow), droplets, |d| d.1 <= narrow);
        self.grids[1].fill_where(wide, droplets, |d| d.1 > narrow);
    }

    /// A droplet d within `reach(d's width)` of `p`, if any.
    pub(super) fn find_within(&self, p: Point, reach: impl Fn(f64) -> f64) -> Option<Droplet> {
        self.grids.iter().find_map(|g| g.find_within(p, &reach))
    }
}

/// ⌊x⌋ for |x| < 2⁵¹ (a grid's cells; this runs per droplet): without a call into the maths
/// library, nor the range checks of a float-to-integer cast. Adding 1.5·2⁵² rounds x to the
/// nearest integer, which the sum's low bits then hold.
pub(super) fn floor(x: f64) -> i64 {
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let y = x + SHIFT;
    let t = (y.to_bits() as i64).wrapping_sub(SHIFT.to_bits() as i64);
    // Without a branch: which way it goes is as often one as the other.
    t - (y - SHIFT > x) as i64
}

/// Droplets added to a layer, in a hash grid (few).
pub(super) struct Added {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<Point>>,
}

impl Added {
    /// None yet, in cells of `cell` (the largest distance [`Added::any_within`] is asked).
    pub(super) fn new(cell: f64) -> Added {
        Added {
            cell,
            cells: HashMap::new(),
        }
    }

    fn key(&self, p: Point) -> (i64, i64) {
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    pub(super) fn add(&mut self, p: Point) {
        let k = self.key(p);
        self.cells.entry(k).or_default().push(p);
    }

    /// Whether an added droplet lies within `r` (≤ the cell) of `p`.
    pub(super) fn any_within(&self, p: Point, r: f64) -> bool {
        let (cx, cy) = self.key(p);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                self.cells
                    .get(&(cx + dx, cy + dy))
                    .is_some_and(|v| v.iter().any(|&q| (p - q).length_squared() <= r * r))
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_is_the_floor() {
        // its range: |x| < 2⁵¹
        for x in crate::base::testing::floor_cases()
            .into_iter()
            .filter(|x| x.abs() < 2_251_799_813_685_248.0)
        {
            assert_eq!(floor(x), x.floor() as i64, "{x:e}");
        }
    }

    #[test]
    fn the_grid_finds_a_droplet_within_reach_as_a_scan_of_every_droplet_does() {
        // Droplets of two widths in clusters and a sparse spread, queries inside and outside
        // the grid and right at the reach: the grid answers "is there one" as a full scan.
        let mut random = crate::base::testing::rng(0x2545_f491_4f6c_dd1du64);
        let (b, b1, limit) = (0.208, 0.15, 0.104);
        let reach = |w: f64| w / 2.0 + limit;
        let (mut found, mut missed) = (0, 0);
        for case in 0..30 {
            let spread = if case % 2 == 0 { 3.0 } else { 40.0 };
            let droplets: Vec<Droplet> = (0..(case * 37 % 400))
                .map(|k| {
                    let w = if k % 3 == 0 { b1 } else { b };
                    (DVec2::new(random() * spread, random() * spread / 2.0), w)
                })
                .collect();
            let grid = Grid::new(reach(b), &droplets);
            for k in 0..300 {
                let p = if k % 4 == 0 && !droplets.is_empty() {
                    // At the reach of a droplet, in a random direction.
                    let (q, w) = droplets[k % droplets.len()];
                    let a = random() * std::f64::consts::TAU;
                    q + reach(w) * DVec2::new(a.cos(), a.sin())
                } else {
                    DVec2::new(
                        random() * 1.2 * spread - 0.1 * spread,
                        random() * spread - 1.0,
                    )
                };
                let scan = droplets.iter().any(|&(q, w)| {
                    let r = reach(w);
                    (p - q).length_squared() <= r * r
                });
                let got = grid.find_within(p, reach);
                assert_eq!(got.is_some(), scan, "case {case} query {k} at {p}");
                if let Some((q, w)) = got {
                    assert!((p - q).length_squared() <= reach(w) * reach(w));
                    found += 1;
                } else {
                    missed += 1;
                }
            }
        }
        assert!(found > 1000 && missed > 1000, "{found} {missed}");
    }
}
