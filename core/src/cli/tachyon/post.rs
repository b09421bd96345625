//! Tachyon's image processing before writing: `-clamp` (the default: values outside [0, 1]
//! are clamped, which every writer does anyway), `-normalize` (the smallest and largest
//! colour value of the image, over every pixel and channel, become 0 and 1) and `-gamma g`
//! (normalize, then c^(1/g)). Measured with tachyon-nox: background (0.5, 0.25, 0.1) gives
//! (255, 95, 0) normalized and (255, 163, 0) with gamma 2.2.

use super::options::Post;
use luxon::Framebuffer;

/// Applies `post` to the colour channels of `fb` (alpha is left alone; NaN stays NaN).
pub fn apply(post: Post, fb: &mut Framebuffer) {
    let gamma = match post {
        Post::Clamp => return,
        Post::Normalize => 1.0,
        Post::Gamma(g) => g as f32,
    };
    let colours = || fb.rgba.chunks_exact(4).flat_map(|p| p[..3].iter().copied());
    let lo = colours()
        .filter(|x| !x.is_nan())
        .fold(f32::INFINITY, f32::min);
    let hi = colours()
        .filter(|x| !x.is_nan())
        .fold(f32::NEG_INFINITY, f32::max);
    // A flat (or empty) image has no range to stretch (NaN was left out: no NaN here).
    if hi <= lo || !(hi - lo).is_finite() {
        return;
    }
    let scale = 1.0 / (hi - lo);
    for p in fb.rgba.chunks_exact_mut(4) {
        for c in &mut p[..3] {
            let x = (*c - lo) * scale;
            *c = if gamma == 1.0 { x } else { x.powf(1.0 / gamma) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(px: &[[f32; 3]]) -> Framebuffer {
        let mut fb = Framebuffer::new(px.len() as u32, 1);
        for (i, p) in px.iter().enumerate() {
            fb.rgba[i * 4..i * 4 + 3].copy_from_slice(p);
            fb.rgba[i * 4 + 3] = 1.0;
        }
        fb
    }

    /// Tachyon's 8-bit value: floor(255 c).
    fn code(x: f32) -> u8 {
        (x.clamp(0.0, 1.0) * 255.0) as u8
    }

    #[test]
    fn normalize_and_gamma_match_tachyons_numbers() {
        let mut fb = image(&[[0.5, 0.25, 0.1]]);
        apply(Post::Normalize, &mut fb);
        assert_eq!(
            fb.rgba[..3].iter().map(|&x| code(x)).collect::<Vec<_>>(),
            [255, 95, 0]
        );
        let mut fb = image(&[[0.5, 0.25, 0.1]]);
        apply(Post::Gamma(2.2), &mut fb);
        assert_eq!(
            fb.rgba[..3].iter().map(|&x| code(x)).collect::<Vec<_>>(),
            [255, 163, 0]
        );
        let mut fb = image(&[[0.5, 0.25, 2.0]]);
        apply(Post::Normalize, &mut fb);
        assert_eq!(
            fb.rgba[..3].iter().map(|&x| code(x)).collect::<Vec<_>>(),
            [36, 0, 255]
        );
        assert_eq!(fb.rgba[3], 1.0);
    }

    #[test]
    fn clamp_and_flat_images_are_left_alone() {
        let mut fb = image(&[[0.5, 2.0, -1.0]]);
        apply(Post::Clamp, &mut fb);
        assert_eq!(&fb.rgba[..3], &[0.5, 2.0, -1.0]);
        let mut fb = image(&[[0.3, 0.3, 0.3], [0.3, 0.3, 0.3]]);
        apply(Post::Normalize, &mut fb);
        assert_eq!(&fb.rgba[..3], &[0.3, 0.3, 0.3]);
    }
}
