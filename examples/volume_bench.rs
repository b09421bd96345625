//! What accuracy costs in time for volume ray casting: the MRI head (`scenes/mri-head.ron`) at
//! step sizes of 0.5, 1 and 2 voxels, nearest against trilinear interpolation, shaded against
//! unshaded, empty-space skipping on and off. Each setting is rendered `--runs` times; the
//! median render time, its ratio to the reference setting's, the volume samples and the image
//! difference (RMSE over linear RGB, PSNR) against the finest setting of the same kind
//! (0.5 voxel, trilinear, same shading) are printed as a table.
//!
//! ```sh
//! cargo build --release && cargo run --release --example volume_bench -- --runs 5 --size 256
//! ```

use luxon::plugin::Registry;
use luxon::{Framebuffer, Scene};
use luxon_formats::{Interpolation, SceneDesc};
use std::path::PathBuf;
use std::time::Instant;

struct Setting {
    name: String,
    step_voxels: f64,
    interpolation: Interpolation,
    shaded: bool,
    skip: bool,
}

fn main() {
    let mut runs = 5usize;
    let mut size = 256u32;
    let mut scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/mri-head.ron");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--runs" => runs = args.next().and_then(|v| v.parse().ok()).expect("--runs N"),
            "--size" => size = args.next().and_then(|v| v.parse().ok()).expect("--size N"),
            "--scene" => scene = args.next().map(PathBuf::from).expect("--scene FILE"),
            other => {
                eprintln!("unknown argument {other}; expected --runs N, --size N, --scene FILE");
                std::process::exit(2);
            }
        }
    }
    let base = match luxon_formats::load(&scene) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("volume_bench: {e}");
            std::process::exit(1);
        }
    };
    let registry = Registry::discover(&base.plugin_path);
    // The step in world units of one voxel: the smallest voxel edge, read from the volume.
    let probe = Scene::build(&base, &registry).unwrap_or_else(|e| {
        eprintln!("volume_bench: {e} (is ../shared/volumes there?)");
        std::process::exit(1)
    });
    let m = &probe.volumes[0].world_from_index;
    let voxel = (0..3)
        .map(|c| (m[c] * m[c] + m[4 + c] * m[4 + c] + m[8 + c] * m[8 + c]).sqrt())
        .fold(f64::INFINITY, f64::min);
    drop(probe);

    let mut settings = Vec::new();
    for shaded in [false, true] {
        for interpolation in [Interpolation::Trilinear, Interpolation::Nearest] {
            for step in [0.5, 1.0, 2.0] {
                settings.push(Setting {
                    name: format!(
                        "{} {:<9} {step:>3} vox",
                        if shaded { "shaded  " } else { "unshaded" },
                        if interpolation == Interpolation::Trilinear {
                            "trilinear"
                        } else {
                            "nearest"
                        }
                    ),
                    step_voxels: step,
                    interpolation,
                    shaded,
                    skip: true,
                });
            }
        }
        settings.push(Setting {
            name: format!(
                "{} trilinear   1 vox, no skipping",
                if shaded { "shaded  " } else { "unshaded" }
            ),
            step_voxels: 1.0,
            interpolation: Interpolation::Trilinear,
            shaded,
            skip: false,
        });
    }

    println!(
        "volume_bench: {} at {size}x{size}, {runs} runs per setting, {} threads",
        scene.display(),
        rayon::current_num_threads()
    );
    println!(
        "{:<40} {:>10} {:>8} {:>12} {:>9} {:>8}",
        "setting", "median s", "ratio", "samples", "RMSE", "PSNR dB"
    );
    let mut references: Vec<(bool, Framebuffer, f64)> = Vec::new();
    for s in &settings {
        let mut desc: SceneDesc = base.clone();
        desc.render.width = size;
        desc.render.height = size;
        desc.render.volume_skip = s.skip;
        for v in &mut desc.volumes {
            if let Some(r) = &mut v.value.render {
                r.value.step = Some(s.step_voxels * voxel);
                r.value.interpolation = s.interpolation;
                if !s.shaded {
                    r.value.shading = None;
                }
            }
        }
        let built = Scene::build(&desc, &registry).unwrap_or_else(|e| panic!("{e}"));
        let mut times = Vec::new();
        let mut image = None;
        let mut samples = 0;
        for _ in 0..runs.max(1) {
            let t = Instant::now();
            let (fb, stats) = luxon::render::render(&built, &|_, _| {}).expect("render");
            times.push(t.elapsed().as_secs_f64());
            samples = stats.counters.volume_samples;
            image = Some(fb);
        }
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        let image = image.unwrap();
        // The first setting of each shading (0.5 voxel, trilinear, skipping) is the reference.
        let (rmse, ratio) = match references.iter().find(|r| r.0 == s.shaded) {
            Some((_, reference, time)) => (Some(rmse(&image, reference)), median / time),
            None => {
                references.push((s.shaded, image, median));
                (None, 1.0)
            }
        };
        let (rmse_text, psnr_text) = match rmse {
            Some(0.0) => ("0".to_string(), "inf".to_string()),
            Some(e) => (format!("{e:.5}"), format!("{:.1}", -20.0 * e.log10())),
            None => ("ref".to_string(), "ref".to_string()),
        };
        println!(
            "{:<40} {median:>10.3} {ratio:>8.2} {samples:>12} {rmse_text:>9} {psnr_text:>8}",
            s.name
        );
    }
}

/// Root mean square difference over linear RGB, clamped to [0, 1] (PSNR against peak 1).
fn rmse(a: &Framebuffer, b: &Framebuffer) -> f64 {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for (pa, pb) in a.rgba.chunks_exact(4).zip(b.rgba.chunks_exact(4)) {
        for k in 0..3 {
            let d = f64::from(pa[k].clamp(0.0, 1.0)) - f64::from(pb[k].clamp(0.0, 1.0));
            sum += d * d;
            n += 1;
        }
    }
    (sum / n as f64).sqrt()
}
