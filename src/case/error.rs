//! Scene errors: defined in [`crate::error::scene`] (below every module, so that the
//! project's [`crate::error::Error`] can carry them) and re-exported here.
pub use crate::error::scene::{SceneError, SceneErrorKind};
