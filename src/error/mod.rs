//! The project's error type, [`Error`]: every fallible function of the library and the
//! program returns it (PETSc's safe layer keeps its own [`PetscError`], which converts into
//! it). It sits below every other module (it imports none of them), so each layer may use it.
//!
//! Display is the message the user reads after `ehl-petsc: error: `; the variants say what
//! kind of failure it is. The exit code of a run is chosen by where the failure happened
//! (reading the inputs: 2; the solve: 1; an agreed signal: 128 + its number), see
//! `app::run`.
pub mod petsc;
pub mod scene;

pub use petsc::PetscError;
pub use scene::{SceneError, SceneErrorKind};
use std::path::{Path, PathBuf};

/// `Result` with the project's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// How far a continuation that did not reach the scene got: the continuation's name, the
/// value of its parameter t < 1 where it last converged, and the state there (gathered, in
/// the layout the solver reports states in). A finer mesh can go on from there instead of
/// repeating the path from the start.
#[derive(Debug, Clone)]
pub struct Reached {
    pub parameter: &'static str,
    pub t: f64,
    pub x: Vec<f64>,
}

/// Every failure of the library and the program.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// PETSc, or the safe layer over it, failed.
    #[error(transparent)]
    Petsc(#[from] PetscError),
    /// The scene file (or the scene of an earlier run) was rejected: the message names the
    /// key, its value and what is allowed.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Input outside what is allowed, other than a scene key: the command line, a
    /// convergence study's ladder, a mesh specification, a parameter of a law, plot data.
    #[error("{0}")]
    Invalid(String),
    /// A file or a folder could not be read, written or created.
    #[error("{}: {source}", action.describe(path))]
    Io {
        /// What was being done.
        action: IoAction,
        /// The file or folder.
        path: PathBuf,
        source: std::io::Error,
    },
    /// A file that was read holds something this version cannot use (JSON, CSV, a
    /// summary of another kind of run).
    #[error("{0}")]
    Format(String),
    /// Newton (or a series of solves: a sweep, a convergence study) did not converge.
    /// `reached` is the furthest a continuation got on the way, if any got past its start.
    #[error("{message}")]
    NotConverged { message: String, reached: Option<Box<Reached>> },
    /// Newton did not converge, and on the way its iterates closed the film (H <= 0) at
    /// `closed` (X, Z in units of a, in the order met): where the mesh was too coarse for
    /// the film, or where the model has none (a spin pole; the message says which).
    /// `reached` is the furthest a continuation got on the way, if any got past its start.
    #[error("{message}")]
    FilmClosed { message: String, closed: Vec<[f64; 2]>, reached: Option<Box<Reached>> },
    /// A solve ended with a state that cannot be used (NaN, infinities, an unphysical film)
    /// or a numerical step failed.
    #[error("{0}")]
    Numerical(String),
    /// Every rank stopped on SIGINT or SIGTERM at the same check.
    #[error("{message}")]
    Interrupted {
        /// The signal number (the exit code is 128 + it).
        signal: i32,
        /// Which signal, and during what (see `interrupt::message`).
        message: String,
    },
    /// This rank succeeded but another one failed (see [`crate::collective::agree`]).
    #[error("another MPI rank failed (see its message above)")]
    PeerFailed,
    /// An error and what was being done when it happened: "`context`: `source`".
    #[error("{context}: {source}")]
    Context {
        /// What was being done, e.g. "mesh" or the scene file's name.
        context: String,
        source: Box<Error>,
    },
    /// Anything else (an internal inconsistency).
    #[error("{0}")]
    Other(String),
}

/// What was being done to a file or a folder when an I/O error happened; with its path it
/// gives the message's lead.
#[derive(Debug, Clone, PartialEq)]
pub enum IoAction {
    /// "cannot read PATH"
    Read,
    /// "cannot write PATH"
    Write,
    /// "cannot create PATH"
    Create,
    /// "cannot write plot 'PATH'"
    WritePlot,
    /// "output folder 'PATH' cannot be created"
    CreateOutputFolder,
    /// "output folder 'PATH' is not writable"
    OutputFolderNotWritable,
    /// "cannot move the results from PATH to `to`"
    MoveResults {
        /// The output folder.
        to: PathBuf,
    },
}

impl IoAction {
    /// The message's lead for `path`.
    pub fn describe(&self, path: &Path) -> String {
        let p = path.display();
        match self {
            IoAction::Read => format!("cannot read {p}"),
            IoAction::Write => format!("cannot write {p}"),
            IoAction::Create => format!("cannot create {p}"),
            IoAction::WritePlot => format!("cannot write plot '{p}'"),
            IoAction::CreateOutputFolder => format!("output folder '{p}' cannot be created"),
            IoAction::OutputFolderNotWritable => format!("output folder '{p}' is not writable"),
            IoAction::MoveResults { to } => format!("cannot move the results from {p} to {}", to.display()),
        }
    }
}

impl Error {
    /// [`Error::Invalid`].
    pub fn invalid(message: impl Into<String>) -> Self {
        Error::Invalid(message.into())
    }

    /// [`Error::NotConverged`], with no continuation state.
    pub fn not_converged(message: impl Into<String>) -> Self {
        Error::NotConverged { message: message.into(), reached: None }
    }

    /// The furthest state of a continuation that did not reach the scene, if the failure
    /// carries one.
    pub fn reached(&self) -> Option<&Reached> {
        match self.root() {
            Error::NotConverged { reached, .. } | Error::FilmClosed { reached, .. } => reached.as_deref(),
            _ => None,
        }
    }

    /// [`Error::Format`].
    pub fn format(message: impl Into<String>) -> Self {
        Error::Format(message.into())
    }

    /// [`Error::Numerical`].
    pub fn numerical(message: impl Into<String>) -> Self {
        Error::Numerical(message.into())
    }

    /// [`Error::Other`].
    pub fn other(message: impl Into<String>) -> Self {
        Error::Other(message.into())
    }

    /// For `map_err`: an I/O error of `action` on `path`.
    pub fn io(action: IoAction, path: &Path) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.to_path_buf();
        move |source| Error::Io { action, path, source }
    }

    /// For `map_err`: "cannot read PATH: ...".
    pub fn reading(path: &Path) -> impl FnOnce(std::io::Error) -> Error {
        Error::io(IoAction::Read, path)
    }

    /// For `map_err`: "cannot write PATH: ...".
    pub fn writing(path: &Path) -> impl FnOnce(std::io::Error) -> Error {
        Error::io(IoAction::Write, path)
    }

    /// This error with what was being done: "`context`: `self`".
    pub fn context(self, context: impl Into<String>) -> Error {
        Error::Context { context: context.into(), source: Box::new(self) }
    }

    /// The error under every [`Error::Context`].
    pub fn root(&self) -> &Error {
        match self {
            Error::Context { source, .. } => source.root(),
            e => e,
        }
    }
}

/// [`Error::context`] on a `Result`.
pub trait ResultExt<T> {
    /// The error, if any, with what was being done: "`context`: error".
    fn context(self, context: impl Into<String>) -> Result<T>;
}

impl<T, E: Into<Error>> ResultExt<T> for std::result::Result<T, E> {
    fn context(self, context: impl Into<String>) -> Result<T> {
        self.map_err(|e| e.into().context(context))
    }
}

#[cfg(test)]
mod tests {
    use super::{Error, IoAction, PetscError, ResultExt};
    use std::path::Path;

    #[test]
    fn messages_read_as_before() {
        let io = || std::io::Error::new(std::io::ErrorKind::PermissionDenied, "denied");
        assert_eq!(Error::writing(Path::new("out/a.csv"))(io()).to_string(), "cannot write out/a.csv: denied");
        assert_eq!(Error::io(IoAction::WritePlot, Path::new("p.png"))(io()).to_string(), "cannot write plot 'p.png': denied");
        let to = Path::new("out").to_path_buf();
        assert_eq!(
            Error::io(IoAction::MoveResults { to }, Path::new("out/.partial-1"))(io()).to_string(),
            "cannot move the results from out/.partial-1 to out: denied"
        );
        assert_eq!(Error::from(PetscError { code: 0, message: "m".into() }).to_string(), "m");
        assert_eq!(Error::from(PetscError { code: 73, message: "m".into() }).to_string(), "PETSc error 73: m");
        let e: Result<(), Error> = Err(Error::invalid("bad")).context("mesh");
        let e = e.unwrap_err();
        assert_eq!(e.to_string(), "mesh: bad");
        assert!(matches!(e.root(), Error::Invalid(_)));
    }
}
