//! The image being rendered: linear RGBA f32, rows top to bottom; and the pieces it arrives in
//! from the render threads (spans of pixels, and chunks: spans with their values).

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
        let (rgba, charge) = budget.alloc_vec(Use::Image, n, 0.0f32, what)?;
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
        let mut src = c.rgba.chunks_exact(4);
        for s in &c.spans {
            let row = s.y as usize * self.width as usize;
            for x in s.xs() {
                let i = (row + x as usize) * 4;
                if let Some(px) = src.next() {
                    self.rgba[i..i + 4].copy_from_slice(px);
                }
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
}

impl Chunk {
    pub fn pixels(&self) -> u64 {
        self.spans.iter().map(|s| s.count as u64).sum()
    }
}
