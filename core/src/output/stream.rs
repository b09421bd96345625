//! Asynchronous output (the thesis's asynchronous I/O): render threads hand finished chunks to a
//! writer thread, which assembles the image and writes every completed row of 8-bit PPM outputs
//! into their temporary files while rendering goes on. Other formats are encoded from the
//! assembled image at the end. The files are committed together afterwards ([`super::commit`]).

use super::{Output, OutputSet};
use crate::budget::{Budget, Charge};
use crate::error::Error;
use crate::framebuffer::Chunk;
use crate::framebuffer::Framebuffer;
use crate::plugin::Registry;
use crate::ppm::{ppm_header, srgb8};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::Arc;
use std::time::Duration;

/// An output the core writes itself, row by row: the `ppm` writer with 8 bits per channel.
pub fn is_ppm8(o: &Output) -> bool {
    let params: String = o.desc.params.split_whitespace().collect();
    o.writer.name == "ppm" && (params == "()" || params == "(bits:8)")
}

/// A PPM written row by row into its temporary file: its index in the output set, and the first
/// write error (reported when the render is done).
struct RowFile {
    index: usize,
    path: PathBuf,
    error: Option<std::io::Error>,
}

impl RowFile {
    fn write_row(&mut self, set: &mut OutputSet, offset: u64, bytes: &[u8]) {
        if self.error.is_none() {
            let f = set.file(self.index);
            let r = f
                .seek(SeekFrom::Start(offset))
                .and_then(|_| f.write_all(bytes));
            self.error = r.err();
        }
    }
}

/// How often the writer looks for finished chunks while rendering goes on.
const POLL: Duration = Duration::from_millis(20);

/// The outputs of a render, written as its pixels arrive into the temporary files of an
/// [`OutputSet`] (created before rendering), by [`AsyncOutput::run`] on a writer thread.
pub struct AsyncOutput<'r> {
    set: OutputSet,
    rows: Vec<RowFile>,
    /// Outputs encoded from the whole image at the end, with their index in the set.
    encoded: Vec<(usize, Output<'r>)>,
    fb: Framebuffer,
    /// The image's bytes in the memory budget, held while it is assembled.
    _image: Charge,
    /// Pixels still missing per row.
    missing: Vec<u32>,
}

impl<'r> AsyncOutput<'r> {
    /// `outputs`: the outputs this writer produces, each with its index in `set`.
    pub fn new(
        outputs: Vec<(usize, Output<'r>)>,
        mut set: OutputSet,
        width: u32,
        height: u32,
        budget: &Arc<Budget>,
    ) -> Result<AsyncOutput<'r>, Error> {
        // The image first: one over the budget fails before any file is touched.
        let (fb, image) = Framebuffer::charged(width, height, budget)?;
        let mut rows = Vec::new();
        let mut encoded = Vec::new();
        for (i, o) in outputs {
            if is_ppm8(&o) {
                set.file(i)
                    .write_all(&ppm_header(width, height))
                    .map_err(|source| Error::Io {
                        path: o.desc.path.clone(),
                        source,
                    })?;
                rows.push(RowFile {
                    index: i,
                    path: o.desc.path.clone(),
                    error: None,
                });
            } else {
                encoded.push((i, o));
            }
        }
        Ok(AsyncOutput {
            set,
            rows,
            encoded,
            fb,
            _image: image,
            missing: vec![width; height as usize],
        })
    }

    /// Takes chunks until every sender is gone, then completes every file; returns the output
    /// set, ready to commit. Incomplete rows (a failed render) leave no file behind. Unpark the
    /// thread running this after dropping the last sender, or the end waits up to `POLL`.
    pub fn run(
        mut self,
        chunks: Receiver<Chunk>,
        registry: &Registry,
        scene_dir: &Path,
    ) -> Result<OutputSet, Error> {
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
                        f.write_row(&mut self.set, header + (y * w * 3) as u64, &row);
                    }
                }
            }
        }
        if self.missing.iter().any(|&m| m > 0) {
            return Err(Error::Render(
                "the render ended before every pixel was done; no file written".into(),
            ));
        }
        for f in &mut self.rows {
            if let Some(source) = f.error.take() {
                return Err(Error::Io {
                    path: f.path.clone(),
                    source,
                });
            }
        }
        for (i, o) in &self.encoded {
            self.set.encode(*i, o, &self.fb, registry, scene_dir)?;
        }
        Ok(self.set)
    }
}
