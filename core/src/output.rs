//! Writing finished images through writer plugins, all outputs or none ([`commit`]): every
//! file is written to a temporary file beside its target, and the temporary files are renamed
//! over their targets only when every one is complete, so a failed run leaves every existing
//! file as it was.

use crate::error::Error;
use crate::framebuffer::Framebuffer;
use crate::plugin::{Entry, PluginKind, Registry};
use luxon_formats::OutputDesc;
use std::path::{Path, PathBuf};

pub mod commit;
pub mod frames;
pub mod inputs;
pub mod manifest;
pub mod preview;
pub mod stream;

pub use commit::{Durability, OutputSet};

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
                    let found = registry
                        .writer_for_extension(ext)
                        .map_err(|e| Error::at(&o.params_at, e.to_string()))?;
                    found.ok_or_else(|| {
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

/// Encodes and writes every output, all or none, synced before the commit; returns the paths
/// written.
pub fn write_all(
    outputs: &[Output],
    fb: &Framebuffer,
    registry: &Registry,
    scene_dir: &Path,
) -> Result<Vec<PathBuf>, Error> {
    write_all_with(outputs, fb, registry, scene_dir, Durability::Synced)
}

/// [`write_all`] with the commit's [`Durability`] given.
pub fn write_all_with(
    outputs: &[Output],
    fb: &Framebuffer,
    registry: &Registry,
    scene_dir: &Path,
    durability: Durability,
) -> Result<Vec<PathBuf>, Error> {
    let mut set = OutputSet::prepare(outputs, registry, scene_dir)?;
    for (i, o) in outputs.iter().enumerate() {
        set.encode(i, o, fb, registry, scene_dir)?;
    }
    set.commit_with(durability)
}
