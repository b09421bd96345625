//! Tachyon scenes rendered: the picture is oriented as Tachyon's (its world is left-handed),
//! and, when `tachyon-nox` (Debian's `tachyon-bin-nox`) is installed, scenes of unlit,
//! fully saturated surfaces come out pixel for pixel as Tachyon draws them: camera window,
//! zoom, aspect, frustum, the half-pixel sample offset, orthographic views and the primitives'
//! placement all agree (colours 0 and 1 are the same with and without gamma).

mod common;

use common::*;
use std::path::Path;
use std::process::Command;

/// An unlit, fully saturated texture of colour `c`.
fn emitter(c: &str) -> String {
    format!("TEXTURE AMBIENT 1 DIFFUSE 0 SPECULAR 0 OPACITY 1 COLOR {c} TEXFUNC 0")
}

/// Renders Tachyon scene text with Luxon: 8-bit RGB rows, top first (values 0 or 255 here).
fn luxon_pixels(dir: &Path, text: &str) -> (u32, u32, Vec<u8>) {
    let p = dir.join("scene.dat");
    std::fs::write(&p, text).unwrap();
    let fb = render_with(&p, |_| {});
    let rgb = fb
        .rgba
        .chunks_exact(4)
        .flat_map(|px| [0, 1, 2].map(|k| (px[k].clamp(0.0, 1.0) * 255.0).floor() as u8))
        .collect();
    (fb.width, fb.height, rgb)
}

/// Renders Tachyon scene text with `tachyon-nox` (binary PPM), or `None` without it.
fn tachyon_pixels(dir: &Path, text: &str) -> Option<(u32, u32, Vec<u8>)> {
    let p = dir.join("t.dat");
    let out = dir.join("t.ppm");
    std::fs::write(&p, text).unwrap();
    let _ = std::fs::remove_file(&out);
    let status = Command::new("tachyon-nox")
        .arg(&p)
        .args(["-format", "PPM", "-numthreads", "1", "-o"])
        .arg(&out)
        .current_dir(dir)
        .output()
        .ok()?;
    assert!(status.status.success());
    let bytes = std::fs::read(&out).unwrap_or_else(|_| {
        panic!(
            "tachyon-nox wrote no image:\n{}",
            String::from_utf8_lossy(&status.stdout)
        )
    });
    // "P6\nW H\n255\n" then the pixels.
    let mut fields = Vec::new();
    let mut i = 0;
    while fields.len() < 4 {
        while bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        while !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        fields.push(String::from_utf8_lossy(&bytes[start..i]).to_string());
    }
    let (w, h): (u32, u32) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    Some((w, h, bytes[i + 1..].to_vec()))
}

fn tachyon_present() -> bool {
    Command::new("tachyon-nox").arg("-version").output().is_ok()
}

#[test]
fn the_picture_has_tachyons_orientation() {
    // Tachyon's world is left-handed: looking along +z with +y up, +x is on the right.
    let dir = temp_dir("tachyon-orientation");
    let text = format!(
        "BEGIN_SCENE RESOLUTION 21 21\n\
         SPHERE CENTER 2 0 5 RAD 0.5 {}\nSPHERE CENTER 0 2 5 RAD 0.5 {}\nEND_SCENE\n",
        emitter("1 0 0"),
        emitter("0 1 0")
    );
    let (w, _, px) = luxon_pixels(&dir, &text);
    let at = |x: u32, y: u32| {
        let i = 3 * (y * w + x) as usize;
        [px[i], px[i + 1], px[i + 2]]
    };
    // Window 1 wide at distance 1: x = 2 at z = 5 is 0.4 of the width right of centre.
    assert_eq!(at(18, 10), [255, 0, 0]);
    assert_eq!(at(2, 10), [0, 0, 0]);
    assert_eq!(at(10, 2), [0, 255, 0]);
    assert_eq!(at(10, 18), [0, 0, 0]);
}

/// Scenes whose every pixel is 0 or 255 in both renderers.
fn flat_scenes() -> Vec<(&'static str, String)> {
    let red = emitter("1 0 0");
    let green = emitter("0 1 0");
    let blue = emitter("0 0 1");
    let white = emitter("1 1 1");
    let things = format!(
        "SPHERE CENTER 1.2 0.3 6 RAD 0.7 {red}\n\
         RING CENTER -1 -0.5 5 NORMAL 0.3 0.2 -1 INNER 0.2 OUTER 0.6 {green}\n\
         BOX MIN -0.4 0.4 4 MAX 0.1 1.1 4.6 {blue}\n\
         FCYLINDER BASE -1.5 1 6 APEX -0.5 1.6 7 RAD 0.15 {white}\n\
         TRI V0 0.2 -1.2 4 V1 1.4 -0.9 5 V2 0.5 -0.2 4.5 {green}\n\
         PLANE CENTER 0 -2 0 NORMAL 0 1 0.1 {blue}\n"
    );
    let cam = |extra: &str, window: &str| {
        format!(
            "CAMERA {extra} {window} ANTIALIASING 0 RAYDEPTH 1 CENTER 0.1 0.2 -0.5 \
             VIEWDIR 0.05 -0.02 1 UPDIR 0.02 1 0 END_CAMERA\n"
        )
    };
    vec![
        (
            "perspective",
            format!(
                "BEGIN_SCENE RESOLUTION 61 47\n{}{things}END_SCENE\n",
                cam("", "ZOOM 0.8 ASPECTRATIO 1")
            ),
        ),
        (
            "zoom and aspect",
            format!(
                "BEGIN_SCENE RESOLUTION 50 50\n{}{things}END_SCENE\n",
                cam("", "ZOOM 1.3 ASPECTRATIO 1.4")
            ),
        ),
        (
            "frustum",
            format!(
                "BEGIN_SCENE RESOLUTION 40 60\n{}{things}END_SCENE\n",
                cam("", "ZOOM 1 ASPECTRATIO 1")
                    .replace("END_CAMERA", "FRUSTUM -0.3 0.5 -0.4 0.8 END_CAMERA")
            ),
        ),
        (
            "orthographic",
            format!(
                "BEGIN_SCENE RESOLUTION 45 45\n{}{things}END_SCENE\n",
                cam("PROJECTION ORTHOGRAPHIC", "ZOOM 0.3 ASPECTRATIO 1")
            ),
        ),
        (
            "clip group",
            format!(
                "BEGIN_SCENE RESOLUTION 48 48\n{}START_CLIPGROUP NUMPLANES 1 1 0.2 0 0.9\n\
                 {things}END_CLIPGROUP\nEND_SCENE\n",
                cam("", "ZOOM 0.8 ASPECTRATIO 1")
            ),
        ),
    ]
}

#[test]
fn flat_scenes_match_tachyon_pixel_for_pixel() {
    if !tachyon_present() {
        eprintln!("skipped: tachyon-nox is not installed (Debian package tachyon-bin-nox)");
        return;
    }
    let dir = temp_dir("tachyon-flat");
    for (name, text) in flat_scenes() {
        let (w, h, ours) = luxon_pixels(&dir, &text);
        let (tw, th, theirs) = tachyon_pixels(&dir, &text).unwrap();
        assert_eq!((w, h), (tw, th), "{name}");
        let differ: Vec<(u32, u32)> = (0..w * h)
            .filter(|&i| {
                let i = 3 * i as usize;
                ours[i..i + 3] != theirs[i..i + 3]
            })
            .map(|i| (i % w, i / w))
            .collect();
        // Pixels whose sample point lies on an edge may round either way in f32: a handful.
        assert!(
            differ.len() <= 2,
            "{name}: {} of {} pixels differ from Tachyon's, e.g. {:?}",
            differ.len(),
            w * h,
            &differ[..differ.len().min(8)]
        );
        // Something of each colour is in the picture.
        for c in [[255, 0, 0], [0, 255, 0], [0, 0, 255]] {
            assert!(
                ours.chunks_exact(3).any(|p| p == c),
                "{name}: no pixel of {c:?}"
            );
        }
    }
}
