//! `Scene`: a `SceneDesc` with plugins resolved and called, geometry stored natively and
//! re-centred, BVHs built, and the set of effects the scene calls for; and the queries the
//! integrator asks of it (closest hit, surface, shadow transmittance). The build is in `build`;
//! an animated scene's frames (`Scene::set_frame`, the keyed objects' moving group) in `frame`;
//! what a retained scene ([`crate::api::Scene`]) changes without a build (settings, size,
//! camera, background, lights, materials, fog and ambient occlusion) in `update`; instances of
//! prototypes, baked into flat copies, in `instances`; moving recorded geometry by a transform
//! (for both) in `place`.

mod build;
mod few;
mod frame;
mod instances;
mod place;
mod series;
mod shadows;
#[cfg(test)]
mod testing {
    /// A small deterministic generator (xorshift), numbers in [0, 1).
    pub fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 40) as f32 / (1u64 << 24) as f32
        }
    }
}
mod sky;
mod sweep;
pub(crate) mod update;

pub(crate) use build::shadowless_groups;
pub use build::Prebuilt;
pub use few::Few;
pub use frame::Animation;
pub use instances::PrototypeUse;
pub use series::DataFiles;
pub use shadows::Casters;
pub use sky::Sky;

use crate::budget::Budget;
use crate::bvh::BoxRay;
use crate::camera::Camera;
use crate::geometry::cone::Cones;
use crate::geometry::custom::Customs;
use crate::geometry::disc::Discs;
use crate::geometry::group::Group;
use crate::geometry::instance::Instances;
use crate::geometry::objects::Objects;
use crate::geometry::plane::Planes;
use crate::geometry::sphere::Spheres;
use crate::geometry::triangle::Triangles;
use crate::geometry::{material_of, Clips, Counters, Hit, Kind, Surface, NO_INSTANCE};
use crate::math::{DVec3, Vec3A};
use crate::plugin::texture::TextureInstance;
use crate::ray::Ray;
use crate::volume::Volume;
use crate::volume_render::RenderVolume;
use luxon_formats::OutputDesc;
use std::path::PathBuf;
use std::sync::Arc;
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
    pub highlight: luxon_formats::Highlight,
    /// The highlight takes the surface's colour (metal), not white.
    pub highlight_surface: bool,
    pub reflect: f32,
    pub transmit: f32,
    pub ior: f32,
    /// How the transmit coefficient changes with the viewing angle.
    pub angle: AngleRule,
    /// What a shadow ray keeps after crossing this surface once; `None`: it is blocked.
    pub shadow: Option<Vec3A>,
    /// Silhouette darkening of the diffuse light (0: none) and its exponent 32·(1 − width).
    pub outline: f32,
    pub outline_power: f32,
    /// Whether fog covers the surface.
    pub fog: bool,
    /// Whether one of its textures reads texture coordinates (see [`Material::reads_uv`]).
    pub uv: bool,
}

/// How a material's transmit coefficient t changes with the angle θ it is seen at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AngleRule {
    Constant,
    /// t^(1/|cos θ|): a slab seen at θ (the `AngleModulated` mode).
    Slab,
    /// Tachyon's Raster3D: opacity 1 − t becomes ¼(1 + cos(π·t·cos θ))².
    Raster3D,
}

impl Material {
    /// Whether shading reads the texture coordinates at this material's points: one of its
    /// textures declares it reads them (`abi::READS_UV`; an image projected from the point
    /// does not).
    #[inline]
    pub fn reads_uv(&self) -> bool {
        self.uv
    }

    /// The outline factor on the diffuse light where the view direction makes cosine `cos`
    /// with the normal: 1 facing the viewer, darker toward the silhouette.
    #[inline]
    pub fn outline_factor(&self, cos: f32) -> f32 {
        let edge = (1.0 - cos * cos).max(0.0).powf(self.outline_power);
        (1.0 - self.outline) + self.outline * (1.0 - edge)
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
    /// cosine above `cos_inner`, none below `cos_outer`, fading between as `fade` says.
    Spot {
        position: Vec3A,
        axis: Vec3A,
        cos_inner: f32,
        cos_outer: f32,
        fade: Fade,
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
    /// 1 inside the inner cone, 0 outside the outer one, and across the band between them a
    /// smoothstep in the cosine (no visible edge) or linear in the angle.
    #[inline]
    pub fn spot_weight(cos: f32, cos_inner: f32, cos_outer: f32, fade: Fade) -> f32 {
        if cos <= cos_outer {
            return 0.0;
        }
        if cos >= cos_inner {
            return 1.0;
        }
        match fade {
            Fade::Smooth => {
                let x = (cos - cos_outer) / (cos_inner - cos_outer);
                x * x * (3.0 - 2.0 * x)
            }
            Fade::Linear { inner, outer } => {
                ((outer - crate::math::acos(cos)) / (outer - inner)).clamp(0.0, 1.0)
            }
        }
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

/// How a spot light fades across its band (angles from the axis in radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fade {
    Smooth,
    Linear { inner: f32, outer: f32 },
}

/// Fog over the distance camera rays travel (`every_ray`: every ray, over its own segment);
/// `planar` measures camera rays' distance along the view direction.
#[derive(Clone, Debug)]
pub struct Fog {
    pub mode: luxon_formats::FogMode,
    pub color: Vec3A,
    pub planar: bool,
    pub every_ray: bool,
    /// Rays that hit nothing show the fog colour.
    pub misses: bool,
}

impl Fog {
    /// The fraction of the surface's colour left after distance `d`.
    pub fn visibility(&self, d: f32) -> f32 {
        use luxon_formats::FogMode;
        // Exponential fog starts at `start`: clear before it.
        let after = |start: f64| {
            if start > 0.0 {
                (d - start as f32).max(0.0)
            } else {
                d
            }
        };
        match self.mode {
            FogMode::Linear { start, end } => {
                (1.0 - (d - start as f32) / (end - start) as f32).clamp(0.0, 1.0)
            }
            FogMode::Exp { density, start } => (-(density as f32) * after(start)).exp(),
            FogMode::Exp2 { density, start } => (-(density as f32 * after(start)).powi(2)).exp(),
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
    /// Fog on camera rays' own shading.
    pub fog: bool,
    /// Fog on every ray's segment and whole colour (Tachyon's).
    pub fog_every_ray: bool,
    pub reflection: bool,
    /// Any used material lets light through (refraction or plain transparency).
    pub transmission: bool,
    /// Shadow rays can pass some surface (a transparent one, or one that casts no shadow), so
    /// they look at what they hit.
    pub shadow_filters: bool,
    /// Some of those let a shadow ray through unchanged (filter one: a surface casting no
    /// shadow), so shadow rays can pass them over untested.
    pub see_through: bool,
    /// Some used material darkens its silhouette.
    pub outline: bool,
    /// Lights follow Tachyon's rules (its threshold, plain highlights).
    pub tachyon_lights: bool,
    pub textures: bool,
    pub antialiasing: bool,
    /// Some volume is drawn (has `render` settings).
    pub volumes: bool,
    /// Camera rays sample a time in the shutter (an animated scene with a shutter and
    /// something keyed that moves).
    pub motion_blur: bool,
}

impl std::fmt::Display for Features {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut v = Vec::new();
        for (on, name) in [
            (self.shadows, "shadows"),
            (self.ambient_occlusion, "ambient occlusion"),
            (self.fog || self.fog_every_ray, "fog"),
            (self.reflection, "reflection"),
            (self.transmission, "refraction/transparency"),
            (self.outline, "outlines"),
            (self.textures, "textures"),
            (self.antialiasing, "antialiasing"),
            (self.volumes, "volumes"),
            (self.motion_blur, "motion blur"),
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
    /// Scale of every light's direct contribution (light colours are multiplied by it).
    pub light_scale: f32,
    /// Tachyon's shading rules.
    pub tachyon: luxon_formats::TachyonDesc,
    /// The shutter (open, close) in frames from the frame's time when camera rays sample a
    /// time in it (motion blur); `None`: every ray carries `time`.
    pub shutter: Option<(f32, f32)>,
}

pub struct Scene {
    pub source: PathBuf,
    pub camera: Camera,
    /// What rays that hit nothing show: this colour, or the gradient `sky`.
    pub background: Vec3A,
    pub sky: Option<Sky>,
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
    /// How many of `volumes` (the last ones) a retained scene read from arrays.
    pub(crate) array_volumes: usize,
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
    /// Whether the scene holds any surface (shadows and occlusion need one).
    pub has_geometry: bool,
    /// Objects per plugin name, in first-use order.
    pub object_counts: Vec<(String, usize)>,
    pub degenerate_triangles: u64,
    pub bvh_time: Duration,
    /// Instantiating the objects through their plugins and storing all geometry natively
    /// (after reading the scene, before the BVH build).
    pub plugin_time: Duration,
    /// Keyed objects placed at the current frame (empty in a still scene).
    pub moving: Group,
    /// The camera changes during this frame's shutter: each camera ray is cast by the camera
    /// at its own time.
    pub camera_moves: bool,
    /// Instances sharing one copy of their prototype (a two-level BVH; empty unless some
    /// prototype is shared).
    pub instances: Instances,
    /// A retained scene's array objects (read in place from the caller's arrays; empty
    /// otherwise).
    pub objects: Objects,
    /// The prototypes with instances, and how each was realised.
    pub prototypes: Vec<PrototypeUse>,
    /// How the scene changes from frame to frame; `None`: a still scene.
    pub animation: Option<Box<Animation>>,
    /// The memory budget the build charged (geometry, BVHs, volumes, texture cache) and the
    /// render charges (images).
    pub budget: Arc<Budget>,
    /// What shadow rays test when every surface blocks them or lets them through unchanged
    /// (refreshed with the features).
    pub casters: Option<Casters>,
    /// Some triangle, cone, disc or plugin object: closest hits ask those kinds too
    /// (refreshed with the features; spheres and planes are asked anyway).
    pub more_kinds: bool,
    /// A scene of a few spheres, at most one triangle and planes: closest hits test them
    /// without the trees (refreshed with `more_kinds`).
    pub few: Option<Few>,
}

impl Scene {
    /// How many NaN results each plugin instance gave since the last call, and restarts the
    /// counts (each render, each frame of a sequence, is told its own): every texture's
    /// values that were NaN or infinite, then every custom object's hits at a NaN distance or
    /// normal. Every rank of a job has the same instances in the same order, so the counts of
    /// ranks add up entry by entry.
    pub fn nan_counts(&self) -> Vec<u64> {
        use std::sync::atomic::Ordering::Relaxed;
        let textures = self.textures.iter().map(|t| t.nan_results.swap(0, Relaxed));
        let customs = self
            .customs
            .objects
            .iter()
            .map(|o| o.nan_hits.swap(0, Relaxed));
        textures.chain(customs).collect()
    }

    /// One warning per plugin instance with NaN results in `counts` (as [`Self::nan_counts`]
    /// gives them, possibly summed over ranks), naming it, its plugin and its place.
    pub fn nan_warnings(&self, counts: &[u64]) -> Vec<String> {
        let mut counts = counts.iter().copied();
        let mut out = Vec::new();
        for t in &self.textures {
            let n = counts.next().unwrap_or(0);
            if n > 0 {
                out.push(format!(
                    "{}: texture `{}` (plugin `{}`) gave NaN or infinite values at {n} shading \
                     point(s); expected finite RGBA",
                    t.at, t.name, t.plugin
                ));
            }
        }
        for o in &self.customs.objects {
            let n = counts.next().unwrap_or(0);
            if n > 0 {
                out.push(format!(
                    "{} answered {n} ray(s) with a hit at a NaN distance or normal; expected \
                     finite numbers (those hits were taken as misses)",
                    o.label()
                ));
            }
        }
        out
    }

    /// Whether any kind besides spheres and planes has primitives (see `more_kinds`).
    pub(crate) fn has_more_kinds(&self) -> bool {
        !self.triangles.set.is_empty()
            || !self.cones.is_empty()
            || !self.discs.is_empty()
            || !self.customs.is_empty()
    }

    /// The closest hit along `ray` before `t_max`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32, c: &mut Counters) -> Option<Hit> {
        if let Some(few) = &self.few {
            if let Some(hit) = few.closest(self, ray, t_max, c) {
                return hit;
            }
        }
        self.intersect_trees(ray, t_max, c)
    }

    /// [`Scene::intersect`] through the kinds' trees.
    #[inline]
    fn intersect_trees(&self, ray: &Ray, mut t_max: f32, c: &mut Counters) -> Option<Hit> {
        let mut hit = None;
        // The box tests' set-up, once for every kind.
        let boxes = BoxRay::new(ray.origin, ray.dir);
        let (t, h, clips) = (&mut t_max, &mut hit, &self.clips);
        (self.spheres).intersect_noting(ray, &boxes, t, h, clips, c, |_| {});
        if !self.more_kinds {
            // Tachyon's usual scenes: spheres and planes only, one test for the kinds they
            // lack (same order of kinds, so ties go as below).
            self.planes.intersect(ray, t, h, clips, c);
        } else {
            (self.triangles.set).intersect_noting(ray, &boxes, t, h, clips, c, |i| {
                self.triangles.prefetch_shading(i)
            });
            self.planes.intersect(ray, t, h, clips, c);
            (self.cones).intersect_noting(ray, &boxes, t, h, clips, c, |_| {});
            (self.discs).intersect_noting(ray, &boxes, t, h, clips, c, |_| {});
            self.customs
                .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        }
        if !self.moving.is_empty() {
            self.moving
                .intersect(ray, &mut t_max, &mut hit, &self.clips, c);
        }
        if !self.instances.is_empty() {
            (self.instances).intersect(ray, &boxes, &mut t_max, &mut hit, c);
        }
        if !self.objects.is_empty() {
            self.objects.intersect(ray, &boxes, &mut t_max, &mut hit, c);
        }
        hit
    }

    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        if hit.moving {
            return self.moving.surface(hit, ray, self.features.textures);
        }
        if hit.instance != NO_INSTANCE {
            return self.instances.surface(hit, ray, self.features.textures);
        }
        // Texture coordinates only for a material with a texture (the only reader of uv).
        let uv = |packed: u32| {
            self.features.textures && self.materials[material_of(packed) as usize].reads_uv()
        };
        if hit.object != 0 {
            return self.objects.surface(hit, ray, uv);
        }
        let i = hit.index as usize;
        match hit.kind {
            Kind::Sphere => (self.spheres).surface(hit, ray, uv(self.spheres.material[i])),
            Kind::Triangle => self.triangles.surface(hit, self.features.textures),
            Kind::Plane => (self.planes).surface(hit, ray, uv(self.planes.planes[i].material)),
            Kind::Cone => self.cones.surface(hit, ray, uv(self.cones.material[i])),
            Kind::Disc => self.discs.surface(hit, ray, uv(self.discs.material[i])),
            Kind::Custom => self.customs.surface(hit, ray),
        }
    }

    /// What reaches the end of a shadow ray: zero when an opaque surface blocks it, otherwise
    /// the product of the filters (`Material::shadow`) of the surfaces it crosses.
    #[inline]
    pub fn transmittance(&self, ray: &Ray, t_max: f32, min_weight: f32, c: &mut Counters) -> Vec3A {
        match self.blocked(ray, t_max, min_weight, 0, c) {
            Some(true) => Vec3A::ZERO,
            Some(false) => Vec3A::ONE,
            None => self.transmittance_filtered(ray, t_max, min_weight, c),
        }
    }

    /// In a scene whose shadow rays are blocked or pass unchanged ([`Casters`]): whether
    /// `ray` is blocked ([`Scene::transmittance`] zero or one). `None` elsewhere, asking
    /// nothing: the caller asks [`Scene::transmittance`]. `skip`: [`Scene::own_caster`] of
    /// the sphere a ray leaves outward toward its end on the same side, else 0.
    #[inline(always)]
    pub fn blocked(
        &self,
        ray: &Ray,
        t_max: f32,
        min_weight: f32,
        skip: u32,
        c: &mut Counters,
    ) -> Option<bool> {
        match (&self.casters, min_weight <= 1.0) {
            (Some(casters), true) => Some(casters.blocked(self, ray, t_max, skip, c)),
            _ => None,
        }
    }

    /// For a hit from outside (`entering`) on a sphere of the scene's own geometry: what
    /// [`Scene::blocked`] may pass over for shadow rays leaving it outward (0 for any other
    /// hit or scene).
    #[inline(always)]
    pub fn own_caster(&self, hit: &Hit, entering: bool) -> u32 {
        let own = hit.kind == Kind::Sphere && hit.instance == NO_INSTANCE && !hit.moving;
        if !entering || !own || hit.object != 0 {
            return 0;
        }
        match &self.casters {
            Some(casters) => casters.own(hit.index),
            None => 0,
        }
    }

    /// [`Scene::transmittance`] of a scene without [`Casters`] (or asked with a `min_weight`
    /// above 1).
    #[inline(never)]
    fn transmittance_filtered(
        &self,
        ray: &Ray,
        t_max: f32,
        min_weight: f32,
        c: &mut Counters,
    ) -> Vec3A {
        // The box tests' set-up, once for every kind.
        let boxes = BoxRay::new(ray.origin, ray.dir);
        let b = &boxes;
        if !self.features.shadow_filters {
            // Opaque world: the first hit anywhere ends the query.
            let clips = &self.clips;
            let blocked = self.spheres.any_opaque(ray, b, t_max, clips, c)
                || (self.triangles.set).any_opaque(ray, b, t_max, clips, c)
                || self.planes.any(ray, t_max, clips, c, |_, _| true)
                || self.cones.any_opaque(ray, b, t_max, clips, c)
                || self.discs.any_opaque(ray, b, t_max, clips, c)
                || self.customs.any(ray, t_max, clips, c, |_, _| true)
                || (!self.moving.is_empty()
                    && self
                        .moving
                        .any(ray, t_max, &self.clips, c, &mut |_, _| true))
                || (!self.instances.is_empty()
                    && (self.instances).any(ray, b, t_max, c, &mut |_, _| true))
                || (!self.objects.is_empty()
                    && self.objects.any(ray, b, t_max, c, &mut |_, _| true));
            return if blocked { Vec3A::ZERO } else { Vec3A::ONE };
        }
        let mut filter = Vec3A::ONE;
        let mut on_hit = |m: u32, crossings: u32| {
            let Some(f) = self.materials[m as usize].shadow else {
                filter = Vec3A::ZERO;
                return true;
            };
            for _ in 0..crossings {
                filter *= f;
            }
            filter.max_element() < min_weight
        };
        // Surfaces a shadow ray crosses unchanged (the light spheres Tachyon draws: no shadow)
        // are not tested: the filter times one is the filter. Unless `min_weight` exceeds 1,
        // when even the first crossing would end the ray.
        let blocked = if self.features.see_through && min_weight <= 1.0 {
            let skip = |m: u32| self.materials[m as usize].shadow == Some(Vec3A::ONE);
            let clips = &self.clips;
            let f = &mut on_hit;
            (self.spheres).any_skipping(ray, b, t_max, clips, c, skip, &mut *f)
                || (self.triangles.set).any_skipping(ray, b, t_max, clips, c, skip, &mut *f)
                || self.planes.any(ray, t_max, clips, c, &mut *f)
                || (self.cones).any_skipping(ray, b, t_max, clips, c, skip, &mut *f)
                || (self.discs).any_skipping(ray, b, t_max, clips, c, skip, &mut *f)
        } else {
            let (clips, f) = (&self.clips, &mut on_hit);
            self.spheres.any_prepared(ray, b, t_max, clips, c, &mut *f)
                || (self.triangles.set).any_prepared(ray, b, t_max, clips, c, &mut *f)
                || self.planes.any(ray, t_max, clips, c, &mut *f)
                || self.cones.any_prepared(ray, b, t_max, clips, c, &mut *f)
                || self.discs.any_prepared(ray, b, t_max, clips, c, &mut *f)
        };
        if blocked
            || self.customs.any(ray, t_max, &self.clips, c, &mut on_hit)
            || (!self.moving.is_empty() && self.moving.any(ray, t_max, &self.clips, c, &mut on_hit))
            || (!self.instances.is_empty() && self.instances.any(ray, b, t_max, c, &mut on_hit))
            || (!self.objects.is_empty() && self.objects.any(ray, b, t_max, c, &mut on_hit))
        {
            return Vec3A::ZERO;
        }
        filter
    }

    /// Moves the camera without rebuilding anything (the next view of a Tachyon camera file,
    /// or an animated scene's keyed camera, which `set_frame` places here): the
    /// geometry stays stored relative to `world_offset` (the first camera's position) and the
    /// new camera is placed in that space. Only the camera's position, direction and window
    /// change what a render computes; `settings` (resolution, samples) stay as built.
    /// The camera ray through image point (`px`, `py`) at frame-relative time `time`: from
    /// the camera at that time when the camera moves during the shutter, else the frame's.
    #[inline]
    pub fn primary(&self, px: f32, py: f32, time: f32) -> Option<Ray> {
        let s = &self.settings;
        if self.camera_moves {
            let moved = self
                .animation
                .as_ref()
                .and_then(|a| a.camera_at_time(time, self.world_offset, s.width, s.height));
            if let Some(c) = moved {
                return c.primary(px, py, s.width, s.height, time);
            }
        }
        self.camera.primary(px, py, s.width, s.height, time)
    }

    /// The camera rays through the image points (`xs[i]`, `ys[i]`) at times `times[i]`, into
    /// `out` (as long as `xs`): [`Scene::primary`]'s, bit for bit, made side by side when the
    /// camera holds still ([`Camera::primaries`]).
    pub fn primaries(&self, xs: &[f32], ys: &[f32], times: &[f32], out: &mut [Option<Ray>]) {
        if self.camera_moves {
            for (((o, &x), &y), &t) in out.iter_mut().zip(xs).zip(ys).zip(times) {
                *o = self.primary(x, y, t);
            }
            return;
        }
        let size = (self.settings.width, self.settings.height);
        self.camera.primaries(xs, ys, times, size, out);
    }

    pub fn set_camera(&mut self, desc: &luxon_formats::CameraDesc) {
        let origin = Vec3A::from((DVec3::from(desc.position) - self.world_offset).as_vec3());
        let s = &self.settings;
        self.camera = Camera::new(desc, origin, s.width, s.height);
        (self.primary_width, self.pixel_spread) = self.camera.footprint();
    }

    pub fn primitive_count(&self) -> usize {
        self.spheres.len()
            + self.triangles.len()
            + self.planes.planes.len()
            + self.cones.len()
            + self.discs.len()
            + self.customs.len()
            + self.objects.len()
    }
}
