//! Writing finished images through writer plugins. Every file is written to a temporary file in
//! the same directory and renamed over the target, so an existing file is never left half-written.

use crate::error::Error;
use crate::files::write_atomic;
use crate::framebuffer::Framebuffer;
use crate::plugin::writer::encode_image;
use crate::plugin::{Entry, PluginKind, Registry};
use luxon_formats::OutputDesc;
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
