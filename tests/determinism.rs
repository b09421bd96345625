//! Images are bitwise identical whatever the thread count and tile size.

mod common;

use common::*;

fn render(name: &str, threads: u32, tile: u32) -> Vec<f32> {
    render_with(&root().join("scenes").join(format!("{name}.ron")), |d| {
        d.render.width = 97;
        d.render.height = 61;
        d.render.parallel.threads = Some(threads);
        d.render.parallel.tile_size = tile;
    })
    .rgba
}

#[test]
fn one_and_two_threads_and_any_tile_size_agree_bitwise() {
    for name in ["glass", "torus", "antialiasing"] {
        let one = render(name, 1, 16);
        let two = render(name, 2, 16);
        let odd_tiles = render(name, 3, 7);
        assert!(one.iter().any(|&v| v > 0.05), "{name}: image is black");
        let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same(&one, &two), "{name}: 1 vs 2 threads differ");
        assert!(
            same(&one, &odd_tiles),
            "{name}: tile size changes the image"
        );
    }
}
