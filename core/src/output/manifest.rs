//! What makes a sequence resumable: a completion record per frame, and claims that let several
//! processes share the frames. Beside the first output's name pattern, a directory
//! `.{pattern}.luxon-frames` holds
//!
//! ```text
//! manifest   what the sequence is (scene hash, outputs, frames, settings), for people
//! done/0037  frame 37's record: written (atomically) after its outputs are committed
//! claims/0037  flock'ed while a process renders frame 37; holds "pid P on HOST"
//! ```
//!
//! A frame is done iff its record parses to its final `check` line, its inputs hash is the
//! current one, and every current output of the frame exists with the size recorded. Outputs
//! appear only by rename once complete, and the record follows them, so a run killed in between
//! leaves a frame without a record (rendered again); an empty, partial, truncated or deleted
//! output is never taken for a finished frame.

use super::inputs::{absolute, Fnv};
use crate::error::Error;
use crate::files::{sweep_stale, write_atomic, Claim};
use std::path::{Path, PathBuf};

/// The format's first line.
const HEADER: &str = "luxon-frame 1";

/// The record directory of a sequence.
pub struct Manifest {
    dir: PathBuf,
    /// Outputs are recorded relative to this directory (the first output's) when inside it, so
    /// runs from other working directories (other nodes) agree.
    base: PathBuf,
}

impl Manifest {
    /// The records of the sequence whose first output is named by `pattern` (as written).
    pub fn beside(pattern: &Path) -> Manifest {
        let base = match pattern.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = pattern
            .file_name()
            .map_or("frames".into(), |n| n.to_string_lossy().to_string());
        Manifest {
            dir: base.join(format!(".{name}.luxon-frames")),
            base,
        }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Creates the directories and writes `manifest` (`about`: what the sequence is); removes
    /// the temporary files of killed runs from the record directory and from `output_dirs`.
    pub fn open(&self, about: &str, output_dirs: &[PathBuf]) -> Result<(), Error> {
        for sub in ["done", "claims"] {
            let d = self.dir.join(sub);
            std::fs::create_dir_all(&d).map_err(|e| self.unwritable(&d, e))?;
        }
        write_atomic(&self.dir.join("manifest"), about.as_bytes()).map_err(|e| match e {
            Error::Io { path, source } => self.unwritable(&path, source),
            e => e,
        })?;
        sweep_stale(&self.dir.join("done"), "");
        for d in output_dirs {
            sweep_stale(d, "");
        }
        Ok(())
    }

    fn unwritable(&self, path: &Path, e: std::io::Error) -> Error {
        Error::Usage(format!(
            "cannot keep the frame records in `{}` ({}: {e}); expected a writable directory \
             beside the first output",
            self.dir.display(),
            path.display()
        ))
    }

    fn done_path(&self, k: u32) -> PathBuf {
        self.dir.join("done").join(format!("{k:04}"))
    }

    fn claim_path(&self, k: u32) -> PathBuf {
        self.dir.join("claims").join(format!("{k:04}"))
    }

    /// How an output is named in records.
    fn recorded_name(&self, output: &Path) -> String {
        let out = absolute(output);
        let name = match out.strip_prefix(absolute(&self.base)) {
            Ok(rel) => rel.to_path_buf(),
            Err(_) => out,
        };
        name.to_string_lossy().into_owned()
    }

    /// Whether frame `k` is done: its record is whole, for `inputs`, and lists each of
    /// `outputs` with the size it has.
    pub fn is_done(&self, k: u32, inputs: u64, outputs: &[PathBuf]) -> bool {
        let Ok(text) = std::fs::read_to_string(self.done_path(k)) else {
            return false;
        };
        let Some(record) = Record::parse(&text) else {
            return false;
        };
        record.frame == k
            && record.inputs == inputs
            && outputs.iter().all(|o| {
                let name = self.recorded_name(o);
                let size = std::fs::metadata(o)
                    .ok()
                    .filter(|m| m.is_file())
                    .map(|m| m.len());
                record
                    .outputs
                    .iter()
                    .any(|(n, s)| *n == name && Some(*s) == size)
            })
    }

    /// Writes frame `k`'s record (after its outputs are committed).
    pub fn record(&self, k: u32, inputs: u64, outputs: &[PathBuf]) -> Result<(), Error> {
        let mut outs = Vec::with_capacity(outputs.len());
        for o in outputs {
            let size = std::fs::metadata(o)
                .map_err(|source| Error::Io {
                    path: o.clone(),
                    source,
                })?
                .len();
            outs.push((self.recorded_name(o), size));
        }
        let text = Record {
            frame: k,
            inputs,
            outputs: outs,
        }
        .to_text();
        write_atomic(&self.done_path(k), text.as_bytes())
    }

    /// Removes frame `k`'s record (`--force`).
    pub fn forget(&self, k: u32) -> Result<(), Error> {
        let p = self.done_path(k);
        match std::fs::remove_file(&p) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(Error::Io { path: p, source: e })
            }
            _ => Ok(()),
        }
    }

    /// Claims frame `k` for this process; `None` when another process holds it.
    pub fn claim(&self, k: u32) -> Result<Option<Claim>, Error> {
        let p = self.claim_path(k);
        Claim::try_take(&p).map_err(|source| Error::Io { path: p, source })
    }

    /// Who holds frame `k`'s claim ("pid 4411 on node7").
    pub fn holder(&self, k: u32) -> Option<String> {
        Claim::holder(&self.claim_path(k))
    }
}

/// A frame's completion record.
#[derive(Debug, PartialEq)]
struct Record {
    frame: u32,
    inputs: u64,
    /// (name as recorded, size in bytes)
    outputs: Vec<(String, u64)>,
}

impl Record {
    fn to_text(&self) -> String {
        let mut t = format!(
            "{HEADER}\nframe {}\ninputs {:016x}\n",
            self.frame, self.inputs
        );
        for (name, size) in &self.outputs {
            t.push_str(&format!("output {size} {name}\n"));
        }
        let check = Fnv::new().bytes(t.as_bytes()).finish();
        t.push_str(&format!("check {check:016x}\n"));
        t
    }

    /// The record in `text`, if whole: every line known, the check line last and right.
    fn parse(text: &str) -> Option<Record> {
        let body_end = text.rfind("check ")?;
        let (body, check) = text.split_at(body_end);
        let check = check.strip_prefix("check ")?.strip_suffix('\n')?;
        if u64::from_str_radix(check, 16).ok()? != Fnv::new().bytes(body.as_bytes()).finish() {
            return None;
        }
        let mut lines = body.lines();
        if lines.next()? != HEADER {
            return None;
        }
        let frame = lines.next()?.strip_prefix("frame ")?.parse().ok()?;
        let inputs = u64::from_str_radix(lines.next()?.strip_prefix("inputs ")?, 16).ok()?;
        let outputs = lines
            .map(|l| {
                let (size, name) = l.strip_prefix("output ")?.split_once(' ')?;
                Some((name.to_string(), size.parse().ok()?))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Record {
            frame,
            inputs,
            outputs,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> Record {
        Record {
            frame: 37,
            inputs: 0xfeed,
            outputs: vec![("f037.png".into(), 48213), ("exr/f 037.exr".into(), 9)],
        }
    }

    #[test]
    fn a_record_reads_back_and_any_cut_or_change_is_refused() {
        let text = record().to_text();
        assert_eq!(Record::parse(&text), Some(record()));
        for cut in 0..text.len() {
            assert_eq!(Record::parse(&text[..cut]), None, "cut at {cut}");
        }
        let changed = text.replace("48213", "48214");
        assert_eq!(Record::parse(&changed), None);
    }

    #[test]
    fn done_needs_the_record_the_inputs_and_every_output_at_its_size() {
        let d = std::env::temp_dir().join(format!("luxon-manifest-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let m = Manifest::beside(&d.join("f%03d.ppm"));
        assert!(m.dir().ends_with(".f%03d.ppm.luxon-frames"));
        m.open("about", &[]).unwrap();
        let out = vec![d.join("f003.ppm")];
        std::fs::write(&out[0], b"P6 1 1 255\n...").unwrap();
        assert!(!m.is_done(3, 1, &out));
        m.record(3, 1, &out).unwrap();
        assert!(m.is_done(3, 1, &out));
        assert!(!m.is_done(3, 2, &out), "other inputs");
        assert!(!m.is_done(4, 1, &out), "another frame's record");
        let other = vec![d.join("f003.ppm"), d.join("f003.png")];
        assert!(!m.is_done(3, 1, &other), "an output not recorded");
        std::fs::write(&out[0], b"P6 1").unwrap();
        assert!(!m.is_done(3, 1, &out), "truncated");
        m.forget(3).unwrap();
        m.forget(3).unwrap();
        assert!(!m.done_path(3).exists());
        std::fs::remove_dir_all(&d).unwrap();
    }
}
