//! One file's serde values plus its span tree into checked `desc` values with positions.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::desc::*;
use crate::error::shown;
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

/// What one file says (without its includes). `None`: the file does not give it.
#[derive(Default)]
pub(crate) struct Part {
    pub camera: Option<Spanned<CameraDesc>>,
    pub background: Option<BackgroundDesc>,
    pub lights: Vec<Spanned<LightDesc>>,
    pub fog: Option<FogDesc>,
    pub ambient_occlusion: Option<AoDesc>,
    pub textures: Vec<(String, Spanned<PluginCall>)>,
    pub materials: Vec<(String, Spanned<MaterialDesc>)>,
    pub clip_groups: Vec<(String, Spanned<Vec<ClipPlaneDesc>>)>,
    pub objects: Vec<Spanned<ObjectDesc>>,
    pub volumes: Vec<Spanned<VolumeDescEntry>>,
    /// `meshes:` entries, read after merging (see `ron_scene`).
    pub meshes: Vec<MeshFile>,
    /// Without outputs: those are merged as a list, the rest as a whole.
    pub render: Option<RenderDesc>,
    pub outputs: Vec<OutputDesc>,
    pub plugin_path: Vec<PathBuf>,
    pub animation: Option<Spanned<AnimationDesc>>,
    /// The named lights and objects (index within this part's list).
    pub light_names: Vec<(usize, Spanned<String>)>,
    pub object_names: Vec<(usize, Spanned<String>)>,
    pub prototypes: Vec<(String, Spanned<PrototypeDesc>)>,
    pub instances: Vec<Spanned<InstanceDesc>>,
    pub series: Vec<Spanned<SeriesDesc>>,
    /// The named instances (index within this part's list).
    pub instance_names: Vec<(usize, Spanned<String>)>,
    /// Where this part's `render` gives `frame` or `time` (which an animation decides).
    pub render_clock: Option<Origin>,
}

type Result<T> = std::result::Result<T, crate::error::SceneError>;

fn angle(a: raw::TransparencyAngle) -> TransparencyAngle {
    match a {
        raw::TransparencyAngle::Constant => TransparencyAngle::Constant,
        raw::TransparencyAngle::Raster3D => TransparencyAngle::Raster3D,
    }
}

impl Checker<'_> {
    /// Converts everything but `include`, which the loader follows.
    pub fn part(&self, scene: raw::Scene, root: &Node) -> Result<Part> {
        let dir = self
            .src
            .file
            .parent()
            .unwrap_or(Path::new(""))
            .to_path_buf();
        let field = |name| root.field(name).unwrap_or(root);
        let mut part = Part {
            plugin_path: scene.plugin_path.iter().map(|p| dir.join(p)).collect(),
            ..Part::default()
        };
        if let Some(camera) = scene.camera {
            part.camera = Some(self.camera(camera, field("camera"))?);
        }
        if let Some(background) = scene.background {
            part.background = Some(self.background(background, field("background"))?);
        }
        if let Some(fog) = scene.fog {
            part.fog = Some(self.fog(fog, field("fog"))?);
        }
        if let Some(ao) = scene.ambient_occlusion {
            part.ambient_occlusion = Some(self.ao(ao, field("ambient_occlusion"))?);
        }
        part.light_names = self.item_names(
            field("lights"),
            scene.lights.iter().map(raw::Light::name),
            "light",
        )?;
        part.object_names = self.item_names(
            field("objects"),
            scene.objects.iter().map(|o| o.name.as_deref()),
            "object",
        )?;
        for (i, light) in scene.lights.into_iter().enumerate() {
            let node = field("lights").item(i).unwrap_or(root);
            part.lights.push(self.light(light, node)?);
        }
        self.names_once(field("textures"), "texture", &scene.textures.0)?;
        self.names_once(field("materials"), "material", &scene.materials.0)?;
        self.names_once(field("clip_groups"), "clip group", &scene.clip_groups.0)?;
        for (i, (name, texture)) in scene.textures.0.into_iter().enumerate() {
            let (key, node) = field("textures").entry(i).unwrap_or((root, root));
            let plugin = self.plugin_name(
                node.field("plugin").unwrap_or(node),
                texture.plugin,
                "checker",
            )?;
            let call = self.call(plugin, node);
            part.textures.push((name, self.spanned(call, key)));
        }
        for (i, (name, material)) in scene.materials.0.into_iter().enumerate() {
            let (key, node) = field("materials").entry(i).unwrap_or((root, root));
            let material = self.material(material, node)?;
            part.materials.push((name, self.spanned(material, key)));
        }
        for (i, (name, planes)) in scene.clip_groups.0.into_iter().enumerate() {
            let (key, node) = field("clip_groups").entry(i).unwrap_or((root, root));
            let mut group = Vec::new();
            for (k, p) in planes.into_iter().enumerate() {
                let at = node.item(k).unwrap_or(node);
                let n = p.normal;
                if (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) == 0.0 {
                    return Err(self.error(
                        at.field("normal").unwrap_or(at),
                        "the clip plane's `normal` has zero length; expected a non-zero vector",
                    ));
                }
                group.push(ClipPlaneDesc {
                    point: p.point,
                    normal: n,
                });
            }
            part.clip_groups.push((name, self.spanned(group, key)));
        }
        for (i, object) in scene.objects.into_iter().enumerate() {
            let node = field("objects").item(i).unwrap_or(root);
            part.objects.push(self.object(object, node)?);
        }
        self.names_once(field("prototypes"), "prototype", &scene.prototypes.0)?;
        for (i, (name, p)) in scene.prototypes.0.into_iter().enumerate() {
            let (key, node) = field("prototypes").entry(i).unwrap_or((root, root));
            part.prototypes.push((name, self.prototype(p, key, node)?));
        }
        part.instance_names = self.item_names(
            field("instances"),
            scene.instances.iter().map(|o| o.name.as_deref()),
            "instance",
        )?;
        for (i, instance) in scene.instances.into_iter().enumerate() {
            let node = field("instances").item(i).unwrap_or(root);
            part.instances.push(self.instance(instance, node)?);
        }
        for (i, s) in scene.series.into_iter().enumerate() {
            let node = field("series").item(i).unwrap_or(root);
            part.series.push(self.series(s, node)?);
        }
        for (i, volume) in scene.volumes.into_iter().enumerate() {
            let node = field("volumes").item(i).unwrap_or(root);
            part.volumes.push(self.volume(volume, node)?);
        }
        for (i, mesh) in scene.meshes.into_iter().enumerate() {
            let node = field("meshes").item(i).unwrap_or(root);
            part.meshes.push(self.mesh(mesh, node)?);
        }
        if let Some(a) = scene.animation {
            let at = field("animation");
            part.animation = Some(self.spanned(self.animation(a, at)?, at));
        }
        if let Some(render) = scene.render {
            part.render_clock = ["frame", "time"]
                .into_iter()
                .zip([render.frame.is_some(), render.time.is_some()])
                .find(|(_, given)| *given)
                .map(|(name, _)| self.origin(field("render").field(name).unwrap_or(root)));
            let (render, outputs) = self.render(render, field("render"), &dir)?;
            part.render = Some(render);
            part.outputs = outputs;
        }
        Ok(part)
    }

    /// A `meshes:` entry (of the scene or of a prototype) at `node`, its path resolved against
    /// this file's directory.
    pub(crate) fn mesh(&self, mesh: raw::Mesh, node: &Node) -> Result<MeshFile> {
        let file_node = node.field("file").unwrap_or(node);
        if mesh.file.trim().is_empty() {
            return Err(self.error(
                file_node,
                "the mesh file name is empty; expected a path such as \"teapot.obj\"",
            ));
        }
        let dir = self.src.file.parent().unwrap_or(Path::new(""));
        let material = mesh
            .material
            .map(|m| self.spanned(m, node.field("material").unwrap_or(node)));
        Ok(MeshFile {
            file: self.spanned(dir.join(&mesh.file), file_node),
            material,
        })
    }

    /// An object of `objects:` (or of a prototype) at `node`.
    pub(crate) fn object(&self, object: raw::Object, node: &Node) -> Result<Spanned<ObjectDesc>> {
        let plugin = self.plugin_name(
            node.field("plugin").unwrap_or(node),
            object.plugin,
            "sphere",
        )?;
        let material = object
            .material
            .map(|m| self.spanned(m, node.field("material").unwrap_or(node)));
        let clip = object
            .clip
            .map(|c| self.spanned(c, node.field("clip").unwrap_or(node)));
        let call = self.call(plugin, node);
        Ok(self.spanned(
            ObjectDesc {
                call,
                material,
                clip,
                shadows: object.shadows.unwrap_or(true),
            },
            node,
        ))
    }

    /// Each name of a map (`node`, holding `entries`) once: a second definition in the same
    /// file is an error at its key, naming the first (a file that includes this one may still
    /// redefine the name: later files win).
    pub(crate) fn names_once<T>(
        &self,
        node: &Node,
        what: &str,
        entries: &[(String, T)],
    ) -> Result<()> {
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for (i, (name, _)) in entries.iter().enumerate() {
            if let Some(&first) = seen.get(name.as_str()) {
                let at = |k| node.entry(k).map_or(node, |(key, _)| key);
                let first = self.origin(at(first));
                return Err(self.error(
                    at(i),
                    format!(
                        "{what} `{}` is defined twice in this file (first at {}:{}); expected \
                         each name once (a file that includes this one may redefine it)",
                        shown(name),
                        first.line,
                        first.col
                    ),
                ));
            }
            seen.insert(name, i);
        }
        Ok(())
    }

    /// A plugin name and its `params` text, verbatim; "()" at the entry when absent.
    fn call(&self, plugin: Spanned<String>, entry: &Node) -> PluginCall {
        let (params, params_at) = self.params(entry);
        PluginCall {
            plugin,
            params,
            params_at,
        }
    }

    fn params(&self, entry: &Node) -> (String, Origin) {
        match entry.raw_field("params") {
            Some(node) => (self.src.slice(node).to_string(), self.origin(node)),
            None => ("()".to_string(), self.origin(entry)),
        }
    }

    fn volume(&self, v: raw::Volume, node: &Node) -> Result<Spanned<VolumeDescEntry>> {
        let field = |name| node.field(name).unwrap_or(node);
        let plugin = self.plugin_name(field("plugin"), v.plugin, "raw")?;
        let name = match v.name {
            Some(name) if name.trim().is_empty() => {
                return Err(self.error(
                    field("name"),
                    "the volume name is empty; expected a name such as \"head\" (or no `name`)",
                ))
            }
            Some(name) => Some(self.spanned(name, field("name"))),
            None => None,
        };
        let render = match v.render {
            Some(r) => {
                let at = field("render");
                Some(self.spanned(self.volume_render(r, at)?, at))
            }
            None => None,
        };
        let call = self.call(plugin, node);
        Ok(self.spanned(VolumeDescEntry { call, name, render }, node))
    }

    fn material(&self, m: raw::Material, node: &Node) -> Result<MaterialDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        let d = MaterialDesc::default();
        let coefficient = |name, value: Option<f64>, default, max| match value {
            Some(v) => self.range(field(name), name, v, 0.0, max),
            None => Ok(default),
        };
        let inf = f64::INFINITY;
        let positive = |name, value: Option<f64>, default| match value {
            Some(v) => self.positive(field(name), name, v),
            None => Ok(default),
        };
        Ok(MaterialDesc {
            color: match m.color {
                Some(c) => self.colour(field("color"), "color", c)?,
                None => d.color,
            },
            texture: m.texture.map(|t| self.spanned(t, field("texture"))),
            reflect_texture: m
                .reflect_texture
                .map(|t| self.spanned(t, field("reflect_texture"))),
            transmit_texture: m
                .transmit_texture
                .map(|t| self.spanned(t, field("transmit_texture"))),
            ambient: coefficient("ambient", m.ambient, d.ambient, inf)?,
            diffuse: coefficient("diffuse", m.diffuse, d.diffuse, inf)?,
            specular: coefficient("specular", m.specular, d.specular, inf)?,
            shininess: positive("shininess", m.shininess, d.shininess)?,
            highlight: match m.highlight {
                Some(raw::Highlight::Phong) => Highlight::Phong,
                Some(raw::Highlight::Blinn) => Highlight::Blinn,
                Some(raw::Highlight::BlinnFast) => Highlight::BlinnFast,
                None => d.highlight,
            },
            highlight_color: match m.highlight_color {
                Some(raw::HighlightColor::Light) => HighlightColor::Light,
                Some(raw::HighlightColor::Surface) => HighlightColor::Surface,
                None => d.highlight_color,
            },
            reflect: coefficient("reflect", m.reflect, d.reflect, 1.0)?,
            transmit: coefficient("transmit", m.transmit, d.transmit, 1.0)?,
            ior: positive("ior", m.ior, d.ior)?,
            transparency_angle: m.transparency_angle.map(angle),
            outline: coefficient("outline", m.outline, d.outline, 1.0)?,
            outline_width: coefficient("outline_width", m.outline_width, d.outline_width, 1.0)?,
            fog: m.fog.unwrap_or(d.fog),
        })
    }

    fn render(
        &self,
        r: raw::Render,
        node: &Node,
        dir: &Path,
    ) -> Result<(RenderDesc, Vec<OutputDesc>)> {
        let field = |name| node.field(name).unwrap_or(node);
        let d = RenderDesc::default();
        let whole = |name, value: Option<f64>, default, min, max| match value {
            Some(v) => self.whole(field(name), name, v, min, max),
            None => Ok(default),
        };
        let width = whole("width", r.width, d.width, 1, 65536)?;
        let height = whole("height", r.height, d.height, 1, 65536)?;
        let pixels = u64::from(width) * u64::from(height);
        if pixels > 268_435_456 {
            return Err(self.error(
                field("width"),
                format!(
                    "the image is absurdly large: {width} x {height} = {pixels} pixels; \
                     expected at most 268435456 pixels"
                ),
            ));
        }
        let min_weight = r.min_weight.unwrap_or(d.min_weight);
        if !(0.0..1.0).contains(&min_weight) {
            let written = self.literal(field("min_weight"));
            return Err(self.error(
                field("min_weight"),
                format!("`min_weight` is {written}; expected at least 0 and less than 1"),
            ));
        }
        let mut outputs = Vec::new();
        for (i, output) in r.outputs.into_iter().enumerate() {
            let entry = field("outputs").item(i).unwrap_or(node);
            outputs.push(self.output(output, entry, dir)?);
        }
        let render = RenderDesc {
            width,
            height,
            samples: whole("samples", r.samples, d.samples, 1, 65536)?,
            max_depth: whole("max_depth", r.max_depth, d.max_depth, 0, 1024)?,
            min_weight,
            outputs: Vec::new(),
            parallel: match r.parallel {
                Some(p) => self.parallel(p, field("parallel"))?,
                None => d.parallel,
            },
            frame: whole("frame", r.frame, d.frame, 0, u32::MAX)?,
            time: r.time.unwrap_or(d.time),
            transparency: match r.transparency {
                Some(t) => self.transparency(t, field("transparency"))?,
                None => d.transparency,
            },
            volume_step: match r.volume_step {
                Some(v) => self.positive(field("volume_step"), "volume_step", v)?,
                None => d.volume_step,
            },
            volume_skip: r.volume_skip.unwrap_or(d.volume_skip),
            instancing: match r.instancing {
                Some(raw::Instancing::Auto) => Instancing::Auto,
                Some(raw::Instancing::Bake) => Instancing::Bake,
                Some(raw::Instancing::Share) => Instancing::Share,
                None => d.instancing,
            },
            memory: match &r.memory {
                Some(text) => Some(self.memory_size(field("memory"), "memory", text)?),
                None => None,
            },
            texture_cache: match &r.texture_cache {
                Some(text) => {
                    match self.memory_size(field("texture_cache"), "texture_cache", text)? {
                        MemorySize::Bytes(n) => Some(n),
                        MemorySize::Percent(_) => {
                            return Err(self.error(
                                field("texture_cache"),
                                format!(
                                "`texture_cache` is {}; expected a size in bytes such as \"512M\" \
                                 or \"1 GiB\" (not a percentage)",
                                self.literal(field("texture_cache"))
                            ),
                            ))
                        }
                    }
                }
                None => None,
            },
            adaptive: match r.adaptive {
                Some(a) => {
                    let at = field("adaptive");
                    let sub = |name| at.field(name).unwrap_or(at);
                    if !(a.threshold >= 0.0 && a.threshold.is_finite()) {
                        return Err(self.error(
                            sub("threshold"),
                            format!(
                                "`threshold` is {}; expected a number of at least 0 (a colour difference, e.g. 0.05)",
                                self.literal(sub("threshold"))
                            ),
                        ));
                    }
                    Some(AdaptiveDesc {
                        threshold: a.threshold,
                        max_depth: match a.max_depth {
                            Some(n) => {
                                self.whole(sub("max_depth"), "max_depth", n, 0, ADAPTIVE_MAX_DEPTH)?
                            }
                            None => 3,
                        },
                    })
                }
                None => None,
            },
            light_scale: match r.light_scale {
                Some(s) => {
                    self.range(field("light_scale"), "light_scale", s, 0.0, f64::INFINITY)?
                }
                None => d.light_scale,
            },
            tachyon: match r.tachyon {
                Some(t) => TachyonDesc {
                    light_threshold: t.light_threshold.unwrap_or(false),
                    plain_highlights: t.plain_highlights.unwrap_or(false),
                    depth_limit_background: t.depth_limit_background.unwrap_or(false),
                    centre_sample: t.centre_sample.unwrap_or(false),
                    additive_volumes: t.additive_volumes.unwrap_or(false),
                    terminator_shadows: t.terminator_shadows.unwrap_or(false),
                },
                None => d.tachyon,
            },
        };
        Ok((render, outputs))
    }

    fn transparency(&self, t: raw::Transparency, node: &Node) -> Result<TransparencyDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        let d = TransparencyDesc::default();
        let mode = match t.mode {
            Some(raw::TransparencyMode::Filter) | None => TransparencyMode::Filter,
            Some(raw::TransparencyMode::AngleModulated) => TransparencyMode::AngleModulated,
            Some(raw::TransparencyMode::PostMultiplied) => TransparencyMode::PostMultiplied,
            Some(raw::TransparencyMode::Additive) => TransparencyMode::Additive,
        };
        let angle = t.angle.map_or(d.angle, angle);
        if mode == TransparencyMode::AngleModulated && angle != TransparencyAngle::Constant {
            return Err(self.error(
                field("angle"),
                "`angle` is given with `mode: AngleModulated`, which has its own angle rule; \
                 expected one of them (e.g. `mode: Filter, angle: Raster3D`)",
            ));
        }
        let scale_reflection = t.scale_reflection.unwrap_or(d.scale_reflection);
        if scale_reflection && mode != TransparencyMode::PostMultiplied {
            return Err(self.error(
                field("scale_reflection"),
                "`scale_reflection` scales the reflection by opacity in `mode: PostMultiplied` \
                 only; expected that mode or no `scale_reflection`",
            ));
        }
        Ok(TransparencyDesc {
            mode,
            angle,
            max_surfaces: match t.max_surfaces {
                Some(n) => Some(self.whole(field("max_surfaces"), "max_surfaces", n, 0, 1024)?),
                None => None,
            },
            beyond_max: match t.beyond_max {
                Some(raw::BeyondMax::Opaque) => BeyondMax::Opaque,
                Some(raw::BeyondMax::Skip) => BeyondMax::Skip,
                None => d.beyond_max,
            },
            shadows: match t.shadows {
                Some(raw::TransparentShadows::Tinted) => TransparentShadows::Tinted,
                Some(raw::TransparentShadows::Untinted) => TransparentShadows::Untinted,
                Some(raw::TransparentShadows::Off) => TransparentShadows::Off,
                None => d.shadows,
            },
            scale_reflection,
        })
    }

    fn output(&self, o: raw::Output, entry: &Node, dir: &Path) -> Result<OutputDesc> {
        let field = |name| entry.field(name).unwrap_or(entry);
        if o.path.trim().is_empty() {
            return Err(self.error(
                field("path"),
                "the output path is empty; expected a file name such as \"out.png\"",
            ));
        }
        let plugin = match o.plugin {
            Some(name) => Some(self.plugin_name(field("plugin"), name, "png")?),
            None => None,
        };
        let (params, params_at) = self.params(entry);
        Ok(OutputDesc {
            path: dir.join(&o.path),
            plugin,
            params,
            params_at,
        })
    }

    fn parallel(&self, p: raw::Parallel, node: &Node) -> Result<ParallelDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        let d = ParallelDesc::default();
        Ok(ParallelDesc {
            mode: match p.mode {
                Some(raw::Mode::Threads) => ParallelMode::Threads,
                Some(raw::Mode::Mpi) => ParallelMode::Mpi,
                Some(raw::Mode::Hybrid) => ParallelMode::Hybrid,
                None => d.mode,
            },
            threads: match p.threads {
                Some(t) => Some(self.whole(field("threads"), "threads", t, 1, 4096)?),
                None => None,
            },
            decomposition: match p.decomposition {
                Some(raw::Decomposition::PixelCyclic) => Decomposition::PixelCyclic,
                Some(raw::Decomposition::ScanlineCyclic) => Decomposition::ScanlineCyclic,
                Some(raw::Decomposition::BlockCyclic) => Decomposition::BlockCyclic,
                Some(raw::Decomposition::Dynamic) => Decomposition::Dynamic,
                None => d.decomposition,
            },
            tile_size: match p.tile_size {
                Some(t) => self.whole(field("tile_size"), "tile_size", t, 1, 4096)?,
                None => d.tile_size,
            },
            io: match p.io {
                Some(raw::IoMode::Async) => OutputIo::Async,
                Some(raw::IoMode::Sync) => OutputIo::Sync,
                Some(raw::IoMode::MpiIo) => OutputIo::MpiIo,
                None => d.io,
            },
            frames: match p.frames {
                Some(raw::Frames::Whole) => FrameGroups::Whole,
                Some(raw::Frames::Shared) => FrameGroups::Shared,
                Some(raw::Frames::Groups(n)) => {
                    let at = field("frames");
                    let n = self.whole(at.item(0).unwrap_or(at), "Groups", n, 1, 65536)?;
                    FrameGroups::Groups(n)
                }
                None => d.frames,
            },
        })
    }
}
