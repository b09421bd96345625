//! The `image_texture` fuzz target's body (tests/fuzz), run over its seeds and the shipped
//! images, so the normal test suite exercises it; and inputs it once failed on.

use std::path::{Path, PathBuf};

#[path = "../../../tests/fuzz/image_texture_body.rs"]
mod image_texture;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn image_texture_target_over_its_seeds() {
    let seeds = root().join("tests/fuzz/seeds/image_texture");
    let mut inputs = Vec::new();
    for dir in [seeds.clone(), root().join("scenes/textures")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                inputs.push(path);
            }
        }
    }
    assert!(inputs.len() > 15, "{inputs:?}");
    for path in &inputs {
        // Ok or an error: the body itself asserts the cap, the sizes and finite texels.
        let _ = image_texture::run(&std::fs::read(path).unwrap());
    }
    let seed = |name: &str| image_texture::run(&std::fs::read(seeds.join(name)).unwrap());
    for ok in [
        "rgba8.png",
        "rgb16.png",
        "grey8.png",
        "greya16.png",
        "grey2.png",
        "palette-trns.png",
        "interlaced.png",
        "photo.jpg",
        "grey.jpg",
        "t.tga",
        "rgba.tga",
        "t.ppm",
        "g.pgm",
        "t16.ppm",
        "hdr.exr",
    ] {
        let levels = seed(ok).unwrap_or_else(|e| panic!("{ok}: {e}"));
        assert!(levels[0].width > 1, "{ok}: used at full size");
    }
    let e = seed("liar-65535.png").unwrap_err();
    assert!(e.contains("not have enough data"), "{e}");
    let e = seed("liar-16000.jpg").unwrap_err();
    assert!(
        e.contains("(16000x16000 JPEG) needs 732.4 MiB to decode, more than the texture memory cap of 64.0 MiB"),
        "{e}"
    );
    assert!(seed("truncated.png").is_err());
}
