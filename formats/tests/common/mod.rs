//! Helpers shared by the scene-format tests (each test file uses some of them).
#![allow(dead_code)]

use std::ops::Deref;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

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

/// A scratch directory under the system's temporary directory, removed with everything in it
/// when dropped (so a run leaves nothing behind). Each one is new: the process id and a counter
/// keep parallel tests and earlier runs apart.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("luxon-formats-{name}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    /// Writes `bytes` to `name` inside the directory (making its folders) and returns its path.
    pub fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let path = self.0.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, bytes).unwrap();
        path
    }
}

impl Deref for TempDir {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
