//! The syntax tree to a `SceneDesc`: statements in file order (last CAMERA, BACKGROUND and FOG
//! win; shader options accumulate), then the render settings. What each mapping does and why
//! is in the module documentation (`mod.rs`).

use std::collections::HashSet;

use super::materials::Materials;
use super::notes::Notes;
use super::options::{Highlights, Options};
use super::shapes::{tpoly_vertex, volume_slices, Shapes};
use super::syntax::*;
use super::terrain::scape;
use super::{mirror, Warnings};
use crate::desc::{
    AoDesc, Attenuation, BackgroundDesc, BeyondMax, CameraDesc, DepthOfField, FogDesc,
    FogMode as LuxFog, Frustum, GradientDesc, GradientKind, Highlight, LightDesc, MaterialDesc,
    Projection as LuxProjection, RenderDesc, SceneDesc, SpotFade, TachyonDesc, TransparencyAngle,
    TransparencyDesc, TransparencyMode, TransparentShadows,
};
use crate::error::SceneError;
use crate::origin::{Origin, Spanned};

type Result<T> = std::result::Result<T, SceneError>;

/// Luxon's deepest ray tree (render threads' stacks are sized for it).
const MAX_DEPTH: u32 = 1024;

/// The shading state SHADER_MODE statements build up.
struct Shading {
    level: ShadeLevel,
    /// TRANS_VMD and TRANS_RASTER3D flags (TRANS_ORIG clears both).
    vmd: bool,
    raster3d: bool,
    max_surfaces: Option<(u32, Origin)>,
    fog_vmd: bool,
    shadow_filter_off: Option<Origin>,
}

/// Everything the statements set, in order.
struct Mapper {
    camera: Option<(Origin, Camera)>,
    background: V3,
    /// The last BACKGROUND_GRADIENT: once given, it is shown whatever BACKGROUND says.
    gradient: Option<BackgroundDesc>,
    fog: Option<(Origin, Fog)>,
    ao: Option<AoDesc>,
    /// Tachyon's direct light scale (RESCALE_DIRECT): it outlives the occlusion that set it.
    light_scale: f64,
    shading: Shading,
    lights: Vec<Spanned<LightDesc>>,
    materials: Materials,
    shapes: Shapes,
    notes: Notes,
    warnings: Warnings,
    /// The command line's overrides.
    options: Options,
}

pub(super) fn to_desc(scene: Scene, options: &Options) -> Result<SceneDesc> {
    let reserved: HashSet<String> = scene
        .statements
        .iter()
        .filter_map(|s| match &s.kind {
            Kind::TexDef { name, .. } | Kind::TexAlias { name, .. } => Some(name.value.clone()),
            _ => None,
        })
        .collect();
    let mut m = Mapper {
        camera: None,
        background: [0.0; 3],
        gradient: None,
        fog: None,
        ao: None,
        light_scale: 1.0,
        shading: Shading {
            level: ShadeLevel::Full,
            vmd: false,
            raster3d: false,
            max_surfaces: None,
            fog_vmd: false,
            shadow_filter_off: None,
        },
        lights: Vec::new(),
        materials: Materials::new(reserved),
        shapes: Shapes::default(),
        notes: Notes::default(),
        warnings: scene.warnings,
        options: options.clone(),
    };
    for s in &scene.statements {
        m.statement(s)?;
    }
    m.command_line_shading();
    m.finish(&scene.source, &scene.resolution, &scene.begin)
}

fn light_color(c: V3, at: &Origin) -> Result<V3> {
    if c.iter().any(|&x| x < 0.0) {
        return Err(SceneError::at(
            at.clone(),
            format!("COLOR {c:?} has a negative component; expected components of 0 or more"),
        ));
    }
    Ok(c)
}

/// BACKGROUND_GRADIENT: Tachyon blends by UPDIR·D (SKY_SPHERE, D the missed ray's direction)
/// or UPDIR·O (SKY_ORTHO_PLANE, O its origin), UPDIR as written (not normalised), mirrored
/// like every direction. A zero UPDIR gives every ray the same mix: a plain colour.
fn gradient(g: &Gradient, at: &Origin) -> Result<BackgroundDesc> {
    let top_color = light_color(g.topcolor, at)?;
    let bottom_color = light_color(g.bottomcolor, at)?;
    if g.updir == [0.0; 3] {
        let t = (0.0 - g.bottomval) / (g.topval - g.bottomval);
        // (0 / 0, a sharp horizon at 0: the bottom colour, as the core mixes there.)
        let t = if t >= 0.0 { t.min(1.0) } else { 0.0 };
        return Ok(BackgroundDesc::Color(
            [0, 1, 2].map(|k| t * top_color[k] + (1.0 - t) * bottom_color[k]),
        ));
    }
    Ok(BackgroundDesc::Gradient(GradientDesc {
        kind: match g.kind.value {
            SkyKind::Sphere => GradientKind::Sphere,
            SkyKind::OrthoPlane => GradientKind::OrthoPlane,
        },
        up: mirror(g.updir),
        top: g.topval,
        bottom: g.bottomval,
        top_color,
        bottom_color,
    }))
}

/// Vertex colours as written (display values, like every Tachyon colour), none negative.
fn vertex_colors(c: &[V3], what: &str, at: &Origin) -> Result<Vec<V3>> {
    if let Some(i) = c.iter().position(|c| c.iter().any(|&x| x < 0.0)) {
        return Err(SceneError::at(
            at.clone(),
            format!(
                "{what}: colour {i} {:?} has a negative component; expected components of 0 or \
                 more",
                c[i]
            ),
        ));
    }
    Ok(c.to_vec())
}

fn attenuation(a: &Option<Spanned<V3>>) -> Attenuation {
    match a {
        Some(a) => Attenuation {
            constant: a.value[0],
            linear: a.value[1],
            quadratic: a.value[2],
        },
        None => Attenuation::default(),
    }
}

fn nonzero(v: V3, what: &str, at: &Origin) -> Result<V3> {
    if v == [0.0; 3] {
        return Err(SceneError::at(
            at.clone(),
            format!("{what} is (0, 0, 0); expected a direction"),
        ));
    }
    Ok(v)
}

impl Mapper {
    /// The material of a texture reference.
    fn material(&mut self, tex: &TexRef) -> Result<String> {
        self.materials
            .resolve(tex, &mut self.notes, &mut self.warnings)
    }

    fn statement(&mut self, s: &Statement) -> Result<()> {
        let at = &s.at;
        match &s.kind {
            Kind::ShaderMode(mode) => self.shader_mode(mode),
            Kind::Camera(c) => self.camera = Some((at.clone(), c.clone())),
            Kind::Background(c) => self.background = light_color(*c, at)?,
            Kind::BackgroundGradient(g) => self.gradient = Some(gradient(g, at)?),
            Kind::Fog(f) => self.fog = Some((at.clone(), f.clone())),
            Kind::Light(l) => {
                let color = light_color(l.color, at)?;
                self.light_sphere(l.center, l.rad, color, at);
                self.lights.push(Spanned {
                    value: LightDesc::Point {
                        position: mirror(l.center),
                        color,
                        intensity: 1.0,
                        shadows: true,
                        attenuation: attenuation(&l.attenuation),
                    },
                    at: at.clone(),
                });
            }
            Kind::DirectionalLight { direction, color } => self.lights.push(Spanned {
                value: LightDesc::Directional {
                    direction: mirror(nonzero(*direction, "DIRECTION", at)?),
                    color: light_color(*color, at)?,
                    intensity: 1.0,
                    shadows: true,
                },
                at: at.clone(),
            }),
            Kind::Spotlight(l) => self.spotlight(l, at)?,
            Kind::SkyLight { samples, color } => {
                self.ao = (*samples > 0).then_some(AoDesc {
                    samples: *samples,
                    max_distance: f64::INFINITY,
                    color: *color,
                    intensity: 1.0,
                    direct: 1.0,
                });
            }
            Kind::TexDef { name, body } => {
                self.materials
                    .define(name, body, &mut self.notes, &mut self.warnings)?
            }
            Kind::TexAlias { name, target } => self.materials.alias(name, target, &mut self.notes),
            Kind::ImageDef(def) => self.materials.imagedef(def),
            Kind::Include { .. } => {}
            Kind::Sphere { center, rad, tex } => {
                let m = self.material(tex)?;
                self.shapes.sphere(&m, *center, *rad, at);
            }
            Kind::Tri { v, tex } => {
                let m = self.material(tex)?;
                self.shapes.triangle(&m, *v, None, None, at);
            }
            Kind::Stri { v, n, tex } => {
                let m = self.material(tex)?;
                self.shapes.triangle(&m, *v, Some(*n), None, at);
            }
            Kind::Vcstri { v, n, c, surface } => {
                // The surface's material in white: the vertex colours are the surface colour.
                let m = self
                    .materials
                    .surface_material(surface, at, &mut self.notes)?;
                let c = vertex_colors(c, "VCSTRI C0 C1 C2", at)?;
                self.shapes
                    .triangle(&m, *v, Some(*n), Some([c[0], c[1], c[2]]), at);
            }
            Kind::VertexArray(va) => self.vertex_array(va, at)?,
            Kind::Fcylinder {
                base,
                apex,
                rad,
                tex,
            } => {
                let m = self.material(tex)?;
                self.shapes.cylinder(&m, *base, *apex, *rad, at);
            }
            Kind::Cylinder {
                center,
                axis,
                rad,
                tex,
            } => {
                let m = self.material(tex)?;
                self.shapes
                    .infinite_cylinder(&m, *center, *axis, *rad, at)?;
            }
            Kind::Ring {
                center,
                normal,
                inner,
                outer,
                tex,
            } => {
                let m = self.material(tex)?;
                self.shapes
                    .ring(&m, *center, *normal, [*inner, *outer], at)?;
            }
            Kind::Plane {
                center,
                normal,
                tex,
            } => {
                let m = self.material(tex)?;
                self.shapes.plane(&m, *center, *normal, at)?;
            }
            Kind::Box { min, max, tex } => {
                let m = self.material(tex)?;
                self.shapes.boxed(&m, *min, *max, at, &mut self.warnings);
            }
            Kind::Polycylinder { points, rad, tex } => {
                let m = self.material(tex)?;
                self.shapes.polycylinder(&m, points, *rad, at);
            }
            Kind::Scape {
                res,
                scale,
                center,
                tex,
            } => {
                let m = self.material(tex)?;
                let (v, n, t) = scape(*res, *scale, *center);
                self.shapes.mesh(&m, &v, &n, None, &t, at);
            }
            Kind::ScalarVol {
                min,
                max,
                dim,
                path,
                tex,
                ..
            } => {
                let m = self.material(tex)?;
                let density = match tex {
                    TexRef::Body(b) => b.surface.opacity,
                    TexRef::Name(_) => 1.0,
                };
                let slices = match path {
                    Some(p) => volume_slices(p, *dim).map(|n| (p, n)),
                    None => Err(String::new()),
                };
                match slices {
                    Ok((p, n)) => {
                        self.notes.add(
                            "SCALARVOL",
                            "is drawn by Luxon's volume ray casting with Tachyon's colour ramp \
                             and compositing; nearest-voxel edges may sit up to a voxel apart, \
                             and shadows pass through it as through a volume (Tachyon's box \
                             blocks light wholly while its shadow filter is on)",
                            at,
                        );
                        self.shapes.volume(*min, *max, *dim, p, n, density, at)?;
                    }
                    Err(why) => {
                        // Tachyon draws the box in the texture's colour, unlit.
                        if !why.is_empty() {
                            self.warnings.push(Spanned {
                                value: format!(
                                    "{why}; Tachyon draws the volume's box in its texture's \
                                     colour instead, and so does Luxon"
                                ),
                                at: at.clone(),
                            });
                        }
                        let flat = self.materials.unlit(&m, at);
                        self.shapes.boxed(&flat, *min, *max, at, &mut self.warnings);
                    }
                }
            }
            Kind::TpolyFile {
                scale,
                rot,
                center,
                triangles,
                tex,
                ..
            } => {
                let m = self.material(tex)?;
                for t in triangles {
                    // Each record becomes TRI (v1, v0, v2).
                    let v = [t[1], t[0], t[2]].map(|p| tpoly_vertex(p, *scale, *rot, *center));
                    self.shapes.triangle(&m, v, None, None, at);
                }
            }
            Kind::StartClipGroup { planes } => self.shapes.start_clip(planes, at)?,
            Kind::EndClipGroup => self.shapes.end_clip(),
        }
        Ok(())
    }

    /// The command line's shading switches, over the scene's SHADER_MODE (Tachyon applies
    /// them after reading the scene).
    fn command_line_shading(&mut self) {
        let (o, s) = (&self.options, &mut self.shading);
        if let Some(level) = o.shade {
            s.level = level;
        }
        if let Some((vmd, raster3d)) = o.transparency {
            (s.vmd, s.raster3d) = (vmd, raster3d);
        }
        if let Some(n) = o.max_surfaces {
            s.max_surfaces = Some((n, o.at.clone()));
        }
        if let Some(on) = o.shadow_filter {
            s.shadow_filter_off = (!on).then(|| o.at.clone());
        }
        if let Some(vmd) = o.fog_vmd {
            s.fog_vmd = vmd;
        }
    }

    /// Ambient occlusion and the direct light scale: the scene's, then the command line's
    /// (`-rescale_lights` below 1 replaces the scene's RESCALE_DIRECT; `-auto_skylight f`
    /// replaces both with f and 1 − f; `-add_skylight f` only the occlusion). The scale is the
    /// occlusion's `direct` while occlusion is on, else it scales every light.
    fn lighting(&mut self, shadows: bool) -> Option<AoDesc> {
        let o = &self.options;
        let mut scale = self.light_scale;
        if let Some(s) = o.light_scale.filter(|&s| s < 1.0) {
            scale = s.max(0.0);
        }
        let mut ao = self.ao.take();
        if let Some(sky) = o.skylight.filter(|s| s.level > 0.0) {
            let old = ao.as_ref().map_or(1.0, |a| a.intensity);
            ao = (sky.samples > 0).then_some(AoDesc {
                samples: sky.samples,
                max_distance: f64::INFINITY,
                color: [sky.level; 3],
                intensity: old,
                direct: 1.0,
            });
            if sky.rescale {
                scale = (1.0 - sky.level).max(0.0);
            }
        }
        // MEDIUM and below trace no occlusion rays; the scale stays.
        if !shadows {
            ao = None;
        }
        match &mut ao {
            Some(a) => a.direct = scale,
            None if scale != 1.0 => {
                for l in &mut self.lights {
                    match &mut l.value {
                        LightDesc::Point { intensity, .. }
                        | LightDesc::Directional { intensity, .. }
                        | LightDesc::Spot { intensity, .. }
                        | LightDesc::Sphere { intensity, .. }
                        | LightDesc::Rect { intensity, .. } => *intensity *= scale,
                    }
                }
            }
            None => {}
        }
        ao
    }

    /// `-shade_phong` and the other highlight switches, on every material.
    fn highlights(&mut self, materials: &mut [(String, Spanned<MaterialDesc>)]) {
        let Some(h) = self.options.highlights else {
            return;
        };
        for (_, m) in materials.iter_mut() {
            let m = &mut m.value;
            match h {
                Highlights::Phong => m.highlight = Highlight::Phong,
                Highlights::Blinn => m.highlight = Highlight::Blinn,
                Highlights::BlinnFast => m.highlight = Highlight::BlinnFast,
                Highlights::None => m.specular = 0.0,
            }
        }
    }

    fn shader_mode(&mut self, mode: &ShaderMode) {
        let s = &mut self.shading;
        s.level = mode.level.value;
        for o in &mode.options {
            match &o.value {
                ShaderOption::ShadowFilter(on) => {
                    s.shadow_filter_off = (!on).then(|| o.at.clone());
                }
                ShaderOption::TransMaxSurfaces(n) => s.max_surfaces = Some((*n, o.at.clone())),
                ShaderOption::TransOrig => (s.vmd, s.raster3d) = (false, false),
                ShaderOption::TransRaster3d => s.raster3d = true,
                ShaderOption::TransVmd => s.vmd = true,
                ShaderOption::FogVmd => s.fog_vmd = true,
                ShaderOption::AmbientOcclusion {
                    color,
                    rescale_direct,
                    samples,
                } => {
                    self.ao = (*samples > 0).then_some(AoDesc {
                        samples: *samples,
                        max_distance: f64::INFINITY,
                        color: *color,
                        intensity: 1.0,
                        direct: 1.0,
                    });
                    self.light_scale = *rescale_direct;
                }
            }
        }
    }

    /// A light with RAD > 0 is also a sphere in its colour, unlit and unfogged, casting no
    /// shadow (Tachyon's light object).
    fn light_sphere(&mut self, center: V3, rad: f64, color: V3, at: &Origin) {
        if rad > 0.0 {
            let m = self.materials.light(color, at);
            self.shapes.light_sphere(&m, center, rad, at);
        }
    }

    fn spotlight(&mut self, l: &Spotlight, at: &Origin) -> Result<()> {
        let color = light_color(l.color, at)?;
        self.light_sphere(l.center, l.rad, color, at);
        let end = l.falloff_end.clamp(0.0, 180.0);
        let start = l.falloff_start.clamp(0.0, end);
        self.lights.push(Spanned {
            value: LightDesc::Spot {
                position: mirror(l.center),
                direction: mirror(nonzero(l.direction, "DIRECTION", at)?),
                cone_deg: 2.0 * end,
                falloff_deg: 2.0 * (end - start),
                fade: SpotFade::Linear,
                color,
                intensity: 1.0,
                shadows: true,
                attenuation: attenuation(&l.attenuation),
            },
            at: at.clone(),
        });
        Ok(())
    }

    /// A VERTEXARRAY's meshes, each with the texture and colours in effect before it. With
    /// COLORS, the texture's colour (and TEXFUNC) gives way to the vertex colours, as in
    /// Tachyon: its material in white, without texture.
    fn vertex_array(&mut self, va: &VertexArray, at: &Origin) -> Result<()> {
        let mut material = None;
        let mut colors = None;
        for block in &va.blocks {
            let b_at = &block.at;
            let triangles = match &block.value {
                VertexBlock::Colors(c) => {
                    colors = Some(vertex_colors(c, "COLORS", b_at)?);
                    continue;
                }
                VertexBlock::Texture(body) => {
                    material = Some(self.material(&TexRef::Body(body.clone()))?);
                    continue;
                }
                VertexBlock::TriMesh(t) => t.clone(),
                VertexBlock::TriStrip(s) => strip(s),
            };
            let mut m = match &material {
                Some(m) => m.clone(),
                None => self.materials.default_material(b_at),
            };
            if colors.is_some() {
                m = self.materials.vertex_colored(&m, b_at);
            }
            self.shapes.mesh(
                &m,
                &va.coords,
                &va.normals,
                colors.as_deref(),
                &triangles,
                at,
            );
        }
        Ok(())
    }

    fn finish(
        mut self,
        source: &std::path::Path,
        res: &Spanned<[u32; 2]>,
        begin: &Origin,
    ) -> Result<SceneDesc> {
        let [width, height] = self.options.resolution.unwrap_or(res.value);
        if u64::from(width) * u64::from(height) > 1 << 28 {
            return Err(SceneError::at(
                res.at.clone(),
                format!("RESOLUTION {width} {height} has more than 2^28 pixels"),
            ));
        }
        let (camera, samples, max_depth) = self.camera(width, height, begin)?;
        let level = self.shading.level;
        let mut fog = self.fog()?;
        let shadows = level == ShadeLevel::Full;
        let ao = self.lighting(shadows);
        if !shadows {
            for l in &mut self.lights {
                match &mut l.value {
                    LightDesc::Point { shadows, .. }
                    | LightDesc::Directional { shadows, .. }
                    | LightDesc::Spot { shadows, .. }
                    | LightDesc::Sphere { shadows, .. }
                    | LightDesc::Rect { shadows, .. } => *shadows = false,
                }
            }
        }
        let mut background = self
            .gradient
            .unwrap_or(BackgroundDesc::Color(self.background));
        let mut materials = std::mem::take(&mut self.materials.materials);
        let mut textures = std::mem::take(&mut self.materials.textures);
        // LOW: the texture colour, unlit; LOWEST: white on black.
        if matches!(level, ShadeLevel::Low | ShadeLevel::Lowest) {
            fog = None;
            for (_, m) in &mut materials {
                let m = &mut m.value;
                (m.ambient, m.diffuse, m.specular, m.reflect, m.transmit) =
                    (1.0, 0.0, 0.0, 0.0, 0.0);
                if level == ShadeLevel::Lowest {
                    m.color = [1.0; 3];
                    m.texture = None;
                }
            }
            if level == ShadeLevel::Lowest {
                background = BackgroundDesc::Color([0.0; 3]);
                textures.clear();
            }
        }
        self.highlights(&mut materials);
        let transparency = self.transparency();
        let mut warnings = self.warnings;
        warnings.extend(self.notes.into_warnings());
        Ok(SceneDesc {
            source: source.to_path_buf(),
            camera,
            background,
            lights: self.lights,
            fog,
            ambient_occlusion: ao,
            textures,
            materials,
            clip_groups: self.shapes.clip_groups,
            objects: self.shapes.objects,
            inline: self.shapes.groups,
            volumes: self.shapes.volumes,
            render: RenderDesc {
                width,
                height,
                samples,
                max_depth,
                transparency,
                tachyon: TachyonDesc {
                    light_threshold: true,
                    plain_highlights: true,
                    depth_limit_background: true,
                    centre_sample: true,
                    additive_volumes: true,
                    terminator_shadows: true,
                },
                ..RenderDesc::default()
            },
            animation: None,
            prototypes: Vec::new(),
            instances: Vec::new(),
            series: Vec::new(),
            plugin_path: Vec::new(),
            warnings: warnings
                .into_iter()
                .map(|w| crate::error::Warning {
                    at: w.at,
                    message: w.value,
                })
                .collect(),
        })
    }

    /// Tachyon's transparency: TRANS_ORIG adds what is behind to the unscaled shading,
    /// TRANS_VMD post-multiplies (the mirror reflection too), TRANS_RASTER3D changes opacity
    /// with the angle; later surfaces past TRANS_MAX_SURFACES are skipped; shadows through
    /// transparent surfaces are grey, or none with SHADOW_FILTER_OFF.
    fn transparency(&mut self) -> TransparencyDesc {
        let s = &self.shading;
        TransparencyDesc {
            mode: if s.vmd {
                TransparencyMode::PostMultiplied
            } else {
                TransparencyMode::Additive
            },
            angle: if s.raster3d {
                TransparencyAngle::Raster3D
            } else {
                TransparencyAngle::Constant
            },
            max_surfaces: s.max_surfaces.as_ref().map(|(n, _)| *n),
            beyond_max: BeyondMax::Skip,
            shadows: if s.shadow_filter_off.is_some() {
                TransparentShadows::Off
            } else {
                TransparentShadows::Untinted
            },
            scale_reflection: s.vmd,
        }
    }

    fn fog(&mut self) -> Result<Option<FogDesc>> {
        let Some((at, f)) = self.fog.take() else {
            return Ok(None);
        };
        let mode = match f.mode.value {
            FogMode::Off => return Ok(None),
            FogMode::Linear => {
                if f.end <= f.start {
                    return Err(SceneError::at(
                        at,
                        format!(
                            "FOG LINEAR END {} is not beyond START {}; expected START < END",
                            f.end, f.start
                        ),
                    ));
                }
                LuxFog::Linear {
                    start: f.start,
                    end: f.end,
                }
            }
            FogMode::Exp | FogMode::Exp2 => {
                if f.density <= 0.0 {
                    // Tachyon's visibility, clamped to 1: no fog.
                    return Ok(None);
                }
                // Tachyon's visibility is 1 before START: a negative START is fog from the eye
                // on, thicker.
                let (density, start) = (f.density, f.start.max(0.0));
                if f.start < 0.0 {
                    self.notes.add(
                        "FOG START below 0",
                        "starts at the eye (Tachyon's fog is already thicker there)",
                        &at,
                    );
                }
                if f.mode.value == FogMode::Exp {
                    LuxFog::Exp { density, start }
                } else {
                    LuxFog::Exp2 { density, start }
                }
            }
        };
        // Tachyon fogs every ray over its own segment; radial fog turns misses into the fog
        // colour, FOG_VMD (planar for camera rays) leaves the background alone.
        Ok(Some(FogDesc {
            mode,
            color: light_color(f.color, &at)?,
            planar: self.shading.fog_vmd,
            every_ray: true,
            misses: !self.shading.fog_vmd,
        }))
    }

    /// The camera, samples per pixel and ray depth. The image window is Tachyon's (1/zoom
    /// high at unit distance, or the FRUSTUM), moved by half a pixel right and up: Tachyon
    /// samples each pixel at its upper-right quarter point, Luxon at its centre.
    fn camera(
        &mut self,
        width: u32,
        height: u32,
        begin: &Origin,
    ) -> Result<(Spanned<CameraDesc>, u32, u32)> {
        let (at, mut c) = match self.camera.take() {
            Some(c) => c,
            None => (
                begin.clone(),
                Camera {
                    projection: None,
                    zoom: 1.0,
                    aspect: 1.0,
                    antialiasing: 0,
                    raydepth: 6,
                    center: [0.0; 3],
                    viewdir: [0.0, 0.0, 1.0],
                    updir: [0.0, 1.0, 0.0],
                    frustum: None,
                },
            ),
        };
        if let Some(n) = self.options.antialiasing {
            c.antialiasing = n;
        }
        if let Some(n) = self.options.raydepth {
            c.raydepth = n;
        }
        if c.zoom <= 0.0 {
            return Err(SceneError::at(
                at,
                format!("ZOOM is {}; expected a number greater than 0", c.zoom),
            ));
        }
        if c.aspect <= 0.0 {
            return Err(SceneError::at(
                at,
                format!(
                    "ASPECTRATIO is {}; expected a number greater than 0",
                    c.aspect
                ),
            ));
        }
        let view = nonzero(c.viewdir, "VIEWDIR", &at)?;
        let up = nonzero(c.updir, "UPDIR", &at)?;
        let cross = [
            view[1] * up[2] - view[2] * up[1],
            view[2] * up[0] - view[0] * up[2],
            view[0] * up[1] - view[1] * up[0],
        ];
        if cross == [0.0; 3] {
            return Err(SceneError::at(
                at,
                "UPDIR is parallel to VIEWDIR; expected an up direction across the view",
            ));
        }
        let (w, h) = (width as f64, height as f64);
        let window_h = 1.0 / c.zoom;
        let window_w = (w / h) / (c.aspect * c.zoom);
        let [l, r, b, t] = match &c.frustum {
            Some(f) => {
                let [l, r, b, t] = f.value;
                if !(l < r && b < t) {
                    return Err(SceneError::at(
                        f.at.clone(),
                        format!("FRUSTUM {l} {r} {b} {t}: expected left < right and bottom < top"),
                    ));
                }
                f.value
            }
            None => [
                -window_w / 2.0,
                window_w / 2.0,
                -window_h / 2.0,
                window_h / 2.0,
            ],
        };
        let (dx, dy) = ((r - l) / (2.0 * w), (t - b) / (2.0 * h));
        let shifted = Frustum {
            left: l + dx,
            right: r + dx,
            bottom: b + dy,
            top: t + dy,
        };
        let kind = c.projection.as_ref().map(|p| (p.value, p.at.clone()));
        let mut depth_of_field = None;
        let (projection, frustum) = match kind {
            None | Some((Projection::Perspective, _)) => (
                LuxProjection::PerspectiveZoom { zoom: c.zoom },
                Some(shifted),
            ),
            Some((Projection::Orthographic, _)) => {
                (LuxProjection::Orthographic { height: t - b }, Some(shifted))
            }
            // Tachyon's fisheye is a window of longitude and latitude in radians (zoom 1: one
            // radian tall), sampled like its other windows.
            Some((Projection::Fisheye, _)) => (
                LuxProjection::Equirectangular,
                Some(Frustum {
                    left: shifted.left.to_degrees(),
                    right: shifted.right.to_degrees(),
                    bottom: shifted.bottom.to_degrees(),
                    top: shifted.top.to_degrees(),
                }),
            ),
            Some((
                Projection::PerspectiveDof {
                    focal,
                    focal_dist,
                    aperture,
                },
                p_at,
            )) => {
                // Tachyon 0.99b6 ignores FOCALLENGTH and focuses on the image plane (unit
                // distance); its lens is a rectangle aperture × the window: a disc of the same
                // area stands in for it. Without antialiasing it traces the pinhole ray only.
                let focal_distance = if focal_dist { focal } else { 1.0 };
                if focal_distance <= 0.0 {
                    return Err(SceneError::at(
                        p_at,
                        format!("FOCALDIST is {focal}; expected a distance greater than 0"),
                    ));
                }
                let radius = aperture.abs() * ((r - l) * (t - b) / std::f64::consts::PI).sqrt();
                if c.antialiasing > 0 && radius > 0.0 {
                    depth_of_field = Some(DepthOfField {
                        aperture: radius,
                        focal_distance,
                    });
                }
                (
                    LuxProjection::PerspectiveZoom { zoom: c.zoom },
                    Some(shifted),
                )
            }
        };
        let position = mirror(c.center);
        let v = mirror(view);
        let camera = CameraDesc {
            position,
            look_at: [position[0] + v[0], position[1] + v[1], position[2] + v[2]],
            up: mirror(up),
            projection,
            aspect: None,
            frustum,
            depth_of_field,
            stereo: None,
        };
        let max_depth = c.raydepth.saturating_sub(1).min(MAX_DEPTH);
        Ok((Spanned { value: camera, at }, c.antialiasing + 1, max_depth))
    }
}

/// `camera` at Tachyon's CENTER, looking along VIEWDIR with UPDIR up (see `camera_at`).
pub(super) fn moved_camera(
    camera: &CameraDesc,
    viewdir: V3,
    updir: V3,
    center: V3,
) -> std::result::Result<CameraDesc, String> {
    let finite = |v: V3| v.iter().all(|x| x.is_finite());
    if !(finite(viewdir) && finite(updir) && finite(center)) {
        return Err("a number is not finite; expected finite numbers".into());
    }
    if viewdir == [0.0; 3] {
        return Err("VIEWDIR is (0, 0, 0); expected a direction".into());
    }
    if updir == [0.0; 3] {
        return Err("UPDIR is (0, 0, 0); expected a direction".into());
    }
    let [v, u] = [viewdir, updir];
    let cross = [
        v[1] * u[2] - v[2] * u[1],
        v[2] * u[0] - v[0] * u[2],
        v[0] * u[1] - v[1] * u[0],
    ];
    if cross == [0.0; 3] {
        return Err(
            "UPDIR is parallel to VIEWDIR; expected an up direction across the view".into(),
        );
    }
    let (p, v) = (mirror(center), mirror(viewdir));
    Ok(CameraDesc {
        position: p,
        look_at: [p[0] + v[0], p[1] + v[1], p[2] + v[2]],
        up: mirror(updir),
        ..camera.clone()
    })
}

/// A strip's triangles: (s[t], s[t+1], s[t+2]) for even t, (s[t+1], s[t], s[t+2]) for odd t,
/// so that all keep one winding.
fn strip(s: &[u32]) -> Vec<[u32; 3]> {
    (0..s.len().saturating_sub(2))
        .map(|t| {
            if t % 2 == 0 {
                [s[t], s[t + 1], s[t + 2]]
            } else {
                [s[t + 1], s[t], s[t + 2]]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::strip;

    #[test]
    fn strips_alternate_their_first_two_indices() {
        assert_eq!(
            strip(&[0, 1, 2, 3, 4]),
            vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]]
        );
        assert!(strip(&[0, 1]).is_empty());
    }
}
