//! Files appear whole: each is written to a temporary file in the same directory and renamed
//! over the target, so an existing file is never left half-written. Temporary files being
//! written are recorded, so a process that must end at once can remove them first.

use crate::error::Error;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporary file `path` is written to before it is renamed over `path` (same directory,
/// named after the process `pid`); creates missing directories.
pub fn temp_path(path: &Path, pid: u32) -> Result<PathBuf, Error> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    Ok(dir.join(format!(".{name}.{pid}.tmp")))
}

/// Writes `bytes` to `path` atomically (temporary file + rename), creating missing directories.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = temp_path(path, std::process::id())?;
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e));
    }
    Ok(())
}

/// Temporary files being written, removed by [`discard_temp_files`] when the process must end
/// at once.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes the temporary files of unfinished outputs (before an abort that runs no destructor).
pub fn discard_temp_files() {
    if let Ok(files) = PENDING.try_lock() {
        for f in files.iter() {
            let _ = std::fs::remove_file(f);
        }
    }
}

/// Records (`add`) or forgets the temporary file `tmp` for [`discard_temp_files`].
pub fn pending(tmp: &Path, add: bool) {
    let mut files = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    files.retain(|f| f != tmp);
    if add {
        files.push(tmp.to_path_buf());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_and_leaves_no_temp() {
        let dir = std::env::temp_dir().join(format!("luxon-atomic-{}", std::process::id()));
        let p = dir.join("sub").join("x.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let leftovers: Vec<_> = std::fs::read_dir(p.parent().unwrap()).unwrap().collect();
        assert_eq!(leftovers.len(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
