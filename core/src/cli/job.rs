//! The processes of one `luxon render`: this process alone, or the ranks of an MPI job (with
//! the `mpi` feature). Hides the feature from the rest of the command.

use luxon::api::{Renderer, Scene};
use luxon::framebuffer::Chunk;
use luxon::schedule::{available_cpus, launched_ranks, RankStats, Sink};
use luxon::Error;
use luxon_formats::{ParallelMode, RenderDesc};
use std::path::Path;

#[cfg(feature = "mpi")]
pub use luxon::schedule::cluster::Cluster;

/// Uninhabited without the `mpi` feature.
#[cfg(not(feature = "mpi"))]
pub enum Cluster {}

pub enum Job {
    Local,
    #[cfg_attr(not(feature = "mpi"), allow(dead_code))]
    Mpi(Cluster),
}

impl Job {
    /// Joins the MPI job when an MPI launcher started this process (before anything can fail,
    /// so that failures are agreed on collectively).
    pub fn from_launcher() -> Result<Job, Error> {
        match launched_ranks() {
            None => Ok(Job::Local),
            Some(n) => Self::mpi(n),
        }
    }

    /// Starts a one-rank MPI job for a scene that asks for MPI or hybrid mode without a
    /// launcher (without the `mpi` feature: renders in this process).
    pub fn for_mode(self, mode: ParallelMode) -> Result<Job, Error> {
        match (self, mode) {
            (Job::Local, ParallelMode::Mpi | ParallelMode::Hybrid) if cfg!(feature = "mpi") => {
                Self::mpi(1)
            }
            (job, _) => Ok(job),
        }
    }

    #[cfg(feature = "mpi")]
    fn mpi(_ranks: usize) -> Result<Job, Error> {
        Ok(Job::Mpi(Cluster::init()?))
    }

    #[cfg(not(feature = "mpi"))]
    fn mpi(ranks: usize) -> Result<Job, Error> {
        if ranks > 1 {
            return Err(Error::Usage(format!(
                "started as {ranks} MPI processes, but this luxon was built without MPI; rebuild with `cargo build --release --features mpi`"
            )));
        }
        Ok(Job::Local)
    }

    /// Ends this process with no message, finalising MPI first: rank 0 reports the cause and
    /// exits with status 1, which becomes mpirun's. This rank exits with 0: mpirun aborts a job
    /// as soon as one process returns non-zero, and a rank leaving with 1 got rank 0 killed
    /// before it had printed the cause (seen once in CI, on a loaded host).
    pub fn exit_quietly(self) -> ! {
        #[cfg(feature = "mpi")]
        drop(self);
        std::process::exit(0)
    }

    pub fn rank(&self) -> usize {
        match self {
            Job::Local => 0,
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => c.rank(),
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }

    /// Processes of the job on this node (1 without MPI): they share its memory.
    pub fn node_ranks(&self) -> usize {
        match self {
            Job::Local => 1,
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => c.node_ranks(),
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }

    pub fn size(&self) -> usize {
        match self {
            Job::Local => 1,
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => c.size(),
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }
}

impl Job {
    /// Render threads of this process for a scene's render settings.
    pub fn threads(&self, r: &RenderDesc) -> usize {
        match self {
            Job::Local => r
                .parallel
                .threads
                .map_or_else(available_cpus, |n| n as usize),
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => c.threads_for(r.parallel.threads, r.parallel.mode),
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }

    /// Whether every process is ready to render: then the threads of every rank; otherwise the
    /// error to report (on rank 0; `None` on ranks that should exit quietly).
    pub fn agree(&self, ready: Result<usize, Error>) -> Result<Vec<usize>, Option<Error>> {
        match self {
            Job::Local => ready.map(|t| vec![t]).map_err(Some),
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => c.agree(ready),
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }

    /// Renders this process's share with `renderer` (whose pool has this rank's `threads`):
    /// rank 0's `sink` gets its own chunks and, when `gather`, every rank's. Returns every
    /// rank's statistics (on rank 0) and, with `keep`, the chunks this rank rendered.
    pub fn render(
        &self,
        renderer: &Renderer,
        scene: &mut Scene,
        threads: &[usize],
        gather: bool,
        keep: bool,
        sink: Sink,
    ) -> Result<(Vec<RankStats>, Vec<Chunk>), Error> {
        match self {
            Job::Local => {
                let _ = (threads, gather, keep);
                renderer
                    .render_chunks(scene, sink)
                    .map(|r| (vec![r], Vec::new()))
            }
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => {
                let r = renderer.render_cluster(scene, c, threads, gather, keep, sink)?;
                Ok((r.ranks, r.kept))
            }
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }

    /// Rank 0's `value`, on every rank (collective).
    pub fn root_value(&self, value: u64) -> u64 {
        match self {
            Job::Local => value,
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => c.broadcast_u64(value),
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }

    /// Every rank writes its `chunks` of an 8-bit PPM with MPI-IO into the temporary file `tmp`
    /// that rank 0 created (and gives here; other ranks `None`); it is committed with the other
    /// outputs afterwards.
    pub fn write_concurrent(
        &self,
        tmp: Option<&Path>,
        width: u32,
        height: u32,
        chunks: &[Chunk],
    ) -> Result<(), Error> {
        match self {
            Job::Local => {
                let _ = (tmp, width, height, chunks);
                Err(Error::Render("MPI-IO needs an MPI job".into()))
            }
            #[cfg(feature = "mpi")]
            Job::Mpi(c) => {
                let tmp = c.broadcast_path(tmp);
                c.barrier();
                c.write_ppm(&tmp, width, height, chunks);
                c.barrier();
                Ok(())
            }
            #[cfg(not(feature = "mpi"))]
            Job::Mpi(c) => match *c {},
        }
    }
}
