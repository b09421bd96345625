//! 8-bit binary PPM, the one format the core writes itself (row by row while rendering, and
//! collectively over MPI-IO): the header and the pixel bytes, exactly as the `ppm` writer plugin
//! makes them.

/// Appends the 8-bit sRGB RGB bytes of linear RGBA pixels, exactly as the `ppm` writer does.
pub fn srgb8(rgba: &[f32], out: &mut Vec<u8>) {
    for px in rgba.chunks_exact(4) {
        out.extend(
            px[..3]
                .iter()
                .map(|&c| (luxon_plugin::linear_to_srgb(c) * 255.0).round() as u8),
        );
    }
}

pub fn ppm_header(width: u32, height: u32) -> Vec<u8> {
    format!("P6\n{width} {height}\n255\n").into_bytes()
}
