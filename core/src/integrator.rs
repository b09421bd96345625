//! Whitted ray tracing with the thesis's shading model: ambient, Lambert diffuse, Phong or Blinn
//! highlights, mirror reflection, refraction with an index-of-refraction stack and total internal
//! reflection, transparency with filtered shadows. Effects the scene does not call for (see
//! `Features`) are skipped before any ray is spawned for them.

pub mod march;
mod pixels;

pub use pixels::render_spans;

use crate::geometry::{Counters, Hit, Surface};
use crate::math::{gamma, reflect, refract, Vec3A};
use crate::ray::{spawn, spawn_to, Ray};
use crate::sampler::{mix, pixel_sample};
use crate::scene::{Ao, Light, Material, Scene};
use luxon_formats::TransparencyMode;
use luxon_plugin::abi::TexQuery;

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
        Whitted { scene, draws }
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
        let width = if depth == 0 {
            self.scene.primary_width
        } else {
            0.0
        };
        self.trace(ray, depth, weight, media, width, c)
    }

    /// Texture `t` at a surface point; a panicking plugin raises the scene's fault.
    fn texture(&self, t: u32, q: &TexQuery) -> [f32; 4] {
        let tex = &self.scene.textures[t as usize];
        tex.eval(q).unwrap_or_else(|status| {
            self.scene.customs.fault.raise(tex.failure(status));
            [0.0; 4]
        })
    }

    /// `width` is the width of the ray's footprint at its origin: rays are traced as thin cones
    /// (a pixel wide at the camera, widening by the pixel angle per unit of distance) so textures
    /// know how much of them a pixel covers and can filter (MIP mapping).
    fn trace(
        &self,
        ray: &Ray,
        depth: u32,
        weight: f32,
        media: &IorStack,
        width: f32,
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        let hit = scene.intersect(ray, f32::INFINITY, c);
        if !scene.features.volumes {
            return match hit {
                Some(hit) => self.shade(ray, &hit, depth, weight, media, width, c),
                None => scene.background,
            };
        }
        // Volumes in front of the first surface (or the background), composited over it.
        let t_hit = hit.map_or(f32::INFINITY, |h| h.t);
        let cutoff = scene.settings.min_weight / weight.max(f32::MIN_POSITIVE);
        let (color, through) = march::march(scene, ray, t_hit, cutoff, c);
        if through < cutoff {
            // Early ray termination: what lies behind cannot show.
            return color;
        }
        let behind = match hit {
            Some(hit) => self.shade(ray, &hit, depth, weight * through, media, width, c),
            None => scene.background,
        };
        color + through * behind
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
        width: f32,
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        let hit = *hit;
        let s = scene.surface(&hit, ray);
        let mat = &scene.materials[s.material as usize];
        let features = scene.features;
        let footprint = width + scene.pixel_spread * hit.t;
        let side = Side::of(&s, ray);
        let (base, kr, kt) = self.material_at(&s, mat, side.n, footprint, ray.time);
        let transparency = scene.settings.transparency;
        let kt = self.transparency(kt, ray, side.n, media);
        let post = transparency.mode == TransparencyMode::PostMultiplied;

        let opacity = 1.0 - kt;
        // Post-multiplied: shade as if opaque, then scale everything by the opacity.
        let shade_opacity = if post { 1.0 } else { opacity };
        let mut color = mat.ambient * shade_opacity * base;
        color += self.lighting(ray, &s, &side, mat, base, shade_opacity, c);
        if post {
            color *= opacity;
        }
        let filter = if post { Vec3A::ONE } else { base };
        if depth == 0 {
            self.fog(&mut color, ray, hit.t);
        }

        let next = depth + 1;
        if features.reflection && kr > 0.0 {
            let bounce = Bounce {
                depth: next,
                weight: weight * kr,
                footprint,
            };
            self.reflection(&mut color, ray, &s, &side, kr, &bounce, media, c);
        }
        if features.transmission && kt > 0.0 {
            let bounce = Bounce {
                depth: next,
                weight: weight * kt,
                footprint,
            };
            let filter = kt * filter;
            self.transmission(&mut color, ray, &s, &side, mat, filter, &bounce, media, c);
        }
        color
    }

    /// The material's colour and reflect and transmit coefficients at a surface point, with
    /// its textures (looked up along shading normal `n`) and vertex colour applied.
    #[inline]
    fn material_at(
        &self,
        s: &Surface,
        mat: &Material,
        n: Vec3A,
        footprint: f32,
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
                footprint,
                uv_footprint: footprint * s.uv_scale,
                time,
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

    /// The transmit coefficient after the scene's transparency rules: none past the most
    /// transparent surfaces a path may cross, thicker at grazing angles when angle-modulated.
    #[inline]
    fn transparency(&self, kt: f32, ray: &Ray, n: Vec3A, media: &IorStack) -> f32 {
        let transparency = self.scene.settings.transparency;
        let mut kt = kt;
        if kt > 0.0 {
            if transparency
                .max_surfaces
                .is_some_and(|n| media.surfaces >= n)
            {
                kt = 0.0;
            } else if transparency.mode == TransparencyMode::AngleModulated {
                // A slab seen at angle θ is 1/|cos θ| thick: edge-on surfaces look opaque.
                let cos = ray.dir.dot(n).abs().max(1e-3);
                kt = kt.powf(1.0 / cos);
            }
        }
        kt
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
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        // Random numbers for area lights and occlusion, from the ray itself: deterministic for
        // any thread count or decomposition, different for every path.
        let seed = if self.draws { ray_seed(ray) } else { 0 };
        // Light and occlusion rays leave smooth meshes from the curved surface, not the facet.
        let (light_p, light_error) = if side.entering && s.lift != Vec3A::ZERO {
            let q = s.p + s.lift;
            (q, s.p_error + gamma(4) * (s.lift.abs() + q.abs()))
        } else {
            (s.p, s.p_error)
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
        };
        let mut lit = Vec3A::ZERO;
        for (k, light) in scene.lights.iter().enumerate() {
            lit += self.direct(&shade, mat, light, mix(seed ^ k as u32), c);
        }
        if let (true, Some(ao)) = (scene.features.ambient_occlusion, &scene.ao) {
            lit *= ao.direct;
            lit += mat.diffuse * opacity * base * ao.sky * self.unoccluded(&shade, ao, seed, c);
        }
        lit
    }

    /// Fog over the distance `t` a camera ray travelled to its hit.
    #[inline]
    fn fog(&self, color: &mut Vec3A, ray: &Ray, t: f32) {
        let scene = self.scene;
        if let (true, Some(fog)) = (scene.features.fog, &scene.fog) {
            let d = if fog.planar {
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
            *color += kr * self.scene.background;
        } else if bounce.weight >= settings.min_weight {
            c.reflection += 1;
            let r = spawn(s.p, s.p_error, side.ng, reflect(ray.dir, side.n), ray.time);
            *color += kr * self.trace(&r, bounce.depth, bounce.weight, media, bounce.footprint, c);
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
            *color += filter * self.scene.background;
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
            *color += filter * self.trace(&r, depth, weight, stack, bounce.footprint, c);
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
/// pixel), and the width of its footprint at its origin.
struct Bounce {
    depth: u32,
    weight: f32,
    footprint: f32,
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
    /// shadow rays let through. Area lights average `samples` points on the light.
    fn direct(
        &self,
        sh: &Shade,
        mat: &Material,
        light: &Light,
        seed: u32,
        c: &mut Counters,
    ) -> Vec3A {
        let scene = self.scene;
        let shadows = light.casts_shadows() && scene.features.shadows;
        // (point on the light or None for a direction, direction to it, radiance arriving)
        let one =
            |target: Option<Vec3A>, to_light: Vec3A, arriving: Vec3A, c: &mut Counters| -> Vec3A {
                let ndotl = sh.n.dot(to_light);
                if ndotl <= 0.0 || arriving == Vec3A::ZERO {
                    return Vec3A::ZERO;
                }
                let mut arriving = arriving;
                if shadows {
                    c.shadow += 1;
                    let (sray, t_max) = match target {
                        Some(t) => spawn_to(sh.p, sh.p_error, sh.ng, t, sh.time),
                        None => (
                            spawn(sh.p, sh.p_error, sh.ng, to_light, sh.time),
                            f32::INFINITY,
                        ),
                    };
                    arriving *= scene.transmittance(&sray, t_max, scene.settings.min_weight, c);
                    if scene.features.volumes && arriving != Vec3A::ZERO {
                        arriving *= march::transmittance(scene, &sray, t_max, c);
                    }
                    if arriving == Vec3A::ZERO {
                        return Vec3A::ZERO;
                    }
                }
                let mut lit = mat.diffuse * sh.opacity * ndotl * sh.base;
                if mat.specular > 0.0 {
                    let cos = if mat.blinn {
                        sh.n.dot((to_light + sh.view).normalize())
                    } else {
                        reflect(-to_light, sh.n).dot(sh.view)
                    };
                    if cos > 0.0 {
                        lit += Vec3A::splat(mat.specular * cos.powf(mat.shininess));
                    }
                }
                arriving * lit
            };
        let from_point = |q: Vec3A, color: Vec3A, a: &[f32; 3], c: &mut Counters| {
            let d = q - sh.p;
            let dist = d.length();
            one(Some(q), d / dist, color * Light::attenuate(a, dist), c)
        };
        match light {
            Light::Directional {
                to_light, color, ..
            } => one(None, *to_light, *color, c),
            Light::Point {
                position,
                color,
                attenuation,
                ..
            } => from_point(*position, *color, attenuation, c),
            Light::Spot {
                position,
                axis,
                cos_inner,
                cos_outer,
                color,
                attenuation,
                ..
            } => {
                let cos = (sh.p - *position).normalize().dot(*axis);
                if cos <= *cos_outer {
                    return Vec3A::ZERO;
                }
                let w = Light::spot_weight(cos, *cos_inner, *cos_outer);
                from_point(*position, *color * w, attenuation, c)
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
                let mut sum = Vec3A::ZERO;
                for i in 0..*samples {
                    let (a, b) = square(seed, i, *samples);
                    let (r, phi) = (a.sqrt() * radius, b * std::f32::consts::TAU);
                    let q = *center + r * (phi.cos() * u + phi.sin() * v);
                    sum += from_point(q, *color, attenuation, c);
                }
                sum / *samples as f32
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
                let mut sum = Vec3A::ZERO;
                for i in 0..*samples {
                    let (a, b) = square(seed, i, *samples);
                    sum += from_point(*corner + a * *edge1 + b * *edge2, *color, attenuation, c);
                }
                sum / *samples as f32
            }
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
