//! # {{package}}: the `{{name}}` primitive
//!
//! A ball intersected by the plugin itself (custom geometry, called from inside Luxon's BVH).
//! Change `bounds` and `intersect` into your own shape. A shape made of spheres, planes,
//! cones, discs or triangles is better handed over as such (`out.spheres`, `out.mesh`...):
//! Luxon intersects those itself, faster.
//!
//! ## `{{name}}`
//! ```text
//! center: (x, y, z) = (0, 0, 0)  centre
//! radius: f64 = 1  radius, > 0
//! ```
//!
//! Texture coordinates: `u` is the longitude around the y axis, `v` the latitude from the top,
//! both from 0 to 1.
//!
//! ```text
//! objects: [(plugin: "{{name}}", params: (center: (0, 1, 0), radius: 1), material: "red")],
//! ```

#![forbid(unsafe_code)]

use luxon_plugin::{export, finite, invalid, Context, Describe, Error, Geometry, Primitive};
use luxon_plugin::{Aabb, CustomShape, Hit, Ray};
use serde::Deserialize;

/// The scene's `params: (...)`. Fields left out take the defaults below; an unknown field is
/// an error that suggests the closest name.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct {{Name}}Params {
    pub center: [f64; 3],
    pub radius: f64,
}

impl Default for {{Name}}Params {
    fn default() -> Self {
        Self {
            center: [0.0; 3],
            radius: 1.0,
        }
    }
}

/// The plugin entry: scenes name it, `create` turns its parameters into geometry.
pub struct {{Name}}Primitive;

/// The geometry handed to Luxon, which calls it from every render thread.
pub struct {{Name}}Surface {
    center: [f64; 3],
    radius: f64,
}

impl Describe for {{Name}}Primitive {
    const NAME: &'static str = "{{name}}";
    const DESCRIPTION: &'static str = "A ball, intersected as custom geometry.";
    const PARAMS: &'static str = "\
center: (x, y, z) = (0, 0, 0)  centre
radius: f64 = 1  radius, > 0";
}

impl Primitive for {{Name}}Primitive {
    type Params = {{Name}}Params;

    /// Checks the parameters once: an error here stops the scene from loading, with the
    /// message and the scene's line and column.
    fn create(p: Self::Params, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        let center = finite("center", p.center)?;
        if !(p.radius > 0.0 && p.radius.is_finite()) {
            // "parameter `radius`..." first: Luxon reports it at `radius:` in the scene.
            let message = format!("parameter `radius`: expected > 0, found {}", p.radius);
            return Err(invalid(message));
        }
        out.custom({{Name}}Surface {
            center,
            radius: p.radius,
        })
    }
}

impl CustomShape for {{Name}}Surface {
    /// One primitive; a particle system would return one per particle and tell them apart by
    /// the `index` of the calls below.
    fn count(&self) -> u64 {
        1
    }

    /// A world-space box around primitive `index`: the tighter, the fewer `intersect` calls.
    fn bounds(&self, _index: u64) -> Aabb {
        Aabb {
            min: self.center.map(|c| c - self.radius),
            max: self.center.map(|c| c + self.radius),
        }
    }

    /// The nearest hit with `ray.tmin < t < ray.tmax`. The ray is in world space and its
    /// direction need not be unit length (`t` counts in its units); the normal may have any
    /// length and either orientation.
    fn intersect(&self, _index: u64, ray: &Ray) -> Option<Hit> {
        let oc: [f64; 3] = std::array::from_fn(|k| ray.origin[k] - self.center[k]);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let d = ray.direction;
        // |oc + t d|² = r²: a t² + 2 h t + c = 0.
        let a = dot(d, d);
        let h = dot(oc, d);
        let c = dot(oc, oc) - self.radius * self.radius;
        let disc = h * h - a * c;
        if a == 0.0 || disc.is_nan() || disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        let t = [(-h - root) / a, (-h + root) / a]
            .into_iter()
            .find(|&t| t > ray.tmin && t < ray.tmax)?;
        let normal: [f64; 3] = std::array::from_fn(|k| (oc[k] + t * d[k]) / self.radius);
        let u = 0.5 + normal[2].atan2(normal[0]) / std::f64::consts::TAU;
        let v = normal[1].clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
        Some(Hit {
            t,
            normal,
            uv: [u as f32, v as f32],
        })
    }
}

export!(library: "{{package}}", primitives: [{{Name}}Primitive]);
