//! Ray throughput against Embree 3 in one run: for each NFF scene, on one thread, Luxon's
//! closest-hit (primary) and any-hit (shadow) rays per second next to the reference harness
//! `../shared/tools/embree-bench` (spawned on the same file), on the same rays:
//! - primary: one ray per pixel through the pixel centres as embree_bench forms them (NFF
//!   `angle` spans the centres of the outer pixel columns; pixel (x, y) at integer offsets
//!   from the image centre), from the NFF `from` point;
//! - prim+shadow: the primary rays plus, at every primary hit, one shadow ray per light from
//!   the hit point moved 1e-5 scene diagonals along the viewer-facing geometric normal, unit
//!   direction, ending at 0.9999 of the distance to the light (every light, whatever side it
//!   is on, as embree_bench traces them).
//!
//! The table gives medians of `--reps` timed repetitions (each at least `--min-rep` seconds)
//! for both programs, Embree's single-ray mode (`rtcIntersect1`/`rtcOccluded1`) and its best
//! mode (8-wide packets or `rtcIntersect1M` streams), and the hit counts of both (they should
//! agree but for a few silhouette pixels: Luxon stores the scene relative to the camera).
//! The shadow rows are the any-hit rate alone: Luxon's shadow rays traced on their own,
//! Embree's from its (prim+shadow − primary) frame time.
//!
//! ```sh
//! make -C ../shared/tools/embree-bench BUILD=/tmp/embree-bench
//! EMBREE_BENCH=/tmp/embree-bench/embree_bench \
//!   cargo run --release --example throughput_bench -- /tmp/nff/balls4.nff /tmp/nff/teapot48.nff
//! ```
//!
//! Without `EMBREE_BENCH` (or `--embree PATH`) only Luxon's figures are printed.
//! `--embree-args "..."` replaces the harness options after `-t 1 -s WxH -o DIR` (default:
//! `-m 1,8,s -q medium -c -b 1 -W -u 0 -r REPS`: no waiting for an idle machine, which a
//! shared machine never is).

use luxon::math::Vec3A;
use luxon::ray::Ray;
use luxon::scene::Light;
use luxon::{geometry::Counters, plugin::Registry, Scene};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

struct Options {
    reps: usize,
    min_rep: f64,
    embree: Option<PathBuf>,
    embree_args: Option<String>,
    scenes: Vec<PathBuf>,
}

fn main() {
    let opts = options();
    match &opts.embree {
        Some(p) => println!("embree_bench: {}", p.display()),
        None => println!(
            "NOTICE: no EMBREE_BENCH=path (or --embree PATH): Luxon's figures only, no Embree \
             columns"
        ),
    }
    let mut rows = Vec::new();
    for path in &opts.scenes {
        let name = path
            .file_stem()
            .map_or_else(|| "?".into(), |s| s.to_string_lossy().into_owned());
        let view = read_view(path).unwrap_or_else(|e| fail(&format!("{}: {e}", path.display())));
        let luxon = measure_luxon(path, &view, &opts);
        eprintln!(
            "{name}: Luxon primary {:.2}, prim+shadow {:.2}, shadow {:.2} Mrays/s",
            luxon.primary.mrays(),
            luxon.prim_shadow.mrays(),
            luxon.shadow.mrays()
        );
        let embree = opts
            .embree
            .as_ref()
            .map(|exe| run_embree(exe, path, &view, &opts));
        rows.push((name, luxon, embree));
    }
    print_table(&rows, &opts);
}

fn options() -> Options {
    let mut o = Options {
        reps: 7,
        min_rep: 0.1,
        embree: std::env::var_os("EMBREE_BENCH")
            .filter(|s| !s.is_empty())
            .map(PathBuf::from),
        embree_args: None,
        scenes: Vec::new(),
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |what: &str| args.next().unwrap_or_else(|| fail(what));
        match a.as_str() {
            "--reps" => {
                o.reps = value("--reps N")
                    .parse()
                    .unwrap_or_else(|_| fail("--reps N"))
            }
            "--min-rep" => {
                o.min_rep =
                    (value("--min-rep S").parse()).unwrap_or_else(|_| fail("--min-rep SECONDS"))
            }
            "--embree" => o.embree = Some(PathBuf::from(value("--embree PATH"))),
            "--embree-args" => o.embree_args = Some(value("--embree-args \"...\"")),
            "-h" | "--help" => {
                println!(
                    "usage: throughput_bench [--reps N] [--min-rep S] [--embree PATH] \
                     [--embree-args \"...\"] scene.nff..."
                );
                std::process::exit(0)
            }
            _ => o.scenes.push(PathBuf::from(a)),
        }
    }
    if o.scenes.is_empty() {
        fail("one or more plain-text NFF files (embree_bench does not read gzip)");
    }
    o.reps = o.reps.max(1);
    o
}

/// The NFF view, read the way embree_bench reads it (its defaults where a line is missing).
struct View {
    from: [f32; 3],
    at: [f32; 3],
    up: [f32; 3],
    angle: f32,
    width: u32,
    height: u32,
}

fn read_view(path: &Path) -> Result<View, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut v = View {
        from: [0.0, 0.0, 0.0],
        at: [0.0, 0.0, -1.0],
        up: [0.0, 1.0, 0.0],
        angle: 45.0,
        width: 512,
        height: 512,
    };
    // The view block comes first in the SPD's files: stop at the first geometry.
    for line in BufReader::new(file).lines() {
        let line = line.map_err(|e| e.to_string())?;
        let mut t = line.split_whitespace();
        let key = t.next().unwrap_or("");
        let nums: Vec<f32> = t.filter_map(|s| s.parse().ok()).collect();
        match (key, nums.as_slice()) {
            ("from", [x, y, z, ..]) => v.from = [*x, *y, *z],
            ("at", [x, y, z, ..]) => v.at = [*x, *y, *z],
            ("up", [x, y, z, ..]) => v.up = [*x, *y, *z],
            ("angle", [a, ..]) => v.angle = *a,
            ("resolution", [w, h, ..]) => (v.width, v.height) = (*w as u32, *h as u32),
            ("s" | "p" | "pp" | "c", _) => break,
            _ => {}
        }
    }
    Ok(v)
}

// The camera arithmetic of embree_bench in the same order, in f32 (glam's SIMD dot products
// may sum in another order).
fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn normalize(a: [f32; 3]) -> [f32; 3] {
    let l = dot(a, a).sqrt();
    if l > 0.0 {
        scale(a, 1.0 / l)
    } else {
        a
    }
}

/// Unit directions of the camera rays, row by row.
fn camera_dirs(v: &View) -> Vec<[f32; 3]> {
    let (w, h) = (v.width as i32, v.height as i32);
    let fwd = normalize(sub(v.at, v.from));
    let right = normalize(cross(fwd, v.up));
    let upv = cross(right, fwd);
    let half = (0.5 * v.angle * std::f32::consts::PI / 180.0).tan();
    let pix = half / (0.5 * (w - 1) as f32).max(0.5);
    let (u, vv) = (scale(right, pix), scale(upv, pix));
    let (cx, cy) = (0.5 * (w - 1) as f32, 0.5 * (h - 1) as f32);
    let mut dirs = Vec::with_capacity((w * h) as usize);
    for py in 0..h {
        for px in 0..w {
            let d = add(
                add(fwd, scale(u, px as f32 - cx)),
                scale(vv, cy - py as f32),
            );
            dirs.push(normalize(d));
        }
    }
    dirs
}

/// Rays of one kind traced in one timed pass, and the median seconds of a pass.
#[derive(Default, Clone, Copy)]
struct Rate {
    rays: u64,
    seconds: f64,
}

impl Rate {
    fn mrays(&self) -> f64 {
        if self.seconds > 0.0 {
            self.rays as f64 / self.seconds * 1e-6
        } else {
            0.0
        }
    }
}

struct Counts {
    hits: u64,
    shadow: u64,
    unoccluded: u64,
}

struct LuxonResult {
    primary: Rate,
    prim_shadow: Rate,
    shadow: Rate,
    counts: Counts,
    lights: usize,
}

/// Median seconds of one call of `pass` over `reps` timed repetitions, each repeating the
/// pass enough times to last `min_rep` seconds (sized by an untimed warm-up call).
fn median_pass(reps: usize, min_rep: f64, mut pass: impl FnMut() -> u64) -> f64 {
    let start = Instant::now();
    std::hint::black_box(pass());
    let warm = start.elapsed().as_secs_f64().max(1e-6);
    let k = ((min_rep / warm).ceil() as usize).clamp(1, 1000);
    let mut times: Vec<f64> = (0..reps)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..k {
                std::hint::black_box(pass());
            }
            start.elapsed().as_secs_f64() / k as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn measure_luxon(path: &Path, view: &View, opts: &Options) -> LuxonResult {
    let desc = luxon_formats::load(path).unwrap_or_else(|e| fail(&e.to_string()));
    let registry = Registry::discover(&desc.plugin_path);
    let scene = Scene::build(&desc, &registry).unwrap_or_else(|e| fail(&e.to_string()));
    // The scene is stored relative to `world_offset`; the rays start there too.
    let off = scene.world_offset;
    let origin = Vec3A::new(
        (view.from[0] as f64 - off.x) as f32,
        (view.from[1] as f64 - off.y) as f32,
        (view.from[2] as f64 - off.z) as f32,
    );
    let rays: Vec<Ray> = camera_dirs(view)
        .into_iter()
        .map(|d| Ray::new(origin, Vec3A::from(d), 0.0))
        .collect();
    let lights: Vec<Vec3A> = (scene.lights.iter())
        .filter_map(|l| match l {
            Light::Point { position, .. } => Some(*position),
            _ => None,
        })
        .collect();
    let bounds = [
        scene.spheres.bounds(),
        scene.triangles.set.bounds(),
        scene.cones.bounds(),
        scene.discs.bounds(),
    ]
    .into_iter()
    .filter(|b| !b.is_empty())
    .reduce(|a, b| a.union(b));
    let eps = bounds.map_or(0.0, |b| 1e-5 * (b.max - b.min).length());

    // The shadow rays of a hit, as embree_bench forms them.
    let shadow_rays = |r: &Ray, t: f32, ng: Vec3A, out: &mut dyn FnMut(Ray, f32)| {
        let p = r.origin + r.dir * t;
        let mut n = ng.normalize();
        if n.dot(r.dir) > 0.0 {
            n = -n;
        }
        let o = p + n * eps;
        for l in &lights {
            let d = *l - o;
            let dist = d.length();
            out(Ray::new(o, d * (1.0 / dist), 0.0), dist * (1.0 - 1e-4));
        }
    };
    let mut c = Counters::default();
    let closest = |c: &mut Counters| {
        let mut hits = 0;
        for r in &rays {
            hits += scene.intersect(r, f32::INFINITY, c).is_some() as u64;
        }
        hits
    };
    // The untimed reference pass: counts, and the shadow rays to time on their own.
    let mut shadow = Vec::new();
    let mut hits = 0;
    for r in &rays {
        if let Some(hit) = scene.intersect(r, f32::INFINITY, &mut c) {
            hits += 1;
            let ng = scene.surface(&hit, r).ng;
            shadow_rays(r, hit.t, ng, &mut |s, t| shadow.push((s, t)));
        }
    }
    let occluded = |c: &mut Counters| {
        let mut unoccluded = 0;
        for (s, t) in &shadow {
            unoccluded += (scene.transmittance(s, *t, 0.0, c) != Vec3A::ZERO) as u64;
        }
        unoccluded
    };
    let unoccluded = occluded(&mut c);
    let both = |c: &mut Counters| {
        let mut unoccluded = 0;
        for r in &rays {
            if let Some(hit) = scene.intersect(r, f32::INFINITY, c) {
                let ng = scene.surface(&hit, r).ng;
                shadow_rays(r, hit.t, ng, &mut |s, t| {
                    unoccluded += (scene.transmittance(&s, t, 0.0, c) != Vec3A::ZERO) as u64;
                });
            }
        }
        unoccluded
    };
    let (reps, min_rep) = (opts.reps, opts.min_rep);
    let n = rays.len() as u64;
    let ns = shadow.len() as u64;
    LuxonResult {
        primary: Rate {
            rays: n,
            seconds: median_pass(reps, min_rep, || closest(&mut c)),
        },
        prim_shadow: Rate {
            rays: n + ns,
            seconds: median_pass(reps, min_rep, || both(&mut c)),
        },
        shadow: Rate {
            rays: ns,
            seconds: median_pass(reps, min_rep, || occluded(&mut c)),
        },
        counts: Counts {
            hits,
            shadow: ns,
            unoccluded,
        },
        lights: lights.len(),
    }
}

/// One measurement of embree_bench: its `trace[...]` line's counts and its `RESULT` line.
struct EmbreeLine {
    mode: String,
    shadows: bool,
    rays: u64,
    med_ms: f64,
    hits: u64,
    shadow: u64,
    unoccluded: u64,
}

struct EmbreeResult {
    lines: Vec<EmbreeLine>,
    error: Option<String>,
}

fn run_embree(exe: &Path, scene: &Path, view: &View, opts: &Options) -> EmbreeResult {
    let default = format!("-m 1,8,s -q medium -c -b 1 -W -u 0 -r {}", opts.reps);
    let extra = opts.embree_args.clone().unwrap_or(default);
    let out_dir = std::env::temp_dir();
    let mut cmd = Command::new(exe);
    cmd.args(["-t", "1", "-s", &format!("{}x{}", view.width, view.height)])
        .arg("-o")
        .arg(&out_dir)
        .args(extra.split_whitespace())
        .arg(scene);
    let out = match cmd.output() {
        Ok(o) => o,
        Err(e) => {
            return EmbreeResult {
                lines: Vec::new(),
                error: Some(format!("cannot run {}: {e}", exe.display())),
            }
        }
    };
    let text = String::from_utf8_lossy(&out.stdout);
    let mut counts = Vec::new();
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.starts_with("trace[") {
            counts.push([
                number_after(line, "(hits ").unwrap_or(0.0) as u64,
                number_after(line, ", shadow ").unwrap_or(0.0) as u64,
                number_after(line, ", unocc ").unwrap_or(0.0) as u64,
            ]);
        } else if line.starts_with("RESULT ") {
            let field = |k: &str| {
                line.split_whitespace()
                    .find_map(|f| f.strip_prefix(k).and_then(|v| v.strip_prefix('=')))
                    .unwrap_or("")
            };
            let [hits, shadow, unoccluded] = counts.last().copied().unwrap_or_default();
            lines.push(EmbreeLine {
                mode: field("mode").to_string(),
                shadows: field("kind") == "shadow",
                rays: field("rays").parse().unwrap_or(0),
                med_ms: field("med_ms").parse().unwrap_or(0.0),
                hits,
                shadow,
                unoccluded,
            });
        }
    }
    let error = (!out.status.success() || lines.is_empty()).then(|| {
        let err = String::from_utf8_lossy(&out.stderr);
        format!(
            "embree_bench failed ({}): {}",
            out.status,
            err.lines().last().unwrap_or("no output")
        )
    });
    EmbreeResult { lines, error }
}

/// The number that follows `key` in `line`.
fn number_after(line: &str, key: &str) -> Option<f64> {
    let rest = &line[line.find(key)? + key.len()..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(rest.len());
    rest[..end].parse().ok()
}

impl EmbreeResult {
    fn get(&self, mode: &str, shadows: bool) -> Option<&EmbreeLine> {
        (self.lines.iter()).find(|l| l.mode == mode && l.shadows == shadows)
    }

    /// Rate of one mode: primary rays, primary + shadow rays, or the shadow rays alone from
    /// the difference of the two frame times.
    fn rate(&self, mode: &str, kind: Kind) -> Option<Rate> {
        let p = self.get(mode, false)?;
        let ps = self.get(mode, true)?;
        let rate = match kind {
            Kind::Primary => Rate {
                rays: p.rays,
                seconds: p.med_ms * 1e-3,
            },
            Kind::PrimShadow => Rate {
                rays: ps.rays,
                seconds: ps.med_ms * 1e-3,
            },
            Kind::Shadow => Rate {
                rays: ps.shadow,
                seconds: (ps.med_ms - p.med_ms).max(0.0) * 1e-3,
            },
        };
        Some(rate)
    }

    /// The fastest mode other than single rays, and its rate.
    fn best(&self, kind: Kind) -> Option<(String, Rate)> {
        let mut modes: Vec<&str> = self.lines.iter().map(|l| l.mode.as_str()).collect();
        modes.dedup();
        (modes.into_iter())
            .filter(|m| *m != "1")
            .filter_map(|m| Some((m.to_string(), self.rate(m, kind)?)))
            .max_by(|a, b| a.1.mrays().total_cmp(&b.1.mrays()))
    }
}

#[derive(Clone, Copy)]
enum Kind {
    Primary,
    PrimShadow,
    Shadow,
}

fn print_table(rows: &[(String, LuxonResult, Option<EmbreeResult>)], opts: &Options) {
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let load: Vec<&str> = load.split_whitespace().take(3).collect();
    println!();
    println!(
        "Single thread, medians of {} reps (each >= {} s); load average {} at the end.",
        opts.reps,
        opts.min_rep,
        load.join(" ")
    );
    println!();
    println!(
        "| scene | rays | rays per frame | Luxon Mrays/s | Embree 1-ray Mrays/s | Embree best \
         Mrays/s (mode) | Luxon / 1-ray | Luxon / best | hits, unoccluded (Luxon / Embree) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---|");
    for (name, lx, em) in rows {
        let kinds = [
            (Kind::Primary, "primary", lx.primary),
            (Kind::PrimShadow, "prim+shadow", lx.prim_shadow),
            (Kind::Shadow, "shadow (any-hit)", lx.shadow),
        ];
        for (kind, label, rate) in kinds {
            let mut cells = vec![
                name.clone(),
                label.to_string(),
                rate.rays.to_string(),
                format!("{:.2}", rate.mrays()),
            ];
            let em_ok = em.as_ref().filter(|e| e.error.is_none());
            match em_ok {
                Some(e) => {
                    let one = e.rate("1", kind);
                    let best = e.best(kind);
                    let ratio = |r: Option<Rate>| {
                        r.filter(|r| r.mrays() > 0.0).map_or("-".to_string(), |r| {
                            format!("{:.0} %", 100.0 * rate.mrays() / r.mrays())
                        })
                    };
                    cells.push(one.map_or("-".into(), |r| format!("{:.2}", r.mrays())));
                    cells.push(best.as_ref().map_or("-".into(), |(m, r)| {
                        format!("{:.2} ({})", r.mrays(), mode_name(m))
                    }));
                    cells.push(ratio(one));
                    cells.push(ratio(best.map(|b| b.1)));
                    cells.push(compare_counts(lx, e, kind));
                }
                None => {
                    let why = em.as_ref().and_then(|e| e.error.clone());
                    cells.extend(["-", "-", "-", "-"].map(String::from));
                    cells.push(why.unwrap_or_else(|| "no Embree run".into()));
                }
            }
            println!("| {} |", cells.join(" | "));
        }
    }
    for (name, lx, _) in rows {
        if lx.lights == 0 {
            println!("\nNOTE: {name} has no point lights: no shadow rays.");
        }
    }
}

fn mode_name(m: &str) -> &str {
    match m {
        "8" => "8-wide packets",
        "4" => "4-wide packets",
        "1M" => "rtcIntersect1M stream",
        other => other,
    }
}

/// Both programs' hit (primary) or unoccluded (shadow) counts; a WARNING when they differ.
fn compare_counts(lx: &LuxonResult, e: &EmbreeResult, kind: Kind) -> String {
    let Some(line) = e.get("1", !matches!(kind, Kind::Primary)) else {
        return "-".into();
    };
    let (ours, theirs) = match kind {
        Kind::Primary => (lx.counts.hits, line.hits),
        Kind::PrimShadow => (lx.counts.shadow, line.shadow),
        Kind::Shadow => (lx.counts.unoccluded, line.unoccluded),
    };
    let what = match kind {
        Kind::Primary => "hits",
        Kind::PrimShadow => "shadow rays",
        Kind::Shadow => "unoccluded",
    };
    if ours == theirs {
        format!("{what} {ours} = {theirs}")
    } else {
        let diff = ours as i64 - theirs as i64;
        format!("WARNING {what} {ours} / {theirs} ({diff:+})")
    }
}

fn fail(what: &str) -> ! {
    eprintln!("throughput_bench: {what}");
    std::process::exit(2)
}
