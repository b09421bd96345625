//! `luxon sweep`: renders a scene at a range of settings and writes what each costs and how
//! far it is from a reference (the work is [`luxon::sweep`]'s).

use luxon::plugin::Registry;
use luxon::sweep::{self, Curve, Options};
use luxon::Error;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// PARAMETER=VALUE,VALUE,...: samples=1,4,16,64; max_depth=1,2,4,8;
    /// texture_filter=nearest,bilinear,mip; adaptive=off,0.1,0.05:3 (THRESHOLD[:DEPTH]);
    /// volume_step=... (not supported by this build).
    #[arg(long, required = true)]
    pub vary: Vec<String>,
    /// Compare with this image (same resolution); default: a reference rendered with many
    /// samples and every varied parameter at its most accurate value.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Samples per pixel of the rendered reference (default: 4x the most any setting
    /// gives a pixel, 64..=1024).
    #[arg(long = "reference-samples")]
    pub reference_samples: Option<u32>,
    /// Samples per pixel for every curve but a `samples` one (also adaptive sampling's
    /// base); default: the scene's.
    #[arg(long)]
    pub samples: Option<u32>,
    /// Renders per setting; the median time is reported.
    #[arg(long, default_value_t = 3)]
    pub runs: u32,
    /// Resolution as WIDTHxHEIGHT.
    #[arg(long, value_parser = super::parse_res)]
    pub res: Option<(u32, u32)>,
    /// Render threads (default: every CPU).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Memory budget of every build and render (as for `render`).
    #[arg(long, value_name = "SIZE", value_parser = super::parse_memory)]
    pub memory: Option<luxon_formats::MemorySize>,
    /// Render frame K of an animated scene (default: its first frame).
    #[arg(long, value_name = "K")]
    pub frame: Option<u32>,
    /// An animated scene's shutter (motion blur), as for `render`: LENGTH[:start|centre|end]
    /// in frames, or off.
    #[arg(long, value_name = "LENGTH[:start|centre|end]|off")]
    pub shutter: Option<String>,
    /// Directory for the report.
    #[arg(short, long = "output", value_name = "OUTPUT")]
    pub out: PathBuf,
}

pub fn run(path: &Path, a: &Args) -> Result<(), Error> {
    let curves = a
        .vary
        .iter()
        .map(|v| v.parse::<Curve>())
        .collect::<Result<Vec<_>, _>>()?;
    if a.runs == 0 || a.runs > 100 {
        return Err(Error::Usage(format!("--runs {}: expected 1..=100", a.runs)));
    }
    if let Some(n) = a.reference_samples {
        if n == 0 || n > 65536 {
            return Err(Error::Usage(format!(
                "--reference-samples {n}: expected 1..=65536"
            )));
        }
    }
    let options = luxon::budget::Budget::for_load(a.memory, 1).load_options();
    let mut desc = luxon_formats::load_with(path, &options)?;
    super::warn_scene(&desc);
    if let Some((w, h)) = a.res {
        desc.render.width = w;
        desc.render.height = h;
    }
    if let Some(n) = a.samples {
        if n == 0 || n > 65536 {
            return Err(Error::Usage(format!("--samples {n}: expected 1..=65536")));
        }
        desc.render.samples = n;
    }
    if let Some(n) = a.threads {
        if n == 0 || n > 4096 {
            return Err(Error::Usage(format!("--threads {n}: expected 1..=4096")));
        }
        desc.render.parallel.threads = Some(n);
    }
    if let Some(m) = a.memory {
        desc.render.memory = Some(m);
    }
    if let Some(s) = &a.shutter {
        super::shading::set_shutter(&mut desc, s)?;
    }
    if let Some(k) = a.frame {
        let Some(anim) = &desc.animation else {
            return Err(Error::Usage(format!(
                "--frame {k}: {} has no `animation:`",
                desc.source.display()
            )));
        };
        let (first, last) = (anim.value.first, anim.value.last);
        if !(first..=last).contains(&k) {
            return Err(Error::Usage(format!(
                "--frame {k}: the scene's frames are {first} to {last}"
            )));
        }
    }
    // The sweep writes its own files, not the scene's outputs.
    desc.render.outputs.clear();
    let registry = Registry::discover(&desc.plugin_path);
    super::warn_skipped(&registry);
    let options = Options {
        curves,
        reference: a.reference.clone(),
        reference_samples: a.reference_samples,
        runs: a.runs,
        frame: a.frame,
    };
    let result = sweep::run(&desc, &registry, &options, &|what| {
        eprintln!("luxon: rendering {what}")
    })?;
    let written = sweep::report::write(&result, &a.out)?;
    print!("{}", sweep::report::markdown(&result));
    eprintln!(
        "luxon: wrote {} files to {} (sweep.md, sweep.csv, sweep.svg, contact.png, images)",
        written.len(),
        a.out.display()
    );
    Ok(())
}
