//! Volumes read through the real `raw` plugin: values across bricks, statistics, errors at scene
//! positions, and the real MRI head data set when it is available.

mod common;
use common::*;

use luxon::plugin::read_volume;
use luxon::plugin::PluginKind;

use std::path::{Path, PathBuf};

/// The known value of voxel (x, y, z) in the 10x7x5 test grid.
fn known(x: i64, y: i64, z: i64) -> u16 {
    (1000 + x + 10 * y + 100 * z) as u16
}

/// A 10x7x5 u16 big-endian file with `known` values (700 bytes).
fn write_grid(dir: &Path) -> PathBuf {
    let mut bytes = Vec::new();
    for z in 0..5 {
        for y in 0..7 {
            for x in 0..10 {
                bytes.extend(known(x, y, z).to_be_bytes());
            }
        }
    }
    let path = dir.join("grid.raw");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn raw_u16_big_endian_values_across_bricks() {
    let dir = temp_dir("volume-u16");
    write_grid(&dir);
    let desc = volume_scene(
        &dir,
        r#"        (plugin: "raw", name: "grid", params: (file: "grid.raw", dims: (10, 7, 5), format: "u16", endian: "big", normalize: false, spacing: (0.5, 0.5, 2), origin: (1, 2, 3))),
        (plugin: "raw", params: (file: "grid.raw", dims: (10, 7, 5), format: "u16", endian: "big")),"#,
    );
    let reg = registry(&desc);
    let v = read_volume_of(&desc, &reg, 0).unwrap_or_else(|(at, m)| panic!("{at}: {m}"));

    assert_eq!(v.name, "grid");
    assert_eq!(v.grid_name, "grid.raw");
    assert_eq!(v.plugin, "raw");
    assert_eq!(v.index_min, [0, 0, 0]);
    assert_eq!(v.index_max, [9, 6, 4]);
    assert_eq!(v.background, 0.0);
    assert_eq!(
        v.world_from_index,
        [0.5, 0., 0., 1., 0., 0.5, 0., 2., 0., 0., 2., 3.]
    );
    assert_eq!(v.index_to_world([2.0, 4.0, 1.0]), [2.0, 4.0, 5.0]);

    // Corners, both sides of the brick boundary at x = 8, and inner voxels.
    for ijk in [
        [0, 0, 0],
        [7, 0, 0],
        [8, 0, 0],
        [9, 6, 4],
        [7, 6, 4],
        [8, 3, 2],
        [3, 5, 1],
        [9, 0, 4],
    ] {
        let want = f32::from(known(ijk[0], ijk[1], ijk[2]));
        assert_eq!(v.value(ijk), want, "voxel {ijk:?}");
    }
    // Every voxel, to be sure nothing is misplaced.
    for z in 0..5 {
        for y in 0..7 {
            for x in 0..10 {
                assert_eq!(v.value([x, y, z]), f32::from(known(x, y, z)));
            }
        }
    }
    // Outside the data: the background, also inside a stored brick (x = 10..15 of brick 1).
    for ijk in [
        [-1, 0, 0],
        [10, 0, 0],
        [15, 6, 4],
        [0, 7, 0],
        [0, 0, 5],
        [0, -1, 0],
        [0, 0, -8],
        [i64::MAX, i64::MIN, 0],
    ] {
        assert_eq!(v.value(ijk), 0.0, "voxel {ijk:?}");
    }

    assert_eq!(v.voxel_count(), 10 * 7 * 5);
    assert_eq!(v.min_max(), (1000.0, f32::from(known(9, 6, 4))));
    // 10 x 7 x 5 voxels touch two bricks, both with varying values.
    assert_eq!(v.brick_counts(), (2, 0));
    // Both kept as u16 (the background 0 has a code, so the partial bricks stay u16).
    assert_eq!(v.dense_counts(), [0, 2, 0]);
    assert!(v.memory_bytes() >= 2 * 512 * 2, "{}", v.memory_bytes());

    // The second volume: normalised by default, unnamed, default transform.
    let w = read_volume_of(&desc, &reg, 1).unwrap_or_else(|(at, m)| panic!("{at}: {m}"));
    assert_eq!(w.name, "volume 1");
    assert_eq!(w.value([9, 6, 4]), f32::from(known(9, 6, 4)) / 65535.0);
    assert_eq!(
        w.world_from_index,
        [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn size_mismatch_is_reported_at_the_params() {
    let dir = temp_dir("volume-size");
    let path = write_grid(&dir);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes.pop();
    std::fs::write(&path, bytes).unwrap();
    let desc = volume_scene(
        &dir,
        "        (plugin: \"raw\",\n         params: (file: \"grid.raw\", dims: (10, 7, 5), format: \"u16\")),",
    );
    let reg = registry(&desc);
    let (at, message) = read_volume_of(&desc, &reg, 0).unwrap_err();
    // The params start on line 5, column 18 of scene.ron.
    assert_eq!(*at.file, dir.join("scene.ron"));
    assert_eq!((at.line, at.col), (5, 18));
    assert_eq!(
        (at.line, at.col),
        (
            desc.volumes[0].value.call.params_at.line,
            desc.volumes[0].value.call.params_at.col
        )
    );
    assert!(message.starts_with("plugin `raw` ("), "{message}");
    assert!(
        message.contains(
            "expected 700 bytes for 10x7x5 u16 voxels plus a 0-byte header, the file has 699"
        ),
        "{message}"
    );
    assert!(message.contains(&path.display().to_string()), "{message}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn plugin_errors_inside_params_point_into_the_scene() {
    let dir = temp_dir("volume-params");
    write_grid(&dir);
    let desc = volume_scene(
        &dir,
        "        (plugin: \"raw\", params: (\n            file: \"grid.raw\",\n            dims: (10, 7, 5),\n            format: \"u32\",\n        )),",
    );
    let reg = registry(&desc);
    let (at, message) = read_volume_of(&desc, &reg, 0).unwrap_err();
    // `format: "u32"` is on line 7 of scene.ron (line 4 of the params text).
    assert_eq!(at.line, 7, "{at}: {message}");
    assert!(
        message.contains("unknown format \"u32\"; expected one of \"u8\", \"u16\", \"f32\""),
        "{message}"
    );

    // A missing file names the path it resolved to (against the scene's directory).
    let desc = volume_scene(
        &dir,
        "        (plugin: \"raw\", params: (file: \"sub/missing.raw\", dims: (1, 1, 1))),",
    );
    let (_, message) = read_volume_of(&desc, &reg, 0).unwrap_err();
    assert!(
        message.contains(&format!(
            "volume file `{}` does not exist",
            dir.join("sub/missing.raw").display()
        )),
        "{message}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn only_volume_readers_are_called() {
    let dir = temp_dir("volume-kind");
    let desc = volume_scene(&dir, "        (plugin: \"sphere\"),");
    let reg = registry(&desc);
    let call = &desc.volumes[0].value.call;
    let e = reg
        .get(&call.plugin.value, PluginKind::VolumeReader)
        .unwrap_err();
    assert!(e.to_string().contains("volume reader"), "{e}");
    // Even if a caller looked it up as something else, it is not called as a reader.
    let sphere = reg.get("sphere", PluginKind::Primitive).unwrap();
    let (at, message) = read_volume(
        &reg,
        sphere,
        &call.params,
        &call.params_at,
        &dir,
        "volume 0",
        &std::sync::Arc::new(luxon::budget::Budget::unlimited()),
    )
    .unwrap_err();
    assert_eq!(at, call.params_at);
    assert!(
        message.contains("is a primitive, but a volume reader is expected"),
        "{message}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The MRI head of the Chapel Hill data sets (../shared/volumes), decompressed with gzip.
#[test]
fn real_mri_head() {
    let gz = root().join("../shared/volumes/mri-head-256x256x109-u8.raw.gz");
    if !gz.is_file() {
        println!("SKIPPED real_mri_head: {} is not available", gz.display());
        return;
    }
    let dir = temp_dir("volume-mri");
    let raw = dir.join("head.raw");
    let out = std::fs::File::create(&raw).unwrap();
    let status = std::process::Command::new("gzip")
        .arg("-dc")
        .arg(&gz)
        .stdout(out)
        .status()
        .expect("cannot run gzip");
    assert!(status.success(), "gzip -dc {} failed", gz.display());
    let bytes = std::fs::read(&raw).unwrap();
    assert_eq!(bytes.len(), 256 * 256 * 109);

    let desc = volume_scene(
        &dir,
        r#"        (plugin: "raw", name: "head", params: (file: "head.raw", dims: (256, 256, 109), spacing: (1, 1, 2))),"#,
    );
    let reg = registry(&desc);
    let v = read_volume_of(&desc, &reg, 0).unwrap_or_else(|(at, m)| panic!("{at}: {m}"));
    assert_eq!(v.voxel_count(), 256 * 256 * 109);
    assert_eq!(v.index_max, [255, 255, 108]);
    assert_eq!(v.min_max(), (0.0, 1.0));

    let byte = |x: usize, y: usize, z: usize| bytes[(z * 256 + y) * 256 + x];
    for [x, y, z] in [
        [128, 128, 54],
        [100, 150, 30],
        [7, 8, 15],
        [8, 8, 16],
        [255, 255, 108],
        [60, 120, 80],
    ] {
        let want = f32::from(byte(x, y, z)) / 255.0;
        assert_eq!(
            v.value([x as i64, y as i64, z as i64]),
            want,
            "voxel {x} {y} {z}"
        );
    }
    // The centre of the head is tissue, not air.
    assert!(v.value([128, 128, 54]) > 0.0);
    // Every voxel matches the file.
    for z in 0..109 {
        for y in 0..256 {
            for x in 0..256 {
                let want = f32::from(byte(x, y, z)) / 255.0;
                assert_eq!(v.value([x as i64, y as i64, z as i64]), want);
            }
        }
    }
    assert_eq!(v.value([256, 0, 0]), 0.0);
    assert_eq!(v.value([0, 0, 109]), 0.0);

    // Air around the head (the background, 0) is not stored at all, so fewer bricks than the
    // 32 x 32 x 14 of the grid are, and the volume is smaller than its bricks stored densely.
    let (dense, constant) = v.brick_counts();
    assert!(dense + constant < 32 * 32 * 14, "{dense} + {constant}");
    // The bytes are kept as bytes: every dense brick is u8, and the volume costs about the
    // file's size (f32 bricks would take four times as much).
    assert_eq!(v.dense_counts(), [dense, 0, 0]);
    let voxels = 256 * 256 * 109;
    assert!(
        v.memory_bytes() < voxels * 11 / 10 + (1 << 20),
        "{}",
        v.memory_bytes()
    );
    println!(
        "MRI head: {dense} dense and {constant} constant bricks, {} MiB",
        v.memory_bytes() >> 20
    );
    let _ = std::fs::remove_dir_all(&dir);
}
