//! Tachyon's example scenes rendered by Tachyon and by Luxon, side by side: the SSIM of each
//! pair (luma, `luxon::metrics::ssim`) and both programs' times, in one run.
//!
//! ```sh
//! cargo build --release && cargo build --release --example tachyon_compare
//! target/release/examples/tachyon_compare [--runs N] [--threads T] SCENE_DIR OUT_DIR [NAME.dat ...]
//! ```
//!
//! SCENE_DIR holds the `.dat` files and what they read (Debian's
//! `/usr/share/doc/tachyon/examples/scenes`, copied somewhere writable; Tachyon opens relative
//! paths from the working directory, so both programs run there). Without names every `.dat`
//! file is rendered. `tachyon-nox` (Debian's `tachyon-bin-nox`) must be on the path, and
//! Luxon's release binary beside this example's directory (`target/release/luxon`, with its
//! plugins: `--example` alone rebuilds neither, so build both as above).
//!
//! Each scene is rendered `N` times (default 3) by each program, alternating, with the same
//! thread count (`-numthreads T`, default 2), each as the whole command a user runs:
//! `tachyon-nox SCENE -numthreads T -format PPM -o …` and `luxon tachyon SCENE -numthreads T
//! -format PPM -o …` (Luxon's drop-in for Tachyon's command line, which writes Tachyon's
//! 8-bit values: floor(255·c), clamped, no gamma). The table gives medians of each program's
//! own "Ray Tracing Time" (render) and of the command's wall time (start to exit: start-up,
//! parsing, building, rendering and writing), and Luxon's over Tachyon's. The SSIM compares
//! the two programs' last pictures; `OUT_DIR/NAME.png` shows Tachyon's on the left, Luxon's on
//! the right. The lines after the table name the scenes where Tachyon renders for more than
//! 0.1 s and Luxon is not faster in render or wall time.
//!
//! A scene name may carry Tachyon command-line shading switches after a colon, written into the
//! scene as the SHADER_MODE and CAMERA words they stand for, e.g. `janbadoutput.dat:vmd`
//! renders `janbadoutput.dat` as its header asks (`-trans_vmd -mediumshade -aasamples 4`).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use luxon::metrics::{gray, ssim};

/// Tachyon's render time above which Luxon must be faster (issue 18's rule).
const COUNTED: f64 = 0.1;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut runs = 3usize;
    let mut threads = 2usize;
    let usage = "usage: tachyon_compare [--runs N] [--threads T] SCENE_DIR OUT_DIR \
                 [NAME.dat[:vmd] ...]";
    while args.first().is_some_and(|a| a.starts_with("--")) {
        let flag = args.remove(0);
        let value = (!args.is_empty()).then(|| args.remove(0));
        let number = value
            .and_then(|v| v.parse::<usize>().ok())
            .filter(|&n| n > 0);
        match (flag.as_str(), number) {
            ("--runs", Some(n)) => runs = n,
            ("--threads", Some(n)) => threads = n,
            _ => {
                eprintln!("{usage}\n(`{flag}` needs a whole number above 0)");
                std::process::exit(2);
            }
        }
    }
    if args.len() < 2 {
        eprintln!("{usage}");
        std::process::exit(2);
    }
    let (dir, out) = (PathBuf::from(&args[0]), PathBuf::from(&args[1]));
    std::fs::create_dir_all(&out).expect("cannot create OUT_DIR");
    let out = std::fs::canonicalize(&out).expect("cannot resolve OUT_DIR");
    let luxon = luxon_binary();
    let mut names: Vec<String> = args[2..].to_vec();
    if names.is_empty() {
        names = std::fs::read_dir(&dir)
            .expect("cannot read SCENE_DIR")
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().to_string())
            .filter(|n| n.ends_with(".dat"))
            .collect();
        names.sort();
    }
    println!(
        "{runs} run(s) of each program per scene, {threads} thread(s), medians; \
         ratio: Luxon / Tachyon"
    );
    println!();
    println!(
        "| scene | SSIM | Tachyon render s | Luxon render s | render ratio | Tachyon wall s \
         | Luxon wall s | wall ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    let mut misses = Vec::new();
    for name in &names {
        let setup = Setup {
            dir: &dir,
            out: &out,
            luxon: &luxon,
            runs,
            threads,
        };
        match compare(&setup, name) {
            Ok(r) => {
                let (render, wall) = (r.luxon.0 / r.tachyon.0, r.luxon.1 / r.tachyon.1);
                println!(
                    "| {name} | {:.3} | {:.3} | {:.3} | {render:.2} | {:.3} | {:.3} | {wall:.2} |",
                    r.ssim, r.tachyon.0, r.luxon.0, r.tachyon.1, r.luxon.1
                );
                if r.tachyon.0 > COUNTED && (render >= 1.0 || wall >= 1.0) {
                    misses.push(format!("{name} (render {render:.2}, wall {wall:.2})"));
                }
            }
            Err(e) => println!("| {name} | – ({e}) | | | | | | |"),
        }
    }
    println!();
    if misses.is_empty() {
        println!("Luxon is faster on every scene Tachyon renders for more than {COUNTED} s.");
    } else {
        println!(
            "Tachyon renders for more than {COUNTED} s and Luxon is not faster: {}",
            misses.join(", ")
        );
    }
}

/// `target/release/luxon`: this example lives in `target/release/examples/`.
fn luxon_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("cannot find this program's path");
    let bin = exe
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join("luxon"))
        .filter(|p| p.exists());
    bin.unwrap_or_else(|| {
        eprintln!("tachyon_compare: no luxon binary beside {}", exe.display());
        std::process::exit(2);
    })
}

/// What every scene's comparison shares.
struct Setup<'a> {
    dir: &'a Path,
    out: &'a Path,
    luxon: &'a Path,
    runs: usize,
    threads: usize,
}

/// One scene's figures: the SSIM and each program's median (render, wall) seconds.
struct Compared {
    ssim: f64,
    tachyon: (f64, f64),
    luxon: (f64, f64),
}

/// The scene file to render: `NAME.dat`, or for `NAME.dat:vmd` a copy with VMD's switches.
fn scene_file(dir: &Path, name: &str) -> Result<(PathBuf, String), String> {
    let (file, variant) = name.split_once(':').unwrap_or((name, ""));
    let path = dir.join(file);
    let stem = file.trim_end_matches(".dat").to_string();
    if variant.is_empty() {
        return Ok((path, stem));
    }
    if variant != "vmd" {
        return Err(format!("unknown variant `{variant}` (expected `vmd`)"));
    }
    // -trans_vmd -mediumshade -aasamples 4, as words of the scene itself.
    let text = std::fs::read_to_string(&path).map_err(|e| e.to_string())?;
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for l in &mut lines {
        let lower = l.to_ascii_lowercase();
        if let Some(i) = lower.find("antialiasing") {
            *l = format!("{}Antialiasing 4", &l[..i]);
        }
    }
    let at = lines
        .iter()
        .position(|l| l.to_ascii_lowercase().contains("resolution"))
        .ok_or("no RESOLUTION line")?;
    lines.insert(
        at + 1,
        "SHADER_MODE MEDIUM TRANS_VMD END_SHADER_MODE".to_string(),
    );
    let copy = dir.join(format!("{stem}-vmd.dat"));
    std::fs::write(&copy, lines.join("\n") + "\n").map_err(|e| e.to_string())?;
    Ok((copy, format!("{stem}-vmd")))
}

/// Renders `scene` with `program` and its arguments `pre` (Tachyon's command line follows)
/// into `image`: (render seconds as the program reports them, wall seconds of the command).
fn run(
    setup: &Setup,
    (program, pre): (&Path, &[&str]),
    scene: &Path,
    image: &Path,
) -> Result<(f64, f64), String> {
    let _ = std::fs::remove_file(image);
    let t0 = Instant::now();
    let done = Command::new(program)
        .args(pre)
        .arg(scene)
        .args(["-numthreads", &setup.threads.to_string()])
        .args(["-format", "PPM", "-o"])
        .arg(image)
        .current_dir(setup.dir)
        .output()
        .map_err(|e| format!("{}: {e}", program.display()))?;
    let wall = t0.elapsed().as_secs_f64();
    let text =
        String::from_utf8_lossy(&done.stdout).to_string() + &String::from_utf8_lossy(&done.stderr);
    if !image.exists() {
        let last = text.lines().last().unwrap_or("").trim().to_string();
        return Err(format!("{} wrote no image: {last}", program.display()));
    }
    Ok((
        render_seconds(&text).ok_or("no render time reported")?,
        wall,
    ))
}

/// The number after "Ray Tracing Time:" (both programs print it, Luxon in Tachyon's words).
fn render_seconds(text: &str) -> Option<f64> {
    let (_, after) = text.rsplit_once("Ray Tracing Time:")?;
    after.split_whitespace().next()?.parse().ok()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Renders one scene `runs` times with each program, alternating; compares the pictures.
fn compare(setup: &Setup, name: &str) -> Result<Compared, String> {
    let (scene, stem) = scene_file(setup.dir, name)?;
    let scene = std::fs::canonicalize(&scene).map_err(|e| format!("{}: {e}", scene.display()))?;
    let theirs_path = setup.out.join(format!("{stem}.tachyon.ppm"));
    let ours_path = setup.out.join(format!("{stem}.luxon.ppm"));
    let (mut tachyon, mut luxon) = (Vec::new(), Vec::new());
    for _ in 0..setup.runs {
        let them = (Path::new("tachyon-nox"), &[][..]);
        tachyon.push(run(setup, them, &scene, &theirs_path)?);
        luxon.push(run(setup, (setup.luxon, &["tachyon"]), &scene, &ours_path)?);
    }
    let medians = |v: &[(f64, f64)]| {
        (
            median(v.iter().map(|t| t.0).collect()),
            median(v.iter().map(|t| t.1).collect()),
        )
    };
    let read = |p: &Path| {
        image::open(p)
            .map(|i| i.to_rgb8())
            .map_err(|e| format!("{}: {e}", p.display()))
    };
    let (theirs, ours) = (read(&theirs_path)?, read(&ours_path)?);
    if ours.dimensions() != theirs.dimensions() {
        return Err(format!(
            "sizes differ: {:?} and {:?}",
            ours.dimensions(),
            theirs.dimensions()
        ));
    }
    let (w, h) = ours.dimensions();
    let s = ssim(
        &gray(ours.as_raw()),
        &gray(theirs.as_raw()),
        w as usize,
        h as usize,
    )
    .ok_or("image too small for SSIM")?;
    let mut pair = image::RgbImage::new(2 * w, h);
    image::imageops::replace(&mut pair, &theirs, 0, 0);
    image::imageops::replace(&mut pair, &ours, w as i64, 0);
    pair.save(setup.out.join(format!("{stem}.png")))
        .map_err(|e| e.to_string())?;
    Ok(Compared {
        ssim: s,
        tachyon: medians(&tachyon),
        luxon: medians(&luxon),
    })
}
