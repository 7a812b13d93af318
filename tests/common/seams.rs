//! Loop seams measured on written G-code (SPEC.md "Loop seams"), shared by tests/seams.rs and
//! examples/seams.rs: only the `G26` droplets of each layer, in file order, from the text.
//!
//! Loops are found without the planner: in `exact` code a loop ends where its first droplet is
//! repeated. `even` code repeats nothing, so its loops are cut at the loop starts of the
//! `exact` code of the same model and settings: both modes start every loop at the same point
//! (`start_jitter` moves it the same way), so the same written coordinates begin each loop.
//!
//! A *gap* is the straight-line distance between two consecutive droplet centres of a loop,
//! as written (4 decimals), the seam (last droplet → first) included: B is a straight-line
//! spacing in SPEC.md (a droplet's width), and what two droplets overlap or leave open depends
//! on the distance of their centres, not on the arc of the loop between them.
#![allow(dead_code)]

use std::collections::HashSet;

pub type P = [f64; 2];

/// Rounding of written coordinates (±0.00005 each) moves a distance by up to 1.42e-4 mm.
pub const TOL: f64 = 1.5e-4;

pub fn d(a: P, b: P) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

pub fn key(p: P) -> (i64, i64) {
    ((p[0] * 1e4).round() as i64, (p[1] * 1e4).round() as i64)
}

/// The `G26` droplets of each layer, in file order (a new layer where Z changes).
pub fn g26_layers(text: &str) -> Vec<Vec<P>> {
    let mut layers: Vec<Vec<P>> = Vec::new();
    let mut z = f64::NAN;
    for line in text.lines() {
        if line.starts_with(';') {
            continue;
        }
        let mut w = line.split(' ');
        let code = w.next().unwrap_or("");
        let mut num = |c: char| {
            w.next()
                .and_then(|t| t.strip_prefix(c))
                .and_then(|t| t.parse::<f64>().ok())
                .unwrap_or_else(|| panic!("bad line {line:?}"))
        };
        let (x, y, lz) = (num('X'), num('Y'), num('Z'));
        if lz != z {
            layers.push(Vec::new());
            z = lz;
        }
        if code == "G26" {
            layers.last_mut().expect("a layer").push([x, y]);
        }
    }
    layers
}

/// One loop's droplets as written; `repeated` when its first droplet is written again at its
/// end (that copy is not in `points`).
#[derive(Clone, Debug)]
pub struct Loop {
    pub points: Vec<P>,
    pub repeated: bool,
}

impl Loop {
    /// Gaps between consecutive droplets, the seam (last → first) last; none for a loop of
    /// fewer than 3 droplets.
    pub fn gaps(&self) -> Vec<f64> {
        let p = &self.points;
        let n = p.len();
        if n < 3 {
            return Vec::new();
        }
        (0..n).map(|i| d(p[i], p[(i + 1) % n])).collect()
    }
}

/// The loops of one layer of `exact` code (`close_loops = true`): a loop runs from a droplet
/// to the next copy of it, its steps B apart; a droplet whose next one is not B away (and is
/// not repeated) is a loop of one droplet.
pub fn exact_loops(drops: &[P], b: f64) -> Vec<Loop> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < drops.len() {
        let mut j = i + 1;
        let mut closed = None;
        while j < drops.len() && d(drops[j - 1], drops[j]) <= b + TOL {
            if key(drops[j]) == key(drops[i]) {
                closed = Some(j);
                break;
            }
            j += 1;
        }
        match closed {
            Some(j) => {
                out.push(Loop {
                    points: drops[i..j].to_vec(),
                    repeated: true,
                });
                i = j + 1;
                // A walk that lands exactly on its start writes it twice before the copy.
                while i < drops.len() && key(drops[i]) == key(drops[j]) {
                    i += 1;
                }
            }
            None => {
                out.push(Loop {
                    points: vec![drops[i]],
                    repeated: false,
                });
                i += 1;
            }
        }
    }
    out
}

/// The loops of one layer of `even` code, cut where a droplet is one of `starts` (the first
/// droplets of the `exact` code's loops of the same layer). A loop's first droplet written
/// again closes it (`repeated`). Err if a droplet follows a closed loop and is no start.
pub fn loops_from_starts(drops: &[P], starts: &[P]) -> Result<Vec<Loop>, String> {
    let starts: HashSet<(i64, i64)> = starts.iter().map(|&p| key(p)).collect();
    let mut out: Vec<Loop> = Vec::new();
    for &p in drops {
        match out.last_mut() {
            Some(l) if l.points.len() > 1 && key(l.points[0]) == key(p) => {
                // (twice where an exact walk lands on its start)
                l.repeated = true;
            }
            _ if starts.contains(&key(p)) => out.push(Loop {
                points: vec![p],
                repeated: false,
            }),
            Some(l) if !l.repeated => l.points.push(p),
            _ => {
                return Err(format!(
                    "droplet {p:?} follows a closed loop but starts none"
                ));
            }
        }
    }
    Ok(out)
}

/// Seam and gap figures over many loops (those of at least 3 droplets).
#[derive(Clone, Debug, Default)]
pub struct SeamStats {
    pub loops: usize,
    /// Loops of at least 3 droplets whose first droplet is repeated.
    pub repeated: usize,
    pub seams_below_quarter_b: usize,
    pub min_seam: f64,
    pub min_gap: f64,
    pub max_gap: f64,
    pub gap_sum: f64,
    pub gaps: usize,
}

impl SeamStats {
    pub fn new() -> SeamStats {
        SeamStats {
            min_seam: f64::INFINITY,
            min_gap: f64::INFINITY,
            ..SeamStats::default()
        }
    }

    pub fn add(&mut self, l: &Loop, b: f64) {
        let g = l.gaps();
        if g.is_empty() {
            return;
        }
        self.loops += 1;
        self.repeated += usize::from(l.repeated);
        let seam = *g.last().expect("gaps");
        self.seams_below_quarter_b += usize::from(seam < b / 4.0);
        self.min_seam = self.min_seam.min(seam);
        for &x in &g {
            self.min_gap = self.min_gap.min(x);
            self.max_gap = self.max_gap.max(x);
            self.gap_sum += x;
        }
        self.gaps += g.len();
    }

    pub fn close_share(&self) -> f64 {
        self.seams_below_quarter_b as f64 / self.loops.max(1) as f64
    }

    pub fn mean_gap(&self) -> f64 {
        self.gap_sum / self.gaps.max(1) as f64
    }
}

/// Upper bound of how much shorter than the loop n chords of s can be at its corners: a chord
/// straddling a corner of turn φ spans at most sec(φ/2) times its length of loop. φ of a step
/// is taken as the droplet polygon's turns at both its ends (a corner between two droplets
/// turns the polygon at both; on a smooth curve this counts each turn twice, a generous bound),
/// capped at 170°.
pub fn corner_allowance(points: &[P]) -> f64 {
    let n = points.len();
    let turn = |i: usize| {
        let (a, b, c) = (points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
        let cross = u[0] * v[1] - u[1] * v[0];
        let dot = u[0] * v[0] + u[1] * v[1];
        cross.atan2(dot).abs()
    };
    (0..n)
        .map(|i| {
            let phi = (turn(i) + turn((i + 1) % n)).min(170f64.to_radians());
            d(points[i], points[(i + 1) % n]) * (1.0 / (phi / 2.0).cos() - 1.0)
        })
        .sum()
}
