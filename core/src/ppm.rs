//! 8-bit binary PPM, the one format the core writes itself (row by row while rendering, and
//! collectively over MPI-IO): the header and the pixel bytes, exactly as the `ppm` writer plugin
//! makes them.

/// Appends the 8-bit sRGB RGB bytes of linear RGBA pixels, exactly as the `ppm` writer does.
pub fn srgb8(rgba: &[f32], out: &mut Vec<u8>) {
    let encode = |c: f32| (luxon_plugin::linear_to_srgb(c) * 255.0).round() as u8;
    luxon_plugin::encode_rgb(rgba, encode, |rgb, _| out.extend_from_slice(&rgb));
}

pub fn ppm_header(width: u32, height: u32) -> Vec<u8> {
    format!("P6\n{width} {height}\n255\n").into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs of equal pixels (copied bytes) encode as every pixel computed on its own.
    #[test]
    fn repeated_pixels_encode_as_computed_alone() {
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
    }
}
