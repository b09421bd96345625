//! Test plugin: a texture that answers NaN, so the host can check that a NaN never aborts a
//! render: it is counted, reported by `--stats` and its pixel clamped.
//!
//! - `nan_texture` (texture): NaN where the hit point has `x < 0`, else `color`.
//! - `nan_box` (primitive): custom geometry in [-1, 1]³ whose every hit is at a NaN distance.
//!
//! | name    | type        | default   | meaning |
//! |---------|-------------|-----------|---------|
//! | `color` | `(r, g, b)` | `(1, 1, 1)` | the colour where `x >= 0` |
//!
//! ```ron
//! textures: { "half": (plugin: "nan_texture", params: (color: (1, 0, 0))) },
//! ```

#![forbid(unsafe_code)]

use luxon_plugin::abi::TexQuery;
use luxon_plugin::{
    finite, Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Primitive, Ray, Texture,
};

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NanParams {
    #[serde(default = "white")]
    color: [f64; 3],
}

fn white() -> [f64; 3] {
    [1.0; 3]
}

pub struct NanTexture {
    color: [f32; 3],
}

impl Describe for NanTexture {
    const NAME: &'static str = "nan_texture";
    const DESCRIPTION: &'static str = "Test plugin: NaN where x < 0, else a colour.";
    const PARAMS: &'static str = "color: (r, g, b) = (1, 1, 1)  the colour where x >= 0";
}

impl Texture for NanTexture {
    type Params = NanParams;
    fn create(p: NanParams, _: &Context) -> Result<Self, Error> {
        let c = finite("color", p.color)?;
        Ok(NanTexture {
            color: c.map(|v| v as f32),
        })
    }
    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        if q.p[0] < 0.0 {
            [f32::NAN; 4]
        } else {
            let [r, g, b] = self.color;
            [r, g, b, 1.0]
        }
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

pub struct NanBox;

impl Describe for NanBox {
    const NAME: &'static str = "nan_box";
    const DESCRIPTION: &'static str = "Test plugin: custom geometry whose hits are at NaN.";
    const PARAMS: &'static str = "";
}

impl Primitive for NanBox {
    type Params = NoParams;
    fn create(_: NoParams, _: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(NanShape)
    }
}

pub struct NanShape;

impl CustomShape for NanShape {
    fn count(&self) -> u64 {
        1
    }
    fn bounds(&self, _: u64) -> Aabb {
        Aabb {
            min: [-1.0; 3],
            max: [1.0; 3],
        }
    }
    fn intersect(&self, _: u64, _: &Ray) -> Option<Hit> {
        Some(Hit {
            t: f64::NAN,
            normal: [0.0, 0.0, -1.0],
            uv: [0.0; 2],
        })
    }
    fn occluded(&self, _: u64, _: &Ray) -> bool {
        false
    }
}

luxon_plugin::export!(
    library: "luxon-test-nan",
    primitives: [NanBox],
    textures: [NanTexture]
);
