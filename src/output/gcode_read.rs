//! Reading `.gco` back: machine code → layers of droplet centres, roles and travel moves (the
//! page's viewer of existing files; later `dropslice calibrate PART.gco`).
//!
//! `G01` travels, `G25` sets droplets every B on the line from the current position (the first
//! at the current position: [`crate::base::geom::line_droplets`], as the plan counts them), `G26`
//! travels and sets one droplet. B = `layer_height` × `droplet_aspect`, read from the header's
//! `; name = value` lines before the first command. G-code does not say which loop a droplet
//! belongs to: every `G26` droplet counts as a loop droplet (role 0), every `G25` droplet as
//! fill (role 2). A new layer starts where Z changes by more than 1e-6 mm. `T0`/`T1` select
//! the discharge unit of the commands that follow (a file starts with unit 0); every droplet
//! is tagged with its unit ([`ReadLayer::units`]), and unit 1's `G25` lines set droplets every
//! B₁ = `layer_height` × `unit1_droplet_aspect` (default 1.04).
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

use crate::base::error::Error;
use crate::base::error::grouped;
use crate::base::geom::{DVec2, dist, line_droplet_count_f64, line_droplets};
use crate::base::settings::{Settings, schema};
use crate::output::gcode::{FIGURE_LINES, FigureField};
use crate::output::preview::PreviewLayer;
use crate::output::summary::{Figures, Summary};
use crate::slicing::plan::Counts;
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
    /// The discharge unit of each droplet (0 or 1), in the order of `preview.roles` (empty
    /// when [counting](GcodeReader::counting)).
    pub units: Vec<u8>,
}

/// Streaming reader: feed text or lines, take finished layers.
#[derive(Debug, Default)]
pub struct GcodeReader {
    /// The header's `name = value` lines before the first command, in file order.
    pub header: Vec<(String, String)>,
    width: f64,
    /// B₁, unit 1's droplet width.
    width1: f64,
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
    header_counts: [Option<u64>; 5],
    /// The header's figures (`; print time = S s`, …), as read.
    header_figures: Vec<(FigureField, f64)>,
    /// Why the header's figures cannot be used (a line that is not a number ≥ 0, `pending`).
    header_figures_problem: Option<String>,
    /// The command that made the reader refuse the file as another printer's (the first).
    foreign: Option<String>,
}

/// The header's droplet count lines, in the order of [`GcodeReader::header_counts`]: outer,
/// inner, fill, support, unit 1.
const COUNT_LINES: [&str; 5] = [
    "droplets outer loops",
    "droplets inner loops",
    "droplets fill",
    "droplets support",
    "droplets of unit 1",
];

/// A filament (FDM) or CNC command: `M104`, `G1`, `G28`, `G92.1` — a G or M and a number.
fn machine_command(word: &str) -> bool {
    let Some(number) = word.strip_prefix(['G', 'g', 'M', 'm']) else {
        return false;
    };
    let (int, frac) = number.split_once('.').unwrap_or((number, "0"));
    let digits = |t: &str| !t.is_empty() && t.len() <= 5 && t.bytes().all(|b| b.is_ascii_digit());
    digits(int) && digits(frac)
}

/// The message for G-code of another kind of printer with the commands `names`.
fn foreign_message(names: &[String]) -> String {
    format!(
        "this is G-code for another kind of printer (it has {}): dropslice reads the droplet printer's code it writes (G01 travel, G25 droplet line, G26 droplet); open the model (STL, OBJ or 3MF) and slice it instead",
        names.join(", ")
    )
}

/// The distinct foreign commands of a file: `first`, then those of the lines of `ahead` (its
/// first 64 kB): at most four, one that feeds filament (`G1 … E…`) among them when any does.
fn foreign_names(first: &str, ahead: &str) -> Vec<String> {
    let mut end = ahead.len().min(1 << 16);
    while !ahead.is_char_boundary(end) {
        end -= 1;
    }
    let mut names = vec![first.to_string()];
    let mut feeds = first.contains('E').then(|| first.to_string());
    for name in ahead[..end].lines().filter_map(foreign_name) {
        if name.ends_with("E…") && feeds.is_none() {
            feeds = Some(name.clone());
        }
        if names.len() < 4 && !names.contains(&name) {
            names.push(name);
        }
    }
    if let Some(f) = feeds
        && !names.contains(&f)
    {
        if names.len() < 4 {
            names.push(f);
        } else {
            names[3] = f;
        }
    }
    names
}

/// How the foreign commands of a line are named: the command word as written in upper case
/// (`M140`), and `G1 … E…` for a move that feeds filament.
fn foreign_name(line: &str) -> Option<String> {
    let line = line.split(';').next().unwrap_or("").trim();
    let mut words = line.split_whitespace();
    let first = words.next()?;
    if !machine_command(first) {
        return None;
    }
    let first = first.to_ascii_uppercase();
    // A move (G0 … G3) with an E word feeds filament; `G92 E0` only sets the position.
    let moves = matches!(
        first.as_str(),
        "G0" | "G1" | "G2" | "G3" | "G00" | "G02" | "G03"
    );
    let feeds = moves && words.any(|w| w.starts_with(['E', 'e']));
    Some(if feeds {
        format!("{first} … E…")
    } else {
        first
    })
}

/// The header's droplet size must lie within the settings' ranges: (least, greatest, unit).
fn header_range(name: &str) -> Option<(f64, f64, &'static str)> {
    let spec = crate::base::settings::schema().into_iter().find(|s| {
        s.name == name
            && matches!(
                name,
                "layer_height" | "droplet_aspect" | "unit1_droplet_aspect"
            )
    })?;
    Some((spec.min?, spec.max?, spec.unit))
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
            width1: f64::NAN,
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

    /// Reads one line.
    pub fn line(&mut self, raw: &str) -> Result<(), GcodeError> {
        self.line_no += 1;
        let no = self.line_no;
        let line = raw.trim();
        if line.is_empty() {
            return Ok(());
        }
        if let Some(c) = line.strip_prefix(';') {
            return self.comment(c.trim());
        }
        if let Some(n) = line.strip_prefix(['T', 't']) {
            let n = n.split(';').next().unwrap_or("").trim();
            self.unit = match n {
                "0" => 0,
                "1" => 1,
                _ => {
                    return Err(GcodeError(format!(
                        "line {no}: \"{}\" selects a discharge unit this slicer does not have: only T0 and T1 are known",
                        shown(line)
                    )));
                }
            };
            return Ok(());
        }
        let code = line.get(..3).map(str::to_ascii_uppercase);
        let code = match code.as_deref() {
            Some(c @ ("G01" | "G25" | "G26"))
                if !line[3..].starts_with(|c: char| c.is_ascii_digit() || c == '.') =>
            {
                c.to_string()
            }
            _ if let Some(name) = foreign_name(line) => {
                let e = GcodeError(format!(
                    "line {no}: {}",
                    foreign_message(std::slice::from_ref(&name))
                ));
                self.foreign = Some(name);
                return Err(e);
            }
            _ => {
                return Err(GcodeError(format!(
                    "line {no}: \"{}\" is not a G01, G25 or G26 command",
                    line.chars().take(40).collect::<String>()
                )));
            }
        };
        let (mut x, mut y, mut z) = (self.at.x, self.at.y, self.z);
        for word in line[3..].split_whitespace() {
            if word.starts_with(';') {
                break;
            }
            let mut chars = word.chars();
            let letter = chars.next().unwrap_or(' ');
            let number = chars.as_str();
            let v = if number.is_empty() {
                f64::NAN
            } else {
                number.parse::<f64>().unwrap_or(f64::NAN)
            };
            if !v.is_finite() {
                return Err(GcodeError(format!(
                    "line {no}: bad number in \"{}\"",
                    shown(word)
                )));
            }
            if v.abs() > MAX_COORD_MM {
                return Err(GcodeError(format!(
                    "line {no}: the coordinate \"{}\" is too far out: this viewer reads coordinates up to ±{} mm",
                    shown(word),
                    grouped(MAX_COORD_MM as u64)
                )));
            }
            match letter.to_ascii_uppercase() {
                'X' => x = v,
                'Y' => y = v,
                'Z' => z = v,
                // Filament and feed rate: a filament printer's move written as G01.
                'E' | 'F' => {
                    let name = format!("{code} … {}…", letter.to_ascii_uppercase());
                    let e = GcodeError(format!(
                        "line {no}: {}",
                        foreign_message(std::slice::from_ref(&name))
                    ));
                    self.foreign = Some(name);
                    return Err(e);
                }
                _ => {
                    return Err(GcodeError(format!(
                        "line {no}: unknown word \"{}\"",
                        shown(word)
                    )));
                }
            }
        }
        if self.width.is_nan() || self.width <= 0.0 {
            return Err(GcodeError(
                "the header does not give the droplet size (lines '; layer_height = …' and '; droplet_aspect = …' are needed before the first command)".into(),
            ));
        }
        let to = DVec2::new(x, y);
        // What this line adds, checked before anything is stored.
        let len = dist(self.at, to);
        let width = if self.unit == 1 {
            self.width1
        } else {
            self.width
        };
        let too_many = || {
            GcodeError(format!(
                "line {no}: the file holds more than {} droplets, the most this viewer expands; it was not opened",
                count(MAX_DROPLETS as f64)
            ))
        };
        let n: u64 = match code.as_str() {
            "G25" if self.counts_only => {
                // Counted by arithmetic (as `line_droplets` expands), never expanded.
                let n = line_droplet_count_f64(len, width);
                if !n.is_finite() {
                    return Err(GcodeError(format!(
                        "line {no}: a G25 of {} mm with droplets every {} mm has no droplet count",
                        precise(len, 6),
                        precise(width, 4)
                    )));
                }
                n as u64
            }
            "G26" if self.counts_only => 1,
            "G01" if self.counts_only => 0,
            "G25" => {
                let n = line_droplet_count_f64(len, width);
                if n.is_nan() || self.droplets as f64 + n > MAX_DROPLETS as f64 {
                    return Err(if n > MAX_DROPLETS as f64 / 10.0 || !n.is_finite() {
                        GcodeError(format!(
                            "line {no}: a G25 of {} mm would expand to {} droplets (one every {} mm); this viewer expands at most {} droplets per file",
                            precise(len, 6),
                            count(n),
                            precise(width, 4),
                            count(MAX_DROPLETS as f64)
                        ))
                    } else {
                        too_many()
                    });
                }
                n as u64
            }
            "G26" => {
                if self.droplets + 1 > MAX_DROPLETS {
                    return Err(too_many());
                }
                1
            }
            _ => {
                self.travels += 1;
                if self.travels > MAX_TRAVEL_MOVES {
                    return Err(GcodeError(format!(
                        "line {no}: the file holds more than {} travel moves (G01), the most this viewer shows; it was not opened",
                        count(MAX_TRAVEL_MOVES as f64)
                    )));
                }
                0
            }
        };
        self.droplets = self.droplets.saturating_add(n);
        self.commands += 1;
        if self.layer.as_ref().is_none_or(|l| (z - l.z).abs() > 1e-6) {
            if self.index + 1 >= MAX_LAYERS && self.layer.is_some() {
                return Err(GcodeError(format!(
                    "line {no}: the file has more than {} layers (heights), the most this viewer shows; it was not opened",
                    grouped(MAX_LAYERS as u64)
                )));
            }
            self.flush();
            self.layer = Some(ReadLayer {
                z,
                ..ReadLayer::default()
            });
        }
        let from = self.at;
        let keep = !self.counts_only;
        let l = self.layer.as_mut().expect("a layer is open");
        let p = &mut l.preview;
        match code.as_str() {
            "G01" => {
                if keep {
                    p.travel.extend([from.x, from.y, x, y].map(|v| v as f32));
                }
                l.travel_mm += len;
            }
            "G26" => {
                if to != from {
                    l.travel_mm += len;
                }
                if keep {
                    p.droplets.extend([x as f32, y as f32]);
                    p.roles.push(0);
                }
                l.counts.outer += 1;
                if keep {
                    l.units.push(self.unit);
                }
            }
            _ => {
                if keep {
                    for d in line_droplets(from, to, width) {
                        p.droplets.extend([d.x as f32, d.y as f32]);
                        p.roles.push(2);
                    }
                }
                l.counts.fill = l.counts.fill.saturating_add(n);
                if keep {
                    l.units.extend(std::iter::repeat_n(self.unit, n as usize));
                }
            }
        }
        if self.unit == 1 {
            l.counts.unit1 = l.counts.unit1.saturating_add(n);
        }
        (self.at, self.z) = (to, z);
        Ok(())
    }

    fn comment(&mut self, text: &str) -> Result<(), GcodeError> {
        if self.commands > 0 {
            return Ok(());
        }
        // The header's droplet counts and figures (`pending` in a header never filled in).
        if let Some((label, value)) = text.split_once('=') {
            let (label, value) = (label.trim(), value.split_whitespace().next().unwrap_or(""));
            if label == "droplets total" {
                self.header_droplets = value.parse::<u64>().ok();
                return Ok(());
            }
            if let Some(i) = COUNT_LINES.iter().position(|l| *l == label) {
                self.header_counts[i] = value.parse::<u64>().ok();
                return Ok(());
            }
            if let Some((_, field, _, _)) = FIGURE_LINES.iter().find(|l| l.0 == label) {
                match value.parse::<f64>() {
                    Ok(v) if v.is_finite() && v >= 0.0 => {
                        self.header_figures.retain(|(f, _)| f != field);
                        self.header_figures.push((*field, v));
                    }
                    _ if value == "pending" => {
                        self.header_figures_problem = Some(
                            "the header's figures were never filled in (the code was not finished)"
                                .into(),
                        );
                    }
                    _ => {
                        self.header_figures_problem = Some(format!(
                            "the header's {label} \"{}\" (line {}) is not a number ≥ 0",
                            shown(value),
                            self.line_no
                        ));
                    }
                }
                return Ok(());
            }
        }
        // `name = value`: a lower-case name, then the value's first word.
        let name_len = text
            .bytes()
            .enumerate()
            .take_while(|(i, b)| {
                b.is_ascii_lowercase() || *b == b'_' || (*i > 0 && b.is_ascii_digit())
            })
            .count();
        if name_len == 0 {
            return Ok(());
        }
        let (name, after) = text.split_at(name_len);
        let Some(after) = after.trim_start().strip_prefix('=') else {
            return Ok(());
        };
        let Some(value) = after.split_whitespace().next() else {
            return Ok(());
        };
        if let Some((min, max, unit)) = header_range(name) {
            // The droplet size decides how many droplets a G25 line holds: only the core's range.
            let v: f64 = value.parse().unwrap_or(f64::NAN);
            if v.is_nan() || v < min || v > max {
                let unit = if unit.is_empty() {
                    String::new()
                } else {
                    format!(" {unit}")
                };
                return Err(GcodeError(format!(
                    "line {}: the header's {name} = {} is out of range: it must be at least {min} and at most {max}{unit}",
                    self.line_no,
                    shown(value)
                )));
            }
        }
        match self.header.iter_mut().find(|(n, _)| n == name) {
            Some(entry) => entry.1 = value.to_string(),
            None => self.header.push((name.to_string(), value.to_string())),
        }
        let num = |n: &str| {
            self.header_value(n)
                .map(|v| v.parse::<f64>().unwrap_or(f64::NAN))
        };
        let h = num("layer_height").unwrap_or(f64::NAN);
        let a = num("droplet_aspect").unwrap_or(1.04);
        let a1 = num("unit1_droplet_aspect").unwrap_or(1.04);
        if h > 0.0 && a > 0.0 {
            self.width = h * a;
        }
        if h > 0.0 && a1 > 0.0 {
            self.width1 = h * a1;
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

impl GcodeReader {
    /// The settings of the header's `name = value` lines that name a setting (the others
    /// take their defaults), checked as `--set` values are. A header without `layer_height`
    /// is not a dropslice code: refused.
    pub fn header_settings(&self) -> Result<Settings, Error> {
        if self.header_value("layer_height").is_none() {
            return Err(Error::Setting {
                name: String::new(),
                message: "the code's header gives no layer_height: it is not a dropslice code, so its time and material are unknown".into(),
            });
        }
        let known = schema();
        let mut settings = Settings::default();
        for (name, value) in &self.header {
            if known.iter().any(|s| s.name == name) {
                settings.set(name, value)?;
            }
        }
        settings.validate()?;
        Ok(settings)
    }

    /// The header's settings as typed values (`{"droplet_aspect": 1.3, …}`), only those its
    /// lines name, checked as [`header_settings`](Self::header_settings) checks them: what the
    /// page's form shows for an opened code.
    pub fn header_setting_values(
        &self,
    ) -> Result<serde_json::Map<String, serde_json::Value>, Error> {
        let settings = self.header_settings()?;
        let all = serde_json::to_value(&settings)
            .map_err(|e| Error::Internal(format!("the settings do not serialize: {e}")))?;
        Ok(self
            .header
            .iter()
            .filter_map(|(name, _)| Some((name.clone(), all.get(name)?.clone())))
            .collect())
    }

    /// The figures of the file: the header's own (the slice's, exactly) when it has them all
    /// and they agree with the commands, else those of the layers read so far with the
    /// header's settings ([`header_settings`](Self::header_settings)) — then
    /// [`figures_note`](Self::figures_note) says why.
    pub fn figures(&self) -> Result<Figures, Error> {
        let settings = self.header_settings()?;
        let Ok(counts) = self.header_counts() else {
            return Ok(self.totals.figures(&settings));
        };
        let travel = self
            .header_figures
            .iter()
            .find(|(f, _)| *f == FigureField::Travel)
            .map_or(self.totals.travel_mm, |(_, v)| *v);
        let mut f = Summary {
            layers: self.totals.layers,
            counts,
            travel_mm: travel,
            ..Summary::default()
        }
        .figures(&settings);
        for (field, v) in &self.header_figures {
            field.set(&mut f, *v);
        }
        Ok(f)
    }

    /// Why [`figures`](Self::figures) are computed from the commands rather than read from
    /// the header (`None`: they are the header's).
    pub fn figures_note(&self) -> Option<String> {
        self.header_counts().err()
    }

    /// The header's droplet counts when its figures can be used: every count and figure line
    /// of its kind (one unit or two) there, each a number ≥ 0, the counts adding up to its
    /// total and that total (and unit 1's) the commands' own.
    fn header_counts(&self) -> Result<Counts, String> {
        if let Some(p) = &self.header_figures_problem {
            return Err(p.clone());
        }
        if self.header_figures.is_empty() {
            return Err(
                "the header has no figures (a code of an earlier dropslice, or of another program)"
                    .into(),
            );
        }
        let [outer, inner, fill, support, unit1] = self.header_counts;
        let (Some(outer), Some(inner), Some(fill), Some(total)) =
            (outer, inner, fill, self.header_droplets)
        else {
            return Err("the header's droplet counts are missing".into());
        };
        let two = unit1.is_some();
        let counts = Counts {
            outer,
            inner,
            fill,
            support: support.unwrap_or(0),
            unit1: unit1.unwrap_or(0),
        };
        let sum = [inner, fill, counts.support]
            .into_iter()
            .try_fold(outer, u64::checked_add);
        if sum != Some(total) || counts.unit1 > total {
            return Err("the header's droplet counts do not add up to its total".into());
        }
        let read = &self.totals.counts;
        if read.total() != total || read.unit1 != counts.unit1 {
            return Err(format!(
                "the header's droplets ({} in all, {} of unit 1) are not those of the commands ({}, {}): the code was changed after slicing",
                grouped(total),
                grouped(counts.unit1),
                grouped(read.total()),
                grouped(read.unit1)
            ));
        }
        for (label, field, _, only) in FIGURE_LINES {
            if only.is_some_and(|o| o != two) {
                continue;
            }
            if !self.header_figures.iter().any(|(f, _)| *f == field) {
                return Err(format!("the header has no {label}"));
            }
        }
        Ok(counts)
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
                ..Counts::default()
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
        assert_eq!(layers[0].counts.unit1, 4);
        assert_eq!(layers[0].counts.total(), 10);
        let err = read_gcode(&format!("{head}T2\nG26 X0 Y0 Z0.2\n"))
            .unwrap_err()
            .0;
        assert_eq!(
            err,
            "line 4: \"T2\" selects a discharge unit this slicer does not have: only T0 and T1 are known"
        );
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
