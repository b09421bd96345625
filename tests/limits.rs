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
