//! Reading scene files within limits: the options of a load, where RON scene files come from
//! (the disk, or memory for tests and fuzzing), and the SDK's checked file reading
//! (`luxon_plugin::files`: regular files only, checked by type before opening; size and line
//! caps; one UTF-8 byte-order mark skipped; UTF-16 and binary data refused) as scene errors.

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

pub use luxon_plugin::files::FileError;

use crate::error::SceneError;
use crate::origin::Origin;

/// Limits of one load. Formats knows no memory budget: the caller (the core, from its budget)
/// sets these limits and says in `limit` what set them, for the messages.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Bytes of RON scene text one load may read: the main file and all its includes
    /// together. Parsing RON takes about 12 bytes of memory per byte of text (a 654 MB scene
    /// peaks at 7.9 GB), so this bounds the memory of a load whatever the files claim to be.
    /// Default: 1 GiB, above the largest scene Luxon generates (`luxon spd teapot --size 200`
    /// writes 654 MB of RON). NFF and OBJ files are streamed and have no such cap: their
    /// memory is that of the geometry they hold (`max_geometry`).
    pub max_scene_bytes: u64,
    /// Bytes of geometry the importers may hold: what NFF files and OBJ files (whole scenes
    /// or a RON scene's `meshes:`) are read into, counted as they are read (NFF) or estimated
    /// before they are (OBJ, from its statements). Default: no limit.
    pub max_geometry: u64,
    /// What sets these limits, ending the message of an import over `max_geometry` ("the
    /// memory budget is 64 MiB (from --memory); raise it with --memory").
    pub limit: String,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            max_scene_bytes: 1 << 30,
            max_geometry: u64::MAX,
            limit: "the load has no memory limit".into(),
        }
    }
}

impl LoadOptions {
    /// The error for importing `path` when `what` (e.g. "its 2000000 spheres up to line
    /// 2000010") needs `needs` bytes, more than `max_geometry`.
    pub(crate) fn over_geometry(&self, path: &Path, what: &str, needs: u64) -> SceneError {
        SceneError::File {
            path: path.to_path_buf(),
            message: format!(
                "cannot import `{}`: {what} need {}, more than the {} left for imported geometry; {}",
                path.display(),
                luxon_plugin::files::bytes(needs),
                luxon_plugin::files::bytes(self.max_geometry),
                self.limit
            ),
        }
    }
}

/// The longest line the NFF reader takes. NFF lines hold a keyword and at most eight
/// numbers (a comment may be longer): this only stops a file without line ends (a sparse
/// file, a device) from being collected as one line.
pub(crate) const NFF_MAX_LINE: u64 = 1 << 20;
/// The longest line the OBJ and MTL readers take: an OBJ face lists all its corners on one
/// line, and a face of a million corners takes about 16 MB.
pub(crate) const OBJ_MAX_LINE: u64 = 16 << 20;
/// The largest MTL material library read (it is read whole): thousands of times the size of
/// any real one.
pub(crate) const MTL_MAX_BYTES: u64 = 64 << 20;

/// Where RON scene files come from: the disk, or memory (tests, fuzzing).
pub trait Source {
    /// The identity of a file, for include cycles and repeats (the canonical path on disk).
    fn key(&self, path: &Path) -> PathBuf;
    /// The text of a file of at most `max` bytes, without a byte-order mark.
    fn read(&mut self, path: &Path, max: u64) -> Result<String, FileError>;
}

/// Scene files on disk: regular files only (see `luxon_plugin::files`).
#[derive(Clone, Copy, Debug, Default)]
pub struct DiskSource;

impl Source for DiskSource {
    fn key(&self, path: &Path) -> PathBuf {
        std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
    }

    fn read(&mut self, path: &Path, max: u64) -> Result<String, FileError> {
        luxon_plugin::files::read_text(path, max)
    }
}

/// Scene files held in memory, by path (`.` and `..` resolved by name), counting reads.
#[derive(Clone, Debug, Default)]
pub struct MemorySource {
    files: HashMap<PathBuf, Vec<u8>>,
    reads: HashMap<PathBuf, usize>,
}

impl MemorySource {
    pub fn new() -> MemorySource {
        MemorySource::default()
    }

    /// Adds (or replaces) a file.
    pub fn insert(&mut self, path: impl AsRef<Path>, bytes: impl Into<Vec<u8>>) {
        let key = self.key(path.as_ref());
        self.files.insert(key, bytes.into());
    }

    /// How often the file at `path` was read.
    pub fn reads(&self, path: impl AsRef<Path>) -> usize {
        let key = self.key(path.as_ref());
        self.reads.get(&key).copied().unwrap_or(0)
    }

    /// Reads of all files together.
    pub fn total_reads(&self) -> usize {
        self.reads.values().sum()
    }
}

impl Source for MemorySource {
    fn key(&self, path: &Path) -> PathBuf {
        let mut out = PathBuf::new();
        for c in path.components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir => {
                    if !out.pop() {
                        out.push("..");
                    }
                }
                c => out.push(c),
            }
        }
        out
    }

    fn read(&mut self, path: &Path, max: u64) -> Result<String, FileError> {
        let key = self.key(path);
        let bytes = self.files.get(&key).ok_or(FileError::Missing)?;
        *self.reads.entry(key).or_default() += 1;
        if bytes.len() as u64 > max {
            return Err(FileError::TooLarge {
                size: bytes.len() as u64,
                max,
            });
        }
        luxon_plugin::files::text(bytes.clone())
    }
}

/// A scene file that could not be read, as an error naming it: at the line and column of a
/// problem in its text, else about the whole file. `what` names what it should have been
/// ("a scene file").
pub(crate) fn file_error(e: FileError, path: &Path, what: &str) -> SceneError {
    let message = e.sentence(path, what);
    match e.position() {
        Some((line, col)) => SceneError::At {
            at: Origin {
                file: Arc::new(path.to_path_buf()),
                line: u32::try_from(line).unwrap_or(u32::MAX),
                col: u32::try_from(col).unwrap_or(u32::MAX),
            },
            message,
        },
        None => SceneError::File {
            path: path.to_path_buf(),
            message,
        },
    }
}
