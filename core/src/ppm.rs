//! 8-bit binary PPM, the one format the core writes itself (row by row while rendering, and
//! collectively over MPI-IO): the header and the pixel bytes, exactly as the `ppm` writer plugin
//! makes them.

/// Appends the 8-bit sRGB RGB bytes of linear RGBA pixels, exactly as the `ppm` writer does
/// (the SDK's exact tables, [`luxon_plugin::srgb8`]).
pub fn srgb8(rgba: &[f32], out: &mut Vec<u8>) {
    let t = luxon_plugin::srgb8::tables();
    out.reserve(rgba.len() / 4 * 3);
    for px in rgba.chunks_exact(4) {
        out.extend_from_slice(&[t.sample(px[0]), t.sample(px[1]), t.sample(px[2])]);
    }
}

pub fn ppm_header(width: u32, height: u32) -> Vec<u8> {
    format!("P6\n{width} {height}\n255\n").into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels encode as each alone, and as the curve itself rounds (NaN, negative and over-one
    /// values, runs of equal pixels).
    #[test]
    fn pixels_encode_alone_and_as_the_curve_gives() {
        let values = [
            0.0,
            -0.0,
            0.5,
            0.5,
            0.25,
            f32::NAN,
            f32::NAN,
            1.5,
            0.003,
            0.0031,
        ];
        let mut rgba = Vec::new();
        for (i, &v) in values.iter().enumerate() {
            rgba.extend([v, 0.2, v, 1.0, v, 0.2, v, 0.5]);
            rgba.extend([v, 0.2, values[(i + 3) % values.len()], 1.0]);
        }
        let mut all = Vec::new();
        srgb8(&rgba, &mut all);
        let mut alone = Vec::new();
        for px in rgba.chunks_exact(4) {
            srgb8(px, &mut alone);
        }
        assert_eq!(all, alone);
        assert_eq!(&all[..3], &[0, 124, 0]);
        let curve: Vec<u8> = rgba
            .chunks_exact(4)
            .flat_map(|p| p[..3].to_vec())
            .map(luxon_plugin::srgb8::direct)
            .collect();
        assert_eq!(all, curve);
    }
}
