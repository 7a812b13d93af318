//! The header of a `.gco`: its `; name = value` lines (the settings the code was sliced with,
//! the droplet size they give), its droplet counts and figures, and the figures of the file
//! ([`GcodeReader::figures`]): the header's own when they agree with the commands, else
//! computed, and why ([`GcodeReader::figures_note`]).

use super::{GcodeError, GcodeReader, shown};
use crate::base::error::Error;
use crate::base::error::grouped;
use crate::base::settings::{MAX_UNITS, Settings, UnitId, schema};
use crate::output::gcode::{FigureField, figure_lines};
use crate::output::summary::{Figures, Summary};
use crate::slicing::plan::Counts;

/// The header's droplet count lines by role, in the order of [`GcodeReader::header_counts`]:
/// outer, inner, fill, support (then `droplets of unit N` for each unit but 0 that prints).
const COUNT_LINES: [&str; 4] = [
    "droplets outer loops",
    "droplets inner loops",
    "droplets fill",
    "droplets support",
];

/// The unit a `droplets of unit N` line counts (1 … [`MAX_UNITS`] − 1).
fn unit_count_line(label: &str) -> Option<UnitId> {
    let n = label.strip_prefix("droplets of unit ")?;
    let u: u8 = n.parse().ok()?;
    (u > 0 && usize::from(u) < MAX_UNITS && n == u.to_string()).then_some(UnitId(u))
}

/// The header's droplet sizes (`layer_height`, each unit's `…droplet_aspect`) must lie within
/// the settings' ranges: (least, greatest, unit).
fn header_range(name: &str) -> Option<(f64, f64, &'static str)> {
    let aspect = UnitId::all(MAX_UNITS).any(|u| u.name("droplet_aspect") == name);
    if name != "layer_height" && !aspect {
        return None;
    }
    let spec = crate::base::settings::schema()
        .into_iter()
        .find(|s| s.name == name)?;
    Some((spec.domain.min?, spec.domain.max?, spec.domain.unit))
}

impl GcodeReader {
    /// A comment line: before the first command, a header line (`name = value`, a count or a
    /// figure); after it, nothing.
    pub(super) fn comment(&mut self, text: &str) -> Result<(), GcodeError> {
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
            if let Some(u) = unit_count_line(label) {
                self.header_units[u.index()] = value.parse::<u64>().ok();
                return Ok(());
            }
            if let Some(field) = FigureField::of_label(label) {
                match value.parse::<f64>() {
                    Ok(v) if v.is_finite() && v >= 0.0 => {
                        self.header_figures.retain(|(f, _)| *f != field);
                        self.header_figures.push((field, v));
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
        let default = Settings::default();
        let aspects = UnitId::all(MAX_UNITS)
            .map(|u| num(&u.name("droplet_aspect")).unwrap_or(default.unit(u).droplet_aspect));
        let aspects: Vec<f64> = aspects.collect();
        for (w, a) in self.widths.iter_mut().zip(aspects) {
            if h > 0.0 && a > 0.0 {
                *w = h * a;
            }
        }
        if h > 0.0 {
            self.width = self.widths[0];
        }
        Ok(())
    }

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
        let [outer, inner, fill, support] = self.header_counts;
        let (Some(outer), Some(inner), Some(fill), Some(total)) =
            (outer, inner, fill, self.header_droplets)
        else {
            return Err("the header's droplet counts are missing".into());
        };
        let used: Vec<UnitId> = UnitId::all(MAX_UNITS)
            .filter(|u| u.index() == 0 || self.header_units[u.index()].is_some())
            .collect();
        let mut counts = Counts {
            outer,
            inner,
            fill,
            support: support.unwrap_or(0),
            ..Counts::default()
        };
        for u in &used[1..] {
            counts.units[u.index()] = self.header_units[u.index()].unwrap_or(0);
        }
        let sum = [inner, fill, counts.support]
            .into_iter()
            .try_fold(outer, u64::checked_add);
        let others = (counts.units[1..].iter()).try_fold(0u64, |a, &n| a.checked_add(n));
        match (sum, others) {
            (Some(sum), Some(others)) if sum == total && others <= total => {
                counts.units[0] = total - others;
            }
            _ => return Err("the header's droplet counts do not add up to its total".into()),
        }
        let read = &self.totals.counts;
        if read.total() != total || read.units[1..] != counts.units[1..] {
            let of_units = |c: &Counts| -> String {
                (used[1..].iter())
                    .map(|&u| format!(", {} of unit {u}", grouped(c.unit(u))))
                    .collect()
            };
            return Err(format!(
                "the header's droplets ({} in all{}) are not those of the commands ({}{}): the code was changed after slicing",
                grouped(total),
                of_units(&counts),
                grouped(read.total()),
                of_units(read)
            ));
        }
        for (label, field, _) in figure_lines(&used) {
            if !self.header_figures.iter().any(|(f, _)| *f == field) {
                return Err(format!("the header has no {label}"));
            }
        }
        Ok(counts)
    }
}
