//! Texture trees: inputs of `checker` and `blend` that are colours or other textures of this
//! plugin written inline, and the `blend` entry.
//!
//! An input is written as a grey level (`0.5`), a colour (`(r, g, b)`) or a texture named by
//! its variant with that texture's own parameters: `Marble(scale: 0.5)`,
//! `Image(file: "wood.png", mapping: planar)`, `Checker(even: Wood(), odd: (0, 0, 0))`...
//! Nested textures are evaluated at the same shading point as their parent, each with its own
//! `scale`/`rotate`/`translate` (a parent's placement does not move its inputs).

use crate::image::{ImageParams, ImageTexture, MAGENTA};
use crate::params::explain;
use crate::procedural::{
    Checker, CheckerParams, Constant, ConstantParams, Gradient, GradientParams, Marble,
    MarbleParams, Noise, NoiseParams, Wood, WoodParams,
};
use luxon_plugin::abi::TexQuery;
use luxon_plugin::{Context, Describe, Error, Texture};
use serde::de::value::{MapAccessDeserializer, MapDeserializer};
use serde::de::{Deserializer, Error as _, MapAccess, Visitor};
use serde::Deserialize;

/// Anything that can be evaluated at a shading point (every texture of this plugin); an
/// image that does not decode fails, and so does every tree holding it.
pub trait Eval: Send + Sync {
    fn eval_at(&self, q: &TexQuery) -> Result<[f32; 4], Error>;
}

impl<T: Texture> Eval for T {
    fn eval_at(&self, q: &TexQuery) -> Result<[f32; 4], Error> {
        self.try_eval(q)
    }
}

/// A nested texture: the variant names the texture, its fields are that texture's parameters.
#[derive(Deserialize)]
pub enum Spec {
    Constant(Args<ConstantParams>),
    Checker(Args<CheckerParams>),
    Blend(Args<BlendParams>),
    Gradient(Args<GradientParams>),
    Marble(Args<MarbleParams>),
    Wood(Args<WoodParams>),
    Noise(Args<NoiseParams>),
    Image(Args<ImageParams>),
}

/// A nested texture's parameters: `(name: value, ...)`, or `()` for every default (which RON
/// hands over as a unit value rather than an empty struct).
pub struct Args<T>(T);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Args<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<T> {
            type Value = Args<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the texture's parameters in parentheses, `(name: value, ...)`")
            }
            fn visit_unit<E: serde::de::Error>(self) -> Result<Args<T>, E> {
                let none = std::iter::empty::<((), ())>();
                T::deserialize(MapDeserializer::new(none)).map(Args)
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Args<T>, A::Error> {
                T::deserialize(MapAccessDeserializer::new(map)).map(Args)
            }
        }
        d.deserialize_any(V(std::marker::PhantomData))
    }
}

/// The variant names of [`Spec`], for messages.
const SPEC_NAMES: &str = "Constant, Checker, Blend, Gradient, Marble, Wood, Noise, Image";

impl Spec {
    fn build(self, ctx: &Context) -> Result<Box<dyn Eval>, Error> {
        fn make<T: Texture>(p: Args<T::Params>, ctx: &Context) -> Result<Box<dyn Eval>, Error> {
            Ok(Box::new(T::create(p.0, ctx)?))
        }
        match self {
            Spec::Constant(p) => make::<Constant>(p, ctx),
            Spec::Checker(p) => make::<Checker>(p, ctx),
            Spec::Blend(p) => make::<Blend>(p, ctx),
            Spec::Gradient(p) => make::<Gradient>(p, ctx),
            Spec::Marble(p) => make::<Marble>(p, ctx),
            Spec::Wood(p) => make::<Wood>(p, ctx),
            Spec::Noise(p) => make::<Noise>(p, ctx),
            Spec::Image(p) => make::<ImageTexture>(p, ctx),
        }
    }
}

/// An input as written in the params: a grey level, a colour, or a nested texture.
pub enum InputSpec {
    Color([f64; 3]),
    Texture(Box<Spec>),
}

/// A nested spec, or the reason it is not one (kept so that the real error reaches the user
/// instead of serde's "data did not match any variant").
struct Attempt(Result<Box<Spec>, String>);

impl<'de> Deserialize<'de> for Attempt {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(Attempt(Spec::deserialize(d).map(Box::new).map_err(|e| {
            let m = e.to_string();
            // Not an enum-shaped value at all (a number, a tuple of the wrong length...).
            if m.contains("string or map") || m.starts_with("invalid type") {
                format!(
                    "expected a grey level, a colour `(r, g, b)` or a texture such as \
                     `Marble(scale: 0.5)` (one of: {SPEC_NAMES})"
                )
            } else {
                explain(&m)
            }
        })))
    }
}

impl<'de> Deserialize<'de> for InputSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        // Untagged: RON hands serde's buffer the variant name of `Marble(...)`, so the nested
        // spec is tried after the plain forms. `Attempt` always succeeds and carries its error.
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Helper {
            Grey(f64),
            Color([f64; 3]),
            Texture(Attempt),
        }
        match Helper::deserialize(d)? {
            Helper::Grey(g) => Ok(InputSpec::Color([g; 3])),
            Helper::Color(c) => Ok(InputSpec::Color(c)),
            Helper::Texture(Attempt(Ok(s))) => Ok(InputSpec::Texture(s)),
            Helper::Texture(Attempt(Err(m))) => Err(D::Error::custom(m)),
        }
    }
}

impl InputSpec {
    pub fn color(c: [f64; 3]) -> InputSpec {
        InputSpec::Color(c)
    }

    /// The evaluable input; errors name the parameter (`even: odd: ...` for deeper trees).
    pub fn build(self, name: &str, ctx: &Context) -> Result<Input, Error> {
        match self {
            InputSpec::Color(c) => Ok(Input::Color(crate::params::color(name, c)?)),
            InputSpec::Texture(spec) => spec
                .build(ctx)
                .map(Input::Texture)
                .map_err(|e| Error::new(format!("`{name}`: {}", e.message))),
        }
    }
}

/// An evaluable input.
pub enum Input {
    Color([f32; 4]),
    Texture(Box<dyn Eval>),
}

impl Input {
    pub fn eval(&self, q: &TexQuery) -> Result<[f32; 4], Error> {
        match self {
            Input::Color(c) => Ok(*c),
            Input::Texture(t) => t.eval_at(q),
        }
    }
}

// ------------------------------------------------------------------------------------------------
// blend
// ------------------------------------------------------------------------------------------------

/// `a` and `b` mixed per channel by `mix` (0: all `a`, 1: all `b`).
pub struct Blend {
    a: Input,
    b: Input,
    mix: Input,
}

fn black_input() -> InputSpec {
    InputSpec::color([0.0; 3])
}

fn white_input() -> InputSpec {
    InputSpec::color([1.0; 3])
}

fn half_input() -> InputSpec {
    InputSpec::color([0.5; 3])
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendParams {
    #[serde(default = "black_input")]
    a: InputSpec,
    #[serde(default = "white_input")]
    b: InputSpec,
    #[serde(default = "half_input")]
    mix: InputSpec,
}

impl Describe for Blend {
    const NAME: &'static str = "blend";
    const DESCRIPTION: &'static str =
        "Two textures or colours mixed per channel by a third (a texture tree node).";
    const PARAMS: &'static str = "\
a: input = (0, 0, 0)  colour, grey level or nested texture (e.g. Marble(scale: 0.5)) where mix is 0
b: input = (1, 1, 1)  the same, where mix is 1
mix: input = 0.5  weight of `b` per channel, clamped to [0, 1]; a number, colour or texture";
}

impl Texture for Blend {
    type Params = BlendParams;

    fn create(p: BlendParams, ctx: &Context) -> Result<Self, Error> {
        Ok(Blend {
            a: p.a.build("a", ctx)?,
            b: p.b.build("b", ctx)?,
            mix: p.mix.build("mix", ctx)?,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        self.try_eval(q).unwrap_or(MAGENTA)
    }

    fn try_eval(&self, q: &TexQuery) -> Result<[f32; 4], Error> {
        let a = self.a.eval(q)?;
        let b = self.b.eval(q)?;
        let m = self
            .mix
            .eval(q)?
            .map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) });
        // Alpha is mixed by the mean of the colour weights.
        let ma = (m[0] + m[1] + m[2]) / 3.0;
        let w = [m[0], m[1], m[2], ma];
        Ok(std::array::from_fn(|i| a[i] + (b[i] - a[i]) * w[i]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{at, close, ctx_in, make, make_in, write_png, TempDir};

    const WHITE: [f32; 4] = [1.0; 4];

    #[test]
    fn checker_of_marble_and_constant() {
        let tree: Checker = make(
            "(even: Marble(scale: 0.5, turbulence: 0, sharpness: 1), \
              odd: Constant(color: (0, 0, 1)))",
        )
        .unwrap();
        let marble: Marble = make("(scale: 0.5, turbulence: 0, sharpness: 1)").unwrap();
        // Even cells show the marble, evaluated at the same world point.
        for p in [
            [0.1, 0.2, 0.3],
            [0.25, 0.5, 0.5],
            [1.7, 1.1, 0.9],
            [-0.5, -0.5, 0.2],
        ] {
            assert_eq!(at(&tree, p), at(&marble, p), "{p:?}");
        }
        // Odd cells the constant.
        assert_eq!(at(&tree, [1.5, 0.5, 0.5]), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(at(&tree, [0.5, 0.5, -0.5]), [0.0, 0.0, 1.0, 1.0]);
        // Known marble values inside even cells: vein at x = 0.25 (half a stripe of 0.5).
        let vein = [0.1f32, 0.1, 0.12, 1.0];
        assert!(close(at(&tree, [0.25, 0.5, 0.5]), vein, 1e-6));
    }

    #[test]
    fn inputs_take_grey_levels_colours_and_deep_trees() {
        let t: Checker = make(
            "(even: 0.25, odd: Checker(scale: 0.5, even: (1, 0, 0), \
              odd: Blend(a: (0, 1, 0), b: Gradient(), mix: 0.5)))",
        )
        .unwrap();
        assert_eq!(at(&t, [0.5, 0.5, 0.5]), [0.25, 0.25, 0.25, 1.0]);
        // Odd outer cell (1, 0, 0); inner cell (2, 1, 1) is even: red.
        assert_eq!(at(&t, [1.25, 0.75, 0.75]), [1.0, 0.0, 0.0, 1.0]);
        // Inner cell (3, 1, 1) odd: the blend of green and the gradient at y = 0.75.
        let c = at(&t, [1.75, 0.75, 0.75]);
        assert!(close(c, [0.375, 0.875, 0.375, 1.0], 1e-6), "{c:?}");
    }

    #[test]
    fn blend_mixes_per_channel() {
        let t: Blend = make("(a: (1, 0, 0), b: (0, 0, 1), mix: (0, 0.5, 1))").unwrap();
        assert_eq!(at(&t, [0.0; 3]), [1.0, 0.0, 1.0, 1.0]);
        let t: Blend = make("()").unwrap();
        assert_eq!(at(&t, [3.0; 3]), [0.5, 0.5, 0.5, 1.0]);
        // A texture as the weight: a gradient from a to b along y; out-of-range weights clamp.
        let t: Blend =
            make("(a: Constant(color: (2, 2, 2)), b: 0, mix: Gradient(to: (4, 4, 4), end: 4))")
                .unwrap();
        assert_eq!(at(&t, [0.0, 0.0, 0.0]), [2.0, 2.0, 2.0, 1.0]);
        assert_eq!(at(&t, [0.0, 0.5, 0.0]), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(at(&t, [0.0, 3.0, 0.0]), [0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn image_inside_a_tree() {
        let dir = TempDir::new("tree-image");
        write_png(&dir.path("red.png"), 2, 2, |_, _| [255, 0, 0, 255]);
        let t: Checker = make_in(
            r#"(even: Image(file: "red.png", mapping: planar, filter: nearest), odd: 1)"#,
            &ctx_in(dir.dir()),
        )
        .unwrap();
        assert_eq!(at(&t, [0.5, 0.5, 0.5]), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(&t, [1.5, 0.5, 0.5]), WHITE);
        // Errors from the nested image name the input and the resolved file.
        let e = make_in::<Checker>(r#"(odd: Image(file: "gone.png"))"#, &ctx_in(dir.dir()))
            .err()
            .unwrap();
        assert!(e.message.starts_with("`odd`: "), "{}", e.message);
        assert!(
            e.message
                .contains(&dir.path("gone.png").display().to_string()),
            "{}",
            e.message
        );
    }
    /// A nested image that turns out not to decode fails its tree's lookups with its reason,
    /// in the cells that use it, at any depth.
    #[test]
    fn a_broken_nested_image_fails_the_tree_with_its_reason() {
        let dir = TempDir::new("tree-broken-image");
        write_png(&dir.path("red.png"), 16, 16, |x, y| {
            [(x * 16) as u8, y as u8, 0, 255]
        });
        let t: Blend = make_in(
            r#"(a: Checker(even: Image(file: "red.png", mapping: planar), odd: 1), b: 0, mix: 0)"#,
            &ctx_in(dir.dir()),
        )
        .unwrap();
        // Header intact, data gone.
        let bytes = std::fs::read(dir.path("red.png")).unwrap();
        std::fs::write(dir.path("red.png"), &bytes[..40]).unwrap();
        let q = |p| TexQuery {
            p,
            ..Default::default()
        };
        let e = t.try_eval(&q([0.5, 0.5, 0.5])).unwrap_err().message;
        assert!(
            e.starts_with("cannot decode image `") && e.contains("red.png"),
            "{e}"
        );
        // An odd cell does not touch the image.
        assert_eq!(t.try_eval(&q([1.5, 0.5, 0.5])).unwrap(), WHITE);
        assert_eq!(t.eval(&q([0.5, 0.5, 0.5])), MAGENTA);
    }

    #[test]
    fn nested_errors_are_clear() {
        let e = make::<Checker>("(even: Marble(scael: 2))").err().unwrap();
        assert!(
            e.message
                .contains("unknown parameter `scael`, did you mean `scale`?"),
            "{}",
            e.message
        );
        let e = make::<Checker>("(even: Marbel(scale: 2))").err().unwrap();
        assert!(
            e.message.contains("`Marbel`") && e.message.contains("Marble"),
            "{}",
            e.message
        );
        let e = make::<Checker>("(even: (1, 2))").err().unwrap();
        assert!(e.message.contains("a colour `(r, g, b)`"), "{}", e.message);
        let e = make::<Checker>("(even: Constant())").err().unwrap();
        assert!(
            e.message.contains("missing parameter `color`"),
            "{}",
            e.message
        );
        let e = make::<Blend>("(mix: Noise(octaves: 0))").err().unwrap();
        assert_eq!(
            e.message,
            "`mix`: parameter `octaves` must be between 1 and 16, got 0"
        );
        let e = make::<Checker>("(odd: Checker(even: Wood(turbulence: -1)))")
            .err()
            .unwrap();
        assert!(
            e.message
                .starts_with("`odd`: `even`: parameter `turbulence`"),
            "{}",
            e.message
        );
        let e = make::<Checker>("(even: -0.5)").err().unwrap();
        assert!(
            e.message.contains("`even` must not be negative"),
            "{}",
            e.message
        );
    }

    #[test]
    fn all_defaults_nested() {
        // `Marble()` with every parameter at its default.
        let t: Checker = make("(even: Marble(), odd: Wood())").unwrap();
        let m: Marble = make("()").unwrap();
        assert_eq!(at(&t, [0.3, 0.3, 0.3]), at(&m, [0.3, 0.3, 0.3]));
    }
}
