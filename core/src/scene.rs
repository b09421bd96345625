//! `Scene`: a `SceneDesc` with plugins resolved and called, geometry stored natively and
//! re-centred, BVHs built, and the set of effects the scene calls for.

use crate::camera::Camera;
use crate::error::Error;
use crate::geometry::cone::Cones;
use crate::geometry::custom::Customs;
use crate::geometry::disc::Discs;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::{MeshInput, Triangles};
use crate::geometry::{pack, Clips, Counters, Hit, Kind, Surface, MAX_CLIP_GROUPS, MAX_MATERIALS};
use crate::math::{DVec3, Vec3A};
use crate::plugin::primitive::{create_primitive, GeometryBuilder};
use crate::plugin::texture::{create_texture, TextureInstance};
use crate::plugin::{read_volume, PluginKind, Registry};
use crate::ray::Ray;
use luxon_formats::{Highlight, InlineGeometry, LightDesc, OutputDesc, SceneDesc};
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Clone, Debug)]
pub struct Material {
    pub color: Vec3A,
    pub texture: Option<u32>,
    /// Textures scaling `reflect` and `transmit` point by point.
    pub reflect_texture: Option<u32>,
    pub transmit_texture: Option<u32>,
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub shininess: f32,
    pub blinn: bool,
    pub reflect: f32,
    pub transmit: f32,
    pub ior: f32,
}

impl Material {
    /// What a shadow ray keeps after crossing this surface once.
    #[inline]
    pub fn shadow_filter(&self) -> Vec3A {
        self.transmit * self.color
    }
}

#[derive(Clone, Debug)]
pub enum Light {
    Point {
        position: Vec3A,
        color: Vec3A,
        shadows: bool,
        attenuation: [f32; 3],
    },
    /// `to_light` is the unit direction toward the light.
    Directional {
        to_light: Vec3A,
        color: Vec3A,
        shadows: bool,
    },
    /// `axis` points from the light into the scene; full strength where the angle to it has a
    /// cosine above `cos_inner`, none below `cos_outer`.
    Spot {
        position: Vec3A,
        axis: Vec3A,
        cos_inner: f32,
        cos_outer: f32,
        color: Vec3A,
        shadows: bool,
        attenuation: [f32; 3],
    },
    Sphere {
        center: Vec3A,
        radius: f32,
        samples: u32,
        color: Vec3A,
        shadows: bool,
        attenuation: [f32; 3],
    },
    /// Shines to the side of `normal` = unit(edge1 × edge2).
    Rect {
        corner: Vec3A,
        edge1: Vec3A,
        edge2: Vec3A,
        normal: Vec3A,
        samples: u32,
        color: Vec3A,
        shadows: bool,
        attenuation: [f32; 3],
    },
}

impl Light {
    /// The fraction of light at distance `d` for attenuation coefficients (constant, linear,
    /// quadratic).
    #[inline]
    pub fn attenuate(a: &[f32; 3], d: f32) -> f32 {
        1.0 / (a[0] + a[1] * d + a[2] * d * d)
    }

    /// A spot light's weight where the direction from it makes cosine `cos` with its axis:
    /// 1 inside the inner cone, 0 outside the outer one, and a smoothstep across the band
    /// between them (no visible edge).
    #[inline]
    pub fn spot_weight(cos: f32, cos_inner: f32, cos_outer: f32) -> f32 {
        if cos <= cos_outer {
            return 0.0;
        }
        let x = if cos >= cos_inner {
            1.0
        } else {
            (cos - cos_outer) / (cos_inner - cos_outer)
        };
        x * x * (3.0 - 2.0 * x)
    }

    pub fn casts_shadows(&self) -> bool {
        match self {
            Light::Point { shadows, .. }
            | Light::Directional { shadows, .. }
            | Light::Spot { shadows, .. }
            | Light::Sphere { shadows, .. }
            | Light::Rect { shadows, .. } => *shadows,
        }
    }
}

/// Fog over the distance camera rays travel; `planar` measures it along the view direction.
#[derive(Clone, Debug)]
pub struct Fog {
    pub mode: luxon_formats::FogMode,
    pub color: Vec3A,
    pub planar: bool,
}

impl Fog {
    /// The fraction of the surface's colour left after distance `d`.
    pub fn visibility(&self, d: f32) -> f32 {
        use luxon_formats::FogMode;
        match self.mode {
            FogMode::Linear { start, end } => {
                (1.0 - (d - start as f32) / (end - start) as f32).clamp(0.0, 1.0)
            }
            FogMode::Exp { density } => (-(density as f32) * d).exp(),
            FogMode::Exp2 { density } => (-(density as f32 * d).powi(2)).exp(),
        }
    }
}

/// Ambient occlusion settings.
#[derive(Clone, Debug)]
pub struct Ao {
    pub samples: u32,
    pub max_distance: f32,
    /// Sky colour times intensity.
    pub sky: Vec3A,
    /// Scale of direct light while occlusion is on.
    pub direct: f32,
}

/// The effects a scene calls for; the integrator skips the rest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    pub shadows: bool,
    pub ambient_occlusion: bool,
    pub fog: bool,
    pub reflection: bool,
    /// Any used material lets light through (refraction or plain transparency).
    pub transmission: bool,
    pub textures: bool,
    pub antialiasing: bool,
    /// Some volume is drawn (has `render` settings).
    pub volumes: bool,
}

impl std::fmt::Display for Features {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut v = Vec::new();
        for (on, name) in [
            (self.shadows, "shadows"),
            (self.ambient_occlusion, "ambient occlusion"),
            (self.fog, "fog"),
            (self.reflection, "reflection"),
            (self.transmission, "refraction/transparency"),
            (self.textures, "textures"),
            (self.antialiasing, "antialiasing"),
            (self.volumes, "volumes"),
        ] {
            if on {
                v.push(name);
            }
        }
        if v.is_empty() {
            f.write_str("none (direct lighting only)")
        } else {
            f.write_str(&v.join(", "))
        }
    }
}

/// Render settings after command-line overrides.
#[derive(Clone, Debug)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub max_depth: u32,
    pub min_weight: f32,
    pub frame: u32,
    pub time: f32,
    pub threads: Option<u32>,
    pub tile_size: u32,
    pub transparency: luxon_formats::TransparencyDesc,
    pub mode: luxon_formats::ParallelMode,
    pub decomposition: luxon_formats::Decomposition,
    pub io: luxon_formats::OutputIo,
    /// Empty-space skipping in volumes.
    pub volume_skip: bool,
    /// Adaptive supersampling; `None`: `samples` uniform samples per pixel.
    pub adaptive: Option<luxon_formats::AdaptiveDesc>,
}

pub struct Scene {
    pub source: PathBuf,
    pub camera: Camera,
    pub background: Vec3A,
    pub lights: Vec<Light>,
    pub fog: Option<Fog>,
    pub ao: Option<Ao>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub textures: Vec<TextureInstance>,
    pub texture_names: Vec<String>,
    pub spheres: Spheres,
    pub triangles: Triangles,
    pub planes: Planes,
    pub cones: Cones,
    pub discs: Discs,
    pub customs: Customs,
    /// Clip groups (render space) that objects are cut by.
    pub clips: Clips,
    /// Volumes read by volume-reader plugins, in scene order.
    pub volumes: Vec<crate::volume::Volume>,
    /// The volumes that are drawn (those with `render` settings), ready for ray casting.
    pub render_volumes: Vec<crate::volume_render::RenderVolume>,
    /// World position of render space's origin (the camera): coordinates are stored relative
    /// to it in f32, so a scene far from the world origin keeps its precision.
    pub world_offset: DVec3,
    pub settings: Settings,
    /// Width of a pixel's footprint at the camera (orthographic cameras: a pixel; else 0).
    pub primary_width: f32,
    /// Angle one pixel spans at the image centre (radians): how fast ray footprints widen.
    pub pixel_spread: f32,
    pub outputs: Vec<OutputDesc>,
    pub features: Features,
    /// Per material: whether any object uses it.
    pub used_materials: Vec<bool>,
    /// Objects per plugin name, in first-use order.
    pub object_counts: Vec<(String, usize)>,
    pub degenerate_triangles: u64,
    pub bvh_time: Duration,
    /// Instantiating the objects through their plugins and storing all geometry natively
    /// (after reading the scene, before the BVH build).
    pub plugin_time: Duration,
}

/// A scene's native geometry with its BVHs built, as a geometry cache gives it back
/// ([`crate::cache`]).
pub struct Prebuilt {
    pub world_offset: DVec3,
    /// Per material of the scene (index 0: the default): whether any primitive uses it.
    pub used: Vec<bool>,
    pub degenerate: u64,
    pub spheres: Spheres,
    pub triangles: Triangles,
    pub cones: Cones,
}

fn v3(a: [f64; 3]) -> Vec3A {
    Vec3A::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

impl Scene {
    /// Resolves plugins, instantiates every object and builds the BVHs.
    pub fn build(desc: &SceneDesc, registry: &Registry) -> Result<Scene, Error> {
        let groups = desc.inline.iter().map(Cow::Borrowed);
        Scene::build_from(desc, Box::new(groups), None, registry)
    }

    /// Builds with the native geometry and BVHs of a geometry cache (`desc` holds the rest of
    /// the scene and no inline geometry).
    pub fn build_prebuilt(
        desc: &SceneDesc,
        geometry: Prebuilt,
        registry: &Registry,
    ) -> Result<Scene, Error> {
        Scene::build_from(desc, Box::new(std::iter::empty()), Some(geometry), registry)
    }

    /// Like `build`, but takes the imported geometry (`desc.inline`) out of `desc` and frees
    /// each group once it is stored, so a large import is not held twice while the BVHs are
    /// built and the image rendered.
    pub fn build_taking_geometry(
        desc: &mut SceneDesc,
        registry: &Registry,
    ) -> Result<Scene, Error> {
        let groups = std::mem::take(&mut desc.inline).into_iter().map(Cow::Owned);
        Scene::build_from(desc, Box::new(groups), None, registry)
    }

    fn build_from<'g>(
        desc: &SceneDesc,
        inline: Box<dyn Iterator<Item = Cow<'g, InlineGeometry>> + 'g>,
        prebuilt: Option<Prebuilt>,
        registry: &Registry,
    ) -> Result<Scene, Error> {
        let scene_dir = desc
            .source
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let world_offset = DVec3::from(desc.camera.value.position);
        let r = &desc.render;

        let mut texture_names = Vec::new();
        let mut textures = Vec::new();
        let t0 = Instant::now();
        for (name, call) in &desc.textures {
            let entry = registry
                .get(&call.value.plugin.value, PluginKind::Texture)
                .map_err(|e| Error::at(&call.value.plugin.at, e.to_string()))?;
            let tex = create_texture(
                registry,
                entry,
                &call.value.params,
                &call.value.params_at,
                &scene_dir,
                name,
            )
            .map_err(|(at, m)| Error::at(&at, m))?;
            texture_names.push(name.clone());
            textures.push(tex);
        }

        let mut volumes = Vec::with_capacity(desc.volumes.len());
        for (i, v) in desc.volumes.iter().enumerate() {
            let call = &v.value.call;
            let entry = registry
                .get(&call.plugin.value, PluginKind::VolumeReader)
                .map_err(|e| Error::at(&call.plugin.at, e.to_string()))?;
            let name = match &v.value.name {
                Some(n) => n.value.clone(),
                None => format!("volume {i}"),
            };
            let volume = read_volume(
                registry,
                entry,
                &call.params,
                &call.params_at,
                &scene_dir,
                &name,
            )
            .map_err(|(at, m)| Error::at(&at, m))?;
            volumes.push(volume);
        }

        let mut material_names = vec!["default".to_string()];
        let mut materials = vec![material(&Default::default(), [None; 3])];
        for (name, m) in &desc.materials {
            let find = |t: &Option<luxon_formats::Spanned<String>>| -> Result<Option<u32>, Error> {
                match t {
                    Some(t) => texture_names
                        .iter()
                        .position(|n| n == &t.value)
                        .map(|i| Some(i as u32))
                        .ok_or_else(|| Error::at(&t.at, format!("no texture named `{}`", t.value))),
                    None => Ok(None),
                }
            };
            let tex = [
                find(&m.value.texture)?,
                find(&m.value.reflect_texture)?,
                find(&m.value.transmit_texture)?,
            ];
            let mat = material(&m.value, tex);
            if let Some(i) = material_names.iter().position(|n| n == name) {
                materials[i] = mat;
            } else {
                material_names.push(name.clone());
                materials.push(mat);
            }
        }

        if materials.len() as u32 > MAX_MATERIALS {
            return Err(Error::Render(format!(
                "the scene defines {} materials; at most {MAX_MATERIALS} are supported",
                materials.len()
            )));
        }
        if desc.clip_groups.len() as u32 >= MAX_CLIP_GROUPS {
            return Err(Error::Render(format!(
                "the scene defines {} clip groups; at most {} are supported",
                desc.clip_groups.len(),
                MAX_CLIP_GROUPS - 1
            )));
        }
        let clips = Clips {
            groups: desc
                .clip_groups
                .iter()
                .map(|(_, g)| {
                    g.value
                        .iter()
                        .map(|p| {
                            let q = Vec3A::from((DVec3::from(p.point) - world_offset).as_vec3());
                            (q, Vec3A::from(DVec3::from(p.normal).normalize().as_vec3()))
                        })
                        .collect()
                })
                .collect(),
        };

        let render_volumes = render_volumes(desc, &volumes, world_offset)?;

        let mut spheres = Spheres::default();
        let mut triangles = Triangles::default();
        let mut planes = Planes::default();
        let mut cones = Cones::default();
        let mut discs = Discs::default();
        let mut customs = Customs::new(world_offset);
        let mut object_counts: Vec<(String, usize)> = Vec::new();
        let mut dropped = 0;
        let mut used = vec![false; materials.len()];
        for (i, obj) in desc.objects.iter().enumerate() {
            let call = &obj.value.call;
            let entry = registry
                .get(&call.plugin.value, PluginKind::Primitive)
                .map_err(|e| Error::at(&call.plugin.at, e.to_string()))?;
            let material = match &obj.value.material {
                Some(m) => material_names
                    .iter()
                    .position(|n| n == &m.value)
                    .ok_or_else(|| Error::at(&m.at, format!("no material named `{}`", m.value)))?,
                None => 0,
            };
            used[material] = true;
            let clip = match &obj.value.clip {
                Some(c) => {
                    1 + desc
                        .clip_groups
                        .iter()
                        .position(|(n, _)| n == &c.value)
                        .ok_or_else(|| {
                            Error::at(&c.at, format!("no clip group named `{}`", c.value))
                        })? as u32
                }
                None => 0,
            };
            let mut b = GeometryBuilder {
                spheres: &mut spheres,
                triangles: &mut triangles,
                planes: &mut planes,
                cones: &mut cones,
                discs: &mut discs,
                customs: &mut customs,
                material: pack(material as u32, clip),
                world_offset,
                plugin: entry.name.clone(),
                dropped: 0,
            };
            create_primitive(
                registry,
                entry,
                &call.params,
                &call.params_at,
                &scene_dir,
                &format!("object {i}"),
                &mut b,
            )
            .map_err(|(at, m)| Error::at(&at, m))?;
            dropped += b.dropped;
            match object_counts.iter_mut().find(|(n, _)| n == &entry.name) {
                Some((_, c)) => *c += 1,
                None => object_counts.push((entry.name.clone(), 1)),
            }
        }
        for (k, g) in inline.enumerate() {
            let at = || g.at.clone().unwrap_or_else(|| desc.camera.at.clone());
            let material = match &g.material {
                Some(m) => material_names
                    .iter()
                    .position(|n| n == &m.value)
                    .ok_or_else(|| Error::at(&m.at, format!("no material named `{}`", m.value)))?,
                None => 0,
            };
            used[material] = true;
            let m = material as u32;
            let fail = |e: String| Error::at(&at(), format!("imported geometry group {k}: {e}"));
            for (i, s) in g.spheres.iter().enumerate() {
                spheres.push_world(i, *s, world_offset, m).map_err(fail)?;
            }
            for (i, c) in g.cones.iter().enumerate() {
                cones.push_world(i, *c, world_offset, m).map_err(fail)?;
            }
            for (i, d) in g.discs.iter().enumerate() {
                discs.push_world(i, *d, world_offset, m).map_err(fail)?;
            }
            for (i, p) in g.planes.iter().enumerate() {
                planes.push_world(i, *p, world_offset, m).map_err(fail)?;
            }
            if !g.mesh.indices.is_empty() {
                let input = MeshInput {
                    positions: g.mesh.positions.as_flattened(),
                    indices: g.mesh.indices.as_flattened(),
                    normals: g.mesh.normals.as_flattened(),
                    colors: &[],
                    uvs: &g
                        .mesh
                        .uvs
                        .iter()
                        .flat_map(|u| u.map(|x| x as f32))
                        .collect::<Vec<_>>(),
                };
                dropped += triangles.push_mesh(&input, world_offset, m).map_err(fail)?;
            }
        }
        let native_built = prebuilt.is_some();
        if let Some(p) = prebuilt {
            if p.used.len() != materials.len() || p.world_offset != world_offset {
                return Err(Error::Render(
                    "the geometry cache does not match the scene".into(),
                ));
            }
            spheres = p.spheres;
            triangles = p.triangles;
            cones = p.cones;
            for (u, p) in used.iter_mut().zip(p.used) {
                *u |= p;
            }
            dropped += p.degenerate;
        }
        let plugin_time = t0.elapsed();

        let t1 = Instant::now();
        let build_native = !native_built;
        let (_, custom_result) = rayon::join(
            || {
                if build_native {
                    rayon::join(
                        || rayon::join(|| spheres.build(), || triangles.set.build()),
                        || rayon::join(|| cones.build(), || discs.build()),
                    );
                }
            },
            || customs.build(),
        );
        custom_result.map_err(Error::Plugin)?;
        let bvh_time = t1.elapsed();

        let at = |p: &[f64; 3]| Vec3A::from((DVec3::from(*p) - world_offset).as_vec3());
        let unit = |d: &[f64; 3]| Vec3A::from(DVec3::from(*d).normalize().as_vec3());
        let att = |a: &luxon_formats::Attenuation| {
            [a.constant as f32, a.linear as f32, a.quadratic as f32]
        };
        let lights: Vec<Light> = desc
            .lights
            .iter()
            .map(|l| match &l.value {
                LightDesc::Point {
                    position,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Point {
                    position: at(position),
                    color: v3(*color) * *intensity as f32,
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
                LightDesc::Directional {
                    direction,
                    color,
                    intensity,
                    shadows,
                } => Light::Directional {
                    to_light: -unit(direction),
                    color: v3(*color) * *intensity as f32,
                    shadows: *shadows,
                },
                LightDesc::Spot {
                    position,
                    direction,
                    cone_deg,
                    falloff_deg,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Spot {
                    position: at(position),
                    axis: unit(direction),
                    cos_inner: ((cone_deg - falloff_deg) * 0.5).to_radians().cos() as f32,
                    cos_outer: (cone_deg * 0.5).to_radians().cos() as f32,
                    color: v3(*color) * *intensity as f32,
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
                LightDesc::Sphere {
                    center,
                    radius,
                    samples,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Sphere {
                    center: at(center),
                    radius: *radius as f32,
                    samples: *samples,
                    color: v3(*color) * *intensity as f32,
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
                LightDesc::Rect {
                    corner,
                    edge1,
                    edge2,
                    samples,
                    color,
                    intensity,
                    shadows,
                    attenuation,
                } => Light::Rect {
                    corner: at(corner),
                    edge1: v3(*edge1),
                    edge2: v3(*edge2),
                    normal: v3(*edge1).cross(v3(*edge2)).normalize(),
                    samples: *samples,
                    color: v3(*color) * *intensity as f32,
                    shadows: *shadows,
                    attenuation: att(attenuation),
                },
            })
            .collect();
        let fog = desc.fog.as_ref().map(|f| Fog {
            mode: f.mode,
            color: v3(f.color),
            planar: f.planar,
        });
        let ao = desc.ambient_occlusion.as_ref().map(|a| Ao {
            samples: a.samples,
            max_distance: a.max_distance as f32,
            sky: v3(a.color) * a.intensity as f32,
            direct: a.direct as f32,
        });

        let used_mats: Vec<&Material> = materials
            .iter()
            .zip(&used)
            .filter(|(_, u)| **u)
            .map(|(m, _)| m)
            .collect();
        let has_geometry = !(spheres.is_empty()
            && triangles.is_empty()
            && planes.planes.is_empty()
            && customs.is_empty());
        let features = Features {
            shadows: has_geometry && lights.iter().any(Light::casts_shadows),
            ambient_occlusion: has_geometry && ao.is_some(),
            fog: fog.is_some(),
            reflection: used_mats.iter().any(|m| m.reflect > 0.0),
            transmission: used_mats.iter().any(|m| m.transmit > 0.0),
            textures: used_mats.iter().any(|m| {
                m.texture
                    .or(m.reflect_texture)
                    .or(m.transmit_texture)
                    .is_some()
            }),
            antialiasing: r.samples > 1 || r.adaptive.is_some(),
            volumes: !render_volumes.is_empty(),
        };

        let settings = Settings {
            width: r.width,
            height: r.height,
            samples: r.samples,
            max_depth: r.max_depth,
            min_weight: r.min_weight as f32,
            frame: r.frame,
            time: r.time as f32,
            threads: r.parallel.threads,
            tile_size: r.parallel.tile_size,
            transparency: r.transparency,
            mode: r.parallel.mode,
            decomposition: r.parallel.decomposition,
            io: r.parallel.io,
            volume_skip: r.volume_skip,
            adaptive: r.adaptive,
        };
        let camera = Camera::new(&desc.camera.value, Vec3A::ZERO, r.width, r.height);
        Ok(Scene {
            source: desc.source.clone(),
            camera: camera.clone(),
            primary_width: camera.footprint().0,
            pixel_spread: camera.footprint().1,
            background: v3(desc.background),
            lights,
            fog,
            ao,
            materials,
            material_names,
            textures,
            texture_names,
            spheres,
            triangles,
            planes,
            cones,
            discs,
            customs,
            clips,
            volumes,
            render_volumes,
            world_offset,
            settings,
            outputs: r.outputs.clone(),
            features,
            used_materials: used,
            object_counts,
            degenerate_triangles: dropped,
            bvh_time,
            plugin_time,
        })
    }

    /// The closest hit along `ray` before `t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, mut t_max: f32, c: &mut Counters) -> Option<Hit> {
        let mut hit = None;
        self.spheres
            .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        self.triangles
            .set
            .intersect_noting(ray, &mut t_max, &mut hit, &self.clips, c, |i| {
                self.triangles.prefetch_shading(i)
            });
        self.planes
            .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        self.cones
            .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        self.discs
            .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        self.customs
            .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        hit
    }

    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        match hit.kind {
            Kind::Sphere => self.spheres.surface(hit, ray),
            Kind::Triangle => self.triangles.surface(hit, self.features.textures),
            Kind::Plane => self.planes.surface(hit, ray),
            Kind::Cone => self.cones.surface(hit, ray),
            Kind::Disc => self.discs.surface(hit, ray),
            Kind::Custom => self.customs.surface(hit, ray),
        }
    }

    /// What reaches the end of a shadow ray: zero when an opaque surface blocks it, otherwise
    /// the product of the filters of the transparent surfaces it crosses.
    #[inline]
    pub fn transmittance(&self, ray: &Ray, t_max: f32, min_weight: f32, c: &mut Counters) -> Vec3A {
        if !self.features.transmission {
            // Opaque world: the first hit anywhere ends the query.
            let blocked = self.spheres.any(ray, t_max, &self.clips, c, |_, _| true)
                || self
                    .triangles
                    .set
                    .any(ray, t_max, &self.clips, c, |_, _| true)
                || self.planes.any(ray, t_max, &self.clips, c, |_, _| true)
                || self.cones.any(ray, t_max, &self.clips, c, |_, _| true)
                || self.discs.any(ray, t_max, &self.clips, c, |_, _| true)
                || self.customs.any(ray, t_max, &self.clips, c, |_, _| true);
            return if blocked { Vec3A::ZERO } else { Vec3A::ONE };
        }
        let mut filter = Vec3A::ONE;
        let mut on_hit = |m: u32, crossings: u32| {
            let mat = &self.materials[m as usize];
            if mat.transmit <= 0.0 {
                filter = Vec3A::ZERO;
                return true;
            }
            let f = mat.shadow_filter();
            for _ in 0..crossings {
                filter *= f;
            }
            filter.max_element() < min_weight
        };
        if self.spheres.any(ray, t_max, &self.clips, c, &mut on_hit)
            || self
                .triangles
                .set
                .any(ray, t_max, &self.clips, c, &mut on_hit)
            || self.planes.any(ray, t_max, &self.clips, c, &mut on_hit)
            || self.cones.any(ray, t_max, &self.clips, c, &mut on_hit)
            || self.discs.any(ray, t_max, &self.clips, c, &mut on_hit)
            || self.customs.any(ray, t_max, &self.clips, c, &mut on_hit)
        {
            return Vec3A::ZERO;
        }
        filter
    }

    pub fn primitive_count(&self) -> usize {
        self.spheres.len()
            + self.triangles.len()
            + self.planes.planes.len()
            + self.cones.len()
            + self.discs.len()
            + self.customs.len()
    }
}

/// The volumes with `render` settings, prepared for ray casting.
fn render_volumes(
    desc: &SceneDesc,
    volumes: &[crate::volume::Volume],
    world_offset: DVec3,
) -> Result<Vec<crate::volume_render::RenderVolume>, Error> {
    use crate::volume_render::{RenderVolume, MAX_RENDERED_VOLUMES};
    let mut out = Vec::new();
    for (i, (v, volume)) in desc.volumes.iter().zip(volumes).enumerate() {
        let Some(r) = &v.value.render else {
            continue;
        };
        if out.len() == MAX_RENDERED_VOLUMES {
            return Err(Error::at(
                &r.at,
                format!("more than {MAX_RENDERED_VOLUMES} volumes are drawn; at most {MAX_RENDERED_VOLUMES} may have `render` settings"),
            ));
        }
        let clip = match &r.value.clip {
            Some(c) => {
                1 + desc
                    .clip_groups
                    .iter()
                    .position(|(n, _)| n == &c.value)
                    .ok_or_else(|| Error::at(&c.at, format!("no clip group named `{}`", c.value)))?
                    as u32
            }
            None => 0,
        };
        let rv = RenderVolume::new(
            &r.value,
            volume,
            i,
            desc.render.volume_step,
            world_offset,
            clip,
        )
        .map_err(|m| Error::at(&r.at, m))?;
        out.push(rv);
    }
    Ok(out)
}

/// `textures`: the material's colour, reflect and transmit textures.
fn material(m: &luxon_formats::MaterialDesc, textures: [Option<u32>; 3]) -> Material {
    Material {
        color: v3(m.color),
        texture: textures[0],
        reflect_texture: textures[1],
        transmit_texture: textures[2],
        ambient: m.ambient as f32,
        diffuse: m.diffuse as f32,
        specular: m.specular as f32,
        shininess: m.shininess as f32,
        blinn: m.highlight == Highlight::Blinn,
        reflect: m.reflect as f32,
        transmit: m.transmit as f32,
        ior: m.ior as f32,
    }
}
