//! The error every loader returns (`SceneError`), and the "did you mean" helper its messages use.

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
}

impl SceneError {
    /// Where in a scene file the error is, when it is in one.
    pub fn origin(&self) -> Option<&Origin> {
        match self {
            SceneError::Io { .. } => None,
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

/// "`a`, `b`, `c`" for messages.
pub(crate) fn quoted_list<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    let names: Vec<String> = names.into_iter().map(|n| format!("`{n}`")).collect();
    names.join(", ")
}

/// "unknown {what} `x`{context}; did you mean `y`? expected one of `a`, `b`".
pub(crate) fn unknown_name<'a>(
    what: &str,
    found: &str,
    context: &str,
    known: impl IntoIterator<Item = &'a str> + Clone,
) -> String {
    let mut message = format!("unknown {what} `{found}`{context}");
    match suggest(found, known.clone()) {
        Some(close) => message.push_str(&format!("; did you mean `{close}`?")),
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
