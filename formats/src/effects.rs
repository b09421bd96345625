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
        let field = |name: &'static str| node.field(name).unwrap_or(node);
        let colour =
            |c: Option<[f64; 3]>| self.colour(field("color"), "color", c.unwrap_or([1.0; 3]));
        let intensity = |i: Option<f64>| {
            self.range(
                field("intensity"),
                "intensity",
                i.unwrap_or(1.0),
                0.0,
                f64::INFINITY,
            )
        };
        let attenuation = |a: Option<[f64; 3]>| -> Result<Attenuation> {
            let Some(a) = a else {
                return Ok(Attenuation::default());
            };
            let at = field("attenuation");
            if a.iter().any(|&k| k < 0.0) || a.iter().all(|&k| k == 0.0) {
                return Err(self.error(
                    at,
                    format!("`attenuation` is {a:?}; expected (constant, linear, quadratic) >= 0, not all 0"),
                ));
            }
            Ok(Attenuation {
                constant: a[0],
                linear: a[1],
                quadratic: a[2],
            })
        };
        let direction = |name: &'static str, d: [f64; 3]| -> Result<[f64; 3]> {
            if length(d) == 0.0 {
                return Err(self.error(
                    field(name),
                    format!("the light's `{name}` has zero length; expected a non-zero vector"),
                ));
            }
            Ok(d)
        };
        let samples = |n: Option<f64>| match n {
            Some(n) => self.whole(field("samples"), "samples", n, 1, 4096),
            None => Ok(16),
        };
        let light = match light {
            raw::Light::Point {
                position,
                color,
                intensity: i,
                shadows,
                attenuation: a,
            } => LightDesc::Point {
                position,
                color: colour(color)?,
                intensity: intensity(i)?,
                shadows: shadows.unwrap_or(true),
                attenuation: attenuation(a)?,
            },
            raw::Light::Directional {
                direction: d,
                color,
                intensity: i,
                shadows,
            } => LightDesc::Directional {
                direction: direction("direction", d)?,
                color: colour(color)?,
                intensity: intensity(i)?,
                shadows: shadows.unwrap_or(true),
            },
            raw::Light::Spot {
                position,
                direction: d,
                angle,
                falloff,
                color,
                intensity: i,
                shadows,
                attenuation: a,
            } => {
                let cone = self.range(field("angle"), "angle", angle, f64::MIN_POSITIVE, 179.0)?;
                let falloff = match falloff {
                    Some(f) => self.range(field("falloff"), "falloff", f, 0.0, cone)?,
                    None => 0.0,
                };
                LightDesc::Spot {
                    position,
                    direction: direction("direction", d)?,
                    cone_deg: cone,
                    falloff_deg: falloff,
                    color: colour(color)?,
                    intensity: intensity(i)?,
                    shadows: shadows.unwrap_or(true),
                    attenuation: attenuation(a)?,
                }
            }
            raw::Light::SphereLight {
                center,
                radius,
                samples: n,
                color,
                intensity: i,
                shadows,
                attenuation: a,
            } => LightDesc::Sphere {
                center,
                radius: self.positive(field("radius"), "radius", radius)?,
                samples: samples(n)?,
                color: colour(color)?,
                intensity: intensity(i)?,
                shadows: shadows.unwrap_or(true),
                attenuation: attenuation(a)?,
            },
            raw::Light::RectLight {
                corner,
                edge1,
                edge2,
                samples: n,
                color,
                intensity: i,
                shadows,
                attenuation: a,
            } => {
                let (e1, e2) = (direction("edge1", edge1)?, direction("edge2", edge2)?);
                let cross = [
                    e1[1] * e2[2] - e1[2] * e2[1],
                    e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0],
                ];
                if length(cross) == 0.0 {
                    return Err(self.error(
                        field("edge2"),
                        "`edge1` and `edge2` are parallel; expected the two sides of a rectangle",
                    ));
                }
                LightDesc::Rect {
                    corner,
                    edge1: e1,
                    edge2: e2,
                    samples: samples(n)?,
                    color: colour(color)?,
                    intensity: intensity(i)?,
                    shadows: shadows.unwrap_or(true),
                    attenuation: attenuation(a)?,
                }
            }
        };
        Ok(self.spanned(light, node))
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
            raw::FogMode::Exp { density } => FogMode::Exp {
                density: self.positive(inner("density"), "density", density)?,
            },
            raw::FogMode::Exp2 { density } => FogMode::Exp2 {
                density: self.positive(inner("density"), "density", density)?,
            },
        };
        Ok(FogDesc {
            mode,
            color: self.colour(field("color"), "color", fog.color.unwrap_or([0.5; 3]))?,
            planar: fog.planar.unwrap_or(false),
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
