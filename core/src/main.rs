//! `luxon`: the command-line shell over the library.

use clap::{Parser, Subcommand};
use luxon::plugin::{PluginKind, Registry};
use luxon::render::RenderStats;
use luxon::{Error, Scene};
use luxon_formats::{Origin, OutputDesc, SceneDesc};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

#[derive(Parser)]
#[command(
    name = "luxon",
    version,
    about = "A parallel ray tracer with dynamic plugins"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to its outputs (or to the files given with -o).
    Render {
        scene: PathBuf,
        /// Output file(s); the writer is chosen by extension. Replaces the scene's outputs.
        #[arg(short, long = "output")]
        output: Vec<PathBuf>,
        /// Resolution as WIDTHxHEIGHT.
        #[arg(long, value_parser = parse_res)]
        res: Option<(u32, u32)>,
        /// Samples per pixel.
        #[arg(long)]
        samples: Option<u32>,
        /// Render threads (default: every CPU).
        #[arg(long)]
        threads: Option<u32>,
        /// Print rays cast per kind, intersection tests and timings.
        #[arg(long)]
        stats: bool,
    },
    /// Validate a scene and print what it contains; renders nothing.
    Check { scene: PathBuf },
    /// List every plugin found: file, kind, names, ABI version, parameters.
    Plugins {
        /// Extra directories or files to search first.
        #[arg(long = "plugin-path")]
        plugin_path: Vec<PathBuf>,
    },
}

fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{s}`"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in `{s}`"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in `{s}`"))?;
    if w == 0 || h == 0 || w > 65536 || h > 65536 || (w as u64 * h as u64) > (1 << 28) {
        return Err(format!(
            "resolution {w}x{h} out of range (1..=65536 each, at most 2^28 pixels)"
        ));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render {
            scene,
            output,
            res,
            samples,
            threads,
            stats,
        } => render(&scene, &output, res, samples, threads, stats),
        Command::Check { scene } => check(&scene),
        Command::Plugins { plugin_path } => {
            plugins(&plugin_path);
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("luxon: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn cli_origin(what: &str) -> Origin {
    Origin {
        file: Arc::new(PathBuf::from(format!("<command line {what}>"))),
        line: 1,
        col: 1,
    }
}

fn render(
    path: &Path,
    output: &[PathBuf],
    res: Option<(u32, u32)>,
    samples: Option<u32>,
    threads: Option<u32>,
    show_stats: bool,
) -> Result<(), Error> {
    let t0 = Instant::now();
    let mut desc = luxon_formats::load(path)?;
    if let Some((w, h)) = res {
        desc.render.width = w;
        desc.render.height = h;
    }
    if let Some(n) = samples {
        if n == 0 || n > 65536 {
            return Err(Error::Usage(format!("--samples {n}: expected 1..=65536")));
        }
        desc.render.samples = n;
    }
    if let Some(n) = threads {
        if n == 0 || n > 4096 {
            return Err(Error::Usage(format!("--threads {n}: expected 1..=4096")));
        }
        desc.render.parallel.threads = Some(n);
    }
    if !output.is_empty() {
        desc.render.outputs = output
            .iter()
            .map(|p| OutputDesc {
                path: p.clone(),
                plugin: None,
                params: "()".into(),
                params_at: cli_origin("-o"),
            })
            .collect();
    }
    if desc.render.outputs.is_empty() {
        return Err(Error::Usage(format!(
            "{} has no outputs; give one with -o FILE.png or add `outputs: [(path: \"out.png\")]` to its render settings",
            path.display()
        )));
    }
    let registry = Registry::discover(&desc.plugin_path);
    let load_time = t0.elapsed();
    let scene = Scene::build(&desc, &registry)?;
    let outputs = luxon::output::resolve(&scene.outputs, &registry)?;

    let bar = Progress::new();
    let (fb, stats) = luxon::render::render(&scene, &|done, total| bar.tick(done, total))?;
    bar.finish();
    let scene_dir = desc.source.parent().unwrap_or(Path::new("."));
    let t_write = Instant::now();
    let written = luxon::output::write_all(&outputs, &fb, &registry, scene_dir)?;
    let write_time = t_write.elapsed();
    if show_stats {
        print_stats(&scene, &stats, load_time, write_time, t0.elapsed());
    }
    for w in written {
        eprintln!("luxon: wrote {}", w.display());
    }
    if stats.counters.nan_pixels > 0 {
        eprintln!(
            "luxon: warning: {} pixel(s) came out NaN or infinite and were set to black",
            stats.counters.nan_pixels
        );
    }
    Ok(())
}

fn print_stats(scene: &Scene, s: &RenderStats, load: Duration, write: Duration, total: Duration) {
    let c = &s.counters;
    let secs = s.render_time.as_secs_f64();
    eprintln!("luxon: statistics");
    eprintln!(
        "  image            {}x{}, {} sample(s) per pixel, max depth {}",
        scene.settings.width,
        scene.settings.height,
        scene.settings.samples,
        scene.settings.max_depth
    );
    eprintln!(
        "  primitives       {} ({} spheres, {} triangles, {} planes, {} custom)",
        scene.primitive_count(),
        scene.spheres.len(),
        scene.triangles.len(),
        scene.planes.planes.len(),
        scene.customs.len()
    );
    eprintln!("  effects          {}", scene.features);
    eprintln!("  threads          {} ({} tiles)", s.threads, s.tiles);
    eprintln!(
        "  rays             {} ({:.2} M/s)",
        c.rays(),
        c.rays() as f64 / secs.max(1e-9) / 1e6
    );
    eprintln!("    primary        {}", c.primary);
    eprintln!("    shadow         {}", c.shadow);
    eprintln!("    reflection     {}", c.reflection);
    eprintln!("    refraction     {}", c.refraction);
    eprintln!("  intersection tests {}", c.tests);
    eprintln!("  NaN pixels       {}", c.nan_pixels);
    eprintln!(
        "  load + plugins   {:.3} s (plugins {:.3} s)",
        load.as_secs_f64() + scene.plugin_time.as_secs_f64(),
        scene.plugin_time.as_secs_f64()
    );
    eprintln!("  BVH build        {:.3} s", scene.bvh_time.as_secs_f64());
    eprintln!("  render           {:.3} s", secs);
    eprintln!("  write            {:.3} s", write.as_secs_f64());
    eprintln!("  total            {:.3} s", total.as_secs_f64());
}

/// A progress bar with ETA on stderr, only on a terminal and only once a render has run a second.
struct Progress {
    start: Instant,
    bar: Mutex<Option<indicatif::ProgressBar>>,
    enabled: bool,
}

impl Progress {
    fn new() -> Progress {
        Progress {
            start: Instant::now(),
            bar: Mutex::new(None),
            enabled: std::io::stderr().is_terminal(),
        }
    }

    fn tick(&self, done: u64, total: u64) {
        if !self.enabled || self.start.elapsed() < Duration::from_secs(1) {
            return;
        }
        let mut bar = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        let b = bar.get_or_insert_with(|| {
            let b = indicatif::ProgressBar::new(total);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} rendering [{bar:40}] {percent:>3}% {elapsed} elapsed, ETA {eta}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b
        });
        b.set_position(done);
    }

    fn finish(&self) {
        if let Some(b) = self.bar.lock().unwrap_or_else(|e| e.into_inner()).take() {
            b.finish_and_clear();
        }
    }
}

fn check(path: &Path) -> Result<(), Error> {
    let desc = luxon_formats::load(path)?;
    let registry = Registry::discover(&desc.plugin_path);
    let scene = Scene::build(&desc, &registry)?;
    let outputs = luxon::output::resolve(&scene.outputs, &registry)?;
    describe(&desc, &scene, &outputs);
    Ok(())
}

fn describe(desc: &SceneDesc, scene: &Scene, outputs: &[luxon::output::Output]) {
    let s = &scene.settings;
    println!("scene      {}", desc.source.display());
    let cam = &desc.camera.value;
    println!(
        "camera     at {:?} looking at {:?}, up {:?}, {:?}",
        cam.position, cam.look_at, cam.up, cam.projection
    );
    println!(
        "image      {}x{}, {} sample(s) per pixel, max depth {}",
        s.width, s.height, s.samples, s.max_depth
    );
    let objects: Vec<String> = scene
        .object_counts
        .iter()
        .map(|(n, c)| format!("{c} {n}"))
        .collect();
    println!(
        "objects    {} ({})",
        desc.objects.len(),
        if objects.is_empty() {
            "none".into()
        } else {
            objects.join(", ")
        }
    );
    println!(
        "primitives {} spheres, {} triangles, {} planes, {} custom",
        scene.spheres.len(),
        scene.triangles.len(),
        scene.planes.planes.len(),
        scene.customs.len()
    );
    if scene.degenerate_triangles > 0 {
        println!(
            "           ({} zero-area triangles dropped)",
            scene.degenerate_triangles
        );
    }
    println!("lights     {}", scene.lights.len());
    println!("materials  {}", scene.material_names.join(", "));
    println!(
        "textures   {}",
        if scene.texture_names.is_empty() {
            "none".into()
        } else {
            scene.texture_names.join(", ")
        }
    );
    println!("effects    {}", scene.features);
    for o in outputs {
        println!(
            "output     {} (writer `{}`)",
            o.desc.path.display(),
            o.writer.name
        );
    }
}

fn plugins(extra: &[PathBuf]) {
    let registry = Registry::discover(extra);
    for (i, lib) in registry.libraries.iter().enumerate() {
        println!(
            "{} (library `{}`, plugin ABI {}, luxon-plugin {})",
            lib.path.display(),
            lib.name,
            lib.abi_version,
            lib.sdk_version
        );
        for e in registry.entries.iter().filter(|e| e.library == i) {
            let ext = if e.kind == PluginKind::Writer {
                format!(" [.{}]", e.extensions.join(", ."))
            } else {
                String::new()
            };
            let shadow = if e.shadowed {
                " (shadowed by an earlier library)"
            } else {
                ""
            };
            println!("  {} `{}`{ext}{shadow}: {}", e.kind, e.name, e.description);
            for line in e.params_doc.lines() {
                println!("      {line}");
            }
        }
    }
    if registry.libraries.is_empty() {
        println!("no plugins found");
    }
    for p in &registry.problems {
        println!("skipped {p}");
    }
    let dirs: Vec<String> = registry
        .searched
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    println!("searched: {}", dirs.join(", "));
}
