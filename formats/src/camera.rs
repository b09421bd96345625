//! The camera: serde values into a checked `CameraDesc`, defaults resolved.
//!
//! Defaults that depend on the scene are taken from the distance `d` from `position` to
//! `look_at`: the orthographic window's height (what a 45° perspective camera sees at `d`), the
//! focal distance and the stereo convergence distance (`d`: `look_at` is sharp and at screen
//! depth) and the eye separation (`convergence / 30`, the stereographers' rule of thumb).

use crate::desc::*;
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

type Result<T> = std::result::Result<T, crate::error::SceneError>;

impl Checker<'_> {
    /// The camera, checked part by part in the order the errors are reported.
    pub(crate) fn camera(&self, c: raw::Camera, node: &Node) -> Result<Spanned<CameraDesc>> {
        let (up, distance) = self.view(&c, node)?;
        let (projection, sized_by) = self.camera_projection(&c, node, distance)?;
        let aspect = self.aspect(c.aspect, &projection, node)?;
        let frustum = match &c.frustum {
            Some(f) => Some(self.frustum(f, &projection, sized_by, aspect.is_some(), node)?),
            None => None,
        };
        let depth_of_field = match &c.depth_of_field {
            Some(d) => Some(self.depth_of_field(d, field(node, "depth_of_field"), distance)?),
            None => None,
        };
        let stereo = match &c.stereo {
            Some(s) => Some(self.stereo(s, field(node, "stereo"), distance)?),
            None => None,
        };
        let camera = CameraDesc {
            position: c.position,
            look_at: c.look_at,
            up,
            projection,
            aspect,
            frustum,
            depth_of_field,
            stereo,
        };
        Ok(self.spanned(camera, node))
    }

    /// `position`, `look_at` and `up` make a view: the `up` to use and the distance from
    /// `position` to `look_at`.
    fn view(&self, c: &raw::Camera, node: &Node) -> Result<([f64; 3], f64)> {
        let up = c.up.unwrap_or([0.0, 1.0, 0.0]);
        let view = sub(c.look_at, c.position);
        if length(view) == 0.0 {
            return Err(self.error(
                field(node, "look_at"),
                "the camera's `look_at` equals its `position`; expected a point away from the camera",
            ));
        }
        if length(up) == 0.0 {
            return Err(self.error(
                field(node, "up"),
                "the camera's `up` has zero length; expected a direction such as (0, 1, 0)",
            ));
        }
        // Parallel when the sine of the angle between them is (almost) zero.
        if length(cross(view, up)) <= 1e-9 * length(view) * length(up) {
            let given = if c.up.is_some() { "" } else { " (the default)" };
            return Err(self.error(
                field(node, "up"),
                format!(
                    "the camera's `up` ({}, {}, {}){given} is parallel to its view direction \
                     (from `position` to `look_at`); expected an `up` at an angle to it",
                    up[0], up[1], up[2]
                ),
            ));
        }
        Ok((up, length(view)))
    }

    /// The projection, and the name of the field that sized it explicitly (if any): from
    /// `projection:` or else from the `fov:` / `zoom:` shorthand.
    fn camera_projection(
        &self,
        c: &raw::Camera,
        node: &Node,
        distance: f64,
    ) -> Result<(Projection, Option<&'static str>)> {
        let Some(p) = &c.projection else {
            return self.perspective(c.fov, c.zoom, node);
        };
        for (name, given) in [("fov", c.fov.is_some()), ("zoom", c.zoom.is_some())] {
            if given {
                return Err(self.error(
                    field(node, name),
                    format!(
                        "the camera gives both `projection` and `{name}`; expected \
                         `{name}` inside the projection, such as \
                         `projection: Perspective({name}: 2)`, or no `projection`"
                    ),
                ));
            }
        }
        self.projection(p, field(node, "projection"), distance)
    }

    /// `aspect`, which an Equirectangular camera cannot have.
    fn aspect(
        &self,
        aspect: Option<f64>,
        projection: &Projection,
        node: &Node,
    ) -> Result<Option<f64>> {
        let Some(a) = aspect else {
            return Ok(None);
        };
        let a = self.positive(field(node, "aspect"), "aspect", a)?;
        if *projection == Projection::Equirectangular {
            return Err(self.error(
                field(node, "aspect"),
                "`aspect` has no effect on an Equirectangular camera (it spans 360° by 180°, or \
                 a `frustum`'s window); expected no `aspect`",
            ));
        }
        Ok(Some(a))
    }

    /// `frustum`: on a Perspective, Orthographic or Equirectangular (a window in degrees of
    /// longitude and latitude) camera not sized otherwise (`sized_by`, `has_aspect`), with
    /// `left < right` and `bottom < top`.
    fn frustum(
        &self,
        f: &raw::Frustum,
        projection: &Projection,
        sized_by: Option<&str>,
        has_aspect: bool,
        node: &Node,
    ) -> Result<Frustum> {
        let at = field(node, "frustum");
        if let Projection::Fisheye { .. } = projection {
            return Err(self.error(
                at,
                "a `frustum` sets the image window of a Perspective, Orthographic or \
                 Equirectangular camera; expected no `frustum` with a Fisheye projection",
            ));
        }
        if let Some(name) = sized_by {
            return Err(self.error(
                at,
                format!(
                    "the camera gives both `{name}` and `frustum`; expected only one of \
                     them (the frustum sets the window)"
                ),
            ));
        }
        if has_aspect {
            return Err(self.error(
                field(node, "aspect"),
                "the camera gives both `aspect` and `frustum`; expected only one of them \
                 (the frustum sets the window's shape)",
            ));
        }
        for (lo, hi, a, b) in [
            ("left", "right", f.left, f.right),
            ("bottom", "top", f.bottom, f.top),
        ] {
            if a >= b {
                return Err(self.error(
                    field(at, hi),
                    format!(
                        "the frustum's `{hi}` ({b}) is not greater than its `{lo}` ({a}); \
                         expected {lo} < {hi}"
                    ),
                ));
            }
        }
        Ok(Frustum {
            left: f.left,
            right: f.right,
            bottom: f.bottom,
            top: f.top,
        })
    }

    /// `depth_of_field: (...)`; `node` is its value. The focal distance defaults to the
    /// distance to `look_at`.
    fn depth_of_field(
        &self,
        d: &raw::DepthOfField,
        node: &Node,
        distance: f64,
    ) -> Result<DepthOfField> {
        let aperture = self.range(
            field(node, "aperture"),
            "aperture",
            d.aperture,
            0.0,
            f64::INFINITY,
        )?;
        let focal_distance = match d.focal_distance {
            Some(f) => self.positive(field(node, "focal_distance"), "focal_distance", f)?,
            None => distance,
        };
        Ok(DepthOfField {
            aperture,
            focal_distance,
        })
    }

    /// `stereo: (...)`; `node` is its value. Convergence defaults to the distance to
    /// `look_at`, the eye separation to a thirtieth of the convergence.
    fn stereo(&self, s: &raw::Stereo, node: &Node, distance: f64) -> Result<Stereo> {
        let convergence = match s.convergence {
            Some(v) => self.positive(field(node, "convergence"), "convergence", v)?,
            None => distance,
        };
        let eye_separation = match s.eye_separation {
            Some(v) => self.range(
                field(node, "eye_separation"),
                "eye_separation",
                v,
                0.0,
                f64::INFINITY,
            )?,
            None => convergence / 30.0,
        };
        let layout = match s.layout {
            Some(raw::StereoLayout::OverUnder) => StereoLayout::OverUnder,
            Some(raw::StereoLayout::SideBySide) | None => StereoLayout::SideBySide,
        };
        Ok(Stereo {
            layout,
            eye_separation,
            convergence,
        })
    }

    /// `projection: ...`; `node` is its value.
    fn projection(
        &self,
        p: &raw::Projection,
        node: &Node,
        distance: f64,
    ) -> Result<(Projection, Option<&'static str>)> {
        Ok(match *p {
            raw::Projection::Perspective { fov, zoom } => self.perspective(fov, zoom, node)?,
            raw::Projection::Orthographic { height } => match height {
                Some(h) => (
                    Projection::Orthographic {
                        height: self.positive(field(node, "height"), "height", h)?,
                    },
                    Some("height"),
                ),
                None => {
                    let height = 2.0 * distance * 22.5f64.to_radians().tan();
                    (Projection::Orthographic { height }, None)
                }
            },
            raw::Projection::Fisheye { fov } => {
                let fov_deg = fov.unwrap_or(180.0);
                if !(fov_deg > 0.0 && fov_deg <= 360.0) {
                    return Err(self.error(
                        field(node, "fov"),
                        format!(
                            "`fov` is {}; expected degrees for a fisheye from 0 (excluded) to 360",
                            self.literal(field(node, "fov"))
                        ),
                    ));
                }
                (Projection::Fisheye { fov_deg }, fov.map(|_| "fov"))
            }
            raw::Projection::Equirectangular => (Projection::Equirectangular, None),
        })
    }

    /// A perspective projection from `fov` or `zoom`, fields of `node` (the camera itself for
    /// the `fov:` / `zoom:` shorthand).
    fn perspective(
        &self,
        fov: Option<f64>,
        zoom: Option<f64>,
        node: &Node,
    ) -> Result<(Projection, Option<&'static str>)> {
        Ok(match (fov, zoom) {
            (Some(_), Some(_)) => {
                return Err(self.error(
                    field(node, "zoom"),
                    "the camera gives both `fov` and `zoom`; expected only one of them",
                ))
            }
            (_, Some(zoom)) => (
                Projection::PerspectiveZoom {
                    zoom: self.positive(field(node, "zoom"), "zoom", zoom)?,
                },
                Some("zoom"),
            ),
            (fov, None) => {
                let fov_deg = fov.unwrap_or(45.0);
                if !(fov_deg > 0.0 && fov_deg < 180.0) {
                    return Err(self.error(
                        field(node, "fov"),
                        format!(
                            "`fov` is {}; expected degrees between 0 and 180 (both excluded)",
                            self.literal(field(node, "fov"))
                        ),
                    ));
                }
                (Projection::Perspective { fov_deg }, fov.map(|_| "fov"))
            }
        })
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn length(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Field `name` of `node`, or `node` itself when it has none (errors then point at `node`).
fn field<'n>(node: &'n Node, name: &str) -> &'n Node {
    node.field(name).unwrap_or(node)
}
