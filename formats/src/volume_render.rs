//! A volume's `render: (...)`: transfer function (points or a preset), step, interpolation,
//! shading, clip group and crop box, checked value by value.

use crate::desc::*;
use crate::error::unknown_name;
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

type Result<T> = std::result::Result<T, crate::error::SceneError>;

impl Checker<'_> {
    pub(crate) fn volume_render(
        &self,
        r: raw::VolumeRender,
        node: &Node,
    ) -> Result<VolumeRenderDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        let transfer = self.transfer(r.transfer, field("transfer"))?;
        let step = match r.step {
            Some(s) => Some(self.positive(field("step"), "step", s)?),
            None => None,
        };
        let shading = match r.shading {
            Some(s) => {
                let at = field("shading");
                let inner = |name| at.field(name).unwrap_or(at);
                let d = VolumeShadingDesc::default();
                let coefficient = |name, v: Option<f64>, default| match v {
                    Some(v) => self.range(inner(name), name, v, 0.0, f64::INFINITY),
                    None => Ok(default),
                };
                Some(VolumeShadingDesc {
                    ambient: coefficient("ambient", s.ambient, d.ambient)?,
                    diffuse: coefficient("diffuse", s.diffuse, d.diffuse)?,
                    specular: coefficient("specular", s.specular, d.specular)?,
                    shininess: match s.shininess {
                        Some(v) => self.positive(inner("shininess"), "shininess", v)?,
                        None => d.shininess,
                    },
                    shadows: s.shadows.unwrap_or(d.shadows),
                })
            }
            None => None,
        };
        let bounds = match r.bounds {
            Some(b) => {
                let at = field("bounds");
                for a in 0..3 {
                    if b.min[a] >= b.max[a] {
                        let at = at.field("max").unwrap_or(at);
                        return Err(self.error(
                            at.item(a).unwrap_or(at),
                            format!(
                                "the crop box is empty: `max` {:?} is not above `min` {:?} on axis {a}; expected min < max on every axis",
                                b.max, b.min
                            ),
                        ));
                    }
                }
                Some((b.min, b.max))
            }
            None => None,
        };
        Ok(VolumeRenderDesc {
            transfer,
            step,
            interpolation: match r.interpolation {
                Some(raw::Interpolation::Nearest) => Interpolation::Nearest,
                Some(raw::Interpolation::Trilinear) | None => Interpolation::Trilinear,
            },
            shading,
            clip: r.clip.map(|c| self.spanned(c, field("clip"))),
            bounds,
        })
    }

    fn transfer(&self, t: raw::Transfer, node: &Node) -> Result<TransferDesc> {
        let field = |name| node.field(name).unwrap_or(node);
        let names = || TRANSFER_PRESETS.iter().map(|(n, _)| *n);
        let (preset, points) = match (t.preset, t.points) {
            (Some(_), Some(_)) => {
                return Err(self.error(
                    field("points"),
                    "the transfer function has both `preset` and `points`; expected one of them",
                ))
            }
            (None, None) => {
                return Err(self.error(
                    node,
                    format!(
                        "the transfer function has neither `preset` nor `points`; expected e.g. `preset: \"grayscale\"` (presets: {})",
                        names().collect::<Vec<_>>().join(", ")
                    ),
                ))
            }
            (Some(name), None) => {
                let Some((_, points)) = TRANSFER_PRESETS.iter().find(|(n, _)| *n == name) else {
                    return Err(self.error(
                        field("preset"),
                        unknown_name("transfer-function preset", &name, "", names()),
                    ));
                };
                let points = points
                    .iter()
                    .map(|&(x, color, opacity)| TransferPoint { x, color, opacity })
                    .collect();
                (Some(name), points)
            }
            (None, Some(raw_points)) => {
                let list = field("points");
                if raw_points.is_empty() {
                    return Err(self.error(
                        list,
                        "the transfer function has no points; expected at least one `(x: 0.5, color: (1, 1, 1), opacity: 1)`",
                    ));
                }
                let mut points: Vec<TransferPoint> = Vec::with_capacity(raw_points.len());
                for (i, p) in raw_points.into_iter().enumerate() {
                    let at = list.item(i).unwrap_or(list);
                    let inner = |name| at.field(name).unwrap_or(at);
                    let x = self.range(inner("x"), "x", p.x, 0.0, 1.0)?;
                    if let Some(prev) = points.last() {
                        if x <= prev.x {
                            return Err(self.error(
                                inner("x"),
                                format!(
                                    "control point `x` {x} does not follow the previous one ({}); expected increasing x",
                                    prev.x
                                ),
                            ));
                        }
                    }
                    points.push(TransferPoint {
                        x,
                        color: self.colour(inner("color"), "color", p.color)?,
                        opacity: self.range(inner("opacity"), "opacity", p.opacity, 0.0, f64::INFINITY)?,
                    });
                }
                (None, points)
            }
        };
        let range = match t.range {
            Some(r) => {
                if r[1] <= r[0] {
                    let at = field("range");
                    return Err(self.error(
                        at.item(1).unwrap_or(at),
                        format!(
                            "the transfer function's `range` ({}, {}) is empty; expected (low, high) with low < high",
                            r[0], r[1]
                        ),
                    ));
                }
                Some(r)
            }
            None => None,
        };
        Ok(TransferDesc {
            preset,
            points,
            range,
            opacity: match t.opacity {
                Some(o) => self.range(field("opacity"), "opacity", o, 0.0, f64::INFINITY)?,
                None => 1.0,
            },
        })
    }
}
