//! The files a scene names: reading text, and finding relative paths.
//!
//! Tachyon opens relative paths (INCLUDE, image maps, volumes, `.tpoly` files) from the working
//! directory, which is why its examples render only when run from their own directory. Luxon
//! looks there first and then in the directory of the file that names the path (VMD runs
//! Tachyon in the scene's directory, so both rules agree on VMD's files).

use std::path::{Path, PathBuf};

/// Reads a text file of at most `max` bytes whole: regular files only (checked by type before opening, as every
/// reader of Luxon does; see `luxon_plugin::files`), a leading UTF-8 byte-order mark skipped.
/// Bytes that are not UTF-8 become U+FFFD (names and paths in Tachyon files are ASCII; this
/// only keeps a stray Latin-1 comment from stopping the load).
///
/// Every file the importer reads goes through here (the scene, INCLUDEs, `.tpoly` files).
pub(super) fn read_text(path: &Path, max: u64) -> std::io::Result<String> {
    use luxon_plugin::files::{read_capped, FileError};
    let bytes = read_capped(path, max).map_err(|e| match e {
        FileError::Io(e) => e,
        FileError::Missing => std::io::ErrorKind::NotFound.into(),
        other => std::io::Error::new(std::io::ErrorKind::InvalidData, other),
    })?;
    let text = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes);
    Ok(String::from_utf8_lossy(text).into_owned())
}

/// Where a path written in a scene is: as it stands when absolute; else in the working
/// directory, else in `dir` (the directory of the file that names it). The result is absolute,
/// so plugins that resolve relative paths against the scene file do not move it. The error
/// names every place looked in.
pub(super) fn find(written: &str, dir: &Path) -> Result<PathBuf, String> {
    let path = Path::new(written);
    if path.is_absolute() {
        return if path.exists() {
            Ok(path.to_path_buf())
        } else {
            Err(format!("`{written}` does not exist"))
        };
    }
    let cwd = std::env::current_dir().unwrap_or_default();
    let here = cwd.join(path);
    if here.exists() {
        return Ok(here);
    }
    let beside = std::path::absolute(dir.join(path)).unwrap_or_else(|_| dir.join(path));
    if beside.exists() {
        return Ok(beside);
    }
    Err(format!(
        "`{written}` was found neither in the working directory ({}) nor beside the scene ({})",
        cwd.display(),
        std::path::absolute(dir)
            .unwrap_or_else(|_| dir.to_path_buf())
            .display()
    ))
}
