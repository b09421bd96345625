//! NFF scenes rendered end to end: `luxon render FILE.nff` works directly, and every shared SPD
//! scene looks like POV-Ray's picture of it (SSIM >= 0.6 against `../shared/spd/reference`).
//!
//! The renders are 512x512, like the references (`LUXON_NFF_SIZE=256` compares 256x256 renders
//! with the references averaged down 2x2). Set `LUXON_NFF_OUT=DIR` to keep each render next to
//! its reference as `DIR/NAME.png` (ours left, POV-Ray's right).

mod common;

use common::*;
use std::path::{Path, PathBuf};

#[path = "common/ssim.rs"]
mod ssim;

#[test]
fn ssim_behaves() {
    let (w, h) = (64, 48);
    // A structured picture: a gradient with a bright disc off centre.
    let img: Vec<f64> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            let d = ((x - 20.0).powi(2) + (y - 20.0).powi(2)).sqrt();
            if d < 10.0 {
                230.0
            } else {
                2.0 * x + y
            }
        })
        .collect();
    assert!((ssim::ssim(&img, &img, w, h) - 1.0).abs() < 1e-12);
    let mirrored = ssim::mirror(&img, w);
    let s_mirror = ssim::ssim(&img, &mirrored, w, h);
    assert!(s_mirror < 0.9, "mirroring must show: {s_mirror}");
    // Mild noise costs less than the wrong orientation.
    let mut seed = 1u32;
    let noisy: Vec<f64> = img
        .iter()
        .map(|v| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (v + (seed >> 24) as f64 / 64.0 - 2.0).clamp(0.0, 255.0)
        })
        .collect();
    let s_noise = ssim::ssim(&img, &noisy, w, h);
    assert!(
        s_noise > s_mirror && s_noise < 1.0,
        "{s_noise} vs {s_mirror}"
    );
    // Symmetric.
    assert!((ssim::ssim(&noisy, &img, w, h) - s_noise).abs() < 1e-12);
    // Constant images: equal gives 1, a different constant less.
    let a = vec![100.0; w * h];
    let b = vec![150.0; w * h];
    assert!((ssim::ssim(&a, &a, w, h) - 1.0).abs() < 1e-12);
    assert!(ssim::ssim(&a, &b, w, h) < 0.95);
    assert_eq!(ssim::half(&img, w, h).len(), w * h / 4);
}

fn shared() -> Option<PathBuf> {
    let d = root().join("../shared/spd");
    d.is_dir().then_some(d)
}

/// Grayscale of a reference PNG at `size` (512 or 256).
fn reference(path: &Path, size: usize) -> Vec<f64> {
    let img = image::open(path).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (512, 512), "{}", path.display());
    let g = ssim::gray(img.as_raw());
    if size == 512 {
        g
    } else {
        ssim::half(&g, 512, 512)
    }
}

/// Saves ours and the reference side by side (8-bit RGB).
fn save_side_by_side(dir: &Path, name: &str, ours: &[u8], size: u32, reference: &Path) {
    let r = image::imageops::resize(
        &image::open(reference).unwrap().to_rgb8(),
        size,
        size,
        image::imageops::FilterType::Triangle,
    );
    let mut out = image::RgbImage::new(size * 2, size);
    for y in 0..size {
        for x in 0..size {
            let i = ((y * size + x) * 3) as usize;
            out.put_pixel(x, y, image::Rgb([ours[i], ours[i + 1], ours[i + 2]]));
            out.put_pixel(x + size, y, *r.get_pixel(x, y));
        }
    }
    std::fs::create_dir_all(dir).unwrap();
    out.save(dir.join(format!("{name}.png"))).unwrap();
}

#[test]
fn spd_scenes_look_like_pov_ray() {
    let Some(dir) = shared() else {
        eprintln!("note: ../shared/spd is absent; skipping the SSIM comparison with POV-Ray");
        return;
    };
    let size: u32 = match std::env::var("LUXON_NFF_SIZE") {
        Ok(s) => s.parse().expect("LUXON_NFF_SIZE: 256 or 512"),
        Err(_) => 512,
    };
    let keep = std::env::var_os("LUXON_NFF_OUT").map(PathBuf::from);
    let names = [
        "balls4", "balls5", "gears", "lattice", "mount", "rings", "teapot6", "teapot12",
        "teapot48", "tetra", "tree",
    ];
    let mut failed = Vec::new();
    for name in names {
        let scene = dir.join(format!("{name}.nff.gz"));
        let t0 = std::time::Instant::now();
        let fb = render_with(&scene, |d| {
            d.render.width = size;
            d.render.height = size;
        });
        let rgb = to_srgb8(&fb);
        let refpath = dir.join(format!("reference/{name}.png"));
        let ours = ssim::gray(&rgb);
        let theirs = reference(&refpath, size as usize);
        let s = ssim::ssim(&ours, &theirs, size as usize, size as usize);
        let s_mirror = ssim::ssim(
            &ssim::mirror(&ours, size as usize),
            &theirs,
            size as usize,
            size as usize,
        );
        println!(
            "{name:9} {size}x{size}  SSIM {s:.3}  (mirrored {s_mirror:.3})  {:.1} s",
            t0.elapsed().as_secs_f64()
        );
        if let Some(k) = &keep {
            save_side_by_side(k, name, &rgb, size, &refpath);
        }
        if s < 0.6 || s <= s_mirror {
            failed.push(format!("{name}: SSIM {s:.3}, mirrored {s_mirror:.3}"));
        }
    }
    assert!(failed.is_empty(), "unlike POV-Ray's pictures: {failed:?}");
}

const SMALL: &str = "# a small NFF scene\n\
v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 64 48\n\
b 0.2 0.3 0.6\nl 4 -4 6\nl -4 -2 5 0.5 0.5 0.5\n\
f 1 0.8 0.3 0.8 0 1 0 1\np 4\n-3 -3 0\n3 -3 0\n3 3 0\n-3 3 0\n\
f 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\nc 1.5 0 0 0.3 1.5 0 2 0.3\n";

#[test]
fn luxon_renders_nff_directly() {
    let dir = temp_dir("nff-cli");
    let scene = dir.join("small.nff");
    std::fs::write(&scene, SMALL).unwrap();
    let out = dir.join("small.png");
    let o = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (64, 48), "the NFF resolution");
    // The red sphere is in the middle, the sky at the top.
    let top = img.get_pixel(32, 14);
    assert!(
        top[0] > 100 && top[0] > top[1] + 50,
        "upper half of the red sphere: {top:?}"
    );
    let sky = img.get_pixel(32, 1);
    assert!(sky[2] > sky[0] && sky[2] > 150, "background: {sky:?}");

    // An error names file:line:col.
    let bad = dir.join("bad.nff");
    std::fs::write(&bad, SMALL.replace("s 0 0 1 1", "s 0 0 1")).unwrap();
    let o = run(&["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("bad.nff:19:8:") && e.contains("takes 4 numbers"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
