//! What accuracy costs in time: render a scene at a range of settings, one parameter at a time,
//! and measure each image's render time, rays cast and error against a reference.
//!
//! Each [`Curve`] varies one parameter from the scene's own settings (several curves are
//! separate one-parameter sweeps, not a grid). Settings that only change how the built scene is
//! rendered (samples, max depth, adaptive sampling) reuse one built scene; those that change
//! what is built (texture filter, volume step) build the scene once per value.
//!
//! Errors are measured on the 8-bit sRGB images as written: RMSE (0..1 scale), PSNR and SSIM of
//! the luma ([`crate::metrics`]).

mod filter;
pub mod report;

pub use filter::set_image_filter;

use crate::error::Error;
use crate::framebuffer::Framebuffer;
use crate::plugin::Registry;
use crate::scene::{Scene, Settings};
use luxon_formats::{AdaptiveDesc, SceneDesc};
use std::path::PathBuf;
use std::str::FromStr;
use std::time::Duration;

/// A parameter a sweep can vary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Param {
    Samples,
    MaxDepth,
    VolumeStep,
    TextureFilter,
    Adaptive,
}

const PARAMS: [(&str, Param); 5] = [
    ("samples", Param::Samples),
    ("max_depth", Param::MaxDepth),
    ("volume_step", Param::VolumeStep),
    ("texture_filter", Param::TextureFilter),
    ("adaptive", Param::Adaptive),
];

impl Param {
    pub fn name(self) -> &'static str {
        PARAMS.iter().find(|p| p.1 == self).map_or("", |p| p.0)
    }
}

/// One value of a varied parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Setting {
    Samples(u32),
    MaxDepth(u32),
    VolumeStep(f64),
    /// `nearest`, `bilinear` or `mip`.
    TextureFilter(&'static str),
    /// `None`: uniform sampling.
    Adaptive(Option<AdaptiveDesc>),
}

const FILTERS: [&str; 3] = ["nearest", "bilinear", "mip"];

impl Setting {
    pub fn param(&self) -> Param {
        match self {
            Setting::Samples(_) => Param::Samples,
            Setting::MaxDepth(_) => Param::MaxDepth,
            Setting::VolumeStep(_) => Param::VolumeStep,
            Setting::TextureFilter(_) => Param::TextureFilter,
            Setting::Adaptive(_) => Param::Adaptive,
        }
    }

    /// The value as written on the command line.
    pub fn label(&self) -> String {
        match self {
            Setting::Samples(n) | Setting::MaxDepth(n) => n.to_string(),
            Setting::VolumeStep(s) => s.to_string(),
            Setting::TextureFilter(f) => f.to_string(),
            Setting::Adaptive(a) => crate::adaptive::label(a.as_ref()),
        }
    }

    /// Whether the scene must be built anew for this value (else only its settings change).
    pub fn rebuilds(&self) -> bool {
        matches!(self, Setting::VolumeStep(_) | Setting::TextureFilter(_))
    }

    /// Sets the value in a scene description.
    pub fn apply(&self, desc: &mut SceneDesc) -> Result<(), Error> {
        match self {
            Setting::Samples(n) => desc.render.samples = *n,
            Setting::MaxDepth(n) => desc.render.max_depth = *n,
            Setting::Adaptive(a) => desc.render.adaptive = *a,
            Setting::VolumeStep(s) => set_volume_step(desc, *s)?,
            Setting::TextureFilter(f) => {
                let mut changed = 0;
                for (_, t) in &mut desc.textures {
                    let call = &mut t.value;
                    let (params, n) =
                        set_image_filter(&call.params, f, call.plugin.value == "image");
                    call.params = params;
                    changed += n;
                }
                if changed == 0 {
                    return Err(Error::Usage(
                        "--vary texture_filter: the scene has no image textures, so the filter changes nothing".into(),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Sets a value that needs no rebuild in a built scene's settings.
    fn apply_settings(&self, s: &mut Settings) {
        match self {
            Setting::Samples(n) => s.samples = *n,
            Setting::MaxDepth(n) => s.max_depth = *n,
            Setting::Adaptive(a) => s.adaptive = *a,
            Setting::VolumeStep(_) | Setting::TextureFilter(_) => {}
        }
    }

    /// Most samples a pixel can get with this setting on top of `base`.
    fn max_samples(&self, base: &luxon_formats::RenderDesc) -> u64 {
        let samples = match self {
            Setting::Samples(n) => *n,
            _ => base.samples,
        };
        let adaptive = match self {
            Setting::Adaptive(a) => a.as_ref(),
            _ => base.adaptive.as_ref(),
        };
        match adaptive {
            Some(a) => crate::adaptive::max_samples(samples, a.max_depth),
            None => samples as u64,
        }
    }
}

/// `--vary volume_step`: the render setting that multiplies every volume's step.
fn set_volume_step(desc: &mut SceneDesc, step: f64) -> Result<(), Error> {
    if desc.volumes.iter().all(|v| v.value.render.is_none()) {
        return Err(Error::Usage(
            "--vary volume_step: the scene draws no volume, so the step changes nothing".into(),
        ));
    }
    desc.render.volume_step = step;
    Ok(())
}

/// One parameter and the values it takes, in order: `samples=1,4,16,64`.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub param: Param,
    pub settings: Vec<Setting>,
}

impl FromStr for Curve {
    type Err = Error;

    fn from_str(s: &str) -> Result<Curve, Error> {
        let usage = |m: String| Error::Usage(format!("--vary {s}: {m}"));
        let (name, values) = s.split_once('=').ok_or_else(|| {
            usage("expected PARAMETER=VALUE,VALUE,... such as samples=1,4,16,64".into())
        })?;
        let name = name.trim();
        let param = PARAMS
            .iter()
            .find(|p| p.0 == name)
            .map(|p| p.1)
            .ok_or_else(|| {
                let names: Vec<&str> = PARAMS.iter().map(|p| p.0).collect();
                let hint = luxon_formats::suggest(name, names.iter().copied())
                    .map(|n| format!("did you mean `{n}`? "))
                    .unwrap_or_default();
                usage(format!(
                    "unknown parameter `{name}`; {hint}expected one of {}",
                    names.join(", ")
                ))
            })?;
        let mut settings = Vec::new();
        for v in values.split(',') {
            let v = v.trim();
            if v.is_empty() {
                return Err(usage("an empty value".into()));
            }
            let whole = |min: u32, max: u32| match v.parse::<u32>() {
                Ok(n) if (min..=max).contains(&n) => Ok(n),
                _ => Err(usage(format!(
                    "`{v}` is not a whole number from {min} to {max}"
                ))),
            };
            settings.push(match param {
                Param::Samples => Setting::Samples(whole(1, 65536)?),
                Param::MaxDepth => Setting::MaxDepth(whole(0, 1024)?),
                Param::VolumeStep => match v.parse::<f64>() {
                    Ok(x) if x > 0.0 && x.is_finite() => Setting::VolumeStep(x),
                    _ => return Err(usage(format!("`{v}` is not a step length greater than 0"))),
                },
                Param::TextureFilter => match FILTERS.iter().find(|f| **f == v) {
                    Some(f) => Setting::TextureFilter(f),
                    None => {
                        return Err(usage(format!(
                            "`{v}` is not a texture filter; expected nearest, bilinear or mip"
                        )))
                    }
                },
                Param::Adaptive => Setting::Adaptive(crate::adaptive::parse(v, 3).map_err(usage)?),
            });
        }
        if settings.is_empty() {
            return Err(usage("no values".into()));
        }
        Ok(Curve { param, settings })
    }
}

/// What to sweep and how to measure.
#[derive(Clone, Debug)]
pub struct Options {
    pub curves: Vec<Curve>,
    /// An image to compare with (same resolution as the renders); `None`: render one.
    pub reference: Option<PathBuf>,
    /// Samples per pixel of a rendered reference; `None`: [`reference_samples`].
    pub reference_samples: Option<u32>,
    /// Renders per setting; the reported time is their median.
    pub runs: u32,
    /// The frame of an animated scene to render (reference and settings alike); `None`: the
    /// scene as built (its first frame).
    pub frame: Option<u32>,
}

/// One rendered setting.
#[derive(Clone, Debug)]
pub struct Row {
    pub param: Param,
    pub value: String,
    /// Median render time over the runs (building the scene excluded).
    pub time: Duration,
    /// Every ray cast (primary, shadow, secondary, occlusion) in one run.
    pub rays: u64,
    /// Primary rays per pixel.
    pub samples_per_pixel: f64,
    pub rmse: f64,
    pub psnr: f64,
    /// `None` when the image is smaller than the SSIM window.
    pub ssim: Option<f64>,
    /// The image, 8-bit sRGB RGB.
    pub rgb: Vec<u8>,
}

/// A finished sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub width: u32,
    pub height: u32,
    pub rows: Vec<Row>,
    /// How the reference was made.
    pub reference: String,
    pub reference_rgb: Vec<u8>,
    pub runs: u32,
}

/// The 8-bit sRGB image a framebuffer is written as (the PNG writer's encoding).
pub fn to_rgb8(fb: &Framebuffer) -> Vec<u8> {
    fb.rgba
        .chunks_exact(4)
        .flat_map(|p| {
            [p[0], p[1], p[2]].map(|c| (luxon_plugin::linear_to_srgb(c) * 255.0).round() as u8)
        })
        .collect()
}

/// Samples per pixel of the rendered reference: four times the most any swept setting can
/// give a pixel, at least 64 and at most 1024.
pub fn reference_samples(desc: &SceneDesc, curves: &[Curve]) -> u32 {
    let most = curves
        .iter()
        .flat_map(|c| &c.settings)
        .map(|s| s.max_samples(&desc.render))
        .chain([desc.render.samples as u64])
        .max()
        .unwrap_or(1);
    (most * 4).clamp(64, 1024) as u32
}

/// The reference's settings: every varied parameter at its most accurate value (most samples,
/// deepest rays, smallest volume step, bilinear textures: with many samples per pixel the
/// samples do the area filtering, and MIP's own blur would come twice), uniform sampling.
fn reference_desc(desc: &SceneDesc, curves: &[Curve], samples: u32) -> Result<SceneDesc, Error> {
    let mut d = desc.clone();
    for c in curves {
        let best = match c.param {
            Param::MaxDepth => c.settings.iter().max_by_key(|s| match s {
                Setting::MaxDepth(n) => *n,
                _ => 0,
            }),
            Param::VolumeStep => c.settings.iter().min_by(|a, b| match (a, b) {
                (Setting::VolumeStep(x), Setting::VolumeStep(y)) => x.total_cmp(y),
                _ => std::cmp::Ordering::Equal,
            }),
            Param::TextureFilter => Some(&Setting::TextureFilter("bilinear")),
            Param::Samples | Param::Adaptive => None,
        };
        if let Some(s) = best {
            s.apply(&mut d)?;
        }
    }
    d.render.samples = samples;
    d.render.adaptive = None;
    Ok(d)
}

/// The scene of `desc` at `frame` (`None`: as built).
fn build(desc: &SceneDesc, registry: &Registry, frame: Option<u32>) -> Result<Scene, Error> {
    let mut scene = Scene::build(desc, registry)?;
    if let Some(k) = frame {
        scene.set_frame(k)?;
    }
    Ok(scene)
}

fn render_timed(scene: &Scene, runs: u32) -> Result<(Framebuffer, u64, u64, Duration), Error> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let (fb, stats) = crate::render::render(scene, &|_, _| {})?;
        times.push(stats.render_time);
        last = Some((fb, stats.counters.rays(), stats.counters.primary));
    }
    times.sort();
    let (fb, rays, primary) = last.ok_or_else(|| Error::Render("no render".into()))?;
    Ok((fb, rays, primary, times[times.len() / 2]))
}

/// Runs the sweep: the reference first (or reads it), then every curve's settings in order.
/// `progress` is told what is being rendered.
pub fn run(
    desc: &SceneDesc,
    registry: &Registry,
    options: &Options,
    progress: &dyn Fn(&str),
) -> Result<Sweep, Error> {
    if options.curves.is_empty() {
        return Err(Error::Usage(
            "nothing to sweep: give at least one --vary PARAMETER=VALUES".into(),
        ));
    }
    // Every value must apply before anything is rendered.
    for s in options.curves.iter().flat_map(|c| &c.settings) {
        s.apply(&mut desc.clone())?;
    }
    let (w, h) = (desc.render.width, desc.render.height);
    let (reference, reference_rgb) = match &options.reference {
        Some(path) => {
            let img = image::open(path)
                .map_err(|e| Error::Usage(format!("reference {}: {e}", path.display())))?
                .to_rgb8();
            if img.dimensions() != (w, h) {
                return Err(Error::Usage(format!(
                    "reference {} is {}x{}, but the scene renders {w}x{h} (set the resolution with --res)",
                    path.display(),
                    img.width(),
                    img.height()
                )));
            }
            (format!("the image {}", path.display()), img.into_raw())
        }
        None => {
            let samples = options
                .reference_samples
                .unwrap_or_else(|| reference_samples(desc, &options.curves));
            progress(&format!("reference ({samples} samples per pixel)"));
            let d = reference_desc(desc, &options.curves, samples)?;
            let scene = build(&d, registry, options.frame)?;
            let (fb, _, _, time) = render_timed(&scene, 1)?;
            (
                format!(
                    "rendered with {samples} uniform samples per pixel and every varied parameter at its most accurate value ({:.3} s)",
                    time.as_secs_f64()
                ),
                to_rgb8(&fb),
            )
        }
    };
    let reference_gray = crate::metrics::gray(&reference_rgb);

    let mut base: Option<Scene> = None;
    let mut rows = Vec::new();
    // Settings of the shared built scene get their further runs round-robin after every
    // setting has rendered once, so a change in the machine's load over the sweep (it is often
    // shared) falls on all of them alike instead of on whichever ran then.
    let mut later: Vec<(usize, Settings, Vec<Duration>)> = Vec::new();
    for curve in &options.curves {
        for setting in &curve.settings {
            let label = format!("{}={}", curve.param.name(), setting.label());
            progress(&label);
            let rebuilt;
            let scene: &Scene = if setting.rebuilds() {
                let mut d = desc.clone();
                setting.apply(&mut d)?;
                rebuilt = build(&d, registry, options.frame)?;
                &rebuilt
            } else {
                if base.is_none() {
                    base = Some(build(desc, registry, options.frame)?);
                }
                let scene = base
                    .as_mut()
                    .ok_or_else(|| Error::Render("no scene".into()))?;
                scene.settings = settings_of(desc, scene.settings.clone());
                setting.apply_settings(&mut scene.settings);
                scene.features.antialiasing =
                    scene.settings.samples > 1 || scene.settings.adaptive.is_some();
                scene
            };
            let runs = if setting.rebuilds() { options.runs } else { 1 };
            let (fb, rays, primary, time) = render_timed(scene, runs)?;
            if !setting.rebuilds() {
                later.push((rows.len(), scene.settings.clone(), vec![time]));
            }
            let rgb = to_rgb8(&fb);
            let rmse = crate::metrics::rmse(&rgb, &reference_rgb);
            let gray = crate::metrics::gray(&rgb);
            rows.push(Row {
                param: curve.param,
                value: setting.label(),
                time,
                rays,
                samples_per_pixel: primary as f64 / (w as f64 * h as f64),
                rmse,
                psnr: crate::metrics::psnr(rmse),
                ssim: crate::metrics::ssim(&gray, &reference_gray, w as usize, h as usize),
                rgb,
            });
        }
    }
    if let Some(scene) = base.as_mut() {
        for _ in 1..options.runs.max(1) {
            for (_, settings, times) in &mut later {
                scene.settings = settings.clone();
                scene.features.antialiasing =
                    scene.settings.samples > 1 || scene.settings.adaptive.is_some();
                times.push(crate::render::render(scene, &|_, _| {})?.1.render_time);
            }
        }
    }
    for (row, _, mut times) in later {
        times.sort();
        rows[row].time = times[times.len() / 2];
    }
    Ok(Sweep {
        width: w,
        height: h,
        rows,
        reference,
        reference_rgb,
        runs: options.runs.max(1),
    })
}

/// The scene's own values of what a curve changes, restored between settings.
fn settings_of(desc: &SceneDesc, mut s: Settings) -> Settings {
    s.samples = desc.render.samples;
    s.max_depth = desc.render.max_depth;
    s.adaptive = desc.render.adaptive;
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_curves() {
        let c: Curve = "samples=1, 4,16".parse().unwrap();
        assert_eq!(c.param, Param::Samples);
        assert_eq!(
            c.settings,
            vec![
                Setting::Samples(1),
                Setting::Samples(4),
                Setting::Samples(16)
            ]
        );
        let c: Curve = "adaptive=off,0.1,0.02:4".parse().unwrap();
        assert_eq!(
            c.settings.iter().map(Setting::label).collect::<Vec<_>>(),
            ["off", "0.1:3", "0.02:4"]
        );
        let c: Curve = "texture_filter=nearest,mip".parse().unwrap();
        assert!(c.settings[0].rebuilds());
        let err = |s: &str| s.parse::<Curve>().unwrap_err().to_string();
        assert!(err("samples").contains("expected PARAMETER=VALUE"));
        assert!(err("sample=1").contains("did you mean `samples`"));
        assert!(err("samples=1,,4").contains("empty value"));
        assert!(err("samples=0").contains("whole number from 1"));
        assert!(err("max_depth=x").contains("`x`"));
        assert!(err("texture_filter=cubic").contains("nearest, bilinear or mip"));
        assert!(err("adaptive=0.1:9").contains("depth"));
        assert!(err("volume_step=-1").contains("greater than 0"));
    }
}
