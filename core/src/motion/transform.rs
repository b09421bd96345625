//! An object's transform at a time: `world_from_object = translate · rotate · scale` from its
//! keyed tracks (a missing track is the identity), in f64, and what it does to the records a
//! primitive plugin gives (points, normals, radii).

use super::keys::{quaternion, rotation, value};
use glam::{DAffine3, DMat3, DQuat, DVec3};
use luxon_formats::{ObjectTracks, TransformDesc};

/// A transform ready to apply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub world_from_object: DAffine3,
    /// The inverse transpose of the linear part: what normals go through.
    normal_matrix: DMat3,
    /// The scale factor when it is the same size along every axis (radii scale by it);
    /// `None`: the scale differs between axes.
    uniform: Option<f64>,
}

impl Placement {
    /// Scale `s`, then rotation `r`, then translation `t`.
    pub fn new(s: [f64; 3], r: DQuat, t: [f64; 3]) -> Placement {
        let m = DAffine3::from_scale_rotation_translation(DVec3::from(s), r, DVec3::from(t));
        let a = s.map(f64::abs);
        Placement {
            world_from_object: m,
            normal_matrix: m.matrix3.inverse().transpose(),
            uniform: (a[0] == a[1] && a[1] == a[2]).then_some(a[0]),
        }
    }

    /// Any invertible affine map. Its scale counts as uniform when its columns have one
    /// length and are perpendicular, both to 1e-12 relative (a matrix written in decimals is
    /// seldom an exact similarity).
    pub fn from_affine(m: DAffine3) -> Placement {
        let c = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
        let len = c.map(DVec3::length);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.max(b);
        let similar = close(len[0], len[1])
            && close(len[1], len[2])
            && [(0, 1), (1, 2), (0, 2)]
                .iter()
                .all(|&(i, j)| c[i].dot(c[j]).abs() <= 1e-12 * len[i] * len[j]);
        Placement {
            world_from_object: m,
            normal_matrix: m.matrix3.inverse().transpose(),
            uniform: similar.then_some(len[0]),
        }
    }

    /// A static transform of the scene description.
    pub fn from_desc(t: &TransformDesc) -> Placement {
        match t {
            TransformDesc::Trs {
                translate,
                rotate,
                scale,
            } => {
                let r = rotate.as_ref().map_or(DQuat::IDENTITY, quaternion);
                Placement::new(*scale, r, *translate)
            }
            TransformDesc::Matrix(rows) => {
                let col = |j: usize| DVec3::new(rows[0][j], rows[1][j], rows[2][j]);
                Placement::from_affine(DAffine3::from_cols(col(0), col(1), col(2), col(3)))
            }
        }
    }

    /// The object's placement at time `t` (frames).
    pub fn at(tracks: &ObjectTracks, t: f64) -> Placement {
        let s = tracks.scale.as_ref().map_or([1.0; 3], |k| value(k, t));
        let r = tracks
            .rotate
            .as_ref()
            .map_or(DQuat::IDENTITY, |k| rotation(k, t));
        let p = tracks.translate.as_ref().map_or([0.0; 3], |k| value(k, t));
        Placement::new(s, r, p)
    }

    pub fn point(&self, p: [f64; 3]) -> [f64; 3] {
        self.world_from_object
            .transform_point3(DVec3::from(p))
            .to_array()
    }

    /// A normal's direction after the transform (not normalised).
    pub fn normal(&self, n: [f64; 3]) -> [f64; 3] {
        (self.normal_matrix * DVec3::from(n)).to_array()
    }

    /// The factor radii scale by, when the scale is uniform.
    pub fn uniform_scale(&self) -> Option<f64> {
        self.uniform
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_then_rotates_then_moves() {
        let r = DQuat::from_axis_angle(DVec3::Z, 90f64.to_radians());
        let p = Placement::new([2.0, 3.0, 4.0], r, [10.0, 0.0, 0.0]);
        // x scaled by 2 → (2, 0, 0), turned to (0, 2, 0), moved to (10, 2, 0).
        let q = p.point([1.0, 0.0, 0.0]);
        assert!((DVec3::from(q) - DVec3::new(10.0, 2.0, 0.0)).length() < 1e-12);
        assert_eq!(p.uniform_scale(), None);
        assert_eq!(
            Placement::new([-2.0, 2.0, 2.0], r, [0.0; 3]).uniform_scale(),
            Some(2.0)
        );
    }

    #[test]
    fn matrices_are_rows_and_similarities_scale_uniformly() {
        let m = TransformDesc::Matrix([
            [0.0, -2.0, 0.0, 1.0],
            [2.0, 0.0, 0.0, 2.0],
            [0.0, 0.0, 2.0, 3.0],
        ]);
        let p = Placement::from_desc(&m);
        assert_eq!(p.point([1.0, 0.0, 0.0]), [1.0, 4.0, 3.0]);
        assert_eq!(p.uniform_scale(), Some(2.0));
        let shear = TransformDesc::Matrix([
            [1.0, 0.5, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ]);
        assert_eq!(Placement::from_desc(&shear).uniform_scale(), None);
        // The identity description is the identity, bit for bit.
        let id = Placement::from_desc(&TransformDesc::IDENTITY);
        let q = [0.1, -3.7e5, 1e-300];
        assert_eq!(id.point(q).map(f64::to_bits), q.map(f64::to_bits));
    }

    #[test]
    fn normals_stay_perpendicular_to_surfaces() {
        let r = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let p = Placement::new([1.0, 5.0, 0.5], r, [1.0, 2.0, 3.0]);
        // The plane x + y = 1: its points and normal (1, 1, 0).
        let (a, b) = (p.point([1.0, 0.0, 0.0]), p.point([0.0, 1.0, 7.0]));
        let n = DVec3::from(p.normal([1.0, 1.0, 0.0]));
        let along = DVec3::from(b) - DVec3::from(a);
        assert!(n.dot(along).abs() < 1e-12 * along.length() * n.length());
    }
}
