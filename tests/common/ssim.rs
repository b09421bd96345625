#![allow(dead_code)] // each includer uses its own subset
//! SSIM (Wang, Bovik, Sheikh & Simoncelli 2004) on grayscale images: an 11x11 Gaussian window
//! (sigma 1.5), C1 = (0.01 L)^2, C2 = (0.03 L)^2 with L = 255, averaged over every window that
//! fits in the image.
//!
//! Shared by `tests/nff.rs` and `examples/spd_bench.rs` (included there by path).

/// Rec. 601 luma of 8-bit RGB.
pub fn gray(rgb: &[u8]) -> Vec<f64> {
    rgb.chunks_exact(3)
        .map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64)
        .collect()
}

/// Halves a grayscale image by averaging 2x2 blocks.
pub fn half(img: &[f64], w: usize, h: usize) -> Vec<f64> {
    let (w2, h2) = (w / 2, h / 2);
    let mut out = vec![0.0; w2 * h2];
    for y in 0..h2 {
        for x in 0..w2 {
            let p = |dx: usize, dy: usize| img[(2 * y + dy) * w + 2 * x + dx];
            out[y * w2 + x] = (p(0, 0) + p(1, 0) + p(0, 1) + p(1, 1)) / 4.0;
        }
    }
    out
}

/// Mirrors a grayscale image left to right.
pub fn mirror(img: &[f64], w: usize) -> Vec<f64> {
    img.chunks_exact(w)
        .flat_map(|row| row.iter().rev().copied())
        .collect()
}

const N: usize = 11;

fn window() -> [f64; N] {
    let mut g = [0.0; N];
    let c = (N - 1) as f64 / 2.0;
    for (i, v) in g.iter_mut().enumerate() {
        let d = i as f64 - c;
        *v = (-d * d / (2.0 * 1.5 * 1.5)).exp();
    }
    let sum: f64 = g.iter().sum();
    g.map(|v| v / sum)
}

/// The image filtered by the (separable) window, "valid" part only: (w-N+1) x (h-N+1).
fn filter(img: &[f64], w: usize, h: usize, g: &[f64; N]) -> Vec<f64> {
    let (ow, oh) = (w - N + 1, h - N + 1);
    let mut rows = vec![0.0; ow * h];
    for y in 0..h {
        for x in 0..ow {
            rows[y * ow + x] = (0..N).map(|k| g[k] * img[y * w + x + k]).sum();
        }
    }
    let mut out = vec![0.0; ow * oh];
    for y in 0..oh {
        for x in 0..ow {
            out[y * ow + x] = (0..N).map(|k| g[k] * rows[(y + k) * ow + x]).sum();
        }
    }
    out
}

/// Mean SSIM of two grayscale images (0..=255) of `w` x `h`.
pub fn ssim(a: &[f64], b: &[f64], w: usize, h: usize) -> f64 {
    assert_eq!(a.len(), w * h);
    assert_eq!(b.len(), w * h);
    assert!(w >= N && h >= N, "images smaller than the window");
    let g = window();
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let prod = |x: &[f64], y: &[f64]| -> Vec<f64> { x.iter().zip(y).map(|(p, q)| p * q).collect() };
    let ma = filter(a, w, h, &g);
    let mb = filter(b, w, h, &g);
    let saa = filter(&prod(a, a), w, h, &g);
    let sbb = filter(&prod(b, b), w, h, &g);
    let sab = filter(&prod(a, b), w, h, &g);
    let mut total = 0.0;
    for i in 0..ma.len() {
        let (mx, my) = (ma[i], mb[i]);
        let vx = saa[i] - mx * mx;
        let vy = sbb[i] - my * my;
        let cov = sab[i] - mx * my;
        total +=
            ((2.0 * mx * my + c1) * (2.0 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
    }
    total / ma.len() as f64
}
