//! `luxon check`: validate a scene and describe it.

use luxon::budget::{Budget, Use};
use luxon::plugin::Registry;
use luxon::{Error, Scene};
use luxon_formats::{InlineGeometry, MemorySize, SceneDesc};
use std::path::Path;
use std::sync::Arc;

pub fn run(path: &Path, memory: Option<MemorySize>) -> Result<(), Error> {
    let desc = luxon_formats::load_with(path, &Budget::for_load(memory, 1).load_options())?;
    super::warn_scene(&desc);
    let registry = Registry::discover(&desc.plugin_path);
    super::warn_skipped(&registry);
    let budget = Arc::new(Budget::for_render(&desc.render, memory, 1));
    // The imported geometry stays in `desc` while the scene is built from it.
    let held = desc.inline.iter().map(InlineGeometry::bytes).sum();
    let imported = budget.charge(Use::Import, held, || {
        format!("the geometry imported from `{}`", desc.source.display())
    })?;
    let scene = Scene::build_with(&desc, &registry, budget.clone())?;
    drop(imported);
    let outputs = luxon::output::resolve(&scene.outputs, &registry)?;
    describe(&desc, &scene, &outputs);
    Ok(())
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
