//! Whitted ray tracing with the thesis's shading model: ambient, Lambert diffuse, Phong or Blinn
//! highlights, mirror reflection, refraction with an index-of-refraction stack and total internal
//! reflection, transparency with filtered shadows. Effects the scene does not call for (see
//! `Features`) are skipped before any ray is spawned for them.

use crate::geometry::Counters;
use crate::math::{reflect, refract, Vec3A};
use crate::ray::{spawn, spawn_to, Ray};
use crate::scene::{Light, Scene};
use luxon_plugin::abi::TexQuery;

/// Media the ray is inside, innermost last: (material, index of refraction).
#[derive(Clone, Copy, Debug)]
pub struct IorStack {
    items: [(u32, f32); 8],
    len: usize,
}

impl Default for IorStack {
    fn default() -> Self {
        IorStack {
            items: [(0, 1.0); 8],
            len: 0,
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
        self.trace(ray, depth, weight, media, 0.0, c)
    }

    /// Texture `t` at a surface point; a panicking plugin raises the scene's fault.
    fn texture(&self, t: u32, q: &TexQuery) -> [f32; 4] {
        let tex = &self.scene.textures[t as usize];
        tex.eval(q).unwrap_or_else(|| {
            let message = format!("plugin `{}` panicked evaluating a texture", tex.plugin);
            self.scene.customs.fault.raise(message);
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
        let Some(hit) = scene.intersect(ray, f32::INFINITY, c) else {
            return scene.background;
        };
        let s = scene.surface(&hit, ray);
        let mat = &scene.materials[s.material as usize];
        let features = scene.features;
        let settings = &scene.settings;
        let footprint = width + scene.pixel_spread * hit.t;

        // Orient normals toward the viewer; remember which side was hit for media changes.
        let entering = s.ng.dot(ray.dir) < 0.0;
        let ng = if entering { s.ng } else { -s.ng };
        let mut n = if s.ns.dot(ng) < 0.0 { -s.ns } else { s.ns };
        if n.dot(ray.dir) > 0.0 {
            // Interpolated normals can face away at silhouettes; fall back to the true one.
            n = ng;
        }

        let mut base = mat.color;
        let (mut kr, mut kt) = (mat.reflect, mat.transmit);
        if features.textures {
            let q = TexQuery {
                p: (s.p.as_dvec3() + scene.world_offset).into(),
                n: n.into(),
                uv: s.uv,
                footprint,
                uv_footprint: footprint * s.uv_scale,
                time: ray.time,
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

        let opacity = 1.0 - kt;
        let view = -ray.dir;
        let mut color = mat.ambient * opacity * base;
        for light in &scene.lights {
            let (to_light, light_color, shadows) = match light {
                Light::Point {
                    position,
                    color,
                    shadows,
                } => ((*position - s.p).normalize(), *color, *shadows),
                Light::Directional {
                    to_light,
                    color,
                    shadows,
                } => (*to_light, *color, *shadows),
            };
            let ndotl = n.dot(to_light);
            if ndotl <= 0.0 {
                continue;
            }
            let mut arriving = light_color;
            if shadows && features.shadows {
                c.shadow += 1;
                let (sray, t_max) = match light {
                    Light::Point { position, .. } => {
                        spawn_to(s.p, s.p_error, ng, *position, ray.time)
                    }
                    Light::Directional { .. } => {
                        (spawn(s.p, s.p_error, ng, to_light, ray.time), f32::INFINITY)
                    }
                };
                arriving *= scene.transmittance(&sray, t_max, settings.min_weight, c);
                if arriving == Vec3A::ZERO {
                    continue;
                }
            }
            let mut lit = mat.diffuse * opacity * ndotl * base;
            if mat.specular > 0.0 {
                let cos = if mat.blinn {
                    n.dot((to_light + view).normalize())
                } else {
                    reflect(-to_light, n).dot(view)
                };
                if cos > 0.0 {
                    lit += Vec3A::splat(mat.specular * cos.powf(mat.shininess));
                }
            }
            color += arriving * lit;
        }

        let next = depth + 1;
        if features.reflection && kr > 0.0 {
            let w = weight * kr;
            if next > settings.max_depth {
                color += kr * scene.background;
            } else if w >= settings.min_weight {
                c.reflection += 1;
                let r = spawn(s.p, s.p_error, ng, reflect(ray.dir, n), ray.time);
                color += kr * self.trace(&r, next, w, media, footprint, c);
            }
        }

        if features.transmission && kt > 0.0 {
            let w = weight * kt;
            if next > settings.max_depth {
                color += kt * base * scene.background;
            } else if w >= settings.min_weight {
                // Which media are on each side of the surface.
                let mut inside = *media;
                let (n1, n2) = if entering {
                    let n1 = media.current();
                    inside.push(s.material, mat.ior);
                    (n1, mat.ior)
                } else {
                    inside.remove(s.material);
                    (mat.ior, inside.current())
                };
                let (dir, through) = match refract(ray.dir, n, n1 / n2) {
                    Some(t) => (t, true),
                    // Total internal reflection: the light stays on this side.
                    None => (reflect(ray.dir, n), false),
                };
                c.refraction += 1;
                let r = spawn(s.p, s.p_error, ng, dir, ray.time);
                let stack = if through { &inside } else { media };
                color += kt * base * self.trace(&r, next, w, stack, footprint, c);
            }
        }
        color
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
