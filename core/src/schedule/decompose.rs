//! Which pixels each worker renders. Static decompositions (the thesis's pixel-, scanline- and
//! block-cyclic) deal units round-robin to `workers` workers numbered across every rank; the
//! dynamic one cuts the image into tiles that are handed out on demand.

use crate::framebuffer::Span;
use luxon_formats::Decomposition;

/// A rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
}

impl Rect {
    pub fn spans(&self) -> Vec<Span> {
        (self.y0..self.y0 + self.h)
            .map(|y| Span {
                y,
                x0: self.x0,
                step: 1,
                count: self.w,
            })
            .collect()
    }
}

/// `size`×`size` tiles (smaller at the right and bottom edges), row-major.
pub fn tiles(width: u32, height: u32, size: u32) -> Vec<Rect> {
    let size = size.max(1);
    let mut v = Vec::new();
    for y0 in (0..height).step_by(size as usize) {
        for x0 in (0..width).step_by(size as usize) {
            v.push(Rect {
                x0,
                y0,
                w: size.min(width - x0),
                h: size.min(height - y0),
            });
        }
    }
    v
}

/// The units of work of static worker `worker` of `workers`, in order; each unit is a list of
/// spans rendered and delivered together. `Dynamic` has no static share: it yields nothing.
pub fn static_units(
    width: u32,
    height: u32,
    how: Decomposition,
    block: u32,
    worker: usize,
    workers: usize,
) -> Box<dyn Iterator<Item = Vec<Span>> + Send> {
    let (g, n) = (worker as u64, workers.max(1) as u64);
    match how {
        Decomposition::PixelCyclic => Box::new((0..height).filter_map(move |y| {
            // Pixel i = y * width + x belongs to worker i mod n.
            let first = (g as i64 - (y as u64 * width as u64) as i64).rem_euclid(n as i64) as u64;
            (first < width as u64).then(|| {
                let count = (width as u64 - 1 - first) / n + 1;
                vec![Span {
                    y,
                    x0: first as u32,
                    step: n.min(u32::MAX as u64) as u32,
                    count: count as u32,
                }]
            })
        })),
        Decomposition::ScanlineCyclic => {
            Box::new((g..height as u64).step_by(n as usize).map(move |y| {
                vec![Span {
                    y: y as u32,
                    x0: 0,
                    step: 1,
                    count: width,
                }]
            }))
        }
        Decomposition::BlockCyclic => {
            let blocks = tiles(width, height, block);
            Box::new(
                (g as usize..blocks.len())
                    .step_by(n as usize)
                    .map(move |b| blocks[b].spans()),
            )
        }
        Decomposition::Dynamic => Box::new(std::iter::empty()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel is covered exactly once over all workers.
    fn covers_once(how: Decomposition, w: u32, h: u32, block: u32, workers: usize) {
        let mut seen = vec![0u32; (w * h) as usize];
        for g in 0..workers {
            for unit in static_units(w, h, how, block, g, workers) {
                for s in unit {
                    for x in s.xs() {
                        seen[(s.y * w + x) as usize] += 1;
                    }
                }
            }
        }
        assert!(
            seen.iter().all(|&c| c == 1),
            "{how:?} {w}x{h} block {block} over {workers}"
        );
    }

    #[test]
    fn static_decompositions_cover_every_pixel_once() {
        for how in [
            Decomposition::PixelCyclic,
            Decomposition::ScanlineCyclic,
            Decomposition::BlockCyclic,
        ] {
            for (w, h) in [(37, 20), (1, 1), (5, 3), (64, 64)] {
                for workers in [1, 2, 3, 7, 100] {
                    for block in [1, 4, 16] {
                        covers_once(how, w, h, block, workers);
                    }
                }
            }
        }
    }

    #[test]
    fn pixel_cyclic_deals_neighbours_to_different_workers() {
        let a: Vec<_> = static_units(4, 2, Decomposition::PixelCyclic, 1, 0, 3).collect();
        // Pixels 0, 3, 6 of a 4-wide image: (0,0), (3,0), (2,1).
        assert_eq!(a.len(), 2);
        assert_eq!((a[0][0].x0, a[0][0].step, a[0][0].count), (0, 3, 2));
        assert_eq!((a[1][0].y, a[1][0].x0, a[1][0].count), (1, 2, 1));
    }

    #[test]
    fn tiles_cover_the_image_once() {
        let t = tiles(37, 20, 16);
        let area: u32 = t.iter().map(|t| t.w * t.h).sum();
        assert_eq!(area, 37 * 20);
        assert_eq!(t.len(), 3 * 2);
    }
}
