//! Test plugin: entry points that panic or fail, so the host can check that each becomes an
//! error naming the plugin instead of unwinding into it, aborting or going unnoticed.
//!
//! - `panic_create` (primitive): panics in `create`.
//! - `panic_intersect` (primitive): custom geometry filling the box [-1, 1]³ whose `intersect`
//!   and `occluded` panic (`bounds` works, so the host gets as far as tracing rays).
//! - `panic_texture` (texture): created fine, panics in `eval`.
//! - `fail_texture` (texture): created fine, `try_eval` fails with a message where the hit
//!   point has `x < 0` (plugin ABI 2's error sink for `eval`); elsewhere it is grey.
//! - `panic_writer` (writer, `.panicimg`): writes a 1x1 image (the check before a render),
//!   panics for anything larger.

#![forbid(unsafe_code)]

use luxon_plugin::abi::TexQuery;
use luxon_plugin::{
    Aabb, Context, CustomShape, Describe, Error, Geometry, Hit, Image, Primitive, Ray, Texture,
    Writer,
};

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

pub struct PanicCreate;

impl Describe for PanicCreate {
    const NAME: &'static str = "panic_create";
    const DESCRIPTION: &'static str = "Test plugin: panics in create.";
    const PARAMS: &'static str = "";
}

impl Primitive for PanicCreate {
    type Params = NoParams;
    fn create(_: NoParams, _: &Context, _: &mut Geometry) -> Result<(), Error> {
        panic!("deliberate panic in create")
    }
}

pub struct PanicIntersect;

impl Describe for PanicIntersect {
    const NAME: &'static str = "panic_intersect";
    const DESCRIPTION: &'static str =
        "Test plugin: custom geometry in [-1, 1]^3 that panics in intersect and occluded.";
    const PARAMS: &'static str = "";
}

impl Primitive for PanicIntersect {
    type Params = NoParams;
    fn create(_: NoParams, _: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.custom(PanicBox)
    }
}

pub struct PanicBox;

impl CustomShape for PanicBox {
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
        panic!("deliberate panic in intersect")
    }
    fn occluded(&self, _: u64, _: &Ray) -> bool {
        panic!("deliberate panic in occluded")
    }
}

pub struct PanicTexture;

impl Describe for PanicTexture {
    const NAME: &'static str = "panic_texture";
    const DESCRIPTION: &'static str = "Test plugin: a texture that panics in eval.";
    const PARAMS: &'static str = "";
}

impl Texture for PanicTexture {
    type Params = NoParams;
    fn create(_: NoParams, _: &Context) -> Result<Self, Error> {
        Ok(PanicTexture)
    }
    fn eval(&self, _: &TexQuery) -> [f32; 4] {
        panic!("deliberate panic in texture eval")
    }
}

pub struct FailTexture;

impl Describe for FailTexture {
    const NAME: &'static str = "fail_texture";
    const DESCRIPTION: &'static str = "Test plugin: a texture with no value where x < 0.";
    const PARAMS: &'static str = "";
}

impl Texture for FailTexture {
    type Params = NoParams;
    fn create(_: NoParams, _: &Context) -> Result<Self, Error> {
        Ok(FailTexture)
    }
    fn eval(&self, _: &TexQuery) -> [f32; 4] {
        [0.5, 0.5, 0.5, 1.0]
    }
    fn try_eval(&self, q: &TexQuery) -> Result<[f32; 4], Error> {
        if q.p[0] < 0.0 {
            return Err(Error::new("deliberate failure: no value where x < 0"));
        }
        Ok(self.eval(q))
    }
}

pub struct PanicWriter;

impl Describe for PanicWriter {
    const NAME: &'static str = "panic_writer";
    const DESCRIPTION: &'static str = "Test plugin: a writer that panics for images over 1x1.";
    const PARAMS: &'static str = "";
}

impl Writer for PanicWriter {
    const EXTENSIONS: &'static str = "panicimg";
    type Params = NoParams;
    fn write(
        _: NoParams,
        _: &Context,
        image: &Image,
        out: &mut dyn std::io::Write,
    ) -> Result<(), Error> {
        if image.width * image.height > 1 {
            panic!(
                "deliberate panic writing a {}x{} image",
                image.width, image.height
            );
        }
        Ok(out.write_all(b"1x1")?)
    }
}

luxon_plugin::export!(
    library: "luxon-test-panics",
    primitives: [PanicCreate, PanicIntersect],
    textures: [PanicTexture, FailTexture],
    writers: [PanicWriter],
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_params_parse() {
        assert!(luxon_plugin::parse_params::<NoParams>("()").is_ok());
        assert!(luxon_plugin::parse_params::<NoParams>("").is_ok());
    }
}
