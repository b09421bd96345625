//! `Scene`: a `SceneDesc` with plugins resolved and called, geometry stored natively and
//! re-centred, BVHs built, and the set of effects the scene calls for; and the queries the
//! integrator asks of it (closest hit, surface, shadow transmittance). The build is in `build`;
//! an animated scene's frames (`Scene::set_frame`, the keyed objects' moving group) in `frame`.

mod build;
mod frame;

pub use build::Prebuilt;
pub use frame::Animation;

use crate::camera::Camera;
use crate::geometry::cone::Cones;
use crate::geometry::custom::Customs;
use crate::geometry::disc::Discs;
use crate::geometry::group::Group;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::Triangles;
use crate::geometry::{Clips, Counters, Hit, Kind, Surface};
use crate::math::{DVec3, Vec3A};
use crate::plugin::texture::TextureInstance;
use crate::ray::Ray;
use crate::volume::Volume;
use crate::volume_render::RenderVolume;
use luxon_formats::OutputDesc;
use std::path::PathBuf;
use std::time::Duration;

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
    pub volumes: Vec<Volume>,
    /// The volumes that are drawn (those with `render` settings), ready for ray casting.
    pub render_volumes: Vec<RenderVolume>,
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
    /// Keyed objects placed at the current frame (empty in a still scene).
    pub moving: Group,
    /// How the scene changes from frame to frame; `None`: a still scene.
    pub animation: Option<Box<Animation>>,
}

impl Scene {
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
        if !self.moving.is_empty() {
            self.moving
                .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        }
        hit
    }

    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        if hit.moving {
            return self.moving.surface(hit, ray, self.features.textures);
        }
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
                || self.customs.any(ray, t_max, &self.clips, c, |_, _| true)
                || (!self.moving.is_empty()
                    && self
                        .moving
                        .any(ray, t_max, &self.clips, c, &mut |_, _| true));
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
            || (!self.moving.is_empty() && self.moving.any(ray, t_max, &self.clips, c, &mut on_hit))
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
