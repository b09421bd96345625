//! Errors of the renderer: values, never panics, each naming where the problem is.

use luxon_formats::{Origin, SceneError};
use std::panic::AssertUnwindSafe;
use std::path::PathBuf;
use std::sync::{Arc, RwLock};

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
    /// A caller's buffers that cannot take the image (sizes, strides).
    #[error("{0}")]
    Target(String),
    /// The caller asked the render to stop before it finished.
    #[error("the render was cancelled")]
    Cancelled,
    /// A library call given what it cannot take (an array's size, stride or type, say).
    #[error("{0}")]
    Api(String),
    /// An allocation the system refused, sized by the caller's data.
    #[error("cannot allocate {bytes} bytes for {what}; the system refused")]
    OutOfMemory { what: String, bytes: u128 },
    /// MPI cannot be used as asked (not initialised, finalised, a thread level that forbids
    /// this thread, a handle that is not a communicator).
    #[error("{0}")]
    Mpi(String),
}

impl Error {
    pub fn at(at: &Origin, message: impl Into<String>) -> Error {
        Error::At {
            at: at.clone(),
            message: message.into(),
        }
    }
}

/// How much a log line matters: the plugin ABI's numbering (`HostTable::log`), 0 to 3.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    Error,
    Warning,
    Info,
    Debug,
}

impl Level {
    /// The level of the plugin ABI's number (anything above 3 is debug).
    pub fn from_code(code: u32) -> Level {
        match code {
            0 => Level::Error,
            1 => Level::Warning,
            2 => Level::Info,
            _ => Level::Debug,
        }
    }

    /// `error`, `warning`, `info` or `debug`.
    pub fn name(self) -> &'static str {
        match self {
            Level::Error => "error",
            Level::Warning => "warning",
            Level::Info => "info",
            Level::Debug => "debug",
        }
    }
}

/// Where the library's log lines go: called from any thread, possibly several at once.
pub type LogSink = Box<dyn Fn(Level, &str) + Send + Sync>;

/// The sink as [`log`] holds it: shared, so it is called without holding the lock (a sink may
/// log or replace itself).
type SharedSink = Arc<dyn Fn(Level, &str) + Send + Sync>;

/// The process's sink.
static SINK: RwLock<Option<SharedSink>> = RwLock::new(None);

/// Sends the library's log lines (plugin messages among them) to `sink`; `None` drops them,
/// which is the default: the library prints nothing unless its user asks (the `luxon` command
/// installs a sink that prints to stderr).
pub fn set_log(sink: Option<LogSink>) {
    let sink = sink.map(Arc::from);
    *SINK.write().unwrap_or_else(|e| e.into_inner()) = sink;
}

/// Hands a line to the sink, if one is set. A sink that panics loses that line; the panic goes
/// no further (this is called across the plugin ABI, where unwinding would abort).
pub fn log(level: Level, message: &str) {
    let sink = SINK.read().unwrap_or_else(|e| e.into_inner()).clone();
    if let Some(sink) = sink {
        let _ = std::panic::catch_unwind(AssertUnwindSafe(|| sink(level, message)));
    }
}

/// Prints `luxon: error: {message}` to stderr in a single write: for the `luxon` command (and
/// its MPI abort path) only; the library reports through errors and [`log`]. `eprintln!` writes its pieces
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
