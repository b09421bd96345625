//! Golden images: every shipped scene, rendered small, against a committed reference picture.
//! After an intended change of the pictures, regenerate them with
//! `LUXON_BLESS=1 cargo test --test golden` and look at every one before committing.

mod common;

use common::*;

const WIDTH: u32 = 192;

/// The scene's render size scaled to `WIDTH` pixels across.
fn small(d: &mut luxon_formats::SceneDesc) {
    let aspect = d.render.height as f64 / d.render.width as f64;
    d.render.width = WIDTH;
    d.render.height = (WIDTH as f64 * aspect).round() as u32;
}

fn check(name: &str) {
    let path = root().join("scenes").join(format!("{name}.ron"));
    let fb = render_with(&path, small);
    compare(name, &fb);
}

/// Frame `k` of an animated scene, against `golden/{name}-f{k}.png`.
fn check_frame(name: &str, k: u32) {
    check_frame_with(name, k, None);
}

/// `check_frame` with `samples` per pixel instead of the scene's (blurred scenes, which ask
/// for many, stay quick in a debug build).
fn check_frame_with(name: &str, k: u32, samples: Option<u32>) {
    let path = root().join("scenes").join(format!("{name}.ron"));
    let mut desc = luxon_formats::load(&path).unwrap_or_else(|e| panic!("{e}"));
    small(&mut desc);
    if let Some(n) = samples {
        desc.render.samples = n;
    }
    let reg = registry(&desc);
    let mut scene = luxon::Scene::build(&desc, &reg).unwrap_or_else(|e| panic!("{e}"));
    scene.set_frame(k).unwrap_or_else(|e| panic!("{e}"));
    let (fb, _) = luxon::render::render(&scene, &|_, _| {}).unwrap_or_else(|e| panic!("{e}"));
    compare(&format!("{name}-f{k}"), &fb);
}

/// `fb` against `golden/{name}.png` (or blessed into it).
fn compare(name: &str, fb: &luxon::Framebuffer) {
    let got = to_srgb8(fb);
    let golden = root().join("tests/golden").join(format!("{name}.png"));
    if std::env::var_os("LUXON_BLESS").is_some() {
        image::save_buffer(&golden, &got, fb.width, fb.height, image::ColorType::Rgb8).unwrap();
        return;
    }
    let want = image::open(&golden)
        .unwrap_or_else(|e| panic!("{}: {e} (bless with LUXON_BLESS=1)", golden.display()))
        .to_rgb8();
    assert_eq!(
        (want.width(), want.height()),
        (fb.width, fb.height),
        "{name}: size"
    );
    // A reference that is one flat colour would let a broken renderer pass.
    let px = want.as_raw();
    let distinct = {
        let mut v: Vec<[u8; 3]> = px.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    assert!(
        distinct > 50,
        "{name}: golden image has only {distinct} colours"
    );
    let (mean, max) = diff(&got, px);
    // Same machine: identical. Elsewhere, libm's last bits may differ a little at edges.
    assert!(
        mean < 0.5 && max < 64,
        "{name}: mean diff {mean:.3}, max {max} (see LUXON_BLESS in this file)"
    );
}

#[test]
fn animation_carousel_frames() {
    check_frame("carousel", 0);
    check_frame("carousel", 17);
}

#[test]
fn animation_orbit_molecule() {
    check_frame("orbit", 0);
    check_frame("orbit", 12);
}

/// Landing (squashed, the blur turning back up) and in flight (smeared along its path).
#[test]
fn animation_bouncing_ball_blurred() {
    check_frame_with("bouncing-ball", 12, Some(4));
    check_frame_with("bouncing-ball", 15, Some(4));
}

/// Keyed shared instances with motion blur: 25 gears meshing, neighbours turning apart.
#[test]
fn animation_gears_instanced_and_blurred() {
    check_frame_with("gears", 0, Some(1));
    check_frame_with("gears", 5, Some(1));
}

#[test]
fn shared_instances_field_of_molecules() {
    check("shared-instances");
}

#[test]
fn instances_ring_of_molecules() {
    check("instances");
}

#[test]
fn spheres() {
    check("spheres");
}

#[test]
fn glass() {
    check("glass");
}

#[test]
fn mirrors() {
    check("mirrors");
}

#[test]
fn shadows_through_glass() {
    check("shadows-glass");
}

#[test]
fn antialiasing() {
    check("antialiasing");
}

#[test]
fn torus_custom_primitive() {
    check("torus");
}

/// The example texture plugin (examples/stripes), its scene beside it: unfiltered stripes
/// aliasing on the left, filtered ones fading to grey on the right.
#[test]
fn stripes_texture_plugin() {
    let fb = render_with(&root().join("examples/stripes/scene.ron"), small);
    compare("stripes", &fb);
}

#[test]
fn molecule_cylinders_cones_rings() {
    check("molecule");
}

#[test]
fn every_texture_kind() {
    check("textures");
}

#[test]
fn lights_spot_area_attenuation_fog() {
    check("lights");
}

#[test]
fn ambient_occlusion_through_a_transparent_surface() {
    check("ao-molecule");
}

#[test]
fn custom_solids_box_quadric_cylinder_heightfield() {
    check("solids");
}

#[test]
fn camera_dof() {
    check("cameras-dof");
}

#[test]
fn camera_orthographic() {
    check("cameras-orthographic");
}

#[test]
fn camera_fisheye() {
    check("cameras-fisheye");
}

#[test]
fn camera_stereo() {
    check("cameras-stereo");
}

#[test]
fn camera_vr() {
    check("cameras-vr");
}

#[test]
fn obj_mesh_groups_ngons_computed_normals() {
    check("obj-mesh");
}

#[test]
fn clip_groups_cutaway() {
    check("cutaway");
}

#[test]
fn transparency_angle_modulated_with_surface_limit() {
    check("transparency");
}

#[test]
fn transparency_vmd_post_multiplied() {
    check("transparency-vmd");
}

/// Scenes reading the real data sets in `../shared/volumes` (not part of the repository): skipped
/// with a notice when that directory is absent.
fn check_shared_volume(name: &str, file: &str) {
    let data = root().join("../shared/volumes").join(file);
    if !data.is_file() {
        eprintln!("golden {name}: skipped, {} is absent", data.display());
        return;
    }
    check(name);
}

#[test]
fn volume_mri_head() {
    check_shared_volume("mri-head", "mri-head-256x256x109-u8.raw.gz");
}

#[test]
fn volume_ct_engine() {
    check_shared_volume("ct-engine", "ct-engine-256x256x110-u8.raw.gz");
}

#[test]
fn volume_phantom_clipped_and_shaded() {
    check("phantom");
}

#[test]
fn volume_flow_field() {
    check("vortex");
}

#[test]
fn volume_with_geometry_inside() {
    check("volume-geometry");
}

#[test]
fn volume_openvdb_cloud() {
    check("vdb-cloud");
}
