//! `luxon tachyon [Tachyon's options] scene.dat`: Tachyon's own command line, for drop-in use
//! by VMD and by scripts written for Tachyon. The options are read as Tachyon reads them
//! ([`args`]), each is mapped by the table of [`options`], the scene is read by the Tachyon
//! importer with the scene options, rendered once or along a camera file ([`camfile`]), and
//! written under the names Tachyon gives ([`names`]), after Tachyon's image processing
//! ([`post`]), holding the values Tachyon writes: colours as they are, clamped and truncated,
//! without the sRGB curve (a Tachyon scene's colours are display values), Targa uncompressed. Timings go to standard output in Tachyon's words ("Scene Parsing Time", "Ray
//! Tracing Time", ...); warnings and errors to standard error as for every command.
//!
//! A scene file is read as a Tachyon scene whatever its name, as Tachyon does (`.nff` and
//! AC3D's `.ac` excepted: `luxon render` reads NFF). Several scene files render one after the
//! other, as Tachyon renders them (`outfile.0000.tga`, ...).

pub mod args;
pub mod camfile;
pub mod names;
pub mod options;
pub mod post;

use super::progress::Progress;
use args::{split, usage};
use luxon::budget::Budget;
use luxon::output::Durability;
use luxon::plugin::Registry;
use luxon::{Error, Framebuffer, Scene};
use luxon_formats::{Origin, OutputDesc, Spanned};
use options::{apply, warning, Plan};
use std::collections::HashSet;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where command-line options are said to come from in messages.
fn origin() -> Origin {
    Origin {
        file: Arc::new(PathBuf::from("<command line>")),
        line: 1,
        col: 1,
    }
}

/// Runs `luxon tachyon` with the words after the subcommand.
pub fn run(words: &[OsString]) -> Result<(), Error> {
    let line = split(words)?;
    if let Some(a) = line
        .args
        .iter()
        .find(|a| matches!(a.name, "-help" | "-version" | "-banner"))
    {
        match a.name {
            "-help" => print!("{}", help()),
            "-version" => println!(
                "0.99 (luxon {}, Tachyon's command line)",
                env!("CARGO_PKG_VERSION")
            ),
            _ => println!("{}", banner()),
        }
        return Ok(());
    }
    let mut plan = Plan::new(origin());
    let mut warned = HashSet::new();
    for a in &line.args {
        let support = apply(a, &mut plan)?;
        if let Some(w) = warning(a.name, support) {
            if warned.insert(a.name) {
                luxon::error::print_warning(&w);
            }
        }
    }
    let plan = plan.finish();
    if line.scenes.is_empty() {
        return Err(usage(
            "no scene file; expected `luxon tachyon [options] scene.dat`".into(),
        ));
    }
    for s in &line.scenes {
        let is = |e: &str| s.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
        if is("nff") || is("ac") {
            return Err(usage(format!(
                "{}: `luxon tachyon` reads Tachyon scene files (.dat); render NFF scenes with \
                 `luxon render`",
                s.display()
            )));
        }
    }
    if plan.camfile.is_some() && line.scenes.len() > 1 {
        return Err(usage(format!(
            "-camfile animates one scene; got {} scene files",
            line.scenes.len()
        )));
    }
    println!("{}", banner());
    let ext = plan.format.extension();
    if line.scenes.len() == 1 {
        let names = match &plan.camfile {
            Some(_) => Names::Sequence(sequence_names(&plan, "cam")?),
            None => Names::One(names::single(plan.output.as_deref(), ext)),
        };
        return render_scene(&line.scenes[0], &plan, names, true);
    }
    // Several scenes: Tachyon numbers them (outfile.0000.tga...) and goes on after a failure.
    let pattern = sequence_names(&plan, "outfile")?;
    println!("Rendering {} scene files.", line.scenes.len());
    let mut failed = 0;
    for (k, s) in line.scenes.iter().enumerate() {
        println!(
            "\nRendering scene file {} of {}, {}",
            k + 1,
            line.scenes.len(),
            s.display()
        );
        let last = k + 1 == line.scenes.len();
        if let Err(e) = render_scene(s, &plan, Names::One(pattern.name(k)), last) {
            luxon::error::print_error(&e.to_string());
            failed += 1;
        }
    }
    match failed {
        0 => Ok(()),
        n => Err(Error::Render(format!(
            "{n} of {} scene files were not rendered",
            line.scenes.len()
        ))),
    }
}

fn sequence_names(plan: &Plan, stem: &str) -> Result<names::Pattern, Error> {
    let (pattern, warning) =
        names::sequence(plan.output.as_deref(), stem, plan.format.extension())?;
    if let Some(w) = warning {
        luxon::error::print_warning(&w);
    }
    Ok(pattern)
}

/// What a scene is written to.
enum Names {
    One(PathBuf),
    Sequence(names::Pattern),
}

fn seconds(d: Duration) -> f64 {
    d.as_secs_f64()
}

/// Loads, builds and renders one scene file (every frame of the camera file, if any); `last`:
/// the process ends after it.
fn render_scene(path: &Path, plan: &Plan, names: Names, last: bool) -> Result<(), Error> {
    // The plugins are loaded (dlopen, 5-25 ms) on a thread while the scene file is read: a
    // Tachyon scene names no plugin places, so where to search is known before the file is.
    std::thread::scope(|s| {
        let plugins = s.spawn(|| Registry::discover(&[]));
        render_loaded(path, plan, names, plugins, last)
    })
}

/// [`render_scene`] with the plugins being loaded by `plugins`.
fn render_loaded(
    path: &Path,
    plan: &Plan,
    names: Names,
    plugins: std::thread::ScopedJoinHandle<'_, Registry>,
    last: bool,
) -> Result<(), Error> {
    let t0 = Instant::now();
    // The scene's text within the machine's default budget (Tachyon's options set none).
    let mut options = plan.scene.clone();
    options.max_text = Budget::for_load(None, 1).load_options().max_scene_bytes;
    let mut desc = luxon_formats::tachyon::load_with(path, &options)?;
    super::warn_scene(&desc);
    if plan.threads.is_some() {
        desc.render.parallel.threads = plan.threads;
    }
    let frames = match &plan.camfile {
        Some(f) => Some(camfile::read(f)?),
        None => None,
    };
    println!("Scene Parsing Time: {:10.4} seconds", seconds(t0.elapsed()));
    let registry = match plugins.join() {
        Ok(r) if desc.plugin_path.is_empty() => r,
        Ok(_) => Registry::discover(&desc.plugin_path),
        Err(panic) => std::panic::resume_unwind(panic),
    };
    super::warn_skipped(&registry);
    // The writer is found before anything is built: a missing plugin fails at once.
    let probe = output(plan, PathBuf::from("probe"));
    luxon::output::resolve(std::slice::from_ref(&probe), &registry)?;
    let t1 = Instant::now();
    let camera = desc.camera.value.clone();
    // Tachyon's options have no memory budget: the machine's default share applies.
    let budget = Arc::new(Budget::for_render(&desc.render, None, 1));
    let mut scene = Scene::build_taking_geometry(&mut desc, &registry, budget)?;
    println!("Scene contains {} primitives.", scene.primitive_count());
    println!("Preprocessing Time: {:10.4} seconds", seconds(t1.elapsed()));
    if plan.verbose {
        verbose(&scene);
    }
    let dir = desc.source.parent().unwrap_or(Path::new(".")).to_path_buf();
    let Some(frames) = frames else {
        let Names::One(target) = names else {
            return Err(Error::Render("a single image needs a single name".into()));
        };
        let (fb, render_time) = render_frame(&scene, plan)?;
        println!("  Ray Tracing Time: {:10.4} seconds", seconds(render_time));
        let t = Instant::now();
        if !plan.nosave {
            // One image, as Tachyon writes it: atomic but not synced (see `output::commit`).
            write(plan, &fb, target, &registry, &dir, Durability::Atomic)?;
        }
        println!("    Image I/O Time: {:10.4} seconds", seconds(t.elapsed()));
        if last {
            // The process ends now: the system takes the memory back at once, where freeing a
            // volume's bricks one by one took milliseconds (voltest: 2.6 M instructions).
            std::mem::forget(scene);
        }
        return Ok(());
    };
    let Names::Sequence(pattern) = names else {
        return Err(Error::Render("a camera file needs numbered names".into()));
    };
    // Every frame's camera first: a bad frame fails before anything is rendered.
    let frame_name = |k: usize| match plan.nosave {
        true => format!("frame {k}"),
        false => format!("frame {k} ({})", pattern.name(k).display()),
    };
    let cameras = frames
        .iter()
        .enumerate()
        .map(|(k, f)| {
            luxon_formats::tachyon::camera_at(&camera, f.viewdir, f.updir, f.center)
                .map_err(|e| Error::at(&f.at, format!("{}: {e}", frame_name(k))))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    let camfile = plan.camfile.as_deref().unwrap_or(Path::new(""));
    println!("Running Camera File: {}", camfile.display());
    let t_anim = Instant::now();
    let base_frame = scene.settings.frame;
    for (k, cam) in cameras.iter().enumerate() {
        let in_frame = |e: Error| Error::Render(format!("{}: {e}", frame_name(k)));
        scene.set_camera(cam);
        // Each frame samples afresh (the sampler is seeded with the frame number).
        scene.settings.frame = base_frame.wrapping_add(k as u32);
        let (fb, render_time) = render_frame(&scene, plan).map_err(in_frame)?;
        if plan.nosave {
            println!(
                "Rendering Frame: {k:9}   (ray tracing {:.4} s)",
                seconds(render_time)
            );
            continue;
        }
        let name = pattern.name(k);
        // A sequence's frames are synced: a resumed sequence trusts a frame on disk.
        write(plan, &fb, name.clone(), &registry, &dir, Durability::Synced).map_err(in_frame)?;
        println!(
            "Rendering Frame to {}   (ray tracing {:.4} s)",
            name.display(),
            seconds(render_time)
        );
    }
    let total = t_anim.elapsed();
    println!("Completed animation of {} frames", frames.len());
    println!(
        "Animation Time: {:10.4} seconds  (Averaged {:7.4} FPS)",
        seconds(total),
        frames.len() as f64 / seconds(total).max(1e-9)
    );
    Ok(())
}

/// Renders the scene as it stands, with a progress bar on a terminal; Tachyon's image
/// processing applied.
fn render_frame(scene: &Scene, plan: &Plan) -> Result<(Framebuffer, Duration), Error> {
    let bar = Progress::new();
    let (mut fb, stats) = luxon::render::render(scene, &|done, total| bar.tick(done, total))?;
    bar.finish();
    if stats.counters.nan_pixels > 0 {
        luxon::error::print_warning(&format!(
            "{} pixel(s) came out NaN or infinite and were set to black",
            stats.counters.nan_pixels
        ));
    }
    for w in scene.nan_warnings(&stats.nan_sources) {
        luxon::error::print_warning(&w);
    }
    if plan.verbose {
        let c = &stats.counters;
        let secs = seconds(stats.render_time).max(1e-9);
        println!(
            "Rays: {} ({} primary, {} shadow, {} reflection, {} refraction, {} occlusion), \
             {:.2} M/s on {} thread(s)",
            c.rays(),
            c.primary,
            c.shadow,
            c.reflection,
            c.refraction,
            c.occlusion,
            c.rays() as f64 / secs / 1e6,
            stats.threads
        );
    }
    post::apply(plan.post, &mut fb);
    Ok((fb, stats.render_time))
}

/// The output of `path` in the plan's format (the writer by format, not by extension).
fn output(plan: &Plan, path: PathBuf) -> OutputDesc {
    let (writer, params) = plan.format.writer();
    OutputDesc {
        path,
        plugin: Some(Spanned {
            value: writer.to_string(),
            at: origin(),
        }),
        params: params.to_string(),
        params_at: origin(),
    }
}

/// Writes `fb` to `path` (relative to the working directory, as Tachyon writes), whole or not
/// at all, synced before the rename or not as `durability` says.
fn write(
    plan: &Plan,
    fb: &Framebuffer,
    path: PathBuf,
    registry: &Registry,
    scene_dir: &Path,
    durability: Durability,
) -> Result<(), Error> {
    let outputs = luxon::output::resolve(&[output(plan, path)], registry)?;
    luxon::output::write_all_with(&outputs, fb, registry, scene_dir, durability)?;
    Ok(())
}

/// `+V`: what the scene holds and what the render will do.
fn verbose(scene: &Scene) {
    let s = &scene.settings;
    println!(
        "Image: {}x{}, {} sample(s) per pixel, ray depth {}",
        s.width, s.height, s.samples, s.max_depth
    );
    println!("Effects: {}", scene.features);
    println!(
        "Load and BVH: objects and geometry {:.4} s, BVH {:.4} s",
        seconds(scene.plugin_time),
        seconds(scene.bvh_time)
    );
}

fn banner() -> String {
    format!(
        "Luxon {} (Tachyon's command line: Tachyon 0.99 options)",
        env!("CARGO_PKG_VERSION")
    )
}

/// `-help`: the options and what Luxon does with them.
fn help() -> String {
    "Usage: luxon tachyon [options] scene.dat [more scenes...]\n\
     \n\
     Renders Tachyon scene files with Luxon, reading Tachyon 0.99's command line (for VMD:\n\
     `luxon tachyon -aasamples 12 %s -format TARGA -o %s.tga`). Options may come before or\n\
     after the scene files.\n\
     \n\
     Output:\n  \
     -o file             output file name, used as given (default outfile.<ext>)\n  \
     -format F           TARGA (default), BMP, PPM, PPM48, PNG, JPEG\n  \
     -res X Y            override the scene's resolution\n  \
     -clamp              clamp colours to [0, 1] (default)\n  \
     -normalize          stretch the image's colours to [0, 1]\n  \
     -gamma g            normalize, then apply gamma g\n  \
     -nosave             render without writing\n\
     Rendering:\n  \
     -aasamples n        n antialiasing samples per pixel beyond the first\n  \
     -raydepth n         maximum ray depth\n  \
     -numthreads n       render threads (default: every CPU)\n  \
     -fullshade | -mediumshade | -lowshade | -lowestshade   shading level\n  \
     -shade_phong | -shade_blinn | -shade_blinn_fast | -shade_nullphong   highlights\n  \
     -trans_orig | -trans_raster3d | -trans_vmd   transparency\n  \
     -trans_max_surfaces n   transparent surfaces shown along a ray\n  \
     -shadow_filter_on | -shadow_filter_off   shadows of transparent surfaces\n  \
     -fog_radial | -fog_vmd   fog distance along the ray or the view direction\n  \
     -rescale_lights f   scale direct light (f < 1)\n  \
     -auto_skylight f    ambient occlusion of level f, direct light × (1 - f)\n  \
     -add_skylight f     ambient occlusion of level f\n  \
     -skylight_samples n occlusion rays per point (default 128)\n  \
     -normalfixup off|flip|guess   (only off is supported)\n\
     Animation:\n  \
     -camfile file.cam   render a frame per camera of the file (cam.0000.<ext>, ...;\n                      \
     with -o, a %04d in the name numbers the frames)\n\
     Other:\n  \
     +V | -V             more or fewer messages\n  \
     -nobounding, -boundthresh n, -spaceball, -spaceballport dev   accepted, ignored\n  \
     -help | -version | -banner\n"
        .to_string()
}

/// For tests: the camera a scene's description would have at a camera-file frame.
#[cfg(test)]
fn frame_camera(
    desc: &luxon_formats::SceneDesc,
    f: &camfile::Frame,
) -> Result<luxon_formats::CameraDesc, String> {
    luxon_formats::tachyon::camera_at(&desc.camera.value, f.viewdir, f.updir, f.center)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_frame_moves_only_the_camera() {
        let dir = std::env::temp_dir().join(format!("luxon-tcli-frame-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("s.dat");
        std::fs::write(
            &p,
            "BEGIN_SCENE RESOLUTION 8 8 CAMERA ZOOM 2 ASPECTRATIO 1 ANTIALIASING 0 RAYDEPTH 4 \
             CENTER 0 0 0 VIEWDIR 0 0 1 UPDIR 0 1 0 END_CAMERA END_SCENE",
        )
        .unwrap();
        let desc = luxon_formats::load(&p).unwrap();
        let frames = camfile::parse("1 0 0  0 1 0  1 2 3", Path::new("a.cam")).unwrap();
        let c = frame_camera(&desc, &frames[0]).unwrap();
        // Tachyon's z is mirrored.
        assert_eq!(c.position, [1.0, 2.0, -3.0]);
        assert_eq!(c.look_at, [2.0, 2.0, -3.0]);
        assert_eq!(c.up, [0.0, 1.0, -0.0]);
        assert_eq!(c.frustum, desc.camera.value.frustum);
        assert_eq!(c.projection, desc.camera.value.projection);
        let bad = camfile::parse("0 1 0  0 2 0  0 0 0", Path::new("a.cam")).unwrap();
        assert!(frame_camera(&desc, &bad[0])
            .unwrap_err()
            .contains("parallel"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
