//! `luxon render`: load, override from the command line, build, render (in this process or as
//! one rank of an MPI job), write.

use super::job::Job;
use super::progress::Progress;
use luxon::api::{self, Context, ContextOptions, Renderer, RendererOptions};
use luxon::budget::{Budget, Use};
use luxon::cache::{self, Lookup};
use luxon::framebuffer::Chunk;
use luxon::output::inputs::SceneFile;
use luxon::output::stream::{is_ppm8, AsyncOutput};
use luxon::output::{Output, OutputSet};
use luxon::plugin::Registry;
use luxon::render::RenderStats;
use luxon::scene::Settings;
use luxon::schedule::RankStats;
use luxon::{Error, Framebuffer, Scene};
use luxon_formats::{
    Decomposition, FrameGroups, InlineGeometry, MemorySize, Origin, OutputDesc, OutputIo,
    ParallelMode, RenderDesc, SceneDesc,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// `--adaptive`: settings, or `None` for off.
#[derive(Clone, Debug)]
pub struct AdaptiveArg(pub Option<luxon_formats::AdaptiveDesc>);

/// What the command line can change in a scene's render settings.
#[derive(clap::Args, Default)]
pub struct Overrides {
    /// Output file(s); the writer is chosen by extension. Replaces the scene's outputs.
    #[arg(short, long = "output")]
    pub output: Vec<PathBuf>,
    /// Resolution as WIDTHxHEIGHT.
    #[arg(long, value_parser = super::parse_res)]
    pub res: Option<(u32, u32)>,
    /// Samples per pixel.
    #[arg(long)]
    pub samples: Option<u32>,
    /// Adaptive supersampling: split the pixel cells whose samples differ by more than
    /// THRESHOLD (colour, 0..1), at most DEPTH times (default 3); `off` turns a scene's off.
    #[arg(long, value_name = "THRESHOLD[:DEPTH]", value_parser = parse_adaptive)]
    pub adaptive: Option<AdaptiveArg>,
    /// Render threads per process (default: every CPU; with MPI, the rank's share of them).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Memory budget: a size (512M, 6G, "1.5 GiB") or a share of the machine's memory (50%);
    /// replaces the scene's `memory`. Default: 75% of the machine's limit, at most 90% of
    /// what is free, shared by the MPI ranks of a node.
    #[arg(long, value_name = "SIZE", value_parser = super::parse_memory)]
    pub memory: Option<MemorySize>,
    /// Print rays cast per kind, intersection tests, timings and the work of every rank and
    /// thread.
    #[arg(long)]
    pub stats: bool,
    /// Neither read nor write the binary geometry cache of an NFF scene.
    #[arg(long, conflicts_with = "cache")]
    pub no_cache: bool,
    /// Write the geometry cache of an NFF scene whatever its size (by default only scenes
    /// of 100,000 primitives or more get one).
    #[arg(long)]
    pub cache: bool,
    /// Parallel mode: threads in one process, MPI ranks (one thread each), or both.
    #[arg(long, value_parser = ["threads", "mpi", "hybrid"])]
    pub parallel: Option<String>,
    /// How pixels are dealt to threads and ranks.
    #[arg(long, value_parser = ["pixel-cyclic", "scanline-cyclic", "block-cyclic", "dynamic"])]
    pub decomposition: Option<String>,
    /// Edge in pixels of dynamic tiles and block-cyclic blocks.
    #[arg(long = "block-size", alias = "tile-size")]
    pub block_size: Option<u32>,
    /// Output: written while rendering, after it, or by every MPI rank (8-bit PPM).
    #[arg(long, value_parser = ["async", "sync", "mpi-io"])]
    pub io: Option<String>,
    /// How MPI ranks share a sequence's frames: each rank whole frames, groups of N ranks
    /// sharing each frame, or every rank on every frame (default: whole when there are at
    /// least as many frames as ranks, else shared).
    #[arg(long, value_name = "whole|shared|N", value_parser = parse_frame_groups)]
    pub frame_groups: Option<FrameGroups>,
    #[command(flatten)]
    pub shading: super::shading::ShadingArgs,
    /// Frames of an animated scene to render, A to B inclusive (or one frame K); default:
    /// the scene's `animation: (frames: ...)`. Frames done by an earlier run (recorded in
    /// `.NAME.luxon-frames/` beside the first output) are skipped, and processes started on
    /// the same outputs share the frames.
    #[arg(long, value_name = "A..B|K", value_parser = super::sequence::parse_frames)]
    pub frames: Option<(u32, u32)>,
    /// Render every Nth frame from the first (with an animated scene).
    #[arg(long, value_name = "N")]
    pub step: Option<u32>,
    /// Render every frame again, even those a completion record says are done (an animated
    /// scene; by default a sequence renders only the frames missing or stale).
    #[arg(long)]
    pub force: bool,
    /// Also write an animation of the frames (at most 320 pixels wide) to FILE: `.png` for
    /// an animated PNG, `.gif` for a GIF (an animated scene).
    #[arg(long, value_name = "FILE")]
    pub preview: Option<PathBuf>,
}

fn parse_frame_groups(s: &str) -> Result<FrameGroups, String> {
    match s {
        "whole" => Ok(FrameGroups::Whole),
        "shared" => Ok(FrameGroups::Shared),
        n => match n.parse::<u32>() {
            Ok(n) if (1..=65536).contains(&n) => Ok(FrameGroups::Groups(n)),
            _ => Err(format!(
                "`{n}`: expected whole, shared or a number of ranks per group (1 to 65536)"
            )),
        },
    }
}

fn parse_adaptive(s: &str) -> Result<AdaptiveArg, String> {
    luxon::adaptive::parse(s, 3).map(AdaptiveArg)
}

pub fn cli_origin(what: &str) -> Origin {
    Origin {
        file: Arc::new(PathBuf::from(format!("<command line {what}>"))),
        line: 1,
        col: 1,
    }
}

/// Scenes with fewer primitives load in well under a second without a cache.
const CACHE_MIN_PRIMITIVES: usize = 100_000;

/// Loads the scene within the memory budget of `--memory` (or the machine's), shared by
/// `node_ranks` processes; `skeleton`: the non-geometry lines of an NFF file from its geometry
/// cache.
/// `read`: the RON scene files read, for the inputs hash of a sequence's frames.
pub(super) fn load(
    path: &Path,
    o: &Overrides,
    node_ranks: usize,
    skeleton: Option<&str>,
    read: &mut Vec<SceneFile>,
) -> Result<SceneDesc, Error> {
    let mut desc = match skeleton {
        Some(text) => luxon_formats::nff::parse_str(text, path)?.desc,
        None => {
            let options = Budget::for_load(o.memory, node_ranks).load_options();
            let ron = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("ron"));
            if ron {
                let mut source = Recorder { read };
                luxon_formats::load_ron_with(&mut source, path, &options)?
            } else {
                luxon_formats::load_with(path, &options)?
            }
        }
    };
    o.shading.apply(&mut desc)?;
    let r = &mut desc.render;
    if let Some((w, h)) = o.res {
        r.width = w;
        r.height = h;
    }
    if let Some(n) = o.samples {
        if n == 0 || n > 65536 {
            return Err(Error::Usage(format!("--samples {n}: expected 1..=65536")));
        }
        r.samples = n;
    }
    if let Some(a) = &o.adaptive {
        r.adaptive = a.0;
    }
    if let Some(n) = o.threads {
        if n == 0 || n > 4096 {
            return Err(Error::Usage(format!("--threads {n}: expected 1..=4096")));
        }
        r.parallel.threads = Some(n);
    }
    if let Some(n) = o.block_size {
        if n == 0 || n > 4096 {
            return Err(Error::Usage(format!("--block-size {n}: expected 1..=4096")));
        }
        r.parallel.tile_size = n;
    }
    // clap has checked the names.
    match o.parallel.as_deref() {
        Some("threads") => r.parallel.mode = ParallelMode::Threads,
        Some("mpi") => r.parallel.mode = ParallelMode::Mpi,
        Some("hybrid") => r.parallel.mode = ParallelMode::Hybrid,
        _ => {}
    }
    match o.decomposition.as_deref() {
        Some("pixel-cyclic") => r.parallel.decomposition = Decomposition::PixelCyclic,
        Some("scanline-cyclic") => r.parallel.decomposition = Decomposition::ScanlineCyclic,
        Some("block-cyclic") => r.parallel.decomposition = Decomposition::BlockCyclic,
        Some("dynamic") => r.parallel.decomposition = Decomposition::Dynamic,
        _ => {}
    }
    if let Some(g) = o.frame_groups {
        r.parallel.frames = g;
    }
    match o.io.as_deref() {
        Some("async") => r.parallel.io = OutputIo::Async,
        Some("sync") => r.parallel.io = OutputIo::Sync,
        Some("mpi-io") => r.parallel.io = OutputIo::MpiIo,
        _ => {}
    }
    if !o.output.is_empty() {
        r.outputs = o
            .output
            .iter()
            .map(|p| OutputDesc {
                path: p.clone(),
                plugin: None,
                params: "()".into(),
                params_at: cli_origin("-o"),
            })
            .collect();
    }
    if r.outputs.is_empty() {
        return Err(Error::Usage(format!(
            "{} has no outputs; give one with -o FILE.png or add `outputs: [(path: \"out.png\")]` to its render settings",
            path.display()
        )));
    }
    Ok(desc)
}

/// Scene files from the disk, each recorded as it is read.
struct Recorder<'a> {
    read: &'a mut Vec<SceneFile>,
}

impl luxon_formats::Source for Recorder<'_> {
    fn key(&self, path: &Path) -> PathBuf {
        luxon_formats::DiskSource.key(path)
    }

    fn read(&mut self, path: &Path, max: u64) -> Result<String, luxon_formats::input::FileError> {
        let text = luxon_formats::DiskSource.read(path, max)?;
        self.read.push(SceneFile::new(path, &text));
        Ok(text)
    }
}

/// How rank 0 writes: outputs split between its writer (async or after the render) and MPI-IO,
/// each with its index in the output set.
pub(super) struct Plan<'r> {
    written_by_root: Vec<(usize, Output<'r>)>,
    concurrent: Vec<(usize, Output<'r>)>,
    /// Rank 0: every output's temporary file, created before anything is built or rendered (so
    /// an unwritable path fails at once); `None` while the stream writer has it.
    files: Option<OutputSet>,
    streams: Option<AsyncOutput<'r>>,
}

pub(super) fn plan<'r>(
    r: &RenderDesc,
    outputs: Vec<Output<'r>>,
    job: &Job,
    registry: &Registry,
    scene_dir: &Path,
    budget: &Arc<Budget>,
) -> Result<Plan<'r>, Error> {
    let io = r.parallel.io;
    let mpi_io = io == OutputIo::MpiIo && matches!(job, Job::Mpi(_));
    let mut files = match job.rank() {
        0 => Some(OutputSet::prepare(&outputs, registry, scene_dir)?),
        _ => None,
    };
    let (concurrent, written_by_root): (Vec<_>, Vec<_>) = outputs
        .into_iter()
        .enumerate()
        .partition(|(_, o)| mpi_io && is_ppm8(o));
    let streams = match (files.take(), io) {
        (Some(set), OutputIo::Async | OutputIo::MpiIo) if !written_by_root.is_empty() => Some(
            AsyncOutput::new(written_by_root.clone(), set, r.width, r.height, budget)?,
        ),
        (set, _) => {
            files = set;
            None
        }
    };
    Ok(Plan {
        written_by_root,
        concurrent,
        files,
        streams,
    })
}

/// `luxon render`: the stages below, in order. Every rank runs them; only rank 0 reports.
pub fn run(path: &Path, o: &Overrides) -> Result<(), Error> {
    let t0 = Instant::now();
    let job = Job::from_launcher()?;
    let mut cache = CacheUse::new(path, o);
    let cached = cache.open(path);
    let skeleton = cached.as_ref().map(|c| c.skeleton.as_str());
    let mut read = Vec::new();
    let desc = load(path, o, job.node_ranks(), skeleton, &mut read);
    let job = match &desc {
        Ok(d) => job.for_mode(d.render.parallel.mode)?,
        Err(_) => job,
    };
    let (plugin_path, threads) = match &desc {
        Ok(d) => (d.plugin_path.clone(), job.threads(&d.render)),
        Err(_) => (Vec::new(), 1),
    };
    // The context's pool renders and builds (never rayon's global pool).
    let ctx = Context::new(ContextOptions {
        plugin_path,
        threads,
    })?;
    let renderer = Renderer::new(&ctx, RendererOptions::default())?;
    let registry = ctx.registry();
    if job.rank() == 0 {
        super::warn_skipped(registry);
        if let Ok(d) = &desc {
            super::warn_scene(d);
        }
    }
    let load_time = t0.elapsed();
    let animated = desc.as_ref().is_ok_and(|d| d.animation.is_some());
    if animated || o.frames.is_some() || o.step.is_some() || o.force || o.preview.is_some() {
        return super::sequence::run(o, desc, &read, &ctx, &renderer, job, t0);
    }
    let ready =
        desc.and_then(|desc| prepare(path, o, desc, cached, &ctx, &renderer, &job, &mut cache));
    let (ready, status) = match ready {
        Ok(r) => (Some(r), Ok(renderer.threads())),
        Err(e) => (None, Err(e)),
    };
    let threads = match job.agree(status) {
        Ok(t) => t,
        Err(Some(e)) => return Err(e),
        Err(None) => job.exit_quietly(),
    };
    let Some((mut scene, plan)) = ready else {
        return Err(Error::Render("not ready to render".into()));
    };
    let scene_dir = scene_dir_of(scene.desc());
    let written = write_image(
        &mut scene, plan, &job, &renderer, &threads, registry, &scene_dir,
    )?;
    let Some(image) = written else {
        return Ok(());
    };
    let scene = built(&scene)?;
    let Image {
        written,
        stats,
        write_time,
    } = image;
    let total = t0.elapsed();
    // After the image: writing the cache delays no picture.
    let cache_written = cache.write_after(path, scene);
    if o.stats {
        print_stats(scene, &job, &stats, load_time, write_time, total);
        eprintln!("  geometry cache   {}", cache.note);
    }
    for w in written {
        eprintln!("luxon: wrote {}", w.display());
    }
    if let Some(p) = cache_written {
        eprintln!("luxon: wrote geometry cache {}", p.display());
    }
    warn_nan(scene, &stats);
    Ok(())
}

/// Where a scene's relative paths start.
pub(super) fn scene_dir_of(desc: &SceneDesc) -> PathBuf {
    desc.source.parent().unwrap_or(Path::new(".")).to_path_buf()
}

/// The built form of a committed scene.
pub(super) fn built(scene: &api::Scene) -> Result<&Scene, Error> {
    scene
        .built()
        .ok_or_else(|| Error::Render("the scene is not built".into()))
}

/// What rank 0 has after writing an image.
pub(super) struct Image {
    pub written: Vec<PathBuf>,
    pub stats: RenderStats,
    pub write_time: Duration,
}

/// Warns when pixels came out NaN or infinite, and names each plugin instance that gave NaN.
pub(super) fn warn_nan(scene: &Scene, stats: &RenderStats) {
    if stats.counters.nan_pixels > 0 {
        luxon::error::print_warning(&format!(
            "{} pixel(s) came out NaN or infinite and were set to black",
            stats.counters.nan_pixels
        ));
    }
    for w in scene.nan_warnings(&stats.nan_sources) {
        luxon::error::print_warning(&w);
    }
}

/// Renders `scene` on every rank and writes its outputs as `plan` says, all or none; rank 0
/// gets what it wrote, the other ranks `None`.
pub(super) fn write_image(
    scene: &mut api::Scene,
    plan: Plan,
    job: &Job,
    renderer: &Renderer,
    threads: &[usize],
    registry: &Registry,
    scene_dir: &Path,
) -> Result<Option<Image>, Error> {
    let s = &built(scene)?.settings.clone();
    let Plan {
        written_by_root,
        concurrent,
        files,
        streams,
    } = plan;
    let gather = !written_by_root.is_empty();
    let keep = !concurrent.is_empty();
    let shares = Shares {
        threads,
        gather,
        keep,
    };
    let r = render(scene, job, renderer, &shares, streams, registry, scene_dir)?;

    let t_write = Instant::now();
    // Rank 0's output files: kept here, or back from the stream writer.
    let files = files.or(r.files);
    for (i, _) in &concurrent {
        if let Some(f) = &files {
            f.unlock(*i);
        }
        let tmp = files.as_ref().map(|f| f.temp_path(*i));
        job.write_concurrent(tmp, s.width, s.height, &r.kept)?;
    }
    if job.rank() != 0 {
        return Ok(None);
    }
    let mut files = files.ok_or_else(|| Error::Render("the output files are missing".into()))?;
    if let Some(fb) = r.sync_fb {
        for (i, o) in &written_by_root {
            files.encode(*i, o, &fb, registry, scene_dir)?;
        }
    }
    // The commit point: every output complete, all renamed together.
    let written = files.commit()?;
    let write_time = r.tail + t_write.elapsed();
    let stats = RenderStats::of(r.ranks, r.render_time);
    Ok(Some(Image {
        written,
        stats,
        write_time,
    }))
}

/// The geometry cache of an NFF scene during one render: whether it is used, what became of it
/// (for `--stats`), and whether to write it once the image is out.
struct CacheUse {
    on: bool,
    note: String,
    write: bool,
}

impl CacheUse {
    fn new(path: &Path, o: &Overrides) -> CacheUse {
        let on = !o.no_cache && luxon_formats::nff::is_nff_path(path);
        CacheUse {
            on,
            note: if on { "not used" } else { "off" }.to_string(),
            write: false,
        }
    }

    /// The scene's cache when it is valid; warns about a corrupt one (it is rebuilt).
    fn open(&self, path: &Path) -> Option<Box<cache::Cached>> {
        if !self.on {
            return None;
        }
        match cache::open(path) {
            Lookup::Hit(c) => Some(c),
            Lookup::Miss => None,
            Lookup::Corrupt(p, why) => {
                luxon::error::print_warning(&format!(
                    "geometry cache {} is unusable ({why}); rebuilding it",
                    p.display()
                ));
                None
            }
        }
    }

    /// Writes the cache when the build asked for it; the file written.
    fn write_after(&mut self, path: &Path, scene: &Scene) -> Option<PathBuf> {
        if !self.write {
            return None;
        }
        let result = luxon_formats::nff::skeleton(path)
            .map_err(|e| e.to_string())
            .and_then(|sk| cache::write(path, &sk, scene).map_err(|e| e.to_string()));
        match result {
            Ok(p) => {
                self.note = format!("written to {}", p.display());
                Some(p)
            }
            Err(e) => {
                self.note = format!("could not be written: {e}");
                None
            }
        }
    }
}

/// Builds the scene (from the geometry cache when it fits the scene, else from the source) on
/// the renderer's pool, resolves its outputs and plans who writes them.
#[allow(clippy::too_many_arguments)]
fn prepare<'r>(
    path: &Path,
    o: &Overrides,
    desc: SceneDesc,
    cached: Option<Box<cache::Cached>>,
    ctx: &'r Context,
    renderer: &Renderer,
    job: &Job,
    cache: &mut CacheUse,
) -> Result<(api::Scene, Plan<'r>), Error> {
    let registry = ctx.registry();
    // Outputs first: an unwritable path or a writer's bad parameter fails before any work.
    let outputs = luxon::output::resolve(&desc.render.outputs, registry)?;
    let scene_dir = scene_dir_of(&desc);
    let budget = Budget::for_render(&desc.render, o.memory, job.node_ranks());
    let budget = Arc::new(budget);
    let plan = plan(&desc.render, outputs, job, registry, &scene_dir, &budget)?;
    let had_objects = !(desc.objects.is_empty() && desc.instances.is_empty());
    let scene = match cached {
        Some(c) => {
            let cache::Cached {
                path: from,
                geometry,
                ..
            } = *c;
            let mut scene = api::Scene::from_prebuilt(ctx, desc, geometry)?;
            scene.set_budget(budget.clone());
            match scene.commit(renderer) {
                Ok(_) => {
                    cache.note = format!("read {}", from.display());
                    scene
                }
                Err(_) => {
                    // The cache's view of the scene did not fit: read the source itself.
                    drop(scene);
                    let desc = load(path, o, job.node_ranks(), None, &mut Vec::new())?;
                    build_source(desc, ctx, renderer, &budget, o, cache, had_objects)?
                }
            }
        }
        None => build_source(desc, ctx, renderer, &budget, o, cache, had_objects)?,
    };
    Ok((scene, plan))
}

/// Builds the scene from its source, consuming its imported geometry group by group, and says
/// whether to write its geometry cache afterwards.
fn build_source(
    desc: SceneDesc,
    ctx: &Context,
    renderer: &Renderer,
    budget: &Arc<Budget>,
    o: &Overrides,
    cache: &mut CacheUse,
    had_objects: bool,
) -> Result<api::Scene, Error> {
    // Held until the build has taken the imported geometry into the scene's arrays.
    let held = desc.inline.iter().map(InlineGeometry::bytes).sum();
    let imported = budget.charge(Use::Import, held, || {
        format!("the geometry imported from `{}`", desc.source.display())
    })?;
    let mut scene = api::Scene::from_desc_frozen(ctx, desc)?;
    scene.set_budget(budget.clone());
    scene.commit(renderer)?;
    drop(imported);
    let built = built(&scene)?;
    cache.write = cache.on
        && (o.cache || built.primitive_count() >= CACHE_MIN_PRIMITIVES)
        && cache::cacheable(built, had_objects);
    Ok(scene)
}

/// How the ranks share the render: threads per rank, whether rank 0 gathers every rank's
/// pixels, whether each rank keeps its own (for concurrent output).
struct Shares<'a> {
    threads: &'a [usize],
    gather: bool,
    keep: bool,
}

/// What the render phase leaves: every rank's work (on rank 0), this rank's chunks when kept,
/// the output files the writer thread completed, the image for a synchronous write, and how long the
/// render took and the writer went on after it.
struct Rendered {
    ranks: Vec<RankStats>,
    kept: Vec<Chunk>,
    /// The output files, back from the stream writer (which completed them).
    files: Option<OutputSet>,
    sync_fb: Option<Framebuffer>,
    render_time: Duration,
    tail: Duration,
}

/// Renders this rank's share with a progress bar, handing finished chunks to the writer thread
/// (asynchronous output), to a framebuffer (synchronous output, rank 0), or to nobody.
fn render(
    scene: &mut api::Scene,
    job: &Job,
    renderer: &Renderer,
    shares: &Shares,
    streams: Option<AsyncOutput>,
    registry: &Registry,
    scene_dir: &Path,
) -> Result<Rendered, Error> {
    let built = built(scene)?;
    let s: &Settings = &built.settings.clone();
    let budget = built.budget.clone();
    let bar = Progress::new();
    let total = s.width as u64 * s.height as u64;
    let done = AtomicU64::new(0);
    let sync = s.io == OutputIo::Sync && job.rank() == 0;
    let sync_fb = Mutex::new(Framebuffer::new(0, 0));
    // Held while rendering: the image's bytes in the memory budget.
    let mut _image = None;
    if sync {
        let (fb, charge) = Framebuffer::charged(s.width, s.height, &budget)?;
        *sync_fb.lock().unwrap_or_else(|e| e.into_inner()) = fb;
        _image = Some(charge);
    }
    let (tx, rx) = mpsc::channel::<Chunk>();
    let start = Instant::now();
    let (rendered, streamed, tail) = std::thread::scope(|sc| {
        let writer = streams.map(|streams| sc.spawn(|| streams.run(rx, registry, scene_dir)));
        let streaming = writer.is_some();
        let sink = |c: Chunk| {
            let n = c.pixels();
            if streaming {
                let _ = tx.send(c);
            } else if sync {
                sync_fb
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .put_chunk(&c);
            }
            bar.tick(done.fetch_add(n, Ordering::Relaxed) + n, total);
        };
        let rendered = job.render(
            renderer,
            scene,
            shares.threads,
            shares.gather,
            shares.keep,
            &sink,
        );
        let render_end = Instant::now();
        drop(tx);
        if let Some(w) = &writer {
            w.thread().unpark();
        }
        let streamed = writer.map(|w| {
            w.join()
                .unwrap_or_else(|_| Err(Error::Render("the writer thread panicked".into())))
        });
        (rendered, streamed, render_end.elapsed())
    });
    let render_time = start.elapsed() - tail;
    bar.finish();
    let (ranks, kept) = rendered?;
    let files = streamed.transpose()?;
    Ok(Rendered {
        ranks,
        kept,
        files,
        sync_fb: sync.then(|| sync_fb.into_inner().unwrap_or_else(|e| e.into_inner())),
        render_time,
        tail,
    })
}

pub(super) fn print_stats(
    scene: &Scene,
    job: &Job,
    s: &RenderStats,
    load: Duration,
    write: Duration,
    total: Duration,
) {
    // One write for the whole block: under mpirun, ranks' blocks would interleave line by line.
    let mut o = String::new();
    macro_rules! out {
        ($($t:tt)*) => {
            let _ = writeln!(o, $($t)*);
        };
    }
    let c = &s.counters;
    let set = &scene.settings;
    let secs = s.render_time.as_secs_f64();
    out!("luxon: statistics");
    out!(
        "  image            {}x{}, {} sample(s) per pixel, max depth {}",
        set.width,
        set.height,
        set.samples,
        set.max_depth
    );
    out!(
        "  primitives       {} ({} spheres, {} triangles, {} planes, {} custom)",
        scene.primitive_count(),
        scene.spheres.len(),
        scene.triangles.len(),
        scene.planes.planes.len(),
        scene.customs.len()
    );
    if let Some(a) = &set.adaptive {
        let pixels = (set.width as u64 * set.height as u64).max(1);
        out!(
            "  adaptive         threshold {}, max depth {}: {} base sample(s) per pixel, {:.2} on average, at most {}",
            a.threshold,
            a.max_depth,
            luxon::adaptive::base_samples(set.samples),
            c.primary as f64 / pixels as f64,
            luxon::adaptive::max_samples(set.samples, a.max_depth)
        );
    }
    out!("  effects          {}", scene.features);
    if let Some((open, close)) = set.shutter {
        let moving = scene.instances.keyed_count();
        out!(
            "  motion blur      shutter {open}..{close} frames from the frame's time; {moving} \
             moving instance(s) placed per ray{}",
            if scene.camera_moves {
                ", camera per ray"
            } else {
                ""
            }
        );
    }
    out!(
        "  memory budget    {}; the scene holds {}",
        scene.budget.describe(),
        scene.budget.in_use()
    );
    let mode = match (job, set.mode) {
        (Job::Local, ParallelMode::Threads) => "threads",
        (Job::Local, _) => "threads (this luxon was built without MPI)",
        (Job::Mpi(_), ParallelMode::Mpi) => "mpi",
        (Job::Mpi(_), _) => "hybrid",
    };
    let (how, unit) = match set.decomposition {
        Decomposition::PixelCyclic => ("pixel-cyclic", "rows"),
        Decomposition::ScanlineCyclic => ("scanline-cyclic", "rows"),
        Decomposition::BlockCyclic => ("block-cyclic", "blocks"),
        Decomposition::Dynamic => ("dynamic", "tiles"),
    };
    let io = match set.io {
        OutputIo::Async => "asynchronous",
        OutputIo::Sync => "synchronous",
        OutputIo::MpiIo => "MPI-IO",
    };
    out!(
        "  parallel         {mode}, {how} ({} px), {io} output",
        set.tile_size
    );
    out!("  ranks            {}", job.size());
    out!(
        "  threads          {} per rank ({} {unit})",
        s.threads,
        s.tiles
    );
    for r in &s.ranks {
        let t = r.total();
        out!(
            "    rank {:<3}       {} thread(s), {} {unit}, {} pixels, {} rays, busy {:.3} s of {:.3} s",
            r.rank,
            r.threads.len(),
            t.units,
            t.pixels,
            t.counters.rays(),
            t.busy.as_secs_f64(),
            r.time.as_secs_f64()
        );
        for (i, w) in r.threads.iter().enumerate() {
            out!(
                "      thread {i:<3}   {} {unit}, {} pixels, {} rays, busy {:.3} s",
                w.units,
                w.pixels,
                w.counters.rays(),
                w.busy.as_secs_f64()
            );
        }
    }
    out!(
        "  rays             {} ({:.2} M/s)",
        c.rays(),
        c.rays() as f64 / secs.max(1e-9) / 1e6
    );
    out!("    primary        {}", c.primary);
    out!("    shadow         {}", c.shadow);
    out!("    reflection     {}", c.reflection);
    out!("    refraction     {}", c.refraction);
    out!("    occlusion      {}", c.occlusion);
    out!("  intersection tests {}", c.tests);
    if scene.features.volumes {
        out!("  volume samples   {}", c.volume_samples);
    }
    out!("  NaN pixels       {}", c.nan_pixels);
    out!(
        "  load + objects   {:.3} s (objects and geometry {:.3} s)",
        load.as_secs_f64() + scene.plugin_time.as_secs_f64(),
        scene.plugin_time.as_secs_f64()
    );
    out!("  BVH build        {:.3} s", scene.bvh_time.as_secs_f64());
    out!("  render           {:.3} s", secs);
    out!("  write            {:.3} s", write.as_secs_f64());
    out!("  total            {:.3} s", total.as_secs_f64());
    eprint!("{o}");
}
