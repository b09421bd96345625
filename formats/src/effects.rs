//! Lights, fog and ambient occlusion: serde values into checked `desc` values.

use crate::desc::*;
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

type Result<T> = std::result::Result<T, crate::error::SceneError>;

fn length(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

impl Checker<'_> {
    pub(crate) fn light(&self, light: raw::Light, node: &Node) -> Result<Spanned<LightDesc>> {
        let f = LightFields { check: self, node };
        let light = match light {
            raw::Light::Point {
                position,
                color,
                intensity,
                shadows,
                attenuation,
                ..
            } => LightDesc::Point {
                position,
                color: f.colour(color)?,
                intensity: f.intensity(intensity)?,
                shadows: shadows.unwrap_or(true),
                attenuation: f.attenuation(attenuation)?,
            },
            raw::Light::Directional {
                direction,
                color,
                intensity,
                shadows,
                ..
            } => LightDesc::Directional {
                direction: f.direction("direction", direction)?,
                color: f.colour(color)?,
                intensity: f.intensity(intensity)?,
                shadows: shadows.unwrap_or(true),
            },
            raw::Light::Spot {
                position,
                direction,
                angle,
                falloff,
                fade,
                color,
                intensity,
                shadows,
                attenuation,
                ..
            } => {
                // Above 0 (a cone of no width lights nothing) and at most 179.
                let cone = self.positive(f.field("angle"), "angle", angle)?;
                let cone = self.range(f.field("angle"), "angle", cone, 0.0, 179.0)?;
                let falloff = match falloff {
                    Some(v) => self.range(f.field("falloff"), "falloff", v, 0.0, cone)?,
                    None => 0.0,
                };
                LightDesc::Spot {
                    position,
                    direction: f.direction("direction", direction)?,
                    cone_deg: cone,
                    falloff_deg: falloff,
                    fade: match fade {
                        Some(raw::SpotFade::Linear) => SpotFade::Linear,
                        Some(raw::SpotFade::Smooth) | None => SpotFade::Smooth,
                    },
                    color: f.colour(color)?,
                    intensity: f.intensity(intensity)?,
                    shadows: shadows.unwrap_or(true),
                    attenuation: f.attenuation(attenuation)?,
                }
            }
            raw::Light::SphereLight {
                center,
                radius,
                samples,
                color,
                intensity,
                shadows,
                attenuation,
                ..
            } => LightDesc::Sphere {
                center,
                radius: self.positive(f.field("radius"), "radius", radius)?,
                samples: f.samples(samples)?,
                color: f.colour(color)?,
                intensity: f.intensity(intensity)?,
                shadows: shadows.unwrap_or(true),
                attenuation: f.attenuation(attenuation)?,
            },
            raw::Light::RectLight {
                corner,
                edge1,
                edge2,
                samples,
                color,
                intensity,
                shadows,
                attenuation,
                ..
            } => {
                let (edge1, edge2) = f.rectangle(edge1, edge2)?;
                LightDesc::Rect {
                    corner,
                    edge1,
                    edge2,
                    samples: f.samples(samples)?,
                    color: f.colour(color)?,
                    intensity: f.intensity(intensity)?,
                    shadows: shadows.unwrap_or(true),
                    attenuation: f.attenuation(attenuation)?,
                }
            }
        };
        Ok(self.spanned(light, node))
    }

    /// `background:` a colour, or a gradient (named `Gradient`, with an `up` that is not
    /// zero).
    pub(crate) fn background(&self, b: raw::Background, node: &Node) -> Result<BackgroundDesc> {
        let g = match b {
            raw::Background::Color(rgb) => {
                return Ok(BackgroundDesc::Color(self.colour(
                    node,
                    "background",
                    rgb,
                )?));
            }
            raw::Background::Gradient(g) => g,
        };
        // RON gives the struct without its name: a gradient is `Gradient(...)` or `(...)`.
        let text = self.src.slice(node);
        let name = text[..text.find('(').unwrap_or(0)].trim();
        if !(name.is_empty() || name == "Gradient") {
            return Err(self.error(
                node,
                format!(
                    "`background: {}(...)`: expected a colour `(r, g, b)` or `Gradient(kind: \
                     Sphere, up: (0, 1, 0), top: 1, bottom: -1, top_color: (..), bottom_color: \
                     (..))`",
                    crate::error::shown(name)
                ),
            ));
        }
        let field = |name| node.field(name).unwrap_or(node);
        let up = g.up.unwrap_or([0.0, 1.0, 0.0]);
        if up == [0.0; 3] {
            return Err(self.error(
                field("up"),
                "gradient `up` is (0, 0, 0); expected a direction",
            ));
        }
        Ok(BackgroundDesc::Gradient(GradientDesc {
            kind: match g.kind {
                raw::GradientKind::Sphere => GradientKind::Sphere,
                raw::GradientKind::OrthoPlane => GradientKind::OrthoPlane,
            },
            up,
            top: g.top,
            bottom: g.bottom,
            top_color: self.colour(field("top_color"), "top_color", g.top_color)?,
            bottom_color: self.colour(field("bottom_color"), "bottom_color", g.bottom_color)?,
        }))
    }

    pub(crate) fn fog(&self, fog: raw::Fog, node: &Node) -> Result<FogDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        let mode_node = field("mode");
        let inner = |name| mode_node.field(name).unwrap_or(mode_node);
        let mode = match fog.mode {
            raw::FogMode::Linear { start, end } => {
                let start = self.range(inner("start"), "start", start, 0.0, f64::INFINITY)?;
                if end <= start {
                    return Err(self.error(
                        inner("end"),
                        format!("fog `end` is {end}; expected a distance greater than `start` ({start})"),
                    ));
                }
                FogMode::Linear { start, end }
            }
            raw::FogMode::Exp { density, start } => FogMode::Exp {
                density: self.positive(inner("density"), "density", density)?,
                start: self.range(
                    inner("start"),
                    "start",
                    start.unwrap_or(0.0),
                    0.0,
                    f64::INFINITY,
                )?,
            },
            raw::FogMode::Exp2 { density, start } => FogMode::Exp2 {
                density: self.positive(inner("density"), "density", density)?,
                start: self.range(
                    inner("start"),
                    "start",
                    start.unwrap_or(0.0),
                    0.0,
                    f64::INFINITY,
                )?,
            },
        };
        Ok(FogDesc {
            mode,
            color: self.colour(field("color"), "color", fog.color.unwrap_or([0.5; 3]))?,
            planar: fog.planar.unwrap_or(false),
            every_ray: fog.every_ray.unwrap_or(false),
            misses: fog.misses.unwrap_or(false),
        })
    }

    pub(crate) fn ao(&self, ao: raw::Ao, node: &Node) -> Result<AoDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        Ok(AoDesc {
            samples: match ao.samples {
                Some(n) => self.whole(field("samples"), "samples", n, 1, 4096)?,
                None => 16,
            },
            max_distance: match ao.distance {
                Some(d) => self.positive(field("distance"), "distance", d)?,
                None => f64::INFINITY,
            },
            color: self.colour(field("color"), "color", ao.color.unwrap_or([1.0; 3]))?,
            intensity: match ao.intensity {
                Some(i) => self.range(field("intensity"), "intensity", i, 0.0, f64::INFINITY)?,
                None => 1.0,
            },
            direct: match ao.direct {
                Some(d) => self.range(field("direct"), "direct", d, 0.0, f64::INFINITY)?,
                None => 1.0,
            },
        })
    }
}

/// The checks the kinds of light share, each reported at its field of the light `node`.
struct LightFields<'a> {
    check: &'a Checker<'a>,
    node: &'a Node,
}

impl LightFields<'_> {
    fn field(&self, name: &str) -> &Node {
        self.node.field(name).unwrap_or(self.node)
    }

    fn colour(&self, c: Option<[f64; 3]>) -> Result<[f64; 3]> {
        self.check
            .colour(self.field("color"), "color", c.unwrap_or([1.0; 3]))
    }

    fn intensity(&self, i: Option<f64>) -> Result<f64> {
        self.check.range(
            self.field("intensity"),
            "intensity",
            i.unwrap_or(1.0),
            0.0,
            f64::INFINITY,
        )
    }

    fn attenuation(&self, a: Option<[f64; 3]>) -> Result<Attenuation> {
        let Some(a) = a else {
            return Ok(Attenuation::default());
        };
        if a.iter().any(|&k| k < 0.0) || a.iter().all(|&k| k == 0.0) {
            return Err(self.check.error(
                self.field("attenuation"),
                format!("`attenuation` is {a:?}; expected (constant, linear, quadratic) >= 0, not all 0"),
            ));
        }
        Ok(Attenuation {
            constant: a[0],
            linear: a[1],
            quadratic: a[2],
        })
    }

    /// A non-zero vector, field `name`.
    fn direction(&self, name: &str, d: [f64; 3]) -> Result<[f64; 3]> {
        if length(d) == 0.0 {
            return Err(self.check.error(
                self.field(name),
                format!("the light's `{name}` has zero length; expected a non-zero vector"),
            ));
        }
        Ok(d)
    }

    /// A rectangle light's two sides: non-zero and not parallel.
    fn rectangle(&self, edge1: [f64; 3], edge2: [f64; 3]) -> Result<([f64; 3], [f64; 3])> {
        let (e1, e2) = (
            self.direction("edge1", edge1)?,
            self.direction("edge2", edge2)?,
        );
        let cross = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        if length(cross) == 0.0 {
            return Err(self.check.error(
                self.field("edge2"),
                "`edge1` and `edge2` are parallel; expected the two sides of a rectangle",
            ));
        }
        Ok((e1, e2))
    }

    /// Shadow rays per shading point of an area light (default 16).
    fn samples(&self, n: Option<f64>) -> Result<u32> {
        match n {
            Some(n) => self
                .check
                .whole(self.field("samples"), "samples", n, 1, 4096),
            None => Ok(16),
        }
    }
}
