//! What each effect costs, and proof that effects a scene defines but does not use cost nothing.
//!
//! Renders one scene (a 20×20 grid of spheres on a floor, two lights, 512×512) in variants: the
//! diffuse-only base; the base with mirror, glass, textured materials, textures and a volume
//! reader defined but used by nothing; and the base with one effect switched on at a time
//! (shadows, reflection, refraction, textures, ambient occlusion, fog, 4× antialiasing, depth of
//! field, a drawn volume). Each variant runs `luxon render --stats` several times; the table
//! gives the median render time, its ratio to the base and the rays cast per kind.
//!
//! ```sh
//! cargo build --release
//! cargo run --release --example effects_bench -- [--runs 7] [--threads 2]
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

struct Variant {
    name: &'static str,
    /// Extra top-level scene fields.
    extra: String,
    /// Extra entries of the materials map.
    more_materials: &'static str,
    /// Material of the spheres and the floor.
    sphere: &'static str,
    floor: &'static str,
    shadows: bool,
    samples: u32,
    /// Extra camera settings.
    camera: &'static str,
}

/// Defined, used by nothing: the scene's effects must not change. The volume is read but has
/// no `render` settings, so nothing draws it.
const UNUSED_TEXTURES: &str = r#"textures: {
        "marble": (plugin: "marble", params: (scale: 0.5)),
        "checks": (plugin: "checker", params: (scale: 1.0)),
    },
    volumes: [(plugin: "phantom", name: "unused", params: (size: 32))],"#;
const UNUSED_MATERIALS: &str = r#""mirror": (color: (0.9, 0.9, 0.9), reflect: 0.8),
        "glass": (color: (1, 1, 1), transmit: 0.9, ior: 1.5),
        "stone": (texture: "marble"),
        "tiles": (texture: "checks", reflect_texture: "checks", reflect: 0.5),"#;

fn variants() -> Vec<Variant> {
    let base = || Variant {
        name: "",
        extra: String::new(),
        more_materials: "",
        sphere: "(color: (0.8, 0.3, 0.2), diffuse: 0.8)",
        floor: "(color: (0.8, 0.8, 0.8), diffuse: 0.8)",
        shadows: false,
        samples: 1,
        camera: "",
    };
    vec![
        Variant {
            name: "diffuse only (base)",
            ..base()
        },
        Variant {
            name: "base + unused mirror/glass/textured materials, textures, a volume",
            extra: UNUSED_TEXTURES.into(),
            more_materials: UNUSED_MATERIALS,
            ..base()
        },
        Variant {
            name: "shadows",
            shadows: true,
            ..base()
        },
        Variant {
            name: "reflection (spheres reflect 0.4)",
            sphere: "(color: (0.8, 0.3, 0.2), diffuse: 0.6, reflect: 0.4)",
            ..base()
        },
        Variant {
            name: "refraction (glass spheres)",
            sphere: "(color: (1, 1, 1), diffuse: 0.1, transmit: 0.9, ior: 1.5)",
            ..base()
        },
        Variant {
            name: "textures (marble spheres, checker floor)",
            extra: r#"textures: {
                "marble": (plugin: "marble", params: (scale: 0.5)),
                "checks": (plugin: "checker", params: (scale: 1.0)),
            },"#
            .into(),
            sphere: "(texture: \"marble\", diffuse: 0.8)",
            floor: "(texture: \"checks\", diffuse: 0.8)",
            ..base()
        },
        Variant {
            name: "ambient occlusion (8 rays)",
            extra: "ambient_occlusion: (samples: 8, distance: 2),".into(),
            ..base()
        },
        Variant {
            name: "fog (exponential)",
            extra: "fog: (mode: Exp(density: 0.03), color: (0.5, 0.5, 0.5)),".into(),
            ..base()
        },
        Variant {
            name: "antialiasing (4 samples)",
            samples: 4,
            ..base()
        },
        Variant {
            name: "volume (64³ vortex rings over the spheres)",
            extra: r#"volumes: [(plugin: "vortex", name: "rings", params: (size: 64),
                render: (transfer: (preset: "hot", range: (0.05, 1.0), opacity: 4), step: 0.02))],"#
                .into(),
            ..base()
        },
        Variant {
            name: "depth of field (4 samples)",
            samples: 4,
            camera: "depth_of_field: (aperture: 0.3, focal_distance: 14),",
            ..base()
        },
    ]
}

fn scene(v: &Variant) -> String {
    let mut centers = String::new();
    for i in 0..20 {
        for j in 0..20 {
            let (x, z) = (i as f64 - 9.5, j as f64 - 9.5);
            write!(centers, "({x}, 0.45, {z}),").unwrap();
        }
    }
    let materials = format!(
        "materials: {{ \"ball\": {}, \"ground\": {}, {} }},",
        v.sphere, v.floor, v.more_materials
    );
    format!(
        r#"Scene(
    camera: (position: (0, 9, -16), look_at: (0, 0, 0), fov: 45, {camera}),
    background: (0.6, 0.7, 0.9),
    lights: [
        Point(position: (-10, 15, -10), intensity: 0.7, shadows: {shadows}),
        Point(position: (12, 10, -6), intensity: 0.4, shadows: {shadows}),
    ],
    {materials}
    {extra}
    objects: [
        (plugin: "spheres", params: (centers: [{centers}], radius: 0.45), material: "ball"),
        (plugin: "plane", params: (normal: (0, 1, 0)), material: "ground"),
    ],
    render: (width: 512, height: 512, samples: {samples}),
)"#,
        extra = v.extra,
        camera = v.camera,
        shadows = v.shadows,
        samples = v.samples,
    )
}

/// Render seconds and rays per kind from `--stats` (and instructions from `perf stat`).
fn run(luxon: &Path, scene: &Path, out: &Path, threads: usize, perf: bool, tiny: bool) -> Sample {
    let counts = out.with_extension("perf");
    let mut cmd = if perf {
        let mut c = Command::new("perf");
        c.args(["stat", "-x,", "-e", "instructions:u", "-o"])
            .arg(&counts)
            .arg(luxon);
        c
    } else {
        Command::new(luxon)
    };
    let o = cmd
        .arg("render")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .arg("--stats")
        .arg("--threads")
        .arg(threads.to_string())
        .args(if tiny { &["--res", "1x1"][..] } else { &[] })
        .output()
        .expect("run luxon");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{}: {err}", scene.display());
    let field = |key: &str| -> &str {
        err.lines()
            .find_map(|l| l.trim().strip_prefix(key).map(str::trim))
            .unwrap_or_else(|| panic!("no `{key}` in --stats output:\n{err}"))
    };
    let secs = field("render ").trim_end_matches(" s").parse().unwrap();
    let rays = ["primary", "shadow", "reflection", "refraction", "occlusion"]
        .map(|k| field(k).parse().unwrap_or(0));
    // `perf stat -x,` writes "count,unit,event,...".
    let instructions = perf
        .then(|| std::fs::read_to_string(&counts).ok())
        .flatten()
        .and_then(|t| {
            t.lines()
                .find(|l| l.contains("instructions"))
                .and_then(|l| l.split(',').next()?.parse().ok())
        });
    Sample {
        secs,
        rays,
        instructions,
    }
}

struct Sample {
    secs: f64,
    rays: [u64; 5],
    /// Instructions the whole process retired (user space), when `perf` counts them.
    instructions: Option<u64>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut runs = 7;
    let mut threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut val = || it.next().unwrap_or_else(|| panic!("{k} needs a value"));
        match k.as_str() {
            "--runs" => runs = val().parse().expect("--runs N"),
            "--threads" => threads = val().parse().expect("--threads N"),
            _ => panic!("unknown argument {k}; see the comment at the top of effects_bench.rs"),
        }
    }
    // Instruction counts do not depend on what else the machine is doing: the fair measure
    // of "costs nothing" on a shared machine (when perf can count them here).
    let perf = Command::new("perf")
        .args(["stat", "-x,", "-e", "instructions:u", "true"])
        .output()
        .is_ok_and(|o| {
            o.status.success() && !String::from_utf8_lossy(&o.stderr).contains("not supported")
        });
    let exe = std::env::current_exe().unwrap();
    let luxon: PathBuf = exe.parent().unwrap().parent().unwrap().join("luxon");
    assert!(
        luxon.exists(),
        "{} missing: run `cargo build --release` first",
        luxon.display()
    );
    let dir = std::env::temp_dir().join(format!("luxon-effects-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let all = variants();
    let mut paths = Vec::new();
    for (k, v) in all.iter().enumerate() {
        let path = dir.join(format!("v{k}.ron"));
        std::fs::write(&path, scene(v)).unwrap();
        let out = dir.join(format!("v{k}.png"));
        // Warm-up (page cache, plugin loading).
        run(&luxon, &path, &out, threads, false, false);
        paths.push((path, out));
    }
    // Round robin: drift on a shared machine hits every variant alike.
    let mut times = vec![Vec::new(); all.len()];
    let mut rays = vec![[0; 5]; all.len()];
    let mut instructions = vec![Vec::new(); all.len()];
    // The same scene at 1x1 pixel: everything but the render (loading, building, plugins), to
    // subtract from the instruction counts so they measure the render alone.
    let setup: Vec<Option<f64>> = paths
        .iter()
        .map(|(path, out)| {
            let tiny = out.with_extension("tiny.png");
            run(&luxon, path, &tiny, threads, perf, true)
                .instructions
                .map(|i| i as f64)
        })
        .collect();
    for round in 0..runs {
        for (k, (path, out)) in paths.iter().enumerate() {
            let s = run(&luxon, path, out, threads, perf, false);
            times[k].push(s.secs);
            rays[k] = s.rays;
            instructions[k].extend(s.instructions.map(|i| i as f64));
        }
        eprintln!("round {} of {runs} done", round + 1);
    }
    let rows: Vec<_> = all
        .iter()
        .zip(times)
        .zip(rays)
        .zip(instructions)
        .zip(setup)
        .map(|((((v, t), r), i), setup)| {
            let render = (!i.is_empty()).then(|| median(i) - setup.unwrap_or(0.0));
            (v.name, median(t), r, render)
        })
        .collect();
    let (base, base_instr) = (rows[0].1, rows[0].3);
    let mut table = String::new();
    writeln!(
        table,
        "| variant | render (median of {runs}) | vs base | render instructions vs base | primary | shadow | reflection | refraction | occlusion |"
    )
    .unwrap();
    writeln!(table, "|---|---|---|---|---|---|---|---|---|").unwrap();
    for (name, t, r, i) in &rows {
        let instr = match (i, base_instr) {
            (Some(i), Some(b)) => format!("{:.3}", i / b),
            _ => "n/a".into(),
        };
        writeln!(
            table,
            "| {name} | {t:.3} s | {:.3} | {instr} | {} | {} | {} | {} | {} |",
            t / base,
            r[0],
            r[1],
            r[2],
            r[3],
            r[4]
        )
        .unwrap();
    }
    println!("{table}");
    println!(
        "{threads} thread(s), 512x512; images in {} (look at them).",
        dir.display()
    );
}
