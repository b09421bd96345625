//! Placement of a solid texture in the world: `scale`, `rotate`, `translate`.
//!
//! The pattern is defined in its own space; placing it scales it by `scale`, then rotates it by
//! `rotate` (degrees about the x axis, then y, then z: `R = Rz · Ry · Rx`), then moves it by
//! `translate`. A lookup maps the world point back: `local = S⁻¹ · Rᵀ · (p - translate)`.
//! So a checker with `scale: 0.5` has cells 0.5 world units wide, and `translate` is where the
//! pattern's origin lands.

use crate::params::Factors;
use luxon_plugin::{finite, Error};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// World-to-pattern linear part, `S⁻¹ · Rᵀ`, row major.
    m: [[f64; 3]; 3],
    translate: [f64; 3],
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            translate: [0.0; 3],
        }
    }
}

/// Rotation by `deg` degrees about axis `axis` (0 = x, 1 = y, 2 = z), right-handed.
fn rotation(axis: usize, deg: f64) -> [[f64; 3]; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    // Exact quarter turns, so that a 90° rotation maps cells onto cells exactly.
    let (s, c) = if deg % 90.0 == 0.0 {
        (s.round(), c.round())
    } else {
        (s, c)
    };
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

impl Transform {
    /// From the three parameters, checked (scale factors > 0, everything finite).
    pub fn new(scale: Factors<3>, rotate: [f64; 3], translate: [f64; 3]) -> Result<Self, Error> {
        let scale = scale.positive("scale")?;
        let rotate = finite("rotate", rotate)?;
        let translate = finite("translate", translate)?;
        // R = Rz · Ry · Rx: x is applied first.
        let r = mul(
            &rotation(2, rotate[2]),
            &mul(&rotation(1, rotate[1]), &rotation(0, rotate[0])),
        );
        // S⁻¹ · Rᵀ: row i of Rᵀ is column i of R.
        let m = std::array::from_fn(|i| std::array::from_fn(|j| r[j][i] / scale[i]));
        Ok(Transform { m, translate })
    }

    /// The lookup point in pattern space for world point `p`.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [
            p[0] - self.translate[0],
            p[1] - self.translate[1],
            p[2] - self.translate[2],
        ];
        std::array::from_fn(|i| self.m[i][0] * d[0] + self.m[i][1] * d[1] + self.m[i][2] * d[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn identity_by_default() {
        let t = Transform::new(Factors::default(), [0.0; 3], [0.0; 3]).unwrap();
        assert_eq!(t, Transform::default());
        assert_eq!(t.apply([1.0, -2.0, 3.5]), [1.0, -2.0, 3.5]);
    }

    #[test]
    fn scale_then_rotate_then_translate() {
        // A pattern point (1, 0, 0), scaled by 2 -> (2, 0, 0), rotated 90° about z -> (0, 2, 0),
        // moved by (5, 0, 0) -> (5, 2, 0). The lookup inverts that.
        let t = Transform::new(Factors([2.0; 3]), [0.0, 0.0, 90.0], [5.0, 0.0, 0.0]).unwrap();
        assert!(close(t.apply([5.0, 2.0, 0.0]), [1.0, 0.0, 0.0]));
        assert!(close(t.apply([5.0, 0.0, 0.0]), [0.0, 0.0, 0.0]));
        // Per-axis scale acts in pattern space (before the rotation).
        let t = Transform::new(Factors([1.0, 4.0, 1.0]), [0.0, 0.0, 90.0], [0.0; 3]).unwrap();
        assert!(close(t.apply([-4.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
    }

    #[test]
    fn rotation_order_is_x_then_y_then_z() {
        // x then y: local +y --Rx(90)--> +z --Ry(90)--> +x.
        let t = Transform::new(Factors::default(), [90.0, 90.0, 0.0], [0.0; 3]).unwrap();
        assert!(close(t.apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
        // The other order would send +y to +y then to +z... a different point.
        let t = Transform::new(Factors::default(), [0.0, 90.0, 90.0], [0.0; 3]).unwrap();
        // local +y --Ry--> +y --Rz(90)--> -x.
        assert!(close(t.apply([-1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
    }

    #[test]
    fn bad_values() {
        assert!(Transform::new(Factors([0.0; 3]), [0.0; 3], [0.0; 3]).is_err());
        assert!(Transform::new(Factors([1.0, -1.0, 1.0]), [0.0; 3], [0.0; 3]).is_err());
        let e = Transform::new(Factors::default(), [f64::NAN, 0.0, 0.0], [0.0; 3]).unwrap_err();
        assert!(e.message.contains("`rotate`"), "{}", e.message);
        let e =
            Transform::new(Factors::default(), [0.0; 3], [f64::INFINITY, 0.0, 0.0]).unwrap_err();
        assert!(e.message.contains("`translate`"), "{}", e.message);
    }
}
