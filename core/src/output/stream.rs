//! Asynchronous output (the thesis's asynchronous I/O): render threads hand finished chunks to a
//! writer thread, which assembles the image and writes every completed row of 8-bit PPM outputs
//! into their temporary files while rendering goes on. Other formats are encoded from the
//! assembled image at the end. Every file appears atomically (temporary file + rename).

use super::{write_all, Output};
use crate::error::Error;
use crate::files::{pending, temp_path};
use crate::framebuffer::Chunk;
use crate::framebuffer::Framebuffer;
use crate::plugin::Registry;
use crate::ppm::{ppm_header, srgb8};
use std::fs::File;
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError};
use std::time::Duration;

/// An output the core writes itself, row by row: the `ppm` writer with 8 bits per channel.
pub fn is_ppm8(o: &Output) -> bool {
    let params: String = o.desc.params.split_whitespace().collect();
    o.writer.name == "ppm" && (params == "()" || params == "(bits:8)")
}

/// A PPM written row by row into its temporary file.
struct RowFile {
    path: PathBuf,
    tmp: PathBuf,
    file: File,
    error: Option<std::io::Error>,
    renamed: bool,
}

impl Drop for RowFile {
    fn drop(&mut self) {
        pending(&self.tmp, false);
        if !self.renamed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

impl RowFile {
    fn create(path: &Path, width: u32, height: u32) -> Result<RowFile, Error> {
        let tmp = temp_path(path, std::process::id())?;
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        pending(&tmp, true);
        let mut file = File::create(&tmp).map_err(io)?;
        file.write_all(&ppm_header(width, height)).map_err(io)?;
        Ok(RowFile {
            path: path.to_path_buf(),
            tmp,
            file,
            error: None,
            renamed: false,
        })
    }

    fn write_row(&mut self, offset: u64, bytes: &[u8]) {
        if self.error.is_none() {
            let r = self
                .file
                .seek(SeekFrom::Start(offset))
                .and_then(|_| self.file.write_all(bytes));
            self.error = r.err();
        }
    }

    fn finish(mut self) -> Result<PathBuf, Error> {
        let r = match self.error.take() {
            Some(e) => Err(e),
            None => self
                .file
                .sync_all()
                .and_then(|_| std::fs::rename(&self.tmp, &self.path)),
        };
        self.renamed = r.is_ok();
        r.map(|_| self.path.clone()).map_err(|source| Error::Io {
            path: self.path.clone(),
            source,
        })
    }
}

/// How often the writer looks for finished chunks while rendering goes on.
const POLL: Duration = Duration::from_millis(20);

/// The outputs of a render, written as its pixels arrive. Created before rendering (so a path
/// that cannot be written fails at once), then [`AsyncOutput::run`] on a writer thread.
pub struct AsyncOutput<'r> {
    rows: Vec<RowFile>,
    encoded: Vec<Output<'r>>,
    /// Every output path, in the scene's order.
    order: Vec<PathBuf>,
    fb: Framebuffer,
    /// Pixels still missing per row.
    missing: Vec<u32>,
}

impl<'r> AsyncOutput<'r> {
    pub fn new(outputs: &[Output<'r>], width: u32, height: u32) -> Result<AsyncOutput<'r>, Error> {
        let mut rows = Vec::new();
        let mut encoded = Vec::new();
        for o in outputs {
            if is_ppm8(o) {
                rows.push(RowFile::create(&o.desc.path, width, height)?);
            } else {
                encoded.push(o.clone());
            }
        }
        Ok(AsyncOutput {
            rows,
            encoded,
            order: outputs.iter().map(|o| o.desc.path.clone()).collect(),
            fb: Framebuffer::new(width, height),
            missing: vec![width; height as usize],
        })
    }

    /// Takes chunks until every sender is gone, then finishes every file; returns the paths
    /// written. Incomplete rows (a failed render) leave no file behind. Unpark the thread
    /// running this after dropping the last sender, or the end waits up to `POLL`.
    pub fn run(
        mut self,
        chunks: Receiver<Chunk>,
        registry: &Registry,
        scene_dir: &Path,
    ) -> Result<Vec<PathBuf>, Error> {
        let w = self.fb.width as usize;
        let header = ppm_header(self.fb.width, self.fb.height).len() as u64;
        let mut row = Vec::with_capacity(w * 3);
        loop {
            let c = match chunks.try_recv() {
                Ok(c) => c,
                Err(TryRecvError::Disconnected) => break,
                Err(TryRecvError::Empty) => {
                    // Polled, not woken per chunk: a blocking receive costs the render threads a
                    // futex wake for every chunk they send (about 8 % of teapot48's render on 2
                    // cores). The renderer unparks this thread once it has dropped its sender.
                    std::thread::park_timeout(POLL);
                    continue;
                }
            };
            self.fb.put_chunk(&c);
            for s in &c.spans {
                let y = s.y as usize;
                self.missing[y] = self.missing[y].saturating_sub(s.count);
                if self.missing[y] == 0 && !self.rows.is_empty() {
                    row.clear();
                    srgb8(&self.fb.rgba[y * w * 4..(y + 1) * w * 4], &mut row);
                    for f in &mut self.rows {
                        f.write_row(header + (y * w * 3) as u64, &row);
                    }
                }
            }
        }
        if self.missing.iter().any(|&m| m > 0) {
            return Err(Error::Render(
                "the render ended before every pixel was done; no file written".into(),
            ));
        }
        let mut written = Vec::new();
        for f in self.rows {
            written.push(f.finish()?);
        }
        written.extend(write_all(&self.encoded, &self.fb, registry, scene_dir)?);
        written.sort_by_key(|p| self.order.iter().position(|o| o == p));
        Ok(written)
    }
}
