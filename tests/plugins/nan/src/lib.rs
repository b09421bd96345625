//! Test plugin: a texture that answers NaN, so the host can check that a NaN never aborts a
//! render: it is counted, reported by `--stats` and its pixel clamped.
//!
//! - `nan_texture` (texture): NaN where the hit point has `x < 0`, else `color`.
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
use luxon_plugin::{finite, Context, Describe, Error, Texture};

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

luxon_plugin::export!(library: "luxon-test-nan", textures: [NanTexture]);
