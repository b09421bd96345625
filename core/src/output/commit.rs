//! All outputs of a run, or none: every output's temporary file is created (and locked) before
//! the render starts, so a path that cannot be written fails at once; the images go into those
//! files, and only when every one is complete are they renamed over their targets. Any error
//! before that point (a failed render, a writer's error, a signal) removes the temporary files
//! and leaves every existing target as it was.
//!
//! The renames are the commit point. They start only after every file is complete and (with
//! [`Durability::Synced`], the default) synced, and each is a rename within one directory, which
//! does not fail in practice; if one did, the error names the outputs already replaced and those
//! not.
//!
//! [`Durability`] says whether the files are synced before the renames. `Synced` (every command
//! but one) means a target on disk is complete even after an operating-system crash, which a
//! resumed sequence trusts (`luxon render`, `luxon animate`, `luxon tachyon -camfile`).
//! `Atomic` skips the `fsync`, as Tachyon itself writes: still all or nothing for the process (a
//! killed or failed render leaves every target as it was, never a partial file), but a crash of
//! the whole machine just after the rename may leave an empty or partial target. `luxon
//! tachyon` writes the image of a scene file so (not its `-camfile` frames): the sync cost 14 ms
//! and more per image, a tenth of a small scene's whole run.

use super::stream::is_ppm8;
use super::Output;
use crate::error::Error;
use crate::files::TempFile;
use crate::framebuffer::Framebuffer;
use crate::plugin::writer::encode_image;
use crate::plugin::Registry;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Whether [`OutputSet::commit_with`] syncs the files before renaming them (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Durability {
    /// `fsync` every file before the renames: a committed target survives an OS crash complete.
    Synced,
    /// Rename without `fsync`: atomic for the process (all or nothing, never a partial file),
    /// durable only once the kernel writes the pages back.
    Atomic,
}

/// The temporary files of a run's outputs, in the order of the outputs given to `prepare`.
pub struct OutputSet {
    files: Vec<TempFile>,
}

impl OutputSet {
    /// Checks every output before anything is rendered: no target given twice, none that is a
    /// directory or a special file, every writer's parameters accepted (each writer encodes a
    /// 1x1 image), and a temporary file created beside each target.
    pub fn prepare(
        outputs: &[Output],
        registry: &Registry,
        scene_dir: &Path,
    ) -> Result<OutputSet, Error> {
        for (i, o) in outputs.iter().enumerate() {
            let (path, at) = (&o.desc.path, &o.desc.params_at);
            if outputs[..i].iter().any(|p| p.desc.path == *path) {
                return Err(Error::at(
                    at,
                    format!(
                        "output `{}` is given twice; expected each output file once",
                        path.display()
                    ),
                ));
            }
            if let Some(kind) = not_a_file(path) {
                return Err(Error::at(
                    at,
                    format!(
                        "cannot write output `{}`: it is {kind}; expected a file path",
                        path.display()
                    ),
                ));
            }
            if !is_ppm8(o) {
                encode_image(
                    registry,
                    o.writer,
                    &o.desc.params,
                    at,
                    scene_dir,
                    &format!("output `{}`", path.display()),
                    1,
                    1,
                    &[0.0, 0.0, 0.0, 1.0],
                )
                .map_err(|(at, m)| Error::at(&at, m))?;
            }
        }
        let mut files = Vec::with_capacity(outputs.len());
        for o in outputs {
            let tmp = TempFile::create(&o.desc.path).map_err(|e| {
                let why = match e {
                    Error::Io { source, .. } => source.to_string(),
                    e => e.to_string(),
                };
                Error::at(
                    &o.desc.params_at,
                    format!(
                        "cannot write output `{}`: {why}; expected a path in a writable directory",
                        o.desc.path.display()
                    ),
                )
            })?;
            files.push(tmp);
        }
        Ok(OutputSet { files })
    }

    /// The temporary file of output `i`.
    pub fn file(&mut self, i: usize) -> &mut File {
        self.files[i].file()
    }

    /// The path of output `i`'s temporary file (where MPI-IO writes it).
    pub fn temp_path(&self, i: usize) -> &Path {
        self.files[i].path()
    }

    /// Releases the lock of output `i`'s temporary file, before MPI-IO writes it from every rank
    /// (see [`TempFile::unlock`]).
    pub fn unlock(&self, i: usize) {
        self.files[i].unlock();
    }

    /// The target of output `i`.
    pub fn target(&self, i: usize) -> &Path {
        self.files[i].target()
    }

    /// Encodes `fb` with output `i`'s writer into its temporary file.
    pub fn encode(
        &mut self,
        i: usize,
        output: &Output,
        fb: &Framebuffer,
        registry: &Registry,
        scene_dir: &Path,
    ) -> Result<(), Error> {
        let bytes = encode_image(
            registry,
            output.writer,
            &output.desc.params,
            &output.desc.params_at,
            scene_dir,
            &format!("output `{}`", output.desc.path.display()),
            fb.width,
            fb.height,
            &fb.rgba,
        )
        .map_err(|(at, m)| Error::at(&at, m))?;
        self.files[i]
            .file()
            .write_all(&bytes)
            .map_err(|source| Error::Io {
                path: output.desc.path.clone(),
                source,
            })
    }

    /// Syncs every file, checks that each is still in place, then renames them all; returns
    /// the targets written.
    pub fn commit(self) -> Result<Vec<PathBuf>, Error> {
        self.commit_with(Durability::Synced)
    }

    /// [`commit`](Self::commit), syncing the files first only when `durability` says so.
    pub fn commit_with(mut self, durability: Durability) -> Result<Vec<PathBuf>, Error> {
        for f in &mut self.files {
            if durability == Durability::Synced {
                f.sync()?;
            }
            if !f.path().exists() {
                return Err(Error::Render(format!(
                    "the temporary file of output `{}` disappeared ({}); no output written",
                    f.target().display(),
                    f.path().display()
                )));
            }
        }
        let targets: Vec<PathBuf> = self
            .files
            .iter()
            .map(|f| f.target().to_path_buf())
            .collect();
        for (k, f) in self.files.drain(..).enumerate() {
            if let Err(e) = f.rename() {
                if k == 0 {
                    return Err(e);
                }
                let list = |p: &[PathBuf]| {
                    p.iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                return Err(Error::Render(format!(
                    "{e} (outputs already replaced: {}; not replaced: {})",
                    list(&targets[..k]),
                    list(&targets[k..])
                )));
            }
        }
        Ok(targets)
    }
}

/// What an existing `path` is when it is not a regular file (after symbolic links): a target
/// that must not be replaced.
fn not_a_file(path: &Path) -> Option<&'static str> {
    let m = std::fs::metadata(path).ok()?;
    if m.is_file() {
        return None;
    }
    if m.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = m.file_type();
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}
