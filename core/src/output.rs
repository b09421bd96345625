//! Writing finished images through writer plugins. Every file is written to a temporary file in
//! the same directory and renamed over the target, so an existing file is never left half-written.

use crate::error::Error;
use crate::framebuffer::Framebuffer;
use crate::plugin::calls::encode_image;
use crate::plugin::{Entry, PluginKind, Registry};
use luxon_formats::OutputDesc;
use std::io::Write;
use std::path::{Path, PathBuf};

pub mod stream;

/// An output with its writer resolved.
#[derive(Clone)]
pub struct Output<'r> {
    pub desc: OutputDesc,
    pub writer: &'r Entry,
}

/// Finds the writer of every output (by name, or by the file's extension), before rendering.
pub fn resolve<'r>(
    outputs: &[OutputDesc],
    registry: &'r Registry,
) -> Result<Vec<Output<'r>>, Error> {
    outputs
        .iter()
        .map(|o| {
            let writer = match &o.plugin {
                Some(name) => registry
                    .get(&name.value, PluginKind::Writer)
                    .map_err(|e| Error::at(&name.at, e.to_string()))?,
                None => {
                    let ext = o.path.extension().and_then(|e| e.to_str()).unwrap_or("");
                    registry.writer_for_extension(ext).ok_or_else(|| {
                        let known = registry.writer_extensions();
                        Error::at(
                            &o.params_at,
                            format!(
                                "no writer for `{}`: the file name must end in one of {} (or name a writer with `plugin:`)",
                                o.path.display(),
                                if known.is_empty() {
                                    "(no writer plugins found)".to_string()
                                } else {
                                    known.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(", ")
                                }
                            ),
                        )
                    })?
                }
            };
            Ok(Output {
                desc: o.clone(),
                writer,
            })
        })
        .collect()
}

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

/// Encodes and writes every output; returns the paths written.
pub fn write_all(
    outputs: &[Output],
    fb: &Framebuffer,
    registry: &Registry,
    scene_dir: &Path,
) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    for o in outputs {
        let bytes = encode_image(
            registry,
            o.writer,
            &o.desc.params,
            &o.desc.params_at,
            scene_dir,
            fb.width,
            fb.height,
            &fb.rgba,
        )
        .map_err(|(at, m)| Error::at(&at, m))?;
        write_atomic(&o.desc.path, &bytes)?;
        written.push(o.desc.path.clone());
    }
    Ok(written)
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
