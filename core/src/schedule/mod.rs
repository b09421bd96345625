#![doc = include_str!("README.md")]

pub mod decompose;
pub mod wire;

// MPI calls (the raw rsmpi FFI).
#[cfg(feature = "mpi")]
#[allow(unsafe_code)]
mod abort;
#[cfg(feature = "mpi")]
pub mod cluster;
// A caller's MPI (guest mode): thread-level checks, Fortran handles (the raw rsmpi FFI).
#[cfg(feature = "mpi")]
#[allow(unsafe_code)]
pub mod guest;
// Frames of a sequence dealt to groups of ranks (a communicator moved to a thread).
#[cfg(feature = "mpi")]
#[allow(unsafe_code)]
pub mod frames;
// MPI calls (the raw rsmpi FFI).
#[cfg(feature = "mpi")]
#[allow(unsafe_code)]
mod mailbox;
// MPI calls (the raw rsmpi FFI).
#[cfg(feature = "mpi")]
#[allow(unsafe_code)]
mod mpi_io;

use crate::error::Error;
use crate::framebuffer::{Chunk, Span};
use crate::geometry::Counters;
use crate::integrator::{render_depth, render_spans};
use crate::scene::Scene;
pub use decompose::Rect;
use luxon_formats::Decomposition;
use rayon::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Where finished chunks go; called from the render threads.
pub type Sink<'a> = &'a (dyn Fn(Chunk) + Sync);

/// The work one render thread did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorkerStats {
    /// Units of work: tiles, blocks or rows.
    pub units: u64,
    pub pixels: u64,
    pub counters: Counters,
    /// Time spent rendering (not waiting).
    pub busy: Duration,
}

impl WorkerStats {
    pub fn add(&mut self, o: &WorkerStats) {
        self.units += o.units;
        self.pixels += o.pixels;
        self.counters.add(&o.counters);
        self.busy += o.busy;
    }
}

/// The work one process (MPI rank) did, per thread.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RankStats {
    pub rank: usize,
    pub threads: Vec<WorkerStats>,
    /// Wall time of the rank's render phase.
    pub time: Duration,
    /// NaN results per plugin instance, in the order of [`Scene::nan_counts`].
    pub nan_sources: Vec<u64>,
}

impl RankStats {
    pub fn total(&self) -> WorkerStats {
        let mut t = WorkerStats::default();
        for w in &self.threads {
            t.add(w);
        }
        t
    }
}

/// What the render threads of one process take on.
pub enum Share<'a> {
    /// A static decomposition: this process's threads are workers `first..first + threads` of
    /// `workers` numbered across every rank.
    Static {
        how: Decomposition,
        first: usize,
        workers: usize,
    },
    /// Rayon work stealing over these tiles.
    Steal(&'a [Rect]),
    /// Tiles (indices into `tiles`) taken from `next` until it says there are no more; `next`
    /// may block waiting for one.
    Queue {
        tiles: &'a [Rect],
        next: &'a (dyn Fn() -> Option<usize> + Sync),
    },
}

/// How a render runs, beside which pixels it takes on.
#[derive(Clone, Copy)]
pub struct RunOptions<'a> {
    /// Stops the render when set (from any thread): no unit starts after it is seen, so the
    /// render ends within a unit (a tile) of work per thread.
    pub cancel: &'a AtomicBool,
    /// Chunks also carry their pixels' depth (`integrator::render_depth`).
    pub depth: bool,
}

/// The cancel flag of renders no one can cancel.
static NEVER: AtomicBool = AtomicBool::new(false);

impl Default for RunOptions<'_> {
    /// Not cancellable, no depth: what the command line renders.
    fn default() -> Self {
        RunOptions {
            cancel: &NEVER,
            depth: false,
        }
    }
}

/// Every CPU this process may run on (affinity respected).
pub fn available_cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool, Error> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("luxon-render-{i}"))
        // The integrator recurses once per bounce, up to max_depth 1024: room to spare (only
        // the pages touched are ever committed).
        .stack_size(32 << 20)
        .build()
        .map_err(|e| Error::Render(format!("cannot start {threads} render threads: {e}")))
}

/// Runs `share` on `pool`, handing each finished unit to `sink`. Stops early (leaving pixels
/// out) once a plugin has faulted or `options.cancel` is set; the caller reports which. A unit
/// that panics (a bug, in Luxon or in `sink`) raises the scene's fault instead of unwinding
/// into the caller.
pub fn run_share(
    scene: &Scene,
    pool: &rayon::ThreadPool,
    share: Share,
    options: RunOptions,
    sink: Sink,
) -> RankStats {
    let start = Instant::now();
    let stats: Vec<Mutex<WorkerStats>> = (0..pool.current_num_threads())
        .map(|_| Mutex::default())
        .collect();
    let unit = |thread: usize, spans: Vec<Span>| {
        let t0 = Instant::now();
        let mut w = WorkerStats {
            units: 1,
            ..Default::default()
        };
        let rgba = render_spans(scene, &spans, &mut w.counters);
        let depth = if options.depth {
            render_depth(scene, &spans, &mut w.counters)
        } else {
            Vec::new()
        };
        let chunk = Chunk { spans, rgba, depth };
        w.pixels = chunk.pixels();
        w.busy = t0.elapsed();
        sink(chunk);
        stats[thread]
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .add(&w);
    };
    let one = |thread: usize, spans: Vec<Span>| {
        if let Err(p) = catch_unwind(AssertUnwindSafe(|| unit(thread, spans))) {
            scene.customs.fault.raise(format!(
                "internal error (a bug in Luxon; please report it): a render thread panicked: {}",
                panic_message(p.as_ref())
            ));
        }
    };
    let stop = || scene.customs.fault.is_raised() || options.cancel.load(Ordering::Relaxed);
    let s = &scene.settings;
    match share {
        Share::Static {
            how,
            first,
            workers,
        } => {
            pool.broadcast(|ctx| {
                let units = decompose::static_units(
                    s.width,
                    s.height,
                    how,
                    s.tile_size,
                    first + ctx.index(),
                    workers,
                );
                for unit in units {
                    if stop() {
                        break;
                    }
                    one(ctx.index(), unit);
                }
            });
        }
        Share::Steal(tiles) => pool.install(|| {
            tiles.par_iter().for_each(|t| {
                if !stop() {
                    one(rayon::current_thread_index().unwrap_or(0), t.spans());
                }
            })
        }),
        Share::Queue { tiles, next } => {
            pool.broadcast(|ctx| {
                while let Some(i) = next() {
                    if stop() {
                        break;
                    }
                    one(ctx.index(), tiles[i].spans());
                }
            });
        }
    }
    RankStats {
        rank: 0,
        threads: stats
            .into_iter()
            .map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()))
            .collect(),
        time: start.elapsed(),
        nan_sources: scene.nan_counts(),
    }
}

/// What a panic carried, when it is text.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("(no message)")
}

/// Renders the whole image in this process on `pool` with the scene's decomposition (dynamic:
/// work stealing over tiles), handing finished chunks to `sink`. A plugin fault is an error,
/// and so is a cancel that left pixels out ([`Error::Cancelled`]).
pub fn render_local(
    scene: &Scene,
    pool: &rayon::ThreadPool,
    options: RunOptions,
    sink: Sink,
) -> Result<RankStats, Error> {
    let s = &scene.settings;
    let tiles = decompose::tiles(s.width, s.height, s.tile_size);
    let share = match s.decomposition {
        Decomposition::Dynamic => Share::Steal(&tiles),
        how => Share::Static {
            how,
            first: 0,
            workers: pool.current_num_threads(),
        },
    };
    let stats = run_share(scene, pool, share, options, sink);
    if let Some(m) = scene.customs.fault.message() {
        return Err(Error::Plugin(m));
    }
    let all = s.width as u64 * s.height as u64;
    if options.cancel.load(Ordering::Relaxed) && stats.total().pixels < all {
        return Err(Error::Cancelled);
    }
    Ok(stats)
}

/// Threads per process: the scene's (or command line's) count, else every CPU.
pub fn threads_for(scene: &Scene) -> usize {
    scene
        .settings
        .threads
        .map_or_else(available_cpus, |n| n as usize)
}

/// The number of processes an MPI launcher (mpirun, mpiexec) started this job with, read from
/// the environment before (or without) initialising MPI; `None` when not launched by one.
pub fn launched_ranks() -> Option<usize> {
    [
        "OMPI_COMM_WORLD_SIZE",
        "PMI_SIZE",
        "PMIX_SIZE",
        "MPI_LOCALNRANKS",
    ]
    .iter()
    .find_map(|v| std::env::var(v).ok()?.trim().parse().ok())
}
