//! [`Renderer`]: renders retained scenes on a thread pool, into the caller's buffers or as a
//! stream of chunks.

use super::{Context, Scene};
use crate::error::Error;
use crate::framebuffer::Target;
use crate::render::{render_into, Progress, RenderStats};
use crate::schedule::{available_cpus, render_local, thread_pool, RankStats, RunOptions, Sink};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// How a [`Renderer`] starts.
#[derive(Clone, Debug, Default)]
pub struct RendererOptions {
    /// Threads of a pool of its own (0: every CPU this process may run on); `None`: render on
    /// the context's pool.
    pub threads: Option<usize>,
}

/// Stops the render running now on a renderer (from any thread); see
/// [`Renderer::cancel_handle`].
#[derive(Clone, Debug)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// The render running now stops within a tile per thread and returns
    /// [`Error::Cancelled`]. A render that starts later is not affected.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::SeqCst);
    }
}

/// Renders scenes on its thread pool (its own, or its context's). Each render commits the scene
/// first ([`Scene::commit`]), so what it shows is the scene as it is now.
///
/// With the `mpi` feature a renderer can be given the caller's communicator
/// (`Renderer::with_communicator`): its renders are then image-parallel over the ranks of
/// that communicator, see [the MPI rules](crate::api#mpi-owned-by-the-caller).
pub struct Renderer {
    pub(super) pool: Arc<rayon::ThreadPool>,
    cancel: Arc<AtomicBool>,
    /// A duplicate of the caller's communicator; the lock keeps two renders from driving MPI
    /// at once.
    #[cfg(feature = "mpi")]
    cluster: std::sync::Mutex<Option<crate::schedule::guest::Guest>>,
}

// A renderer moves between threads and is shared by them (Python, C hosts), with or without
// a communicator: this fails to compile otherwise.
const _: () = {
    const fn send_and_sync<T: Send + Sync>() {}
    send_and_sync::<Renderer>();
};

impl Renderer {
    pub fn new(ctx: &Context, o: RendererOptions) -> Result<Renderer, Error> {
        let pool = match o.threads {
            None => ctx.pool.clone(),
            Some(0) => Arc::new(thread_pool(available_cpus())?),
            Some(n) => Arc::new(thread_pool(n)?),
        };
        Ok(Renderer {
            pool,
            cancel: Arc::new(AtomicBool::new(false)),
            #[cfg(feature = "mpi")]
            cluster: std::sync::Mutex::new(None),
        })
    }

    /// Render threads.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// A handle that cancels the render running now, from any thread.
    pub fn cancel_handle(&self) -> Cancel {
        Cancel(self.cancel.clone())
    }

    /// Commits `scene` at the target's size and renders it into `target` (colour in the
    /// target's format, depth when it has a depth plane). Pixels are the same, bit for bit,
    /// whatever the thread count.
    pub fn render(&self, scene: &mut Scene, target: Target) -> Result<RenderStats, Error> {
        self.render_with(scene, target, &|_, _| {})
    }

    /// `render`, telling `progress` (from any render thread) about finished pixels.
    pub fn render_with(
        &self,
        scene: &mut Scene,
        target: Target,
        progress: Progress,
    ) -> Result<RenderStats, Error> {
        #[cfg(feature = "mpi")]
        {
            let cluster = self.cluster.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(guest) = cluster.as_ref() {
                return self.render_across(&guest.0, scene, target, progress);
            }
        }
        target.check().map_err(Error::Target)?;
        scene.set_size(target.width, target.height);
        self.start();
        let rendered = scene.commit_pinned(self).and_then(|_| {
            render_into(
                scene.committed()?,
                &self.pool,
                target,
                &self.cancel,
                progress,
            )
        });
        scene.unpin();
        if rendered.is_err() {
            scene.after_failure();
        }
        rendered
    }

    /// Commits `scene` (at its description's size, or its last render's) and renders it in this
    /// process, handing each finished chunk of pixels to `sink` (from the render threads).
    pub fn render_chunks(&self, scene: &mut Scene, sink: Sink) -> Result<RankStats, Error> {
        #[cfg(feature = "mpi")]
        if self.communicator().is_some() {
            return Err(Error::Api(
                "render_chunks renders in this process only, and this renderer has a \
                 communicator: use render (rank 0 gets the image)"
                    .into(),
            ));
        }
        self.start();
        let options = RunOptions {
            cancel: &self.cancel,
            depth: false,
        };
        let rendered = scene
            .commit_pinned(self)
            .and_then(|_| render_local(scene.committed()?, &self.pool, options, sink));
        scene.unpin();
        if rendered.is_err() {
            scene.after_failure();
        }
        rendered
    }

    /// `render_chunks` as one rank of an MPI job the caller owns (`cluster`): `threads` are
    /// every rank's thread counts (this renderer's pool has this rank's); rank 0's `sink` gets
    /// its chunks and, when `gather`, every rank's; with `keep` each rank also gets back its
    /// own. A failure on any rank ends the job (the command line's policy).
    #[cfg(feature = "mpi")]
    pub fn render_cluster(
        &self,
        scene: &mut Scene,
        cluster: &crate::schedule::cluster::Cluster,
        threads: &[usize],
        gather: bool,
        keep: bool,
        sink: Sink,
    ) -> Result<crate::schedule::cluster::Rendered, Error> {
        self.start();
        let rendered = scene.commit_pinned(self).and_then(|_| {
            Ok(cluster.render(scene.committed()?, &self.pool, threads, gather, keep, sink))
        });
        scene.unpin();
        rendered
    }

    /// A renderer whose renders are image-parallel over the ranks of `comm`, the caller's
    /// communicator (see [`Renderer::set_communicator`]). Collective over `comm`.
    #[cfg(feature = "mpi")]
    pub fn with_communicator(
        ctx: &Context,
        o: RendererOptions,
        comm: &mpi::topology::SimpleCommunicator,
    ) -> Result<Renderer, Error> {
        let r = Renderer::new(ctx, o)?;
        r.set_communicator(comm)?;
        Ok(r)
    }

    /// From now on, renders are image-parallel over the ranks of `comm` (a duplicate of it:
    /// the caller keeps its own and Luxon's messages never meet the caller's). Collective over
    /// `comm` (`MPI_Comm_dup`): every rank calls it. MPI must be initialised, by the caller
    /// (Luxon never initialises or finalises it), with a thread level that allows this thread
    /// (see [the MPI rules](crate::api#mpi-owned-by-the-caller)).
    #[cfg(feature = "mpi")]
    pub fn set_communicator(&self, comm: &mpi::topology::SimpleCommunicator) -> Result<(), Error> {
        let cluster = crate::schedule::cluster::Cluster::from_communicator(comm)?;
        self.put_cluster(Some(cluster));
        Ok(())
    }

    /// [`Renderer::set_communicator`] for the communicator whose Fortran handle is `handle`
    /// (C's `MPI_Comm_c2f(comm)`, or a Fortran integer communicator).
    #[cfg(feature = "mpi")]
    pub fn set_fortran_communicator(&self, handle: i32) -> Result<(), Error> {
        let cluster = crate::schedule::cluster::Cluster::from_fortran(handle)?;
        self.put_cluster(Some(cluster));
        Ok(())
    }

    /// Renders in this process alone again; the duplicate communicator is freed (call it from
    /// a thread that may call MPI, on every rank).
    #[cfg(feature = "mpi")]
    pub fn clear_communicator(&self) {
        self.put_cluster(None);
    }

    /// This process's rank in the renderer's communicator and the communicator's size, when it
    /// has one.
    #[cfg(feature = "mpi")]
    pub fn communicator(&self) -> Option<(usize, usize)> {
        let cluster = self.cluster.lock().unwrap_or_else(|e| e.into_inner());
        cluster.as_ref().map(|g| (g.0.rank(), g.0.size()))
    }

    #[cfg(feature = "mpi")]
    fn put_cluster(&self, cluster: Option<crate::schedule::cluster::Cluster>) {
        let old = std::mem::replace(
            &mut *self.cluster.lock().unwrap_or_else(|e| e.into_inner()),
            cluster.map(crate::schedule::guest::Guest),
        );
        drop(old);
    }

    /// `render_with` over the renderer's communicator (collective): every rank commits its
    /// copy of the scene and the ranks agree that all are ready (and render the same size),
    /// then each renders its share; rank 0's target receives the whole image (other ranks'
    /// targets are not written). Every rank returns the same outcome.
    #[cfg(feature = "mpi")]
    fn render_across(
        &self,
        cluster: &crate::schedule::cluster::Cluster,
        scene: &mut Scene,
        target: Target,
        progress: Progress,
    ) -> Result<RenderStats, Error> {
        use crate::framebuffer::Chunk;
        use std::sync::atomic::AtomicU64;
        // No MPI call may be made from this thread otherwise: a local error.
        crate::schedule::guest::usable_here()?;
        self.start();
        let t0 = std::time::Instant::now();
        let (width, height) = (target.width, target.height);
        let ready = target
            .check()
            .map_err(Error::Target)
            .and_then(|_| {
                scene.set_size(width, height);
                scene.commit_pinned(self)
            })
            .map(|_| {
                let depth = u64::from(target.depth.is_some());
                [self.threads() as u64, width.into(), height.into(), depth]
            });
        let target = std::sync::Mutex::new(target);
        let total = u64::from(width) * u64::from(height);
        let done = AtomicU64::new(0);
        let sink = |c: Chunk| {
            let n = c.pixels();
            target
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .put_chunk(&c);
            progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
        };
        let rendered = cluster.settle(ready).and_then(|all| {
            let first = all[0];
            if let Some((r, w)) = all.iter().enumerate().find(|(_, w)| w[1..3] != first[1..3]) {
                return Err(Error::Target(format!(
                    "rank {r}'s target is {}x{} pixels but rank 0's is {}x{}; every rank of the \
                     communicator renders the same image",
                    w[1], w[2], first[1], first[2]
                )));
            }
            let threads: Vec<usize> = all.iter().map(|w| w[0] as usize).collect();
            let depth = first[3] != 0;
            let built = scene.committed()?;
            cluster.render_guest(built, &self.pool, &threads, depth, &self.cancel, &sink)
        });
        scene.unpin();
        if rendered.is_err() {
            scene.after_failure();
        }
        rendered.map(|ranks| RenderStats::of(ranks, t0.elapsed()))
    }

    /// A render starts: a cancel meant for an earlier one is forgotten.
    fn start(&self) {
        self.cancel.store(false, Ordering::SeqCst);
    }
}
