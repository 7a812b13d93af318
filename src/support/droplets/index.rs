//! A layer's droplets indexed for the droplet-level pass' question "is there one within
//! reach". Most of a layer's droplets lie on hatch lines: the part's fill and the support (of the unit `support` names)
//! are lines (j + phase)·spacing across the layer's hatch direction, their droplets a pitch
//! apart along them ([`crate::slicing::hatch`], [`crate::support::lattice`]). Such a line is a
//! run of one row of its [`Frame`]: a question looks at the rows within reach, finds the runs
//! there by their extent along the row and computes their droplets within reach as the line
//! sets them ([`line_droplet`]), so the answer is that of a search of every droplet. The other
//! droplets (the contours' single droplets, a line off the rows, one that overlaps another run
//! of its row) go to a hash grid ([`Below`]).

use super::Droplet;
use super::cover::Cover;
use super::grid::{Below, floor};
use crate::base::geom::{DVec2, Point, dist, line_droplet, line_droplet_count, sin_cos_deg};
use crate::base::settings::MAX_UNITS;
use crate::slicing::plan::{Move, MoveKind};

/// How far (in each coordinate of the row's frame) the first and last droplet of a line may
/// lie from where a run of its row puts them for the line to be taken as that run, mm. A
/// line's ends are written rounded to 0.1 µm, so its droplets stray from the row by up to
/// about 0.15 µm. The droplets between lie as near as the first and last: a line's droplets
/// are an affine function of their index, and so are the places the run gives them.
const TOL: f64 = 5e-4;

/// Places up to this much beyond the reach are looked at (a droplet lies within √5·[`TOL`]
/// of its place on the run: `TOL` across, 2·`TOL` along).
const SLACK: f64 = 3.0 * TOL;

/// The raster's cells lie this much within reach (the rounding of its products).
const EPS: f64 = 1e-6;

/// At most this many rows between a layer's first and last run (else its lines go to the
/// grid).
const MAX_ROWS: i64 = 1 << 22;

/// Rows of hatch lines: (j + `phase`)·`spacing` across the direction `angle`, droplets `pitch`
/// apart along them. Rotated by −angle, the rows are horizontal (as in
/// [`crate::slicing::hatch::hatch_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Frame {
    sin: f64,
    cos: f64,
    spacing: f64,
    phase: f64,
    pitch: f64,
    /// 1 / spacing, 1 / pitch (rows and places by products).
    inv_spacing: f64,
    inv_pitch: f64,
}

impl Frame {
    /// `None` unless `spacing` and `pitch` are positive and finite, `phase` 0 or ½ (the rows
    /// a half turn maps onto themselves).
    pub(super) fn new(angle_deg: f64, spacing: f64, phase: f64, pitch: f64) -> Option<Frame> {
        let fine = |x: f64| x.is_finite() && x > 8.0 * TOL;
        if !(fine(spacing)
            && fine(pitch)
            && angle_deg.is_finite()
            && (phase == 0.0 || phase == 0.5))
        {
            return None;
        }
        let (sin, cos) = sin_cos_deg(angle_deg.rem_euclid(180.0));
        Some(Frame {
            sin,
            cos,
            spacing,
            phase,
            pitch,
            inv_spacing: 1.0 / spacing,
            inv_pitch: 1.0 / pitch,
        })
    }

    fn to(&self, p: Point) -> DVec2 {
        DVec2::new(
            self.cos * p.x + self.sin * p.y,
            -self.sin * p.x + self.cos * p.y,
        )
    }

    /// The row within [`TOL`] of the frame's `y`, if any.
    fn row(&self, y: f64) -> Option<i64> {
        const FAR: f64 = (1u64 << 40) as f64;
        let r = (y / self.spacing - self.phase).round();
        ((y - (r + self.phase) * self.spacing).abs() <= TOL && r.abs() < FAR).then_some(r as i64)
    }

    /// The run of the line from `from` to `to` (length `len`, `n` droplets of width `w`, the
    /// frame's pitch) if its first and last droplets lie on one row, `n − 1` pitches apart.
    fn run(&self, from: Point, to: Point, len: f64, w: f64, n: u64) -> Option<Run> {
        let a = self.to(line_droplet(from, to, len, w, 0));
        let b = self.to(line_droplet(from, to, len, w, n - 1));
        let row = self.row(a.y)?;
        let dir = if b.x < a.x { -1.0 } else { 1.0 };
        let along = (n - 1) as f64 * self.pitch;
        let fits = self.row(b.y) == Some(row) && (a.x + dir * along - b.x).abs() <= 2.0 * TOL;
        fits.then(|| Run {
            row,
            x0: a.x,
            lo: a.x.min(a.x + dir * along),
            hi: a.x.max(a.x + dir * along),
            dir,
            n,
            from,
            to,
            len,
        })
    }
}

/// The droplets of one line on a row: droplet j of the line from `from` to `to` (length
/// `len`) lies near x0 + dir·j·pitch along the row, within `lo..=hi`.
#[derive(Clone, Copy, Debug)]
struct Run {
    row: i64,
    x0: f64,
    lo: f64,
    hi: f64,
    dir: f64,
    n: u64,
    from: Point,
    to: Point,
    len: f64,
}

/// The hatch frames of a layer: the part's fill (droplets of width B) and the support's
/// (of its unit's width); one when they are the same.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Frames {
    frames: [Option<Frame>; 2],
    /// Whether the support's droplets share the part's frame.
    shared: bool,
    /// The unit that prints the support.
    support_unit: u8,
}

impl Frames {
    /// The part's frame (lines of unit 0's width) and the support's, of unit `support_unit`.
    pub(super) fn new(part: Option<Frame>, support: Option<Frame>, support_unit: u8) -> Frames {
        let shared = part.is_some() && part == support;
        Frames {
            frames: [part, if shared { None } else { support }],
            shared,
            support_unit,
        }
    }

    /// The frame a move of `unit` may lie on: its index (a line of another width lies on
    /// none, [`Listed::list`]).
    fn of(&self, unit: u8) -> usize {
        if unit == self.support_unit && !self.shared {
            1
        } else {
            0
        }
    }
}

/// A layer's droplets as the pass reads them ([`Listed::list`]): its lines on hatch rows, and
/// the other droplets.
#[derive(Default)]
pub(super) struct Listed {
    /// The runs, with their frame.
    runs: Vec<(u8, Run)>,
    /// The droplets on no run.
    others: Vec<Droplet>,
}

impl Listed {
    /// Lists the droplets of `lists` (each a sequence of moves from the origin, as
    /// [`super::droplets_of`] reads them: each unit's width `widths[unit]`): keeps the lines on the
    /// rows of `frames` as runs, the other droplets as they are. With `ask = Some((below,
    /// f))`, calls `f` in their order with each droplet ([`At`]) that `below` does not cover
    /// ([`Index::covers`]) and the frame of its line (0 or 1, [`Frames`]).
    pub(super) fn list(
        &mut self,
        lists: [&[Move]; 2],
        frames: &Frames,
        widths: &[f64; MAX_UNITS],
        mut ask: Option<Ask>,
    ) {
        self.runs.clear();
        self.others.clear();
        for moves in lists {
            let mut at = Point::ZERO;
            for m in moves {
                let w = widths[usize::from(m.unit)];
                let (from, to) = (at, m.to);
                at = m.to;
                let which = frames.of(m.unit);
                match m.kind {
                    MoveKind::Droplet => {
                        if let Some((below, f)) = ask.as_mut()
                            && !below.covers(to)
                        {
                            f(&At::droplet(to, w), which as u8);
                        }
                        self.others.push((to, w));
                    }
                    MoveKind::Line => {
                        let len = dist(from, to);
                        let n = line_droplet_count(len, w);
                        let step = if len > 0.0 {
                            (to - from) * (w / len)
                        } else {
                            DVec2::ZERO
                        };
                        if let Some((below, f)) = ask.as_mut() {
                            below.cover.uncovered(from, step, n, |j| {
                                let d = At {
                                    near: from + j as f64 * step,
                                    line: Some((from, to, len, j)),
                                    w,
                                };
                                f(&d, which as u8);
                            });
                        }
                        let run = match frames.frames[which] {
                            Some(f) if n > 0 && f.pitch == w => f.run(from, to, len, w, n),
                            _ => None,
                        };
                        match run {
                            Some(r) => self.runs.push((which as u8, r)),
                            None => self
                                .others
                                .extend((0..n).map(|j| (line_droplet(from, to, len, w, j), w))),
                        }
                    }
                    _ => {}
                }
            }
        }
    }
}

/// The layer below and what to do with a droplet it does not cover ([`Listed::list`]).
pub(super) type Ask<'a> = (&'a Index, &'a mut dyn FnMut(&At, u8));

/// A droplet as [`Listed::list`] gives it: where it lies within 10⁻⁹ mm (`near`, without a
/// division), and how to compute it exactly ([`At::exact`]).
pub(super) struct At {
    pub(super) near: Point,
    /// Droplet j of the line from, to of length len; `None`: a single droplet at `near`.
    line: Option<(Point, Point, f64, u64)>,
    pub(super) w: f64,
}

impl At {
    fn droplet(p: Point, w: f64) -> At {
        At {
            near: p,
            line: None,
            w,
        }
    }

    /// The droplet as the line sets it ([`line_droplet`]).
    pub(super) fn exact(&self) -> Point {
        match self.line {
            Some((from, to, len, j)) => line_droplet(from, to, len, self.w, j),
            None => self.near,
        }
    }
}

/// The runs of one frame, by row and extent along it, disjoint.
#[derive(Default)]
struct Rows {
    frame: Option<Frame>,
    /// The width of their droplets (the frame's pitch).
    width: f64,
    runs: Vec<Run>,
    /// The runs as given, while they are sorted (kept for the next fill).
    sorting: Vec<Run>,
    row0: i64,
    /// Row `row0 + r`'s runs are `runs[rows[r]..rows[r + 1]]`.
    rows: Vec<u32>,
}

impl Rows {
    /// The runs `runs` of `frame` in place of these; a run that overlaps the one before it in
    /// its row (or all, beyond [`MAX_ROWS`] rows) appends its droplets to `others` instead.
    fn fill(
        &mut self,
        frame: Option<Frame>,
        runs: impl Iterator<Item = Run>,
        others: &mut Vec<Droplet>,
    ) {
        self.frame = frame;
        self.width = frame.map_or(0.0, |f| f.pitch);
        self.sorting.clear();
        self.sorting.extend(runs);
        let (mut first, mut last) = (i64::MAX, i64::MIN);
        for r in &self.sorting {
            (first, last) = (first.min(r.row), last.max(r.row));
        }
        let too_many = !self.sorting.is_empty() && last - first >= MAX_ROWS;
        if too_many || self.sorting.is_empty() {
            std::mem::swap(&mut self.runs, &mut self.sorting);
        } else {
            // By row (a counting sort: the runs come in the order of the moves), then by where
            // they start (to a quarter pitch: runs of a row that lie apart are apart by more,
            // and two that overlap are caught in any order).
            self.rows.clear();
            self.rows.resize((last - first + 2) as usize, 0);
            for r in &self.sorting {
                self.rows[(r.row - first) as usize + 1] += 1;
            }
            for i in 1..self.rows.len() {
                self.rows[i] += self.rows[i - 1];
            }
            self.runs.clear();
            self.runs.resize(self.sorting.len(), self.sorting[0]);
            // rows[k] is row k's next free place; afterwards the end of row k.
            for r in &self.sorting {
                let at = &mut self.rows[(r.row - first) as usize];
                self.runs[*at as usize] = *r;
                *at += 1;
            }
            let key = frame.map_or(0.0, |f| 4.0 * f.inv_pitch);
            let mut from = 0;
            for &end in &self.rows[..self.rows.len() - 1] {
                let row = &mut self.runs[from..end as usize];
                if row.len() > 1 {
                    row.sort_unstable_by_key(|r| (r.lo * key) as i64);
                }
                from = end as usize;
            }
        }
        let mut kept = 0;
        for i in 0..self.runs.len() {
            let r = self.runs[i];
            let overlaps = kept > 0 && {
                let last = &self.runs[kept - 1];
                last.row == r.row && r.lo <= last.hi + 2.0 * SLACK
            };
            if too_many || overlaps {
                let w = self.width;
                others.extend((0..r.n).map(|j| (line_droplet(r.from, r.to, r.len, w, j), w)));
            } else {
                self.runs[kept] = r;
                kept += 1;
            }
        }
        self.runs.truncate(kept);
        self.rows.clear();
        if let (Some(a), Some(z)) = (self.runs.first(), self.runs.last()) {
            self.row0 = a.row;
            self.rows.resize((z.row - a.row + 2) as usize, 0);
            for r in &self.runs {
                self.rows[(r.row - self.row0) as usize + 1] += 1;
            }
            for i in 1..self.rows.len() {
                self.rows[i] += self.rows[i - 1];
            }
        }
    }

    /// The runs of row `j`, if it is within these rows.
    fn row(&self, j: i64) -> Option<&[Run]> {
        let r = usize::try_from(j - self.row0).ok()?;
        let (a, b) = (*self.rows.get(r)?, *self.rows.get(r + 1)?);
        Some(&self.runs[a as usize..b as usize])
    }

    /// A droplet of the runs within `r` of `p`: the nearest row first, then every row within
    /// `r` + [`SLACK`]; in each, the droplets whose places lie within reach.
    fn find_within(&self, p: Point, r: f64) -> Option<Droplet> {
        let f = self.frame.as_ref()?;
        if self.runs.is_empty() {
            return None;
        }
        let q = f.to(p);
        let rr = r + SLACK;
        // Rows by products with the inverse: off by far less than the slack.
        let at = q.y * f.inv_spacing - f.phase;
        let near = floor(at + 0.5);
        let last = self.row0 + self.rows.len() as i64 - 2;
        let j0 = (-floor(-(at - rr * f.inv_spacing))).max(self.row0);
        let j1 = floor(at + rr * f.inv_spacing).min(last);
        let found = self.in_row(f, near, p, q, r, rr);
        if found.is_some() || j0 > j1 {
            return found;
        }
        (j0..=j1)
            .filter(|&j| j != near)
            .find_map(|j| self.in_row(f, j, p, q, r, rr))
    }

    /// A droplet of row `j`'s runs within `r` of `p` (`q` in the frame).
    fn in_row(&self, f: &Frame, j: i64, p: Point, q: DVec2, r: f64, rr: f64) -> Option<Droplet> {
        let runs = self.row(j)?;
        let dy = q.y - (j as f64 + f.phase) * f.spacing;
        let h2 = rr * rr - dy * dy;
        if h2.is_nan() || h2 < 0.0 {
            return None;
        }
        let h = h2.sqrt();
        let (lo, hi) = (q.x - h, q.x + h);
        let mut i = runs.partition_point(|x| x.hi < lo);
        while let Some(run) = runs.get(i).filter(|x| x.lo <= hi) {
            // The droplets whose places x0 + dir·j·pitch lie in lo..=hi.
            let (a, b) = ((lo - run.x0) * run.dir, (hi - run.x0) * run.dir);
            let (a, b) = (a.min(b) * f.inv_pitch, a.max(b) * f.inv_pitch);
            let ja = (-floor(-a)).max(0);
            let jb = floor(b).min(run.n as i64 - 1);
            for k in ja..=jb {
                let d = line_droplet(run.from, run.to, run.len, self.width, k as u64);
                if (p - d).length_squared() <= r * r {
                    return Some((d, self.width));
                }
            }
            i += 1;
        }
        None
    }
}

/// A layer's droplets for "is there one within reach" ([`Index::covers`], then
/// [`Index::find_within`]).
pub(super) struct Index {
    grid: Below,
    /// The grid's droplets (kept for the next fill).
    others: Vec<Droplet>,
    /// The runs of the part's frame and of the support's.
    rows: [Rows; 2],
    cover: Cover,
    /// The raster's rectangles (kept for the next fill).
    rects: Vec<(DVec2, DVec2)>,
}

impl Index {
    pub(super) fn new(narrow: f64, wide: f64, reach: impl Fn(f64) -> f64) -> Index {
        Index {
            grid: Below::new(narrow, wide, reach, &[]),
            others: Vec::new(),
            rows: Default::default(),
            cover: Cover::default(),
            rects: Vec::new(),
        }
    }

    /// The index of the layer `listed` (listed with `frames`) in place of this one's.
    pub(super) fn fill(&mut self, listed: &Listed, frames: &Frames, reach: impl Fn(f64) -> f64) {
        self.others.clear();
        self.others.extend_from_slice(&listed.others);
        for (k, rows) in self.rows.iter_mut().enumerate() {
            let runs = listed
                .runs
                .iter()
                .filter(|(f, _)| *f as usize == k)
                .map(|(_, r)| *r);
            rows.fill(frames.frames[k], runs, &mut self.others);
        }
        self.grid.fill(&reach, &self.others);
        self.fill_cover(&reach);
    }

    /// The raster of the cells the layer surely supports, in its rows' frame: along each run
    /// the band within reach of its droplets wherever one lies within half a pitch along (half
    /// a pitch beyond its ends), around each other droplet the square inside its reach.
    fn fill_cover(&mut self, reach: impl Fn(f64) -> f64) {
        self.rects.clear();
        let Some(f) = self.rows.iter().find_map(|r| r.frame) else {
            self.cover.reset(0.0, 1.0, 0.0, DVec2::ONE, DVec2::ZERO);
            return;
        };
        let mut cell = f64::INFINITY;
        for rows in &self.rows {
            let Some(g) = rows.frame.filter(|g| (g.sin, g.cos) == (f.sin, f.cos)) else {
                continue;
            };
            let (p, r) = (g.pitch, reach(rows.width) - SLACK - EPS);
            if r.is_nan() || r <= 0.5 * p || rows.runs.is_empty() {
                continue;
            }
            let half = (r * r - 0.25 * p * p).sqrt();
            cell = cell.min(0.45 * half);
            self.rects.extend(rows.runs.iter().map(|run| {
                let y = (run.row as f64 + g.phase) * g.spacing;
                (
                    DVec2::new(run.lo - 0.5 * p, y - half),
                    DVec2::new(run.hi + 0.5 * p, y + half),
                )
            }));
        }
        for &(d, w) in &self.others {
            let a = (reach(w) - EPS) * std::f64::consts::FRAC_1_SQRT_2;
            if a > 0.0 {
                let q = Cover::frame(f.sin, f.cos, d);
                self.rects.push((q - a, q + a));
                if cell == f64::INFINITY {
                    cell = 0.6 * a;
                }
            }
        }
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for &(a, b) in &self.rects {
            lo = lo.min(a);
            hi = hi.max(b);
        }
        self.cover.reset(f.sin, f.cos, cell, lo, hi);
        for &(a, b) in &self.rects {
            self.cover.mark(a, b);
        }
    }

    /// Whether a point within 10⁻⁹ mm of `p` lies where the layer surely supports it (within
    /// reach of one of its droplets); false says nothing.
    #[inline]
    pub(super) fn covers(&self, p: Point) -> bool {
        self.cover.covers(p)
    }

    /// A droplet d within `reach(d's width)` of `p`, if any, looked for first in the runs of
    /// frame `which` (p's own line's: the layer below's lines of the same kind most often
    /// support it), then in the grid, then in the other frame's runs.
    pub(super) fn find_within(
        &self,
        p: Point,
        which: u8,
        reach: impl Fn(f64) -> f64 + Copy,
    ) -> Option<Droplet> {
        let (first, other) = (
            &self.rows[which as usize & 1],
            &self.rows[1 - (which as usize & 1)],
        );
        first
            .find_within(p, reach(first.width))
            .or_else(|| self.grid.find_within(p, reach))
            .or_else(|| other.find_within(p, reach(other.width)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::geom::round_output;
    use crate::slicing::plan::Role;

    /// Moves of unit `unit` along rows of `f` (some reversed, some cut short, one across the
    /// rows, one off them), single droplets, from a seeded generator.
    fn lines(f: &Frame, w: f64, unit: u8, random: &mut impl FnMut() -> f64) -> Vec<Move> {
        let back = |x: f64, y: f64| DVec2::new(f.cos * x - f.sin * y, f.sin * x + f.cos * y);
        let mut out = Vec::new();
        let mv = |kind, to| Move {
            kind,
            role: Role::Fill,
            to: round_output(to),
            unit,
        };
        for j in -12..12 {
            let y = (j as f64 + f.phase) * f.spacing;
            let mut x = -3.0 + random();
            while x < 3.0 {
                let n = 1 + (random() * 12.0) as usize;
                let (a, b) = (x, x + (n - 1) as f64 * w + random() * 0.5 * w);
                let (a, b) = if random() < 0.5 { (a, b) } else { (b, a) };
                let off = if random() < 0.05 {
                    0.3 * f.spacing
                } else {
                    0.0
                };
                out.push(mv(MoveKind::Travel, back(a, y + off)));
                out.push(mv(MoveKind::Line, back(b, y + off)));
                x += (n + 1) as f64 * w + random() * 2.0 * w;
            }
            if random() < 0.3 {
                out.push(mv(MoveKind::Droplet, back(random() * 6.0 - 3.0, y)));
            }
        }
        // One across the rows, and one overlapping a row's runs.
        out.push(mv(MoveKind::Travel, back(0.1, -2.0)));
        out.push(mv(MoveKind::Line, back(0.3, 2.0)));
        out.push(mv(MoveKind::Travel, back(-2.0, 0.5 * f.spacing)));
        out.push(mv(MoveKind::Line, back(2.0, 0.5 * f.spacing)));
        out
    }

    #[test]
    fn the_index_answers_as_a_search_of_every_droplet() {
        let mut random = crate::base::testing::rng(0x9e37_79b9_7f4a_7c15u64);
        let limit = 0.104;
        let reach = |w: f64| w / 2.0 + limit;
        let (mut found, mut missed) = (0, 0);
        // Both frames alike (the default), apart (another B₁ and spacing), and at 0°.
        for (angle, b, b1, sp1) in [
            (45.0, 0.208, 0.208, 0.208),
            (135.0, 0.208, 0.3, 0.45),
            (0.0, 0.2, 0.2, 0.2),
        ] {
            let fa = Frame::new(angle, b, 0.5, b).unwrap();
            let fb = Frame::new(angle, sp1, 0.5, b1).unwrap();
            let frames = Frames::new(Some(fa), Some(fb), 1);
            let widths = [b, b1, b, b];
            let part = lines(&fa, b, 0, &mut random);
            let support = lines(&fb, b1, 1, &mut random);
            let mut listed = Listed::default();
            let mut listed_all = Vec::new();
            let none = Index::new(b, b1, reach);
            listed.list(
                [&part, &support],
                &frames,
                &widths,
                Some((&none, &mut |d, _| {
                    assert!((d.near - d.exact()).length() < 1e-9);
                    listed_all.push((d.exact(), d.w));
                })),
            );
            assert!(listed.runs.len() > 100, "{}", listed.runs.len());
            let mut index = Index::new(b, b1, reach);
            index.fill(&listed, &frames, reach);
            // Every droplet is listed as `droplets_of` lists them.
            let mut all = Vec::new();
            super::super::droplets_of(&part, &widths, None, &mut all);
            super::super::droplets_of(&support, &widths, None, &mut all);
            assert_eq!(listed_all, all);
            let mut covered = 0;
            for k in 0..4000 {
                let p = if k % 3 == 0 {
                    // At the reach of a droplet, in a random direction.
                    let (q, w) = all[k % all.len()];
                    let a = random() * std::f64::consts::TAU;
                    q + reach(w) * DVec2::new(a.cos(), a.sin())
                } else {
                    DVec2::new(random() * 8.0 - 4.0, random() * 8.0 - 4.0)
                };
                let scan = all
                    .iter()
                    .any(|&(q, w)| (p - q).length_squared() <= reach(w).powi(2));
                // The raster covers only points within reach of a droplet.
                if index.covers(p) {
                    assert!(
                        scan,
                        "query {k} at {p}: covered, but no droplet within reach"
                    );
                    covered += 1;
                }
                for which in [0, 1] {
                    let got = index.find_within(p, which, reach);
                    assert_eq!(got.is_some(), scan, "query {k} at {p}");
                    if let Some((q, w)) = got {
                        assert!((p - q).length_squared() <= reach(w).powi(2));
                        assert!(all.contains(&(q, w)));
                    }
                }
                if scan { found += 1 } else { missed += 1 }
            }
            assert!(covered > 400, "{covered}");
        }
        assert!(found > 2000 && missed > 2000, "{found} {missed}");
    }
}
