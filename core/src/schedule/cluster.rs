//! Rendering across MPI ranks (feature `mpi`). Every rank builds the whole scene and renders its
//! share on the thread pool it is given (a renderer's); only rank 0 writes outputs (unless
//! MPI-IO).
//!
//! - Static decompositions: workers are numbered across ranks (rank r's threads follow rank
//!   r-1's), so pixel-, scanline- and block-cyclic deal units over every thread of the job.
//! - Dynamic: rank 0 hands out tiles from a counter its own threads also take from; each other
//!   rank keeps `threads + 1` tiles requested (one ahead), asks for one more per finished tile,
//!   and asks further ahead whenever one of its threads had to wait for a tile.
//!
//! All MPI calls are made by each rank's main thread (the thread that called render), which
//! polls (and sleeps briefly: OpenMPI's blocking calls spin and would steal a core from the
//! render threads).
//!
//! Two modes:
//! - **Owner** ([`Cluster::init`], the command line): Luxon initialises MPI with
//!   `MPI_THREAD_MULTIPLE`, renders over the world, and finalises it when the cluster drops. An
//!   error or panic anywhere ends the whole job through `abort::fail` (`MPI_Abort`), after rank
//!   0 has printed the cause.
//! - **Guest** ([`Cluster::from_communicator`], [`Cluster::from_fortran`], a library caller's
//!   MPI): renders over a duplicate of the caller's communicator, never initialises, finalises
//!   or aborts, never touches the world on its own. A failure on a rank stops its rendering; the
//!   ranks still finish the tile protocol (so no message is left behind for the next render),
//!   then agree collectively, and every rank returns the first failing rank's error.

use super::abort::{fail, Injected, TAG_ERROR};
use super::guest;
use super::mailbox::{bytes_of, word, Outbox, TileQueue, POLL};
use super::{decompose, run_share, wire, RankStats, RunOptions, Share, Sink};
use crate::error::Error;
use crate::framebuffer::Chunk;
use crate::scene::Scene;
use luxon_formats::{Decomposition, ParallelMode};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Mutex};

const TAG_REQUEST: i32 = 1;
const TAG_TILE: i32 = 2;
const TAG_DONE: i32 = 3;
const TAG_CHUNK: i32 = 4;
const TAG_FINISHED: i32 = 5;
/// A follower (guest mode) failed and takes no more tiles; rank 0 answers with `TAG_DONE`.
const TAG_GIVE_UP: i32 = 7;

pub struct Cluster {
    /// The world (owner mode) or the duplicate of the caller's communicator (guest mode).
    world: SimpleCommunicator,
    rank: usize,
    size: usize,
    /// Ranks on this node that share this rank's CPUs (including it).
    sharing: usize,
    /// Ranks on this node (they share its memory).
    node_ranks: usize,
    // Dropped last: in owner mode, finalises MPI.
    mode: Mode,
}

enum Mode {
    /// Luxon owns MPI (the command line): it finalises MPI when the universe drops.
    Owner(#[allow(dead_code)] mpi::environment::Universe),
    /// The caller owns MPI; `world` is our duplicate of its communicator.
    Guest,
    /// A group of an owner cluster's ranks ([`Cluster::split`]): failures end the whole job as
    /// in owner mode; the owner finalises MPI.
    Group,
}

impl Drop for Cluster {
    /// Runs before the fields drop (in owner mode the universe finalises MPI: no MPI call after
    /// that). In guest mode the duplicate communicator is freed, unless the caller has already
    /// finalised MPI (then nothing may be called: the handle is forgotten).
    fn drop(&mut self) {
        match self.mode {
            Mode::Owner(_) => super::abort::on_finalize(),
            Mode::Group => {}
            Mode::Guest => {
                if mpi::environment::is_finalized() {
                    let dup = std::mem::replace(&mut self.world, SimpleCommunicator::self_comm());
                    std::mem::forget(dup);
                }
            }
        }
    }
}

/// What [`Cluster::render`] leaves: every rank's statistics (rank 0; others: their own) and the
/// chunks this rank rendered, when asked to keep them.
pub struct Rendered {
    pub ranks: Vec<RankStats>,
    pub kept: Vec<Chunk>,
}

impl Cluster {
    /// Initialises MPI (once per process) and makes a panic anywhere end the whole job.
    pub fn init() -> Result<Cluster, Error> {
        let (universe, threading) = mpi::initialize_with_threading(mpi::Threading::Multiple)
            .ok_or_else(|| Error::Render("MPI was already initialised in this process".into()))?;
        // A failure on any thread reaches rank 0 and ends the job through MPI (`abort`).
        if threading != mpi::Threading::Multiple {
            return Err(Error::Render(format!(
                "the MPI library offers {threading:?} threading, but Luxon needs Multiple \
                 (MPI_THREAD_MULTIPLE)"
            )));
        }
        let world = universe.world();
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        super::abort::on_rank(rank);
        // Ranks bound to the same CPUs share them; ranks bound to other CPUs do not.
        let node = world.split_shared(0);
        let mine = cpu_set_fingerprint();
        let mut all = vec![0u64; node.size() as usize];
        node.all_gather_into(&mine, &mut all[..]);
        let sharing = all.iter().filter(|&&f| f == mine).count().max(1);
        Ok(Cluster {
            world,
            rank,
            size,
            sharing,
            node_ranks: all.len().max(1),
            mode: Mode::Owner(universe),
        })
    }

    /// Guest mode: renders over a duplicate of `comm` (`MPI_Comm_dup`: collective, every rank
    /// of `comm` must call it). MPI must be initialised by the caller (with a thread level that
    /// allows this thread, see [`guest::usable_here`]) and stay so while the cluster lives.
    pub fn from_communicator(comm: &SimpleCommunicator) -> Result<Cluster, Error> {
        guest::usable_here()?;
        Ok(Cluster::guest(comm.duplicate()))
    }

    /// [`Cluster::from_communicator`] for the communicator whose Fortran handle is `handle`
    /// (what C's `MPI_Comm_c2f` gives).
    pub fn from_fortran(handle: i32) -> Result<Cluster, Error> {
        guest::duplicate_fortran(handle).map(Cluster::guest)
    }

    /// Collective over this cluster's ranks: groups of `n` consecutive ranks (the last may be
    /// smaller), each a cluster of its own that renders over its own communicator (so its
    /// messages never meet this cluster's). Drop it before this cluster.
    pub fn split(&self, n: usize) -> Cluster {
        let color = mpi::topology::Color::with_value((self.rank / n.max(1)) as i32);
        let group = self
            .world
            .split_by_color(color)
            .unwrap_or_else(|| fail("MPI_Comm_split gave no communicator"));
        let (rank, size) = (group.rank() as usize, group.size() as usize);
        Cluster {
            world: group,
            rank,
            size,
            sharing: self.sharing,
            node_ranks: self.node_ranks,
            mode: Mode::Group,
        }
    }

    /// Collective: a duplicate of this cluster's communicator, for messages of another protocol.
    pub(super) fn duplicate(&self) -> SimpleCommunicator {
        self.world.duplicate()
    }

    fn guest(world: SimpleCommunicator) -> Cluster {
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        Cluster {
            world,
            rank,
            size,
            sharing: 1,
            node_ranks: 1,
            mode: Mode::Guest,
        }
    }

    pub fn rank(&self) -> usize {
        self.rank
    }

    pub fn size(&self) -> usize {
        self.size
    }

    /// Ranks on this node, this one included.
    pub fn node_ranks(&self) -> usize {
        self.node_ranks
    }

    /// Render threads for this rank: the settings' count, else one in pure MPI mode, else this
    /// rank's share of the CPUs it may run on.
    pub fn threads(&self, scene: &Scene) -> usize {
        self.threads_for(scene.settings.threads, scene.settings.mode)
    }

    /// `threads` for render settings' thread count and mode (known before the scene is built).
    pub fn threads_for(&self, threads: Option<u32>, mode: ParallelMode) -> usize {
        match (threads, mode) {
            (Some(n), _) => n as usize,
            (None, ParallelMode::Mpi) => 1,
            (None, _) => (super::available_cpus() / self.sharing).max(1),
        }
    }

    /// Collective, before rendering: every rank says whether it is ready (with its thread
    /// count). All ready: every rank's thread count. Otherwise rank 0 gets the first failing
    /// rank's error and the other ranks `None` (they should exit quietly).
    pub fn agree(&self, ready: Result<usize, Error>) -> Result<Vec<usize>, Option<Error>> {
        let mine: [u64; 2] = match &ready {
            Ok(t) => [0, *t as u64],
            Err(_) => [1, 0],
        };
        let mut all = vec![0u64; 2 * self.size];
        self.world.all_gather_into(&mine[..], &mut all[..]);
        let Some(bad) = (0..self.size).find(|&r| all[2 * r] == 1) else {
            return Ok((0..self.size).map(|r| all[2 * r + 1] as usize).collect());
        };
        match (self.rank, ready) {
            (0, Err(e)) => Err(Some(e)),
            (0, Ok(_)) => {
                let (bytes, _) = self
                    .world
                    .process_at_rank(bad as i32)
                    .receive_vec_with_tag::<u8>(TAG_ERROR);
                let m = String::from_utf8_lossy(&bytes).to_string();
                Err(Some(Error::Render(format!("rank {bad}: {m}"))))
            }
            (r, Err(e)) if r == bad => {
                let m = e.to_string();
                self.world
                    .process_at_rank(0)
                    .send_with_tag(m.as_bytes(), TAG_ERROR);
                Err(None)
            }
            _ => Err(None),
        }
    }

    /// Renders this rank's share on `pool` (of `threads[rank]` threads). On rank 0, `sink` gets
    /// rank 0's chunks, and every other rank's when `gather`. With `keep`, each rank also
    /// returns the chunks it rendered (for MPI-IO). Any failure ends the job.
    pub fn render(
        &self,
        scene: &Scene,
        pool: &rayon::ThreadPool,
        threads: &[usize],
        gather: bool,
        keep: bool,
        sink: Sink,
    ) -> Rendered {
        let run = Run::new(self, scene, pool, threads, gather, keep);
        if self.rank == 0 {
            run.lead(sink)
        } else {
            run.follow()
        }
    }

    /// Guest mode, collective: whether every rank is ready to render, with `words` of its own
    /// (thread count, image size...). All ready: every rank's words. Otherwise every rank gets
    /// the first failing rank's error: [`Error::Cancelled`] when it was a cancel, else its
    /// message naming the rank.
    pub fn settle<const N: usize>(
        &self,
        mine: Result<[u64; N], Error>,
    ) -> Result<Vec<[u64; N]>, Error> {
        let mut words = vec![0u64; N + 1];
        let mut message = String::new();
        match &mine {
            Ok(w) => words[1..].copy_from_slice(w),
            Err(Error::Cancelled) => words[0] = 2,
            Err(e) => {
                words[0] = 1;
                message = e.to_string();
            }
        }
        let mut all = vec![0u64; (N + 1) * self.size];
        mpi::request::scope(|scope| {
            patiently(
                self.world
                    .immediate_all_gather_into(scope, &words[..], &mut all[..]),
            )
        });
        let rows: Vec<&[u64]> = all.chunks_exact(N + 1).collect();
        let Some(bad) = rows.iter().position(|r| r[0] != 0) else {
            return Ok(rows
                .iter()
                .map(|r| {
                    let mut w = [0u64; N];
                    w.copy_from_slice(&r[1..]);
                    w
                })
                .collect());
        };
        if rows[bad][0] == 2 {
            return Err(Error::Cancelled);
        }
        let root = self.world.process_at_rank(bad as i32);
        let mut bytes = message.into_bytes();
        let mut len = bytes.len() as u64;
        root.broadcast_into(&mut len);
        bytes.resize(len as usize, 0);
        root.broadcast_into(&mut bytes[..]);
        let m = String::from_utf8_lossy(&bytes);
        Err(Error::Render(format!("rank {bad}: {m}")))
    }

    /// Guest mode, collective: renders this rank's share on `pool` (of `threads[rank]`
    /// threads); rank 0's `sink` gets every rank's chunks (with depth when `depth`). `cancel`
    /// (this rank's renderer's) stops this rank's part. Every rank returns the same outcome:
    /// its statistics (rank 0: every rank's), or the first failing rank's error.
    pub fn render_guest(
        &self,
        scene: &Scene,
        pool: &rayon::ThreadPool,
        threads: &[usize],
        depth: bool,
        cancel: &AtomicBool,
        sink: Sink,
    ) -> Result<Vec<RankStats>, Error> {
        let mut run = Run::new(self, scene, pool, threads, true, false);
        run.depth = depth;
        run.cancel = Some(cancel);
        let rendered = if self.rank == 0 {
            run.lead(sink)
        } else {
            run.follow()
        };
        let failure = run.failure.into_inner().map_or(Ok([]), Err);
        self.settle::<0>(failure).map(|_| rendered.ranks)
    }

    /// Whether this cluster renders over a caller's communicator.
    pub fn is_guest(&self) -> bool {
        matches!(self.mode, Mode::Guest)
    }

    /// Collective: rank 0's process id, so every rank names the same temporary file.
    /// Collective: rank 0's `path` (`Some` there), on every rank.
    pub fn broadcast_path(&self, path: Option<&std::path::Path>) -> std::path::PathBuf {
        use std::os::unix::ffi::OsStrExt;
        let root = self.world.process_at_rank(0);
        let mut bytes = path.map_or(Vec::new(), |p| p.as_os_str().as_bytes().to_vec());
        let mut len = bytes.len() as u64;
        root.broadcast_into(&mut len);
        bytes.resize(len as usize, 0);
        root.broadcast_into(&mut bytes[..]);
        std::path::PathBuf::from(std::ffi::OsStr::from_bytes(&bytes))
    }

    /// Collective: rank 0's `value`, on every rank. A frame group's members wait here for the
    /// next frame while their leader finishes its tiles, so the wait must not spin.
    pub fn broadcast_u64(&self, value: u64) -> u64 {
        let mut v = value;
        let root = self.world.process_at_rank(0);
        mpi::request::scope(|scope| patiently(root.immediate_broadcast_into(scope, &mut v)));
        v
    }

    pub fn barrier(&self) {
        patiently(self.world.immediate_barrier());
    }

    /// Collective: writes this rank's pixels of an 8-bit PPM into `tmp` with MPI-IO (rank 0 adds
    /// the header).
    pub fn write_ppm(&self, tmp: &std::path::Path, width: u32, height: u32, mine: &[Chunk]) {
        let header = if self.rank == 0 {
            crate::ppm::ppm_header(width, height)
        } else {
            Vec::new()
        };
        if let Err(e) = super::mpi_io::write_ppm(&self.world, tmp, &header, width, height, mine) {
            fail(&format!("{}: MPI-IO: {e}", tmp.display()));
        }
    }
}

/// One render of this rank's share.
struct Run<'a> {
    cluster: &'a Cluster,
    scene: &'a Scene,
    pool: &'a rayon::ThreadPool,
    tiles: Vec<decompose::Rect>,
    threads: &'a [usize],
    gather: bool,
    keep: bool,
    depth: bool,
    injected: Injected,
    /// Guest mode: the caller's cancel flag, copied into `stop` when seen.
    cancel: Option<&'a AtomicBool>,
    /// Stops this rank's render threads (guest mode, after a failure or cancel).
    stop: AtomicBool,
    /// Guest mode: this rank's first failure (owner mode ends the job instead).
    failure: RefCell<Option<Error>>,
}

impl<'a> Run<'a> {
    fn new(
        cluster: &'a Cluster,
        scene: &'a Scene,
        pool: &'a rayon::ThreadPool,
        threads: &'a [usize],
        gather: bool,
        keep: bool,
    ) -> Run<'a> {
        let s = &scene.settings;
        Run {
            cluster,
            scene,
            pool,
            tiles: decompose::tiles(s.width, s.height, s.tile_size),
            threads,
            gather,
            keep,
            depth: false,
            injected: Injected::from_env(cluster.rank),
            cancel: None,
            stop: AtomicBool::new(false),
            failure: RefCell::new(None),
        }
    }

    fn options(&self) -> RunOptions<'_> {
        RunOptions {
            cancel: &self.stop,
            depth: self.depth,
        }
    }

    /// A failure on this rank: owner mode ends the job; guest mode records the first one and
    /// stops this rank's render threads.
    fn failed(&self, e: Error) {
        if !self.cluster.is_guest() {
            fail(&e.to_string());
        }
        self.stop.store(true, Ordering::Relaxed);
        self.failure.borrow_mut().get_or_insert(e);
    }

    fn has_failed(&self) -> bool {
        self.failure.borrow().is_some()
    }

    fn share<'s>(&'s self, next: &'s (dyn Fn() -> Option<usize> + Sync)) -> Share<'s> {
        let rank = self.cluster.rank;
        match self.scene.settings.decomposition {
            Decomposition::Dynamic => Share::Queue {
                tiles: &self.tiles,
                next,
            },
            how => Share::Static {
                how,
                first: self.threads[..rank].iter().sum(),
                workers: self.threads.iter().sum(),
            },
        }
    }

    /// A plugin fault, an injected failure (tests) or the caller's cancel.
    fn check(&self) {
        if let Some(m) = self.scene.customs.fault.message() {
            self.failed(Error::Plugin(m));
        }
        if self.injected.raised.load(Ordering::Relaxed) {
            self.failed(Error::Render(
                "injected failure (LUXON_TEST_FAIL_RANK)".into(),
            ));
        }
        if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            self.failed(Error::Cancelled);
        }
    }

    /// Rank 0: renders, hands out tiles, takes chunks and statistics from the other ranks.
    fn lead(&self, sink: Sink) -> Rendered {
        let world = &self.cluster.world;
        let size = self.cluster.size;
        // The closures handed to render threads borrow fields, never `self` (MPI handles are
        // not Sync).
        let (tiles, injected, keep) = (&self.tiles, &self.injected, self.keep);
        let counter = AtomicUsize::new(0);
        let take = || {
            let i = counter.fetch_add(1, Ordering::Relaxed);
            (i < tiles.len()).then_some(i)
        };
        let kept = Mutex::new(Vec::new());
        let local_sink = |c: Chunk| {
            injected.on_chunk();
            if keep {
                kept.lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(c.clone());
            }
            sink(c);
        };
        let share = self.share(&take);
        let mut stats: Vec<Option<RankStats>> = vec![None; size];
        let mut done_sent = vec![false; size];
        let mut finished = 0;
        let options = self.options();
        std::thread::scope(|sc| {
            let (scene, pool) = (self.scene, self.pool);
            let local = sc.spawn(|| run_share(scene, pool, share, options, &local_sink));
            loop {
                while let Some((msg, status)) = world.any_process().immediate_matched_probe() {
                    let (from, tag) = (status.source_rank(), status.tag());
                    let (bytes, _) = (msg, status).matched_receive_vec::<u8>();
                    let to = world.process_at_rank(from);
                    match tag {
                        TAG_GIVE_UP if !done_sent[from as usize] => {
                            done_sent[from as usize] = true;
                            to.send_with_tag(&bytes_of(0)[..], TAG_DONE);
                        }
                        TAG_REQUEST => {
                            for _ in 0..word(&bytes) {
                                match take() {
                                    Some(i) => to.send_with_tag(&bytes_of(i as u64)[..], TAG_TILE),
                                    None if !done_sent[from as usize] => {
                                        done_sent[from as usize] = true;
                                        to.send_with_tag(&bytes_of(0)[..], TAG_DONE);
                                    }
                                    None => {}
                                }
                            }
                        }
                        TAG_CHUNK if self.gather => match wire::decode_chunk(&bytes) {
                            Some(c) => sink(c),
                            None => self
                                .failed(Error::Render(format!("rank {from} sent a corrupt chunk"))),
                        },
                        TAG_FINISHED => {
                            let s = wire::decode_stats(&bytes);
                            if s.is_none() {
                                self.failed(Error::Render(format!(
                                    "rank {from} sent corrupt statistics"
                                )));
                            }
                            stats[from as usize] = s;
                            finished += 1;
                        }
                        TAG_ERROR => {
                            let m = String::from_utf8_lossy(&bytes);
                            fail(&format!("rank {from}: {m}"));
                        }
                        _ => {}
                    }
                }
                self.check();
                if self.has_failed() {
                    // The render fails anyway: hand out no more tiles (here or to any rank).
                    counter.store(tiles.len(), Ordering::Relaxed);
                }
                if finished == size - 1 && local.is_finished() {
                    break;
                }
                std::thread::sleep(POLL);
            }
            let mine = local.join();
            if self.cluster.is_guest() {
                self.injected.on_end();
            }
            if mine.is_err() {
                self.failed(Error::Render("a render thread panicked".into()));
            }
            self.check();
            stats[0] = mine.ok();
        });
        let ranks = stats
            .into_iter()
            .enumerate()
            .map(|(rank, s)| RankStats {
                rank,
                ..s.unwrap_or_default()
            })
            .collect();
        Rendered {
            ranks,
            kept: kept.into_inner().unwrap_or_else(|e| e.into_inner()),
        }
    }

    /// Ranks above 0: render, send chunks (when gathering) and statistics to rank 0; for the
    /// dynamic decomposition, keep `threads + 1` tiles requested.
    fn follow(&self) -> Rendered {
        let (tx, chunks) = mpsc::channel();
        let injected = &self.injected;
        let to_main = move |c: Chunk| {
            injected.on_chunk();
            let _ = tx.send(c);
        };
        let queue = TileQueue::default();
        let next = || queue.pop();
        let share = self.share(&next);
        let dynamic = matches!(share, Share::Queue { .. });
        let root = self.cluster.world.process_at_rank(0);
        let mut kept = Vec::new();
        let mut outbox = Outbox::new(&self.cluster.world);
        let mut no_more_tiles = !dynamic;
        // Tiles requested and not finished: every thread's plus at least one ahead.
        let threads = self.threads[self.cluster.rank];
        let (mut ahead, max_ahead) = (threads + 1, 4 * threads + 8);
        if dynamic {
            root.send_with_tag(&bytes_of(ahead as u64)[..], TAG_REQUEST);
        }
        let options = self.options();
        let mut gave_up = false;
        let stats = std::thread::scope(|sc| {
            let (scene, pool) = (self.scene, self.pool);
            let local = sc.spawn(|| run_share(scene, pool, share, options, &to_main));
            loop {
                let finished = local.is_finished();
                match chunks.recv_timeout(POLL) {
                    Ok(c) => {
                        if self.gather {
                            if let Err(m) = outbox.send(wire::encode_chunk(&c), TAG_CHUNK) {
                                self.failed(Error::Render(m));
                            }
                        }
                        if !no_more_tiles {
                            // One more for the finished tile, and one further ahead when a
                            // render thread had to wait (the round trip took longer than the
                            // tiles in hand).
                            let mut more = 1;
                            if queue.starved.swap(0, Ordering::Relaxed) > 0 && ahead < max_ahead {
                                ahead += 1;
                                more += 1;
                            }
                            root.send_with_tag(&bytes_of(more)[..], TAG_REQUEST);
                        }
                        if self.keep {
                            kept.push(c);
                        }
                    }
                    // Every chunk is sent before the render threads finish, and every tile
                    // message before rank 0's TAG_DONE (none is left for the next render).
                    Err(_) if finished && no_more_tiles => break,
                    Err(_) => {}
                }
                while let Some((msg, status)) = root.immediate_matched_probe() {
                    let tag = status.tag();
                    let (bytes, _) = (msg, status).matched_receive_vec::<u8>();
                    match tag {
                        TAG_TILE => queue.push(word(&bytes) as usize),
                        TAG_DONE => {
                            no_more_tiles = true;
                            queue.close();
                        }
                        _ => {}
                    }
                }
                outbox.progress();
                self.check();
                if self.has_failed() && !gave_up {
                    // Guest mode: stop taking tiles; rank 0 answers with TAG_DONE.
                    gave_up = true;
                    queue.close();
                    if !no_more_tiles {
                        root.send_with_tag(&bytes_of(0)[..], TAG_GIVE_UP);
                    }
                }
            }
            local.join()
        });
        if self.cluster.is_guest() {
            self.injected.on_end();
        }
        let mut stats = stats.unwrap_or_else(|_| {
            self.failed(Error::Render("a render thread panicked".into()));
            RankStats::default()
        });
        self.check();
        outbox.flush();
        stats.rank = self.cluster.rank;
        root.send_with_tag(&wire::encode_stats(&stats)[..], TAG_FINISHED);
        Rendered {
            ranks: vec![stats],
            kept,
        }
    }
}

/// Waits for a non-blocking collective, testing it every [`POLL`]. OpenMPI's blocking
/// collectives spin, so a rank that has finished its part would take a core from the ranks
/// still rendering on its node (93 % of a member's loop was such a wait at `--frame-groups 2`).
fn patiently<'a, D: ?Sized, S: mpi::request::Scope<'a>>(
    mut request: mpi::request::Request<'a, D, S>,
) {
    loop {
        match request.test() {
            Ok(_) => return,
            Err(pending) => {
                request = pending;
                std::thread::sleep(POLL);
            }
        }
    }
}

/// A fingerprint of the CPUs this process may run on (Linux; elsewhere every rank's is equal).
fn cpu_set_fingerprint() -> u64 {
    use std::hash::{Hash, Hasher};
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let line = status
        .lines()
        .find(|l| l.starts_with("Cpus_allowed_list:"))
        .unwrap_or("");
    let mut h = std::collections::hash_map::DefaultHasher::new();
    line.hash(&mut h);
    h.finish()
}
