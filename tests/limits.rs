//! Memory in proportion to the scene's content, not to what a file claims or decompresses to:
//! checked by running `luxon` under an address-space limit (`common::limits::run_limited`).
#![cfg(target_os = "linux")]

mod common;

use common::limits::run_limited;
use common::*;
use std::io::Write;

/// A 512³ u8 raw volume of zeros as a gzip file of 16 identical members (about 400 KB): 128 MiB
/// once decompressed, and entirely background. It used to cost the whole decompressed file (held
/// at once) plus 512 MiB of f32 bricks; now the reader streams slabs of 8 slices and the host
/// stores no background brick, so the render fits in little more than a tiny one needs.
#[test]
fn an_empty_gzip_volume_renders_in_little_memory() {
    let dir = temp_dir("limits-empty-volume");
    let mut member = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    member.write_all(&vec![0u8; 8 << 20]).unwrap();
    let member = member.finish().unwrap();
    let mut file = std::fs::File::create(dir.join("zeros.raw.gz")).unwrap();
    for _ in 0..16 {
        file.write_all(&member).unwrap();
    }
    drop(file);
    std::fs::write(
        dir.join("v.ron"),
        r#"Scene(
    camera: (position: (0, 0, -3000), look_at: (0, 0, 0)),
    volumes: [(plugin: "raw", params: (file: "zeros.raw.gz", dims: (512, 512, 512), origin: (-256, -256, -256)))],
    render: (width: 16, height: 16),
)"#,
    )
    .unwrap();
    let out = run_limited(
        &["render", "v.ron", "-o", "v.png", "--threads", "2"],
        &dir,
        288 << 20,
        120,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("v.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An RGB 8-bit PNG of zeros whose header says `w × h` but whose data holds only `rows` rows
/// (all of them when `rows == h`), compressed row by row: a 16000² file is about 750 KB.
fn zero_png(path: &std::path::Path, w: u32, h: u32, rows: u32) {
    let chunk = |out: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        out.extend((data.len() as u32).to_be_bytes());
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        out.extend(kind);
        out.extend(data);
        out.extend(crc.sum().to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    let row = vec![0u8; 1 + 3 * w as usize];
    for _ in 0..rows {
        z.write_all(&row).unwrap();
    }
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut png, b"IHDR", &ihdr);
    chunk(&mut png, b"IDAT", &z.finish().unwrap());
    chunk(&mut png, b"IEND", &[]);
    std::fs::write(path, png).unwrap();
}

/// A sphere with an image texture, rendered 32×32 to `t.png`.
fn texture_scene(dir: &std::path::Path, image: &str) {
    std::fs::write(
        dir.join("t.ron"),
        format!(
            r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    lights: [Point(position: (0, 5, -5))],
    textures: {{ "img": (plugin: "image", params: (file: "{image}", mapping: spherical, center: (0, 0, 0))) }},
    materials: {{ "m": (texture: "img") }},
    objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1), material: "m")],
    render: (width: 32, height: 32),
)"#
        ),
    )
    .unwrap();
}

/// A 16000² PNG (750 KB) used to be decoded whole, copied twice and MIP-mapped in float: about
/// 7 GB for a 32×32 render, an abort under a memory limit. Now it is streamed row by row and
/// only the MIP levels that fit the decode cap (1 GiB by default) are kept: from 4000×4000 on,
/// 341 MB, with a warning.
#[test]
fn a_huge_png_texture_is_decoded_within_the_cap() {
    let dir = temp_dir("limits-huge-png");
    zero_png(&dir.join("big.png"), 16000, 16000, 16000);
    texture_scene(&dir, "big.png");
    let out = run_limited(
        &["render", "t.ron", "-o", "t.png", "--threads", "2"],
        &dir,
        700 << 20,
        300,
    );
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{e}");
    assert!(
        e.contains("image `big.png` (16000x16000) is decoded at 4000x4000 to stay within the texture memory cap of 1.0 GiB"),
        "{e}"
    );
    assert!(dir.join("t.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A PNG whose header claims 65535² texels but holds two rows: an error naming the file, and
/// nothing allocated for what the header claims (levels are allocated as their rows arrive).
#[test]
fn a_png_header_that_lies_fails_the_render_without_allocating() {
    let dir = temp_dir("limits-lying-png");
    zero_png(&dir.join("liar.png"), 65535, 65535, 2);
    texture_scene(&dir, "liar.png");
    let out = run_limited(
        &["render", "t.ron", "-o", "t.png", "--threads", "2"],
        &dir,
        288 << 20,
        120,
    );
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("cannot decode image") && e.contains("liar.png"),
        "{e}"
    );
    assert!(!dir.join("t.png").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
