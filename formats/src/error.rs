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

/// The candidate closest to `word` by edit distance, if it is close enough to be a likely typo:
/// at most `max(2, len / 3)` edits (len in characters), and not a complete rewrite of the word.
pub fn suggest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let len = word.chars().count();
    let limit = (len / 3).max(2);
    let mut best: Option<(usize, &'a str)> = None;
    for candidate in candidates {
        let d = edit_distance(word, candidate);
        // Replacing every character is not a typo ("x" is not a misspelt "up").
        let whole = len.max(candidate.chars().count());
        if d <= limit && d < whole && !matches!(best, Some((b, _)) if b <= d) {
            best = Some((d, candidate));
        }
    }
    best.map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

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
    fn distance_counts_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("fov", "fov"), 0);
        assert_eq!(edit_distance("fvo", "fov"), 2);
    }

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(suggest("Pont", ["Point", "Directional"]), Some("Point"));
        assert_eq!(suggest("radus", ["center", "radius"]), Some("radius"));
        assert_eq!(suggest("glas", ["red", "glass", "floor"]), Some("glass"));
        assert_eq!(suggest("zzzzzz", ["red", "glass"]), None);
        assert_eq!(suggest("x", ["up"]), None);
        // Long words tolerate more edits: 12 / 3 = 4.
        assert_eq!(
            suggest("declmpositio", ["decomposition"]),
            Some("decomposition")
        );
    }
}
