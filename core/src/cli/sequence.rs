//! `luxon render` of an animated scene: the scene is built once, then frame after frame is set
//! ([`Scene::set_frame`]), rendered on every rank as a still image is, and written under its
//! own names ([`FrameNames`]), all outputs of a frame or none, as `render` writes a still.
//!
//! Which frames: `--frames A..B` (inclusive, like POV-Ray's first and last frame) or
//! `--frames K`, every `--step N`-th from the first; without `--frames` the scene's own
//! `animation: (frames: ...)`. A frame that fails (a camera that degenerates at that frame, an
//! unwritable output) is reported at once with its number, the others are rendered, and the
//! command ends with an error naming the failed frames.
//!
//! Sequences resume: a frame whose completion record says it is done for the same inputs is
//! not rendered again (`--force` renders it anyway), and processes started on the same outputs
//! share the frames by claiming them ([`super::resume`]).

use super::frame_clock::FrameClock;
use super::job::Job;
use super::render::{
    built, plan, print_stats, scene_dir_of, warn_nan, write_image, Image, Overrides,
};
use super::resume::Resume;
use luxon::api::{Context, Renderer, Scene};
use luxon::budget::Budget;
use luxon::output::frames::FrameNames;
use luxon::output::inputs::{absolute, SceneFile, SceneInputs};
use luxon::output::manifest::Manifest;
use luxon::output::preview::Preview;
use luxon::plugin::Registry;
use luxon::schedule::wire::FrameResult;
use luxon::Error;
use luxon_formats::{OutputIo, SceneDesc};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use std::time::{Duration, Instant};

/// Broadcast by rank 0 when no frame is left.
pub(super) const NO_FRAME: u64 = u64::MAX;

/// `--frames A..B` or `--frames K`.
pub fn parse_frames(s: &str) -> Result<(u32, u32), String> {
    let number = |t: &str| {
        t.trim().parse::<u32>().map_err(|_| {
            format!("`{t}` is not a frame number; expected A..B or K (whole numbers from 0)")
        })
    };
    let (a, b) = match s.split_once("..") {
        Some((a, b)) => (number(a)?, number(b)?),
        None => {
            let k = number(s)?;
            (k, k)
        }
    };
    if a > b {
        return Err("the first frame is after the last; expected A..B with A <= B".into());
    }
    Ok((a, b))
}

/// The frames to render, in order.
fn frame_list(o: &Overrides, desc: &SceneDesc) -> Result<Vec<u32>, Error> {
    let Some(a) = &desc.animation else {
        let flag = if o.frames.is_some() {
            "--frames"
        } else if o.step.is_some() {
            "--step"
        } else if o.preview.is_some() {
            "--preview"
        } else {
            "--force"
        };
        return Err(Error::Usage(format!(
            "{} has no `animation:`; {flag} needs one (e.g. `animation: (frames: (0, 47))`)",
            desc.source.display()
        )));
    };
    let (first, last) = o.frames.unwrap_or((a.value.first, a.value.last));
    let step = match o.step {
        Some(0) => return Err(Error::Usage("--step 0: expected 1 or more".into())),
        Some(n) => n,
        None => 1,
    };
    Ok((first..=last).step_by(step as usize).collect())
}

/// What every rank has before the first frame; rank 0 also the frame records.
struct Ready {
    scene: Scene,
    frames: Vec<u32>,
    names: FrameNames,
    resume: Option<Resume>,
    preview: Option<Preview>,
}

/// Loads nothing (the caller did), builds the scene once (within the memory budget, which
/// every frame's keyed objects and image are charged to as well), names the outputs and, on
/// rank 0, opens the frame records. `read`: the scene files the load read.
fn prepare(
    o: &Overrides,
    desc: SceneDesc,
    read: &[SceneFile],
    ctx: &Context,
    renderer: &Renderer,
    job: &Job,
) -> Result<Ready, Error> {
    let registry = ctx.registry();
    let frames = frame_list(o, &desc)?;
    let scene_last = desc.animation.as_ref().map_or(0, |a| a.value.last);
    let last = frames.last().copied().unwrap_or(0).max(scene_last);
    let names = FrameNames::new(&desc.render.outputs, last, frames.len() == 1)?;
    let preview = match (&o.preview, &desc.animation) {
        (Some(p), Some(a)) => {
            let seconds = f64::from(o.step.unwrap_or(1)) / a.value.fps;
            let preview = Preview::new(p, seconds)?;
            // Checked before any work: the frames must be readable back.
            preview.source(&output_paths(&names, frames.first().copied().unwrap_or(0)))?;
            Some(preview)
        }
        _ => None,
    };
    // Writers first: an output no writer takes fails before any work.
    luxon::output::resolve(&desc.render.outputs, registry)?;
    let budget = Budget::for_render(&desc.render, o.memory, job.node_ranks());
    let mut scene = Scene::from_desc_frozen(ctx, desc)?;
    scene.set_budget(Arc::new(budget));
    scene.commit(renderer)?;
    let desc = scene.desc();
    let resume = match job.rank() {
        0 => {
            let hash = scene_hash(o, desc, read, registry, &names, &frames);
            let about = about(desc, &frames, hash, o);
            // The data files of a `series:` are per frame: each frame's own join its hash.
            let data = luxon::scene::DataFiles::new(desc);
            let data = Box::new(move |k| data.of(k));
            Some(Resume::start(&names, &frames, hash, data, o.force, &about)?)
        }
        _ => None,
    };
    Ok(Ready {
        scene,
        frames,
        names,
        resume,
        preview,
    })
}

/// The files frame `k` is written to.
fn output_paths(names: &FrameNames, k: u32) -> Vec<PathBuf> {
    names.outputs_for(k).into_iter().map(|o| o.path).collect()
}

/// Writes the preview of the frames of `frames` whose files exist (done now or before).
fn write_preview(preview: &Preview, names: &FrameNames, frames: &[u32]) -> Result<(), Error> {
    let mut files = Vec::new();
    for &k in frames {
        let outputs = output_paths(names, k);
        let file = preview.source(&outputs)?;
        if file.is_file() {
            files.push(file.to_path_buf());
        }
    }
    if files.is_empty() {
        return Ok(());
    }
    preview.write(&files)?;
    eprintln!(
        "luxon: wrote {} (a preview of {} frames)",
        preview.path().display(),
        files.len()
    );
    Ok(())
}

/// The hash of everything the frames are rendered from (see [`luxon::output::inputs`]), after
/// the build (which looks the plugins up).
fn scene_hash(
    o: &Overrides,
    desc: &SceneDesc,
    read: &[SceneFile],
    registry: &Registry,
    names: &FrameNames,
    frames: &[u32],
) -> u64 {
    let records = names.first().map(|p| absolute(Manifest::beside(p).dir()));
    let outputs: HashSet<PathBuf> = frames
        .iter()
        .flat_map(|&k| names.outputs_for(k))
        .map(|o| absolute(&o.path))
        .collect();
    let skip = |p: &Path| {
        let p = absolute(p);
        outputs.contains(&p) || records.as_ref().is_some_and(|r| p.starts_with(r))
    };
    let libraries = registry.used_libraries();
    luxon::output::inputs::scene_hash(&SceneInputs {
        files: read,
        render: &desc.render,
        libraries: libraries.iter().map(|l| l.path.as_path()).collect(),
        extra: format!("{:?}", o.shading),
        skip: &skip,
    })
}

/// The `manifest` file: what the sequence is, for people.
fn about(desc: &SceneDesc, frames: &[u32], hash: u64, o: &Overrides) -> String {
    let r = &desc.render;
    let outputs: Vec<String> = desc
        .render
        .outputs
        .iter()
        .map(|o| o.path.display().to_string())
        .collect();
    let step = o.step.unwrap_or(1);
    let range = match (frames.first(), frames.last()) {
        (Some(a), Some(b)) => format!("{a}..{b} step {step}"),
        _ => "none".into(),
    };
    format!(
        "luxon-frames 1\nscene {hash:016x}\noutputs {}\nframes {range}\nsettings {}x{}, {} spp\n",
        outputs.join(" "),
        r.width,
        r.height,
        r.samples
    )
}

/// Renders the frames of an animated scene (`desc` is loaded with the command line's
/// overrides); every rank runs this. `start`: when the command started.
pub fn run(
    o: &Overrides,
    desc: Result<SceneDesc, Error>,
    read: &[SceneFile],
    ctx: &Context,
    renderer: &Renderer,
    job: Job,
    start: Instant,
) -> Result<(), Error> {
    let t0 = Instant::now();
    let ready = desc.and_then(|d| prepare(o, d, read, ctx, renderer, &job));
    let (ready, status) = match ready {
        Ok(r) => (Some(r), Ok(renderer.threads())),
        Err(e) => (None, Err(e)),
    };
    match job.agree(status) {
        Ok(_) => {}
        Err(Some(e)) => return Err(e),
        Err(None) => job.exit_quietly(),
    }
    let Some(Ready {
        mut scene,
        frames,
        names,
        resume,
        preview,
    }) = ready
    else {
        return Err(Error::Render("not ready to render".into()));
    };
    let total = frames.len();
    if let Some(note) = resume.as_ref().and_then(Resume::start_note) {
        eprintln!("luxon: {note}");
    }
    let mut tally = resume.map(|r| Tally::new(r, total));
    let group = scene
        .desc()
        .render
        .parallel
        .frames
        .group_size(total, job.size());
    let each = Each {
        o,
        names: &names,
        renderer,
        registry: ctx.registry(),
        scene_dir: scene_dir_of(scene.desc()),
        build_time: t0.elapsed(),
        // Several groups render frames side by side into the same directories: MPI-IO
        // outputs are then written by each group's leader (as `Async`), since an MPI-IO
        // temporary file is unlocked while the ranks write it, and another group starting a
        // frame there would sweep it as stale.
        mpi_io: group >= job.size(),
    };
    let mut clock = FrameClock::new(start);
    if group < job.size() {
        #[cfg(feature = "mpi")]
        if let Job::Mpi(cluster) = &job {
            if let Err(e) = super::frame_groups::check_shared_dir(&names, &job) {
                match e {
                    Some(e) => return Err(e),
                    None => job.exit_quietly(),
                }
            }
            tally = super::frame_groups::run(&each, &mut scene, cluster, group, tally, &mut clock)?;
        }
    } else {
        // Rank 0 picks (and claims) the next frame; every rank renders it. Rank 0 records the
        // previous frame once the others have the next one: they need not wait for that.
        let mut done = None;
        loop {
            let next = clock.wait(|| {
                let next = tally
                    .as_mut()
                    .and_then(Tally::next)
                    .map_or(NO_FRAME, u64::from);
                job.root_value(next)
            });
            if let (Some(tally), Some(r)) = (tally.as_mut(), done.take()) {
                clock.report(|| tally.report(r));
            }
            if next == NO_FRAME {
                break;
            }
            let k = next as u32;
            let t = Instant::now();
            done = clock
                .render(|| each.frame(k, &mut scene, &job))
                .map(|outcome| FrameResult {
                    frame: k,
                    outcome,
                    seconds: t.elapsed().as_secs_f64(),
                });
        }
    }
    if o.stats {
        clock.print(job.rank(), job.size());
    }
    let Some(tally) = tally else {
        return Ok(());
    };
    if let Some(note) = tally.resume.others() {
        eprintln!("luxon: {note}");
    }
    let previewed = match &preview {
        Some(p) => write_preview(p, &names, &frames),
        None => Ok(()),
    };
    if tally.failed.is_empty() {
        return previewed;
    }
    if let Err(e) = previewed {
        luxon::error::print_error(&e.to_string());
    }
    let list: Vec<String> = tally.failed.iter().map(u32::to_string).collect();
    Err(Error::Render(format!(
        "{} of {total} frames failed ({}); the other frames are written",
        tally.failed.len(),
        list.join(", ")
    )))
}

/// Rank 0's account of the sequence: which frame is next (claimed), and what each gave.
pub(super) struct Tally {
    resume: Resume,
    to_render: usize,
    failed: Vec<u32>,
    spent: f64,
    done: usize,
}

impl Tally {
    fn new(resume: Resume, total: usize) -> Tally {
        Tally {
            to_render: total - resume.done_at_start,
            resume,
            failed: Vec::new(),
            spent: 0.0,
            done: 0,
        }
    }

    /// The next frame to render, claimed (`None`: none left); a frame whose claim fails is
    /// reported and counted as failed.
    pub(super) fn next(&mut self) -> Option<u32> {
        loop {
            match self.resume.next() {
                Ok(k) => return k,
                Err((k, e)) => {
                    luxon::error::print_error(&format!("frame {k}: {e}"));
                    self.failed.push(k);
                }
            }
        }
    }

    /// How frame `r.frame` ended: records it (or lets its claim go) and tells the user.
    pub(super) fn report(&mut self, r: FrameResult) {
        let k = r.frame;
        let outcome = match r.outcome {
            Ok(files) => self
                .resume
                .finished(k)
                .map(|()| files)
                .map_err(|e| e.to_string()),
            Err(m) => {
                self.resume.release(k);
                Err(m)
            }
        };
        match outcome {
            Ok(files) => {
                self.spent += r.seconds;
                self.done += 1;
                let left = self.resume.left();
                let eta = self.spent / self.done as f64 * left as f64;
                eprintln!(
                    "luxon: wrote {} (frame {k}, {} of {}, {:.2} s, ETA {eta:.1} s)",
                    files.join(", "),
                    self.done,
                    self.to_render,
                    r.seconds,
                );
            }
            Err(m) => {
                luxon::error::print_error(&format!("frame {k}: {m}"));
                self.failed.push(k);
            }
        }
    }
}

/// What rendering any frame needs besides the scene and the ranks.
pub(super) struct Each<'a> {
    o: &'a Overrides,
    names: &'a FrameNames,
    renderer: &'a Renderer,
    registry: &'a Registry,
    scene_dir: PathBuf,
    build_time: Duration,
    /// Whether MPI-IO outputs are written by every rank (one group) or gathered.
    mpi_io: bool,
}

impl Each<'_> {
    /// Renders frame `k` on the ranks of `job` and writes it; the rank that wrote it (rank 0 of
    /// `job`) gets the files written or why the frame failed, and prints its statistics.
    pub(super) fn frame(
        &self,
        k: u32,
        scene: &mut Scene,
        job: &Job,
    ) -> Option<Result<Vec<String>, String>> {
        let t = Instant::now();
        let image = match frame(self, k, scene, job) {
            Ok(Some(image)) => image,
            Ok(None) => return None,
            Err(e) => return (job.rank() == 0).then(|| Err(e.to_string())),
        };
        let built = match built(scene) {
            Ok(b) => b,
            Err(e) => return Some(Err(e.to_string())),
        };
        if self.o.stats {
            eprintln!("luxon: frame {k}");
            print_stats(
                built,
                job,
                &image.stats,
                self.build_time,
                image.write_time,
                t.elapsed(),
            );
        }
        warn_nan(built, &image.stats);
        Some(Ok(image
            .written
            .iter()
            .map(|w| w.display().to_string())
            .collect()))
    }
}

/// Sets, renders and writes frame `k` on every rank; rank 0 gets what it wrote. A frame that
/// cannot be set up on some rank is skipped by all (the ranks agree first).
fn frame(each: &Each, k: u32, scene: &mut Scene, job: &Job) -> Result<Option<Image>, Error> {
    let ready = scene.set_frame(k).and_then(|()| {
        scene.commit(each.renderer)?;
        let outputs = luxon::output::resolve(&each.names.outputs_for(k), each.registry)?;
        let budget = &built(scene)?.budget;
        let mut render = scene.desc().render.clone();
        if !each.mpi_io && render.parallel.io == OutputIo::MpiIo {
            render.parallel.io = OutputIo::Async;
        }
        plan(
            &render,
            outputs,
            job,
            each.registry,
            &each.scene_dir,
            budget,
        )
    });
    let (ready, status) = match ready {
        Ok(p) => (Some(p), Ok(each.renderer.threads())),
        Err(e) => (None, Err(e)),
    };
    let threads = match job.agree(status) {
        Ok(t) => t,
        Err(Some(e)) => return Err(e),
        Err(None) => return Err(Error::Render(format!("frame {k} failed on another rank"))),
    };
    let Some(plan) = ready else {
        return Err(Error::Render(format!("frame {k} is not ready")));
    };
    write_image(
        scene,
        plan,
        job,
        each.renderer,
        &threads,
        each.registry,
        &each.scene_dir,
    )
}
