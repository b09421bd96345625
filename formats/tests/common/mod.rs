//! Helpers shared by the scene-format tests.

use luxon_formats::SceneError;

/// Asserts that `e` is at the first `needle` on line `line` of the scene `text` (1-based, as
/// messages count) and that its message holds every one of `words`.
#[track_caller]
pub fn assert_error_at(text: &str, e: &SceneError, line: u32, needle: &str, words: &[&str]) {
    let on = text
        .lines()
        .nth(line as usize - 1)
        .expect("the line exists");
    let col = on
        .find(needle)
        .unwrap_or_else(|| panic!("`{needle}` is not on line {line}"))
        + 1;
    let at = e.origin().expect("a position");
    let message = e.to_string();
    assert!(message.starts_with(&format!("{at}: ")), "{message}");
    assert_eq!(
        (at.line, at.col),
        (line, col as u32),
        "wrong position for: {message}"
    );
    for w in words {
        assert!(message.contains(w), "`{w}` missing from: {message}");
    }
}
