//! # luxon-stripes: stripes, the example texture plugin
//!
//! Stripes of two colours across the world, averaged over each shading point's footprint so
//! that stripes finer than a pixel fade to their mean colour instead of breaking into moiré.
//! It shows what a texture plugin gets from Luxon ([`TexQuery`]) and how to filter with the
//! footprint. This crate is an example inside Luxon's workspace; to start a texture of your
//! own, `luxon new-plugin NAME --kind texture` writes a crate that builds anywhere. The SDK's
//! documentation (`plugins/README.md`, "Writing a texture") walks through the parts.
//!
//! ## Build and use
//! ```text
//! cargo build --release -p luxon-stripes          # -> target/release/libluxon_stripes.so
//! target/release/luxon render examples/stripes/scene.ron -o stripes.png
//! ```
//! `luxon` finds the libraries beside its executable; for a plugin elsewhere, set
//! `LUXON_PLUGIN_PATH` to its directory or name it in the scene's `plugin_path`.
//! `scene.ron` lays two striped floors side by side: on the left unfiltered (`filter: false`),
//! where the distant stripes alias; on the right filtered, fading to grey.
//!
//! ## `stripes`
//! ```text
//! a: (r, g, b) = (0.9, 0.9, 0.85)  colour of the even stripes, linear RGB
//! b: (r, g, b) = (0.1, 0.15, 0.45)  colour of the odd stripes, linear RGB
//! width: f64 = 0.25  width of one stripe in world units, > 0
//! axis: (x, y, z) = (1, 0, 0)  direction across the stripes, any non-zero length
//! filter: bool = true  average over the footprint (false: the colour at the point)
//! ```
//! Stripe `k` covers the points whose distance along `axis` from the origin lies in
//! `[k * width, (k + 1) * width)`; even `k` are `a`, odd ones `b`. Alpha is 1.
//!
//! ```text
//! textures: { "zebra": (plugin: "stripes", params: (width: 0.1, axis: (1, 1, 0))) },
//! ```
//!
//! ## The filter
//! A pixel sees not a point but a patch about `footprint` wide (in world units, see
//! [`TexQuery::footprint`]). The stripes are a square wave `s(x)` (0 on even stripes, 1 on odd
//! ones) of `x`, the distance along the axis in stripe widths; the colour the pixel should
//! show is `a` mixed with `b` by a weighted mean of `s` around `x`. A box of the footprint's
//! width `f` (in stripe widths) is the obvious weight, and exact through the integral `S` of
//! `s`: `(S(x + f/2) - S(x - f/2)) / f`; but a box lets a ripple of the stripes through, which
//! the pixels then sample into faint moiré. A tent twice as wide (the weight falling from the
//! point to 0 a footprint away on either side) damps that ripple far better, and is as exact
//! and cheap through the second integral `S₂`: `(S₂(x + f) - 2 S₂(x) + S₂(x - f)) / f²`, with
//! `S₂` a quadratic on each stripe. A pattern without such integrals can average a few samples
//! spread over the footprint, or fade to its mean colour once the footprint is much wider than
//! its detail.

#![forbid(unsafe_code)]

use luxon_plugin::{export, finite, invalid_at, Context, Describe, Error, TexQuery, Texture};
use serde::Deserialize;

/// The scene's `params: (...)`; fields left out take the defaults.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StripesParams {
    pub a: [f64; 3],
    pub b: [f64; 3],
    pub width: f64,
    pub axis: [f64; 3],
    pub filter: bool,
}

impl Default for StripesParams {
    fn default() -> Self {
        StripesParams {
            a: [0.9, 0.9, 0.85],
            b: [0.1, 0.15, 0.45],
            width: 0.25,
            axis: [1.0, 0.0, 0.0],
            filter: true,
        }
    }
}

/// One `stripes` texture of a scene.
pub struct Stripes {
    a: [f32; 3],
    b: [f32; 3],
    /// The axis divided by its length and by the stripe width: `x = p · across` counts stripes.
    across: [f64; 3],
    /// One world unit in stripe widths (footprints are in world units).
    per_unit: f64,
    filter: bool,
}

impl Describe for Stripes {
    const NAME: &'static str = "stripes";
    const DESCRIPTION: &'static str =
        "Stripes of two colours, filtered over the footprint; the example texture plugin.";
    const PARAMS: &'static str = "\
a: (r, g, b) = (0.9, 0.9, 0.85)  colour of the even stripes, linear RGB
b: (r, g, b) = (0.1, 0.15, 0.45)  colour of the odd stripes, linear RGB
width: f64 = 0.25  width of one stripe in world units, > 0
axis: (x, y, z) = (1, 0, 0)  direction across the stripes, any non-zero length
filter: bool = true  average over the footprint (false: the colour at the point)";
}

impl Texture for Stripes {
    type Params = StripesParams;

    fn create(p: StripesParams, _ctx: &Context) -> Result<Stripes, Error> {
        let [a, b] = [finite("a", p.a)?, finite("b", p.b)?].map(|c| c.map(|v| v as f32));
        let axis = finite("axis", p.axis)?;
        let length = axis.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(length > 0.0 && length.is_finite()) {
            // Reported at `axis:` in the scene (see `Error::invalid_at`).
            let message = format!("expected a non-zero direction, found {axis:?}");
            return Err(invalid_at("axis", message));
        }
        if !(p.width > 0.0 && p.width.is_finite()) {
            let found = p.width;
            return Err(invalid_at("width", format!("expected > 0, found {found}")));
        }
        Ok(Stripes {
            a,
            b,
            across: axis.map(|v| v / (length * p.width)),
            per_unit: 1.0 / p.width,
            filter: p.filter,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let x = (0..3).map(|k| q.p[k] * self.across[k]).sum::<f64>();
        let f = if self.filter {
            q.footprint as f64 * self.per_unit
        } else {
            0.0
        };
        let t = odd_share(x, f) as f32;
        let mix = |k: usize| self.a[k] + t * (self.b[k] - self.a[k]);
        [mix(0), mix(1), mix(2), 1.0]
    }
}

/// The mean of the square wave (0 on even stripes, 1 on odd ones) around `x` weighted by a
/// tent of half-width `f` (both in stripe widths); the value at `x` when `f` is too small to
/// matter.
pub fn odd_share(x: f64, f: f64) -> f64 {
    // The pattern repeats every two stripes: within [0, 2) the sums below stay small, so
    // their difference keeps its precision far from the origin.
    let x = x.rem_euclid(2.0);
    if f.is_nan() || f < 1e-5 {
        return if x >= 1.0 { 1.0 } else { 0.0 };
    }
    let second_difference = odd_integral2(x + f) - 2.0 * odd_integral2(x) + odd_integral2(x - f);
    (second_difference / (f * f)).clamp(0.0, 1.0)
}

/// `S₂(x) = ∫₀ˣ S`, where `S(t) = ∫₀ᵗ s` counts one per full period of two stripes plus the
/// part of the current odd stripe: on period `k` (`x = 2k + r`, `0 <= r < 2`) the full periods
/// before add `k² - k/2`, the current one `k r + max(0, r - 1)² / 2`.
fn odd_integral2(x: f64) -> f64 {
    let k = (0.5 * x).floor();
    let r = x - 2.0 * k;
    k * k - 0.5 * k + k * r + 0.5 * (r - 1.0).max(0.0).powi(2)
}

export!(library: "luxon-stripes", textures: [Stripes]);

#[cfg(test)]
mod tests {
    use super::*;

    fn stripes(params: &str) -> Stripes {
        let p = luxon_plugin::parse_params(params).unwrap_or_else(|e| panic!("{}", e.message));
        Stripes::create(p, &Context::default()).unwrap_or_else(|e| panic!("{}", e.message))
    }

    fn at(s: &Stripes, x: f64, footprint: f32) -> [f32; 4] {
        s.eval(&TexQuery {
            p: [x, 0.3, -2.0],
            footprint,
            ..TexQuery::default()
        })
    }

    #[test]
    fn a_point_has_its_stripes_colour() {
        let s = stripes("(a: (1, 0, 0), b: (0, 0, 1), width: 0.5)");
        assert_eq!(at(&s, 0.25, 0.0), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(at(&s, 0.75, 0.0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(at(&s, -0.25, 0.0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(at(&s, 1.25, 0.0), [1.0, 0.0, 0.0, 1.0]);
        // A footprint well inside one stripe changes nothing.
        assert_eq!(at(&s, 0.25, 0.1), [1.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn the_filter_is_the_tent_weighted_mean() {
        let square = |t: f64| if t.rem_euclid(2.0) >= 1.0 { 1.0 } else { 0.0 };
        for (x, f) in [
            (0.3, 0.7),
            (-1.9, 2.5),
            (5.2, 0.01),
            (0.0, 13.0),
            (3.7, 1.0),
            (12345.6, 0.3),
        ] {
            // Midpoint sums over [x - f, x + f], weighted by the tent 1 - |t - x| / f.
            let n = 40_000;
            let (mut sum, mut weight) = (0.0, 0.0);
            for i in 0..n {
                let u = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let w = 1.0 - u.abs();
                sum += w * square(x + u * f);
                weight += w;
            }
            let numeric = sum / weight;
            assert!(
                (odd_share(x, f) - numeric).abs() < 1e-3,
                "x {x} f {f}: {} against {numeric}",
                odd_share(x, f)
            );
        }
        // Far wider than the stripes: their mean colour.
        let s = stripes("(a: (1, 1, 1), b: (0, 0, 0), width: 0.01)");
        let c = at(&s, 0.123, 10.0);
        assert!((c[0] - 0.5).abs() < 0.01, "{c:?}");
        // Unfiltered, the same point keeps its stripe's colour.
        let raw = stripes("(a: (1, 1, 1), b: (0, 0, 0), width: 0.01, filter: false)");
        assert!(matches!(at(&raw, 0.123, 10.0)[0], 0.0 | 1.0));
    }

    #[test]
    fn bad_parameters_are_errors() {
        for (params, message) in [
            ("(width: 0)", "parameter `width`: expected > 0, found 0"),
            (
                "(axis: (0, 0, 0))",
                "parameter `axis`: expected a non-zero direction, found [0.0, 0.0, 0.0]",
            ),
        ] {
            let p = luxon_plugin::parse_params(params).unwrap();
            let e = Stripes::create(p, &Context::default()).err().unwrap();
            assert_eq!(e.message, message);
        }
    }
}
