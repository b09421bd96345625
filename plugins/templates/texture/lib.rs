//! # {{package}}: the `{{name}}` texture
//!
//! A checker in texture coordinates: squares of two colours along `u` and `v`. Change `eval`
//! (and the parameters) into your own texture.
//!
//! ## `{{name}}`
//! ```text
//! even: (r, g, b) = (0.9, 0.9, 0.9)  colour of the even squares, linear RGB
//! odd: (r, g, b) = (0.1, 0.3, 0.8)  colour of the odd squares, linear RGB
//! squares: f64 = 8  squares along u and along v, > 0
//! ```
//!
//! ```text
//! textures: { "checks": (plugin: "{{name}}", params: (squares: 8)) },
//! materials: { "checked": (texture: "checks") },
//! ```

#![forbid(unsafe_code)]

use luxon_plugin::{export, finite, invalid, Context, Describe, Error, TexQuery, Texture};
use serde::Deserialize;

/// The scene's `params: (...)`. Fields left out take the defaults below; an unknown field is
/// an error that suggests the closest name.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct {{Name}}Params {
    pub even: [f64; 3],
    pub odd: [f64; 3],
    pub squares: f64,
}

impl Default for {{Name}}Params {
    fn default() -> Self {
        Self {
            even: [0.9, 0.9, 0.9],
            odd: [0.1, 0.3, 0.8],
            squares: 8.0,
        }
    }
}

/// One texture of a scene, made once by `create` and then evaluated from every render thread.
pub struct {{Name}}Texture {
    even: [f32; 4],
    odd: [f32; 4],
    squares: f32,
}

impl Describe for {{Name}}Texture {
    const NAME: &'static str = "{{name}}";
    const DESCRIPTION: &'static str = "A checker in texture coordinates (uv).";
    const PARAMS: &'static str = "\
even: (r, g, b) = (0.9, 0.9, 0.9)  colour of the even squares, linear RGB
odd: (r, g, b) = (0.1, 0.3, 0.8)  colour of the odd squares, linear RGB
squares: f64 = 8  squares along u and along v, > 0";
}

/// An opaque linear RGBA colour.
fn rgba(c: [f64; 3]) -> [f32; 4] {
    [c[0] as f32, c[1] as f32, c[2] as f32, 1.0]
}

impl Texture for {{Name}}Texture {
    type Params = {{Name}}Params;

    /// Checks the parameters once: an error here stops the scene from loading, with the
    /// message and the scene's line and column.
    fn create(p: Self::Params, _ctx: &Context) -> Result<Self, Error> {
        let even = finite("even", p.even)?;
        let odd = finite("odd", p.odd)?;
        if !(p.squares > 0.0 && p.squares.is_finite()) {
            // "parameter `squares`..." first: Luxon reports it at `squares:` in the scene.
            let message = format!("parameter `squares`: expected > 0, found {}", p.squares);
            return Err(invalid(message));
        }
        Ok(Self {
            even: rgba(even),
            odd: rgba(odd),
            squares: p.squares as f32,
        })
    }

    /// The colour at one shading point: `q.uv` are the surface's texture coordinates (`q.p`
    /// the world point, `q.footprint` how wide a pixel is there, for filtering).
    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let i = (q.uv[0] * self.squares).floor() as i64;
        let j = (q.uv[1] * self.squares).floor() as i64;
        if (i + j).rem_euclid(2) == 0 {
            self.even
        } else {
            self.odd
        }
    }
}

export!(library: "{{package}}", textures: [{{Name}}Texture]);
