//! Solid (3-D, world-space) procedural textures: constant, checker, gradient, marble, wood and
//! noise. Every one is placed by a [`Transform`] (`scale`, `rotate`, `translate`) applied to the
//! lookup point; colours are linear RGB with alpha 1.

use crate::image::MAGENTA;
use crate::noise::{Fractal, Perlin};
use crate::params::{color, direction, non_negative, octaves, one, positive, up, white, Factors};
use crate::transform::Transform;
use crate::tree::{Input, InputSpec};
use luxon_plugin::abi::TexQuery;
use luxon_plugin::{finite, invalid, Context, Describe, Error, Texture};
use serde::Deserialize;
use std::f64::consts::TAU;

/// The placement parameter lines shared by every procedural texture's table.
macro_rules! placement_doc {
    () => {
        "scale: f64 or (x, y, z) = 1.0  size of the pattern, world units per pattern unit (> 0)
rotate: (x, y, z) = (0, 0, 0)  degrees about x, then y, then z
translate: (x, y, z) = (0, 0, 0)  where the pattern's origin lands"
    };
}

fn lerp_color(a: [f32; 4], b: [f32; 4], t: f64) -> [f32; 4] {
    // NaN (never expected) gives `a` rather than a NaN colour.
    let t = if t.is_nan() {
        0.0
    } else {
        t.clamp(0.0, 1.0) as f32
    };
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
}

// ------------------------------------------------------------------------------------------------
// constant
// ------------------------------------------------------------------------------------------------

pub struct Constant {
    color: [f32; 4],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantParams {
    color: [f64; 3],
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default)]
    rotate: [f64; 3],
    #[serde(default)]
    translate: [f64; 3],
}

impl Describe for Constant {
    const NAME: &'static str = "constant";
    const DESCRIPTION: &'static str = "One colour everywhere.";
    const PARAMS: &'static str = concat!(
        "color: (r, g, b) = required  linear RGB, non-negative\n",
        placement_doc!(),
        " (accepted like every texture's; no visible effect)"
    );
}

impl Texture for Constant {
    type Params = ConstantParams;

    fn create(p: ConstantParams, _ctx: &Context) -> Result<Self, Error> {
        Transform::new(p.scale, p.rotate, p.translate)?;
        Ok(Constant {
            color: color("color", p.color)?,
        })
    }

    fn eval(&self, _q: &TexQuery) -> [f32; 4] {
        self.color
    }
}

// ------------------------------------------------------------------------------------------------
// checker
// ------------------------------------------------------------------------------------------------

pub struct Checker {
    place: Transform,
    even: Input,
    odd: Input,
}

fn white_input() -> InputSpec {
    InputSpec::color(white())
}

fn black_input() -> InputSpec {
    InputSpec::color([0.0; 3])
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckerParams {
    #[serde(default = "white_input")]
    even: InputSpec,
    #[serde(default = "black_input")]
    odd: InputSpec,
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default)]
    rotate: [f64; 3],
    translate: Option<[f64; 3]>,
    /// The name older scenes use for `translate`.
    offset: Option<[f64; 3]>,
}

/// Distance from a boundary, in cell units, within which a coordinate counts as on it.
const SNAP: f64 = 1e-4;

/// The cell index along one axis: `floor(u)`, with `u` snapped onto a nearby integer first.
fn cell(u: f64) -> i64 {
    let r = u.round();
    let k = if (u - r).abs() <= SNAP { r } else { u.floor() };
    // `as` saturates (and maps NaN to 0), so far-away or bad points cannot panic.
    k as i64
}

impl Describe for Checker {
    const NAME: &'static str = "checker";
    const DESCRIPTION: &'static str =
        "A 3D checkerboard of cubes; each cell colour may itself be a texture (a tree node).";
    const PARAMS: &'static str = concat!(
        "even: input = (1, 1, 1)  cells whose indices sum to an even number: colour, grey level or nested texture (e.g. Marble(scale: 0.5))\n",
        "odd: input = (0, 0, 0)  the other cells\n",
        placement_doc!(),
        "; a cell corner (`offset` is accepted as another name)"
    );
}

impl Texture for Checker {
    type Params = CheckerParams;

    fn create(p: CheckerParams, ctx: &Context) -> Result<Self, Error> {
        let translate = match (p.translate, p.offset) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "give `translate` or `offset` (its older name), not both",
                ))
            }
            (Some(t), None) => t,
            (None, Some(o)) => finite("offset", o)?,
            (None, None) => [0.0; 3],
        };
        Ok(Checker {
            place: Transform::new(p.scale, p.rotate, translate)?,
            even: p.even.build("even", ctx)?,
            odd: p.odd.build("odd", ctx)?,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        self.try_eval(q).unwrap_or(MAGENTA)
    }

    /// Fails when the input of the cell fails (a nested image that does not decode).
    fn try_eval(&self, q: &TexQuery) -> Result<[f32; 4], Error> {
        let l = self.place.apply(q.p);
        let sum = l.iter().fold(0i64, |acc, &u| acc.wrapping_add(cell(u)));
        if sum & 1 == 0 {
            self.even.eval(q)
        } else {
            self.odd.eval(q)
        }
    }
}

// ------------------------------------------------------------------------------------------------
// gradient
// ------------------------------------------------------------------------------------------------

pub struct Gradient {
    place: Transform,
    from: [f32; 4],
    to: [f32; 4],
    axis: [f64; 3],
    start: f64,
    inv_length: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GradientParams {
    #[serde(default)]
    from: [f64; 3],
    #[serde(default = "white")]
    to: [f64; 3],
    #[serde(default = "up")]
    axis: [f64; 3],
    #[serde(default)]
    start: f64,
    #[serde(default = "one")]
    end: f64,
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default)]
    rotate: [f64; 3],
    #[serde(default)]
    translate: [f64; 3],
}

impl Describe for Gradient {
    const NAME: &'static str = "gradient";
    const DESCRIPTION: &'static str =
        "A linear blend between two colours along an axis, clamped outside [start, end].";
    const PARAMS: &'static str = concat!(
        "from: (r, g, b) = (0, 0, 0)  colour at `start` and before it\n",
        "to: (r, g, b) = (1, 1, 1)  colour at `end` and after it\n",
        "axis: (x, y, z) = (0, 1, 0)  direction of the blend in pattern space (normalised; must not be zero)\n",
        "start: f64 = 0.0  where the blend starts, distance along `axis` from the pattern origin\n",
        "end: f64 = 1.0  where it ends (must differ from `start`)\n",
        placement_doc!()
    );
}

impl Texture for Gradient {
    type Params = GradientParams;

    fn create(p: GradientParams, _ctx: &Context) -> Result<Self, Error> {
        let axis = direction("axis", p.axis)?;
        let [start] = finite("start", [p.start])?;
        let [end] = finite("end", [p.end])?;
        let inv_length = 1.0 / (end - start);
        if start == end || !inv_length.is_finite() {
            return Err(invalid(format!(
                "parameters `start` and `end` must differ, got {start} and {end}"
            )));
        }
        Ok(Gradient {
            place: Transform::new(p.scale, p.rotate, p.translate)?,
            from: color("from", p.from)?,
            to: color("to", p.to)?,
            axis,
            start,
            inv_length,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let l = self.place.apply(q.p);
        let d: f64 = (0..3).map(|i| l[i] * self.axis[i]).sum();
        lerp_color(self.from, self.to, (d - self.start) * self.inv_length)
    }
}

// ------------------------------------------------------------------------------------------------
// marble
// ------------------------------------------------------------------------------------------------

/// Perlin's marble: stripes across the pattern's x axis, one per unit, bent by turbulence.
pub struct Marble {
    place: Transform,
    base: [f32; 4],
    vein: [f32; 4],
    turbulence: f64,
    sharpness: f64,
    noise: Fractal,
}

fn marble_base() -> [f64; 3] {
    [0.8, 0.78, 0.74]
}

fn marble_vein() -> [f64; 3] {
    [0.1, 0.1, 0.12]
}

fn one_f() -> f64 {
    1.0
}

fn three() -> f64 {
    3.0
}

fn five_octaves() -> u32 {
    5
}

fn three_octaves() -> u32 {
    3
}

fn four_octaves() -> u32 {
    4
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarbleParams {
    #[serde(default = "marble_base")]
    base: [f64; 3],
    #[serde(default = "marble_vein")]
    vein: [f64; 3],
    #[serde(default = "one_f")]
    turbulence: f64,
    #[serde(default = "three")]
    sharpness: f64,
    #[serde(default = "five_octaves")]
    octaves: u32,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default)]
    rotate: [f64; 3],
    #[serde(default)]
    translate: [f64; 3],
}

impl Describe for Marble {
    const NAME: &'static str = "marble";
    const DESCRIPTION: &'static str =
        "Veined marble: stripes across the pattern's x axis (one per unit) bent by Perlin turbulence.";
    const PARAMS: &'static str = concat!(
        "base: (r, g, b) = (0.8, 0.78, 0.74)  the stone's colour\n",
        "vein: (r, g, b) = (0.1, 0.1, 0.12)  the veins' colour\n",
        "turbulence: f64 = 1.0  how far the veins wander, in stripe widths (>= 0; 0: straight stripes)\n",
        "sharpness: f64 = 3.0  exponent of the vein profile (> 0; larger: thinner veins)\n",
        "octaves: u32 = 5  octaves of turbulence (1 to 16)\n",
        "seed: u64 = 0  noise seed: the same seed gives the same marble everywhere, every run\n",
        placement_doc!()
    );
}

impl Texture for Marble {
    type Params = MarbleParams;

    fn create(p: MarbleParams, _ctx: &Context) -> Result<Self, Error> {
        Ok(Marble {
            place: Transform::new(p.scale, p.rotate, p.translate)?,
            base: color("base", p.base)?,
            vein: color("vein", p.vein)?,
            turbulence: non_negative("turbulence", p.turbulence)?,
            sharpness: positive("sharpness", p.sharpness)?,
            noise: Fractal {
                perlin: Perlin::new(p.seed),
                octaves: octaves("octaves", p.octaves)?,
                gain: 0.5,
                lacunarity: 2.0,
            },
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let l = self.place.apply(q.p);
        let mut phase = l[0];
        if self.turbulence > 0.0 {
            phase += self.turbulence * self.noise.turbulent(l);
        }
        // 0 at integer phases (stone), 1 half-way between (the middle of a vein).
        let v = (0.5 - 0.5 * (TAU * phase).cos())
            .max(0.0)
            .powf(self.sharpness);
        lerp_color(self.base, self.vein, v)
    }
}

// ------------------------------------------------------------------------------------------------
// wood
// ------------------------------------------------------------------------------------------------

/// Growth rings around the pattern's y axis, one per unit of radius, wobbled by noise.
pub struct Wood {
    place: Transform,
    light: [f32; 4],
    dark: [f32; 4],
    turbulence: f64,
    noise: Fractal,
}

fn wood_light() -> [f64; 3] {
    [0.73, 0.48, 0.24]
}

fn wood_dark() -> [f64; 3] {
    [0.26, 0.1, 0.025]
}

fn wood_turbulence() -> f64 {
    0.15
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WoodParams {
    #[serde(default = "wood_light")]
    light: [f64; 3],
    #[serde(default = "wood_dark")]
    dark: [f64; 3],
    #[serde(default = "wood_turbulence")]
    turbulence: f64,
    #[serde(default = "three_octaves")]
    octaves: u32,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default)]
    rotate: [f64; 3],
    #[serde(default)]
    translate: [f64; 3],
}

impl Describe for Wood {
    const NAME: &'static str = "wood";
    const DESCRIPTION: &'static str =
        "Wood grain: concentric rings around the pattern's y axis (one per unit of radius), wobbled by Perlin noise.";
    const PARAMS: &'static str = concat!(
        "light: (r, g, b) = (0.73, 0.48, 0.24)  early wood, at whole radii\n",
        "dark: (r, g, b) = (0.26, 0.1, 0.025)  late wood, half-way between rings\n",
        "turbulence: f64 = 0.15  ring wobble, in ring spacings (>= 0; 0: perfect circles)\n",
        "octaves: u32 = 3  octaves of noise (1 to 16)\n",
        "seed: u64 = 0  noise seed\n",
        placement_doc!()
    );
}

impl Texture for Wood {
    type Params = WoodParams;

    fn create(p: WoodParams, _ctx: &Context) -> Result<Self, Error> {
        Ok(Wood {
            place: Transform::new(p.scale, p.rotate, p.translate)?,
            light: color("light", p.light)?,
            dark: color("dark", p.dark)?,
            turbulence: non_negative("turbulence", p.turbulence)?,
            noise: Fractal {
                perlin: Perlin::new(p.seed),
                octaves: octaves("octaves", p.octaves)?,
                gain: 0.5,
                lacunarity: 2.0,
            },
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let l = self.place.apply(q.p);
        let mut r = l[0].hypot(l[2]);
        if self.turbulence > 0.0 {
            r += self.turbulence * self.noise.smooth(l);
        }
        lerp_color(self.light, self.dark, 0.5 - 0.5 * (TAU * r).cos())
    }
}

// ------------------------------------------------------------------------------------------------
// noise ("grit")
// ------------------------------------------------------------------------------------------------

/// Fractal Perlin noise mapped onto a blend between two colours.
pub struct Noise {
    place: Transform,
    from: [f32; 4],
    to: [f32; 4],
    turbulent: bool,
    noise: Fractal,
}

fn half() -> f64 {
    0.5
}

fn two() -> f64 {
    2.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseParams {
    #[serde(default)]
    from: [f64; 3],
    #[serde(default = "white")]
    to: [f64; 3],
    #[serde(default = "four_octaves")]
    octaves: u32,
    #[serde(default = "half")]
    gain: f64,
    #[serde(default = "two")]
    lacunarity: f64,
    #[serde(default)]
    turbulent: bool,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default)]
    rotate: [f64; 3],
    #[serde(default)]
    translate: [f64; 3],
}

impl Describe for Noise {
    const NAME: &'static str = "noise";
    const DESCRIPTION: &'static str =
        "Perlin noise (\"grit\"): fractal gradient noise blending two colours, deterministic per seed.";
    const PARAMS: &'static str = concat!(
        "from: (r, g, b) = (0, 0, 0)  colour where the noise is lowest\n",
        "to: (r, g, b) = (1, 1, 1)  colour where it is highest\n",
        "octaves: u32 = 4  octaves summed (1 to 16)\n",
        "gain: f64 = 0.5  amplitude ratio between octaves (> 0)\n",
        "lacunarity: f64 = 2.0  frequency ratio between octaves (> 0)\n",
        "turbulent: bool = false  sum absolute values (Perlin's turbulence: creases) instead of signed noise\n",
        "seed: u64 = 0  noise seed\n",
        placement_doc!()
    );
}

impl Texture for Noise {
    type Params = NoiseParams;

    fn create(p: NoiseParams, _ctx: &Context) -> Result<Self, Error> {
        Ok(Noise {
            place: Transform::new(p.scale, p.rotate, p.translate)?,
            from: color("from", p.from)?,
            to: color("to", p.to)?,
            turbulent: p.turbulent,
            noise: Fractal {
                perlin: Perlin::new(p.seed),
                octaves: octaves("octaves", p.octaves)?,
                gain: positive("gain", p.gain)?,
                lacunarity: positive("lacunarity", p.lacunarity)?,
            },
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let l = self.place.apply(q.p);
        let t = if self.turbulent {
            self.noise.turbulent(l)
        } else {
            0.5 + 0.5 * self.noise.smooth(l)
        };
        lerp_color(self.from, self.to, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{at, make};

    const WHITE: [f32; 4] = [1.0, 1.0, 1.0, 1.0];
    const BLACK: [f32; 4] = [0.0, 0.0, 0.0, 1.0];

    #[test]
    fn constant_everywhere() {
        let t: Constant = make("(color: (0.25, 0.5, 2))").unwrap();
        for p in [[0.0; 3], [1e9, -3.0, 7.5], [-0.5, 0.5, 0.0]] {
            assert_eq!(at(&t, p), [0.25, 0.5, 2.0, 1.0]);
        }
    }

    #[test]
    fn constant_requires_color() {
        let e = make::<Constant>("()").err().unwrap();
        assert!(
            e.message.contains("missing parameter `color`"),
            "{}",
            e.message
        );
    }

    #[test]
    fn checker_defaults_known_points() {
        let t: Checker = make("()").unwrap();
        assert_eq!(at(&t, [0.5, 0.5, 0.5]), WHITE);
        assert_eq!(at(&t, [1.5, 0.5, 0.5]), BLACK);
        assert_eq!(at(&t, [1.5, 1.5, 0.5]), WHITE);
        assert_eq!(at(&t, [1.5, 1.5, 1.5]), BLACK);
        assert_eq!(at(&t, [2.5, 0.5, 0.5]), WHITE);
    }

    #[test]
    fn checker_negative_coordinates_use_floor() {
        let t: Checker = make("()").unwrap();
        // (-0.5) is in cell -1, not 0: no doubled cell around zero.
        assert_eq!(at(&t, [-0.5, 0.5, 0.5]), BLACK);
        assert_eq!(at(&t, [-1.5, 0.5, 0.5]), WHITE);
        assert_eq!(at(&t, [-0.5, -0.5, 0.5]), WHITE);
        assert_eq!(at(&t, [-0.5, -0.5, -0.5]), BLACK);
        assert_eq!(at(&t, [-2.5, -7.5, 3.5]), WHITE);
        assert_eq!(at(&t, [-2.5, -6.5, 3.5]), BLACK);
    }

    #[test]
    fn checker_boundaries_belong_to_positive_side() {
        let t: Checker = make("()").unwrap();
        // Exactly on a boundary: the cell on the positive side, whatever the sign.
        assert_eq!(at(&t, [1.0, 0.5, 0.5]), BLACK);
        assert_eq!(at(&t, [-1.0, 0.5, 0.5]), BLACK);
        assert_eq!(at(&t, [0.0, 0.5, 0.5]), WHITE);
        assert_eq!(at(&t, [-0.0, 0.5, 0.5]), WHITE);
        assert_eq!(at(&t, [2.0, 0.5, 0.5]), WHITE);
        // Rounding noise on either side of a boundary snaps onto it.
        for eps in [1e-12, -1e-12, 1e-7, -1e-7, 5e-5, -5e-5] {
            assert_eq!(at(&t, [0.5, eps, 0.5]), WHITE, "y = {eps}");
            assert_eq!(at(&t, [0.5, 1.0 + eps, 0.5]), BLACK, "y = 1 + {eps}");
            assert_eq!(at(&t, [0.5, -1.0 + eps, 0.5]), BLACK, "y = -1 + {eps}");
        }
        // Further away, the real neighbour.
        assert_eq!(at(&t, [0.5, -2e-4, 0.5]), BLACK);
        assert_eq!(at(&t, [0.5, 1.0 - 2e-4, 0.5]), WHITE);
        assert_eq!(at(&t, [0.5, 0.999, 0.5]), WHITE);
        assert_eq!(at(&t, [0.5, -0.001, 0.5]), BLACK);
    }

    #[test]
    fn checker_scale_offset_and_colours() {
        let t: Checker =
            make("(scale: 0.5, even: (1, 0, 0), odd: (0, 0, 1), offset: (0.25, 0, 0))").unwrap();
        let red = [1.0, 0.0, 0.0, 1.0];
        let blue = [0.0, 0.0, 1.0, 1.0];
        assert_eq!(at(&t, [0.3, 0.1, 0.1]), red);
        assert_eq!(at(&t, [0.2, 0.1, 0.1]), blue);
        assert_eq!(at(&t, [0.75, 0.1, 0.1]), blue);
        assert_eq!(at(&t, [0.74, 0.1, 0.1]), red);
        assert_eq!(at(&t, [0.3, 0.6, 0.1]), blue);
        assert_eq!(at(&t, [0.3, -0.1, -0.1]), red);
        // Small cells: boundaries at multiples of the scale.
        let t: Checker = make("(scale: 0.1)").unwrap();
        assert_eq!(at(&t, [0.3, 0.05, 0.05]), BLACK);
        assert_eq!(at(&t, [0.29, 0.05, 0.05]), WHITE);
    }

    #[test]
    fn checker_far_away_points_do_not_panic() {
        let t: Checker = make("(scale: 1e-300)").unwrap();
        let _ = at(&t, [1e300, -1e300, f64::NAN]);
        let t: Checker = make("()").unwrap();
        let _ = at(&t, [f64::INFINITY, f64::NEG_INFINITY, 0.0]);
    }

    #[test]
    fn checker_param_errors() {
        for (params, name) in [
            ("(scale: 0)", "`scale`"),
            ("(scale: -1)", "`scale`"),
            ("(scale: inf)", "`scale`"),
            ("(scale: NaN)", "`scale`"),
            ("(even: (1, -0.1, 0))", "`even`"),
            ("(odd: (0, 0, inf))", "`odd`"),
            ("(offset: (0, NaN, 0))", "`offset`"),
        ] {
            let e = make::<Checker>(params).err().unwrap();
            assert!(e.message.contains(name), "{params}: {}", e.message);
        }
        let e = make::<Checker>("(scael: 2)").err().unwrap();
        assert!(e.message.contains("did you mean `scale`"), "{}", e.message);
    }

    #[test]
    fn gradient_blends_and_clamps() {
        let t: Gradient = make("(from: (0, 0, 0), to: (1, 2, 4), start: 1, end: 3)").unwrap();
        assert_eq!(at(&t, [0.0, 1.0, 0.0]), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(&t, [0.0, -5.0, 0.0]), [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(&t, [7.0, 2.0, -3.0]), [0.5, 1.0, 2.0, 1.0]);
        assert_eq!(at(&t, [0.0, 3.0, 0.0]), [1.0, 2.0, 4.0, 1.0]);
        assert_eq!(at(&t, [0.0, 30.0, 0.0]), [1.0, 2.0, 4.0, 1.0]);
    }

    #[test]
    fn gradient_axis_is_normalised_and_end_may_precede_start() {
        let t: Gradient = make("(axis: (3, 0, 4), start: 0, end: 10)").unwrap();
        // dot(p, (0.6, 0, 0.8)) = 5 -> halfway.
        let c = at(&t, [3.0, 100.0, 4.0]);
        assert!(c.iter().take(3).all(|&x| (x - 0.5).abs() < 1e-6), "{c:?}");
        let t: Gradient = make("(from: (1, 1, 1), to: (0, 0, 0), start: 2, end: -2)").unwrap();
        assert_eq!(at(&t, [0.0, 3.0, 0.0]), WHITE);
        assert_eq!(at(&t, [0.0, 0.0, 0.0]), [0.5, 0.5, 0.5, 1.0]);
        assert_eq!(at(&t, [0.0, -2.0, 0.0]), BLACK);
    }

    #[test]
    fn gradient_param_errors() {
        for (params, name) in [
            ("(axis: (0, 0, 0))", "`axis`"),
            ("(axis: (0, NaN, 0))", "`axis`"),
            ("(axis: (1e300, 1e300, 0))", "`axis`"),
            ("(start: 1, end: 1)", "`start` and `end`"),
            ("(start: inf)", "`start`"),
            ("(end: NaN)", "`end`"),
            ("(from: (-1, 0, 0))", "`from`"),
            ("(to: (0, inf, 0))", "`to`"),
        ] {
            let e = make::<Gradient>(params).err().unwrap();
            assert!(e.message.contains(name), "{params}: {}", e.message);
        }
    }

    #[test]
    fn constant_param_errors() {
        let e = make::<Constant>("(color: (0.5, -1, 0))").err().unwrap();
        assert!(
            e.message.contains("`color` must not be negative"),
            "{}",
            e.message
        );
        let e = make::<Constant>("(color: (NaN, 0, 0))").err().unwrap();
        assert!(
            e.message.contains("`color` must be finite"),
            "{}",
            e.message
        );
    }

    fn close(a: [f32; 4], b: [f32; 4]) -> bool {
        crate::testutil::close(a, b, 1e-6)
    }

    fn lerp(a: [f32; 4], b: [f32; 4], t: f32) -> [f32; 4] {
        std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
    }

    #[test]
    fn checker_rotated_about_z() {
        // Rotating the cells 45° about z: the point (0.9, 0.1) is in cell (0, 0) unrotated
        // (even) but at (0.707, -0.566) in pattern space: cell (0, -1, 0), odd.
        let straight: Checker = make("()").unwrap();
        let turned: Checker = make("(rotate: (0, 0, 45))").unwrap();
        assert_eq!(at(&straight, [0.9, 0.1, 0.5]), WHITE);
        assert_eq!(at(&turned, [0.9, 0.1, 0.5]), BLACK);
        // (0.1, 0.9) -> (0.707, 0.566): cell (0, 0, 0) in both.
        assert_eq!(at(&turned, [0.1, 0.9, 0.5]), WHITE);
        // (0, 1.5) -> (1.06, 1.06): cell (1, 1, 0), even; unrotated (0, 1, 0), odd.
        assert_eq!(at(&turned, [0.0, 1.5, 0.5]), WHITE);
        assert_eq!(at(&straight, [0.0, 1.5, 0.5]), BLACK);
        // A quarter turn maps cells onto cells: x-neighbours become y-neighbours.
        let quarter: Checker = make("(rotate: (0, 0, 90), scale: 0.5)").unwrap();
        assert_eq!(
            at(&quarter, [0.25, 0.25, 0.25]),
            BLACK,
            "pattern cell (0, -1, 0)"
        );
        assert_eq!(
            at(&quarter, [-0.25, 0.25, 0.25]),
            WHITE,
            "pattern cell (0, 0, 0)"
        );
    }

    #[test]
    fn checker_offset_is_translate() {
        let a: Checker = make("(offset: (0.25, 0, 0), scale: 0.5)").unwrap();
        let b: Checker = make("(translate: (0.25, 0, 0), scale: 0.5)").unwrap();
        for x in [0.2, 0.3, 0.74, 0.76, -0.3] {
            assert_eq!(at(&a, [x, 0.1, 0.1]), at(&b, [x, 0.1, 0.1]), "{x}");
        }
        assert!(make::<Checker>("(offset: (1, 0, 0), translate: (1, 0, 0))").is_err());
    }

    #[test]
    fn checker_per_axis_scale() {
        let t: Checker = make("(scale: (2, 1, 1))").unwrap();
        assert_eq!(at(&t, [1.5, 0.5, 0.5]), WHITE, "cell (0, 0, 0)");
        assert_eq!(at(&t, [2.5, 0.5, 0.5]), BLACK, "cell (1, 0, 0)");
        assert_eq!(at(&t, [1.5, 1.5, 0.5]), BLACK, "cell (0, 1, 0)");
    }

    #[test]
    fn gradient_rotated_and_translated() {
        // The default axis is +y in pattern space; a quarter turn about z points it at -x.
        let t: Gradient = make("(rotate: (0, 0, 90))").unwrap();
        assert_eq!(at(&t, [-0.5, 0.0, 0.0]), [0.5, 0.5, 0.5, 1.0]);
        assert_eq!(at(&t, [-2.0, 0.0, 0.0]), WHITE);
        assert_eq!(at(&t, [0.0, 0.7, 0.0]), BLACK);
        // Translated by 1 and scaled by 4 along the axis: 0 at y = 1, 1 at y = 5.
        let t: Gradient = make("(translate: (0, 1, 0), scale: 4)").unwrap();
        assert_eq!(at(&t, [0.0, 1.0, 0.0]), BLACK);
        assert_eq!(at(&t, [0.0, 3.0, 0.0]), [0.5, 0.5, 0.5, 1.0]);
        assert_eq!(at(&t, [0.0, 5.0, 0.0]), WHITE);
    }

    #[test]
    fn constant_accepts_placement() {
        let t: Constant = make("(color: (1, 0, 0), scale: 3, rotate: (10, 20, 30))").unwrap();
        assert_eq!(at(&t, [4.0, 5.0, 6.0]), [1.0, 0.0, 0.0, 1.0]);
        assert!(make::<Constant>("(color: (1, 0, 0), scale: 0)").is_err());
    }

    const BASE: [f32; 4] = [0.8, 0.78, 0.74, 1.0];
    const VEIN: [f32; 4] = [0.1, 0.1, 0.12, 1.0];

    fn base_vein() -> ([f32; 4], [f32; 4]) {
        (BASE.map(|x| x as f64 as f32), VEIN.map(|x| x as f64 as f32))
    }

    #[test]
    fn marble_stripes_and_period() {
        let (base, vein) = base_vein();
        let t: Marble = make("(turbulence: 0, sharpness: 1)").unwrap();
        // Stone at whole x, vein half-way, half-and-half at the quarters.
        assert!(close(at(&t, [0.0, 3.0, -2.0]), base));
        assert!(close(at(&t, [0.5, 0.0, 0.0]), vein));
        assert!(close(at(&t, [0.25, 0.0, 0.0]), lerp(base, vein, 0.5)));
        // Period 1 along x (times `scale`), constant along y and z.
        for x in [0.1, 0.37, 0.8, -1.3] {
            let c = at(&t, [x, 0.0, 0.0]);
            assert!(close(c, at(&t, [x + 1.0, 5.0, 0.0])), "{x}");
            assert!(close(c, at(&t, [x - 3.0, 0.0, 9.0])), "{x}");
        }
        let t: Marble = make("(turbulence: 0, sharpness: 1, scale: 2)").unwrap();
        assert!(close(at(&t, [1.0, 0.0, 0.0]), vein));
        assert!(close(at(&t, [0.3, 0.0, 0.0]), at(&t, [2.3, 0.0, 0.0])));
    }

    #[test]
    fn marble_turbulence_bends_veins_deterministically() {
        let (base, vein) = base_vein();
        let a: Marble = make("(seed: 3)").unwrap();
        let b: Marble = make("(seed: 3)").unwrap();
        let c: Marble = make("(seed: 4)").unwrap();
        let straight: Marble = make("(turbulence: 0)").unwrap();
        let (mut differs_from_straight, mut differs_by_seed) = (0, 0);
        for i in 0..200 {
            let p = [
                i as f64 * 0.137,
                (i % 7) as f64 * 0.31,
                (i % 5) as f64 * 0.77,
            ];
            let v = at(&a, p);
            assert_eq!(v, at(&b, p));
            // Always between the two colours.
            for k in 0..3 {
                let (lo, hi) = (base[k].min(vein[k]), base[k].max(vein[k]));
                assert!((lo - 1e-6..=hi + 1e-6).contains(&v[k]), "{v:?}");
            }
            differs_from_straight += usize::from(!close(v, at(&straight, p)));
            differs_by_seed += usize::from(!close(v, at(&c, p)));
        }
        assert!(differs_from_straight > 150, "{differs_from_straight}");
        assert!(differs_by_seed > 150, "{differs_by_seed}");
    }

    #[test]
    fn wood_rings_and_period() {
        let light = [0.73f64, 0.48, 0.24].map(|x| x as f32);
        let dark = [0.26f64, 0.1, 0.025].map(|x| x as f32);
        let (light, dark) = (
            [light[0], light[1], light[2], 1.0],
            [dark[0], dark[1], dark[2], 1.0],
        );
        let t: Wood = make("(turbulence: 0)").unwrap();
        // Light on the axis and at whole radii, dark half-way; the same all around the y axis.
        assert!(close(at(&t, [0.0, 7.0, 0.0]), light));
        assert!(close(at(&t, [0.5, 0.0, 0.0]), dark));
        assert!(close(at(&t, [0.0, -3.0, 0.5]), dark));
        assert!(close(at(&t, [0.6, 2.0, 0.8]), light), "radius 1");
        assert!(close(at(&t, [0.25, 0.0, 0.0]), lerp(light, dark, 0.5)));
        for r in [0.1, 0.33, 0.71] {
            let c = at(&t, [r, 0.0, 0.0]);
            assert!(close(c, at(&t, [r + 1.0, 1.0, 0.0])), "{r}");
            assert!(close(c, at(&t, [0.0, -4.0, r + 2.0])), "{r}");
            let s = (r + 3.0) / 2f64.sqrt();
            assert!(close(c, at(&t, [s, 0.0, s])), "{r}");
        }
        // Rotated 90° about x the trunk runs along z: rings around the z axis.
        let t: Wood = make("(turbulence: 0, rotate: (90, 0, 0), scale: 0.5)").unwrap();
        assert!(close(at(&t, [0.0, 0.0, 5.0]), light));
        assert!(close(at(&t, [0.0, 0.25, 5.0]), dark));
        assert!(close(at(&t, [0.25, 0.0, -2.0]), dark));
        // Default turbulence wobbles the rings, deterministically.
        let a: Wood = make("()").unwrap();
        let b: Wood = make("()").unwrap();
        assert_eq!(at(&a, [0.3, 0.4, 0.5]), at(&b, [0.3, 0.4, 0.5]));
        let straight: Wood = make("(turbulence: 0)").unwrap();
        assert_ne!(at(&a, [0.3, 0.4, 0.5]), at(&straight, [0.3, 0.4, 0.5]));
    }

    #[test]
    fn noise_range_determinism_and_seed() {
        let t: Noise = make("(from: (0, 0, 1), to: (1, 0, 0), seed: 9)").unwrap();
        let u: Noise = make("(from: (0, 0, 1), to: (1, 0, 0), seed: 9)").unwrap();
        let other: Noise = make("(from: (0, 0, 1), to: (1, 0, 0), seed: 10)").unwrap();
        let turb: Noise = make("(turbulent: true, octaves: 6)").unwrap();
        let (mut lo, mut hi, mut differ) = (1.0f32, 0.0f32, 0);
        for i in 0..2000 {
            let p = [
                (i as f64 * 0.618).fract() * 10.0 - 5.0,
                (i as f64 * 0.414).fract() * 10.0 - 5.0,
                (i as f64 * 0.732).fract() * 10.0 - 5.0,
            ];
            let c = at(&t, p);
            assert_eq!(c, at(&u, p), "same seed, same value");
            // Always a blend of the two colours: r + b = 1, g = 0.
            assert!((c[0] + c[2] - 1.0).abs() < 1e-6 && c[1] == 0.0, "{c:?}");
            assert!((0.0..=1.0).contains(&c[0]));
            lo = lo.min(c[0]);
            hi = hi.max(c[0]);
            differ += usize::from(c != at(&other, p));
            let g = at(&turb, p)[0];
            assert!((0.0..=1.0).contains(&g), "{g}");
        }
        assert!(lo < 0.35 && hi > 0.65, "spread {lo}..{hi}");
        assert!(differ > 1900, "{differ}");
        // With one octave, lattice points are exactly 0 noise: the middle colour.
        let one: Noise = make("(octaves: 1)").unwrap();
        assert_eq!(at(&one, [3.0, -2.0, 7.0]), [0.5, 0.5, 0.5, 1.0]);
        // `scale` stretches it: lattice points every 2 units.
        let big: Noise = make("(octaves: 1, scale: 2)").unwrap();
        assert_eq!(at(&big, [4.0, -2.0, 6.0]), [0.5, 0.5, 0.5, 1.0]);
        assert_ne!(at(&big, [1.0, 1.0, 1.0]), [0.5, 0.5, 0.5, 1.0]);
    }

    #[test]
    fn noise_based_param_errors() {
        for (params, name) in [
            ("(octaves: 0)", "`octaves`"),
            ("(octaves: 17)", "`octaves`"),
            ("(gain: 0)", "`gain`"),
            ("(lacunarity: -2)", "`lacunarity`"),
            ("(from: (-1, 0, 0))", "`from`"),
            ("(scale: (1, 1, 0))", "`scale`"),
            ("(rotate: (NaN, 0, 0))", "`rotate`"),
        ] {
            let e = make::<Noise>(params).err().unwrap();
            assert!(e.message.contains(name), "{params}: {}", e.message);
        }
        assert!(make::<Marble>("(turbulence: -1)").is_err());
        assert!(make::<Marble>("(sharpness: 0)").is_err());
        assert!(make::<Wood>("(octaves: 40)").is_err());
        let e = make::<Wood>("(rings: 3)").err().unwrap();
        assert!(
            e.message.contains("unknown parameter `rings`"),
            "{}",
            e.message
        );
    }

    #[test]
    fn params_tables_have_one_entry_per_line() {
        for params in [
            Constant::PARAMS,
            Checker::PARAMS,
            Gradient::PARAMS,
            Marble::PARAMS,
            Wood::PARAMS,
            Noise::PARAMS,
            crate::tree::Blend::PARAMS,
            crate::image::ImageTexture::PARAMS,
            crate::tachyon::TachyonMarble::PARAMS,
            crate::tachyon::TachyonWood::PARAMS,
            crate::tachyon::TachyonCylinderChecker::PARAMS,
            crate::tachyon::TachyonVolumeImage::PARAMS,
        ] {
            for line in params.lines() {
                assert!(line.contains(": ") && line.contains(" = "), "{line}");
            }
        }
    }
}
