//! `cylinder`, `cone`, `ring` and `polycylinder`: native cones and discs (and a polycylinder's
//! joint spheres) the core intersects itself.

use crate::params::positive;
use crate::vector::{length, scale, sub};
use luxon_plugin::{finite, invalid, invalid_at, Context, Describe, Error, Geometry, Primitive};
use serde::Deserialize;

/// `x` if it is a number >= 0; else an error reported at parameter `name` in the scene.
fn non_negative(name: &str, x: f64) -> Result<f64, Error> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(invalid_at(
            name,
            format!("expected a number >= 0, found {x}"),
        ))
    }
}

fn default_true() -> bool {
    true
}

/// A cone (or cylinder) and its caps as the host takes them.
#[derive(Debug, PartialEq)]
pub struct Built {
    pub cones: Vec<[f64; 8]>,
    pub discs: Vec<[f64; 8]>,
}

fn cone_with_caps(
    base: [f64; 3],
    rb: f64,
    apex: [f64; 3],
    ra: f64,
    caps: bool,
) -> Result<Built, Error> {
    let axis = sub(apex, base);
    let h = length(axis);
    if h <= 0.0 || h.is_nan() {
        return Err(invalid(
            "`base` and `apex` are the same point; expected a length > 0",
        ));
    }
    if rb == 0.0 && ra == 0.0 {
        return Err(invalid(
            "both radii are 0; expected at least one radius > 0",
        ));
    }
    let w = scale(axis, 1.0 / h);
    let mut discs = Vec::new();
    if caps {
        if rb > 0.0 {
            discs.push([base[0], base[1], base[2], -w[0], -w[1], -w[2], 0.0, rb]);
        }
        if ra > 0.0 {
            discs.push([apex[0], apex[1], apex[2], w[0], w[1], w[2], 0.0, ra]);
        }
    }
    Ok(Built {
        cones: vec![[base[0], base[1], base[2], rb, apex[0], apex[1], apex[2], ra]],
        discs,
    })
}

fn emit(out: &mut Geometry, b: &Built) -> Result<(), Error> {
    out.cones(&b.cones)?;
    if !b.discs.is_empty() {
        out.discs(&b.discs)?;
    }
    Ok(())
}

// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct CylinderParams {
    pub base: [f64; 3],
    pub apex: [f64; 3],
    pub radius: f64,
    #[serde(default = "default_true")]
    pub caps: bool,
}

pub fn cylinder(p: &CylinderParams) -> Result<Built, Error> {
    let r = positive("radius", p.radius)?;
    cone_with_caps(
        finite("base", p.base)?,
        r,
        finite("apex", p.apex)?,
        r,
        p.caps,
    )
}

pub struct Cylinder;

impl Describe for Cylinder {
    const NAME: &'static str = "cylinder";
    const DESCRIPTION: &'static str = "A finite cylinder between two points, capped or open.";
    const PARAMS: &'static str = "base: (x, y, z)  centre of one end
apex: (x, y, z)  centre of the other end
radius: f64 > 0  radius
caps: bool = true  close both ends with discs";
}

impl Primitive for Cylinder {
    type Params = CylinderParams;
    fn create(p: CylinderParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        emit(out, &cylinder(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct ConeParams {
    pub base: [f64; 3],
    pub base_radius: f64,
    pub apex: [f64; 3],
    #[serde(default)]
    pub apex_radius: f64,
    #[serde(default = "default_true")]
    pub caps: bool,
}

pub fn cone(p: &ConeParams) -> Result<Built, Error> {
    let rb = non_negative("base_radius", p.base_radius)?;
    let ra = non_negative("apex_radius", p.apex_radius)?;
    cone_with_caps(
        finite("base", p.base)?,
        rb,
        finite("apex", p.apex)?,
        ra,
        p.caps,
    )
}

pub struct Cone;

impl Describe for Cone {
    const NAME: &'static str = "cone";
    const DESCRIPTION: &'static str = "A cone or truncated cone between two points (NFF's `c`).";
    const PARAMS: &'static str = "base: (x, y, z)  centre of the base
base_radius: f64 >= 0  radius at the base
apex: (x, y, z)  centre of the apex end
apex_radius: f64 >= 0 = 0  radius at the apex (0: pointed)
caps: bool = true  close the ends that have a radius with discs";
}

impl Primitive for Cone {
    type Params = ConeParams;
    fn create(p: ConeParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        emit(out, &cone(&p)?)
    }
}

// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct RingParams {
    pub center: [f64; 3],
    pub normal: [f64; 3],
    #[serde(default)]
    pub inner: f64,
    pub outer: f64,
}

pub fn ring(p: &RingParams) -> Result<[f64; 8], Error> {
    let c = finite("center", p.center)?;
    let n = finite("normal", p.normal)?;
    if length(n) == 0.0 {
        return Err(invalid("parameter `normal` has zero length"));
    }
    let inner = non_negative("inner", p.inner)?;
    let outer = positive("outer", p.outer)?;
    if inner >= outer {
        return Err(invalid(format!(
            "`inner` ({inner}) must be smaller than `outer` ({outer})"
        )));
    }
    Ok([c[0], c[1], c[2], n[0], n[1], n[2], inner, outer])
}

pub struct Ring;

impl Describe for Ring {
    const NAME: &'static str = "ring";
    const DESCRIPTION: &'static str = "A flat ring (a disc when `inner` is 0), Tachyon's ring.";
    const PARAMS: &'static str = "center: (x, y, z)  centre
normal: (x, y, z)  normal, any non-zero length
inner: f64 >= 0 = 0  radius of the hole
outer: f64 > inner  outer radius";
}

impl Primitive for Ring {
    type Params = RingParams;
    fn create(p: RingParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        out.discs(&[ring(&p)?])
    }
}

// ------------------------------------------------------------------------------------------------

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub struct PolycylinderParams {
    pub points: Vec<[f64; 3]>,
    pub radius: f64,
}

/// Cones (cylinders) and spheres as the host takes them.
pub type Chain = (Vec<[f64; 8]>, Vec<[f64; 4]>);

/// Cylinders between consecutive points with a sphere at every point, so bends are smooth.
pub fn polycylinder(p: &PolycylinderParams) -> Result<Chain, Error> {
    let r = positive("radius", p.radius)?;
    if p.points.len() < 2 {
        return Err(invalid("parameter `points` needs at least two points"));
    }
    let mut cones = Vec::new();
    let mut spheres = Vec::new();
    for (i, q) in p.points.iter().enumerate() {
        let q = finite(&format!("points[{i}]"), *q)?;
        spheres.push([q[0], q[1], q[2], r]);
        if i > 0 {
            let a = p.points[i - 1];
            if length(sub(q, a)) == 0.0 {
                return Err(invalid(format!("points[{i}] repeats points[{}]", i - 1)));
            }
            cones.push([a[0], a[1], a[2], r, q[0], q[1], q[2], r]);
        }
    }
    Ok((cones, spheres))
}

pub struct Polycylinder;

impl Describe for Polycylinder {
    const NAME: &'static str = "polycylinder";
    const DESCRIPTION: &'static str =
        "A chain of cylinders with sphere joints (molecular bonds, tubes).";
    const PARAMS: &'static str = "points: [(x, y, z), ...]  at least two points along the chain
radius: f64 > 0  radius of the tube";
}

impl Primitive for Polycylinder {
    type Params = PolycylinderParams;
    fn create(p: PolycylinderParams, _ctx: &Context, out: &mut Geometry) -> Result<(), Error> {
        let (cones, spheres) = polycylinder(&p)?;
        out.cones(&cones)?;
        out.spheres(&spheres)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_plugin::parse_params;

    #[test]
    fn capped_cylinder_has_two_outward_caps() {
        let p: CylinderParams =
            parse_params("(base: (0, 0, 0), apex: (0, 0, 2), radius: 0.5)").unwrap();
        let b = cylinder(&p).unwrap();
        assert_eq!(b.cones, vec![[0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 2.0, 0.5]]);
        assert_eq!(b.discs[0][5], -1.0);
        assert_eq!(b.discs[1][5], 1.0);
        let open: CylinderParams =
            parse_params("(base: (0, 0, 0), apex: (0, 0, 2), radius: 0.5, caps: false)").unwrap();
        assert!(cylinder(&open).unwrap().discs.is_empty());
    }

    #[test]
    fn pointed_cone_has_one_cap() {
        let p: ConeParams =
            parse_params("(base: (0, 0, 0), base_radius: 1, apex: (0, 1, 0))").unwrap();
        assert_eq!(cone(&p).unwrap().discs.len(), 1);
    }

    #[test]
    fn errors_name_the_problem() {
        let p: CylinderParams =
            parse_params("(base: (1, 1, 1), apex: (1, 1, 1), radius: 1)").unwrap();
        assert!(cylinder(&p).unwrap_err().message.contains("same point"));
        let p: ConeParams =
            parse_params("(base: (0, 0, 0), base_radius: 0, apex: (0, 1, 0))").unwrap();
        assert!(cone(&p).unwrap_err().message.contains("both radii are 0"));
        let p: RingParams =
            parse_params("(center: (0, 0, 0), normal: (0, 1, 0), inner: 2, outer: 1)").unwrap();
        assert!(ring(&p).unwrap_err().message.contains("smaller than"));
        let p: PolycylinderParams = parse_params("(points: [(0, 0, 0)], radius: 1)").unwrap();
        assert!(polycylinder(&p)
            .unwrap_err()
            .message
            .contains("at least two"));
    }

    #[test]
    fn polycylinder_joins_with_spheres() {
        let p: PolycylinderParams =
            parse_params("(points: [(0, 0, 0), (1, 0, 0), (1, 1, 0)], radius: 0.1)").unwrap();
        let (c, s) = polycylinder(&p).unwrap();
        assert_eq!((c.len(), s.len()), (2, 3));
    }
}
