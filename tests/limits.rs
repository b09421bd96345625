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

/// A 256³ u8 raw volume of random bytes (16 MiB), written by the test.
fn random_u8_volume(dir: &std::path::Path) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let bytes: Vec<u8> = (0..256 * 256 * 256)
        .map(|_| {
            // xorshift64*: every brick varies, so none collapses.
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 56) as u8
        })
        .collect();
    std::fs::write(dir.join("noise.raw"), bytes).unwrap();
    std::fs::write(
        dir.join("v.ron"),
        r#"Scene(
    camera: (position: (0, 0, -2000), look_at: (0, 0, 0)),
    volumes: [(plugin: "raw", name: "noise", params: (file: "noise.raw", dims: (256, 256, 256), origin: (-128, -128, -128)),
               render: (transfer: (preset: "grayscale")))],
    render: (width: 16, height: 16),
)"#,
    )
    .unwrap();
}

/// A u8 volume is stored a byte per voxel (u8 bricks), not as f32: `check` reports its bricks
/// and a size near the voxel count, and a render fits a limit that f32 bricks (64 MiB) would
/// not.
#[test]
fn a_u8_volume_costs_a_byte_per_voxel() {
    let dir = temp_dir("limits-u8-volume");
    random_u8_volume(&dir);
    let voxels = 256u64 * 256 * 256;
    let out = run_limited(&["check", "v.ron"], &dir, 512 << 20, 120);
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(out.status.code(), Some(0), "{}{text}", stderr(&out));
    let line = text
        .lines()
        .find(|l| l.starts_with("volume     `noise` (raw)"))
        .unwrap_or_else(|| panic!("no volume line in:\n{text}"));
    assert!(line.ends_with("(bricks: 32768 u8)"), "{line}");
    let mib: f64 = line
        .split(", ")
        .find_map(|part| part.split_once(" MiB").map(|(n, _)| n.parse().unwrap()))
        .unwrap_or_else(|| panic!("no size in {line}"));
    assert!(
        mib * 1024.0 * 1024.0 <= 1.1 * voxels as f64 + 16.0 * 1024.0 * 1024.0,
        "{line}"
    );

    let out = run_limited(
        &["render", "v.ron", "-o", "v.png", "--threads", "2"],
        &dir,
        (288 << 20) + voxels,
        120,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(dir.join("v.png").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}
