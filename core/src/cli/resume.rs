//! Which frames of a sequence this process renders: those without a valid completion record
//! (see [`luxon::output::manifest`]) that no other process has claimed. Processes started on
//! the same outputs share the frames this way; each takes the frames in order, and frames
//! claimed by others are tried once more at the end (their owner may have died) before this
//! process reports them and ends. Only rank 0 of an MPI job keeps the records.

use luxon::files::Claim;
use luxon::output::frames::FrameNames;
use luxon::output::inputs::frame_hash;
use luxon::output::manifest::Manifest;
use luxon::Error;
use std::collections::VecDeque;
use std::path::PathBuf;

pub struct Resume {
    manifest: Manifest,
    names: FrameNames,
    scene: u64,
    /// The data files frame k reads (they join its inputs hash).
    data: Box<dyn Fn(u32) -> Vec<PathBuf> + Send + Sync>,
    total: usize,
    /// Done when this run started.
    pub done_at_start: usize,
    queue: VecDeque<u32>,
    /// Claimed by others on the first pass (tried again), then on the second (reported).
    later: Vec<u32>,
    busy: Vec<u32>,
    second_pass: bool,
    /// The frames being rendered (several at once when MPI groups take whole frames).
    claims: Vec<(u32, Claim)>,
}

impl Resume {
    /// Opens the records beside the first output (`force`: forgets those of `frames`) and
    /// counts the frames done already; `data(k)`: the data files frame k reads.
    pub fn start(
        names: &FrameNames,
        frames: &[u32],
        scene: u64,
        data: Box<dyn Fn(u32) -> Vec<PathBuf> + Send + Sync>,
        force: bool,
        about: &str,
    ) -> Result<Resume, Error> {
        let first = names
            .first()
            .ok_or_else(|| Error::Usage("a sequence needs an output".into()))?;
        let manifest = Manifest::beside(first);
        let mut dirs: Vec<PathBuf> = Vec::new();
        if let Some(&k) = frames.first() {
            for o in names.outputs_for(k) {
                let d = match o.path.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                if !dirs.contains(&d) {
                    dirs.push(d);
                }
            }
        }
        manifest.open(about, &dirs)?;
        if force {
            for &k in frames {
                manifest.forget(k)?;
            }
        }
        let mut r = Resume {
            manifest,
            names: names.clone(),
            scene,
            data,
            total: frames.len(),
            done_at_start: 0,
            queue: frames.iter().copied().collect(),
            later: Vec::new(),
            busy: Vec::new(),
            second_pass: false,
            claims: Vec::new(),
        };
        r.done_at_start = frames.iter().filter(|&&k| r.is_done(k)).count();
        Ok(r)
    }

    fn hash(&self, k: u32) -> u64 {
        frame_hash(self.scene, k, &(self.data)(k))
    }

    fn outputs(&self, k: u32) -> Vec<PathBuf> {
        self.names
            .outputs_for(k)
            .into_iter()
            .map(|o| o.path)
            .collect()
    }

    fn is_done(&self, k: u32) -> bool {
        self.manifest.is_done(k, self.hash(k), &self.outputs(k))
    }

    /// What the start found, for the user (`None` when nothing was done).
    pub fn start_note(&self) -> Option<String> {
        let (done, total) = (self.done_at_start, self.total);
        let dir = self.manifest.dir().display();
        match done {
            0 => None,
            d if d == total && total == 1 => Some(format!(
                "the frame is done already (recorded in {dir}); --force renders it again"
            )),
            d if d == total => Some(format!(
                "all {total} frames are done already (recorded in {dir}); --force renders them again"
            )),
            d => Some(format!(
                "{d} of {total} frames are done already (recorded in {dir}); rendering the other {}",
                total - d
            )),
        }
    }

    /// The next frame for this process, claimed; `None` when none is left. An error names the
    /// frame whose claim failed (the others go on).
    pub fn next(&mut self) -> Result<Option<u32>, (u32, Error)> {
        loop {
            let Some(k) = self.queue.pop_front() else {
                if self.second_pass || self.later.is_empty() {
                    return Ok(None);
                }
                self.second_pass = true;
                self.queue.extend(self.later.drain(..));
                continue;
            };
            if self.is_done(k) {
                continue;
            }
            let Some(claim) = self.manifest.claim(k).map_err(|e| (k, e))? else {
                if self.second_pass {
                    self.busy.push(k);
                } else {
                    self.later.push(k);
                }
                continue;
            };
            // Another process may have finished it since the check above.
            if self.is_done(k) {
                continue;
            }
            self.claims.push((k, claim));
            return Ok(Some(k));
        }
    }

    /// Frames left to look at (for the ETA).
    pub fn left(&self) -> usize {
        self.queue.len() + self.later.len()
    }

    /// Frame `k` is written (its outputs committed): records it and lets its claim go.
    pub fn finished(&mut self, k: u32) -> Result<(), Error> {
        let recorded = self.manifest.record(k, self.hash(k), &self.outputs(k));
        self.release(k);
        recorded.map_err(|e| {
            Error::Render(format!(
                "its outputs are written but its record is not ({e}); the next run renders it again"
            ))
        })
    }

    /// Lets the claim of frame `k` go (it failed, or is recorded).
    pub fn release(&mut self, k: u32) {
        self.claims.retain(|(c, _)| *c != k);
    }

    /// The frames left to other processes, for the user (`None`: none).
    pub fn others(&self) -> Option<String> {
        if self.busy.is_empty() {
            return None;
        }
        let mut list: Vec<String> = self.busy.iter().take(12).map(u32::to_string).collect();
        if self.busy.len() > 12 {
            list.push(format!("and {} more", self.busy.len() - 12));
        }
        let mut holders: Vec<String> = self
            .busy
            .iter()
            .filter_map(|&k| self.manifest.holder(k))
            .collect();
        holders.sort();
        holders.dedup();
        let (what, verb) = match self.busy.len() {
            1 => ("frame", "is"),
            _ => ("frames", "are"),
        };
        let by = match holders.len() {
            0 => String::new(),
            _ => format!(" ({})", holders.join(", ")),
        };
        Some(format!(
            "{what} {} {verb} being rendered by other processes{by}",
            list.join(", ")
        ))
    }
}
