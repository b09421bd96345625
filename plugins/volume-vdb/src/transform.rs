//! Linear transforms (OpenVDB's maps): a map type name, then its doubles. Every linear map is
//! turned into our row-major 3x4 `world_from_index`.
//!
//! Layouts (each `Vec3d` is three f64, a `Mat4d` sixteen, row-major):
//! - `UniformScaleMap`, `ScaleMap`: scale, voxel size, inverse scale, inverse scale squared,
//!   inverse twice scale (five `Vec3d`); world = scale * index.
//! - `TranslationMap`: translation (one `Vec3d`).
//! - `UniformScaleTranslateMap`, `ScaleTranslateMap`: translation, then the five of a scale map.
//! - `AffineMap`, `UnitaryMap`: a `Mat4d` acting on row vectors, world = [i j k 1] * M (the
//!   translation is the last row).

use crate::bytes::Cursor;
use crate::VdbError;

/// Reads a transform; returns the map's type name and `world_from_index`.
pub(crate) fn read_transform(c: &mut Cursor) -> Result<(String, [f64; 12]), VdbError> {
    let name = c.string("the transform's map type")?;
    let at = c.pos();
    let vec3 = |c: &mut Cursor| -> Result<[f64; 3], VdbError> {
        Ok([c.f64("a map")?, c.f64("a map")?, c.f64("a map")?])
    };
    let scale_translate = |s: [f64; 3], t: [f64; 3]| {
        [
            s[0], 0.0, 0.0, t[0], //
            0.0, s[1], 0.0, t[1], //
            0.0, 0.0, s[2], t[2],
        ]
    };
    let m =
        match name.as_str() {
            "UniformScaleMap" | "ScaleMap" => {
                let s = vec3(c)?;
                c.take(4 * 24, "a scale map's derived values")?;
                scale_translate(s, [0.0; 3])
            }
            "TranslationMap" => scale_translate([1.0; 3], vec3(c)?),
            "UniformScaleTranslateMap" | "ScaleTranslateMap" => {
                let t = vec3(c)?;
                let s = vec3(c)?;
                c.take(4 * 24, "a scale map's derived values")?;
                scale_translate(s, t)
            }
            "AffineMap" | "UnitaryMap" => {
                let mut r = [[0.0; 4]; 4];
                for row in r.iter_mut() {
                    for v in row.iter_mut() {
                        *v = c.f64("an affine matrix")?;
                    }
                }
                let last = [r[0][3], r[1][3], r[2][3], r[3][3]];
                if last != [0.0, 0.0, 0.0, 1.0] {
                    return Err(VdbError::Corrupt {
                        offset: at,
                        message: format!(
                            "the {name}'s matrix has last column {last:?}; expected (0, 0, 0, 1)"
                        ),
                    });
                }
                [
                    r[0][0], r[1][0], r[2][0], r[3][0], //
                    r[0][1], r[1][1], r[2][1], r[3][1], //
                    r[0][2], r[1][2], r[2][2], r[3][2],
                ]
            }
            "NonlinearFrustumMap" => return Err(VdbError::Unsupported(
                "the grid has a frustum transform (NonlinearFrustumMap); only linear transforms \
                 are supported"
                    .into(),
            )),
            other => {
                return Err(VdbError::Unsupported(format!(
                "unknown transform map type `{other}`; expected a linear map (UniformScaleMap, \
                 ScaleMap, TranslationMap, (Uniform)ScaleTranslateMap, AffineMap or UnitaryMap)"
            )))
            }
        };
    if m.iter().any(|v| !v.is_finite()) {
        return Err(VdbError::Corrupt {
            offset: at,
            message: format!("the {name} has a non-finite entry: {m:?}"),
        });
    }
    Ok((name, m))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(name: &str, values: &[f64]) -> Vec<u8> {
        let mut b = (name.len() as u32).to_le_bytes().to_vec();
        b.extend(name.as_bytes());
        b.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        b
    }

    /// The map types OpenVDB 10 simplifies away when writing from a `Transform` (the fixtures
    /// cover the others), built by hand.
    #[test]
    fn translation_and_unitary_maps() {
        let b = map("TranslationMap", &[1.0, -2.0, 3.5]);
        let (name, m) = read_transform(&mut Cursor::new(&b)).unwrap();
        assert_eq!(name, "TranslationMap");
        assert_eq!(m, [1., 0., 0., 1., 0., 1., 0., -2., 0., 0., 1., 3.5]);
        // A quarter turn about z, as a row-vector matrix: x maps to y.
        let rot = [
            0., 1., 0., 0., //
            -1., 0., 0., 0., //
            0., 0., 1., 0., //
            5., 6., 7., 1.,
        ];
        let b = map("UnitaryMap", &rot);
        let (_, m) = read_transform(&mut Cursor::new(&b)).unwrap();
        assert_eq!(m, [0., -1., 0., 5., 1., 0., 0., 6., 0., 0., 1., 7.]);
        let mut bad = rot;
        bad[3] = 0.5;
        let e = read_transform(&mut Cursor::new(&map("AffineMap", &bad))).unwrap_err();
        assert!(e.to_string().contains("last column"), "{e}");
        let e = read_transform(&mut Cursor::new(&map("NonlinearFrustumMap", &[]))).unwrap_err();
        assert!(e.to_string().contains("frustum"), "{e}");
        let e = read_transform(&mut Cursor::new(&map("SpiralMap", &[]))).unwrap_err();
        assert!(e.to_string().contains("`SpiralMap`"), "{e}");
        let e = read_transform(&mut Cursor::new(&map("ScaleMap", &[1.0, f64::NAN, 1.0])));
        assert!(e.is_err());
    }
}
