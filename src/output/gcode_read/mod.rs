//! Reading `.gco` back: machine code → layers of droplet centres, roles and travel moves (the
//! page's viewer of existing files; later `dropslice calibrate PART.gco`).
//!
//! `G01` travels, `G25` sets droplets every B on the line from the current position (the first
//! at the current position: [`crate::base::geom::line_droplets`], as the plan counts them), `G26`
//! travels and sets one droplet. B = `layer_height` × `droplet_aspect`, read from the header's
//! `; name = value` lines before the first command. G-code does not say which loop a droplet
//! belongs to: every `G26` droplet counts as a loop droplet (role 0), every `G25` droplet as
//! fill (role 2). A new layer starts where Z changes by more than 1e-6 mm. `T0` … `T3` select
//! the discharge unit of the commands that follow (a file starts with unit 0); every droplet
//! is tagged with its unit ([`ReadLayer::units`]), and unit N's `G25` lines set droplets every
//! B_N = `layer_height` × `unitN_droplet_aspect` (default: unit 0's default aspect).
//!
//! A file may come from anyone: the bounds below keep a crafted file from freezing the page or
//! filling its memory, and every refusal names the line and the reason. G-code of another kind
//! of printer (`M140`, `G1 … E…`: a filament printer's) is refused as such, naming the
//! commands found.
//!
//! The figures of a file ([`GcodeReader::figures`]) are the header's own (droplets by role,
//! print time, travel, volume, mass: the very numbers of the slice that wrote it) when it has
//! them, checked (finite, ≥ 0, the droplet total that of the commands); else they are computed
//! from the commands with the header's settings, and [`GcodeReader::figures_note`] says why.

mod foreign;
mod header;
mod line;

use crate::base::error::grouped;
use crate::base::geom::DVec2;
use crate::base::settings::MAX_UNITS;
use crate::output::gcode::FigureField;
use crate::output::preview::PreviewLayer;
use crate::output::summary::Summary;
use crate::slicing::plan::Counts;
use foreign::{foreign_message, foreign_names};
use std::collections::VecDeque;

/// Coordinates beyond ±100 m are refused (no printer is that big; far beyond, the view and
/// the float32 droplet arrays lose all precision).
pub const MAX_COORD_MM: f64 = 1e5;
/// Droplets expanded from one file (G25 lines and G26): 50 million, about 450 MB in the page.
/// Checked before a line is expanded. A [counting](GcodeReader::counting) reader expands
/// nothing and has no such bound (its counts saturate at `u64::MAX`).
pub const MAX_DROPLETS: u64 = 50_000_000;
/// A line longer than this (1 MB) is refused rather than gathered in memory.
pub const MAX_LINE_CHARS: usize = 1 << 20;
/// Travel moves (G01) kept for drawing: 20 million, about 320 MB (not bounded when counting).
pub const MAX_TRAVEL_MOVES: u64 = 20_000_000;
/// Layers (distinct heights): 100,000, e.g. 1 m at 0.01 mm.
pub const MAX_LAYERS: usize = 100_000;

crate::base::error::message_error! {
    /// Why a file was refused.
    GcodeError
}

/// One layer read from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReadLayer {
    /// Layer number from 0, in file order.
    pub index: usize,
    pub z: f64,
    pub counts: Counts,
    /// Length of the moves without material (G01, and G26's way to its droplet), mm.
    pub travel_mm: f64,
    /// Droplet centres, roles and travel moves, as the slicer's preview gives them.
    pub preview: PreviewLayer,
    /// The discharge unit of each droplet (0 … 3), in the order of `preview.roles` (empty
    /// when [counting](GcodeReader::counting)).
    pub units: Vec<u8>,
}

/// Streaming reader: feed text or lines, take finished layers.
#[derive(Debug, Default)]
pub struct GcodeReader {
    /// The header's `name = value` lines before the first command, in file order.
    pub header: Vec<(String, String)>,
    width: f64,
    /// Each unit's droplet width B_u (unit 0's: `width`).
    widths: [f64; MAX_UNITS],
    /// The selected discharge unit.
    unit: u8,
    at: DVec2,
    z: f64,
    layer: Option<ReadLayer>,
    index: usize,
    line_no: usize,
    commands: u64,
    droplets: u64,
    travels: u64,
    rest: String,
    done: VecDeque<ReadLayer>,
    /// The header's `; droplets total = N`, if it has one (not the placeholder `pending`).
    header_droplets: Option<u64>,
    /// Count only: no droplet positions, roles or travel kept (`dropslice calibrate`).
    counts_only: bool,
    /// The layers finished so far: their droplets by role and unit, and travel.
    totals: Summary,
    /// The header's droplet counts (`; droplets outer loops = N`, …), by role; `None` for a
    /// line it does not have or the placeholder `pending`.
    header_counts: [Option<u64>; 4],
    /// The header's `; droplets of unit N = …` (units 1 and on; unit 0's place unused).
    header_units: [Option<u64>; MAX_UNITS],
    /// The header's figures (`; print time = S s`, …), as read.
    header_figures: Vec<(FigureField, f64)>,
    /// Why the header's figures cannot be used (a line that is not a number ≥ 0, `pending`).
    header_figures_problem: Option<String>,
    /// The command that made the reader refuse the file as another printer's (the first).
    foreign: Option<String>,
}

fn shown(word: &str) -> String {
    if word.chars().count() > 40 {
        format!("{}…", word.chars().take(40).collect::<String>())
    } else {
        word.to_string()
    }
}

/// A count for a message: "96 million", "1.2e+300", "12,345".
fn count(n: f64) -> String {
    if !n.is_finite() {
        return "countless".into();
    }
    if n >= 1e15 {
        return js_exponent(format!("{n:.1e}"));
    }
    if n >= 1e7 {
        return format!("{} million", grouped((n / 1e6).round() as u64));
    }
    grouped(n as u64)
}

/// Rust's `1e-7` / `1e21` as JavaScript writes them (`1e-7`, `1e+21`).
fn js_exponent(s: String) -> String {
    match s.split_once('e') {
        Some((m, e)) if !e.starts_with('-') => format!("{m}e+{e}"),
        _ => s,
    }
}

/// `v` to `digits` significant digits, written as JavaScript writes a number.
fn precise(v: f64, digits: usize) -> String {
    let r: f64 = format!("{:.*e}", digits - 1, v).parse().unwrap_or(v);
    if r != 0.0 && (r.abs() < 1e-6 || r.abs() >= 1e21) {
        js_exponent(format!("{r:e}"))
    } else {
        format!("{r}")
    }
}

impl GcodeReader {
    pub fn new() -> GcodeReader {
        GcodeReader {
            width: f64::NAN,
            widths: [f64::NAN; MAX_UNITS],
            ..GcodeReader::default()
        }
    }

    /// A reader that only counts: layers come without droplet positions, roles and travel.
    pub fn counting() -> GcodeReader {
        GcodeReader {
            counts_only: true,
            ..GcodeReader::new()
        }
    }

    /// Droplets the commands set so far (G26 one each, G25 as [`crate::base::geom::line_droplets`]).
    pub fn droplets(&self) -> u64 {
        self.droplets
    }

    /// The header's droplet total (`; droplets total = N`), if it gives one.
    pub fn header_droplets(&self) -> Option<u64> {
        self.header_droplets
    }

    /// Droplet width B from the header (NaN before it is known).
    pub fn droplet_width(&self) -> f64 {
        self.width
    }

    /// Layers finished so far.
    pub fn layers(&self) -> usize {
        self.index
    }

    /// Lines read so far.
    pub fn line_number(&self) -> usize {
        self.line_no
    }

    /// The header's value of `name`.
    pub fn header_value(&self, name: &str) -> Option<&str> {
        self.header
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The next finished layer, if any.
    pub fn take_layer(&mut self) -> Option<ReadLayer> {
        self.done.pop_front()
    }

    /// Reads a piece of the file (any split, lines ending in `\n`).
    pub fn feed(&mut self, text: &str) -> Result<(), GcodeError> {
        let mut text = text;
        while let Some(nl) = text.find('\n') {
            let read = if self.rest.is_empty() {
                self.line(&text[..nl])
            } else {
                let mut line = std::mem::take(&mut self.rest);
                line.push_str(&text[..nl]);
                self.line(&line)
            };
            text = &text[nl + 1..];
            if let (Err(e), Some(first)) = (&read, &self.foreign) {
                // Another printer's code: its first commands named (the rest of this piece).
                let names = foreign_names(first, text);
                let at = e.0.split_once(": ").map_or("", |(l, _)| l);
                return Err(GcodeError(format!("{at}: {}", foreign_message(&names))));
            }
            read?;
        }
        self.rest.push_str(text);
        if self.rest.len() > MAX_LINE_CHARS && self.rest.chars().count() > MAX_LINE_CHARS {
            return Err(GcodeError(format!(
                "line {} is longer than {} characters; this is not a G-code file this viewer reads",
                self.line_no + 1,
                grouped(MAX_LINE_CHARS as u64)
            )));
        }
        Ok(())
    }

    /// Closes the current layer (it becomes available from [`take_layer`](Self::take_layer)).
    pub fn flush(&mut self) {
        if let Some(mut l) = self.layer.take() {
            l.index = self.index;
            self.index += 1;
            self.totals.layers += 1;
            self.totals.counts.add(&l.counts);
            self.totals.travel_mm += l.travel_mm;
            self.done.push_back(l);
        }
    }

    /// After the last piece: reads an unterminated last line and closes the last layer.
    pub fn finish(&mut self) -> Result<(), GcodeError> {
        if !self.rest.is_empty() {
            let rest = std::mem::take(&mut self.rest);
            self.line(&rest)?;
        }
        self.flush();
        if self.commands == 0 {
            return Err(GcodeError("the file holds no G01/G25/G26 commands".into()));
        }
        Ok(())
    }
}

/// Reads a whole file: its layers and its reader (header, droplet width).
pub fn read_gcode(text: &str) -> Result<(Vec<ReadLayer>, GcodeReader), GcodeError> {
    let mut r = GcodeReader::new();
    r.feed(text)?;
    r.finish()?;
    let layers = std::iter::from_fn(|| r.take_layer()).collect();
    Ok((layers, r))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        "; dropslice test\n; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\n; end of header\n";

    #[test]
    fn lines_expand_every_b_and_layers_split_on_z() {
        let b = 0.2 * 1.04;
        let text = format!(
            "{HEADER}G26 X1.0000 Y1.0000 Z0.2000\nG26 X1.2080 Y1.0000 Z0.2000\nG01 X0.0000 Y0.0000 Z0.2000\nG25 X{:.4} Y0.0000 Z0.2000\nG26 X5.0000 Y5.0000 Z0.4000",
            10.0 * b
        );
        let (layers, r) = read_gcode(&text).unwrap();
        assert_eq!(r.droplet_width(), b);
        assert_eq!(layers.len(), 2);
        assert_eq!(
            layers[0].counts,
            Counts {
                outer: 2,
                inner: 0,
                fill: 11,
                support: 0,
                units: [13, 0, 0, 0],
            }
        );
        assert_eq!(layers[0].preview.roles.len(), 13);
        assert!((layers[0].preview.droplets[2 * 12] as f64 - 10.0 * b).abs() < 1e-4);
        assert_eq!(layers[0].preview.travel.len(), 4);
        assert_eq!(layers[1].z, 0.4);
        assert_eq!(layers[1].index, 1);
    }

    #[test]
    fn refusals_name_the_line_and_the_reason() {
        let err = |t: &str| read_gcode(t).unwrap_err().0;
        assert!(err("G26 X1 Y1 Z0.2\n").contains("droplet size"));
        assert!(
            err(&format!("{HEADER}M104 S200\n"))
                .contains("G-code for another kind of printer (it has M104)")
        );
        assert!(err(&format!("{HEADER}G26 X1 Yabc Z0.2\n")).contains("bad number"));
        assert!(err(&format!("{HEADER}G26 X1 Q2 Z0.2\n")).contains("unknown word"));
        assert!(err(HEADER).contains("no G01/G25/G26"));
        assert_eq!(
            err(&format!("{HEADER}G01 X0 Y0 Z0.2\nG25 X20000000\n")),
            "line 6: the coordinate \"X20000000\" is too far out: this viewer reads coordinates up to ±100,000 mm"
        );
        let tiny = err(
            "; layer_height = 0.0001\n; droplet_aspect = 0.001\nG01 X0 Y0 Z0.2\nG25 X100000 Y100000\n",
        );
        assert!(
            tiny.starts_with("line 4: a G25 of 141421 mm would expand to ")
                && tiny.contains(" million droplets (one every 1e-7 mm)"),
            "{tiny}"
        );
        let many = format!(
            "{HEADER}G01 X-100000 Y0 Z0.2\n{}",
            "G25 X100000 Y0\nG25 X-100000 Y0\n".repeat(30)
        );
        assert!(
            err(&many).contains("the file holds more than 50 million droplets"),
            "{}",
            err(&many)
        );
        let long = format!("{HEADER}; {}", "x".repeat(2 << 20));
        assert!(err(&long).contains("is longer than 1,048,576 characters"));
        assert_eq!(
            err("; layer_height = 7\n"),
            "line 1: the header's layer_height = 7 is out of range: it must be at least 0.0001 and at most 5 mm"
        );
    }

    #[test]
    fn t_lines_tag_droplets_with_their_unit() {
        let head = "; layer_height = 0.2\n; droplet_aspect = 1.0\n; unit1_droplet_aspect = 2.0\n";
        let text = format!(
            "{head}G26 X0.0000 Y0.0000 Z0.2000\nT1\nG01 X0.0000 Y0.0000 Z0.2000\nG25 X1.2000 Y0.0000 Z0.2000\nT0\nG25 X2.0000 Y0.0000 Z0.2000\n"
        );
        let (layers, _) = read_gcode(&text).unwrap();
        // Unit 1's line: droplets every 0.4 mm (4); unit 0's: every 0.2 mm (5).
        assert_eq!(layers[0].units, vec![0, 1, 1, 1, 1, 0, 0, 0, 0, 0]);
        assert_eq!(layers[0].counts.units, [6, 4, 0, 0]);
        assert_eq!(layers[0].counts.total(), 10);
        // Unit 3 (the last a machine may have) with the default aspect of its own setting.
        let (layers, _) = read_gcode(&format!("{head}T3\nG25 X1.0400 Y0 Z0.2\n")).unwrap();
        assert_eq!((layers[0].units.len(), layers[0].counts.units[3]), (6, 6));
        for bad in ["T4", "T01", "T-1"] {
            let err = read_gcode(&format!("{head}{bad}\nG26 X0 Y0 Z0.2\n"))
                .unwrap_err()
                .0;
            assert_eq!(
                err,
                format!(
                    "line 4: \"{bad}\" selects a discharge unit this slicer does not have: only T0 … T3 are known"
                )
            );
        }
    }

    /// A filament printer's code (PrusaSlicer, Cura) is named as such, with its first
    /// commands, whatever the header says; so is a G01 that feeds filament.
    #[test]
    fn another_printers_code_is_named_as_such() {
        let err = |t: &str| read_gcode(t).unwrap_err().0;
        let cura = ";FLAVOR:Marlin\n;Generated with Cura_SteamEngine 5.0\nM140 S60\nM105\nM190 S60\nM104 S200\nG28 ;Home\nG92 E0\nG1 Z2.0 F3000\nG1 X10.1 Y20 Z0.28 F5000.0\nG1 X10.1 Y200.0 Z0.28 F1500.0 E15\n";
        assert_eq!(
            err(cura),
            "line 3: this is G-code for another kind of printer (it has M140, M105, M190, G1 … E…): dropslice reads the droplet printer's code it writes (G01 travel, G25 droplet line, G26 droplet); open the model (STL, OBJ or 3MF) and slice it instead"
        );
        // fed line by line (the page's reader may get any split): the first command alone
        let mut r = GcodeReader::new();
        let e = cura.lines().try_for_each(|l| r.line(l)).unwrap_err().0;
        assert!(
            e.starts_with("line 3: this is G-code for another kind of printer (it has M140)"),
            "{e}"
        );
        // a droplet header before it changes nothing
        assert!(
            err(&format!("{HEADER}G90\nM83\n")).starts_with(
                "line 5: this is G-code for another kind of printer (it has G90, M83)"
            )
        );
        assert!(err(&format!("{HEADER}G1 X1 Y2 E0.4\n")).contains("(it has G1 … E…)"));
        assert!(err(&format!("{HEADER}G01 X1 Y2 E0.4\n")).contains("(it has G01 … E…)"));
        assert!(err("G01 X1 Y2 F1200\n").contains("(it has G01 … F…)"));
        assert!(err(&format!("{HEADER}G010 X1\n")).contains("(it has G010)"));
        // not G-code at all: as before
        assert!(
            err(&format!("{HEADER}hello\n")).contains("\"hello\" is not a G01, G25 or G26 command")
        );
        assert!(err(&format!("{HEADER}Gx1\n")).contains("is not a G01, G25 or G26 command"));
    }

    #[test]
    fn numbers_as_javascript_writes_them() {
        assert_eq!(precise(141421.356, 6), "141421");
        assert_eq!(precise(1e-7, 4), "1e-7");
        assert_eq!(precise(0.208, 4), "0.208");
        assert_eq!(count(1.2e300), "1.2e+300");
        assert_eq!(count(96_400_000.0), "96 million");
        assert_eq!(count(12_345.0), "12,345");
    }
}
