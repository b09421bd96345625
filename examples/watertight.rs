//! Watertight triangles at scale: rays from inside closed icospheres aimed exactly at every
//! vertex and at points of every shared edge, through the triangle BVH; prints rays, leaks and
//! rays per second. `tests/stability.rs` runs the same check with fewer rays.
//!
//! ```sh
//! cargo run --release --example watertight            # 14.1 M rays
//! cargo run --release --example watertight -- 40      # origins per mesh (default 40)
//! ```

#[path = "../tests/common/leaks.rs"]
mod leaks;

use glam::DVec3;
use luxon::math::Vec3A;
use std::time::Instant;

fn main() {
    let per_mesh: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("origins per mesh: a whole number"))
        .unwrap_or(40);
    // Unit scale at the origin, tiny, huge and far: the same mesh at three placements (each
    // where f32 still resolves its 0.08-radius edges, so the stored mesh stays closed).
    let placements = [
        (1.0, DVec3::ZERO),
        (1e-3, DVec3::new(1.0, -2.0, 0.5)),
        (1e4, DVec3::new(-3e4, 1e4, 2e4)),
    ];
    let (mut rays, mut leaks) = (0u64, 0u64);
    let start = Instant::now();
    for (radius, center) in placements {
        let (positions, faces) = leaks::icosphere(4, radius, center);
        let (tris, verts) = leaks::build(&positions, &faces);
        let targets = leaks::targets(&verts, &faces, 15);
        let origins = leaks::origins(per_mesh, radius as f32, Vec3A::from(center.as_vec3()));
        let (r, l) = leaks::count_leaks(&tris, &origins, &targets);
        println!(
            "radius {radius:e} at {center}: {} triangles, {} targets, {r} rays, {l} leaks",
            faces.len(),
            targets.len()
        );
        rays += r;
        leaks += l;
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "total: {rays} rays, {leaks} leaks, {secs:.2} s ({:.2} M rays/s)",
        rays as f64 / secs / 1e6
    );
    if leaks > 0 {
        std::process::exit(1);
    }
}
