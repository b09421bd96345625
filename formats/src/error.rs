//! The error every loader returns (`SceneError`), the warnings a load collects (`Warning`), and
//! the helpers their messages use ("did you mean", user text made safe to print).

use std::borrow::Cow;
use std::path::PathBuf;

use crate::origin::Origin;

/// Why a scene could not be loaded. `At` messages are written to follow `file:line:col: `.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{at}: {message}")]
    At { at: Origin, message: String },
    /// A scene file that cannot be read as one (missing, not a regular file, too large...);
    /// the message names it.
    #[error("{message}")]
    File { path: PathBuf, message: String },
}

impl SceneError {
    /// Where in a scene file the error is, when it is in one.
    pub fn origin(&self) -> Option<&Origin> {
        match self {
            SceneError::Io { .. } | SceneError::File { .. } => None,
            SceneError::At { at, .. } => Some(at),
        }
    }

    pub(crate) fn at(at: Origin, message: impl Into<String>) -> Self {
        SceneError::At {
            at,
            message: message.into(),
        }
    }
}

// The "did you mean" rule, shared with plugin parameters (it lives in the plugin SDK, which
// plugins depend on alone).
pub use luxon_plugin::suggest;

/// A problem that did not stop the load, at the place it concerns (the CLI prints each as
/// `luxon: warning: {warning}`).
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    pub at: Origin,
    pub message: String,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.at, self.message)
    }
}

/// Text from a file, safe to echo in a message: control characters (C0, DEL, C1) are written
/// as escapes (`\u{1b}`), so that bytes of a binary or hostile file cannot drive the terminal,
/// and anything longer than 40 characters is cut, ending in `…`.
pub fn shown(s: &str) -> Cow<'_, str> {
    const MAX: usize = 40;
    if s.chars().nth(MAX).is_none() {
        return printable(s);
    }
    let cut: String = s.chars().take(MAX).collect();
    Cow::Owned(format!("{}…", printable(&cut)))
}

/// `s` with its control characters (C0, DEL, C1) written as escapes (`\u{1b}`).
pub(crate) fn printable(s: &str) -> Cow<'_, str> {
    if !s.chars().any(char::is_control) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if c.is_control() {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// "`a`, `b`, `c`" for messages.
pub(crate) fn quoted_list<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    let names: Vec<String> = names
        .into_iter()
        .map(|n| format!("`{}`", shown(n)))
        .collect();
    names.join(", ")
}

/// "unknown {what} `x`{context}; did you mean `y`? expected one of `a`, `b`".
pub(crate) fn unknown_name<'a>(
    what: &str,
    found: &str,
    context: &str,
    known: impl IntoIterator<Item = &'a str> + Clone,
) -> String {
    let mut message = format!("unknown {what} `{}`{context}", shown(found));
    match suggest(found, known.clone()) {
        Some(close) => message.push_str(&format!("; did you mean `{}`?", shown(close))),
        None => message.push(';'),
    }
    let list = quoted_list(known);
    if list.is_empty() {
        message.push_str(" none are defined");
    } else {
        message.push_str(&format!(" expected one of {list}"));
    }
    message
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shown_escapes_control_characters_and_cuts_long_text() {
        assert_eq!(shown("glass"), "glass");
        assert_eq!(shown("\u{1b}[31m"), "\\u{1b}[31m");
        assert_eq!(shown("a\u{0}b\u{7f}\u{85}é"), "a\\u{0}b\\u{7f}\\u{85}é");
        let long = "x".repeat(50);
        assert_eq!(shown(&long), format!("{}…", "x".repeat(40)));
        assert_eq!(shown(&long[..40]), long[..40]);
    }

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(suggest("Pont", ["Point", "Directional"]), Some("Point"));
        assert_eq!(suggest("glas", ["red", "glass", "floor"]), Some("glass"));
        assert_eq!(suggest("zzzzzz", ["red", "glass"]), None);
        assert_eq!(suggest("x", ["up"]), None);
    }

    #[test]
    fn unknown_names_suggest_and_list() {
        assert_eq!(
            unknown_name("material", "glas", " in object 3", ["red", "glass"]),
            "unknown material `glas` in object 3; did you mean `glass`? expected one of `red`, `glass`"
        );
        assert_eq!(
            unknown_name("texture", "wood", "", []),
            "unknown texture `wood`; none are defined"
        );
    }
}
