//! `luxon check`: validate a scene and describe it.

use luxon::api::{self, Context, ContextOptions, Renderer, RendererOptions};
use luxon::budget::{Budget, Use};
use luxon::{Error, Scene};
use luxon_formats::{InlineGeometry, MemorySize, SceneDesc};
use std::path::Path;
use std::sync::Arc;

pub fn run(
    path: &Path,
    memory: Option<MemorySize>,
    instancing: Option<String>,
    shutter: Option<String>,
) -> Result<(), Error> {
    let mut desc = luxon_formats::load_with(path, &Budget::for_load(memory, 1).load_options())?;
    let args = super::shading::ShadingArgs {
        instancing,
        shutter,
        ..Default::default()
    };
    args.apply(&mut desc)?;
    super::warn_scene(&desc);
    // The build runs on every CPU, as a render's would by default.
    let ctx = Context::new(ContextOptions {
        plugin_path: desc.plugin_path.clone(),
        threads: 0,
    })?;
    let renderer = Renderer::new(&ctx, RendererOptions::default())?;
    let registry = ctx.registry();
    super::warn_skipped(registry);
    let budget = Arc::new(Budget::for_render(&desc.render, memory, 1));
    // The imported geometry stays in the description while the scene is built from it.
    let held = desc.inline.iter().map(InlineGeometry::bytes).sum();
    let imported = budget.charge(Use::Import, held, || {
        format!("the geometry imported from `{}`", desc.source.display())
    })?;
    let mut scene = api::Scene::from_desc(&ctx, desc)?;
    scene.set_budget(budget.clone());
    scene.commit(&renderer)?;
    drop(imported);
    let built = super::render::built(&scene)?;
    let outputs = luxon::output::resolve(&built.outputs, registry)?;
    describe(scene.desc(), built, &outputs);
    missing_data(scene.desc())
}

/// Each series' data files over the scene's range: a line each, and an error naming the
/// first missing file (the frames showing it would fail).
fn missing_data(desc: &SceneDesc) -> Result<(), Error> {
    let Some(a) = &desc.animation else {
        return Ok(());
    };
    let range = (a.value.first, a.value.last);
    let mut problems = Vec::new();
    for s in &desc.series {
        let s = &s.value;
        let (total, missing) = luxon_formats::missing_files(s, range);
        let kind = match s.kind {
            luxon_formats::SeriesKind::Atoms { .. } => "atoms",
            luxon_formats::SeriesKind::Mesh { .. } => "meshes",
        };
        println!(
            "series     `{}`: {total} data file(s) `{}` ({kind}), first {}, {} per frame",
            s.name.value, s.files.value, s.first, s.per_frame
        );
        if let Some((k, file)) = missing.first() {
            problems.push(format!(
                "series `{}`: {} of {total} data files are missing (first: {}, frame {k})",
                s.name.value,
                missing.len(),
                file.display()
            ));
        }
    }
    match problems.is_empty() {
        true => Ok(()),
        false => Err(Error::Render(problems.join("; "))),
    }
}

fn describe(desc: &SceneDesc, scene: &Scene, outputs: &[luxon::output::Output]) {
    let s = &scene.settings;
    println!("scene      {}", desc.source.display());
    let cam = &desc.camera.value;
    println!(
        "camera     at {:?} looking at {:?}, up {:?}, {:?}",
        cam.position, cam.look_at, cam.up, cam.projection
    );
    println!(
        "image      {}x{}, {} sample(s) per pixel, max depth {}",
        s.width, s.height, s.samples, s.max_depth
    );
    let objects: Vec<String> = scene
        .object_counts
        .iter()
        .map(|(n, c)| format!("{c} {n}"))
        .collect();
    println!(
        "objects    {} ({})",
        desc.objects.len(),
        if objects.is_empty() {
            "none".into()
        } else {
            objects.join(", ")
        }
    );
    println!(
        "primitives {} spheres, {} triangles, {} planes, {} cones, {} discs, {} custom",
        scene.spheres.len(),
        scene.triangles.len(),
        scene.planes.planes.len(),
        scene.cones.len(),
        scene.discs.len(),
        scene.customs.len()
    );
    for p in &scene.prototypes {
        println!("prototype  {}", prototype(p));
    }
    if let Some(a) = &scene.animation {
        let m = &scene.moving;
        println!(
            "keyed      {} spheres, {} triangles, {} planes, {} cones, {} discs (at frame {})",
            m.spheres.len(),
            m.triangles.len(),
            m.planes.planes.len(),
            m.cones.len(),
            m.discs.len(),
            a.frame()
        );
    }
    if scene.degenerate_triangles > 0 {
        println!(
            "           ({} zero-area triangles dropped)",
            scene.degenerate_triangles
        );
    }
    for v in &scene.volumes {
        let (lo, hi) = v.min_max();
        println!(
            "volume     `{}` ({}): {} voxels, values {lo}..{hi}, {:.1} MiB ({})",
            v.name,
            v.plugin,
            v.voxel_count(),
            v.memory_bytes() as f64 / (1024.0 * 1024.0),
            brick_summary(v)
        );
    }
    for (i, v) in desc.volumes.iter().enumerate() {
        let Some(r) = &v.value.render else {
            println!(
                "           `{}`: data only (no `render` settings)",
                scene.volumes[i].name
            );
            continue;
        };
        let rv = scene.render_volumes.iter().find(|rv| rv.volume == i);
        let r = &r.value;
        println!(
            "           `{}`: drawn, transfer {}, step {}, {:?}, {}",
            scene.volumes[i].name,
            r.transfer.preset.as_deref().unwrap_or("points"),
            rv.map_or(0.0, |rv| rv.step),
            r.interpolation,
            if r.shading.is_some() {
                "shaded"
            } else {
                "unshaded"
            }
        );
    }
    if let Some(a) = &scene.animation {
        println!("animation  {}", animation(a.desc()));
    }
    println!("lights     {}", scene.lights.len());
    println!("materials  {}", scene.material_names.join(", "));
    println!(
        "textures   {}",
        if scene.texture_names.is_empty() {
            "none".into()
        } else {
            scene.texture_names.join(", ")
        }
    );
    println!("effects    {}", scene.features);
    // What the image will take is charged when rendering; here it is only counted.
    let image = u64::from(s.width) * u64::from(s.height) * 16;
    println!(
        "memory     budget {}; the scene holds {}; the image will take {}",
        scene.budget.describe(),
        scene.budget.in_use(),
        luxon::budget::bytes(image)
    );
    for o in outputs {
        println!(
            "output     {} (writer `{}`)",
            o.desc.path.display(),
            o.writer.name
        );
    }
}

/// One line about a prototype: its size, its instances and how they were realised.
fn prototype(p: &luxon::scene::PrototypeUse) -> String {
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let mut how = Vec::new();
    if p.baked > 0 {
        how.push(format!("{} baked (flat copies)", p.baked));
    }
    if p.keyed > 0 {
        how.push(format!("{} keyed (placed anew each frame)", p.keyed));
    }
    if p.shared > 0 {
        how.push(format!("{} shared (one copy, two-level BVH)", p.shared));
    }
    let mut size = plural(p.objects, "object", "objects");
    if p.meshes > 0 {
        size.push_str(&format!(
            ", {}",
            plural(p.meshes, "mesh group", "mesh groups")
        ));
    }
    format!(
        "`{}`: {size}, {} per copy; {}: {}",
        p.name,
        plural(p.primitives, "primitive", "primitives"),
        plural(p.baked + p.keyed + p.shared, "instance", "instances"),
        how.join(", ")
    )
}

/// One line about an animation: its frames, its shutter and what is keyed.
fn animation(a: &luxon_formats::AnimationDesc) -> String {
    use luxon_formats::{Interpolate, Track};
    fn track<T>(name: &str, t: &Option<Track<T>>) -> Option<String> {
        let t = t.as_ref()?;
        let how = match t.interpolation {
            Interpolate::Linear => "Linear",
            Interpolate::CatmullRom => "CatmullRom",
        };
        let n = t.keys.len();
        let s = if n == 1 { "" } else { "s" };
        Some(format!("{name} ({how}, {n} key{s})"))
    }
    let frames = a.last - a.first + 1;
    let mut line = format!(
        "frames {}..{} at {} fps ({} frames, {:.2} s)",
        a.first,
        a.last,
        a.fps,
        frames,
        f64::from(frames) / a.fps
    );
    if let Some(s) = &a.shutter {
        line.push_str(&format!(
            ", shutter {} frame {:?}",
            s.value.length, s.value.at
        ));
    }
    let c = &a.camera;
    let camera: Vec<String> = [
        track("position", &c.position),
        track("look_at", &c.look_at),
        track("up", &c.up),
        track("fov", &c.fov),
        track("focal_distance", &c.focal_distance),
    ]
    .into_iter()
    .flatten()
    .collect();
    let mut keyed = Vec::new();
    if !camera.is_empty() {
        keyed.push(format!("camera {}", camera.join(", ")));
    }
    for l in &a.lights {
        let p: Vec<String> = [
            track("position", &l.position),
            track("direction", &l.direction),
            track("intensity", &l.intensity),
            track("color", &l.color),
        ]
        .into_iter()
        .flatten()
        .collect();
        keyed.push(format!("light `{}` {}", l.name.value, p.join(", ")));
    }
    for m in &a.materials {
        if let Some(c) = track("color", &m.color) {
            keyed.push(format!("material `{}` {c}", m.material.value));
        }
    }
    let objects = a.objects.iter().map(|o| ("object", o));
    for (what, o) in objects.chain(a.instances.iter().map(|o| ("instance", o))) {
        let p: Vec<String> = [
            track("translate", &o.translate),
            track("rotate", &o.rotate),
            track("scale", &o.scale),
        ]
        .into_iter()
        .flatten()
        .collect();
        keyed.push(format!("{what} `{}` {}", o.name.value, p.join(", ")));
    }
    if keyed.is_empty() {
        line.push_str("; nothing keyed");
    } else {
        line.push_str(&format!("; keyed: {}", keyed.join("; ")));
    }
    line
}

/// "bricks: 1200 u8, 40 constant": the stored bricks by kind (at the precision the reader
/// gave), the kinds with none left out.
fn brick_summary(v: &luxon::volume::Volume) -> String {
    let [u8s, u16s, f32s] = v.dense_counts();
    let (_, constant) = v.brick_counts();
    let kinds: Vec<String> = [
        (u8s, "u8"),
        (u16s, "u16"),
        (f32s, "f32"),
        (constant, "constant"),
    ]
    .iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, kind)| format!("{n} {kind}"))
    .collect();
    if kinds.is_empty() {
        "no bricks stored".into()
    } else {
        format!("bricks: {}", kinds.join(", "))
    }
}
