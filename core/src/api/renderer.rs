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
pub struct Renderer {
    pub(super) pool: Arc<rayon::ThreadPool>,
    cancel: Arc<AtomicBool>,
}

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

    /// A render starts: a cancel meant for an earlier one is forgotten.
    fn start(&self) {
        self.cancel.store(false, Ordering::SeqCst);
    }
}
