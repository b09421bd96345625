//! # luxon-textures: procedural texture plugins for Luxon
//!
//! Solid (3D, world-space) textures evaluated at each shading point. Colours are linear RGB,
//! non-negative (values above 1 are allowed); every texture returns alpha 1.
//!
//! | texture    | what |
//! |------------|------|
//! | `constant` | one colour everywhere |
//! | `checker`  | a 3D checkerboard of cubes |
//! | `gradient` | a clamped linear blend between two colours along an axis |
//!
//! ## Parameters
//!
//! `constant`
//!
//! | name    | type        | default  | meaning |
//! |---------|-------------|----------|---------|
//! | `color` | `(r, g, b)` | required | the colour |
//!
//! `checker`
//!
//! | name     | type        | default     | meaning |
//! |----------|-------------|-------------|---------|
//! | `scale`  | f64 > 0     | `1.0`       | edge length of a cell, world units |
//! | `even`   | `(r, g, b)` | `(1, 1, 1)` | colour of cells whose indices sum to an even number (e.g. the cell at the origin) |
//! | `odd`    | `(r, g, b)` | `(0, 0, 0)` | colour of the other cells |
//! | `offset` | `(x, y, z)` | `(0, 0, 0)` | a cell corner; the grid is shifted so that it starts here |
//!
//! The cell of a point `p` has indices `floor((p - offset) / scale)` per axis, so cells are
//! half-open, `[k, k + 1)` in cell units: a point exactly on a boundary belongs to the cell on
//! its positive side, for negative coordinates as for positive ones (no mirroring at zero, and
//! `-0.0` is the same as `0.0`). Points within 1e-4 cell units of a boundary are snapped onto it
//! first, so that rounding noise in hit points on a surface lying on a boundary (the floor
//! `y = 0` with the default grid) cannot make the pattern speckle between two cells.
//!
//! `gradient`
//!
//! | name    | type        | default     | meaning |
//! |---------|-------------|-------------|---------|
//! | `from`  | `(r, g, b)` | `(0, 0, 0)` | colour at `start` and before it |
//! | `to`    | `(r, g, b)` | `(1, 1, 1)` | colour at `end` and after it |
//! | `axis`  | `(x, y, z)` | `(0, 1, 0)` | direction of the blend, normalised (must not be zero) |
//! | `start` | f64         | `0.0`       | where the blend starts: distance along `axis` from the world origin |
//! | `end`   | f64         | `1.0`       | where it ends (must differ from `start`; may be smaller) |
//!
//! The colour at `p` is `from + (to - from) * clamp((dot(p, axis) - start) / (end - start), 0, 1)`,
//! blended in linear RGB.
//!
//! ## Scene
//!
//! ```ron
//! textures: {
//!     "checks": (plugin: "checker", params: (scale: 0.5)),
//!     "sky": (plugin: "gradient", params: (from: (1, 1, 1), to: (0.2, 0.4, 0.9), start: 0, end: 10)),
//! },
//! materials: {
//!     "floor": (texture: "checks", diffuse: 0.8),
//! },
//! ```

use luxon_plugin::abi::TexQuery;
use luxon_plugin::{finite, invalid, Context, Describe, Error, Texture};
use serde::Deserialize;

/// A colour parameter: finite and non-negative.
fn color(name: &str, c: [f64; 3]) -> Result<[f32; 4], Error> {
    let c = finite(name, c)?;
    if c.iter().any(|&x| x < 0.0) {
        return Err(invalid(format!(
            "parameter `{name}` must not be negative, got {c:?}"
        )));
    }
    Ok([c[0] as f32, c[1] as f32, c[2] as f32, 1.0])
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
}

impl Describe for Constant {
    const NAME: &'static str = "constant";
    const DESCRIPTION: &'static str = "One colour everywhere.";
    const PARAMS: &'static str = "color: (r, g, b) = required  linear RGB, non-negative";
}

impl Texture for Constant {
    type Params = ConstantParams;

    fn create(p: ConstantParams, _ctx: &Context) -> Result<Self, Error> {
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
    scale: f64,
    offset: [f64; 3],
    even: [f32; 4],
    odd: [f32; 4],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckerParams {
    #[serde(default = "one")]
    scale: f64,
    #[serde(default = "white")]
    even: [f64; 3],
    #[serde(default)]
    odd: [f64; 3],
    #[serde(default)]
    offset: [f64; 3],
}

fn one() -> f64 {
    1.0
}

fn white() -> [f64; 3] {
    [1.0; 3]
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
    const DESCRIPTION: &'static str = "A 3D checkerboard of cubes in world space.";
    const PARAMS: &'static str = "\
scale: f64 = 1.0  edge length of a cell (> 0), world units
even: (r, g, b) = (1, 1, 1)  colour of cells whose indices sum to an even number
odd: (r, g, b) = (0, 0, 0)  colour of the other cells
offset: (x, y, z) = (0, 0, 0)  a cell corner: the grid starts here";
}

impl Texture for Checker {
    type Params = CheckerParams;

    fn create(p: CheckerParams, _ctx: &Context) -> Result<Self, Error> {
        let [scale] = finite("scale", [p.scale])?;
        if scale <= 0.0 {
            return Err(invalid(format!(
                "parameter `scale` must be greater than 0, got {scale}"
            )));
        }
        Ok(Checker {
            scale,
            offset: finite("offset", p.offset)?,
            even: color("even", p.even)?,
            odd: color("odd", p.odd)?,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let sum = (0..3).fold(0i64, |acc, i| {
            acc.wrapping_add(cell((q.p[i] - self.offset[i]) / self.scale))
        });
        if sum & 1 == 0 {
            self.even
        } else {
            self.odd
        }
    }
}

// ------------------------------------------------------------------------------------------------
// gradient
// ------------------------------------------------------------------------------------------------

pub struct Gradient {
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
}

fn up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

impl Describe for Gradient {
    const NAME: &'static str = "gradient";
    const DESCRIPTION: &'static str =
        "A linear blend between two colours along an axis, clamped outside [start, end].";
    const PARAMS: &'static str = "\
from: (r, g, b) = (0, 0, 0)  colour at `start` and before it
to: (r, g, b) = (1, 1, 1)  colour at `end` and after it
axis: (x, y, z) = (0, 1, 0)  direction of the blend (normalised; must not be zero)
start: f64 = 0.0  where the blend starts, distance along `axis` from the origin
end: f64 = 1.0  where it ends (must differ from `start`)";
}

impl Texture for Gradient {
    type Params = GradientParams;

    fn create(p: GradientParams, _ctx: &Context) -> Result<Self, Error> {
        let axis = finite("axis", p.axis)?;
        let len = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
        if len == 0.0 || !len.is_finite() {
            return Err(invalid(format!(
                "parameter `axis` must be a non-zero finite direction, got {axis:?}"
            )));
        }
        let [start] = finite("start", [p.start])?;
        let [end] = finite("end", [p.end])?;
        let inv_length = 1.0 / (end - start);
        if start == end || !inv_length.is_finite() {
            return Err(invalid(format!(
                "parameters `start` and `end` must differ, got {start} and {end}"
            )));
        }
        Ok(Gradient {
            from: color("from", p.from)?,
            to: color("to", p.to)?,
            axis: axis.map(|a| a / len),
            start,
            inv_length,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let d: f64 = (0..3).map(|i| q.p[i] * self.axis[i]).sum();
        let t = ((d - self.start) * self.inv_length).clamp(0.0, 1.0);
        // NaN points (never expected) get `from` rather than a NaN colour.
        let t = if t.is_nan() { 0.0 } else { t as f32 };
        std::array::from_fn(|i| self.from[i] + (self.to[i] - self.from[i]) * t)
    }
}

luxon_plugin::export!(library: "luxon-textures", textures: [Constant, Checker, Gradient]);

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_plugin::parse_params;

    fn ctx() -> Context {
        Context {
            scene_dir: ".".into(),
            instance: "test".into(),
            ..Default::default()
        }
    }

    fn make<T: Texture>(params: &str) -> Result<T, Error> {
        T::create(parse_params(params)?, &ctx())
    }

    fn at<T: Texture>(t: &T, p: [f64; 3]) -> [f32; 4] {
        t.eval(&TexQuery {
            p,
            ..Default::default()
        })
    }

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

    #[test]
    fn params_tables_have_one_entry_per_line() {
        for params in [Constant::PARAMS, Checker::PARAMS, Gradient::PARAMS] {
            for line in params.lines() {
                assert!(line.contains(": ") && line.contains(" = "), "{line}");
            }
        }
    }
}
