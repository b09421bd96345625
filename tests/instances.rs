//! Prototypes and instances, realised by baking: an instanced scene renders the same bits as
//! the same geometry written out flat (its coordinates computed by `luxon::motion` in f64 and
//! printed with `{:?}`, which reads back exactly), on any thread count; a thousand instances
//! render; what baking cannot do is refused naming the instance and its place; keyed
//! instances move like keyed objects. Shared instances (one copy of a prototype traced through
//! each instance's transform) render within rounding of the flat scene, the same bits on any
//! threads and tiles, far from the origin too, with shadows, reflections and transparency;
//! `instancing: Auto` bakes where baking is exact and small and shares otherwise; a thousand
//! shared copies of a big mesh cost about one copy.

mod common;

use common::{registry, run, stderr, temp_dir};
use luxon::motion::Placement;
use luxon::{Framebuffer, Scene};
use luxon_formats::{SceneDesc, TransformDesc};
use std::fmt::Write as _;
use std::path::Path;

/// A prototype object, as numbers (written into RON by `params`).
enum Obj {
    Sphere([f64; 3], f64),
    Spheres(Vec<[f64; 3]>, f64),
    Mesh {
        positions: Vec<[f64; 3]>,
        normals: Vec<[f64; 3]>,
        uvs: Vec<[f64; 2]>,
        indices: Vec<[u64; 3]>,
    },
    Plane([f64; 3], [f64; 3]),
    /// An open cylinder (base, apex, radius).
    Tube([f64; 3], [f64; 3], f64),
    /// A ring (centre, normal, inner, outer).
    Ring([f64; 3], [f64; 3], f64, f64),
}

/// How a copy is moved: points, normals, and the radius factor.
trait Move {
    fn point(&self, p: [f64; 3]) -> [f64; 3];
    fn normal(&self, n: [f64; 3]) -> [f64; 3];
    fn radius(&self, r: f64) -> f64;
}

/// The prototype as written: nothing moves.
struct Stay;

impl Move for Stay {
    fn point(&self, p: [f64; 3]) -> [f64; 3] {
        p
    }
    fn normal(&self, n: [f64; 3]) -> [f64; 3] {
        n
    }
    fn radius(&self, r: f64) -> f64 {
        r
    }
}

impl Move for Placement {
    fn point(&self, p: [f64; 3]) -> [f64; 3] {
        Placement::point(self, p)
    }
    fn normal(&self, n: [f64; 3]) -> [f64; 3] {
        Placement::normal(self, n)
    }
    fn radius(&self, r: f64) -> f64 {
        r * self
            .uniform_scale()
            .expect("a uniform scale for round primitives")
    }
}

fn v(p: [f64; 3]) -> String {
    format!("({:?}, {:?}, {:?})", p[0], p[1], p[2])
}

impl Obj {
    /// `(plugin: ..., params: ...)` without the closing parenthesis, moved by `m`.
    fn text(&self, m: &dyn Move) -> String {
        match self {
            Obj::Sphere(c, r) => format!(
                "(plugin: \"sphere\", params: (center: {}, radius: {:?})",
                v(m.point(*c)),
                m.radius(*r)
            ),
            Obj::Spheres(cs, r) => {
                let cs: Vec<String> = cs.iter().map(|c| v(m.point(*c))).collect();
                format!(
                    "(plugin: \"spheres\", params: (centers: [{}], radius: {:?})",
                    cs.join(", "),
                    m.radius(*r)
                )
            }
            Obj::Mesh {
                positions,
                normals,
                uvs,
                indices,
            } => {
                let p: Vec<String> = positions.iter().map(|p| v(m.point(*p))).collect();
                let n: Vec<String> = normals.iter().map(|n| v(m.normal(*n))).collect();
                let uv: Vec<String> = uvs
                    .iter()
                    .map(|u| format!("({:?}, {:?})", u[0], u[1]))
                    .collect();
                let i: Vec<String> = indices
                    .iter()
                    .map(|t| format!("({}, {}, {})", t[0], t[1], t[2]))
                    .collect();
                format!(
                    "(plugin: \"mesh\", params: (positions: [{}], normals: [{}], uvs: [{}], indices: [{}])",
                    p.join(", "),
                    n.join(", "),
                    uv.join(", "),
                    i.join(", ")
                )
            }
            Obj::Plane(p, n) => format!(
                "(plugin: \"plane\", params: (point: {}, normal: {})",
                v(m.point(*p)),
                v(m.normal(*n))
            ),
            Obj::Tube(b, a, r) => format!(
                "(plugin: \"cylinder\", params: (base: {}, apex: {}, radius: {:?}, caps: false)",
                v(m.point(*b)),
                v(m.point(*a)),
                m.radius(*r)
            ),
            Obj::Ring(c, n, i, o) => format!(
                "(plugin: \"ring\", params: (center: {}, normal: {}, inner: {:?}, outer: {:?})",
                v(m.point(*c)),
                v(m.normal(*n)),
                m.radius(*i),
                m.radius(*o)
            ),
        }
    }
}

/// A prototype: its name and (object, material) pairs.
type Prototype = (&'static str, Vec<(Obj, &'static str)>);

fn prototypes() -> Vec<Prototype> {
    // A little tetrahedron with shading normals (unit axes, so the plugin's normalising leaves
    // them as they are) and uvs.
    let tetra = Obj::Mesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.1],
            [0.2, 0.9, 0.0],
            [0.3, 0.3, 0.8],
        ],
        normals: vec![
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.5]],
        indices: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    };
    vec![
        (
            "atoms",
            vec![
                (Obj::Sphere([0.0, 0.0, 0.0], 0.45), "red"),
                (
                    Obj::Spheres(
                        vec![[0.6, 0.2, 0.1], [-0.5, 0.3, -0.2], [0.1, -0.4, 0.5]],
                        0.2,
                    ),
                    "white",
                ),
                (Obj::Tube([0.0, 0.0, 0.0], [0.0, 0.9, 0.0], 0.08), "white"),
                (Obj::Ring([0.0, 0.9, 0.0], [0.0, 1.0, 0.0], 0.1, 0.3), "red"),
            ],
        ),
        ("tetra", vec![(tetra, "mirror")]),
        (
            "floor",
            vec![(Obj::Plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]), "white")],
        ),
    ]
}

/// (prototype, `world_from_object` as RON, material override).
const INSTANCES: &[(&str, &str, Option<&str>)] = &[
    ("floor", "(translate: (0, -1.2, 0), rotate: (axis: (1, 0, 0.3), degrees: 4))", None),
    ("atoms", "()", None),
    ("atoms", "(translate: (2.1, 0.3, 0.5))", Some("white")),
    ("atoms", "(rotate: (axis: (1, 2, 3), degrees: 37), translate: (-2, 0.2, 0))", None),
    ("atoms", "(scale: (0.5, 0.5, 0.5), rotate: (axis: (0, 1, 0), degrees: -60), translate: (0.3, -0.8, -1.5))", None),
    ("atoms", "(matrix: ((0, 0, -1.5, 1.2), (0, 1.5, 0, 1.1), (1.5, 0, 0, 2.0)))", Some("mirror")),
    ("tetra", "(translate: (-1.1, -0.9, -1.8), scale: (-1, 1, 1))", None),
    ("tetra", "(matrix: ((1, 0.4, 0, 0.9), (0, 1, 0, -1.0), (0.2, 0, 1.3, -1.9)))", None),
    ("tetra", "(scale: (0.7, 1.4, 0.5), rotate: (axis: (0, 0, 1), degrees: 25), translate: (2.2, -1.0, -0.8))", Some("red")),
];

const HEAD: &str = r#"Scene(
    camera: (position: (0.5, 2.5, -7), look_at: (0, -0.2, 0), fov: 45),
    background: (0.1, 0.12, 0.2),
    lights: [
        Point(position: (-4, 6, -5), intensity: 0.8),
        Directional(direction: (1, -1, 0.5), intensity: 0.4),
    ],
    materials: {
        "red": (color: (0.85, 0.2, 0.15), specular: 0.4, shininess: 30),
        "white": (color: (0.9, 0.9, 0.85)),
        "mirror": (color: (0.5, 0.6, 0.9), reflect: 0.4, specular: 0.6),
    },
    objects: [
        (plugin: "sphere", params: (center: (0, 1.6, 2.5), radius: 0.6), material: "mirror"),
"#;

const TAIL: &str = r#"    render: (width: 96, height: 72, samples: 2),
)
"#;

/// The scene with `prototypes:` and `instances:`.
fn instanced(instances: &[(&str, &str, Option<&str>)]) -> String {
    let mut s = format!("{HEAD}    ],\n    prototypes: {{\n");
    for (name, objects) in prototypes() {
        let _ = writeln!(s, "        \"{name}\": (objects: [");
        for (o, m) in &objects {
            let _ = writeln!(s, "            {}, material: \"{m}\"),", o.text(&Stay));
        }
        s.push_str("        ]),\n");
    }
    s.push_str("    },\n    instances: [\n");
    for (p, t, m) in instances {
        let _ = write!(s, "        (prototype: \"{p}\", world_from_object: {t}");
        if let Some(m) = m {
            let _ = write!(s, ", material: \"{m}\"");
        }
        s.push_str("),\n");
    }
    s.push_str("    ],\n");
    s + TAIL
}

/// The same geometry written out flat: each instance's objects after the scene's own, moved by
/// its transform (read from the instanced scene's description).
fn flat(desc: &SceneDesc, instances: &[(&str, &str, Option<&str>)]) -> String {
    let protos = prototypes();
    let mut s = HEAD.to_string();
    for ((p, _, m), inst) in instances.iter().zip(&desc.instances) {
        let t: &TransformDesc = &inst.value.world_from_object.value;
        let placement = Placement::from_desc(t);
        let (_, objects) = protos.iter().find(|(n, _)| n == p).unwrap();
        for (o, own) in objects {
            let material = m.unwrap_or(own);
            let _ = writeln!(
                s,
                "        {}, material: \"{material}\"),",
                o.text(&placement)
            );
        }
    }
    s.push_str("    ],\n");
    s + TAIL
}

fn load(dir: &Path, name: &str, text: &str) -> SceneDesc {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    luxon_formats::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn build(desc: &SceneDesc) -> Result<Scene, luxon::Error> {
    Scene::build(desc, &registry(desc))
}

fn render(desc: &SceneDesc, threads: u32) -> Framebuffer {
    render_tiles(desc, threads, desc.render.parallel.tile_size)
}

fn render_tiles(desc: &SceneDesc, threads: u32, tile: u32) -> Framebuffer {
    let mut desc = desc.clone();
    desc.render.parallel.threads = Some(threads);
    desc.render.parallel.tile_size = tile;
    let scene = build(&desc).unwrap_or_else(|e| panic!("{e}"));
    luxon::render::render(&scene, &|_, _| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

fn bits(fb: &Framebuffer) -> Vec<u32> {
    fb.rgba.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn baked_instances_render_the_bits_of_the_flat_scene() {
    let dir = temp_dir("inst-flat");
    let inst = load(&dir, "instanced.ron", &instanced(INSTANCES));
    let flat_text = flat(&inst, INSTANCES);
    let flat = load(&dir, "flat.ron", &flat_text);
    assert!(flat.instances.is_empty() && flat.prototypes.is_empty());
    let scene = build(&inst).unwrap();
    let flat_scene = build(&flat).unwrap();
    // Same primitives in both, and every instance realised by baking.
    assert_eq!(scene.spheres.len(), flat_scene.spheres.len());
    assert_eq!(scene.triangles.len(), flat_scene.triangles.len());
    assert_eq!(scene.cones.len(), flat_scene.cones.len());
    assert_eq!(scene.discs.len(), flat_scene.discs.len());
    assert_eq!(scene.planes.planes.len(), flat_scene.planes.planes.len());
    let baked: Vec<(String, usize)> = scene
        .prototypes
        .iter()
        .map(|p| (p.name.clone(), p.baked))
        .collect();
    assert_eq!(
        baked,
        [
            ("atoms".into(), 5),
            ("tetra".into(), 3),
            ("floor".into(), 1)
        ]
    );
    let want = render(&flat, 1);
    // Not a blank picture: the instances are there in many colours.
    let distinct: std::collections::HashSet<_> =
        bits(&want).chunks(4).map(|p| p.to_vec()).collect();
    assert!(distinct.len() > 200, "{} colours", distinct.len());
    for threads in [1, 3] {
        let got = render(&inst, threads);
        assert!(
            bits(&got) == bits(&want),
            "{threads} threads: the instanced scene differs from the flat one"
        );
    }
}

#[test]
fn transforms_scale_then_rotate_then_move() {
    // Checked against Rodrigues' rotation formula, so the flat scene above (which takes its
    // coordinates from `Placement`) is not checked against itself alone.
    let dir = temp_dir("inst-order");
    let inst = load(&dir, "instanced.ron", &instanced(INSTANCES));
    let p = Placement::from_desc(&inst.instances[4].value.world_from_object.value);
    let rodrigues = |v: [f64; 3], k: [f64; 3], deg: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        let kxv = [
            k[1] * v[2] - k[2] * v[1],
            k[2] * v[0] - k[0] * v[2],
            k[0] * v[1] - k[1] * v[0],
        ];
        let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
        [0, 1, 2].map(|i| v[i] * c + kxv[i] * s + k[i] * kv * (1.0 - c))
    };
    let q = [0.6, 0.2, 0.1];
    let r = rodrigues(q.map(|x| x * 0.5), [0.0, 1.0, 0.0], -60.0);
    let want = [r[0] + 0.3, r[1] - 0.8, r[2] - 1.5];
    let got = p.point(q);
    assert!(
        (0..3).all(|i| (got[i] - want[i]).abs() < 1e-12),
        "{got:?} {want:?}"
    );
    // Rows of a matrix: x' = 0x + 0y - 1.5z + 1.2.
    let m = Placement::from_desc(&inst.instances[5].value.world_from_object.value);
    assert_eq!(m.point([0.0, 0.0, 1.0]), [-0.30000000000000004, 1.1, 2.0]);
}

#[test]
fn identity_instances_equal_the_prototype_written_in_place() {
    // The identity (no `world_from_object`) stores the recorded values unchanged.
    let dir = temp_dir("inst-identity");
    let one = [("atoms", "()", None), ("tetra", "()", None)];
    let inst = load(
        &dir,
        "instanced.ron",
        &instanced(&one).replace(", world_from_object: ()", ""),
    );
    assert_eq!(
        inst.instances[0].value.world_from_object.value,
        TransformDesc::IDENTITY
    );
    let flat = load(&dir, "flat.ron", &flat(&inst, &one));
    assert!(bits(&render(&inst, 2)) == bits(&render(&flat, 2)));
}

#[test]
fn a_thousand_instances_render() {
    let dir = temp_dir("inst-many");
    let mut s = String::from(
        r#"Scene(
    camera: (position: (0, 40, -60), look_at: (0, 0, 0), fov: 40),
    lights: [Directional(direction: (-1, -2, 1))],
    materials: { "gold": (color: (0.9, 0.7, 0.2), specular: 0.5) },
    prototypes: {
        "dot": (objects: [
            (plugin: "sphere", params: (center: (0, 0.5, 0), radius: 0.5), material: "gold"),
            (plugin: "cylinder", params: (base: (0, 0, 0), apex: (0, 1.5, 0), radius: 0.15)),
        ]),
    },
    instances: [
"#,
    );
    for i in 0..1000 {
        let (x, z) = ((i % 40) as f64 - 19.5, (i / 40) as f64 - 12.0);
        let _ = writeln!(
            s,
            "        (prototype: \"dot\", world_from_object: (translate: ({}, 0, {}), rotate: (axis: (0, 1, 0), degrees: {})), material: \"gold\"),",
            x * 1.5,
            z * 2.0,
            i * 7
        );
    }
    s.push_str("    ],\n    render: (width: 64, height: 48),\n)\n");
    let desc = load(&dir, "many.ron", &s);
    let scene = build(&desc).unwrap();
    assert_eq!(scene.spheres.len(), 1000);
    assert_eq!(scene.cones.len(), 1000);
    assert_eq!(scene.prototypes[0].baked, 1000);
    let fb = render(&desc, 2);
    // The field of copies fills the lower part of the picture, from side to side.
    let lit = |x0: u32, x1: u32| {
        (0..48)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| fb.rgba[4 * (y * 64 + x) as usize] > 0.2)
            .count()
    };
    assert!(lit(0, 64) > 400, "only {} lit pixels", lit(0, 64));
    assert!(lit(0, 16) > 50 && lit(48, 64) > 50);
}

/// The build's error for `instances` (and `prototypes`) in a small scene.
fn build_error(prototypes: &str, instances: &str) -> String {
    let dir = temp_dir("inst-errors");
    let text = format!(
        "Scene(\n    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n    prototypes: {{ {prototypes} }},\n    instances: [\n        {instances}\n    ],\n    render: (instancing: Bake),\n)\n"
    );
    let desc = load(&dir, "bad.ron", &text);
    match build(&desc) {
        Ok(_) => panic!("built:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn baking_refuses_to_stretch_spheres_and_names_the_instance() {
    let e = build_error(
        r#""ball": (objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 1))])"#,
        r#"(prototype: "ball", name: "egg", world_from_object: (scale: (1, 2, 1))),"#,
    );
    assert!(e.contains("bad.ron:5:61"), "{e}");
    assert!(e.contains("instance 0 (`egg`) of prototype `ball`"), "{e}");
    assert!(e.contains("does not scale the same on every axis"), "{e}");
    // A mesh takes any invertible map.
    let dir = temp_dir("inst-mesh-stretch");
    let text = r#"Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    prototypes: { "tri": (objects: [(plugin: "triangle", params: (vertices: ((0, 0, 0), (1, 0, 0), (0, 1, 0))))]) },
    instances: [(prototype: "tri", world_from_object: (scale: (1, 2, 1)))],
)"#;
    let scene = build(&load(&dir, "ok.ron", text)).unwrap();
    assert_eq!(scene.triangles.len(), 1);
}

#[test]
fn custom_geometry_cannot_be_baked() {
    let e = build_error(
        r#""box": (objects: [(plugin: "box", params: (min: (0, 0, 0), max: (1, 1, 1)))])"#,
        r#"(prototype: "box"),"#,
    );
    assert!(e.contains("bad.ron:3:"), "{e}");
    assert!(e.contains("copied into instances"), "{e}");
}

#[test]
fn check_prints_each_prototype_and_how_it_was_realised() {
    let dir = temp_dir("inst-check");
    let path = dir.join("scene.ron");
    std::fs::write(&path, instanced(INSTANCES)).unwrap();
    let out = run(&["check", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("prototype  `atoms`: 4 objects, 6 primitives per copy; 5 instances: 5 baked (flat copies)"),
        "{text}"
    );
    assert!(
        text.contains("prototype  `floor`: 1 object, 1 primitive per copy; 1 instance: 1 baked"),
        "{text}"
    );
    // `--instancing share` on the command line: every copy shared.
    let out = run(&["check", path.to_str().unwrap(), "--instancing", "share"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("`tetra`: 1 object, 4 primitives per copy; 3 instances: 3 shared (one copy, two-level BVH)"),
        "{text}"
    );
}

#[test]
fn convert_round_trips_prototypes_and_instances() {
    let dir = temp_dir("inst-convert");
    let src = dir.join("scene.ron");
    std::fs::write(&src, instanced(INSTANCES)).unwrap();
    let out_path = dir.join("out.ron");
    let out = run(&[
        "convert",
        src.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let a = luxon_formats::load(&src).unwrap();
    let b = luxon_formats::load(&out_path).unwrap();
    let strip = |d: &SceneDesc| {
        let p: Vec<_> = d
            .prototypes
            .iter()
            .map(|(n, p)| (n.clone(), p.value.objects.len()))
            .collect();
        let i: Vec<_> = d
            .instances
            .iter()
            .map(|i| {
                let i = &i.value;
                (
                    i.prototype.value.clone(),
                    i.world_from_object.value,
                    i.material.as_ref().map(|m| m.value.clone()),
                )
            })
            .collect();
        (p, i)
    };
    assert_eq!(strip(&a), strip(&b));
    assert!(bits(&render(&a, 2)) == bits(&render(&b, 2)));
}

/// Orthographic 64x32 over x in [-2, 2], y in [-1, 1]; `what` adds the moving thing and its
/// keys (frames 0 to 2).
fn keyed_scene(what: &str) -> String {
    format!(
        r#"Scene(
    camera: (position: (0, 0, 10), look_at: (0, 0, 0), projection: Orthographic(height: 2)),
    lights: [Directional(direction: (0, 0, -1), shadows: false)],
    materials: {{ "paint": (color: (1, 0, 0), ambient: 1, diffuse: 0) }},
    {what}
    render: (width: 64, height: 32),
)"#
    )
}

#[test]
fn keyed_instances_move_like_keyed_objects() {
    let dir = temp_dir("inst-keyed");
    let keys = r#"animation: (frames: (0, 2), objects: { "b": (translate: (keys: [(0, (-1.2, 0, 0)), (2, (1.2, 0, 0))]),
        rotate: (keys: [(0, (axis: (0, 0, 1), degrees: 0)), (2, (axis: (0, 0, 1), degrees: 90))])) }),"#;
    let object = keyed_scene(&format!(
        r#"objects: [(plugin: "cylinder", name: "b", params: (base: (-0.4, 0, 0), apex: (0.4, 0, 0), radius: 0.1), material: "paint")],
    {keys}"#
    ));
    let instance = keyed_scene(&format!(
        r#"prototypes: {{ "bar": (objects: [(plugin: "cylinder", params: (base: (-0.4, 0, 0), apex: (0.4, 0, 0), radius: 0.1), material: "paint")]) }},
    instances: [(prototype: "bar", name: "b", world_from_object: (translate: (5, 5, 5)))],
    {keys}"#
    ));
    let a = load(&dir, "object.ron", &object);
    let b = load(&dir, "instance.ron", &instance);
    let (mut sa, mut sb) = (build(&a).unwrap(), build(&b).unwrap());
    assert_eq!(sb.prototypes[0].keyed, 1);
    assert_eq!(sb.cones.len(), 0, "a keyed instance is not baked");
    let out = run(&["check", dir.join("instance.ron").to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("1 instance: 1 keyed (placed anew each frame)"),
        "{text}"
    );
    assert!(
        text.contains("keyed: instance `b` translate (Linear, 2 keys), rotate"),
        "{text}"
    );
    for k in 0..3 {
        sa.set_frame(k).unwrap();
        sb.set_frame(k).unwrap();
        let fa = luxon::render::render(&sa, &|_, _| {}).unwrap().0;
        let fb = luxon::render::render(&sb, &|_, _| {}).unwrap().0;
        assert!(bits(&fa) == bits(&fb), "frame {k}");
        assert!(
            fb.rgba.chunks(4).any(|p| p[0] > 0.5),
            "frame {k} shows the bar"
        );
    }
    // A static `translate` holds where no translate keys are given.
    let still = keyed_scene(
        r#"prototypes: { "bar": (objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 0.3), material: "paint")]) },
    instances: [(prototype: "bar", name: "b", world_from_object: (translate: (1.5, 0, 0)))],
    animation: (frames: (0, 1), objects: { "b": (scale: (keys: [(0, (1, 1, 1)), (1, (2, 2, 2))])) }),"#,
    );
    let desc = load(&dir, "still.ron", &still);
    let scene = build(&desc).unwrap();
    let fb = luxon::render::render(&scene, &|_, _| {}).unwrap().0;
    let red = |x: u32, y: u32| fb.rgba[4 * (y * 64 + x) as usize] > 0.5;
    assert!(red(56, 16) && !red(32, 16), "the ball sits at x = 1.5");
}

#[test]
fn a_keyed_matrix_instance_is_refused() {
    let dir = temp_dir("inst-keyed-matrix");
    let text = keyed_scene(
        r#"prototypes: { "bar": (objects: [(plugin: "sphere", params: (center: (0, 0, 0), radius: 0.3))]) },
    instances: [(prototype: "bar", name: "b", world_from_object: (matrix: ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0))))],
    animation: (frames: (0, 1), objects: { "b": (scale: (keys: [(0, (1, 1, 1))])) }),"#,
    );
    let e = match build(&load(&dir, "m.ron", &text)) {
        Ok(_) => panic!("built"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("m.ron:7:44"), "{e}");
    assert!(
        e.contains("placed by a `matrix`, which keys cannot change"),
        "{e}"
    );
}

/// A tetrahedron with normals and uvs, as an OBJ file moved by `m`.
fn obj(m: &dyn Move) -> String {
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.2],
        [0.1, 1.0, 0.0],
        [0.4, 0.3, 0.9],
    ];
    let n = [
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.3, 0.3, 0.9],
    ];
    let mut s = String::new();
    for p in v {
        let p = m.point(p);
        let _ = writeln!(s, "v {:?} {:?} {:?}", p[0], p[1], p[2]);
    }
    for q in n {
        let q = m.normal(q);
        let _ = writeln!(s, "vn {:?} {:?} {:?}", q[0], q[1], q[2]);
    }
    s.push_str("vt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\n");
    s.push_str(
        "f 1/1/1 3/3/3 2/2/2\nf 1/1/1 2/2/2 4/4/4\nf 2/2/2 3/3/3 4/4/4\nf 3/3/3 1/1/1 4/4/4\n",
    );
    s
}

#[test]
fn mesh_files_in_prototypes_bake_like_the_moved_file() {
    let dir = temp_dir("inst-obj");
    std::fs::write(dir.join("tetra.obj"), obj(&Stay)).unwrap();
    let transforms = [
        "(translate: (-1, -0.5, 0))",
        "(rotate: (axis: (1, 2, 3), degrees: 37), translate: (1, 0, 0))",
        "(matrix: ((-1.2, 0, 0, 0.2), (0, 1.2, 0, 0.5), (0, 0, 1.2, -1)))",
    ];
    let head = r#"Scene(
    camera: (position: (0, 1, -5), look_at: (0, 0, 0), fov: 50),
    lights: [Point(position: (-3, 4, -5))],
    materials: { "red": (color: (0.8, 0.2, 0.1), specular: 0.5), "blue": (color: (0.2, 0.3, 0.9)) },
"#;
    let mut inst = format!(
        "{head}    prototypes: {{ \"t\": (objects: [(plugin: \"sphere\", params: (center: (0, 0, 0), radius: 0.2), material: \"blue\")], meshes: [(file: \"tetra.obj\", material: \"red\")]) }},\n    instances: [\n"
    );
    for t in transforms {
        let _ = writeln!(inst, "        (prototype: \"t\", world_from_object: {t}),");
    }
    inst.push_str("    ],\n    render: (width: 80, height: 60),\n)\n");
    let inst = load(&dir, "instanced.ron", &inst);
    let mut spheres = Vec::new();
    let mut meshes = Vec::new();
    for (k, i) in inst.instances.iter().enumerate() {
        let p = Placement::from_desc(&i.value.world_from_object.value);
        std::fs::write(dir.join(format!("t{k}.obj")), obj(&p)).unwrap();
        spheres.push(format!(
            "{}, material: \"blue\")",
            Obj::Sphere([0.0; 3], 0.2).text(&p)
        ));
        meshes.push(format!("(file: \"t{k}.obj\", material: \"red\")"));
    }
    let flat = format!(
        "{head}    objects: [{}],\n    meshes: [{}],\n    render: (width: 80, height: 60),\n)\n",
        spheres.join(", "),
        meshes.join(", ")
    );
    let flat = load(&dir, "flat.ron", &flat);
    let scene = build(&inst).unwrap();
    assert_eq!(scene.triangles.len(), 12);
    assert_eq!(
        (scene.prototypes[0].objects, scene.prototypes[0].meshes),
        (1, 1)
    );
    let want = render(&flat, 2);
    assert!(want.rgba.chunks(4).filter(|p| p[0] > 0.3).count() > 100);
    assert!(bits(&render(&inst, 2)) == bits(&want));
}

/// `text` (a scene of `instanced`) with the render setting `instancing: how`.
fn instancing(text: &str, how: &str) -> String {
    let t = text.replace("samples: 2)", &format!("samples: 2, instancing: {how})"));
    assert_ne!(t, text);
    t
}

/// Shared instances' tolerance against the flat picture: mean |Δ| ≤ 1e-4 over the channels,
/// and at most 0.1 % of pixels with a channel off by more than 1/255.
fn within_rounding(got: &Framebuffer, want: &Framebuffer) -> Result<(), String> {
    let (a, b) = (&got.rgba, &want.rgba);
    assert_eq!(a.len(), b.len());
    let mean = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() as f64)
        .sum::<f64>()
        / a.len() as f64;
    let pixels = a.len() / 4;
    let off = (a.chunks(4).zip(b.chunks(4)))
        .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| (x - y).abs() > 1.0 / 255.0))
        .count();
    if mean <= 1e-4 && off * 1000 <= pixels {
        Ok(())
    } else {
        Err(format!(
            "mean |Δ| {mean:.3e}, {off} of {pixels} pixels off by more than 1/255"
        ))
    }
}

/// How each prototype was realised: (name, baked, shared).
fn realised(scene: &Scene) -> Vec<(String, usize, usize)> {
    (scene.prototypes.iter())
        .map(|p| (p.name.clone(), p.baked, p.shared))
        .collect()
}

#[test]
fn shared_instances_render_the_flat_scene_within_rounding_on_any_threads() {
    let dir = temp_dir("inst-share");
    let inst = load(
        &dir,
        "shared.ron",
        &instancing(&instanced(INSTANCES), "Share"),
    );
    let flat = load(&dir, "flat.ron", &flat(&inst, INSTANCES));
    let scene = build(&inst).unwrap();
    // Nothing baked: the scene's own sphere alone is in its sets.
    assert_eq!(scene.instances.list.len(), INSTANCES.len());
    assert_eq!((scene.spheres.len(), scene.triangles.len()), (1, 0));
    let want = [("atoms", 0, 5), ("tetra", 0, 3), ("floor", 0, 1)];
    let want: Vec<(String, usize, usize)> =
        want.iter().map(|&(n, b, s)| (n.into(), b, s)).collect();
    assert_eq!(realised(&scene), want);
    let first = render_tiles(&inst, 1, 16);
    within_rounding(&first, &render(&flat, 1)).unwrap();
    for (threads, tile) in [(2, 16), (3, 7), (1, 7)] {
        assert!(
            bits(&render_tiles(&inst, threads, tile)) == bits(&first),
            "{threads} threads, tiles of {tile}: not the bits of 1 thread"
        );
    }
}

#[test]
fn auto_bakes_where_exact_and_small_and_shares_otherwise() {
    let dir = temp_dir("inst-auto");
    // Every instance bakes exactly: Auto bakes them all (the bitwise test above covers them).
    let scene = build(&load(&dir, "auto.ron", &instanced(INSTANCES))).unwrap();
    assert!(scene.instances.is_empty());
    assert!(scene.prototypes.iter().all(|p| p.shared == 0));
    // An instance stretching the prototype holding spheres: that prototype is shared, the
    // others still baked.
    let mut list = INSTANCES.to_vec();
    list.push(("atoms", "(scale: (1, 2, 1), translate: (0, 0, 3))", None));
    let desc = load(&dir, "stretched.ron", &instanced(&list));
    let scene = build(&desc).unwrap();
    let want = [("atoms", 0, 6), ("tetra", 3, 0), ("floor", 1, 0)];
    let want: Vec<(String, usize, usize)> =
        want.iter().map(|&(n, b, s)| (n.into(), b, s)).collect();
    assert_eq!(realised(&scene), want);
    assert_eq!(scene.instances.list.len(), 6);
    // Bake refuses that instance by name.
    let bake = load(&dir, "bake.ron", &instancing(&instanced(&list), "Bake"));
    let e = build(&bake).err().expect("an error").to_string();
    assert!(
        e.contains("instance 9 of prototype `atoms`") && e.contains("Share"),
        "{e}"
    );
}

#[test]
fn shared_instances_far_from_the_origin_keep_their_precision() {
    // The scene moved by 1e6 along x, camera and lights included.
    const FAR: &[(&str, &str, Option<&str>)] = &[
        ("floor", "(translate: (1000000, -1.2, 0), rotate: (axis: (1, 0, 0.3), degrees: 4))", None),
        ("atoms", "(translate: (1000000, 0, 0))", None),
        ("atoms", "(translate: (1000002.1, 0.3, 0.5))", Some("white")),
        ("atoms", "(rotate: (axis: (1, 2, 3), degrees: 37), translate: (999998, 0.2, 0))", None),
        ("atoms", "(scale: (0.5, 0.5, 0.5), rotate: (axis: (0, 1, 0), degrees: -60), translate: (1000000.3, -0.8, -1.5))", None),
        ("atoms", "(matrix: ((0, 0, -1.5, 1000001.2), (0, 1.5, 0, 1.1), (1.5, 0, 0, 2.0)))", Some("mirror")),
        ("tetra", "(translate: (999998.9, -0.9, -1.8), scale: (-1, 1, 1))", None),
        ("tetra", "(matrix: ((1, 0.4, 0, 1000000.9), (0, 1, 0, -1.0), (0.2, 0, 1.3, -1.9)))", None),
        ("tetra", "(scale: (0.7, 1.4, 0.5), rotate: (axis: (0, 0, 1), degrees: 25), translate: (1000002.2, -1.0, -0.8))", Some("red")),
    ];
    let far = |how: &str| {
        instancing(&instanced(FAR), how)
            .replace(
                "position: (0.5, 2.5, -7), look_at: (0, -0.2, 0)",
                "position: (1000000.5, 2.5, -7), look_at: (1000000, -0.2, 0)",
            )
            .replace(
                "Point(position: (-4, 6, -5)",
                "Point(position: (999996, 6, -5)",
            )
            .replace("center: (0, 1.6, 2.5)", "center: (1000000, 1.6, 2.5)")
    };
    let dir = temp_dir("inst-far");
    let shared = load(&dir, "shared.ron", &far("Share"));
    let baked = load(&dir, "baked.ron", &far("Bake"));
    assert_eq!(build(&shared).unwrap().instances.list.len(), FAR.len());
    let want = render(&baked, 2);
    // Not an empty view: the copies are in the picture.
    let lit = want.rgba.chunks(4).filter(|p| p[0] > 0.3).count();
    assert!(lit > 500, "{lit} lit pixels");
    within_rounding(&render(&shared, 2), &want).unwrap();
}

#[test]
fn shared_instances_cast_shadows_reflect_and_let_light_through() {
    // Nothing but instances, one material reflecting and transparent.
    let text = instanced(INSTANCES)
        .replace(
            "        (plugin: \"sphere\", params: (center: (0, 1.6, 2.5), radius: 0.6), material: \"mirror\"),\n",
            "",
        )
        .replace("reflect: 0.4, specular: 0.6)", "reflect: 0.4, transmit: 0.5, specular: 0.6)");
    let dir = temp_dir("inst-effects");
    let shared = load(&dir, "shared.ron", &instancing(&text, "Share"));
    let baked = load(&dir, "baked.ron", &instancing(&text, "Bake"));
    let scene = build(&shared).unwrap();
    assert_eq!(scene.primitive_count(), 0);
    let f = scene.features;
    assert!(
        f.shadows && f.reflection && f.transmission && f.shadow_filters,
        "{f:?}"
    );
    assert_eq!(build(&baked).unwrap().features, f);
    within_rounding(&render(&shared, 2), &render(&baked, 2)).unwrap();
}

#[test]
fn a_thousand_shared_copies_of_a_big_mesh_cost_about_one() {
    use luxon::geometry::instance::{Instance, Placement as Placed};
    let dir = temp_dir("inst-memory");
    // A 100 × 100 grid of quads: 20,000 triangles.
    let mut obj = String::new();
    for j in 0..=100 {
        for i in 0..=100 {
            let (x, z) = (i as f64 / 100.0, j as f64 / 100.0);
            let _ = writeln!(
                obj,
                "v {x} {} {z}",
                0.05 * (x * 9.0).sin() * (z * 7.0).cos()
            );
        }
    }
    for j in 0..100 {
        for i in 0..100 {
            let a = j * 101 + i + 1;
            let _ = writeln!(
                obj,
                "f {a} {} {}\nf {} {} {}",
                a + 1,
                a + 102,
                a,
                a + 102,
                a + 101
            );
        }
    }
    std::fs::write(dir.join("grid.obj"), obj).unwrap();
    let scene = |copies: usize, how: &str| {
        let mut s = String::from(
            "Scene(\n    camera: (position: (0, 30, -40), look_at: (0, 0, 0)),\n    prototypes: { \"grid\": (meshes: [(file: \"grid.obj\")]) },\n    instances: [\n",
        );
        for k in 0..copies {
            let (x, z) = ((k % 40) as f64 * 1.5, (k / 40) as f64 * 1.5);
            let _ = writeln!(
                s,
                "        (prototype: \"grid\", world_from_object: (translate: ({x}, 0, {z}), rotate: (axis: (0, 1, 0), degrees: {}))),",
                k * 7
            );
        }
        let _ = write!(
            s,
            "    ],\n    render: (width: 32, height: 24, instancing: {how}),\n)\n"
        );
        build(&load(&dir, &format!("grid{copies}.ron"), &s)).unwrap()
    };
    // 1,000 copies of 20,000 triangles are past Auto's baking limit: shared.
    let many = scene(1000, "Auto");
    let one = scene(1, "Share");
    assert_eq!((many.triangles.len(), many.instances.list.len()), (0, 1000));
    assert_eq!(many.instances.blases[0].triangles.len(), 20_000);
    let (m, o) = (many.instances.memory_bytes(), one.instances.memory_bytes());
    let per = std::mem::size_of::<Instance>() + std::mem::size_of::<Placed>();
    assert!(
        m as f64 <= 1.1 * (o + 1000 * per as u64) as f64,
        "{m} bytes for 1,000 copies, {o} for one, {per} per instance"
    );
    // About 350 bytes per instance (its placement and its share of the top level).
    let each = (m - o) / 999;
    assert!((250..=450).contains(&each), "{each} bytes per instance");
    // One copy is far more than that: baking 1,000 would cost 1,000 times it.
    assert!(o > 1_000_000, "{o} bytes for one copy");
}

#[test]
fn keyed_shared_instances_get_a_new_top_level_each_frame() {
    let dir = temp_dir("inst-keyed-share");
    let text = |how: &str| {
        keyed_scene(
            r#"prototypes: { "bar": (objects: [(plugin: "cylinder", params: (base: (-0.4, 0, 0), apex: (0.4, 0, 0), radius: 0.1), material: "paint")]) },
    instances: [
        (prototype: "bar", name: "b", world_from_object: (translate: (5, 5, 5))),
        (prototype: "bar", world_from_object: (translate: (0, 0.6, 0), scale: (1.5, 1.5, 1.5))),
    ],
    animation: (frames: (0, 2), objects: { "b": (translate: (keys: [(0, (-1.2, 0, 0)), (2, (1.2, 0, 0))]),
        rotate: (keys: [(0, (axis: (0, 0, 1), degrees: 0)), (2, (axis: (0, 0, 1), degrees: 90))])) }),"#,
        )
        .replace("height: 32)", &format!("height: 32, instancing: {how})"))
    };
    let shared = load(&dir, "shared.ron", &text("Share"));
    let baked = load(&dir, "baked.ron", &text("Bake"));
    let (mut s, mut b) = (build(&shared).unwrap(), build(&baked).unwrap());
    // Both copies share the prototype; nothing is placed in the moving group.
    assert_eq!((s.instances.list.len(), s.cones.len()), (2, 0));
    assert!(s.moving.is_empty());
    assert_eq!((s.prototypes[0].keyed, s.prototypes[0].shared), (1, 1));
    let mut frames = Vec::new();
    for k in 0..3 {
        s.set_frame(k).unwrap();
        b.set_frame(k).unwrap();
        let fs = luxon::render::render(&s, &|_, _| {}).unwrap().0;
        let fb = luxon::render::render(&b, &|_, _| {}).unwrap().0;
        assert!(
            fs.rgba.chunks(4).filter(|p| p[0] > 0.5).count() > 20,
            "frame {k}"
        );
        within_rounding(&fs, &fb).unwrap_or_else(|e| panic!("frame {k}: {e}"));
        frames.push(bits(&fs));
    }
    assert!(frames[0] != frames[2], "the bar moves");
    // Frame 1 alone, in a fresh scene, is frame 1 of the sequence.
    let mut fresh = build(&shared).unwrap();
    fresh.set_frame(1).unwrap();
    let f1 = luxon::render::render(&fresh, &|_, _| {}).unwrap().0;
    assert!(bits(&f1) == frames[1]);
}
