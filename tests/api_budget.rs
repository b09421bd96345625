//! The memory budget of a retained scene (`luxon::api::Scene::set_budget`) counts what Luxon
//! makes from the caller's arrays: the BVHs of array objects and the bricks of volumes from
//! arrays. A request that does not fit is refused with a message naming it, before anything
//! is allocated (never an abort); what is dropped or read again gives its charge back.

mod common;

use common::*;
use luxon::api::{
    Context, ContextOptions, Radius, Renderer, RendererOptions, Scene, Spheres, VolumeGrid,
};
use luxon::arrays::Array;
use luxon::budget::{Budget, Use};
use std::sync::Arc;

const MIB: u64 = 1 << 20;

fn setup(budget: u64) -> (Context, Renderer, Scene) {
    ensure_plugins();
    let ctx = Context::new(ContextOptions {
        threads: 2,
        ..Default::default()
    })
    .unwrap();
    let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
    let mut s = Scene::new(&ctx);
    s.set_camera_ron("(position: (0, 0, 30), look_at: (0, 0, 0))")
        .unwrap();
    s.set_budget(Arc::new(Budget::new(budget, "the test's".into(), None)));
    (ctx, r, s)
}

/// `n` spheres on a line.
fn spheres(n: usize) -> Spheres {
    let centers: Vec<[f64; 3]> = (0..n).map(|i| [i as f64 * 1e-3, 0.0, 0.0]).collect();
    Spheres::new(Array::copy(&centers).unwrap(), Radius::Const(0.01))
}

fn used(s: &Scene, kind: Use) -> u64 {
    s.built().unwrap().budget.used(kind)
}

#[test]
fn a_bvh_over_arrays_beyond_the_budget_is_refused_with_a_message() {
    let (_ctx, r, mut s) = setup(4 * MIB);
    let big = s.add_spheres(spheres(100_000)).unwrap();
    let e = s.commit(&r).unwrap_err().to_string();
    assert!(
        e.starts_with("building the BVH of object 0 (spheres) over 100000 primitives needs "),
        "{e}"
    );
    assert!(e.contains("memory budget of 4 MiB (the test's)"), "{e}");

    // The scene is still usable: smaller arrays fit, and their tree stays charged.
    s.set_spheres(big, spheres(1000)).unwrap();
    s.commit(&r).unwrap();
    let tree = used(&s, Use::Bvh);
    assert!(tree > 0, "the tree is charged");
    // Trees built again (new arrays) give the old one's charge back.
    for _ in 0..20 {
        s.set_spheres(big, spheres(1000)).unwrap();
        assert_eq!(s.commit(&r).unwrap().rebuilt, 1);
    }
    assert_eq!(used(&s, Use::Bvh), tree);
    s.remove(big).unwrap();
    s.commit(&r).unwrap();
    assert_eq!(
        used(&s, Use::Bvh),
        0,
        "a removed object's tree is given back"
    );
}

/// A `n`³ volume of varied values (no brick collapses to a constant).
fn volume(n: u64) -> (Array, VolumeGrid) {
    let values: Vec<f32> = (0..n * n * n).map(|i| (i % 97) as f32 / 97.0).collect();
    let a = Array::copy(&values).unwrap();
    let grid = VolumeGrid {
        name: "field".into(),
        ..VolumeGrid::new(a.clone(), [n; 3])
    };
    (a, grid)
}

#[test]
fn a_volume_from_an_array_beyond_the_budget_is_refused_with_a_message() {
    let (_ctx, r, mut s) = setup(MIB);
    let (_, grid) = volume(96);
    let id = s.add_volume(grid, None).unwrap();
    let e = s.commit(&r).unwrap_err();
    // The budget's refusal, not a complaint about the caller's data (`Error::Api`).
    assert!(matches!(e, luxon::Error::Render(_)), "{e:?}");
    let e = e.to_string();
    assert!(e.starts_with("volume `field`"), "{e}");
    assert!(e.contains("memory budget of 1 MiB (the test's)"), "{e}");
    s.remove(id).unwrap();
    s.commit(&r).unwrap();
}

#[test]
fn a_volume_read_again_gives_back_its_old_charge() {
    // 32³ f32 voxels are 128 KiB of bricks: read ten times, they would need 1.25 MiB.
    let (_ctx, r, mut s) = setup(MIB / 2);
    let (values, grid) = volume(32);
    s.add_volume(grid, None).unwrap();
    s.commit(&r).unwrap();
    let held = used(&s, Use::Volumes);
    assert!(held >= 128 << 10, "{held} bytes charged");
    for _ in 0..10 {
        values.mark_modified();
        assert_eq!(s.commit(&r).unwrap().volumes_read, 1);
    }
    assert_eq!(used(&s, Use::Volumes), held);
}
