//! One line of a `.gco`: a `T0`/`T1` unit selection, a header comment, or a `G01`/`G25`/`G26`
//! command, its words checked against the bounds ([`super::MAX_COORD_MM`], …) before anything
//! is stored, then its droplets and travel added to the open layer.

use super::foreign::{foreign_message, foreign_name};
use super::{
    GcodeError, GcodeReader, MAX_COORD_MM, MAX_DROPLETS, MAX_LAYERS, MAX_TRAVEL_MOVES, ReadLayer,
    count, precise, shown,
};
use crate::base::error::grouped;
use crate::base::geom::{DVec2, dist, line_droplet_count_f64, line_droplets};
use crate::base::settings::MAX_UNITS;

impl GcodeReader {
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
            return self.select_unit(no, line, n);
        }
        let code = self.command_code(no, line)?;
        let (x, y, z) = self.coordinates(no, line, &code)?;
        if self.width.is_nan() || self.width <= 0.0 {
            return Err(GcodeError(
                "the header does not give the droplet size (lines '; layer_height = …' and '; droplet_aspect = …' are needed before the first command)".into(),
            ));
        }
        let to = DVec2::new(x, y);
        // What this line adds, checked before anything is stored.
        let len = dist(self.at, to);
        let width = if self.unit == 0 {
            self.width
        } else {
            self.widths[usize::from(self.unit)]
        };
        let n = self.droplets_of(no, &code, len, width)?;
        self.droplets = self.droplets.saturating_add(n);
        self.commands += 1;
        self.open_layer(no, z)?;
        self.record(&code, to, len, width, n);
        (self.at, self.z) = (to, z);
        Ok(())
    }

    /// `T0` … `T3` (`n`: what follows the `T`): the discharge unit of the commands that
    /// follow.
    fn select_unit(&mut self, no: usize, line: &str, n: &str) -> Result<(), GcodeError> {
        let n = n.split(';').next().unwrap_or("").trim();
        self.unit = match n.parse::<u8>() {
            Ok(u) if usize::from(u) < MAX_UNITS && n == u.to_string() => u,
            _ => {
                return Err(GcodeError(format!(
                    "line {no}: \"{}\" selects a discharge unit this slicer does not have: only T0 … T{} are known",
                    shown(line),
                    MAX_UNITS - 1
                )));
            }
        };
        Ok(())
    }

    /// The line's command in upper case (`G01`, `G25` or `G26`); another printer's command
    /// is refused as such (and kept in `foreign`), anything else as unknown.
    fn command_code(&mut self, no: usize, line: &str) -> Result<String, GcodeError> {
        let code = line.get(..3).map(str::to_ascii_uppercase);
        match code.as_deref() {
            Some(c @ ("G01" | "G25" | "G26"))
                if !line[3..].starts_with(|c: char| c.is_ascii_digit() || c == '.') =>
            {
                Ok(c.to_string())
            }
            _ if let Some(name) = foreign_name(line) => Err(self.foreign_refusal(no, name)),
            _ => Err(GcodeError(format!(
                "line {no}: \"{}\" is not a G01, G25 or G26 command",
                line.chars().take(40).collect::<String>()
            ))),
        }
    }

    /// The refusal of a line holding another printer's command `name` (kept in `foreign`,
    /// so that [`feed`](Self::feed) names the file's other such commands).
    fn foreign_refusal(&mut self, no: usize, name: String) -> GcodeError {
        let e = GcodeError(format!(
            "line {no}: {}",
            foreign_message(std::slice::from_ref(&name))
        ));
        self.foreign = Some(name);
        e
    }

    /// The position the command `code` goes to: its `X`, `Y`, `Z` words over the current
    /// position, each a finite number within [`MAX_COORD_MM`].
    fn coordinates(
        &mut self,
        no: usize,
        line: &str,
        code: &str,
    ) -> Result<(f64, f64, f64), GcodeError> {
        let (mut x, mut y, mut z) = (self.at.x, self.at.y, self.z);
        for word in line[3..].split_whitespace() {
            if word.starts_with(';') {
                break;
            }
            let (letter, v) = word_value(no, word)?;
            match letter {
                'X' => x = v,
                'Y' => y = v,
                'Z' => z = v,
                // Filament and feed rate: a filament printer's move written as G01.
                'E' | 'F' => {
                    let name = format!("{code} … {letter}…");
                    return Err(self.foreign_refusal(no, name));
                }
                _ => {
                    return Err(GcodeError(format!(
                        "line {no}: unknown word \"{}\"",
                        shown(word)
                    )));
                }
            }
        }
        Ok((x, y, z))
    }

    /// The droplets the command `code` sets over `len` mm with droplets every `width` mm,
    /// checked against the bounds (a counting reader has none but a finite count).
    fn droplets_of(
        &mut self,
        no: usize,
        code: &str,
        len: f64,
        width: f64,
    ) -> Result<u64, GcodeError> {
        if self.counts_only {
            return counted(no, code, len, width);
        }
        match code {
            "G25" => self.expanded_g25(no, len, width),
            "G26" => {
                if self.droplets + 1 > MAX_DROPLETS {
                    return Err(too_many(no));
                }
                Ok(1)
            }
            _ => {
                self.travels += 1;
                if self.travels > MAX_TRAVEL_MOVES {
                    return Err(GcodeError(format!(
                        "line {no}: the file holds more than {} travel moves (G01), the most this viewer shows; it was not opened",
                        count(MAX_TRAVEL_MOVES as f64)
                    )));
                }
                Ok(0)
            }
        }
    }

    /// The droplets of a `G25` that is to be expanded: within [`MAX_DROPLETS`] with the
    /// droplets so far.
    fn expanded_g25(&self, no: usize, len: f64, width: f64) -> Result<u64, GcodeError> {
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
                too_many(no)
            });
        }
        Ok(n as u64)
    }

    /// Opens a new layer where Z changes by more than 1e-6 mm (closing the open one), within
    /// [`MAX_LAYERS`].
    fn open_layer(&mut self, no: usize, z: f64) -> Result<(), GcodeError> {
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
        Ok(())
    }

    /// Adds the command `code` to the open layer: its travel, its `n` droplets (every `width`
    /// mm to `to`, kept unless counting) by role and unit.
    fn record(&mut self, code: &str, to: DVec2, len: f64, width: f64, n: u64) {
        let from = self.at;
        let keep = !self.counts_only;
        let unit = self.unit;
        let l = self.layer.as_mut().expect("a layer is open");
        let p = &mut l.preview;
        match code {
            "G01" => {
                if keep {
                    p.travel
                        .extend([from.x, from.y, to.x, to.y].map(|v| v as f32));
                }
                l.travel_mm += len;
            }
            "G26" => {
                if to != from {
                    l.travel_mm += len;
                }
                if keep {
                    p.droplets.extend([to.x as f32, to.y as f32]);
                    p.roles.push(0);
                }
                l.counts.outer += 1;
                if keep {
                    l.units.push(unit);
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
                    l.units.extend(std::iter::repeat_n(unit, n as usize));
                }
            }
        }
        let of_unit = &mut l.counts.units[usize::from(unit)];
        *of_unit = of_unit.saturating_add(n);
    }
}

/// A word of a command (`X12.5`): its letter in upper case and its number, a finite number
/// within [`MAX_COORD_MM`].
fn word_value(no: usize, word: &str) -> Result<(char, f64), GcodeError> {
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
    Ok((letter.to_ascii_uppercase(), v))
}

/// The droplets of the command `code` for a counting reader: a `G25`'s counted by arithmetic
/// (as `line_droplets` expands), never expanded; any finite count.
fn counted(no: usize, code: &str, len: f64, width: f64) -> Result<u64, GcodeError> {
    match code {
        "G25" => {
            let n = line_droplet_count_f64(len, width);
            if !n.is_finite() {
                return Err(GcodeError(format!(
                    "line {no}: a G25 of {} mm with droplets every {} mm has no droplet count",
                    precise(len, 6),
                    precise(width, 4)
                )));
            }
            Ok(n as u64)
        }
        "G26" => Ok(1),
        _ => Ok(0),
    }
}

/// The refusal of a line that would take the file over [`MAX_DROPLETS`].
fn too_many(no: usize) -> GcodeError {
    GcodeError(format!(
        "line {no}: the file holds more than {} droplets, the most this viewer expands; it was not opened",
        count(MAX_DROPLETS as f64)
    ))
}
