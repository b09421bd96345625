//! The in-situ Lennard-Jones example (`examples/insitu/lj.rs`) run in this process at a small
//! size: its frames exist, decode and show particles of both kinds, two runs write the same
//! bytes, every commit after the first refits the spheres' BVH (or rebuilds it by the
//! degradation rule, and says so), and no byte of the positions was copied.

mod common;

#[path = "../examples/insitu/lj.rs"]
#[allow(dead_code)]
mod lj;

use common::*;
use std::path::Path;

fn config(out: &Path) -> lj::Config {
    ensure_plugins();
    lj::Config {
        particles: 500,
        steps: 30,
        every: 10,
        size: 96,
        threads: 2,
        out: out.to_path_buf(),
        plugin_path: Vec::new(),
        verbose: false,
    }
}

#[test]
fn the_lennard_jones_example_renders_in_situ_without_copying() {
    let dir = temp_dir("insitu-lj");
    let first = lj::run(&config(&dir.join("a"))).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        first.frames.len(),
        4,
        "frames before step 1 and after steps 10, 20, 30"
    );
    assert_eq!(first.step_times.len(), 30);

    // Positions are read in place: nothing was copied.
    assert_eq!(first.copied_bytes, 0, "bytes copied into Luxon's arrays");

    // The first commit builds the scene and the spheres' BVH; later ones refit it, or rebuild
    // it because the refitted tree degraded (particles wrap around the box) and say so.
    assert_eq!(first.commits[0].rebuilt, 2, "{:?}", first.commits[0]);
    for c in &first.commits[1..] {
        assert_eq!(c.refitted, 1, "{c:?}");
        assert_eq!(
            c.rebuilt, c.degraded,
            "a rebuild that is not the rule's: {c:?}"
        );
        assert!(c.worst_ratio > 0.0, "{c:?}");
    }

    // The integrator holds the energy (a broken force or step would not).
    let (e0, e1) = first.energy;
    assert!(
        (e1 - e0).abs() < 0.02,
        "energy per particle drifted from {e0} to {e1}"
    );

    // Every frame decodes and shows particles of both kinds over the dark background; the
    // particles (and the camera) move between frames.
    let mut images = Vec::new();
    for path in &first.frames {
        let img = image::open(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .to_rgb8();
        assert_eq!(img.dimensions(), (96, 96));
        let (mut lit, mut orange, mut blue) = (0, 0, 0);
        for p in img.pixels() {
            let [r, g, b] = p.0.map(i32::from);
            lit += usize::from(r + g + b > 60);
            orange += usize::from(r > b + 60);
            blue += usize::from(b > r + 40);
        }
        let n = 96 * 96;
        assert!(lit > n / 5, "{}: {lit} of {n} pixels lit", path.display());
        assert!(
            orange > 50 && blue > 50,
            "{}: {orange} orange, {blue} blue",
            path.display()
        );
        images.push(img.into_raw());
    }
    assert!(
        images.windows(2).all(|w| w[0] != w[1]),
        "a frame repeats the one before"
    );

    // A second run writes the same bytes.
    let second = lj::run(&config(&dir.join("b"))).unwrap_or_else(|e| panic!("{e}"));
    for (a, b) in first.frames.iter().zip(&second.frames) {
        let (a_bytes, b_bytes) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
        assert!(
            a_bytes == b_bytes,
            "{} and {} differ",
            a.display(),
            b.display()
        );
    }
    assert_eq!(first.energy, second.energy);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_box_too_small_for_the_cutoff_is_refused() {
    let dir = temp_dir("insitu-lj-small");
    let mut c = config(&dir);
    c.particles = 20;
    let e = lj::run(&c).unwrap_err().to_string();
    assert!(e.contains("smaller than twice the cutoff"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
