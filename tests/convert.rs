//! `luxon convert`: a scene of any format written as RON reads back as the same description
//! (camera, lights, fog, occlusion, textures, materials, clip groups, volumes, render
//! settings, and the imported geometry as the objects that store it) and renders bitwise the
//! same image. Tachyon scenes written here cover every kind of statement; Debian's Tachyon
//! examples are converted too when `tachyon-doc` is installed; an NFF scene, an OBJ file and a
//! RON scene with an OBJ mesh and outputs complete the formats. Through the command line, a
//! Tachyon example (or a scene of its own) and an NFF scene converted with `luxon convert` and
//! rendered with `luxon render` give the source's pixels, and the warnings say what is not
//! carried over. An animated scene keeps its keys.

mod common;

use common::*;
use luxon::Scene;
use luxon_formats::{
    inline_as_objects, load_ron_str, to_ron, CameraDesc, Interpolate, MaterialDesc, ObjectDesc,
    OutputDesc, Projection, SceneDesc, Spanned, Track,
};
use std::path::{Path, PathBuf};

/// The camera with its window size normalised: with a frustum, the projection's own size is
/// not used and RON takes none beside it.
fn camera(c: &CameraDesc) -> CameraDesc {
    let mut c = c.clone();
    if c.frustum.is_some() {
        c.projection = match c.projection {
            Projection::Perspective { .. } | Projection::PerspectiveZoom { .. } => {
                Projection::Perspective { fov_deg: 0.0 }
            }
            Projection::Orthographic { .. } => Projection::Orthographic { height: 0.0 },
            p => p,
        };
    }
    c
}

/// Objects without positions: plugin, parameters, material, clip group.
fn objects(v: &[ObjectDesc]) -> Vec<(String, String, Option<String>, Option<String>)> {
    v.iter()
        .map(|o| {
            (
                o.call.plugin.value.clone(),
                o.call.params.clone(),
                o.material.as_ref().map(|m| m.value.clone()),
                o.clip.as_ref().map(|c| c.value.clone()),
            )
        })
        .collect()
}

fn outputs(v: &[OutputDesc]) -> Vec<(PathBuf, Option<String>, String)> {
    v.iter()
        .map(|o| {
            (
                std::path::absolute(&o.path).unwrap(),
                o.plugin.as_ref().map(|p| p.value.clone()),
                o.params.clone(),
            )
        })
        .collect()
}

fn values<T: Clone>(v: &[Spanned<T>]) -> Vec<T> {
    v.iter().map(|x| x.value.clone()).collect()
}

fn named<T: Clone>(v: &[(String, Spanned<T>)]) -> Vec<(String, T)> {
    v.iter()
        .map(|(n, x)| (n.clone(), x.value.clone()))
        .collect()
}

/// A name without its position.
fn name(n: &Option<Spanned<String>>) -> Option<String> {
    n.as_ref().map(|n| n.value.clone())
}

/// A material's texture names without their positions.
fn material(m: &MaterialDesc) -> (MaterialDesc, [Option<String>; 3]) {
    let mut plain = m.clone();
    let names = [&m.texture, &m.reflect_texture, &m.transmit_texture].map(name);
    (plain.texture, plain.reflect_texture, plain.transmit_texture) = (None, None, None);
    // Without highlights the exponent is unused, and written as the default when not positive.
    if plain.specular == 0.0 && plain.shininess <= 0.0 {
        plain.shininess = MaterialDesc::default().shininess;
    }
    (plain, names)
}

/// A track's keys (frame, value) and interpolation, without their positions.
type Keys<T> = Option<(Vec<(f64, T)>, Interpolate)>;

fn keys<T: Clone>(t: &Option<Track<T>>) -> Keys<T> {
    let t = t.as_ref()?;
    let keys = t.keys.iter().map(|k| (k.frame, k.value.clone())).collect();
    Some((keys, t.interpolation))
}

/// The animation without positions: frames, shutter, and every track by what it keys (light
/// and object indices, names).
fn animation(d: &SceneDesc) -> Option<String> {
    let a = &d.animation.as_ref()?.value;
    let c = &a.camera;
    let camera = (
        keys(&c.position),
        keys(&c.look_at),
        keys(&c.up),
        keys(&c.fov),
        keys(&c.focal_distance),
    );
    let lights: Vec<_> = a
        .lights
        .iter()
        .map(|l| {
            let tracks = (
                keys(&l.position),
                keys(&l.direction),
                keys(&l.intensity),
                keys(&l.color),
            );
            (l.light, &l.name.value, tracks)
        })
        .collect();
    let materials: Vec<_> = a
        .materials
        .iter()
        .map(|m| (&m.material.value, keys(&m.color)))
        .collect();
    let objects: Vec<_> = a
        .objects
        .iter()
        .map(|o| {
            let tracks = (keys(&o.translate), keys(&o.rotate), keys(&o.scale));
            (o.object, &o.name.value, tracks)
        })
        .collect();
    let shutter = a.shutter.as_ref().map(|s| s.value);
    Some(format!(
        "{:?}",
        (
            (a.first, a.last, a.fps, shutter),
            camera,
            lights,
            materials,
            objects
        )
    ))
}

/// Asserts that `back` (read from the RON text) describes what `source` does.
fn assert_same(source: &SceneDesc, back: &SceneDesc, what: &str) {
    assert_eq!(
        camera(&source.camera.value),
        camera(&back.camera.value),
        "{what}: camera"
    );
    assert_eq!(source.background, back.background, "{what}: background");
    assert_eq!(
        values(&source.lights),
        values(&back.lights),
        "{what}: lights"
    );
    assert_eq!(source.fog, back.fog, "{what}: fog");
    assert_eq!(
        source.ambient_occlusion, back.ambient_occlusion,
        "{what}: occlusion"
    );
    let materials = |d: &SceneDesc| {
        named(&d.materials)
            .iter()
            .map(|(n, m)| (n.clone(), material(m)))
            .collect::<Vec<_>>()
    };
    assert_eq!(materials(source), materials(back), "{what}: materials");
    assert_eq!(
        named(&source.clip_groups),
        named(&back.clip_groups),
        "{what}: clip groups"
    );
    let textures = |d: &SceneDesc| {
        d.textures
            .iter()
            .map(|(n, t)| {
                (
                    n.clone(),
                    t.value.plugin.value.clone(),
                    t.value.params.clone(),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(textures(source), textures(back), "{what}: textures");
    let volumes = |d: &SceneDesc| {
        d.volumes
            .iter()
            .map(|v| {
                let v = &v.value;
                (
                    v.call.plugin.value.clone(),
                    v.call.params.clone(),
                    v.name.as_ref().map(|n| n.value.clone()),
                    v.render.as_ref().map(|r| {
                        let mut r = r.value.clone();
                        let clip = name(&r.clip);
                        r.clip = None;
                        (r, clip)
                    }),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(volumes(source), volumes(back), "{what}: volumes");
    // The geometry: the source's objects, then its imported groups as objects.
    let mut expected: Vec<ObjectDesc> = values(&source.objects);
    for g in &source.inline {
        expected.extend(
            inline_as_objects(g, &source.camera.at)
                .into_iter()
                .map(|o| o.value),
        );
    }
    assert!(back.inline.is_empty(), "{what}: imported geometry left");
    assert_eq!(
        objects(&expected),
        objects(&values(&back.objects)),
        "{what}: objects"
    );
    assert_eq!(animation(source), animation(back), "{what}: animation");
    let mut a = source.render.clone();
    let mut b = back.render.clone();
    assert_eq!(outputs(&a.outputs), outputs(&b.outputs), "{what}: outputs");
    (a.outputs, b.outputs) = (Vec::new(), Vec::new());
    assert_eq!(a, b, "{what}: render settings");
}

/// Renders `desc` at 32x24 (the camera window unchanged).
fn render(desc: &SceneDesc) -> Vec<u32> {
    let mut desc = desc.clone();
    desc.render.width = 32;
    desc.render.height = 24;
    desc.render.parallel.threads = Some(2);
    let reg = registry(&desc);
    let scene = Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{e}"));
    let (fb, _) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    fb.rgba.iter().map(|x| x.to_bits()).collect()
}

/// Converts the scene at `path` into `dir`, reads it back, and checks description, text and
/// image; returns the number of distinct pixel values of the image.
fn round_trip(path: &Path, dir: &Path) -> usize {
    let what = path.display().to_string();
    let source = luxon_formats::load(path).unwrap_or_else(|e| panic!("{what}: {e}"));
    let out = dir.join(format!(
        "{}.ron",
        path.file_name().unwrap().to_string_lossy()
    ));
    let text = to_ron(&source, dir).unwrap_or_else(|e| panic!("{what}: {e}"));
    let back = load_ron_str(&text, &out).unwrap_or_else(|e| panic!("{what}: {e}\n{text}"));
    assert_same(&source, &back, &what);
    // Written again, the scene read back gives the same text.
    let again = to_ron(&back, dir).unwrap();
    // The comments at the top name the source and its warnings.
    let body = |t: &str| -> String {
        t.lines()
            .skip_while(|l| l.starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(
        body(&text),
        body(&again),
        "{what}: the text changed on a second round"
    );
    let image = render(&source);
    assert!(image == render(&back), "{what}: the images differ");
    // Equal images prove little if they are empty: the distinct pixel values.
    let pixels: std::collections::HashSet<&[u32]> = image.chunks_exact(4).collect();
    pixels.len()
}

/// Tachyon scenes that use every statement the importer maps to geometry, lights, fog,
/// occlusion, textures, clip planes and camera kinds.
const TACHYON: &[&str] = &[
    "BEGIN_SCENE RESOLUTION 40 30\n\
     CAMERA ZOOM 1.2 ASPECTRATIO 1 ANTIALIASING 1 RAYDEPTH 6 CENTER 0 1 -8 VIEWDIR 0 -0.1 1 \
     UPDIR 0 1 0 END_CAMERA\n\
     BACKGROUND 0.1 0.2 0.3\n\
     SHADER_MODE FULL TRANS_VMD FOG_VMD TRANS_MAX_SURFACES 3 END_SHADER_MODE\n\
     FOG LINEAR START 2 END 30 DENSITY 1 COLOR 0.4 0.4 0.5\n\
     LIGHT CENTER 5 8 -6 RAD 0 ATTENUATION CONSTANT 1 LINEAR 0.01 QUADRATIC 0 COLOR 1 1 1\n\
     DIRECTIONAL_LIGHT DIRECTION -1 -1 1 COLOR 0.3 0.3 0.3\n\
     SPOTLIGHT CENTER 0 6 0 RAD 0 DIRECTION 0 -1 0 FALLOFF_START 20 FALLOFF_END 35 COLOR 0.5 0.5 0.2\n\
     TEXDEF red AMBIENT 0.1 DIFFUSE 0.7 SPECULAR 0.2 OPACITY 1 PHONG PLASTIC 0.5 PHONG_SIZE 30 \
     COLOR 1 0.1 0.1 TEXFUNC 0\n\
     TEXDEF glass AMBIENT 0.1 DIFFUSE 0.3 SPECULAR 0.1 OPACITY 0.4 COLOR 0.6 0.8 1 TEXFUNC 0\n\
     TEXALIAS crimson red\n\
     TEXDEF check AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 COLOR 1 1 1 TEXFUNC 1 \
     CENTER 0 0 0 ROTATE 0 0 0 SCALE 1 1 1\n\
     SPHERE CENTER -2 0 0 RAD 1 red\n\
     SPHERE CENTER 0 0 0 RAD 0.8 glass\n\
     SPHERE CENTER 2 0 0 RAD 0.6 crimson\n\
     SPHERE CENTER 2 1.5 0 RAD 0.3 crimson\n\
     PLANE CENTER 0 -1 0 NORMAL 0 1 0 check\n\
     TRI V0 -3 -1 3 V1 3 -1 3 V2 0 3 3 glass\n\
     STRI V0 -1 2 1 V1 1 2 1 V2 0 3 1 N0 0 0 -1 N1 0.2 0 -1 N2 0 0.2 -1 red\n\
     FCYLINDER BASE -3 -1 1 APEX -3 2 1 RAD 0.2 red\n\
     CYLINDER CENTER 3 0 4 AXIS 0 1 0 RAD 0.3 glass\n\
     RING CENTER 0 2 -1 NORMAL 0 0 1 INNER 0.2 OUTER 0.5 red\n\
     BOX MIN 1 -1 -2 MAX 1.5 -0.5 -1.5 red\n\
     POLYCYLINDER POINTS 3 -2 0 -3 -2 1 -3 -1.5 1 -2 RAD 0.1 red\n\
     START_CLIPGROUP NUMPLANES 1 1 0 0 2\n\
     SPHERE CENTER 2.2 -0.5 -2 RAD 0.5 glass\n\
     END_CLIPGROUP\n\
     VERTEXARRAY NUMVERTS 4 COORDS -1 -1 -3 1 -1 -3 1 0 -3 -1 0 -3 \
     NORMALS 0 0 -1 0 0 -1 0 0 -1 0 0 -1 \
     TEXTURE AMBIENT 0.2 DIFFUSE 0.6 SPECULAR 0 OPACITY 1 COLOR 0.2 1 0.2 TEXFUNC 0 \
     TRIMESH 2 0 1 2 0 2 3 TRISTRIP 4 0 1 3 2 END_VERTEXARRAY\n\
     END_SCENE\n",
    "BEGIN_SCENE RESOLUTION 24 24\n\
     CAMERA PROJECTION ORTHOGRAPHIC ZOOM 0.25 ASPECTRATIO 1 ANTIALIASING 0 RAYDEPTH 3 \
     CENTER 0 0 -5 VIEWDIR 0 0 1 UPDIR 0 1 0 FRUSTUM -2 2 -1.5 2.5 END_CAMERA\n\
     SKY_LIGHT NUMSAMPLES 4 COLOR 0.5 0.5 0.5\n\
     BACKGROUND_GRADIENT SKY_ORTHO_PLANE UPDIR 0 1 0.2 TOPVAL 2 BOTTOMVAL -1 \
     TOPCOLOR 0.9 0.8 0.2 BOTTOMCOLOR 0.1 0.1 0.5\n\
     LIGHT CENTER 0 5 -5 RAD 0 COLOR 1 1 1\n\
     SCAPE RES 8 8 SCALE 4 4 CENTER 0 -1 0 TEXTURE AMBIENT 0.2 DIFFUSE 0.8 SPECULAR 0 \
     OPACITY 1 COLOR 0.5 0.7 0.3 TEXFUNC 0\n\
     SPHERE CENTER 0 0 0 RAD 1 TEXTURE AMBIENT 0.2 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 \
     COLOR 1 1 1 TEXFUNC 0\n\
     END_SCENE\n",
    "BEGIN_SCENE RESOLUTION 30 20\n\
     CAMERA PROJECTION PERSPECTIVE_DOF FOCALDIST 5 APERTURE 0.05 ZOOM 1 ASPECTRATIO 1 \
     ANTIALIASING 2 RAYDEPTH 4 CENTER 0 0 -5 VIEWDIR 0 0 1 UPDIR 0 1 0 END_CAMERA\n\
     SHADER_MODE MEDIUM AMBIENT_OCCLUSION AMBIENT_COLOR 0.3 0.3 0.3 RESCALE_DIRECT 0.6 \
     SAMPLES 4 END_SHADER_MODE\n\
     FOG EXP2 START 0 END 1 DENSITY 0.05 COLOR 1 1 1\n\
     LIGHT CENTER 0 5 -5 RAD 0 COLOR 1 1 1\n\
     SPHERE CENTER 0 0 0 RAD 1 TEXTURE AMBIENT 0.2 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 \
     COLOR 1 0.5 0 TEXFUNC 0\n\
     END_SCENE\n",
    // Vertex colours and a gradient sky.
    "BEGIN_SCENE RESOLUTION 32 24\n\
     CAMERA ZOOM 1 ASPECTRATIO 1 ANTIALIASING 0 RAYDEPTH 3 CENTER 0 0.5 -4 VIEWDIR 0 -0.1 1 \
     UPDIR 0 1 0 END_CAMERA\n\
     BACKGROUND_GRADIENT SKY_SPHERE UPDIR 0.1 1 0 TOPVAL 0.5 BOTTOMVAL -0.2 \
     TOPCOLOR 1 0.6 0.1 BOTTOMCOLOR 0.1 0.2 0.7\n\
     LIGHT CENTER -2 4 -5 RAD 0 COLOR 1 1 1\n\
     VCSTRI V0 -2 0 1 V1 0 2 1 V2 0 0 1 N0 0 0 -1 N1 0 0 -1 N2 0.1 0 -1 \
     C0 1 0 0 C1 0 1 0 C2 0 0 1 AMBIENT 0.2 DIFFUSE 0.7 SPECULAR 0.3 OPACITY 1 \
     PHONG METAL 0.4 PHONG_SIZE 8 VCST\n\
     VERTEXARRAY NUMVERTS 4 COORDS 0 -1 0 2 -1 0 2 1 0 0 1 0 \
     NORMALS 0 0 -1 0 0 -1 0 0 -1 0 0 -1 \
     TEXTURE AMBIENT 0.2 DIFFUSE 0.6 SPECULAR 0 OPACITY 1 COLOR 0.2 1 0.2 TEXFUNC 0 \
     TRIMESH 1 0 2 1 COLORS 1 1 0 0 1 1 1 0 1 1 1 1 TRIMESH 1 0 3 2 \
     TRISTRIP 4 0 1 3 2 END_VERTEXARRAY\n\
     END_SCENE\n",
];

/// An NFF scene: spheres (one glassy), a floor polygon, a cone, a polygon patch with normals,
/// two lights, two materials.
const NFF: &str = "v\nfrom 0 -10 3\nat 0 0 0\nup 0 0 1\nangle 40\nhither 1\nresolution 32 24\n\
    b 0.1 0.2 0.3\nl 5 -5 10\nl -5 -5 10 0.5 0.5 0.5\n\
    f 1 0.2 0.2 0.8 0.2 20 0.3 1.5\ns 0 0 0 1\ns 2 0 0 0.5\n\
    f 0.2 1 0.2 0.8 0 0 0 0\np 4\n-4 -4 -1\n4 -4 -1\n4 4 -1\n-4 4 -1\n\
    c\n-2 1 -1 0.5\n-2 1 1 0.2\n\
    pp 3\n-1 2 0 0 -1 0\n1 2 0 0 -1 0\n0 2 1.5 0 -1 0\n";

#[test]
fn tachyon_scenes_convert_to_the_same_scene() {
    let dir = temp_dir("convert-tachyon");
    for (k, text) in TACHYON.iter().enumerate() {
        let p = dir.join(format!("s{k}.dat"));
        std::fs::write(&p, text).unwrap();
        let colours = round_trip(&p, &dir);
        assert!(colours > 40, "{}: {colours} colours", p.display());
    }
    // Named materials from TEXDEF, the inline bodies numbered.
    let ron = std::fs::read_to_string({
        let o = run(&[
            "convert",
            &dir.join("s0.dat").display().to_string(),
            "-o",
            &dir.join("cli.ron").display().to_string(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        dir.join("cli.ron")
    })
    .unwrap();
    // (TEXALIAS crimson names the material `red`.)
    for name in ["\"red\":", "\"glass\":", "\"check\":"] {
        assert!(ron.contains(name), "{name} missing");
    }
    assert!(ron.contains("(plugin: \"mesh\", params: (\n            positions: ["));
    assert!(ron.contains("(plugin: \"spheres\", params: (\n            centers: ["));
    // The CLI writes what the library writes.
    let source = luxon_formats::load(&dir.join("s0.dat")).unwrap();
    assert_eq!(ron, to_ron(&source, &dir).unwrap());
    // A gradient and vertex colours are written in the scene format's own syntax.
    let sky = to_ron(&luxon_formats::load(&dir.join("s3.dat")).unwrap(), &dir).unwrap();
    assert!(
        sky.contains("background: Gradient(kind: Sphere, up: (0.1, 1.0, -0.0), top: 0.5"),
        "{sky}"
    );
    assert!(sky.contains("\n            colors: [\n"), "{sky}");
    assert!(!sky.contains("not rendered"), "{sky}");
}

#[test]
fn debian_tachyon_examples_convert_to_the_same_scene() {
    let examples = Path::new("/usr/share/doc/tachyon/examples/scenes");
    if !examples.is_dir() {
        eprintln!("note: Debian's tachyon-doc is not installed; its examples are not converted");
        return;
    }
    let dir = temp_dir("convert-debian");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(examples)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dat"))
        .collect();
    scenes.sort();
    let mut converted = 0;
    for p in &scenes {
        // texture.dat does not load in Tachyon either (a PLANE read as an image file name).
        if p.file_name().is_some_and(|n| n == "texture.dat") {
            continue;
        }
        let colours = round_trip(p, &dir);
        // One colour only where the scene is one: null.dat is empty, null2.dat a wall in
        // front of the camera, gridtest.dat spheres 0.01 wide (between the 32x24 samples).
        let flat = ["null.dat", "null2.dat", "gridtest.dat"];
        if !flat.iter().any(|f| p.ends_with(f)) {
            assert!(colours > 40, "{}: {colours} colours", p.display());
        }
        converted += 1;
    }
    assert!(converted >= 40, "only {converted} examples");
}

#[test]
fn nff_and_ron_scenes_convert_too() {
    let dir = temp_dir("convert-other");
    let nff = dir.join("s.nff");
    std::fs::write(&nff, NFF).unwrap();
    assert!(round_trip(&nff, &dir) > 40);
    // An OBJ file on its own (the importer's camera and light), its MTL materials named.
    assert!(round_trip(&root().join("scenes/models/vase.obj"), &dir) > 40);
    // A RON scene with an include, an OBJ mesh file and outputs: merged into one file.
    assert!(round_trip(&root().join("scenes/obj-mesh.ron"), &dir) > 40);
    assert!(round_trip(&root().join("scenes/spheres.ron"), &dir) > 40);
    // The memory settings are carried over.
    let text = std::fs::read_to_string(root().join("scenes/spheres.ron")).unwrap();
    let text = text.replacen(
        "render: (",
        "render: (memory: \"1536M\", texture_cache: \"100 MiB\", ",
        1,
    );
    let budgeted = dir.join("budgeted.ron");
    std::fs::write(&budgeted, text).unwrap();
    assert!(round_trip(&budgeted, &dir) > 40);
}

/// An animated scene keeps its `animation:` block and the names of what it keys: the same
/// tracks read back, and a later frame renders the same image.
#[test]
fn animated_scenes_convert_with_their_keys() {
    let dir = temp_dir("convert-animation");
    let path = root().join("scenes/carousel.ron");
    assert!(round_trip(&path, &dir) > 40);
    let source = luxon_formats::load(&path).unwrap();
    let text = to_ron(&source, &dir).unwrap();
    for name in [
        "name: \"lamp\"",
        "name: \"ball\"",
        "animation: (",
        "CatmullRom",
    ] {
        assert!(text.contains(name), "{name} missing:\n{text}");
    }
    // An animated scene takes no `frame` or `time`: neither is written.
    assert!(!text.contains("frame: 0,"), "{text}");
    let back = load_ron_str(&text, &dir.join("carousel.ron")).unwrap();
    let frame = |desc: &SceneDesc| {
        let mut desc = desc.clone();
        desc.render.width = 32;
        desc.render.height = 24;
        desc.render.parallel.threads = Some(2);
        let mut scene = Scene::build(&desc, &registry(&desc)).unwrap_or_else(|e| panic!("{e}"));
        scene.set_frame(17).unwrap();
        let (fb, _) = luxon::render::render(&scene, &|_, _| {}).unwrap();
        fb.rgba.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    };
    assert!(frame(&source) == frame(&back), "frame 17 differs");
    let _ = std::fs::remove_dir_all(dir);
}

/// Distinct colours of an image, and the share of its pixels that are black.
fn content(img: &image::RgbImage) -> (usize, f64) {
    let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    let black = img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
    (colours.len(), black as f64 / img.pixels().len() as f64)
}

/// `luxon convert SOURCE OUT.ron` through the command line, then `luxon render` of both at
/// `res`: the same pixels. Returns the converted text, the convert's stderr and the image.
fn convert_and_render(source: &Path, dir: &Path, res: &str) -> (String, String, image::RgbImage) {
    let what = source.display().to_string();
    let stem = source.file_stem().unwrap().to_string_lossy().to_string();
    let ron = dir.join(format!("{stem}.ron"));
    let (s, r) = (source.display().to_string(), ron.display().to_string());
    let o = run(&["convert", &s, &r]);
    assert!(o.status.success(), "{what}: {}", stderr(&o));
    let render = |scene: &str, png: &Path| {
        let png = png.display().to_string();
        let o = run(&["render", scene, "--res", res, "--threads", "2", "-o", &png]);
        assert!(o.status.success(), "{what}: {}", stderr(&o));
        image::open(&png).unwrap().to_rgb8()
    };
    let original = render(&s, &dir.join(format!("{stem}-source.png")));
    let converted = render(&r, &dir.join(format!("{stem}-converted.png")));
    assert!(
        original.as_raw() == converted.as_raw(),
        "{what}: the converted scene renders another image"
    );
    (
        std::fs::read_to_string(&ron).unwrap(),
        stderr(&o),
        converted,
    )
}

#[test]
fn converted_scenes_render_the_same_images_on_the_command_line() {
    let dir = temp_dir("convert-render");
    // A Debian example with image maps, a mirror and light spheres.
    let debian = Path::new("/usr/share/doc/tachyon/examples/scenes/2balls.dat");
    let tachyon = match debian.is_file() {
        true => debian.to_path_buf(),
        false => {
            let p = dir.join("own.dat");
            std::fs::write(&p, TACHYON[0]).unwrap();
            p
        }
    };
    let (text, err, img) = convert_and_render(&tachyon, &dir, "96x72");
    let (colours, black) = content(&img);
    assert!(
        colours > 200 && black < 0.5,
        "{colours} colours, {black} black"
    );
    // What the RON scene cannot hold: on stderr and at the top of the file. Both scenes
    // above convert whole since Tachyon's light spheres and transparency are rendered; an
    // alias defined twice (Tachyon keeps the first) still warns.
    assert!(!err.contains("warning"), "{err}");
    assert!(!text.contains("Not carried over"));
    let warned = dir.join("warned.dat");
    let twice = "TEXALIAS crimson red\n";
    std::fs::write(&warned, TACHYON[0].replacen(twice, &twice.repeat(2), 1)).unwrap();
    let (text, err, _) = convert_and_render(&warned, &dir, "96x72");
    let light = "TEXDEF/TEXALIAS of a name already defined (`crimson` here";
    assert!(err.contains(light), "{err}");
    assert!(
        err.contains("is not carried over (listed at the top of the file)"),
        "{err}"
    );
    let header: Vec<&str> = text.lines().take_while(|l| l.starts_with("//")).collect();
    assert!(header[1].starts_with("// Not carried over"), "{header:?}");
    assert!(header.iter().any(|l| l.contains(light)), "{header:?}");

    let nff = dir.join("s.nff");
    std::fs::write(&nff, NFF).unwrap();
    let (text, err, img) = convert_and_render(&nff, &dir, "64x48");
    let (colours, black) = content(&img);
    assert!(
        colours > 50 && black < 0.5,
        "{colours} colours, {black} black"
    );
    assert!(!err.contains("warning"), "{err}");
    assert!(!text.contains("Not carried over"));
}

#[test]
fn warnings_stay_in_comments() {
    let dir = temp_dir("convert-warnings");
    let file = dir.join("w.ron");
    let ron = "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)))";
    let mut desc = load_ron_str(ron, &file).unwrap();
    desc.warnings.push(luxon_formats::Warning {
        at: desc.camera.at.clone(),
        message: "two\nlines) objects: [".into(),
    });
    let text = to_ron(&desc, &dir).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[1].starts_with("// Not carried over"), "{text}");
    assert!(lines[3].starts_with("//   ") && lines[3].ends_with("two lines) objects: ["));
    // Still a comment: the scene reads back without objects.
    let back = load_ron_str(&text, &file).unwrap();
    assert!(back.objects.is_empty() && back.warnings.is_empty());
}

#[test]
fn convert_errors_are_one_line() {
    let dir = temp_dir("convert-errors");
    let p = dir.join("s.dat");
    std::fs::write(&p, TACHYON[1]).unwrap();
    let o = run(&[
        "convert",
        &p.display().to_string(),
        "-o",
        &dir.join("s.txt").display().to_string(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("expected a `.ron` file name"),
        "{}",
        stderr(&o)
    );
    let o = run(&["convert", "missing.dat", "-o", "x.ron"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
    assert!(!Path::new("x.ron").exists());
}
