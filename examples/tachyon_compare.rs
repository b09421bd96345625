//! Tachyon's example scenes rendered by Tachyon and by Luxon, side by side, with the SSIM of
//! each pair (luma, `luxon::metrics::ssim`).
//!
//! ```sh
//! cargo run --release --example tachyon_compare -- SCENE_DIR OUT_DIR [NAME.dat ...]
//! ```
//!
//! SCENE_DIR holds the `.dat` files and what they read (Debian's
//! `/usr/share/doc/tachyon/examples/scenes`, copied somewhere writable; Tachyon opens relative
//! paths from the working directory, so it runs there). Without names every `.dat` file is
//! rendered. `tachyon-nox` (Debian's `tachyon-bin-nox`) must be on the path; its pictures are
//! kept in OUT_DIR as `NAME.tachyon.ppm` and reused by later runs. Luxon's picture is its
//! framebuffer written as Tachyon writes its own: floor(255·c), clamped, no gamma (Tachyon's
//! colours are display values), so the pair compares like with like whatever Luxon's writers
//! do. `OUT_DIR/NAME.png` shows Tachyon's picture on the left, Luxon's on the right.
//!
//! A scene name may carry Tachyon command-line shading switches after a colon, written into the
//! scene as the SHADER_MODE and CAMERA words they stand for, e.g. `janbadoutput.dat:vmd`
//! renders `janbadoutput.dat` as its header asks (`-trans_vmd -mediumshade -aasamples 4`).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use luxon::metrics::{gray, ssim};
use luxon::plugin::Registry;
use luxon::Scene;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: tachyon_compare SCENE_DIR OUT_DIR [NAME.dat[:vmd] ...]");
        std::process::exit(2);
    }
    let (dir, out) = (PathBuf::from(&args[0]), PathBuf::from(&args[1]));
    std::fs::create_dir_all(&out).expect("cannot create OUT_DIR");
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
    println!("| scene | SSIM | Tachyon s | Luxon s |");
    println!("|---|---:|---:|---:|");
    for name in &names {
        match compare(&dir, &out, name) {
            Ok((s, tt, tl)) => println!("| {name} | {s:.3} | {tt:.2} | {tl:.2} |"),
            Err(e) => println!("| {name} | – ({e}) | | |"),
        }
    }
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

/// SSIM, Tachyon's and Luxon's render times.
fn compare(dir: &Path, out: &Path, name: &str) -> Result<(f64, f64, f64), String> {
    let (scene, stem) = scene_file(dir, name)?;
    let theirs_path = out.join(format!("{stem}.tachyon.ppm"));
    let mut tachyon_s = f64::NAN;
    if !theirs_path.exists() {
        let t0 = Instant::now();
        let run = Command::new("tachyon-nox")
            .arg(&scene)
            .args(["-format", "PPM", "-o"])
            .arg(&theirs_path)
            .current_dir(dir)
            .output()
            .map_err(|e| format!("tachyon-nox: {e}"))?;
        tachyon_s = t0.elapsed().as_secs_f64();
        if !theirs_path.exists() {
            return Err(format!(
                "tachyon-nox wrote no image: {}",
                String::from_utf8_lossy(&run.stdout)
                    .lines()
                    .last()
                    .unwrap_or("")
            ));
        }
    }
    let theirs = image::open(&theirs_path)
        .map_err(|e| e.to_string())?
        .to_rgb8();

    let t0 = Instant::now();
    let ours = render(&scene)?;
    let luxon_s = t0.elapsed().as_secs_f64();
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
    pair.save(out.join(format!("{stem}.png")))
        .map_err(|e| e.to_string())?;
    Ok((s, tachyon_s, luxon_s))
}

/// Luxon's picture of a scene, quantised as Tachyon quantises: floor(255·c), clamped.
fn render(scene: &Path) -> Result<image::RgbImage, String> {
    let desc = luxon_formats::load(scene).map_err(|e| e.to_string())?;
    let mut extra = desc.plugin_path.clone();
    // Plugins live beside the workspace's binaries, one level above `examples/`.
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().and_then(Path::parent).map(Path::to_path_buf))
    {
        extra.push(dir);
    }
    let registry = Registry::discover(&extra);
    let built = Scene::build(&desc, &registry).map_err(|e| e.to_string())?;
    let (fb, _) = luxon::render::render(&built, &|_, _| {}).map_err(|e| e.to_string())?;
    let bytes = fb
        .rgba
        .chunks_exact(4)
        .flat_map(|p| [0, 1, 2].map(|k| (p[k].clamp(0.0, 1.0) * 255.0).floor() as u8))
        .collect();
    image::RgbImage::from_raw(fb.width, fb.height, bytes).ok_or("bad framebuffer".to_string())
}
