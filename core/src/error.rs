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
    /// A library call given what it cannot take (an array's size, stride or type, say).
    #[error("{0}")]
    Api(String),
    /// An allocation the system refused, sized by the caller's data.
    #[error("cannot allocate {bytes} bytes for {what}; the system refused")]
    OutOfMemory { what: String, bytes: u128 },
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
    print_line("error", message);
}

/// Prints `luxon: warning: {message}` to stderr, as [`print_error`] does.
pub fn print_warning(message: &str) {
    print_line("warning", message);
}

/// Prints `luxon: {level}: {message}` to stderr, as [`print_error`] does.
pub fn print_line(level: &str, message: &str) {
    use std::io::Write;
    let line = format!("luxon: {level}: {}\n", escape_controls(message));
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}

/// `text` with control characters (C0 but tab, DEL, C1) written as `\u{1b}`. Messages quote
/// file names, scene text and bytes of broken files; a control character among them could
/// move the cursor or recolour the terminal, and a newline would split one message in two.
/// This is the last line of defence: the readers escape what they quote too.
pub fn escape_controls(text: &str) -> std::borrow::Cow<'_, str> {
    let bad = |c: char| c != '\t' && c.is_control();
    if !text.contains(bad) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if bad(c) {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out.into()
}

#[cfg(test)]
mod tests {
    use super::escape_controls;

    #[test]
    fn control_characters_are_escaped_and_the_rest_kept() {
        assert_eq!(
            escape_controls("a.ron:1:2: fine, ünïcödé\tok"),
            "a.ron:1:2: fine, ünïcödé\tok"
        );
        assert_eq!(
            escape_controls("name `\x1b[31mred` and\nmore\r\u{7f}\u{9b}"),
            "name `\\u{1b}[31mred` and\\u{a}more\\u{d}\\u{7f}\\u{9b}"
        );
    }
}
