//! Errors of the renderer: values, never panics, each naming where the problem is.

use luxon_formats::{Origin, SceneError};
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A problem at a place in a scene file (plugin errors, unknown names...).
    #[error("{at}: {message}")]
    At { at: Origin, message: String },
    /// A plugin failed outside any scene position (e.g. panicked while rendering).
    #[error("{0}")]
    Plugin(String),
    #[error("{}: {source}", .path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{0}")]
    Render(String),
    #[error("{0}")]
    Usage(String),
}

impl Error {
    pub fn at(at: &Origin, message: impl Into<String>) -> Error {
        Error::At {
            at: at.clone(),
            message: message.into(),
        }
    }
}

/// Prints `luxon: error: {message}` to stderr in a single write. `eprintln!` writes its pieces
/// one by one, and under mpirun, which forwards every rank's stderr and adds messages of its
/// own (its abort banner), a line written in pieces can come out split.
pub fn print_error(message: &str) {
    use std::io::Write;
    let line = format!("luxon: error: {message}\n");
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}
