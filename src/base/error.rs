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
    /// A bug in dropslice.
    Internal(String),
}

impl Error {
    /// A short machine-readable tag: "import", "setting", "job", "nothing_to_print", "io", "internal".
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Import(_) => "import",
            Error::Setting { .. } => "setting",
            Error::Job(_) => "job",
            Error::NothingToPrint(_) => "nothing_to_print",
            Error::Io(_) => "io",
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

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Import(m) => write!(f, "cannot read the model file: {m}"),
            Error::Setting { name, message } if name.is_empty() => {
                write!(f, "bad settings: {message}")
            }
            Error::Setting { name, message } => write!(f, "bad setting {name}: {message}"),
            Error::Job(m) => write!(f, "bad job: {m}"),
            Error::NothingToPrint(m) => write!(f, "nothing to print: {m}"),
            Error::Io(m) => write!(f, "{m}"),
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
                f.write_str(&self.0)
            }
        }

        impl std::error::Error for $name {}
    };
}
pub(crate) use message_error;
