//! Images are bitwise identical whatever the thread count, tile size and decomposition.

mod common;

use common::*;
use luxon_formats::Decomposition;

fn render(name: &str, threads: u32, tile: u32, how: Decomposition) -> Vec<f32> {
    render_with(&root().join("scenes").join(format!("{name}.ron")), |d| {
        d.render.width = 97;
        d.render.height = 61;
        d.render.parallel.threads = Some(threads);
        d.render.parallel.tile_size = tile;
        d.render.parallel.decomposition = how;
    })
    .rgba
}

fn same(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn one_and_two_threads_and_any_tile_size_agree_bitwise() {
    for name in [
        "glass",
        "torus",
        "antialiasing",
        "phantom",
        "volume-geometry",
    ] {
        let one = render(name, 1, 16, Decomposition::Dynamic);
        let two = render(name, 2, 16, Decomposition::Dynamic);
        let odd_tiles = render(name, 3, 7, Decomposition::Dynamic);
        assert!(one.iter().any(|&v| v > 0.05), "{name}: image is black");
        assert!(same(&one, &two), "{name}: 1 vs 2 threads differ");
        assert!(
            same(&one, &odd_tiles),
            "{name}: tile size changes the image"
        );
    }
}

#[test]
fn every_decomposition_agrees_bitwise() {
    for name in ["glass", "torus"] {
        let reference = render(name, 1, 16, Decomposition::Dynamic);
        for how in [
            Decomposition::PixelCyclic,
            Decomposition::ScanlineCyclic,
            Decomposition::BlockCyclic,
        ] {
            for (threads, block) in [(1, 16), (2, 5), (3, 16)] {
                let img = render(name, threads, block, how);
                assert!(
                    same(&reference, &img),
                    "{name}: {how:?} on {threads} threads (block {block}) differs"
                );
            }
        }
    }
}

#[test]
fn adaptive_supersampling_agrees_bitwise() {
    let adaptive = |d: &mut luxon_formats::SceneDesc| {
        d.render.samples = 4;
        d.render.adaptive = Some(luxon_formats::AdaptiveDesc {
            threshold: 0.05,
            max_depth: 2,
        });
    };
    for name in ["antialiasing", "glass"] {
        let path = root().join("scenes").join(format!("{name}.ron"));
        let img = |threads, tile, how| {
            render_with(&path, |d| {
                adaptive(d);
                d.render.width = 61;
                d.render.height = 43;
                d.render.parallel.threads = Some(threads);
                d.render.parallel.tile_size = tile;
                d.render.parallel.decomposition = how;
            })
            .rgba
        };
        let one = img(1, 16, Decomposition::Dynamic);
        assert!(one.iter().any(|&v| v > 0.05), "{name}: image is black");
        for (threads, tile, how) in [
            (2, 16, Decomposition::Dynamic),
            (3, 5, Decomposition::Dynamic),
            (2, 3, Decomposition::PixelCyclic),
            (3, 4, Decomposition::BlockCyclic),
        ] {
            assert!(
                same(&one, &img(threads, tile, how)),
                "{name}: adaptive on {threads} threads, {how:?} (tile {tile}) differs"
            );
        }
    }
}

/// Motion blur: the carousel (keyed camera, objects turning and bouncing) and the water
/// trajectory (a series blended between its data frames) under an open shutter, at a frame
/// inside their range: the same bits on any thread count, tile size and decomposition.
#[test]
fn blurred_animations_agree_bitwise() {
    let blurred = |name: &str, frame: u32, threads: u32, tile: u32, how: Decomposition| {
        let mut desc = luxon_formats::load(&root().join("scenes").join(format!("{name}.ron")))
            .unwrap_or_else(|e| panic!("{e}"));
        let a = desc.animation.as_mut().unwrap();
        a.value.shutter = Some(luxon_formats::Spanned {
            value: luxon_formats::ShutterDesc {
                length: 0.5,
                at: luxon_formats::ShutterAt::Centre,
            },
            at: a.at.clone(),
        });
        desc.render.width = 61;
        desc.render.height = 43;
        desc.render.samples = 2;
        desc.render.parallel.threads = Some(threads);
        desc.render.parallel.tile_size = tile;
        desc.render.parallel.decomposition = how;
        let mut scene = luxon::Scene::build(&desc, &registry(&desc)).unwrap();
        assert!(scene.features.motion_blur, "{name}");
        scene.set_frame(frame).unwrap();
        luxon::render::render(&scene, &|_, _| {}).unwrap().0.rgba
    };
    for (name, frame) in [("carousel", 5), ("trajectory/water", 1)] {
        let one = blurred(name, frame, 1, 16, Decomposition::Dynamic);
        assert!(one.iter().any(|&v| v > 0.05), "{name}: image is black");
        for (threads, tile, how) in [
            (2, 16, Decomposition::Dynamic),
            (3, 7, Decomposition::Dynamic),
            (2, 5, Decomposition::PixelCyclic),
            (2, 16, Decomposition::ScanlineCyclic),
            (3, 4, Decomposition::BlockCyclic),
        ] {
            assert!(
                same(&one, &blurred(name, frame, threads, tile, how)),
                "{name}: blurred on {threads} threads, {how:?} (tile {tile}) differs"
            );
        }
    }
}
