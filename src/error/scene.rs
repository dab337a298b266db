//! The error type of scene loading: one clear, single-line message per failure. Defined here,
//! below every module, so that [`crate::error::Error`] can carry it; [`crate::case`] re-exports it.
use std::fmt;
use std::io;
use std::path::PathBuf;

/// Why a scene file was rejected. Display gives one message naming the file (when known),
/// the dotted key and what is allowed; the binary prints it and exits non-zero.
#[derive(Debug)]
pub struct SceneError {
    /// The scene file, when the scene came from a file.
    pub file: Option<PathBuf>,
    /// What went wrong.
    pub kind: SceneErrorKind,
}

/// The classes of scene errors.
#[derive(Debug)]
pub enum SceneErrorKind {
    /// The file could not be read.
    Io(io::Error),
    /// The text is not valid TOML.
    Syntax(String),
    /// A key the schema does not know; `path` is dotted, `suggestion` the closest known key.
    UnknownKey {
        /// Dotted path of the offending key.
        path: String,
        /// Closest known key (a sibling, or a dotted path elsewhere in the schema).
        suggestion: Option<String>,
        /// Keys allowed at that place.
        known: Vec<&'static str>,
    },
    /// A required field is absent.
    MissingField {
        /// Dotted path.
        path: String,
        /// What the field is, its unit and range.
        description: String,
    },
    /// A required section (table) is absent.
    MissingSection {
        /// Dotted path.
        path: String,
        /// What the section is for.
        description: String,
    },
    /// A value of the wrong TOML type.
    WrongType {
        /// Dotted path.
        path: String,
        /// The expected type and the field's description.
        expected: String,
        /// The value found, e.g. `the string "1500"`.
        found: String,
    },
    /// A value of the right type outside what is allowed.
    NotAllowed {
        /// Dotted path.
        path: String,
        /// The value as written.
        value: String,
        /// What is allowed, e.g. `must be in (-1, 0.5)`.
        allowed: String,
    },
    /// Fields that are valid alone but inconsistent together.
    Conflict(String),
}

impl SceneError {
    pub(crate) fn new(kind: SceneErrorKind) -> Self {
        SceneError { file: None, kind }
    }

    pub(crate) fn in_file(mut self, file: PathBuf) -> Self {
        self.file = Some(file);
        self
    }
}

impl From<SceneErrorKind> for SceneError {
    fn from(kind: SceneErrorKind) -> Self {
        SceneError::new(kind)
    }
}

impl fmt::Display for SceneErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneErrorKind::Io(e) => write!(f, "{e}"),
            SceneErrorKind::Syntax(m) => write!(f, "invalid TOML: {}", m.trim_end()),
            SceneErrorKind::UnknownKey { path, suggestion, known } => match suggestion {
                Some(s) => write!(f, "unknown key '{path}' (did you mean '{s}'?)"),
                None => write!(f, "unknown key '{path}' (known keys here: {})", known.join(", ")),
            },
            SceneErrorKind::MissingField { path, description } => {
                write!(f, "missing field '{path}' ({description})")
            }
            SceneErrorKind::MissingSection { path, description } => {
                write!(f, "missing section '[{path}]' ({description})")
            }
            SceneErrorKind::WrongType { path, expected, found } => {
                write!(f, "{path} has the wrong type: expected {expected}, found {found}")
            }
            SceneErrorKind::NotAllowed { path, value, allowed } => {
                write!(f, "{path} = {value} is not allowed: {allowed}")
            }
            SceneErrorKind::Conflict(m) => write!(f, "{m}"),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.file, &self.kind) {
            (Some(p), SceneErrorKind::Io(e)) => {
                write!(f, "cannot read scene file '{}': {e}", p.display())
            }
            (None, SceneErrorKind::Io(e)) => write!(f, "cannot read scene file: {e}"),
            (Some(p), k) => write!(f, "{}: {k}", p.display()),
            (None, k) => write!(f, "{k}"),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            SceneErrorKind::Io(e) => Some(e),
            _ => None,
        }
    }
}
