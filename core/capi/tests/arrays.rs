//! Arrays through the C API: `tests/c/arrays.c` (C99, against libluxon.so) builds spheres from
//! fields of an array of structs (read in place), a mesh and a volume (copies), renders, moves
//! the spheres (marked modified: refitted) and renders again; both pictures equal, bit for bit,
//! the Rust API's renders of the same data. The program also checks the error codes of bad,
//! NULL and released arrays, that an array released while a scene uses it is still read
//! until the scene lets it go, then deleted once, and that an index array changed to
//! out-of-range values without being marked modified renders without a crash (then, marked,
//! is refused at commit).

mod common;

use common::{bits, ensure_built, profile_dir, render_f32, rust_api, temp_dir};
use luxon_core::api::{Context, Mesh, Radius, Scene, Spheres, VolumeGrid};
use luxon_core::arrays::{Array, SharedVec};
use luxon_formats::{Attenuation, CameraDesc, LightDesc, MaterialDesc, Projection};
use std::path::{Path, PathBuf};
use std::process::Command;

const W: u32 = 32;
const H: u32 = 24;
const ATOMS: usize = 27;
const GRID: usize = 6;
const VOX: usize = 12;
const LOOK: &str = "(transfer: (points: [(x: 0, color: (0.2, 0.6, 1), opacity: 0), \
    (x: 1, color: (0.9, 1, 1), opacity: 3)], range: (0, 1)))";

/// The atoms' centres and radii, as arrays.c makes them.
fn atoms() -> (Vec<[f64; 3]>, Vec<f64>) {
    let centers = (0..ATOMS)
        .map(|i| {
            [
                ((i % 3) as f64 - 1.0) * 0.75,
                ((i / 3 % 3) as f64 - 1.0) * 0.75 + 0.5,
                ((i / 9) as f64 - 1.0) * 0.75,
            ]
        })
        .collect();
    let radii = (0..ATOMS).map(|i| 0.15 + 0.01 * (i % 4) as f64).collect();
    (centers, radii)
}

/// The sheet's vertices and triangles.
fn sheet() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for j in 0..GRID {
        for i in 0..GRID {
            positions.push([
                ((i as f64 - 2.5) as f32) * 0.8,
                -0.6f32 + 0.1f32 * ((i * j) % 3) as f32,
                ((j as f64 - 2.5) as f32) * 0.8,
            ]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..GRID - 1 {
        for i in 0..GRID - 1 {
            let a = (j * GRID + i) as u32;
            let g = GRID as u32;
            triangles.push([a, a + g, a + 1]);
            triangles.push([a + 1, a + g, a + g + 1]);
        }
    }
    (positions, triangles)
}

fn voxels() -> Vec<f32> {
    let mut v = Vec::new();
    for k in 0..VOX {
        for j in 0..VOX {
            for i in 0..VOX {
                let (x, y, z) = (i as f64 - 5.5, j as f64 - 5.5, k as f64 - 5.5);
                let b = 1.0 - (x * x + y * y + z * z) / 36.0;
                v.push(if b > 0.0 { b * b } else { 0.0 } as f32);
            }
        }
    }
    v
}

/// The scene arrays.c builds, through the Rust API; its centres shared for the move.
fn arrays_scene(ctx: &Context) -> (Scene, SharedVec<[f64; 3]>) {
    let go = |r: Result<(), luxon_core::Error>| r.unwrap_or_else(|e| panic!("{e}"));
    let mut s = Scene::new(ctx);
    go(s.set_camera(CameraDesc {
        position: [0.0, 1.0, 6.0],
        look_at: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        projection: Projection::Perspective { fov_deg: 40.0 },
        aspect: None,
        frustum: None,
        depth_of_field: None,
        stereo: None,
    }));
    go(s.set_background([0.1, 0.15, 0.3]));
    go(s.add_light(LightDesc::Point {
        position: [4.0, 6.0, 5.0],
        color: [1.0; 3],
        intensity: 1.0,
        shadows: true,
        attenuation: Attenuation::default(),
    })
    .map(drop));
    let clay = MaterialDesc {
        color: [0.8, 0.4, 0.2],
        specular: 0.4,
        ..MaterialDesc::default()
    };
    let clay = s.set_material("clay", clay).unwrap();
    let (c, r) = atoms();
    let centers = SharedVec::new(c);
    let mut balls = Spheres::new(
        Array::shared(&centers),
        Radius::Each(Array::copy(&r).unwrap()),
    );
    balls.material = Some(clay);
    go(s.add_spheres(balls).map(drop));
    let (p, t) = sheet();
    let mesh = Mesh::new(Array::copy(&p).unwrap(), Some(Array::copy(&t).unwrap()));
    go(s.add_mesh(mesh).map(drop));
    let grid = VolumeGrid {
        origin: [-1.1; 3],
        spacing: [0.2; 3],
        name: "bump".into(),
        ..VolumeGrid::new(Array::copy(&voxels()).unwrap(), [VOX as u64; 3])
    };
    go(s.add_volume_ron(grid, LOOK).map(drop));
    (s, centers)
}

fn floats(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]).to_bits())
        .collect()
}

#[test]
fn c99_arrays_render_what_rust_renders() {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    if !Command::new(&cc)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
    {
        println!("note: no C compiler (cc or $CC) found; skipping the C arrays test");
        return;
    }
    ensure_built();
    let lib = profile_dir();
    let dir = temp_dir("arrays");
    let exe = dir.join("arrays");
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let built = Command::new(&cc)
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            "-I",
        ])
        .arg(here.join("include"))
        .arg(here.join("tests/c/arrays.c"))
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-lluxon")
        .output()
        .unwrap();
    assert!(
        built.status.success(),
        "{}",
        String::from_utf8_lossy(&built.stderr)
    );
    let ran = Command::new(&exe)
        .arg(&dir)
        .env_remove("LUXON_PLUGIN_PATH")
        .output()
        .unwrap();
    assert!(
        ran.status.success() && ran.stdout.is_empty() && ran.stderr.is_empty(),
        "arrays.c ({}):\n{}{}",
        ran.status,
        String::from_utf8_lossy(&ran.stdout),
        String::from_utf8_lossy(&ran.stderr)
    );

    let (ctx, renderer) = rust_api();
    let (mut scene, centers) = arrays_scene(&ctx);
    let want = render_f32(&renderer, &mut scene, W, H);
    let lit = want.iter().filter(|p| p[0] > 0.3).count();
    assert!(lit > 20, "the spheres are lit: {lit} bright pixels");
    assert_eq!(
        floats(&dir.join("arrays.f32")),
        bits(&want),
        "the first picture"
    );
    for (i, c) in centers.write().iter_mut().enumerate() {
        c[0] += if i % 2 == 1 { 0.05 } else { -0.05 };
    }
    let report = scene.commit(&renderer).unwrap();
    assert_eq!((report.refitted, report.rebuilt), (1, 0));
    let moved = render_f32(&renderer, &mut scene, W, H);
    assert_ne!(bits(&moved), bits(&want));
    assert_eq!(
        floats(&dir.join("moved.f32")),
        bits(&moved),
        "after the move"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
