//! Tachyon's shading switches for any scene: `--shade`, `--max-depth`, `--no-shadows`, `--ao`;
//! the volume sampling switches `--volume-step`, `--volume-skip`; and how instances are
//! realised, `--instancing`; an animated scene's shutter, `--shutter`.

use luxon::Error;
use luxon_formats::{AoDesc, LightDesc, SceneDesc};

#[derive(clap::Args, Default, Debug)]
pub struct ShadingArgs {
    /// Shading level: full; medium (no shadows); low (no shadows, no reflections); lowest (flat
    /// colour: no lighting at all).
    #[arg(long, value_parser = ["full", "medium", "low", "lowest"])]
    pub shade: Option<String>,
    /// Maximum ray depth (0: primary rays only).
    #[arg(long = "max-depth")]
    pub max_depth: Option<u32>,
    /// No shadow rays for any light.
    #[arg(long = "no-shadows")]
    pub no_shadows: bool,
    /// Ambient occlusion with SAMPLES rays per shading point, for a scene that has none.
    #[arg(long, value_name = "SAMPLES")]
    pub ao: Option<u32>,
    /// Multiplies every volume's sampling step (render setting `volume_step`): 2 takes half the
    /// samples, 0.5 twice as many.
    #[arg(long = "volume-step", value_name = "FACTOR")]
    pub volume_step: Option<f64>,
    /// Empty-space skipping in volumes (render setting `volume_skip`; the image is the same).
    #[arg(long = "volume-skip", value_parser = ["on", "off"])]
    pub volume_skip: Option<String>,
    /// How instances of prototypes are realised (render setting `instancing`): bake (flat
    /// copies, bitwise the flat scene), share (one copy per prototype, a two-level BVH), auto.
    #[arg(long, value_parser = ["auto", "bake", "share"])]
    pub instancing: Option<String>,
    /// An animated scene's shutter (motion blur), overriding its `animation: (shutter: ...)`:
    /// LENGTH in frames (0 to 2), optionally placed at the frame's start, centre (default) or
    /// end; `off`: no shutter (frames at their own time).
    #[arg(long, value_name = "LENGTH[:start|centre|end]|off")]
    pub shutter: Option<String>,
}

/// The shutter `--shutter` asks for; `None`: `off`.
pub fn parse_shutter(s: &str) -> Result<Option<luxon_formats::ShutterDesc>, Error> {
    use luxon_formats::{ShutterAt, ShutterDesc};
    if s == "off" {
        return Ok(None);
    }
    let bad = || {
        Error::Usage(format!(
            "--shutter {s}: expected LENGTH[:start|centre|end] with LENGTH in frames from 0 to \
             2 (e.g. 0.5:centre), or off"
        ))
    };
    let (length, at) = s.split_once(':').unwrap_or((s, "centre"));
    let length: f64 = length.trim().parse().map_err(|_| bad())?;
    if !(0.0..=2.0).contains(&length) {
        return Err(bad());
    }
    let at = match at.trim() {
        "start" => ShutterAt::Start,
        "centre" | "center" => ShutterAt::Centre,
        "end" => ShutterAt::End,
        _ => return Err(bad()),
    };
    Ok(Some(ShutterDesc { length, at }))
}

/// `--shutter s` on an animated scene (`render`, `check` and `sweep`).
pub fn set_shutter(desc: &mut SceneDesc, s: &str) -> Result<(), Error> {
    let shutter = parse_shutter(s)?;
    let Some(a) = &mut desc.animation else {
        return Err(Error::Usage(format!(
            "--shutter {s}: {} has no `animation:`; a shutter needs an animated scene",
            desc.source.display()
        )));
    };
    let at = a.at.clone();
    a.value.shutter = shutter.map(|value| luxon_formats::Spanned { value, at });
    Ok(())
}

fn no_shadows(desc: &mut SceneDesc) {
    for l in &mut desc.lights {
        match &mut l.value {
            LightDesc::Point { shadows, .. }
            | LightDesc::Directional { shadows, .. }
            | LightDesc::Spot { shadows, .. }
            | LightDesc::Sphere { shadows, .. }
            | LightDesc::Rect { shadows, .. } => *shadows = false,
        }
    }
}

impl ShadingArgs {
    pub fn apply(&self, desc: &mut SceneDesc) -> Result<(), Error> {
        if let Some(d) = self.max_depth {
            if d > 1024 {
                return Err(Error::Usage(format!("--max-depth {d}: expected 0..=1024")));
            }
            desc.render.max_depth = d;
        }
        if let Some(n) = self.ao {
            if n == 0 || n > 4096 {
                return Err(Error::Usage(format!("--ao {n}: expected 1..=4096 samples")));
            }
            match &mut desc.ambient_occlusion {
                Some(ao) => ao.samples = n,
                None => {
                    desc.ambient_occlusion = Some(AoDesc {
                        samples: n,
                        max_distance: f64::INFINITY,
                        color: [1.0; 3],
                        intensity: 1.0,
                        direct: 1.0,
                    })
                }
            }
        }
        if let Some(f) = self.volume_step {
            if !(f > 0.0 && f.is_finite()) {
                return Err(Error::Usage(format!(
                    "--volume-step {f}: expected a factor greater than 0"
                )));
            }
            desc.render.volume_step = f;
        }
        if let Some(s) = &self.volume_skip {
            desc.render.volume_skip = s == "on";
        }
        if let Some(s) = &self.instancing {
            use luxon_formats::Instancing;
            desc.render.instancing = match s.as_str() {
                "bake" => Instancing::Bake,
                "share" => Instancing::Share,
                _ => Instancing::Auto,
            };
        }
        if let Some(s) = &self.shutter {
            set_shutter(desc, s)?;
        }
        if self.no_shadows {
            no_shadows(desc);
        }
        match self.shade.as_deref() {
            None | Some("full") => {}
            Some("medium") => no_shadows(desc),
            Some("low") => {
                no_shadows(desc);
                for (_, m) in &mut desc.materials {
                    m.value.reflect = 0.0;
                }
            }
            Some(_) => {
                // Flat colour: every surface shows its colour, unlit.
                no_shadows(desc);
                desc.ambient_occlusion = None;
                for (_, m) in &mut desc.materials {
                    let m = &mut m.value;
                    (m.ambient, m.diffuse, m.specular, m.reflect, m.transmit) =
                        (1.0, 0.0, 0.0, 0.0, 0.0);
                    m.reflect_texture = None;
                    m.transmit_texture = None;
                }
            }
        }
        Ok(())
    }
}
