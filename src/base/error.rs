//! User-facing errors. Everything a user can cause (a bad file, a bad setting, a part too thin
//! to print) is an [`Error`] with a message that says what is wrong and what to do. Bugs are
//! reported as [`Error::Internal`].

use std::fmt;

#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// The file could not be read as a model (STL, OBJ or 3MF).
    Import(String),
    /// A setting is unknown or out of range.
    Setting { name: String, message: String },
    /// A build job (its file, its parts or their arrangement on the plate) is not valid; the
    /// message names the part (`parts[2].scale_x: …`).
    Job(String),
    /// The mesh was read but there is nothing a droplet printer could print.
    NothingToPrint(String),
    /// Reading or writing a file failed.
    Io(String),
    /// The void analysis was not made (a layer too large to analyse in bounded memory); the
    /// slice itself is not affected.
    Analysis(String),
    /// A bug in dropslice.
    Internal(String),
}

impl Error {
    /// A refused setting: its name and what to do.
    pub fn setting(name: &str, message: String) -> Error {
        Error::Setting {
            name: name.into(),
            message,
        }
    }

    /// A short machine-readable tag: "import", "setting", "job", "nothing_to_print", "io",
    /// "analysis", "internal".
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Import(_) => "import",
            Error::Setting { .. } => "setting",
            Error::Job(_) => "job",
            Error::NothingToPrint(_) => "nothing_to_print",
            Error::Io(_) => "io",
            Error::Analysis(_) => "analysis",
            Error::Internal(_) => "internal",
        }
    }
}

/// An [`Error`] as the page receives it: `{kind, message, setting?}` (`setting` names the
/// setting of an [`Error::Setting`]).
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ErrorReport {
    /// [`Error::kind`].
    pub kind: &'static str,
    /// The whole sentence shown to the user (the error's `Display`).
    pub message: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub setting: Option<String>,
}

impl Error {
    /// The error as the page receives it.
    pub fn report(&self) -> ErrorReport {
        ErrorReport {
            kind: self.kind(),
            message: self.to_string(),
            setting: match self {
                Error::Setting { name, .. } if !name.is_empty() => Some(name.clone()),
                _ => None,
            },
        }
    }
}

/// Most characters of input a message quotes ([`quote`]).
pub const QUOTE_CHARS: usize = 80;

/// Most characters of a whole message ([`Error`]'s `Display`): a last bound for messages that
/// hold several quotes or lists, far above any message written for people.
pub const MAX_MESSAGE_CHARS: usize = 2000;

/// `text` as a message quotes it: at most [`QUOTE_CHARS`] characters (then "…"), control
/// characters (line breaks, tabs, vertical tabs …) shown as spaces, so that a message stays
/// one short line whatever the input holds.
pub fn quote(text: &str) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == QUOTE_CHARS {
            out.push('…');
            break;
        }
        out.push(if c.is_control() { ' ' } else { c });
    }
    out
}

/// A number from the input as a message shows it: as Rust prints it (`0.2`, `45`, `-3.5`)
/// unless that is long, then in exponent form (`1e308`, not 309 digits; `1e-300`).
pub fn number(x: f64) -> String {
    let s = format!("{x}");
    if s.len() > 24 { format!("{x:e}") } else { s }
}

/// A number as a message shows it when it need not be exact (a size, an area, a derived
/// figure): three significant digits, never more than a dozen characters — `0.208`, `1000`,
/// `2.35e-7`, `5e-324`, `1.8e308` —, whatever the number (a tiny or huge input gives no
/// 300-digit figure).
pub fn rounded(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        // "NaN", "inf", "-inf"; 0 and −0 as "0".
        return if x == 0.0 { "0".into() } else { format!("{x}") };
    }
    let a = x.abs();
    if (1e-3..1e9).contains(&a) {
        // Digits after the point for three significant ones; an integer part is kept whole.
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        trim_zeros(format!("{x:.digits$}"))
    } else {
        let s = format!("{x:.2e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{exponent}", trim_zeros(mantissa.to_string()))
    }
}

/// `1.500` → `1.5`, `2.00` → `2`; a number without a point as it is.
fn trim_zeros(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A message cut to at most [`MAX_MESSAGE_CHARS`] characters.
pub fn clamp_message(s: &str) -> std::borrow::Cow<'_, str> {
    clamp(s, MAX_MESSAGE_CHARS)
}

/// `s` cut to at most `max` characters (then "…").
fn clamp(s: &str, max: usize) -> std::borrow::Cow<'_, str> {
    match s.char_indices().nth(max) {
        Some((at, _)) => format!("{}…", &s[..at]).into(),
        None => s.into(),
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let whole = self.unbounded();
        f.write_str(&clamp(&whole, MAX_MESSAGE_CHARS))
    }
}

impl Error {
    /// The message before [`MAX_MESSAGE_CHARS`] is applied.
    fn unbounded(&self) -> String {
        struct Whole<'a>(&'a Error);
        impl fmt::Display for Whole<'_> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                self.0.write_unbounded(f)
            }
        }
        Whole(self).to_string()
    }

    fn write_unbounded(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Import(m) => write!(f, "cannot read the model file: {m}"),
            Error::Setting { name, message } if name.is_empty() => {
                write!(f, "bad settings: {message}")
            }
            Error::Setting { name, message } => write!(f, "bad setting {name}: {message}"),
            Error::Job(m) => write!(f, "bad job: {m}"),
            Error::NothingToPrint(m) => write!(f, "nothing to print: {m}"),
            Error::Io(m) => write!(f, "{m}"),
            Error::Analysis(m) => write!(f, "no void analysis: {m}"),
            Error::Internal(m) => write!(
                f,
                "internal error (a bug in dropslice, please report it): {m}"
            ),
        }
    }
}

impl std::error::Error for Error {}

/// Defines an error that is one message (what is wrong and what to do, shown as it is): a
/// `pub struct $name(pub String)` whose `Display` is the message. The `.gco` reader's
/// [`crate::output::gcode_read::GcodeError`] and [`crate::output::calibrate::CalibrationError`] are such
/// errors: two types, so that a signature says which step refused.
macro_rules! message_error {
    ($(#[$attr:meta])* $name:ident) => {
        $(#[$attr])*
        #[derive(Clone, Debug, PartialEq, Eq)]
        pub struct $name(pub String);

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(&$crate::base::error::clamp_message(&self.0))
            }
        }

        impl std::error::Error for $name {}
    };
}
pub(crate) use message_error;

/// `n` with thousands separators.
pub fn grouped(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_and_numbers_are_short() {
        assert_eq!(quote("abc"), "abc");
        assert_eq!(quote("a\u{b}b\nc"), "a b c");
        let q = quote(&"9".repeat(15_000_000));
        assert_eq!(q.chars().count(), QUOTE_CHARS + 1);
        assert!(q.ends_with('…'));
        assert_eq!(number(1e308), "1e308");
        assert_eq!(number(-1e300), "-1e300");
        assert_eq!(number(1e-300), "1e-300");
        assert_eq!(number(0.2), "0.2");
        assert_eq!(number(45.0), "45");
        assert_eq!(number(0.1 + 0.2), "0.30000000000000004");
        assert_eq!(number(1000001.0), "1000001");
        let long = Error::Import("x".repeat(5 * MAX_MESSAGE_CHARS));
        let shown = long.to_string();
        assert_eq!(shown.chars().count(), MAX_MESSAGE_CHARS + 1);
        assert_eq!(long.report().message, shown);
    }

    #[test]
    fn rounded_numbers_have_three_significant_digits() {
        for (x, want) in [
            (0.208, "0.208"),
            (0.2083333, "0.208"),
            (1000.0, "1000"),
            (123456.7, "123457"),
            (2.5, "2.5"),
            (-3.25159, "-3.25"),
            (0.0, "0"),
            (-0.0, "0"),
            (1e-300, "1e-300"),
            (5e-324, "4.94e-324"),
            (2.35e-7, "2.35e-7"),
            (f64::MAX, "1.8e308"),
            (1e9, "1e9"),
            (0.001, "0.001"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(rounded(x), want, "{x:e}");
        }
        // Never long, whatever the number.
        for x in [1e-310, 3.7e-200, 1.23456789e250, -9.87e-15, 7.0 / 3.0] {
            assert!(rounded(x).len() <= 10, "{x:e}: {}", rounded(x));
        }
    }
}
