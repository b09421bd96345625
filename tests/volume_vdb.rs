//! OpenVDB volumes read through the real `vdb` plugin and the host: values as OpenVDB stores
//! them (fog, level set, half floats), `luxon check`, and errors at the scene's parameters.

mod common;
use common::*;

use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    root().join("plugins/volume-vdb/tests/fixtures").join(name)
}

/// The host's volume holds, voxel for voxel, what the parser reads (which the plugin's own tests
/// compare with OpenVDB): every leaf voxel, and the background elsewhere.
#[test]
fn vdb_volumes_match_the_parser_voxel_by_voxel() {
    let dir = temp_dir("vdb-values");
    for f in ["fog_sphere.vdb", "half.vdb", "level_set.vdb", "masks.vdb"] {
        std::fs::copy(fixture(f), dir.join(f)).unwrap();
    }
    let desc = volume_scene(
        &dir,
        r#"        (plugin: "vdb", name: "fog", params: (file: "fog_sphere.vdb")),
        (plugin: "vdb", params: (file: "half.vdb", grid: "density")),
        (plugin: "vdb", name: "surface", params: (file: "level_set.vdb")),
        (plugin: "vdb", params: (file: "masks.vdb", grid: "masks_half")),"#,
    );
    let reg = registry(&desc);
    for (i, (file, grid)) in [
        ("fog_sphere.vdb", None),
        ("half.vdb", None),
        ("level_set.vdb", None),
        ("masks.vdb", Some("masks_half")),
    ]
    .into_iter()
    .enumerate()
    {
        let v = read_volume_of(&desc, &reg, i).unwrap_or_else(|(at, m)| panic!("{at}: {m}"));
        let bytes = std::fs::read(fixture(file)).unwrap();
        let g = luxon_volume_vdb::read_grid(&bytes, grid).unwrap();
        assert_eq!(v.plugin, "vdb");
        assert_eq!(v.grid_name, g.name);
        assert_eq!(v.background, g.background);
        assert_eq!(v.world_from_index, g.world_from_index);
        let (lo, hi) = g.index_box().unwrap();
        assert_eq!((v.index_min, v.index_max), (lo, hi), "{file}");
        assert_eq!(v.voxel_count(), 512 * g.leaves.len() as u64, "{file}");
        // Every voxel of the box and a margin around it.
        for z in lo[2] - 2..=hi[2] + 2 {
            for y in lo[1] - 2..=hi[1] + 2 {
                for x in lo[0] - 2..=hi[0] + 2 {
                    let want = g.value([x, y, z].map(|c| c as i32)).0;
                    assert_eq!(v.value([x, y, z]), want, "{file}: voxel {x} {y} {z}");
                }
            }
        }
    }
    // The level set: minus the background inside (index centre 16, 16, 16), plus outside.
    let v = read_volume_of(&desc, &reg, 2).unwrap();
    assert_eq!(v.name, "surface");
    assert_eq!(v.background, 0.75);
    assert_eq!(v.value([16, 16, 16]), -0.75);
    assert_eq!(v.value([100, 16, 16]), 0.75);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn luxon_check_describes_a_vdb_volume() {
    let dir = temp_dir("vdb-check");
    std::fs::create_dir_all(dir.join("volumes")).unwrap();
    std::fs::copy(fixture("fog_sphere.vdb"), dir.join("volumes/fog.vdb")).unwrap();
    volume_scene(
        &dir,
        &format!(
            r#"        (plugin: "vdb", name: "smoke", params: (file: "volumes/fog.vdb", grid: "density")),
        (plugin: "vdb", name: "cloud", params: (file: "{}")),"#,
            root().join("scenes/volumes/cloud.vdb").display()
        ),
    );
    let out = run(&["check", dir.join("scene.ron").to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}{}", text, stderr(&out));
    // 8 leaves of 512 voxels; densities from 0 to 1 (the centre).
    assert!(
        text.contains("volume     `smoke` (vdb): 4096 voxels, values 0..1,"),
        "{text}"
    );
    // The shipped cloud: 160 leaves of half-float densities.
    assert!(
        text.contains("volume     `cloud` (vdb): 81920 voxels, values 0..1,"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn vdb_errors_point_at_the_params() {
    let dir = temp_dir("vdb-errors");
    for f in ["multi.vdb", "tiles.vdb", "vec3.vdb"] {
        std::fs::copy(fixture(f), dir.join(f)).unwrap();
    }
    std::fs::write(dir.join("fake.vdb"), b"not a volume at all").unwrap();
    let desc = volume_scene(
        &dir,
        r#"        (plugin: "vdb", params: (file: "multi.vdb", grid: "smoke")),
        (plugin: "vdb", params: (file: "vec3.vdb")),
        (plugin: "vdb", params: (file: "fake.vdb")),
        (plugin: "vdb", params: (file: "missing.vdb")),
        (plugin: "vdb", params: (file: "multi.vdb", grd: "density")),
        (plugin: "vdb", params: (file: "tiles.vdb")),"#,
    );
    let reg = registry(&desc);
    let err = |i: usize| {
        let (at, m) = read_volume_of(&desc, &reg, i).unwrap_err();
        assert_eq!(at.line, 4 + i as u32, "{m}");
        m
    };
    let m = err(0);
    assert!(
        m.contains("no grid named `smoke`: the file holds `velocity` (vec3s), `density` (float), `temperature` (float)"),
        "{m}"
    );
    assert!(m.contains("multi.vdb"), "{m}");
    let m = err(1);
    assert!(
        m.contains("no float or double grid to read: the file holds `velocity` (vec3s)"),
        "{m}"
    );
    let m = err(2);
    assert!(m.contains("not an OpenVDB file"), "{m}");
    let m = err(3);
    assert!(m.contains("missing.vdb` does not exist"), "{m}");
    let m = err(4);
    assert!(m.contains("unknown parameter `grd`"), "{m}");
    // The 4096³ root tile is more than the host stores: it says so.
    let m = err(5);
    assert!(m.contains("2^34"), "{m}");
    let _ = std::fs::remove_dir_all(&dir);
}
