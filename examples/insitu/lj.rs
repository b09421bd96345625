//! A Lennard-Jones fluid rendered in situ: the simulation keeps its particles in a vector of
//! structs, hands their positions to Luxon once (a strided field of that vector, read in
//! place: nothing is copied), and every `every` steps commits the scene (a refit of the
//! spheres' BVH, or a rebuild when the refitted tree has degraded) and renders a frame.
//!
//! ```sh
//! cargo run --release --example insitu_lj -- [--particles 4000] [--steps 200] [--every 10]
//!     [--size 512] [--threads 2] [--out out/lj]
//! ```
//!
//! Reduced units (σ = ε = m = 1): cutoff 2.5, a cell list, velocity Verlet, a periodic cube
//! at density 0.6 started on a lattice at temperature 1.0. Everything is serial and in a fixed
//! order, so two runs write the same frames, byte for byte.

use luxon::api::{
    write_image, Color, CommitReport, Context, ContextOptions, Plane, Radius, Renderer,
    RendererOptions, Scene, Spheres, Target,
};
use luxon::arrays::{copied_bytes, Array, SharedVec};
use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// One particle as the simulation stores it: Luxon reads `pos` in place (stride 80 bytes).
#[derive(Clone, Copy, Debug)]
pub struct Particle {
    pub pos: [f64; 3],
    pub vel: [f64; 3],
    pub force: [f64; 3],
    pub kind: u8,
}

/// What to run.
#[derive(Clone, Debug)]
pub struct Config {
    pub particles: usize,
    pub steps: usize,
    /// Render after every `every` steps (and once before the first).
    pub every: usize,
    /// Frames are `size`×`size` pixels.
    pub size: u32,
    /// Threads of Luxon's pool (the simulation runs on the calling thread).
    pub threads: usize,
    /// Where the frames go (`frame0000.png`, ...).
    pub out: PathBuf,
    /// Extra plugin directories (the PNG writer is a plugin).
    pub plugin_path: Vec<PathBuf>,
    /// Print a line per rendered frame.
    pub verbose: bool,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            particles: 4000,
            steps: 200,
            every: 10,
            size: 512,
            threads: 2,
            out: PathBuf::from("out/lj"),
            plugin_path: Vec::new(),
            verbose: true,
        }
    }
}

/// What a run did.
#[derive(Debug)]
pub struct Report {
    pub frames: Vec<PathBuf>,
    /// Every commit's report, the first (which builds) included.
    pub commits: Vec<CommitReport>,
    /// Simulation time of every step.
    pub step_times: Vec<Duration>,
    /// Commit and render time of every frame.
    pub commit_times: Vec<Duration>,
    pub render_times: Vec<Duration>,
    /// Bytes Luxon copied into arrays of its own during the run ([`copied_bytes`]).
    pub copied_bytes: u64,
    /// Total energy per particle at the start and at the end (a sanity check of the
    /// integrator).
    pub energy: (f64, f64),
}

const CUTOFF: f64 = 2.5;
const DENSITY: f64 = 0.6;
const TEMPERATURE: f64 = 1.0;
const DT: f64 = 0.004;

/// The particles in their periodic box, with the cell list's buffers.
pub struct Sim {
    pub side: f64,
    cells: usize,
    head: Vec<usize>,
    next: Vec<usize>,
    neighbours: Vec<Vec<usize>>,
    /// The potential energy at the last force computation.
    potential: f64,
}

const NONE: usize = usize::MAX;

impl Sim {
    /// `n` particles on a cubic lattice with random velocities (a fixed seed), the box sized
    /// for the density; the forces computed.
    pub fn new(n: usize) -> Result<(Sim, Vec<Particle>), String> {
        let side = (n as f64 / DENSITY).cbrt();
        if side <= 2.0 * CUTOFF {
            return Err(format!(
                "{n} particles make a box of side {side:.2}, smaller than twice the cutoff \
                 ({CUTOFF}): use at least {} particles",
                (DENSITY * (2.0 * CUTOFF).powi(3)).ceil() as usize + 1
            ));
        }
        let cells = (side / CUTOFF).floor() as usize;
        let at = |c: [i64; 3]| {
            let w = |k: i64| k.rem_euclid(cells as i64) as usize;
            (w(c[2]) * cells + w(c[1])) * cells + w(c[0])
        };
        // Each cell's neighbours (itself included) once each, even in a box of 1 or 2 cells.
        let mut neighbours = Vec::with_capacity(cells.pow(3));
        for z in 0..cells as i64 {
            for y in 0..cells as i64 {
                for x in 0..cells as i64 {
                    let mut list = Vec::with_capacity(27);
                    for dz in -1..=1 {
                        for dy in -1..=1 {
                            for dx in -1..=1 {
                                list.push(at([x + dx, y + dy, z + dz]));
                            }
                        }
                    }
                    list.sort_unstable();
                    list.dedup();
                    neighbours.push(list);
                }
            }
        }
        let per_side = (n as f64).cbrt().ceil() as usize;
        let spacing = side / per_side as f64;
        let mut seed = 12345u64;
        let mut random = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut ps: Vec<Particle> = (0..n)
            .map(|i| {
                let (x, y, z) = (i % per_side, i / per_side % per_side, i / per_side.pow(2));
                let pos = [x, y, z].map(|k| (k as f64 + 0.5) * spacing);
                let vel = [random(), random(), random()];
                let kind = u8::from(random() > 0.2);
                Particle {
                    pos,
                    vel,
                    force: [0.0; 3],
                    kind,
                }
            })
            .collect();
        // No drift, and the kinetic energy of the temperature asked for.
        let mut mean = [0.0; 3];
        for p in &ps {
            (0..3).for_each(|k| mean[k] += p.vel[k] / n as f64);
        }
        let kinetic: f64 = ps
            .iter()
            .map(|p| (0..3).map(|k| (p.vel[k] - mean[k]).powi(2)).sum::<f64>())
            .sum();
        let scale = (3.0 * n as f64 * TEMPERATURE / kinetic).sqrt();
        for p in &mut ps {
            (0..3).for_each(|k| p.vel[k] = (p.vel[k] - mean[k]) * scale);
        }
        let mut sim = Sim {
            side,
            cells,
            head: vec![NONE; cells.pow(3)],
            next: vec![NONE; n],
            neighbours,
            potential: 0.0,
        };
        sim.potential = sim.forces(&mut ps);
        Ok((sim, ps))
    }

    fn cell_of(&self, p: &[f64; 3]) -> usize {
        let c = |x: f64| ((x / self.side * self.cells as f64) as usize).min(self.cells - 1);
        (c(p[2]) * self.cells + c(p[1])) * self.cells + c(p[0])
    }

    /// Lennard-Jones forces with the cell list (minimum image); returns the potential energy
    /// (shifted to 0 at the cutoff).
    fn forces(&mut self, ps: &mut [Particle]) -> f64 {
        self.head.fill(NONE);
        for (i, p) in ps.iter().enumerate() {
            let c = self.cell_of(&p.pos);
            self.next[i] = self.head[c];
            self.head[c] = i;
        }
        let (rc2, half) = (CUTOFF * CUTOFF, self.side / 2.0);
        let shift = 4.0 * (CUTOFF.powi(-12) - CUTOFF.powi(-6));
        let mut potential = 0.0;
        for i in 0..ps.len() {
            let pi = ps[i].pos;
            let mut f = [0.0; 3];
            for &c in &self.neighbours[self.cell_of(&pi)] {
                let mut j = self.head[c];
                while j != NONE {
                    if j != i {
                        let mut d = [0.0; 3];
                        for k in 0..3 {
                            d[k] = pi[k] - ps[j].pos[k];
                            if d[k] > half {
                                d[k] -= self.side;
                            } else if d[k] < -half {
                                d[k] += self.side;
                            }
                        }
                        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        if r2 < rc2 {
                            let s6 = 1.0 / (r2 * r2 * r2);
                            let magnitude = 24.0 * s6 * (2.0 * s6 - 1.0) / r2;
                            (0..3).for_each(|k| f[k] += magnitude * d[k]);
                            potential += 0.5 * (4.0 * s6 * (s6 - 1.0) - shift);
                        }
                    }
                    j = self.next[j];
                }
            }
            ps[i].force = f;
        }
        potential
    }

    /// The total energy per particle.
    pub fn energy(&self, ps: &[Particle]) -> f64 {
        let kinetic: f64 = ps
            .iter()
            .map(|p| 0.5 * (p.vel[0] * p.vel[0] + p.vel[1] * p.vel[1] + p.vel[2] * p.vel[2]))
            .sum();
        (kinetic + self.potential) / ps.len() as f64
    }

    /// One velocity Verlet step.
    pub fn step(&mut self, ps: &mut [Particle]) {
        for p in ps.iter_mut() {
            for k in 0..3 {
                p.vel[k] += 0.5 * DT * p.force[k];
                p.pos[k] = (p.pos[k] + DT * p.vel[k]).rem_euclid(self.side);
                // rem_euclid of a tiny negative number can round up to the side itself.
                if p.pos[k] >= self.side {
                    p.pos[k] = 0.0;
                }
            }
        }
        self.potential = self.forces(ps);
        for p in ps.iter_mut() {
            for k in 0..3 {
                p.vel[k] += 0.5 * DT * p.force[k];
            }
        }
    }
}

/// Runs the simulation and renders it in situ as `config` says.
pub fn run(config: &Config) -> Result<Report, Box<dyn Error>> {
    if config.every == 0 || config.size == 0 || config.particles == 0 {
        return Err("--every, --size and --particles must be at least 1".into());
    }
    let (mut sim, start) = Sim::new(config.particles)?;
    let particles = SharedVec::new(start);
    // Colours by kind, fixed for the run: an array of their own, shared too.
    let colors = SharedVec::new(
        particles
            .read()
            .iter()
            .map(|p| match p.kind {
                0 => [0.95f32, 0.45, 0.1],
                _ => [0.2, 0.45, 0.85],
            })
            .collect::<Vec<_>>(),
    );

    let copied_before = copied_bytes();
    let ctx = Context::new(ContextOptions {
        plugin_path: config.plugin_path.clone(),
        threads: config.threads,
    })?;
    let renderer = Renderer::new(&ctx, RendererOptions::default())?;
    let mut scene = Scene::new(&ctx);
    scene.set_background([0.03, 0.03, 0.05])?;
    scene.add_light_ron("Point(position: (-20, 60, -30), intensity: 0.9)")?;
    scene.add_light_ron("Directional(direction: (1, -0.3, 1), intensity: 0.35)")?;
    let material = scene.set_material_ron(
        "particle",
        "(color: (1, 1, 1), ambient: 0.15, diffuse: 0.75, specular: 0.4, shininess: 30)",
    )?;
    let mut spheres = Spheres::new(
        Array::field(&particles, |p: &Particle| &p.pos)?,
        Radius::Const(0.5),
    );
    spheres.colors = Some(Array::shared(&colors));
    spheres.material = Some(material);
    scene.add_spheres(spheres)?;

    std::fs::create_dir_all(&config.out)?;
    let (w, h) = (config.size, config.size);
    let mut pixels = vec![[0.0f32; 4]; (w * h) as usize];
    let mut report = Report {
        frames: Vec::new(),
        commits: Vec::new(),
        step_times: Vec::new(),
        commit_times: Vec::new(),
        render_times: Vec::new(),
        copied_bytes: 0,
        energy: (0.0, 0.0),
    };
    report.energy.0 = sim.energy(&particles.read());
    for step in 0..=config.steps {
        if step > 0 {
            let t = Instant::now();
            // The write guard marks the positions modified when it drops.
            sim.step(&mut particles.write());
            report.step_times.push(t.elapsed());
        }
        if step % config.every != 0 {
            continue;
        }
        let frame = report.frames.len();
        // The camera orbits the box slowly.
        let angle = 0.6 + frame as f64 * 0.05;
        let c = sim.side / 2.0;
        let r = sim.side * 1.9;
        scene.set_camera_ron(&format!(
            "(position: ({:.6}, {:.6}, {:.6}), look_at: ({c:.6}, {c:.6}, {c:.6}), up: (0, 1, 0), \
             fov: 40)",
            c + r * angle.cos(),
            c + r * 0.45,
            c + r * angle.sin(),
        ))?;
        let t = Instant::now();
        let commit = scene.commit(&renderer)?;
        report.commit_times.push(t.elapsed());
        let t = Instant::now();
        let color = Color::Rgba32fLinear(Plane::new(&mut pixels, w as usize));
        renderer.render(
            &mut scene,
            Target {
                width: w,
                height: h,
                color,
                depth: None,
            },
        )?;
        report.render_times.push(t.elapsed());
        let path = config.out.join(format!("frame{frame:04}.png"));
        write_image(&ctx, &path, pixels.as_flattened(), w, h)?;
        if config.verbose {
            let energy = sim.energy(&particles.read());
            let sim_ms = match report.step_times.len() {
                0 => 0.0,
                n => {
                    let last = &report.step_times[n.saturating_sub(config.every)..];
                    ms(last.iter().sum::<Duration>()) / last.len() as f64
                }
            };
            println!(
                "step {step:5}: sim {sim_ms:7.2} ms/step, commit {:6.2} ms ({}), render {:7.1} \
                 ms, E/N {energy:.4} -> {}",
                ms(report.commit_times[frame]),
                what_commit(&commit),
                ms(report.render_times[frame]),
                path.display(),
            );
        }
        report.commits.push(commit);
        report.frames.push(path);
    }
    report.energy.1 = sim.energy(&particles.read());
    report.copied_bytes = copied_bytes() - copied_before;
    Ok(report)
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A commit in a word.
pub fn what_commit(c: &CommitReport) -> &'static str {
    match (c.rebuilt, c.refitted, c.degraded) {
        (_, _, d) if d > 0 => "refit, degraded: rebuilt",
        (0, r, _) if r > 0 => "refit",
        (0, _, _) => "no geometry",
        _ => "build",
    }
}

/// The median of `v`.
pub fn median(v: &[Duration]) -> Duration {
    let mut v = v.to_vec();
    v.sort();
    v.get(v.len() / 2).copied().unwrap_or_default()
}

#[allow(dead_code)]
fn main() {
    let mut config = Config::default();
    // The plugins are built next to the `examples` directory cargo puts this program in.
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        if dir.file_name().is_some_and(|n| n == "examples") {
            config
                .plugin_path
                .extend(dir.parent().map(Path::to_path_buf));
        }
    }
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || {
            args.next()
                .unwrap_or_else(|| fail(&format!("{a} needs a value")))
        };
        let number = |v: String| -> usize {
            v.parse()
                .unwrap_or_else(|_| fail(&format!("{a}: `{v}` is not a number")))
        };
        match a.as_str() {
            "--particles" => config.particles = number(value()),
            "--steps" => config.steps = number(value()),
            "--every" => config.every = number(value()),
            "--size" => config.size = number(value()) as u32,
            "--threads" => config.threads = number(value()),
            "--out" => config.out = PathBuf::from(value()),
            "--quiet" => config.verbose = false,
            _ => fail(&format!("unknown argument `{a}`")),
        }
    }
    match run(&config) {
        Ok(r) => {
            let (sim, commit, render) = (
                median(&r.step_times),
                median(r.commit_times.get(1..).unwrap_or_default()),
                median(&r.render_times),
            );
            println!(
                "{} particles, {} steps, {} frames: medians sim {:.2} ms/step, commit {:.2} ms, \
                 render {:.1} ms/frame; rendering every {} steps costs {:.0} % of the \
                 simulation's time; {} bytes of positions copied",
                config.particles,
                config.steps,
                r.frames.len(),
                ms(sim),
                ms(commit),
                ms(render),
                config.every,
                100.0 * ms(commit + render) / (ms(sim) * config.every as f64),
                r.copied_bytes,
            );
        }
        Err(e) => fail(&e.to_string()),
    }
}

fn fail(message: &str) -> ! {
    eprintln!("insitu_lj: {message}");
    std::process::exit(1)
}
