//! `plane`: native infinite planes the core intersects itself.

use crate::vector::normalize;
use luxon_plugin::{finite, invalid, Context, Describe, Error, Geometry, Primitive};
use serde::Deserialize;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct PlaneParams {
    #[serde(default)]
    pub point: [f64; 3],
    pub normal: [f64; 3],
}

/// The plane as the host takes it: point then unit normal.
pub fn plane(p: &PlaneParams) -> Result<[f64; 6], Error> {
    let [px, py, pz] = finite("point", p.point)?;
    let [nx, ny, nz] = normalize(finite("normal", p.normal)?)
        .ok_or_else(|| invalid("parameter `normal` has zero length"))?;
    Ok([px, py, pz, nx, ny, nz])
}

pub struct Plane;

impl Describe for Plane {
    const NAME: &'static str = "plane";
    const DESCRIPTION: &'static str = "An infinite plane through a point.";
    const PARAMS: &'static str = "point: (x, y, z) = (0, 0, 0)  a point on the plane
normal: (x, y, z)  plane normal, any non-zero length";
}

impl Primitive for Plane {
    type Params = PlaneParams;
    fn create(p: PlaneParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.planes(&[plane(&p)?])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_contains, err};
    use luxon_plugin::parse_params;

    #[test]
    fn plane_default_point_and_unit_normal() {
        let p: PlaneParams = parse_params("(normal: (0, 2, 0))").unwrap();
        assert_eq!(plane(&p).unwrap(), [0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let p: PlaneParams =
            parse_params("(point: (1, 2, 3), normal: (1e-300, 0, 1e-300))").unwrap();
        let [_, _, _, nx, ny, nz] = plane(&p).unwrap();
        let h = 0.5f64.sqrt();
        assert!((nx - h).abs() < 1e-15 && ny == 0.0 && (nz - h).abs() < 1e-15);
    }

    #[test]
    fn plane_errors() {
        let p = PlaneParams {
            point: [0.0; 3],
            normal: [0.0; 3],
        };
        assert_contains(&err(plane(&p)), "`normal` has zero length");
        let p = PlaneParams {
            point: [f64::NEG_INFINITY, 0.0, 0.0],
            normal: [0.0, 1.0, 0.0],
        };
        assert_contains(&err(plane(&p)), "`point` must be finite");
        let p = PlaneParams {
            point: [0.0; 3],
            normal: [0.0, f64::NAN, 1.0],
        };
        assert_contains(&err(plane(&p)), "`normal` must be finite");
    }
}
