//! The image being rendered: linear RGBA f32, rows top to bottom; the pieces it arrives in
//! from the render threads (spans of pixels, and chunks: spans with their values); and the
//! caller's buffers a render can write into instead ([`Target`]).

use crate::budget::{Budget, BudgetError, Charge, Use};
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub struct Framebuffer {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<f32>,
}

impl Framebuffer {
    pub fn new(width: u32, height: u32) -> Framebuffer {
        Framebuffer {
            width,
            height,
            rgba: vec![0.0; width as usize * height as usize * 4],
        }
    }

    /// A black image whose pixels are charged to `budget` while the returned guard lives: an
    /// image over the budget, or one the system cannot hold, is an error naming its size.
    pub fn charged(
        width: u32,
        height: u32,
        budget: &Arc<Budget>,
    ) -> Result<(Framebuffer, Charge), BudgetError> {
        let n = width as usize * height as usize * 4;
        let what = || format!("the image ({width}x{height}, 4 f32 channels)");
        let (rgba, charge) = budget.alloc_zeroed_f32(Use::Image, n, what)?;
        Ok((
            Framebuffer {
                width,
                height,
                rgba,
            },
            charge,
        ))
    }

    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }

    /// Copies a `w`×`h` block of pixels to (`x0`, `y0`).
    pub fn put_block(&mut self, x0: u32, y0: u32, w: u32, h: u32, data: &[f32]) {
        let stride = self.width as usize * 4;
        for row in 0..h as usize {
            let dst = (y0 as usize + row) * stride + x0 as usize * 4;
            let src = row * w as usize * 4;
            self.rgba[dst..dst + w as usize * 4].copy_from_slice(&data[src..src + w as usize * 4]);
        }
    }

    /// Copies rendered pixels to where their spans say.
    pub fn put_chunk(&mut self, c: &Chunk) {
        let mut src = &c.rgba[..c.rgba.len() / 4 * 4];
        for s in &c.spans {
            let row = s.y as usize * self.width as usize;
            let (here, rest) = src.split_at((s.count as usize * 4).min(src.len()));
            src = rest;
            if s.step == 1 {
                // A run of the row (every tile's span): one copy.
                let i = (row + s.x0 as usize) * 4;
                self.rgba[i..i + here.len()].copy_from_slice(here);
                continue;
            }
            for (x, px) in s.xs().zip(here.chunks_exact(4)) {
                let i = (row + x as usize) * 4;
                self.rgba[i..i + 4].copy_from_slice(px);
            }
        }
    }
}

/// Pixels `x0, x0 + step, ...` (`count` of them) of row `y`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    pub y: u32,
    pub x0: u32,
    pub step: u32,
    pub count: u32,
}

impl Span {
    pub fn xs(self) -> impl Iterator<Item = u32> {
        (0..self.count).map(move |k| self.x0 + k * self.step)
    }
}

/// Rendered pixels: spans and their linear RGBA values, span after span.
#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    pub spans: Vec<Span>,
    pub rgba: Vec<f32>,
    /// One depth per pixel, in the same order, when the render was asked for depth (else empty).
    pub depth: Vec<f32>,
}

impl Chunk {
    pub fn pixels(&self) -> u64 {
        self.spans.iter().map(|s| s.count as u64).sum()
    }
}

/// Rows of `T` pixels in the caller's memory: pixel (x, y) is `data[y * row_stride + x]`. What
/// lies between rows (`row_stride` past the width) is never touched.
pub struct Plane<'a, T> {
    pub data: &'a mut [T],
    /// Elements from the start of one row to the start of the next; at least the image width.
    pub row_stride: usize,
}

impl<'a, T> Plane<'a, T> {
    pub fn new(data: &'a mut [T], row_stride: usize) -> Plane<'a, T> {
        Plane { data, row_stride }
    }

    /// Whether a `width`×`height` image fits, as a sentence naming the sizes when it does not.
    fn check(&self, what: &str, width: u32, height: u32) -> Result<(), String> {
        let (w, stride) = (width as usize, self.row_stride);
        if stride < w {
            return Err(format!(
                "the {what} plane's row stride is {stride} pixels, less than the image width {width}"
            ));
        }
        let need = (height as usize - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(w));
        match need {
            Some(n) if n <= self.data.len() => Ok(()),
            Some(n) => Err(format!(
                "the {what} plane holds {} pixels; a {width}x{height} image with a row stride of \
                 {stride} needs {n}",
                self.data.len()
            )),
            None => Err(format!(
                "the {what} plane: a {width}x{height} image with a row stride of {stride} is \
                 larger than memory"
            )),
        }
    }

    fn at(&mut self, x: u32, y: u32) -> &mut T {
        &mut self.data[y as usize * self.row_stride + x as usize]
    }
}

/// The colour a [`Target`] receives.
pub enum Color<'a> {
    /// RGB through the sRGB curve and alpha linear, 8 bits each: the PNG writer's bytes.
    Rgba8Srgb(Plane<'a, [u8; 4]>),
    /// The linear values the renderer computes (alpha is 1, as in image files).
    Rgba32fLinear(Plane<'a, [f32; 4]>),
    /// No colour (depth only).
    None,
}

/// Where a render's pixels go when the caller owns the memory: the chunks are written straight
/// into its planes as they finish, and no image of the renderer's own is allocated.
pub struct Target<'a> {
    pub width: u32,
    pub height: u32,
    pub color: Color<'a>,
    /// Per pixel, the distance along its primary rays from where they start (the eye, a lens
    /// point, an orthographic camera's image plane) to the nearest surface they hit;
    /// [`f32::INFINITY`] where none does (see `integrator::render_depth`).
    pub depth: Option<Plane<'a, f32>>,
}

impl Target<'_> {
    /// Whether every plane holds the image: strides at least the width and
    /// `(height − 1) · stride + width` elements (without overflow).
    pub fn check(&self) -> Result<(), String> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 {
            return Err(format!(
                "the target is {w}x{h} pixels; expected at least 1x1"
            ));
        }
        match &self.color {
            Color::Rgba8Srgb(p) => p.check("RGBA8", w, h)?,
            Color::Rgba32fLinear(p) => p.check("RGBA f32", w, h)?,
            Color::None => {}
        }
        match &self.depth {
            Some(p) => p.check("depth", w, h),
            None => Ok(()),
        }
    }

    /// Converts a chunk's pixels into the planes, at the places its spans say. The target must
    /// have passed [`Target::check`] and hold the chunk's spans.
    pub fn put_chunk(&mut self, c: &Chunk) {
        let mut k = 0;
        for s in &c.spans {
            for x in s.xs() {
                if let Some(px) = c.rgba.get(4 * k..4 * k + 4) {
                    let px = [px[0], px[1], px[2], px[3]];
                    match &mut self.color {
                        Color::Rgba8Srgb(p) => *p.at(x, s.y) = rgba8(px),
                        Color::Rgba32fLinear(p) => *p.at(x, s.y) = px,
                        Color::None => {}
                    }
                }
                if let (Some(p), Some(&d)) = (&mut self.depth, c.depth.get(k)) {
                    *p.at(x, s.y) = d;
                }
                k += 1;
            }
        }
    }
}

/// A linear RGBA pixel as the PNG writer stores it in 8 bits: RGB through the sRGB curve,
/// alpha linear, each clamped to [0, 1] (NaN as 0) and rounded (`ppm::srgb8`'s formula for the
/// colour; a test keeps them equal).
pub fn rgba8(px: [f32; 4]) -> [u8; 4] {
    let q = |v: f32| (v * 255.0).round() as u8;
    let alpha = if px[3].is_nan() {
        0.0
    } else {
        px[3].clamp(0.0, 1.0)
    };
    let t = luxon_plugin::srgb8::tables();
    [t.sample(px[0]), t.sample(px[1]), t.sample(px[2]), q(alpha)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn put_chunk_places_runs_and_strided_spans() {
        let mut fb = Framebuffer::new(5, 3);
        let px = |k: usize| [k as f32, 0.5, 0.25, 1.0];
        let spans = vec![
            Span {
                y: 1,
                x0: 1,
                step: 1,
                count: 3,
            },
            Span {
                y: 2,
                x0: 0,
                step: 2,
                count: 3,
            },
        ];
        let rgba: Vec<f32> = (0..6).flat_map(px).collect();
        fb.put_chunk(&Chunk {
            spans,
            rgba,
            depth: Vec::new(),
        });
        let zero = [0.0; 4];
        for (x, y, want) in [
            (0, 1, zero),
            (1, 1, px(0)),
            (2, 1, px(1)),
            (3, 1, px(2)),
            (4, 1, zero),
            (0, 2, px(3)),
            (1, 2, zero),
            (2, 2, px(4)),
            (4, 2, px(5)),
            (0, 0, zero),
        ] {
            assert_eq!(fb.pixel(x, y), want, "pixel ({x}, {y})");
        }
        // A chunk with fewer values than its spans name fills what it has.
        let mut fb = Framebuffer::new(4, 1);
        let spans = vec![Span {
            y: 0,
            x0: 0,
            step: 1,
            count: 4,
        }];
        let rgba: Vec<f32> = (0..2).flat_map(px).collect();
        fb.put_chunk(&Chunk {
            spans,
            rgba,
            depth: Vec::new(),
        });
        assert_eq!(fb.pixel(1, 0), px(1));
        assert_eq!(fb.pixel(2, 0), zero);
    }
}
