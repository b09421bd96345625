//! Whitted ray tracing with the thesis's shading model: ambient, Lambert diffuse, Phong or Blinn
//! highlights, mirror reflection, refraction with an index-of-refraction stack and total internal
//! reflection, transparency with filtered shadows. Effects the scene does not call for (see
//! `Features`) are skipped before any ray is spawned for them.

pub mod march;
mod pixels;

pub use pixels::{render_depth, render_spans};

use crate::geometry::{Counters, Hit, Surface};
use crate::math::{gamma, reflect, refract, Vec3A};
use crate::plugin::texture::{EvalFailure, TextureInstance};
use crate::ray::{offset_up, spawn, spawn_or, spawn_to_or, Ray};
use crate::sampler::{mix, pixel_sample};
use crate::scene::{AngleRule, Ao, Light, Material, Scene, Sky};
use luxon_formats::{BeyondMax, Highlight, TransparencyMode};
use luxon_plugin::abi::TexQuery;

/// Tachyon's threshold on light terms and coefficients (`TachyonDesc::light_threshold`).
const TACHYON_FLOOR: f32 = 1.0 / 510.0;

/// Media the ray is inside, innermost last: (material, index of refraction); and how many
/// transparent surfaces the path has passed through.
#[derive(Clone, Copy, Debug)]
pub struct IorStack {
    items: [(u32, f32); 8],
    len: usize,
    pub surfaces: u32,
}

impl Default for IorStack {
    fn default() -> Self {
        IorStack {
            items: [(0, 1.0); 8],
            len: 0,
            surfaces: 0,
        }
    }
}

impl IorStack {
    /// Index of refraction the ray travels in now (vacuum outside everything).
    pub fn current(&self) -> f32 {
        if self.len == 0 {
            1.0
        } else {
            self.items[self.len - 1].1
        }
    }

    /// Pushes a medium; when full the outermost is forgotten (deeper nesting is unphysical).
    pub fn push(&mut self, material: u32, ior: f32) {
        if self.len == self.items.len() {
            self.items.copy_within(1.., 0);
            self.len -= 1;
        }
        self.items[self.len] = (material, ior);
        self.len += 1;
    }

    /// Removes the innermost entry of `material` (the medium being left).
    pub fn remove(&mut self, material: u32) {
        if let Some(i) = self.items[..self.len]
            .iter()
            .rposition(|&(m, _)| m == material)
        {
            self.items.copy_within(i + 1..self.len, i);
            self.len -= 1;
        }
    }
}

pub struct Whitted<'a> {
    pub scene: &'a Scene,
    /// Some light or occlusion draws random numbers (more than one sample; `square` ignores
    /// the seed for one): only then is a shading point's seed worth hashing.
    draws: bool,
    /// What rays that hit nothing show: camera rays, other rays...
    miss: [Vec3A; 2],
    /// ...or, where they show the background and it is a gradient, the gradient.
    sky: [Option<Sky>; 2],
    /// Mirror and transmission coefficients at or below this are ignored.
    floor: f32,
    /// What a light's term is scaled by before Tachyon's threshold: the light scale, times
    /// occlusion's `direct` when occlusion is on.
    term_scale: f32,
    compose: Compose,
    /// The scene has no surface at all (Tachyon's empty scenes): no ray is worth intersecting.
    blank: bool,
    /// Every light is a point light (most of Tachyon's scenes): `lighting` runs their terms
    /// inline, without the dispatch per light.
    points: bool,
}

/// How a transparent surface's shading and what lies behind it combine (from the mode).
#[derive(Clone, Copy)]
struct Compose {
    /// Ambient and diffuse are scaled by opacity (`Filter`, `AngleModulated`).
    scale_shading: bool,
    /// The whole shaded colour is scaled by opacity (`PostMultiplied`)...
    post: bool,
    /// ...the mirror reflection too.
    post_reflection: bool,
    /// Light from behind is tinted by the surface colour (`Filter`, `AngleModulated`).
    tint: bool,
}

impl<'a> Whitted<'a> {
    pub fn new(scene: &'a Scene) -> Whitted<'a> {
        let sampled = |l: &Light| match l {
            Light::Sphere { samples, .. } | Light::Rect { samples, .. } => *samples > 1,
            _ => false,
        };
        let draws = scene.features.ambient_occlusion
            && scene.ao.as_ref().is_some_and(|a| a.samples > 1)
            || scene.lights.iter().any(sampled);
        let bg = scene.background;
        let miss = match &scene.fog {
            Some(f) if f.misses => [f.color, if f.every_ray { f.color } else { bg }],
            _ => [bg, bg],
        };
        let sky = match &scene.fog {
            Some(f) if f.misses => [None, if f.every_ray { None } else { scene.sky }],
            _ => [scene.sky; 2],
        };
        let settings = &scene.settings;
        let t = settings.transparency;
        let filtered = matches!(
            t.mode,
            TransparencyMode::Filter | TransparencyMode::AngleModulated
        );
        let post = t.mode == TransparencyMode::PostMultiplied;
        let mut term_scale = settings.light_scale;
        if let (true, Some(ao)) = (scene.features.ambient_occlusion, &scene.ao) {
            term_scale *= ao.direct;
        }
        let blank =
            scene.primitive_count() == 0 && scene.moving.is_empty() && scene.instances.is_empty();
        Whitted {
            scene,
            blank,
            points: (scene.lights.iter()).all(|l| matches!(l, Light::Point { .. })),
            draws,
            miss,
            sky,
            floor: if settings.tachyon.light_threshold {
                TACHYON_FLOOR
            } else {
                0.0
            },
            term_scale,
            compose: Compose {
                scale_shading: filtered,
                post,
                post_reflection: post && t.scale_reflection,
                tint: filtered,
            },
        }
    }
}

impl Whitted<'_> {
    /// Radiance arriving along `ray`. `depth` is the ray's generation (0 = primary); `weight` is
    /// the most this ray can still contribute to its pixel.
    pub fn radiance(
        &self,
        ray: &Ray,
        depth: u32,
        weight: f32,
        media: &IorStack,
        c: &mut Counters,
    ) -> Vec3A {
        let cone = Cone {
            width: if depth == 0 {
                self.scene.primary_width
            } else {
                0.0
            },
            travelled: 0.0,
        };
        self.trace(ray, depth, weight, media, cone, c)
    }

    /// Texture `t` at a surface point; a texture that fails or panics raises the scene's fault.
    /// Inlined into `material_at` (a call of its own cost ~15 instructions per lookup).
    #[inline]
    fn texture(&self, t: u32, q: &TexQuery) -> [f32; 4] {
        let tex = &self.scene.textures[t as usize];
        match tex.eval(q) {
            Ok(c) => c,
            Err(f) => self.texture_failed(tex, &f),
        }
    }

    /// [`Self::texture`] of a texture that failed: the fault raised, black meanwhile.
    #[cold]
    #[inline(never)]
    fn texture_failed(&self, tex: &TextureInstance, f: &EvalFailure) -> [f32; 4] {
        self.scene.customs.fault.raise(tex.failure(f));
        [0.0; 4]
    }

    /// `cone` is the ray's footprint at its origin and the path's length so far: rays are traced
    /// as thin cones (a pixel wide at the camera, widening by the pixel angle per unit of
    /// distance) so textures know how much of them a pixel covers and can filter (MIP mapping).
    fn trace(
        &self,
        ray: &Ray,
        depth: u32,
        weight: f32,
        media: &IorStack,
        cone: Cone,
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        let hit = if self.blank {
            None
        } else {
            scene.intersect(ray, f32::INFINITY, c)
        };
        if !scene.features.volumes {
            // By reference: moving the hit out of the `Option` copies it in two wide loads,
            // which stall on `intersect`'s narrow stores (2 % of Tachyon's fog's samples).
            return match &hit {
                Some(hit) => self.shade(ray, hit, depth, weight, media, cone, c),
                None => self.missed(ray, depth),
            };
        }
        // Volumes in front of the first surface (or the background), composited over it.
        let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
        let cutoff = scene.settings.min_weight / weight.max(f32::MIN_POSITIVE);
        let (color, through) = if scene.settings.tachyon.additive_volumes {
            // Tachyon shades a SCALARVOL's box at its front face, then, through it, at its
            // back face from inside: the same march twice, C + (1 − S)(C + (1 − S) behind).
            let (color, sum) = march::march_additive(scene, ray, t_hit, c);
            let through = 1.0 - sum;
            (color * (1.0 + through), through * through)
        } else {
            march::march(scene, ray, t_hit, cutoff, c)
        };
        if through < cutoff {
            // Early ray termination: what lies behind cannot show.
            return color;
        }
        let behind = match hit {
            Some(hit) => self.shade(ray, &hit, depth, weight * through, media, cone, c),
            None => self.missed(ray, depth),
        };
        color + through * behind
    }

    /// What `ray` (of generation `depth`) shows when it hits nothing.
    #[inline]
    fn missed(&self, ray: &Ray, depth: u32) -> Vec3A {
        let k = (depth > 0) as usize;
        match &self.sky[k] {
            Some(sky) => sky.toward(ray.origin, ray.dir),
            None => self.miss[k],
        }
    }

    /// The background a ray from `origin` along `dir()` would show, for rays that are not
    /// traced (past the depth limit); `dir` is only worked out for a gradient.
    #[inline]
    fn background(&self, origin: Vec3A, dir: impl FnOnce() -> Vec3A) -> Vec3A {
        match &self.scene.sky {
            Some(sky) => sky.toward(origin, dir()),
            None => self.scene.background,
        }
    }

    /// The colour a surface hit shows along `ray`: the material at the hit, its lighting, fog,
    /// then reflection and refraction (each a named step below).
    #[allow(clippy::too_many_arguments)]
    fn shade(
        &self,
        ray: &Ray,
        hit: &Hit,
        depth: u32,
        weight: f32,
        media: &IorStack,
        cone: Cone,
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        let s = scene.surface(hit, ray);
        let mat = &scene.materials[s.material as usize];
        let features = scene.features;
        let cone = cone.at(hit.t, scene.pixel_spread);
        let side = Side::of(&s, ray);
        let (base, kr, kt) = self.material_at(&s, mat, side.n, cone, ray.time);
        let mut kt = kt;
        if kt > 0.0 {
            let t = scene.settings.transparency;
            if t.max_surfaces.is_some_and(|n| media.surfaces >= n) {
                if t.beyond_max == BeyondMax::Skip {
                    // Not shown at all: the ray goes on as if the surface were not there.
                    return self.pass_through(ray, &s, &side, depth, weight, media, cone, c);
                }
                kt = 0.0;
            } else {
                kt = angle_rule(mat.angle, kt, ray, side.n);
            }
        }
        let compose = self.compose;

        let opacity = 1.0 - kt;
        // Post-multiplied and additive: shade as if opaque (then scale by the opacity).
        let shade_opacity = if compose.scale_shading { opacity } else { 1.0 };
        let mut color = mat.ambient * shade_opacity * base;
        // Shadow rays leaving a sphere outward need not ask it (see `Casters::blocked`).
        let own = scene.own_caster(hit, side.entering);
        color += self.lighting(ray, &s, &side, mat, base, shade_opacity, own, c);
        if compose.post {
            color *= opacity;
        }
        let filter = if compose.tint { base } else { Vec3A::ONE };
        if depth == 0 {
            self.fog(&mut color, ray, hit.t, mat);
        }

        let next = depth + 1;
        if features.reflection && kr > self.floor {
            let kr = if compose.post_reflection {
                kr * opacity
            } else {
                kr
            };
            let bounce = Bounce {
                depth: next,
                weight: weight * kr,
                cone,
            };
            self.reflection(&mut color, ray, &s, &side, kr, &bounce, media, c);
        }
        if features.transmission && kt > self.floor {
            let bounce = Bounce {
                depth: next,
                weight: weight * kt,
                cone,
            };
            let filter = kt * filter;
            self.transmission(&mut color, ray, &s, &side, mat, filter, &bounce, media, c);
        }
        if features.fog_every_ray {
            self.fog_segment(&mut color, ray, hit.t, depth, mat);
        }
        color
    }

    /// What lies behind a surface a ray skips (a transparent surface past the most a path may
    /// show): the ray goes on, one level deeper; past the depth limit, the background.
    #[allow(clippy::too_many_arguments)]
    fn pass_through(
        &self,
        ray: &Ray,
        s: &Surface,
        side: &Side,
        depth: u32,
        weight: f32,
        media: &IorStack,
        cone: Cone,
        c: &mut Counters,
    ) -> Vec3A {
        let next = depth + 1;
        if next > self.scene.settings.max_depth {
            // Tachyon's: the background of the ray that reached the surface.
            return self.background(ray.origin, || ray.dir);
        }
        c.refraction += 1;
        let r = spawn(s.p, s.p_error, side.ng, ray.dir, ray.time);
        self.trace(&r, next, weight, media, cone, c)
    }

    /// The material's colour and reflect and transmit coefficients at a surface point, with
    /// its textures (looked up along shading normal `n`) and vertex colour applied.
    #[inline]
    fn material_at(
        &self,
        s: &Surface,
        mat: &Material,
        n: Vec3A,
        cone: Cone,
        time: f32,
    ) -> (Vec3A, f32, f32) {
        let scene = self.scene;
        let mut base = mat.color;
        let (mut kr, mut kt) = (mat.reflect, mat.transmit);
        if scene.features.textures {
            let q = TexQuery {
                p: (s.p.as_dvec3() + scene.world_offset).into(),
                n: n.into(),
                uv: s.uv,
                footprint: cone.width,
                uv_footprint: cone.width * s.uv_scale,
                time,
                distance: cone.travelled,
            };
            let mean = |c: [f32; 4]| (c[0] + c[1] + c[2]) / 3.0;
            if let Some(t) = mat.texture {
                let rgba = self.texture(t, &q);
                base = Vec3A::new(rgba[0], rgba[1], rgba[2]);
            }
            if let Some(t) = mat.reflect_texture {
                kr *= mean(self.texture(t, &q)).clamp(0.0, 1.0);
            }
            if let Some(t) = mat.transmit_texture {
                kt *= mean(self.texture(t, &q)).clamp(0.0, 1.0);
            }
        }
        if let Some(vc) = s.color {
            base *= vc;
        }
        (base, kr, kt)
    }

    /// The light sources' and the sky's (ambient occlusion) light a surface point reflects.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn lighting(
        &self,
        ray: &Ray,
        s: &Surface,
        side: &Side,
        mat: &Material,
        base: Vec3A,
        opacity: f32,
        own: u32,
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        // Random numbers for area lights and occlusion, from the ray itself: deterministic for
        // any thread count or decomposition, different for every path.
        let seed = if self.draws { ray_seed(ray) } else { 0 };
        // Light and occlusion rays leave smooth meshes from the curved surface, not the facet.
        let lift = !self.scene.settings.tachyon.terminator_shadows;
        let (light_p, light_error) = if lift && side.entering && s.lift != Vec3A::ZERO {
            let q = s.p + s.lift;
            (q, s.p_error + gamma(4) * (s.lift.abs() + q.abs()))
        } else {
            (s.p, s.p_error)
        };
        // The outline darkens the diffuse light (lights and sky) toward the silhouette.
        let opacity = if scene.features.outline && mat.outline > 0.0 {
            opacity * mat.outline_factor(ray.dir.dot(side.n))
        } else {
            opacity
        };
        let shade = Shade {
            p: light_p,
            p_error: light_error,
            n: side.n,
            ng: side.ng,
            view: -ray.dir,
            base,
            opacity,
            time: ray.time,
            up: if scene.features.shadows {
                offset_up(light_p, light_error, side.ng)
            } else {
                light_p
            },
            own,
        };
        let mut lit = Vec3A::ZERO;
        // Each light's seed is mixed only by the lights that draw (see `direct`).
        // A light's rules: shadows only if it casts them (both made once per point).
        if scene.features.tachyon_lights && self.points {
            // `direct`'s point-light arm, its term inline (no seed: a point light draws none).
            let rules = Rules::new::<true>(scene, mat).per_light();
            for light in &scene.lights {
                if let Light::Point {
                    position,
                    color,
                    attenuation,
                    shadows,
                } = light
                {
                    let (rules, raw) = (&rules[*shadows as usize], (*color, 1.0));
                    let (q, a) = (*position, attenuation);
                    lit += self.point_term::<true, true>(&shade, mat, rules, q, *color, raw, a, c);
                }
            }
        } else if scene.features.tachyon_lights {
            let rules = Rules::new::<true>(scene, mat).per_light();
            for (k, light) in scene.lights.iter().enumerate() {
                let rules = &rules[light.casts_shadows() as usize];
                lit += self.direct::<true>(&shade, mat, rules, light, seed ^ k as u32, c);
            }
        } else {
            let rules = Rules::new::<false>(scene, mat).per_light();
            for (k, light) in scene.lights.iter().enumerate() {
                let rules = &rules[light.casts_shadows() as usize];
                lit += self.direct::<false>(&shade, mat, rules, light, seed ^ k as u32, c);
            }
        }
        if let (true, Some(ao)) = (scene.features.ambient_occlusion, &scene.ao) {
            lit *= ao.direct;
            lit += mat.diffuse * opacity * base * ao.sky * self.unoccluded(&shade, ao, seed, c);
        }
        lit
    }

    /// Fog over the distance `t` a camera ray travelled to its hit.
    #[inline]
    fn fog(&self, color: &mut Vec3A, ray: &Ray, t: f32, mat: &Material) {
        let scene = self.scene;
        if let (true, Some(fog)) = (scene.features.fog, &scene.fog) {
            if !mat.fog {
                return;
            }
            let d = if fog.planar {
                t * ray.dir.dot(scene.camera.forward)
            } else {
                t
            };
            let v = fog.visibility(d);
            *color = *color * v + fog.color * (1.0 - v);
        }
    }

    /// Tachyon's fog: over the segment `t` of any ray (planar for camera rays when `planar`),
    /// on the hit's whole colour.
    fn fog_segment(&self, color: &mut Vec3A, ray: &Ray, t: f32, depth: u32, mat: &Material) {
        let scene = self.scene;
        if let (Some(fog), true) = (&scene.fog, mat.fog) {
            let d = if fog.planar && depth == 0 {
                t * ray.dir.dot(scene.camera.forward)
            } else {
                t
            };
            let v = fog.visibility(d);
            *color = *color * v + fog.color * (1.0 - v);
        }
    }

    /// Adds the mirror reflection, scaled by `kr`, to `color`: the background past the maximum
    /// depth, nothing below the minimum weight.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn reflection(
        &self,
        color: &mut Vec3A,
        ray: &Ray,
        s: &Surface,
        side: &Side,
        kr: f32,
        bounce: &Bounce,
        media: &IorStack,
        c: &mut Counters,
    ) {
        let settings = &self.scene.settings;
        if bounce.depth > settings.max_depth {
            // Tachyon's: the background of the ray that reached the surface, unscaled; else
            // the background the mirror would show.
            *color += if settings.tachyon.depth_limit_background {
                self.background(ray.origin, || ray.dir)
            } else {
                kr * self.background(s.p, || reflect(ray.dir, side.n))
            };
        } else if bounce.weight >= settings.min_weight {
            c.reflection += 1;
            let r = spawn(s.p, s.p_error, side.ng, reflect(ray.dir, side.n), ray.time);
            *color += kr * self.trace(&r, bounce.depth, bounce.weight, media, bounce.cone, c);
        }
    }

    /// Adds the light coming through the surface (refracted, or totally internally reflected),
    /// scaled by `filter`, to `color`, keeping track of the media the ray is in.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn transmission(
        &self,
        color: &mut Vec3A,
        ray: &Ray,
        s: &Surface,
        side: &Side,
        mat: &Material,
        filter: Vec3A,
        bounce: &Bounce,
        media: &IorStack,
        c: &mut Counters,
    ) {
        let settings = &self.scene.settings;
        if bounce.depth > settings.max_depth {
            // As for reflections; the background straight on through the surface.
            *color += if settings.tachyon.depth_limit_background {
                self.background(ray.origin, || ray.dir)
            } else {
                filter * self.background(s.p, || ray.dir)
            };
        } else if bounce.weight >= settings.min_weight {
            // Which media are on each side of the surface.
            let mut inside = *media;
            inside.surfaces += 1;
            let (n1, n2) = if side.entering {
                let n1 = media.current();
                inside.push(s.material, mat.ior);
                (n1, mat.ior)
            } else {
                inside.remove(s.material);
                (mat.ior, inside.current())
            };
            let (dir, through) = match refract(ray.dir, side.n, n1 / n2) {
                Some(t) => (t, true),
                // Total internal reflection: the light stays on this side.
                None => (reflect(ray.dir, side.n), false),
            };
            c.refraction += 1;
            let r = spawn(s.p, s.p_error, side.ng, dir, ray.time);
            let mut outside = *media;
            outside.surfaces += 1;
            let stack = if through { &inside } else { &outside };
            let (depth, weight) = (bounce.depth, bounce.weight);
            *color += filter * self.trace(&r, depth, weight, stack, bounce.cone, c);
        }
    }
}

/// Which side of a surface a ray hit, and the normals facing it.
struct Side {
    /// The ray arrived against the geometric normal (entering a closed shape).
    entering: bool,
    /// Geometric and shading normal, both toward the viewer.
    ng: Vec3A,
    n: Vec3A,
}

impl Side {
    /// Orients the normals toward the viewer; remembers which side was hit for media changes.
    #[inline]
    fn of(s: &Surface, ray: &Ray) -> Side {
        let entering = s.ng.dot(ray.dir) < 0.0;
        let ng = if entering { s.ng } else { -s.ng };
        let mut n = if s.ns.dot(ng) < 0.0 { -s.ns } else { s.ns };
        if n.dot(ray.dir) > 0.0 {
            // Interpolated normals can face away at silhouettes; fall back to the true one.
            n = ng;
        }
        Side { entering, ng, n }
    }
}

/// The ray a reflection or refraction spawns: its depth, its weight (the most it can add to the
/// pixel), and its cone at its origin.
struct Bounce {
    depth: u32,
    weight: f32,
    cone: Cone,
}

/// A ray's footprint and the length of its path from the camera, at a point of the path.
#[derive(Clone, Copy)]
struct Cone {
    /// How wide the pixel's share of the scene is here (world units).
    width: f32,
    /// How far the path has come from the camera (world units).
    travelled: f32,
}

impl Cone {
    /// The cone `t` further along a ray, widening by `spread` per unit of distance.
    #[inline]
    fn at(self, t: f32, spread: f32) -> Cone {
        Cone {
            width: self.width + spread * t,
            travelled: self.travelled + t,
        }
    }
}

/// What lighting needs to know about a shading point.
struct Shade {
    /// Where light and occlusion rays start (the hit point, or above it on smooth meshes).
    p: Vec3A,
    p_error: Vec3A,
    /// Shading normal and geometric normal, both facing the viewer.
    n: Vec3A,
    ng: Vec3A,
    view: Vec3A,
    base: Vec3A,
    opacity: f32,
    time: f32,
    /// With shadows on: the origin of shadow rays toward lights on `ng`'s side
    /// (`offset_up`, ~40 instructions), made once for the point's lights (nearly every
    /// shading point casts one; a lazy `Cell` cost more per shadow ray than it saved).
    up: Vec3A,
    /// What a shadow ray from `up` may pass over ([`Scene::own_caster`], or 0).
    own: u32,
}

/// What every light's term at a shading point obeys, from the settings and the material (see
/// `Whitted::direct`; `T`: Tachyon's lights).
#[derive(Clone, Copy)]
struct Rules {
    /// Shadows are on (each light may still cast none).
    shadows: bool,
    /// Tachyon's threshold on a light's term and highlight, or 0.
    floor: f32,
    /// Tachyon's plain highlights.
    plain: bool,
    /// Tachyon's metal highlight needs no light colour: a black light still makes one.
    colourless: bool,
}

impl Rules {
    #[inline]
    fn new<const T: bool>(scene: &Scene, mat: &Material) -> Rules {
        let tachyon = scene.settings.tachyon;
        let plain = T && tachyon.plain_highlights;
        Rules {
            shadows: scene.features.shadows,
            floor: if T && tachyon.light_threshold {
                TACHYON_FLOOR
            } else {
                0.0
            },
            plain,
            colourless: plain && mat.highlight_surface && mat.specular > 0.0,
        }
    }

    /// These rules for a light that casts no shadow (first) and one that does.
    #[inline]
    fn per_light(self) -> [Rules; 2] {
        [
            Rules {
                shadows: false,
                ..self
            },
            self,
        ]
    }
}

/// A transmit coefficient `kt` after `rule`, for a surface with normal `n` (facing the
/// viewer) seen along `ray`.
#[inline]
fn angle_rule(rule: AngleRule, kt: f32, ray: &Ray, n: Vec3A) -> f32 {
    match rule {
        AngleRule::Constant => kt,
        AngleRule::Slab => {
            // A slab seen at angle θ is 1/|cos θ| thick: edge-on surfaces look opaque.
            let cos = ray.dir.dot(n).abs().max(1e-3);
            kt.powf(1.0 / cos)
        }
        AngleRule::Raster3D => {
            // Tachyon's: opacity ¼(1 + cos(π·kt·(N·D)))², more transparent edge-on.
            let a = 1.0 + (std::f32::consts::PI * kt * ray.dir.dot(n)).cos();
            1.0 - 0.25 * a * a
        }
    }
}

/// A hash of a ray's bits.
fn ray_seed(ray: &Ray) -> u32 {
    let b = |v: f32| v.to_bits();
    mix(b(ray.dir.x)
        ^ mix(b(ray.dir.y)
            ^ mix(
                b(ray.dir.z) ^ mix(b(ray.origin.x) ^ mix(b(ray.origin.y) ^ mix(b(ray.origin.z))))
            )))
}

/// Sample `i` of `n` stratified over the unit square, decorrelated by `seed`.
fn square(seed: u32, i: u32, n: u32) -> (f32, f32) {
    if n <= 1 {
        return (0.5, 0.5);
    }
    pixel_sample(seed, mix(seed), i, n, 0)
}

impl Whitted<'_> {
    /// Light from one source reaching a shading point: diffuse and highlight, times what the
    /// shadow rays let through. Area lights average `samples` points on the light. With `T`
    /// (Tachyon's lights) the light's term must exceed Tachyon's threshold, and plain
    /// highlights take the light's colour before attenuation, spot fade and filtering (or, for
    /// a surface-coloured highlight, the surface's colour in its place). `rules`: `mat`'s
    /// (made once per shading point), shadows already off for a light that casts none; `key`: the
    /// light's seed before mixing.
    fn direct<const T: bool>(
        &self,
        sh: &Shade,
        mat: &Material,
        rules: &Rules,
        light: &Light,
        key: u32,
        c: &mut Counters,
    ) -> Vec3A {
        match light {
            Light::Directional {
                to_light, color, ..
            } => self.term::<T, false>(
                sh,
                mat,
                rules,
                Vec3A::ZERO,
                *to_light,
                *color,
                (*color, 1.0),
                c,
            ),
            Light::Point {
                position,
                color,
                attenuation,
                ..
            } => self.point_term::<T, false>(
                sh,
                mat,
                rules,
                *position,
                *color,
                (*color, 1.0),
                attenuation,
                c,
            ),
            Light::Spot {
                position,
                axis,
                cos_inner,
                cos_outer,
                fade,
                color,
                attenuation,
                ..
            } => {
                let cos = (sh.p - *position).normalize().dot(*axis);
                if cos <= *cos_outer {
                    return Vec3A::ZERO;
                }
                let w = Light::spot_weight(cos, *cos_inner, *cos_outer, *fade);
                self.point_term::<T, false>(
                    sh,
                    mat,
                    rules,
                    *position,
                    *color * w,
                    (*color, w),
                    attenuation,
                    c,
                )
            }
            Light::Sphere {
                center,
                radius,
                samples,
                color,
                attenuation,
                ..
            } => {
                // Points on the disc the sphere shows to the shading point.
                let w = (*center - sh.p).normalize_or_zero();
                if w == Vec3A::ZERO {
                    return Vec3A::ZERO;
                }
                let u = crate::math::orthogonal(w);
                let v = w.cross(u);
                let at = |a: f32, b: f32| {
                    let (r, phi) = (a.sqrt() * radius, b * std::f32::consts::TAU);
                    *center + r * (phi.cos() * u + phi.sin() * v)
                };
                self.area_term::<T>(sh, mat, rules, key, *samples, at, *color, attenuation, c)
            }
            Light::Rect {
                corner,
                edge1,
                edge2,
                normal,
                samples,
                color,
                attenuation,
                ..
            } => {
                if (sh.p - *corner).dot(*normal) <= 0.0 {
                    return Vec3A::ZERO;
                }
                let at = |a: f32, b: f32| *corner + a * *edge1 + b * *edge2;
                self.area_term::<T>(sh, mat, rules, key, *samples, at, *color, attenuation, c)
            }
        }
    }

    /// An area light's term: the mean of `samples` point terms at `at(a, b)`, the light's point
    /// for the stratified sample `(a, b)` of the unit square (seeded by `key`).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn area_term<const T: bool>(
        &self,
        sh: &Shade,
        mat: &Material,
        rules: &Rules,
        key: u32,
        samples: u32,
        at: impl Fn(f32, f32) -> Vec3A,
        color: Vec3A,
        attenuation: &[f32; 3],
        c: &mut Counters,
    ) -> Vec3A {
        let seed = mix(key);
        let mut sum = Vec3A::ZERO;
        for i in 0..samples {
            let (a, b) = square(seed, i, samples);
            sum += self.point_term::<T, false>(
                sh,
                mat,
                rules,
                at(a, b),
                color,
                (color, 1.0),
                attenuation,
                c,
            );
        }
        sum / samples as f32
    }

    /// A point light's term at a shading point: `color` arrives at the point attenuated;
    /// `raw`, `w`: see [`Whitted::term_body`]. With `I` the term is inlined (`lighting`'s loop
    /// over point lights), else called.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn point_term<const T: bool, const I: bool>(
        &self,
        sh: &Shade,
        mat: &Material,
        rules: &Rules,
        q: Vec3A,
        color: Vec3A,
        (raw, w): (Vec3A, f32),
        a: &[f32; 3],
        c: &mut Counters,
    ) -> Vec3A {
        let d = q - sh.p;
        let dist = d.length();
        let att = Light::attenuate(a, dist);
        let (to_light, arriving, raw) = (d / dist, color * att, (raw, w * att));
        if I {
            self.term_body::<T, true>(sh, mat, rules, q, to_light, arriving, raw, c)
        } else {
            self.term::<T, true>(sh, mat, rules, q, to_light, arriving, raw, c)
        }
    }

    /// [`Whitted::term_body`] out of line, for `direct`'s lights.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn term<const T: bool, const P: bool>(
        &self,
        sh: &Shade,
        mat: &Material,
        rules: &Rules,
        target: Vec3A,
        to_light: Vec3A,
        arriving: Vec3A,
        raw: (Vec3A, f32),
        c: &mut Counters,
    ) -> Vec3A {
        self.term_body::<T, P>(sh, mat, rules, target, to_light, arriving, raw, c)
    }

    /// One light term (see [`Whitted::direct`]): with `P`, `target` is the point on the light
    /// (unused for a direction), `to_light` the direction to it, `arriving` the radiance
    /// arriving; with `T`: `raw` is the light's colour and `w` its weight from attenuation and
    /// spot fade.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn term_body<const T: bool, const P: bool>(
        &self,
        sh: &Shade,
        mat: &Material,
        rules: &Rules,
        target: Vec3A,
        to_light: Vec3A,
        arriving: Vec3A,
        (raw, w): (Vec3A, f32),
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        let Rules {
            shadows,
            floor,
            plain,
            colourless,
        } = *rules;
        let ndotl = sh.n.dot(to_light);
        if ndotl <= 0.0 || (arriving == Vec3A::ZERO && !colourless) {
            return Vec3A::ZERO;
        }
        if T && ndotl * w * self.term_scale <= floor {
            return Vec3A::ZERO;
        }
        let mut arriving = arriving;
        if shadows {
            c.shadow += 1;
            let up = || sh.up;
            let (sray, t_max, above) = if P {
                spawn_to_or(sh.p, sh.p_error, sh.ng, target, sh.time, up)
            } else {
                let (r, above) = spawn_or(sh.p, sh.p_error, sh.ng, to_light, sh.time, up);
                (r, f32::INFINITY, above)
            };
            // From `up` toward a light on `ng`'s side: the point's own sphere cannot block.
            let skip = if above { sh.own } else { 0 };
            if colourless {
                // Blocked is what counts, not what arrives.
                let mut through = scene.transmittance(&sray, t_max, scene.settings.min_weight, c);
                if scene.features.volumes && through != Vec3A::ZERO {
                    through *= march::transmittance(scene, &sray, t_max, c);
                }
                if through == Vec3A::ZERO {
                    return Vec3A::ZERO;
                }
                arriving *= through;
            } else {
                // Blocked or not needs no product: `arriving` times one is `arriving`.
                let min_weight = scene.settings.min_weight;
                match scene.blocked(&sray, t_max, min_weight, skip, c) {
                    Some(true) => return Vec3A::ZERO,
                    Some(false) => {}
                    None => arriving *= scene.transmittance(&sray, t_max, min_weight, c),
                }
                if scene.features.volumes && arriving != Vec3A::ZERO {
                    arriving *= march::transmittance(scene, &sray, t_max, c);
                }
                if arriving == Vec3A::ZERO {
                    return Vec3A::ZERO;
                }
            }
        }
        let mut lit = mat.diffuse * sh.opacity * ndotl * sh.base;
        let mut highlight = Vec3A::ZERO;
        if mat.specular > 0.0 {
            let cos = match mat.highlight {
                Highlight::Phong => reflect(-to_light, sh.n).dot(sh.view),
                Highlight::Blinn | Highlight::BlinnFast => {
                    sh.n.dot((to_light + sh.view).normalize())
                }
            };
            if cos > floor {
                let h = if mat.highlight == Highlight::BlinnFast {
                    // Tachyon's cheap stand-in for cos^s.
                    let s = mat.shininess;
                    cos / (s - s * cos + cos)
                } else {
                    cos.powf(mat.shininess)
                };
                if plain {
                    highlight = Vec3A::splat(mat.specular * h);
                } else {
                    // White, or the surface's colour (metal), times the light's.
                    let tint = if mat.highlight_surface {
                        sh.base
                    } else {
                        Vec3A::ONE
                    };
                    lit += (mat.specular * h) * tint;
                }
            }
        }
        if plain {
            // Tachyon's metal highlight takes the surface's colour in place of the light's.
            let tint = if mat.highlight_surface {
                sh.base * self.scene.settings.light_scale
            } else {
                raw
            };
            arriving * lit + tint * highlight
        } else {
            arriving * lit
        }
    }

    /// The fraction of the sky a point sees within the occlusion distance: cosine-weighted
    /// hemisphere rays; transparent occluders block only by their opacity (what VMD users
    /// expect of transparent molecular surfaces).
    fn unoccluded(&self, sh: &Shade, ao: &Ao, seed: u32, c: &mut Counters) -> f32 {
        let u = crate::math::orthogonal(sh.n);
        let v = sh.n.cross(u);
        let seed = mix(seed ^ 0x0a0c_c1de);
        let mut seen = 0.0;
        for i in 0..ao.samples {
            let (a, b) = square(seed, i, ao.samples);
            let (r, phi) = (a.sqrt(), b * std::f32::consts::TAU);
            let dir = (r * phi.cos() * u + r * phi.sin() * v + (1.0 - a).max(0.0).sqrt() * sh.n)
                .normalize();
            if dir.dot(sh.ng) <= 0.0 {
                continue;
            }
            c.occlusion += 1;
            let ray = spawn(sh.p, sh.p_error, sh.ng, dir, sh.time);
            let t = self.scene.transmittance(&ray, ao.max_distance, 0.0, c);
            seen += (t.x + t.y + t.z) / 3.0;
        }
        seen / ao.samples as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ior_stack_nesting() {
        let mut s = IorStack::default();
        assert_eq!(s.current(), 1.0);
        s.push(1, 1.33); // water
        s.push(2, 1.5); // glass inside water
        assert_eq!(s.current(), 1.5);
        s.remove(2);
        assert_eq!(s.current(), 1.33);
        s.remove(7); // leaving something never entered changes nothing
        assert_eq!(s.current(), 1.33);
        s.remove(1);
        assert_eq!(s.current(), 1.0);
    }
}
