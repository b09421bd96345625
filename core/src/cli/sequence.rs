//! `luxon render` of an animated scene: the scene is built once, then frame after frame is set
//! ([`Scene::set_frame`]), rendered on every rank as a still image is, and written under its
//! own names ([`FrameNames`]), all outputs of a frame or none, as `render` writes a still.
//!
//! Which frames: `--frames A..B` (inclusive, like POV-Ray's first and last frame) or
//! `--frames K`, every `--step N`-th from the first; without `--frames` the scene's own
//! `animation: (frames: ...)`. A frame that fails (a camera that degenerates at that frame, an
//! unwritable output) is reported at once with its number, the others are rendered, and the
//! command ends with an error naming the failed frames.

use super::job::Job;
use super::render::{plan, print_stats, warn_nan, write_image, Image, Overrides};
use luxon::budget::Budget;
use luxon::output::frames::FrameNames;
use luxon::plugin::Registry;
use luxon::{Error, Scene};
use luxon_formats::SceneDesc;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

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
        } else {
            "--step"
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

/// Loads nothing (the caller did), builds the scene once (within the memory budget, which
/// every frame's keyed objects and image are charged to as well) and names the outputs.
fn prepare(
    o: &Overrides,
    mut desc: SceneDesc,
    registry: &Registry,
    job: &Job,
) -> Result<(SceneDesc, Scene, Vec<u32>, FrameNames), Error> {
    let frames = frame_list(o, &desc)?;
    let scene_last = desc.animation.as_ref().map_or(0, |a| a.value.last);
    let last = frames.last().copied().unwrap_or(0).max(scene_last);
    let names = FrameNames::new(&desc.render.outputs, last, frames.len() == 1)?;
    // Writers first: an output no writer takes fails before any work.
    luxon::output::resolve(&desc.render.outputs, registry)?;
    let budget = Budget::for_render(&desc.render, o.memory, job.node_ranks());
    let scene = Scene::build_taking_geometry(&mut desc, registry, Arc::new(budget))?;
    Ok((desc, scene, frames, names))
}

/// Renders the frames of an animated scene (`desc` is loaded with the command line's
/// overrides); every rank runs this.
pub fn run(
    o: &Overrides,
    desc: Result<SceneDesc, Error>,
    registry: &Registry,
    job: Job,
) -> Result<(), Error> {
    let t0 = Instant::now();
    let ready = desc.and_then(|d| prepare(o, d, registry, &job));
    let (ready, status) = match ready {
        Ok(r) => {
            let threads = job.threads(&r.1);
            (Some(r), Ok(threads))
        }
        Err(e) => (None, Err(e)),
    };
    match job.agree(status) {
        Ok(_) => {}
        Err(Some(e)) => return Err(e),
        Err(None) => job.exit_quietly(),
    }
    let Some((desc, mut scene, frames, names)) = ready else {
        return Err(Error::Render("not ready to render".into()));
    };
    let build_time = t0.elapsed();
    let scene_dir = desc.source.parent().unwrap_or(Path::new(".")).to_path_buf();
    let total = frames.len();
    let mut failed = Vec::new();
    let mut spent = Duration::ZERO;
    for (n, &k) in frames.iter().enumerate() {
        let t = Instant::now();
        match frame(k, &mut scene, &desc, &names, registry, &job, &scene_dir) {
            Ok(None) => {}
            Ok(Some(image)) => {
                spent += t.elapsed();
                let done = n + 1;
                let eta = spent.as_secs_f64() / done as f64 * (total - done) as f64;
                let written: Vec<String> = image
                    .written
                    .iter()
                    .map(|w| w.display().to_string())
                    .collect();
                if o.stats {
                    eprintln!("luxon: frame {k}");
                    print_stats(
                        &scene,
                        &job,
                        &image.stats,
                        build_time,
                        image.write_time,
                        t.elapsed(),
                    );
                }
                eprintln!(
                    "luxon: wrote {} (frame {k}, {done} of {total}, {:.2} s, ETA {eta:.1} s)",
                    written.join(", "),
                    t.elapsed().as_secs_f64(),
                );
                warn_nan(&scene, &image.stats);
            }
            Err(e) => {
                if job.rank() == 0 {
                    luxon::error::print_error(&format!("frame {k}: {e}"));
                }
                failed.push(k);
            }
        }
    }
    if failed.is_empty() || job.rank() != 0 {
        return Ok(());
    }
    let list: Vec<String> = failed.iter().map(u32::to_string).collect();
    Err(Error::Render(format!(
        "{} of {total} frames failed ({}); the other frames are written",
        failed.len(),
        list.join(", ")
    )))
}

/// Sets, renders and writes frame `k` on every rank; rank 0 gets what it wrote. A frame that
/// cannot be set up on some rank is skipped by all (the ranks agree first).
fn frame(
    k: u32,
    scene: &mut Scene,
    desc: &SceneDesc,
    names: &FrameNames,
    registry: &Registry,
    job: &Job,
    scene_dir: &Path,
) -> Result<Option<Image>, Error> {
    let ready = scene.set_frame(k).and_then(|()| {
        let outputs = luxon::output::resolve(&names.outputs_for(k), registry)?;
        plan(
            &desc.render,
            outputs,
            job,
            registry,
            scene_dir,
            &scene.budget,
        )
    });
    let (ready, status) = match ready {
        Ok(p) => (Some(p), Ok(job.threads(scene))),
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
    write_image(scene, plan, job, &threads, registry, scene_dir)
}
