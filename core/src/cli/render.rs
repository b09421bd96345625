//! `luxon render`: load, override from the command line, build, render, write.

use super::progress::Progress;
use luxon::plugin::Registry;
use luxon::render::RenderStats;
use luxon::{Error, Scene};
use luxon_formats::{Origin, OutputDesc};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What the command line can change in a scene's render settings.
#[derive(Default)]
pub struct Overrides {
    pub output: Vec<PathBuf>,
    pub res: Option<(u32, u32)>,
    pub samples: Option<u32>,
    pub threads: Option<u32>,
    pub stats: bool,
}

pub fn cli_origin(what: &str) -> Origin {
    Origin {
        file: Arc::new(PathBuf::from(format!("<command line {what}>"))),
        line: 1,
        col: 1,
    }
}

pub fn run(path: &Path, o: &Overrides) -> Result<(), Error> {
    let (output, res, samples, threads, show_stats) =
        (&o.output, o.res, o.samples, o.threads, o.stats);
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
