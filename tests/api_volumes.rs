//! Volumes from arrays (`luxon::api::Scene::add_volume`): a grid in the caller's layout (a
//! Fortran array with halo cells, a C array) renders bit for bit as the same voxels written to
//! a raw file and read by the `raw` plugin; values marked modified are read again at the next
//! commit, which says so; bad grids and bad voxels are refused with messages, never a panic.

mod common;

use common::*;
use luxon::api::{Context, Renderer, RendererOptions, Scene, VolumeGrid};
use luxon::arrays::{Array, SharedVec};
use std::path::Path;

const W: u32 = 64;
const H: u32 = 48;
const N: usize = 32;
const ORIGIN: [f64; 3] = [-1.0, -1.25, -0.75];
const SPACING: [f64; 3] = [0.0625, 0.078125, 0.046875];

/// How the volume is drawn, in both scenes.
const LOOK: &str = "(transfer: (points: [(x: 0, color: (0.1, 0.2, 0.8), opacity: 0), \
    (x: 0.4, color: (0.9, 0.5, 0.2), opacity: 3), (x: 1, color: (1, 1, 0.9), opacity: 25)], \
    range: (0, 1)), shading: (ambient: 0.4, diffuse: 0.7, specular: 0.2, shininess: 20))";

fn context() -> Context {
    let desc = luxon_formats::load(&root().join("scenes/spheres.ron")).unwrap();
    api_context(&desc, 2)
}

/// A Gaussian blob of width `sigma` centred at `c` (in voxels), at voxel (i, j, k).
fn gauss(i: usize, j: usize, k: usize, c: [f64; 3], sigma: f64) -> f64 {
    let d = [i as f64 - c[0], j as f64 - c[1], k as f64 - c[2]];
    (-(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / (2.0 * sigma * sigma)).exp()
}

const CENTRE: [f64; 3] = [15.5, 14.0, 16.5];

/// The field packed x fastest.
fn packed(c: [f64; 3], sigma: f64) -> Vec<f64> {
    let mut v = Vec::with_capacity(N * N * N);
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                v.push(gauss(i, j, k, c, sigma));
            }
        }
    }
    v
}

/// A scene file: camera, background, a light, and the raw file's volume when `raw` names it.
fn scene_file(dir: &Path, name: &str, raw: Option<&str>) -> std::path::PathBuf {
    let volumes = match raw {
        Some(file) => format!(
            "volumes: [(plugin: \"raw\", name: \"blob\", params: (file: \"{file}\", \
             dims: ({N}, {N}, {N}), format: \"f32\", origin: {:?}, spacing: {:?}), \
             render: {LOOK})],",
            tuple(ORIGIN),
            tuple(SPACING)
        ),
        None => String::new(),
    };
    let text = format!(
        "Scene(camera: (position: (2.2, -3.0, 1.6), look_at: (0, 0, 0), up: (0, 0, 1), fov: 36), \
         background: (0.05, 0.05, 0.08), \
         lights: [Point(position: (3, -5, 4), intensity: 1.0)], {volumes} \
         render: (width: {W}, height: {H}))"
    );
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn tuple(v: [f64; 3]) -> (f64, f64, f64) {
    (v[0], v[1], v[2])
}

fn render(r: &Renderer, s: &mut Scene) -> Vec<u32> {
    bits(&api_render(r, s, W, H).unwrap_or_else(|e| panic!("{e}")))
}

fn grid(values: Array, dims: [u64; 3]) -> VolumeGrid {
    VolumeGrid {
        origin: ORIGIN,
        spacing: SPACING,
        name: "blob".into(),
        ..VolumeGrid::new(values, dims)
    }
}

/// The same field as a Fortran array `u(0:N+1, 0:N+1, 0:N+1)` with a halo of one cell (set
/// to a value that would show if read), viewed without the halo.
fn fortran_with_halo(field: &[f64]) -> VolumeGrid {
    let m = N + 2;
    let mut u = vec![7.5f64; m * m * m];
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                u[(i + 1) + m * ((j + 1) + m * (k + 1))] = field[i + N * (j + N * k)];
            }
        }
    }
    let m = m as i64;
    VolumeGrid {
        strides: Some([1, m, m * m]),
        first: (1 + m + m * m) as u64,
        ..grid(Array::copy(&u).unwrap(), [N as u64; 3])
    }
}

/// The same field as a C array `v[i][j][k]` (z fastest).
fn c_order(field: &[f64]) -> VolumeGrid {
    let mut v = vec![0.0f64; N * N * N];
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                v[(i * N + j) * N + k] = field[i + N * (j + N * k)];
            }
        }
    }
    let n = N as i64;
    VolumeGrid {
        strides: Some([n * n, n, 1]),
        ..grid(Array::copy(&v).unwrap(), [N as u64; 3])
    }
}

#[test]
fn a_volume_from_an_array_renders_as_the_raw_reader_reads_its_file() {
    let dir = temp_dir("api-volumes-raw");
    let field = packed(CENTRE, 5.0);
    let bytes: Vec<u8> = field
        .iter()
        .flat_map(|&v| (v as f32).to_le_bytes())
        .collect();
    std::fs::write(dir.join("blob.raw"), bytes).unwrap();
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();

    let mut from_file = Scene::load(&ctx, &scene_file(&dir, "raw.ron", Some("blob.raw"))).unwrap();
    let want = render(&r, &mut from_file);
    let bare = scene_file(&dir, "bare.ron", None);
    let mut empty = Scene::load(&ctx, &bare).unwrap();
    assert_ne!(render(&r, &mut empty), want, "the volume shows");

    for (layout, g) in [
        ("packed", grid(Array::copy(&field).unwrap(), [N as u64; 3])),
        ("Fortran with a halo", fortran_with_halo(&field)),
        ("C order", c_order(&field)),
    ] {
        let mut s = Scene::load(&ctx, &bare).unwrap();
        s.add_volume_ron(g, LOOK).unwrap();
        let report = s.commit(&r).unwrap();
        assert_eq!(report.volumes_read, 1, "{layout}");
        assert!(render(&r, &mut s) == want, "{layout}: not bitwise equal");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn modified_values_are_read_again_and_change_the_picture() {
    let dir = temp_dir("api-volumes-modified");
    let bare = scene_file(&dir, "bare.ron", None);
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let values = SharedVec::new(packed(CENTRE, 5.0));
    let mut s = Scene::load(&ctx, &bare).unwrap();
    let id = s
        .add_volume_ron(grid(Array::shared(&values), [N as u64; 3]), LOOK)
        .unwrap();
    let report = s.commit(&r).unwrap();
    assert_eq!((report.volumes_read, report.rebuilt), (1, 1));
    let first = render(&r, &mut s);
    // Nothing changed: nothing read.
    assert_eq!(s.commit(&r).unwrap().volumes_read, 0);

    // A simulation step: the blob moves.
    let moved = packed([12.0, 17.0, 15.0], 4.0);
    values.write().copy_from_slice(&moved);
    let report = s.commit(&r).unwrap();
    assert_eq!((report.volumes_read, report.rebuilt), (1, 0));
    let second = render(&r, &mut s);
    assert_ne!(second, first, "the picture changed");
    let mut fresh = Scene::load(&ctx, &bare).unwrap();
    fresh
        .add_volume_ron(grid(Array::copy(&moved).unwrap(), [N as u64; 3]), LOOK)
        .unwrap();
    assert!(
        render(&r, &mut fresh) == second,
        "as a fresh scene of the moved blob"
    );

    // Memory of the caller's own, marked modified by hand.
    let copy = Array::copy(&moved).unwrap();
    s.set_volume_ron(id, grid(copy.clone(), [N as u64; 3]), LOOK)
        .unwrap();
    assert_eq!(s.commit(&r).unwrap().volumes_read, 1);
    copy.update(0, &packed(CENTRE, 5.0)).unwrap();
    assert_eq!(s.commit(&r).unwrap().volumes_read, 1);
    assert!(render(&r, &mut s) == first, "back to the first blob");

    // A build of the rest keeps the volume without reading it.
    s.add_light_ron("Point(position: (-3, -5, 4), intensity: 0.3)")
        .unwrap();
    s.set_render_ron("(volume_step: 0.5)").unwrap();
    let report = s.commit(&r).unwrap();
    assert_eq!((report.volumes_read, report.rebuilt), (0, 1));

    // Removed: the picture of the scene without it.
    s.remove(id).unwrap();
    let mut empty = Scene::load(&ctx, &bare).unwrap();
    empty
        .add_light_ron("Point(position: (-3, -5, 4), intensity: 0.3)")
        .unwrap();
    empty.set_render_ron("(volume_step: 0.5)").unwrap();
    assert!(render(&r, &mut s) == render(&r, &mut empty), "removed");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_nan_voxel_is_refused_with_its_index() {
    let dir = temp_dir("api-volumes-nan");
    let bare = scene_file(&dir, "bare.ron", None);
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let values = SharedVec::new(packed(CENTRE, 5.0));
    let mut s = Scene::load(&ctx, &bare).unwrap();
    s.add_volume_ron(grid(Array::shared(&values), [N as u64; 3]), LOOK)
        .unwrap();
    let good = render(&r, &mut s);
    values.write()[3 + N * (4 + N * 5)] = f64::NAN;
    let e = s.commit(&r).unwrap_err().to_string();
    assert!(
        e.contains("object 0 (volume)") && e.contains("voxel (3, 4, 5)") && e.contains("NaN"),
        "{e}"
    );
    values.write()[3 + N * (4 + N * 5)] = f64::INFINITY;
    let e = s.commit(&r).unwrap_err().to_string();
    assert!(e.contains("voxel (3, 4, 5)") && e.contains("inf"), "{e}");
    // Repaired: the scene renders again, as before.
    values.write()[3 + N * (4 + N * 5)] = gauss(3, 4, 5, CENTRE, 5.0);
    assert!(render(&r, &mut s) == good);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_grids_are_refused_with_clear_messages() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut s = Scene::new(&ctx);
    s.set_camera_ron("(position: (0, 0, 5), look_at: (0, 0, 0))")
        .unwrap();
    let v = Array::copy(&vec![0.5f32; 1000]).unwrap();
    let mut refused = |g: VolumeGrid, want: &[&str]| {
        let e = s.add_volume(g, None).unwrap_err().to_string();
        for w in want {
            assert!(e.contains(w), "`{w}` not in: {e}");
        }
    };
    refused(
        VolumeGrid::new(v.clone(), [10, 10, 11]),
        &[
            "read element 1099",
            "has 1000 elements",
            "dims [10, 10, 11]",
        ],
    );
    refused(
        VolumeGrid::new(v.clone(), [10, 0, 10]),
        &["dims [10, 0, 10]"],
    );
    refused(
        VolumeGrid {
            strides: Some([1, 0, 100]),
            ..VolumeGrid::new(v.clone(), [10, 10, 10])
        },
        &["stride 0 on axis y"],
    );
    refused(
        VolumeGrid {
            strides: Some([-1, 10, 100]),
            ..VolumeGrid::new(v.clone(), [10, 10, 10])
        },
        &["read element -9"],
    );
    refused(
        VolumeGrid {
            first: 1,
            ..VolumeGrid::new(v.clone(), [10, 10, 10])
        },
        &["read element 1000", "first 1"],
    );
    refused(
        VolumeGrid {
            spacing: [1.0, 0.0, 1.0],
            ..VolumeGrid::new(v.clone(), [10, 10, 10])
        },
        &["spacing [1.0, 0.0, 1.0]"],
    );
    refused(
        VolumeGrid::new(Array::copy(&[[0.0f32; 3]; 8]).unwrap(), [2, 2, 2]),
        &["values", "f32x3", "expected f32 or f64 or u8 or u16"],
    );
    refused(
        VolumeGrid::new(v.clone(), [1 << 20, 1 << 20, 1]),
        &["more than 2^34"],
    );
    // A mirrored axis: a negative stride from the last element is fine.
    let mirrored = VolumeGrid {
        strides: Some([-1, 10, 100]),
        first: 9,
        ..VolumeGrid::new(v.clone(), [10, 10, 10])
    };
    s.add_volume(mirrored, None).unwrap();
    let e = s.add_volume_ron(VolumeGrid::new(v.clone(), [10, 10, 10]), "(transfer: ())");
    assert!(e.unwrap_err().to_string().starts_with("<volume_render>:1:"));

    // A shared vector that shrank after the grid was added: refused at commit.
    let shrinking = SharedVec::new(vec![0.25f64; 1000]);
    let id = s
        .add_volume(
            VolumeGrid::new(Array::shared(&shrinking), [10, 10, 10]),
            None,
        )
        .unwrap();
    s.commit(&r).unwrap();
    shrinking.replace(vec![0.25; 999]);
    let e = s.commit(&r).unwrap_err().to_string();
    assert!(
        e.contains(&format!("{id} (volume)")) && e.contains("999 elements"),
        "{e}"
    );
    // Another kind's setter and a volume setter on another kind are refused.
    let ball = s
        .add_spheres(luxon::api::Spheres::new(
            Array::copy(&[[0.0f64; 3]]).unwrap(),
            luxon::api::Radius::Const(1.0),
        ))
        .unwrap();
    let e = s.set_volume(ball, VolumeGrid::new(v.clone(), [10, 10, 10]), None);
    assert!(e.unwrap_err().to_string().contains("is not a volume"));
    // A scene file cannot refer to the caller's arrays: to_ron says so, naming the object.
    let e = s.to_ron().unwrap_err().to_string();
    assert!(
        e.contains("(volume) is read from arrays and cannot be written as RON"),
        "{e}"
    );
    s.remove(id).unwrap();
    s.commit(&r).unwrap();
    for v in s.objects() {
        if v != ball {
            s.remove(v).unwrap();
        }
    }
    let e = s.to_ron().unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{ball} (spheres) is read from arrays")),
        "{e}"
    );
    s.remove(ball).unwrap();
    assert!(s.to_ron().unwrap().contains("camera"));
}
