//! Write code, stage 6 (docs/spec.md 4.5, 5.3.6): the header and each [`LayerPlan`] as `.gco` text.
//! Coordinates have exactly 4 decimals; `G01` travel, `G25` a line of droplets, `G26` one
//! droplet. The header lists every setting, the input file, the version and a summary; it is
//! written before any layer, with fixed-width placeholders for the droplet counts and the
//! figures (print time, travel, volume, mass: [`FIGURE_LINES`]) that [`header`] fills in once
//! the slice is done (same length, so a file can be patched in place).

use crate::base::geom::{OUTPUT_DECIMALS, OUTPUT_SCALE};
use crate::base::settings::{MAX_UNITS, Settings, UnitId};
pub use crate::output::summary::Summary;
use crate::slicing::plan::{LayerPlan, MoveKind};
use std::fmt::Write;

/// What the header says about the input.
#[derive(Clone, Debug)]
pub struct HeaderInput<'a> {
    pub file_name: &'a str,
    pub facets: usize,
    pub layers: usize,
    /// Bounding box of the placed part (min, max).
    pub bounds: ([f64; 3], [f64; 3]),
    pub warnings: &'a [String],
    /// Every copy of every part (one line each).
    pub instances: &'a [crate::model::layout::Instance],
    /// The discharge units that print in the job, by number (unit 0 among them): a unit's
    /// own settings and figures are listed only when it prints.
    pub units_used: &'a [UnitId],
    /// The profiles applied to the settings, in order (one line when there are some).
    pub profiles: &'a [String],
}

/// Width of the droplet count fields in the header.
const COUNT_WIDTH: usize = 12;

/// Width of a figure's field in the header: [`exact`] writes at most 24 characters.
const FIGURE_WIDTH: usize = 24;

/// Which figure a header line carries ([`figure_lines`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureField {
    /// `Figures::print_seconds`, s.
    PrintSeconds,
    /// `Figures::travel_mm`, mm.
    Travel,
    /// `UnitFigures::seconds` of a unit, s (written when more than one unit prints).
    UnitSeconds(UnitId),
    /// `UnitFigures::volume_mm3` of a unit, mm³.
    UnitVolume(UnitId),
    /// `UnitFigures::mass_g` of a unit, g.
    UnitMass(UnitId),
}

/// The header's figure lines of a job whose units `used` print (by number; unit 0 among
/// them): label, field and unit. With unit 0 alone, `volume` and `mass` are its own; with
/// more, each unit has its droplet time, volume and mass (`volume unit 0`, …).
pub fn figure_lines(used: &[UnitId]) -> Vec<(String, FigureField, &'static str)> {
    let several = used.len() > 1;
    let mut lines = vec![("print time".to_string(), FigureField::PrintSeconds, "s")];
    if several {
        lines.extend(unit_lines(
            used,
            &[("droplet time", FigureField::UnitSeconds, "s")],
        ));
    }
    lines.push(("travel".into(), FigureField::Travel, "mm"));
    let amounts: [UnitFigure; 2] = [
        ("volume", FigureField::UnitVolume, "mm³"),
        ("mass", FigureField::UnitMass, "g"),
    ];
    if several {
        lines.extend(unit_lines(used, &amounts));
    } else {
        let first = UnitId::FIRST;
        lines.extend(amounts.map(|(what, field, unit)| (what.to_string(), field(first), unit)));
    }
    lines
}

/// A figure each unit has: the label's words, the field of a unit, the unit of measure.
type UnitFigure = (&'static str, fn(UnitId) -> FigureField, &'static str);

/// The lines of `figures` ("volume unit 1", …) unit by unit, for every unit of `used`.
fn unit_lines(
    used: &[UnitId],
    figures: &[UnitFigure],
) -> impl Iterator<Item = (String, FigureField, &'static str)> {
    used.iter().flat_map(move |&u| {
        let line =
            move |&(what, field, unit): &UnitFigure| (format!("{what} unit {u}"), field(u), unit);
        figures.iter().map(line)
    })
}

impl FigureField {
    /// The field a header line's label names ([`figure_lines`]), for any unit up to
    /// [`MAX_UNITS`].
    pub fn of_label(label: &str) -> Option<FigureField> {
        let unit = |rest: &str| -> Option<UnitId> {
            let n: u8 = rest.parse().ok()?;
            (usize::from(n) < MAX_UNITS && rest == n.to_string()).then_some(UnitId(n))
        };
        Some(match label {
            "print time" => FigureField::PrintSeconds,
            "travel" => FigureField::Travel,
            "volume" => FigureField::UnitVolume(UnitId::FIRST),
            "mass" => FigureField::UnitMass(UnitId::FIRST),
            _ => {
                if let Some(r) = label.strip_prefix("droplet time unit ") {
                    FigureField::UnitSeconds(unit(r)?)
                } else if let Some(r) = label.strip_prefix("volume unit ") {
                    FigureField::UnitVolume(unit(r)?)
                } else {
                    FigureField::UnitMass(unit(label.strip_prefix("mass unit ")?)?)
                }
            }
        })
    }

    /// This figure of `f` (0 for a unit `f` has no entry for).
    pub fn of(self, f: &crate::output::summary::Figures) -> f64 {
        let unit = |u: UnitId| f.units.get(u.index()).copied().unwrap_or_default();
        match self {
            FigureField::PrintSeconds => f.print_seconds,
            FigureField::Travel => f.travel_mm,
            FigureField::UnitSeconds(u) => unit(u).seconds,
            FigureField::UnitVolume(u) => unit(u).volume_mm3,
            FigureField::UnitMass(u) => unit(u).mass_g,
        }
    }

    /// Sets this figure of `f` (nothing for a unit `f` has no entry for).
    pub fn set(self, f: &mut crate::output::summary::Figures, v: f64) {
        let units = &mut f.units;
        let slot = match self {
            FigureField::PrintSeconds => Some(&mut f.print_seconds),
            FigureField::Travel => Some(&mut f.travel_mm),
            FigureField::UnitSeconds(u) => units.get_mut(u.index()).map(|x| &mut x.seconds),
            FigureField::UnitVolume(u) => units.get_mut(u.index()).map(|x| &mut x.volume_mm3),
            FigureField::UnitMass(u) => units.get_mut(u.index()).map(|x| &mut x.mass_g),
        };
        if let Some(slot) = slot {
            *slot = v;
        }
    }
}

/// `v` exactly: the shortest text that reads back as the same `f64` (plain digits from 1e-4
/// to 1e16, else with an exponent), at most [`FIGURE_WIDTH`] characters. A figure read back
/// from the header is then the very number the slice showed.
pub fn exact(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `x` with [`OUTPUT_DECIMALS`] (4) decimals, never `-0.0000`.
pub fn coord(x: f64) -> String {
    let mut s = String::with_capacity(12);
    push_coord(&mut s, x);
    s
}

/// Appends `x` rounded to [`OUTPUT_DECIMALS`] (4) decimals (half away from zero, as
/// `f64::round`), never `-0.0000`. Much faster than `format!("{x:.4}")`, which matters for
/// files with millions of droplets: the rounding without a call to libm's `round` (the
/// baseline x86-64 target has no rounding instruction), the scaled integer's digits written
/// by `itoa` (two digits a step) and the point put in front of its last four.
pub fn push_coord(out: &mut String, x: f64) {
    const _: () = assert!(OUTPUT_DECIMALS == 4, "push_coord writes 4 digits");
    let t = x * OUTPUT_SCALE;
    if !t.is_finite() || t.abs() >= 1e15 {
        let _ = write!(out, "{x:.OUTPUT_DECIMALS$}");
        return;
    }
    // t − trunc(t) is exact for |t| < 2⁵²: rounding half away from zero by the fraction.
    let i = t as i64;
    let r = t - i as f64;
    let v = i + i64::from(r >= 0.5) - i64::from(r <= -0.5);
    if v < 0 {
        out.push('-');
    }
    let mut buf = itoa::Buffer::new();
    let digits = buf.format(v.unsigned_abs());
    match digits.len().checked_sub(OUTPUT_DECIMALS) {
        Some(int) if int > 0 => {
            out.push_str(&digits[..int]);
            out.push('.');
            out.push_str(&digits[int..]);
        }
        // |v| < 10⁴: "0." and the fraction's leading zeros.
        _ => {
            out.push_str(&"0.000"[..2 + OUTPUT_DECIMALS - digits.len()]);
            out.push_str(digits);
        }
    }
}

/// The header comment block. With `summary = None` the droplet counts are placeholders of
/// the same width, so the final header has exactly the same length.
pub fn header(s: &Settings, input: &HeaderInput, summary: Option<&Summary>) -> String {
    let mut h = String::new();
    let field = |v: Option<u64>| match v {
        Some(v) => format!("{v:>COUNT_WIDTH$}"),
        None => format!("{:>COUNT_WIDTH$}", "pending"),
    };
    let c = summary.map(|s| s.counts);
    let b = s.droplet_width();
    let _ = writeln!(
        h,
        "; dropslice {} — droplet machine code (G01 travel, G25 droplet line, G26 droplet)",
        crate::base::VERSION
    );
    let _ = writeln!(
        h,
        "; input = {}",
        input.file_name.replace(['\n', '\r'], " ")
    );
    let _ = writeln!(h, "; facets = {}", input.facets);
    let (lo, hi) = input.bounds;
    let _ = writeln!(
        h,
        "; bounding box = X{}..{} Y{}..{} Z{}..{} mm",
        coord(lo[0]),
        coord(hi[0]),
        coord(lo[1]),
        coord(hi[1]),
        coord(lo[2]),
        coord(hi[2])
    );
    let _ = writeln!(h, "; layers = {}", input.layers);
    let _ = writeln!(
        h,
        "; droplet width B = {} mm, height H = {} mm",
        coord(b),
        coord(s.layer_height)
    );
    let _ = writeln!(h, "; droplets outer loops = {}", field(c.map(|c| c.outer)));
    let _ = writeln!(h, "; droplets inner loops = {}", field(c.map(|c| c.inner)));
    let _ = writeln!(h, "; droplets fill        = {}", field(c.map(|c| c.fill)));
    if input.units_used.len() > 1 {
        let _ = writeln!(
            h,
            "; droplets support     = {}",
            field(c.map(|c| c.support))
        );
        for &u in &input.units_used[1..] {
            let label = format!("droplets of unit {u}");
            let _ = writeln!(h, "; {label:<20} = {}", field(c.map(|c| c.unit(u))));
        }
    }
    let _ = writeln!(
        h,
        "; droplets total       = {}",
        field(c.map(|c| c.total()))
    );
    // The figures the CLI prints and the page shows, of the same summary and settings.
    let figures = summary.map(|sum| sum.figures(s));
    for (label, f, unit) in figure_lines(input.units_used) {
        let value = figures
            .as_ref()
            .map_or("pending".into(), |g| exact(f.of(g)));
        let _ = writeln!(h, "; {label:<20} = {value:>FIGURE_WIDTH$} {unit}");
    }
    for p in input.instances {
        let _ = writeln!(h, "; {}", part_line(p));
    }
    for w in input.warnings {
        let _ = writeln!(h, "; warning: {}", w.replace(['\n', '\r'], " "));
    }
    if !input.profiles.is_empty() {
        let names: Vec<String> = input
            .profiles
            .iter()
            .map(|p| p.replace(['\n', '\r'], " "))
            .collect();
        let _ = writeln!(h, "; profiles = {}", names.join(", "));
    }
    let _ = writeln!(h, "; settings:");
    for (name, value, unit) in s.entries_with(|u| input.units_used.contains(&u)) {
        if unit.is_empty() {
            let _ = writeln!(h, "; {name} = {value}");
        } else {
            let _ = writeln!(h, "; {name} = {value} ({unit})");
        }
    }
    let _ = writeln!(h, "; end of header");
    h
}

/// An instance as the header lists it: `part 1 = gear.3mf (object 3), rotate 0/0/90 deg,
/// scale 1/1/1, at X30.0000 Y5.0000, angle 0 deg, copy 1 of 2, unit 0` (", mirror x/z" after
/// the scale of a mirrored part).
pub fn part_line(p: &crate::model::layout::Instance) -> String {
    let clean = |s: &str| crate::model::spec::clean_name(s);
    let what = match (&p.object, p.item) {
        (Some(o), _) => format!(" (object {})", clean(o)),
        (None, Some(i)) => format!(" (item {i})"),
        (None, None) => String::new(),
    };
    let name = if crate::model::import::stem(&p.file) == p.name {
        String::new()
    } else {
        format!(" \"{}\"", clean(&p.name))
    };
    let [rx, ry, rz] = p.rotate;
    let [sx, sy, sz] = p.scale;
    let axes: Vec<&str> = ["x", "y", "z"]
        .into_iter()
        .zip(p.mirror)
        .filter(|(_, m)| *m)
        .map(|(a, _)| a)
        .collect();
    let mirror = if axes.is_empty() {
        String::new()
    } else {
        format!(", mirror {}", axes.join("/"))
    };
    format!(
        "part {} = {}{what}{name}, rotate {rx}/{ry}/{rz} deg, scale {sx}/{sy}/{sz}{mirror}, at X{} Y{}{}, angle {} deg, copy {} of {}, unit {}",
        p.id.part + 1,
        clean(&p.file),
        coord(p.at[0]),
        coord(p.at[1]),
        if p.placed { "" } else { " (arranged)" },
        p.place_angle,
        p.id.copy + 1,
        p.copies,
        p.unit
    )
}

/// One layer's commands, with a `T` line wherever the unit changes within the layer (none
/// before its first move: see [`layer_text_after`]).
pub fn layer_text(plan: &LayerPlan) -> String {
    layer_text_after(plan, plan.first_unit().unwrap_or(0))
}

/// One layer's commands after a layer that left unit `before` selected: a `T` line (right
/// after the layer's comment line) wherever the unit of the next move differs from the one
/// selected, and nowhere else (docs/spec.md "Discharge units").
pub fn layer_text_after(plan: &LayerPlan, before: u8) -> String {
    let mut t = String::with_capacity(plan.moves.len() * 34 + 40);
    let z = coord(plan.z);
    let _ = writeln!(t, "; layer {} z = {}", plan.index + 1, z);
    let mut unit = before;
    for m in &plan.moves {
        if m.unit != unit {
            unit = m.unit;
            let _ = writeln!(t, "T{unit}");
        }
        t.push_str(match m.kind {
            MoveKind::Travel => "G01 X",
            MoveKind::Droplet => "G26 X",
            MoveKind::Line => "G25 X",
        });
        push_coord(&mut t, m.to[0]);
        t.push_str(" Y");
        push_coord(&mut t, m.to[1]);
        t.push_str(" Z");
        t.push_str(&z);
        t.push('\n');
    }
    t
}

/// Puts a `T{unit}` line after the first line (the layer's comment) of a layer's text made by
/// [`layer_text`], for a layer that follows one which left another unit selected.
pub fn insert_unit_line(text: &mut String, unit: u8) {
    let at = text.find('\n').map_or(text.len(), |i| i + 1);
    text.insert_str(at, &format!("T{unit}\n"));
}

/// Closing comments: the totals, each unit's droplets beyond unit 0 (`support`: the unit that
/// printed the support) and what slicing repaired.
pub fn footer(summary: &Summary, support: Option<UnitId>) -> String {
    let mut f = format!(
        "; end of code: {} layers, {} droplets ({} outer loops, {} inner loops, {} fill)\n",
        summary.layers,
        summary.counts.total(),
        summary.counts.outer,
        summary.counts.inner,
        summary.counts.fill
    );
    for u in UnitId::all(MAX_UNITS).skip(1) {
        if summary.counts.unit(u) > 0 {
            let support = if support == Some(u) {
                summary.counts.support
            } else {
                0
            };
            let _ = writeln!(
                f,
                "; unit {u}: {} droplets ({support} of them support)",
                summary.counts.unit(u)
            );
        }
    }
    for r in summary.repairs() {
        let _ = writeln!(f, "; repaired: {r}");
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coordinates_have_four_decimals() {
        for (x, s) in [
            (0.0, "0.0000"),
            (-0.00001, "0.0000"),
            (0.312, "0.3120"),
            (-1.23456, "-1.2346"),
            (19.99999, "20.0000"),
            (123456.7, "123456.7000"),
            (-0.5, "-0.5000"),
        ] {
            assert_eq!(coord(x), s, "{x}");
        }
    }

    #[test]
    fn figures_are_written_exactly_within_their_width() {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut xs = vec![
            0.0,
            1e-4,
            9.999_999_999_999_999e-5,
            1e16,
            9_999_999_999_999_998.0,
            f64::MIN_POSITIVE,
            f64::MAX,
            5e-324,
            20478.123456789012,
            0.1 + 0.2,
        ];
        for _ in 0..100_000 {
            let unit = crate::base::testing::random(&mut state);
            xs.push(unit * 10f64.powi((state % 40) as i32 - 20));
        }
        for x in xs {
            for v in [x, -x] {
                let t = exact(v);
                assert!(t.len() <= FIGURE_WIDTH, "{t}");
                assert_eq!(t.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{t}");
            }
        }
    }

    #[test]
    fn the_filled_header_has_the_length_of_the_placeholders() {
        use crate::slicing::plan::Counts;
        let settings = Settings::default();
        let units = Settings {
            units: 3,
            ..Settings::default()
        };
        let used: [&[UnitId]; 3] = [
            &[UnitId(0)],
            &[UnitId(0), UnitId(1)],
            &[UnitId(0), UnitId(2)],
        ];
        for units_used in used {
            let settings = if units_used.len() > 1 && units_used[1].0 == 2 {
                &units
            } else {
                &settings
            };
            let input = HeaderInput {
                file_name: "part.stl",
                facets: 12,
                layers: 3,
                bounds: ([0.0; 3], [1.0; 3]),
                warnings: &[],
                instances: &[],
                units_used,
                profiles: &[],
            };
            let other = units_used.get(1).copied();
            let pending = header(settings, &input, None);
            for (outer, travel) in [(0, 0.0), (7, 1.0 / 3.0), (u32::MAX as u64, 1e300)] {
                let mut counts = Counts {
                    outer,
                    fill: 5,
                    ..Counts::default()
                };
                if let Some(u) = other {
                    counts.units[u.index()] = 1;
                }
                let summary = Summary {
                    layers: 3,
                    counts,
                    travel_mm: travel,
                    ..Summary::default()
                };
                let filled = header(settings, &input, Some(&summary));
                assert_eq!(filled.len(), pending.len(), "{filled}");
                let f = summary.figures(settings);
                let line = filled.lines().find(|l| l.starts_with("; travel")).unwrap();
                assert_eq!(
                    line,
                    format!("; travel               = {:>24} mm", exact(travel))
                );
                assert!(filled.contains(&format!("= {:>24} s\n", exact(f.print_seconds))));
                for u in [1, 2] {
                    let named = filled.contains(&format!("; volume unit {u}"))
                        && filled.contains(&format!("; droplets of unit {u}   = "));
                    assert_eq!(named, other == Some(UnitId(u)), "{filled}");
                }
            }
        }
    }

    /// `x` rounded by `f64::round` and written by `format!`: what [`push_coord`] must write.
    fn formatted(x: f64) -> String {
        let v = (x * OUTPUT_SCALE).round();
        if !v.is_finite() || v.abs() >= 1e15 {
            return format!("{x:.4}");
        }
        let v = v as i64;
        let sign = if v < 0 { "-" } else { "" };
        let m = v.unsigned_abs();
        format!("{sign}{}.{:04}", m / 10_000, m % 10_000)
    }

    #[test]
    fn coordinates_round_as_f64_round_does() {
        // Halves, the largest double below a half, both signs, large and non-finite values.
        let mut xs = vec![
            0.00005,
            -0.00005,
            0.000049999999999999996,
            0.49999999999999994 / 1e4,
            1.23455,
            -1.23455,
            1e10 + 0.00005,
            99_999_999_999.999_95,
            1e11,
            -1e11,
            1e300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
        ];
        // Pseudo-random values of every scale (a fixed sequence: the test is repeatable).
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..200_000 {
            let unit = crate::base::testing::random(&mut state);
            let scale = 10f64.powi((state % 14) as i32 - 5);
            let x = (unit - 0.5) * scale;
            xs.extend([x, (x * 1e4).round() / 1e4, ((x * 1e4).floor() + 0.5) / 1e4]);
        }
        for x in xs {
            assert_eq!(coord(x), formatted(x), "{x:e}");
        }
    }
}
