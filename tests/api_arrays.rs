//! Array objects of a retained scene (`luxon::api::Scene::add_spheres`...): read in place from
//! the caller's arrays in any layout (Luxon's copy, a field of a shared vector of structs, f32
//! packed) they render bit for bit as the same primitives given to the shapes plugins; a
//! commit refits them when their content changed, builds them again when their count changed
//! or the refitted tree degraded, and says so; bad values are refused naming the object and
//! the element.

mod common;

use common::*;
use luxon::api::{Context, Cylinders, Mesh, Radius, Renderer, RendererOptions, Scene, Spheres};
use luxon::arrays::{Array, SharedVec};
use luxon::Error;

const W: u32 = 64;
const H: u32 = 48;
const N: usize = 2000;

fn context() -> Context {
    let desc = luxon_formats::load(&root().join("scenes/spheres.ron")).unwrap();
    api_context(&desc, 2)
}

/// A deterministic pseudo-random number in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// `n` spheres in a 4×4×4 box, f32 values (so f64 copies of them are exact).
fn cloud(n: usize, seed: u64) -> (Vec<[f32; 3]>, Vec<f32>) {
    let mut r = Lcg(seed);
    let centers = (0..n)
        .map(|_| {
            [
                r.next() * 4.0 - 2.0,
                r.next() * 4.0 - 2.0,
                r.next() * 4.0 - 2.0,
            ]
        })
        .collect();
    let radii = (0..n).map(|_| 0.04 + r.next() * 0.06).collect();
    (centers, radii)
}

fn widen(c: &[[f32; 3]]) -> Vec<[f64; 3]> {
    c.iter().map(|p| p.map(f64::from)).collect()
}

/// A camera, a light and a material; the spheres are added by the caller.
fn base(ctx: &Context) -> (Scene, luxon::api::MaterialId) {
    let mut s = Scene::new(ctx);
    s.set_camera_ron("(position: (7, 5, 9), look_at: (0, 0, 0), up: (0, 1, 0))")
        .unwrap();
    s.add_light_ron("Point(position: (10, 12, 6))").unwrap();
    s.set_background([0.1, 0.15, 0.3]).unwrap();
    let m = s
        .set_material_ron("clay", "(color: (0.8, 0.4, 0.2), specular: 0.4)")
        .unwrap();
    (s, m)
}

fn render(r: &Renderer, s: &mut Scene) -> Result<Vec<u32>, Error> {
    api_render(r, s, W, H).map(|px| bits(&px))
}

fn ron_spheres(centers: &[[f32; 3]], radii: &[f32]) -> String {
    let c: Vec<String> = centers
        .iter()
        .map(|p| format!("({:?}, {:?}, {:?})", p[0] as f64, p[1] as f64, p[2] as f64))
        .collect();
    let r: Vec<String> = radii.iter().map(|r| format!("{:?}", *r as f64)).collect();
    format!("(centers: [{}], radii: [{}])", c.join(", "), r.join(", "))
}

#[derive(Clone, Copy)]
#[allow(dead_code)] // `kind` and `charge` are there to make the layout an array of structs
struct Atom {
    kind: u8,
    pos: [f64; 3],
    radius: f64,
    charge: f32,
}

#[test]
fn spheres_from_arrays_render_as_the_spheres_plugin_in_every_layout() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (c32, r32) = cloud(N, 7);
    let (c64, r64) = (
        widen(&c32),
        r32.iter().map(|&r| r as f64).collect::<Vec<_>>(),
    );

    let (mut plugin, m) = base(&ctx);
    let params = ron_spheres(&c32, &r32);
    plugin
        .add_plugin_object("spheres", &params, Some(m), None)
        .unwrap();
    let want = render(&r, &mut plugin).unwrap();
    let lit = want
        .chunks(4)
        .filter(|p| f32::from_bits(p[0]) > 0.3)
        .count();
    assert!(lit > 200, "the spheres are lit: {lit} bright pixels");

    let copy = Spheres::new(
        Array::copy(&c64).unwrap(),
        Radius::Each(Array::copy(&r64).unwrap()),
    );
    let atoms = SharedVec::new(
        (0..N)
            .map(|i| Atom {
                kind: i as u8,
                pos: c64[i],
                radius: r64[i],
                charge: -1.0,
            })
            .collect(),
    );
    let field = Spheres::new(
        Array::field(&atoms, |a: &Atom| &a.pos).unwrap(),
        Radius::Each(Array::field(&atoms, |a: &Atom| &a.radius).unwrap()),
    );
    let packed = Spheres::new(
        Array::from_vec(c32.clone()),
        Radius::Each(Array::from_vec(r32.clone())),
    );
    for (name, spheres) in [("copy", copy), ("field", field), ("f32", packed)] {
        let (mut s, m) = base(&ctx);
        let material = Some(m);
        s.add_spheres(Spheres {
            material,
            ..spheres
        })
        .unwrap();
        let got = render(&r, &mut s).unwrap();
        assert!(got == want, "{name}: the image differs from the plugin's");
    }
}

#[test]
fn moved_spheres_are_refitted_and_render_as_a_fresh_scene() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (c32, r32) = cloud(N, 11);
    let centers = SharedVec::new(widen(&c32));
    let mut s = base(&ctx).0;
    s.add_spheres(Spheres::new(
        Array::shared(&centers),
        Radius::Each(Array::from_vec(r32.clone())),
    ))
    .unwrap();
    let first = s.commit(&r).unwrap();
    assert_eq!((first.rebuilt, first.refitted), (2, 0), "{first:?}");
    let before = render(&r, &mut s).unwrap();

    // Every sphere takes a small random step.
    let mut rng = Lcg(99);
    {
        let mut w = centers.write();
        for p in w.iter_mut() {
            for x in p.iter_mut() {
                *x += (rng.next() as f64 - 0.5) * 0.05;
            }
        }
    }
    let report = s.commit(&r).unwrap();
    assert_eq!(
        (report.refitted, report.rebuilt, report.degraded),
        (1, 0, 0),
        "{report:?}"
    );
    assert!(
        report.worst_ratio > 0.0 && report.worst_ratio <= 1.3,
        "{report:?}"
    );
    let moved = render(&r, &mut s).unwrap();
    assert!(moved != before, "the spheres moved");

    let mut fresh = base(&ctx).0;
    fresh
        .add_spheres(Spheres::new(
            Array::copy(&centers.read()).unwrap(),
            Radius::Each(Array::from_vec(r32)),
        ))
        .unwrap();
    assert!(render(&r, &mut fresh).unwrap() == moved);

    // Nothing changed: nothing is done.
    let idle = s.commit(&r).unwrap();
    assert_eq!((idle.refitted, idle.rebuilt), (0, 0), "{idle:?}");
}

#[test]
fn shuffled_spheres_degrade_and_a_new_count_rebuilds() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (c32, _) = cloud(N, 5);
    let centers = SharedVec::new(widen(&c32));
    let mut s = base(&ctx).0;
    s.add_spheres(Spheres::new(Array::shared(&centers), Radius::Const(0.05)))
        .unwrap();
    s.commit(&r).unwrap();

    // Positions swapped at random among the spheres: each leaf's boxes now span the cloud.
    let mut rng = Lcg(3);
    {
        let mut w = centers.write();
        for i in (1..w.len()).rev() {
            let j = (rng.next() * (i + 1) as f32) as usize % (i + 1);
            w.swap(i, j);
        }
    }
    let report = s.commit(&r).unwrap();
    assert_eq!((report.degraded, report.rebuilt), (1, 1), "{report:?}");
    assert!(report.worst_ratio > 1.3, "{report:?}");
    // The rebuilt tree is the fresh one: the next small change refits it.
    {
        let mut w = centers.write();
        w[0][0] += 0.01;
    }
    let report = s.commit(&r).unwrap();
    assert_eq!((report.refitted, report.rebuilt), (1, 0), "{report:?}");

    // One sphere fewer: a new count, built again.
    let mut fewer = centers.read().to_vec();
    fewer.pop();
    centers.replace(fewer);
    let report = s.commit(&r).unwrap();
    assert_eq!((report.rebuilt, report.refitted), (1, 0), "{report:?}");
    assert_eq!(s.built().unwrap().primitive_count(), N - 1);
}

#[test]
fn removing_and_replacing_array_objects() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (c32, r32) = cloud(200, 1);
    let (mut s, m) = base(&ctx);
    let a = s
        .add_spheres(Spheres::new(
            Array::from_vec(c32.clone()),
            Radius::Const(0.1),
        ))
        .unwrap();
    let with_spheres = render(&r, &mut s).unwrap();
    s.set_spheres(
        a,
        Spheres {
            material: Some(m),
            ..Spheres::new(Array::from_vec(c32), Radius::Each(Array::from_vec(r32)))
        },
    )
    .unwrap();
    assert_eq!(s.commit(&r).unwrap().rebuilt, 1);
    s.remove(a).unwrap();
    let report = s.commit(&r).unwrap();
    assert_eq!((report.rebuilt, report.refitted), (0, 0), "{report:?}");
    assert_eq!(s.built().unwrap().primitive_count(), 0);
    let e = s.remove(a).unwrap_err().to_string();
    assert_eq!(e, "object 0 was removed from this scene");
    assert!(render(&r, &mut s).unwrap() != with_spheres);
}

#[test]
fn bad_spheres_are_refused_naming_the_object_and_the_sphere() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (mut c, radii) = cloud(50, 2);
    c[5][1] = f32::NAN;
    let mut s = base(&ctx).0;
    s.add_plugin_object("sphere", "(center: (0, 0, 0), radius: 1)", None, None)
        .unwrap();
    s.add_spheres(Spheres::new(
        Array::from_vec(c),
        Radius::Each(Array::from_vec(radii)),
    ))
    .unwrap();
    let e = s.commit(&r).unwrap_err().to_string();
    assert!(
        e.starts_with("object 1 (spheres): sphere 5 has a non-finite value ["),
        "{e}"
    );

    let (c, mut radii) = cloud(50, 2);
    radii[3] = 0.0;
    let mut s = base(&ctx).0;
    s.add_spheres(Spheres::new(
        Array::from_vec(c.clone()),
        Radius::Each(Array::from_vec(radii)),
    ))
    .unwrap();
    let e = s.commit(&r).unwrap_err().to_string();
    assert_eq!(
        e,
        "object 0 (spheres): sphere 3 has radius 0; expected a radius > 0"
    );

    let e = s
        .add_spheres(Spheres::new(
            Array::from_vec(c.clone()),
            Radius::Const(-1.0),
        ))
        .unwrap_err()
        .to_string();
    assert_eq!(e, "spheres' radius -1; expected a radius > 0");
    let e = s
        .add_spheres(Spheres::new(
            Array::from_vec(vec![1u32; 3]),
            Radius::Const(1.0),
        ))
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "spheres' centres: an array of u32 elements; expected f32x3 or f64x3"
    );
    let short = Array::from_vec(vec![0.5f64; 49]);
    let mut s = base(&ctx).0;
    s.add_spheres(Spheres::new(Array::from_vec(c), Radius::Each(short)))
        .unwrap();
    let e = s.commit(&r).unwrap_err().to_string();
    assert_eq!(
        e,
        "object 0 (spheres): 49 radii for 50 centres; give one per centre"
    );
}

/// A render holds the arrays (a write waits for it); between renders they are free.
#[test]
fn arrays_are_free_between_renders() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (c32, _) = cloud(100, 4);
    let centers = SharedVec::new(c32);
    let mut s = base(&ctx).0;
    s.add_spheres(Spheres::new(Array::shared(&centers), Radius::Const(0.1)))
        .unwrap();
    render(&r, &mut s).unwrap();
    assert!(centers.try_write().is_some());
    s.commit(&r).unwrap();
    assert!(centers.try_write().is_some());
    // A render from the thread that writes is refused, not a deadlock.
    let w = centers.write();
    let e = render(&r, &mut s).unwrap_err().to_string();
    assert!(e.contains("being written by this thread"), "{e}");
    drop(w);
    render(&r, &mut s).unwrap();
}

/// A wavy `g`×`g` grid in the y = 0 plane: positions, normals, colours, uvs (f32) and the two
/// triangles of every cell (none of zero area).
#[allow(clippy::type_complexity)]
fn grid(
    g: usize,
) -> (
    Vec<[f32; 3]>,
    Vec<[f32; 3]>,
    Vec<[f32; 3]>,
    Vec<[f32; 2]>,
    Vec<[u32; 3]>,
) {
    let (mut p, mut n, mut c, mut uv, mut tri) = (vec![], vec![], vec![], vec![], vec![]);
    for j in 0..g {
        for i in 0..g {
            let (u, v) = (i as f32 / (g - 1) as f32, j as f32 / (g - 1) as f32);
            let h = 0.3 * (u * 6.0).sin() * (v * 5.0).cos();
            p.push([u * 4.0 - 2.0, h - 1.0, v * 4.0 - 2.0]);
            n.push([-0.2 * (u * 6.0).cos(), 1.0, 0.15 * (v * 5.0).sin()]);
            c.push([u, 0.5, 1.0 - v]);
            uv.push([u, v]);
        }
    }
    for j in 0..g - 1 {
        for i in 0..g - 1 {
            let k = (j * g + i) as u32;
            let g = g as u32;
            tri.push([k, k + 1, k + g]);
            tri.push([k + 1, k + g + 1, k + g]);
        }
    }
    (p, n, c, uv, tri)
}

fn list<const K: usize, T: Copy + std::fmt::Debug>(
    v: &[[T; K]],
    f: impl Fn(T) -> String,
) -> String {
    let items: Vec<String> = v
        .iter()
        .map(|x| format!("({})", x.map(&f).join(", ")))
        .collect();
    format!("[{}]", items.join(", "))
}

#[test]
fn a_mesh_from_arrays_renders_as_the_mesh_plugin() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (p, n, c, uv, tri) = grid(24);
    let real = |x: f32| format!("{:?}", x as f64);
    let params = format!(
        "(positions: {}, indices: {}, normals: {}, colors: {}, uvs: {})",
        list(&p, real),
        list(&tri, |i| i.to_string()),
        list(&n, real),
        list(&c, real),
        list(&uv, real),
    );
    let (mut plugin, m) = base(&ctx);
    plugin
        .add_plugin_object("mesh", &params, Some(m), None)
        .unwrap();
    let want = render(&r, &mut plugin).unwrap();
    assert!(
        want != render(&r, &mut base(&ctx).0).unwrap(),
        "the mesh is seen"
    );

    let packed = Mesh {
        normals: Some(Array::from_vec(n.clone())),
        colors: Some(Array::from_vec(c.clone())),
        uvs: Some(Array::from_vec(uv.clone())),
        ..Mesh::new(
            Array::from_vec(p.clone()),
            Some(Array::from_vec(tri.clone())),
        )
    };
    let wide = Mesh {
        normals: Some(Array::from_vec(widen(&n))),
        colors: Some(Array::from_vec(widen(&c))),
        uvs: Some(Array::from_vec(uv.clone())),
        ..Mesh::new(
            Array::from_vec(widen(&p)),
            Some(Array::from_vec(
                tri.iter().map(|t| t.map(u64::from)).collect::<Vec<_>>(),
            )),
        )
    };
    for (name, mesh) in [("f32/u32", packed), ("f64/u64", wide)] {
        let (mut s, m) = base(&ctx);
        let material = Some(m);
        s.add_mesh(Mesh { material, ..mesh }).unwrap();
        assert!(
            render(&r, &mut s).unwrap() == want,
            "{name}: the image differs"
        );
    }

    // Without indices: every three positions make a triangle.
    let soup: Vec<[f32; 3]> = tri.iter().flat_map(|t| t.map(|i| p[i as usize])).collect();
    let (mut s, _) = base(&ctx);
    s.add_mesh(Mesh::new(Array::from_vec(soup), None)).unwrap();
    render(&r, &mut s).unwrap();
    assert_eq!(s.built().unwrap().primitive_count(), tri.len());
}

#[test]
fn mesh_vertices_moved_refit_and_new_indices_rebuild() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (p, _, _, _, tri) = grid(16);
    let positions = SharedVec::new(p);
    let indices = SharedVec::new(tri);
    let mut s = base(&ctx).0;
    let mesh = Mesh::new(Array::shared(&positions), Some(Array::shared(&indices)));
    s.add_mesh(mesh).unwrap();
    s.commit(&r).unwrap();
    for v in positions.write().iter_mut() {
        v[1] += 0.1;
    }
    let report = s.commit(&r).unwrap();
    assert_eq!((report.refitted, report.rebuilt), (1, 0), "{report:?}");
    indices.write().swap(0, 1);
    let report = s.commit(&r).unwrap();
    assert_eq!((report.refitted, report.rebuilt), (0, 1), "{report:?}");

    // A zero-area triangle is kept (never hit): triangle numbers stay those of the caller.
    let count = indices.len();
    indices.write()[3] = [5, 5, 6];
    render(&r, &mut s).unwrap();
    assert_eq!(s.built().unwrap().primitive_count(), count);

    // An index past the vertices is refused, naming the object, triangle and vertex.
    indices.write()[7] = [1, 2, 900];
    let e = s.commit(&r).unwrap_err().to_string();
    assert_eq!(
        e,
        "object 0 (mesh): triangle 7 uses vertex 900, but the mesh has 256 vertices"
    );
}

#[test]
fn capped_cylinders_from_arrays_render_as_the_cylinder_plugin() {
    let ctx = context();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let (bases, radii) = cloud(60, 21);
    let (dirs, _) = cloud(60, 22);
    let apexes: Vec<[f32; 3]> = bases
        .iter()
        .zip(&dirs)
        .map(|(b, d)| [b[0] + d[0] * 0.3, b[1] + d[1] * 0.3, b[2] + d[2] * 0.3])
        .collect();
    let radii: Vec<f32> = radii.iter().map(|r| r * 1.5).collect();
    let real = |x: f32| format!("{:?}", x as f64);
    // A ground sphere in both, for the cylinders' shadows to fall on.
    const GROUND: &str = "(center: (0, -30, 0), radius: 27)";
    let (mut plugin, m) = base(&ctx);
    plugin
        .add_plugin_object("sphere", GROUND, None, None)
        .unwrap();
    for i in 0..bases.len() {
        let params = format!(
            "(base: ({}, {}, {}), apex: ({}, {}, {}), radius: {})",
            real(bases[i][0]),
            real(bases[i][1]),
            real(bases[i][2]),
            real(apexes[i][0]),
            real(apexes[i][1]),
            real(apexes[i][2]),
            real(radii[i]),
        );
        plugin
            .add_plugin_object("cylinder", &params, Some(m), None)
            .unwrap();
    }
    let want = render(&r, &mut plugin).unwrap();
    assert!(
        want != render(&r, &mut base(&ctx).0).unwrap(),
        "the cylinders are seen"
    );

    let (mut s, m) = base(&ctx);
    let cylinders = Cylinders {
        material: Some(m),
        ..Cylinders::new(
            Array::from_vec(widen(&bases)),
            Array::from_vec(apexes.clone()),
            Radius::Each(Array::from_vec(radii.clone())),
        )
    };
    s.add_plugin_object("sphere", GROUND, None, None).unwrap();
    let id = s.add_cylinders(cylinders).unwrap();
    assert!(render(&r, &mut s).unwrap() == want, "the image differs");
    assert_eq!(s.built().unwrap().primitive_count(), 1 + 3 * bases.len());

    // Open ones have no caps; a base at its apex is refused.
    let mut open = Cylinders::new(
        Array::from_vec(bases.clone()),
        Array::from_vec(apexes),
        Radius::Const(0.1),
    );
    open.caps = false;
    s.set_cylinders(id, open).unwrap();
    render(&r, &mut s).unwrap();
    assert_eq!(s.built().unwrap().primitive_count(), 1 + bases.len());
    let same = Cylinders::new(
        Array::from_vec(bases.clone()),
        Array::from_vec(bases),
        Radius::Const(0.1),
    );
    s.set_cylinders(id, same).unwrap();
    let e = s.commit(&r).unwrap_err().to_string();
    assert_eq!(
        e,
        "object 1 (cylinders): cylinder 0 has the same base and apex centre; expected a length > 0"
    );
}
