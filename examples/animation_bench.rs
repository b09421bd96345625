//! What a frame of an animation costs to set up against building the scene afresh: a static
//! field of `--static` × 2 triangles (a bumpy square mesh, about 1 M triangles by default) with
//! one keyed, moving object of `--moving` × 2 triangles (about 10 k) flying over it. For each of
//! `--frames` frames it times `Scene::set_frame` (the moving object placed anew, its BVH and the
//! top level rebuilt; the static field untouched) against `Scene::build` of the whole scene,
//! then checks that a frame set after the whole sequence renders bit for bit the frame set on
//! a fresh build.
//!
//! ```sh
//! cargo run --release --example animation_bench -- --frames 24
//! cargo run --release --example animation_bench -- --static 708 --moving 71 --frames 24 --check 17
//! ```

use luxon::{plugin::Registry, Scene};
use std::fmt::Write as _;
use std::time::{Duration, Instant};

fn main() {
    let mut args = std::env::args().skip(1);
    let (mut big, mut small, mut frames, mut check, mut builds) =
        (708usize, 71usize, 24u32, 17u32, 3usize);
    while let Some(a) = args.next() {
        let mut number = |what: &str| -> usize {
            args.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| fail(&format!("{what}: expected a number")))
        };
        match a.as_str() {
            "--static" => big = number("--static").max(1),
            "--moving" => small = number("--moving").max(1),
            "--frames" => frames = number("--frames").max(2) as u32,
            "--check" => check = number("--check") as u32,
            "--builds" => builds = number("--builds").max(1),
            _ => fail(&format!("unknown argument `{a}`")),
        }
    }
    let check = check.min(frames - 1);
    let dir = std::env::temp_dir().join(format!("luxon-animation-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| fail(&e.to_string()));
    let write = |name: &str, text: String| {
        std::fs::write(dir.join(name), text).unwrap_or_else(|e| fail(&e.to_string()))
    };
    write("field.obj", mesh(big, 0.15));
    write("mover.obj", mesh(small, 0.3));
    write("scene.ron", scene(frames));
    let desc = luxon_formats::load(&dir.join("scene.ron")).unwrap_or_else(|e| fail(&e.to_string()));
    let registry = Registry::discover(&desc.plugin_path);
    let build = || Scene::build(&desc, &registry).unwrap_or_else(|e| fail(&e.to_string()));

    // Full builds (the OBJ files are read at load, so this is geometry and BVHs).
    let mut build_times = Vec::new();
    let mut scene = None;
    for _ in 0..builds {
        let start = Instant::now();
        let s = build();
        build_times.push(start.elapsed());
        scene = Some(s);
    }
    let mut scene = scene.unwrap_or_else(|| fail("no build"));
    let triangles = scene.triangles.len()
        + scene
            .instances
            .blases
            .iter()
            .map(|b| b.triangles.len())
            .sum::<usize>();
    // Every frame of the sequence, in order, on one scene.
    let mut update_times = Vec::new();
    for k in 0..frames {
        let start = Instant::now();
        scene.set_frame(k).unwrap_or_else(|e| fail(&e.to_string()));
        update_times.push(start.elapsed());
    }
    // Frame `check` after the sequence against a fresh build set to it.
    scene
        .set_frame(check)
        .unwrap_or_else(|e| fail(&e.to_string()));
    let after = render(&scene);
    let mut fresh = build();
    fresh
        .set_frame(check)
        .unwrap_or_else(|e| fail(&e.to_string()));
    let same = render(&fresh) == after;

    let (b, u) = (median(&mut build_times), median(&mut update_times));
    println!(
        "{} static + {} moving triangles ({triangles} static stored flat)",
        2 * big * big,
        2 * small * small
    );
    println!(
        "full build {:.1} ms (median of {builds}); per-frame update {:.2} ms (median of {frames}, \
         max {:.2} ms); update / build {:.2} %",
        ms(b),
        ms(u),
        ms(*update_times.iter().max().unwrap_or(&u)),
        100.0 * u.as_secs_f64() / b.as_secs_f64()
    );
    println!(
        "frame {check} after the sequence == fresh build: bitwise {}",
        if same { "yes" } else { "NO" }
    );
    let _ = std::fs::remove_dir_all(&dir);
    if !same {
        std::process::exit(1);
    }
}

fn render(scene: &Scene) -> Vec<f32> {
    luxon::render::render(scene, &|_, _| {})
        .unwrap_or_else(|e| fail(&e.to_string()))
        .0
        .rgba
}

fn median(v: &mut [Duration]) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A `n` × `n` grid of quads over the unit square, bumped by `bump`: 2n² triangles.
fn mesh(n: usize, bump: f64) -> String {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f64 / n as f64, j as f64 / n as f64);
            let y = bump * (x * 17.0).sin() * (z * 13.0).cos();
            let _ = writeln!(s, "v {x} {y} {z}");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            let _ = writeln!(s, "f {a} {b} {c}\nf {a} {c} {d}");
        }
    }
    s
}

/// The field scaled to 20 × 20 at the origin; the mover (2 × 2) crossing it diagonally while
/// it turns, seen from above.
fn scene(frames: u32) -> String {
    let last = frames - 1;
    format!(
        r#"Scene(
    camera: (position: (0, 14, -16), look_at: (0, 0, 0), fov: 50),
    lights: [Directional(direction: (-1, -2, 1))],
    materials: {{ "field": (color: (0.5, 0.7, 0.4)), "mover": (color: (0.9, 0.3, 0.2), specular: 0.5) }},
    prototypes: {{
        "field": (meshes: [(file: "field.obj", material: "field")]),
        "mover": (meshes: [(file: "mover.obj", material: "mover")]),
    }},
    instances: [
        (prototype: "field", world_from_object: (translate: (-10, 0, -10), scale: (20, 20, 20))),
        (prototype: "mover", name: "mover", world_from_object: (scale: (2, 2, 2))),
    ],
    animation: (
        frames: (0, {last}),
        objects: {{
            "mover": (translate: (keys: [(0, (-8, 2, -8)), ({last}, (6, 3, 6))]),
                      rotate: (keys: [(0, (axis: (0, 1, 0), degrees: 0)), ({last}, (axis: (0, 1, 0), degrees: 270))])),
        }},
    ),
    render: (width: 128, height: 128, instancing: Bake),
)
"#
    )
}

fn fail(msg: &str) -> ! {
    eprintln!("animation_bench: {msg}");
    std::process::exit(2)
}
