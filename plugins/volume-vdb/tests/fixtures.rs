//! Every fixture written by OpenVDB (tests/fixtures/make_fixtures.py) read by our parser and
//! compared with what OpenVDB itself reads from it (the `.ref` files), plus the failure modes:
//! wrong types, unknown names, truncated and corrupted files.

use luxon_volume_vdb::{list_grids, read_grid, Grid, VdbError};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn bytes(name: &str) -> Vec<u8> {
    std::fs::read(fixtures().join(name)).unwrap()
}

/// One grid of a `.ref` file.
#[derive(Default, Debug)]
struct Expected {
    name: String,
    value_type: String,
    half: bool,
    class: String,
    background: f32,
    active: u64,
    bbox: Vec<i64>,
    world: Vec<([f64; 3], [f64; 3])>,
    voxels: Vec<([i32; 3], f32, bool)>,
}

fn parse_ref(text: &str) -> Vec<Expected> {
    let mut out: Vec<Expected> = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let f = |i: usize| w[i].parse::<f64>().unwrap();
        let i = |k: usize| w[k].parse::<i64>().unwrap();
        match w[0] {
            "grid" => out.push(Expected {
                name: w[1].into(),
                value_type: w[2].into(),
                half: w[3] == "half",
                class: w[4].replace('_', " "),
                ..Expected::default()
            }),
            "background" => out.last_mut().unwrap().background = f(1) as f32,
            "active" => out.last_mut().unwrap().active = i(1) as u64,
            "bbox" => out.last_mut().unwrap().bbox = (1..7).map(i).collect(),
            "world" => out
                .last_mut()
                .unwrap()
                .world
                .push(([f(1), f(2), f(3)], [f(4), f(5), f(6)])),
            "voxel" => out.last_mut().unwrap().voxels.push((
                [i(1) as i32, i(2) as i32, i(3) as i32],
                f(4) as f32,
                w[5] == "1",
            )),
            other => panic!("unknown reference line kind {other}"),
        }
    }
    out
}

/// Inclusive box of the active voxels (leaves and tiles).
fn active_bbox(g: &Grid) -> Vec<i64> {
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    let mut add = |a: [i64; 3], b: [i64; 3]| {
        for k in 0..3 {
            lo[k] = lo[k].min(a[k]);
            hi[k] = hi[k].max(b[k]);
        }
    };
    for l in &g.leaves {
        for i in 0..512 {
            if l.active[i >> 6] >> (i & 63) & 1 != 0 {
                let p = [i % 8, i / 8 % 8, i / 64].map(|c| c as i64);
                let v = [0, 1, 2].map(|a| i64::from(l.origin[a]) + p[a]);
                add(v, v);
            }
        }
    }
    for t in g.tiles.iter().filter(|t| t.active) {
        let o = t.origin.map(i64::from);
        add(o, o.map(|c| c + i64::from(t.size) - 1));
    }
    lo.iter().chain(hi.iter()).copied().collect()
}

fn world(g: &Grid, p: [f64; 3]) -> [f64; 3] {
    let m = &g.world_from_index;
    [0, 1, 2].map(|r| m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3])
}

/// Checks one fixture against its reference; returns the number of voxels compared.
fn check_fixture(vdb: &str) -> usize {
    let file = bytes(vdb);
    let reference = std::fs::read_to_string(fixtures().join(vdb.replace(".vdb", ".ref"))).unwrap();
    let expected = parse_ref(&reference);
    assert!(!expected.is_empty(), "{vdb}: empty reference");
    let listed = list_grids(&file).unwrap();
    assert_eq!(listed.len(), expected.len(), "{vdb}: grid count");
    let mut compared = 0;
    for e in &expected {
        let got = read_grid(&file, Some(&e.name));
        if !["float", "double"].contains(&e.value_type.as_str()) {
            match got {
                Err(VdbError::WrongType { value_type, .. }) => assert_eq!(value_type, e.value_type),
                other => panic!("{vdb}/{}: expected a type error, got {other:?}", e.name),
            }
            continue;
        }
        let g = got.unwrap_or_else(|err| panic!("{vdb}/{}: {err}", e.name));
        let what = format!("{vdb}/{}", e.name);
        assert_eq!(g.name, e.name);
        assert_eq!(g.value_type, e.value_type, "{what}");
        assert_eq!(g.half, e.half, "{what}");
        assert_eq!(g.class, e.class, "{what}");
        assert_eq!(g.background, e.background, "{what}: background");
        assert_eq!(g.active_voxel_count(), e.active, "{what}: active voxels");
        assert_eq!(active_bbox(&g), e.bbox, "{what}: active box");
        for (p, w) in &e.world {
            let got = world(&g, *p);
            for a in 0..3 {
                assert!(
                    (got[a] - w[a]).abs() <= 1e-12 * (1.0 + w[a].abs()),
                    "{what}: index {p:?} maps to {got:?}, OpenVDB says {w:?}"
                );
            }
        }
        for &(ijk, value, active) in &e.voxels {
            let (v, on) = g.value(ijk);
            assert!(
                v.to_bits() == value.to_bits() || v == value,
                "{what}: voxel {ijk:?} is {v}, OpenVDB says {value}"
            );
            assert_eq!(on, active, "{what}: active flag of voxel {ijk:?}");
            compared += 1;
        }
    }
    compared
}

/// Every committed fixture has a reference and matches it.
#[test]
fn every_fixture_matches_openvdb() {
    let mut names: Vec<String> = std::fs::read_dir(fixtures())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".vdb"))
        .collect();
    names.sort();
    assert!(names.len() >= 13, "{names:?}");
    let mut total = 0;
    for n in &names {
        total += check_fixture(n);
    }
    assert!(total > 3000, "only {total} voxels compared");
}

#[test]
fn default_grid_is_the_first_float_grid() {
    let g = read_grid(&bytes("multi.vdb"), None).unwrap();
    assert_eq!(g.name, "density");
    let g = read_grid(&bytes("double.vdb"), None).unwrap();
    assert_eq!(
        (g.name.as_str(), g.value_type),
        ("surface_double", "double")
    );
}

#[test]
fn missing_and_wrong_grids_are_errors_naming_them() {
    let e = read_grid(&bytes("multi.vdb"), Some("dens")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "no grid named `dens`: the file holds `velocity` (vec3s), `density` (float), \
         `temperature` (float)"
    );
    let e = read_grid(&bytes("multi.vdb"), Some("velocity")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "grid `velocity` has type vec3s (Tree_vec3s_5_4_3); only float and double grids can be \
         read as volumes"
    );
    let e = read_grid(&bytes("bool.vdb"), None).unwrap_err();
    assert_eq!(
        e.to_string(),
        "no float or double grid to read: the file holds `mask` (bool)"
    );
    let e = read_grid(&bytes("vec3.vdb"), Some("velocity")).unwrap_err();
    assert!(matches!(e, VdbError::WrongType { .. }), "{e}");
}

#[test]
fn signature_and_version_are_checked() {
    let mut f = bytes("fog_sphere.vdb");
    f[1] = b'C';
    let e = read_grid(&f, None).unwrap_err();
    assert!(e.to_string().starts_with("not an OpenVDB file"), "{e}");
    let e = read_grid(b"P6\n1 1\n255\n", None).unwrap_err();
    assert!(matches!(e, VdbError::NotVdb(_)), "{e}");
    assert!(matches!(
        read_grid(b"", None).unwrap_err(),
        VdbError::NotVdb(_)
    ));
    let mut f = bytes("fog_sphere.vdb");
    f[8] = 221;
    assert_eq!(read_grid(&f, None).unwrap_err(), VdbError::Version(221));
    f[8] = 225;
    assert_eq!(read_grid(&f, None).unwrap_err(), VdbError::Version(225));
}

/// Inactive voxels of a level set read as plus or minus the background: outside positive,
/// inside negative, exactly what OpenVDB stores.
#[test]
fn level_set_inactive_values_have_their_sign() {
    let g = read_grid(&bytes("level_set.vdb"), None).unwrap();
    assert_eq!(g.class, "level set");
    let bg = g.background;
    // The sphere's centre, index (16, 16, 16), is deep inside; a corner of the box outside.
    assert_eq!(g.value([16, 16, 16]), (-bg, false));
    assert_eq!(g.value([0, 0, 0]), (bg, false));
    assert_eq!(g.value([-500, 0, 0]), (bg, false));
}

/// The root-level tile (4096³), an upper internal tile (128³) and an inactive lower one (8³).
#[test]
fn tiles_of_every_level() {
    let g = read_grid(&bytes("tiles.vdb"), None).unwrap();
    let mut tiles: Vec<(u32, f32, bool)> = g
        .tiles
        .iter()
        .map(|t| (t.size, t.value, t.active))
        .collect();
    tiles.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(
        tiles,
        [(8, -1.25, false), (128, 3.5, true), (4096, 0.75, true)]
    );
    assert_eq!(g.value([8191, 4095, 4095]), (0.75, true));
    assert_eq!(g.value([8192, 4095, 4095]), (0.0, false));
    assert_eq!(g.value([-128, -1, -64]), (3.5, true));
    assert_eq!(g.value([3, 4, -5]), (-1.25, false));
}

/// Every truncation of a small fixture is an error, never a panic.
#[test]
fn truncated_files_are_errors() {
    for name in ["fog_sphere.vdb", "masks.vdb", "none.vdb", "double.vdb"] {
        let f = bytes(name);
        let stride = if name == "fog_sphere.vdb" {
            1
        } else {
            f.len() / 3000 + 1
        };
        for len in (0..f.len()).step_by(stride) {
            assert!(
                read_grid(&f[..len], None).is_err(),
                "{name} cut at {len} read"
            );
        }
    }
}

/// xorshift64*: a deterministic stream for the corruption loop.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
}

/// Random byte changes give an error or a grid, never a panic; when a grid comes back, its
/// leaves and tiles are well formed.
#[test]
fn corrupted_files_never_panic() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for name in [
        "fog_sphere.vdb",
        "half.vdb",
        "tiles.vdb",
        "level_set.vdb",
        "mask_only.vdb",
    ] {
        let f = bytes(name);
        let (mut ok, mut err) = (0, 0);
        for _ in 0..300 {
            let mut g = f.clone();
            let changes = 1 + rng.next() % 4;
            for _ in 0..changes {
                let at = (rng.next() % g.len() as u64) as usize;
                g[at] = rng.next() as u8;
            }
            match read_grid(&g, None) {
                Ok(grid) => {
                    ok += 1;
                    assert!(grid
                        .leaves
                        .iter()
                        .all(|l| l.origin.iter().all(|c| c % 8 == 0)));
                }
                Err(_) => err += 1,
            }
        }
        assert!(
            ok + err == 300 && err > 0,
            "{name}: {ok} read, {err} errors"
        );
    }
}
