//! `sphere` and `spheres`: native spheres the core intersects itself.

use crate::params::{plain_some, positive};
use luxon_plugin::{finite, invalid, Context, Describe, Error, Geometry, Primitive};
use serde::Deserialize;

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct SphereParams {
    pub center: [f64; 3],
    pub radius: f64,
}

/// The sphere as the host takes it: `[x, y, z, radius]`.
pub fn sphere(p: &SphereParams) -> Result<[f64; 4], Error> {
    let [x, y, z] = finite("center", p.center)?;
    Ok([x, y, z, positive("radius", p.radius)?])
}

pub struct Sphere;

impl Describe for Sphere {
    const NAME: &'static str = "sphere";
    const DESCRIPTION: &'static str = "A sphere.";
    const PARAMS: &'static str = "center: (x, y, z)  centre of the sphere
radius: f64 > 0  radius";
}

impl Primitive for Sphere {
    type Params = SphereParams;
    fn create(p: SphereParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.spheres(&[sphere(&p)?])
    }
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct SpheresParams {
    pub centers: Vec<[f64; 3]>,
    #[serde(default, deserialize_with = "plain_some")]
    pub radius: Option<f64>,
    #[serde(default, deserialize_with = "plain_some")]
    pub radii: Option<Vec<f64>>,
}

pub fn spheres(p: &SpheresParams) -> Result<Vec<[f64; 4]>, Error> {
    if p.centers.is_empty() {
        return Err(invalid(
            "parameter `centers` is empty; give at least one centre",
        ));
    }
    let n = p.centers.len();
    let radii: Vec<f64> = match (p.radius, &p.radii) {
        (Some(r), None) => vec![positive("radius", r)?; n],
        (None, Some(radii)) => {
            if radii.len() != n {
                return Err(invalid(format!(
                    "parameter `radii` has {} entries but `centers` has {n}; give one radius per centre",
                    radii.len()
                )));
            }
            let check = |(i, &r): (usize, &f64)| positive(&format!("radii[{i}]"), r);
            radii
                .iter()
                .enumerate()
                .map(check)
                .collect::<Result<_, _>>()?
        }
        (Some(_), Some(_)) => {
            return Err(invalid(
                "give either `radius` (shared) or `radii` (one per centre), not both",
            ))
        }
        (None, None) => {
            return Err(invalid(
                "missing parameter `radius` (shared) or `radii` (one per centre)",
            ))
        }
    };
    let mut out = Vec::with_capacity(n);
    for (i, (&c, r)) in p.centers.iter().zip(radii).enumerate() {
        let [x, y, z] = finite(&format!("centers[{i}]"), c)?;
        out.push([x, y, z, r]);
    }
    Ok(out)
}

pub struct Spheres;

impl Describe for Spheres {
    const NAME: &'static str = "spheres";
    const DESCRIPTION: &'static str =
        "Many spheres in one object, with a shared radius or one radius each (molecules, point sets).";
    const PARAMS: &'static str = "centers: [(x, y, z), ...]  sphere centres, at least one
radius: f64 > 0 = none  radius shared by every sphere (give this or `radii`)
radii: [f64 > 0, ...] = none  one radius per centre (give this or `radius`)";
}

impl Primitive for Spheres {
    type Params = SpheresParams;
    fn create(p: SpheresParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.spheres(&spheres(&p)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{assert_contains, err};
    use luxon_plugin::parse_params;

    #[test]
    fn sphere_from_ron() {
        let p: SphereParams = parse_params("(center: (1, 2, 3), radius: 0.5)").unwrap();
        assert_eq!(sphere(&p).unwrap(), [1.0, 2.0, 3.0, 0.5]);
    }

    #[test]
    fn sphere_errors() {
        let p = |center, radius| SphereParams { center, radius };
        assert_contains(
            &err(sphere(&p([0.0; 3], 0.0))),
            "parameter `radius`: expected a number > 0, found 0",
        );
        assert_contains(
            &err(sphere(&p([0.0; 3], -1.0))),
            "`radius`: expected a number > 0",
        );
        assert_contains(
            &err(sphere(&p([0.0; 3], f64::INFINITY))),
            "`radius` must be finite",
        );
        assert_contains(
            &err(sphere(&p([0.0, f64::NAN, 0.0], 1.0))),
            "`center` must be finite",
        );
    }

    #[test]
    fn spheres_shared_radius_and_radii() {
        let p: SpheresParams =
            parse_params("(centers: [(0, 0, 0), (1, 0, 0)], radius: 0.5)").unwrap();
        assert_eq!(
            spheres(&p).unwrap(),
            vec![[0.0, 0.0, 0.0, 0.5], [1.0, 0.0, 0.0, 0.5]]
        );
        let p: SpheresParams =
            parse_params("(centers: [(0, 0, 0), (1, 0, 0)], radii: [0.25, 2])").unwrap();
        assert_eq!(
            spheres(&p).unwrap(),
            vec![[0.0, 0.0, 0.0, 0.25], [1.0, 0.0, 0.0, 2.0]]
        );
    }

    #[test]
    fn spheres_errors() {
        let e = |text: &str| err(spheres(&parse_params::<SpheresParams>(text).unwrap()));
        assert_contains(&e("(centers: [], radius: 1)"), "`centers` is empty");
        assert_contains(&e("(centers: [(0, 0, 0)])"), "missing parameter `radius`");
        assert_contains(
            &e("(centers: [(0, 0, 0)], radius: 1, radii: [1])"),
            "not both",
        );
        assert_contains(
            &e("(centers: [(0, 0, 0), (1, 1, 1)], radii: [1])"),
            "`radii` has 1 entries but `centers` has 2",
        );
        assert_contains(
            &e("(centers: [(0, 0, 0), (1, 1, 1)], radii: [1, 0])"),
            "`radii[1]`: expected a number > 0",
        );
        assert_contains(
            &e("(centers: [(0, 0, 0)], radius: -2)"),
            "`radius`: expected a number > 0",
        );
        let p = SpheresParams {
            centers: vec![[0.0; 3], [f64::NAN, 0.0, 0.0]],
            radius: Some(1.0),
            radii: None,
        };
        assert_contains(&err(spheres(&p)), "`centers[1]` must be finite");
    }
}
