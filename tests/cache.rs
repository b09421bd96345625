//! The binary geometry cache of NFF scenes: a cache hit gives the identical image; a touched
//! source makes the cache stale (rebuilt silently); a truncated or damaged cache is reported
//! and rebuilt, never trusted.

mod common;

use common::*;
use std::path::Path;

/// Spheres, a cone, a polygon and smooth patches: every kind the cache stores.
const SCENE: &str =
    "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 48 36\n\
b 0.2 0.3 0.6\nl 4 -4 6\nl -4 -2 5 0.5 0.5 0.5\n\
f 1 0.8 0.3 0.8 0 1 0 1\np 4\n-3 -3 0\n3 -3 0\n3 3 0\n-3 3 0\n\
f 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\ns 1.5 1 0.5 0.5\nc 1.5 0 0 0.3 1.5 0 2 0.3\n\
f 0.3 0.9 0.3 0.7 0.3 20 0 0\npp 3\n-2 0 0.2 0 0 1\n-1 0 0.2 0.3 0 1\n-1.5 0 1.2 0 -0.3 1\n";

fn render(scene: &Path, out: &Path, extra: &[&str]) -> (Vec<u8>, String) {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--stats",
    ];
    args.extend(extra);
    let o = run(&args);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    (std::fs::read(out).unwrap(), e)
}

#[test]
fn cache_hit_stale_and_corrupt() {
    let dir = temp_dir("geometry-cache");
    let scene = dir.join("s.nff");
    std::fs::write(&scene, SCENE).unwrap();
    let cache = dir.join("s.nff.luxcache");
    let out = dir.join("o.ppm");

    // Small scenes get no cache unless asked.
    let (reference, e) = render(&scene, &out, &[]);
    assert!(!cache.exists(), "{e}");
    assert!(e.contains("geometry cache   not used"), "{e}");
    let (img, e) = render(&scene, &out, &["--cache"]);
    assert_eq!(img, reference);
    assert!(cache.is_file() && e.contains("wrote geometry cache"), "{e}");

    // A hit: read, not written again, the same image.
    let (img, e) = render(&scene, &out, &[]);
    assert!(e.contains("geometry cache   read"), "{e}");
    assert!(!e.contains("wrote geometry cache"), "{e}");
    assert_eq!(img, reference, "the cached scene renders differently");
    let (img, e) = render(&scene, &out, &["--no-cache"]);
    assert!(e.contains("geometry cache   off"), "{e}");
    assert_eq!(img, reference);

    // Stale: the source changed after the cache was written; rebuilt without a warning.
    std::thread::sleep(std::time::Duration::from_millis(20));
    let moved = SCENE.replace("s 0 0 1 1", "s 0.5 0 1 1.2");
    std::fs::write(&scene, &moved).unwrap();
    let (fresh, e) = render(&scene, &out, &["--no-cache"]);
    assert_ne!(fresh, reference, "the edit must show");
    let (img, e2) = render(&scene, &out, &["--cache"]);
    assert!(!e2.contains("warning"), "{e2}");
    assert!(
        e2.contains("wrote geometry cache"),
        "stale cache not rebuilt: {e2}\n{e}"
    );
    assert_eq!(img, fresh);
    let (img, e) = render(&scene, &out, &[]);
    assert!(e.contains("geometry cache   read"), "{e}");
    assert_eq!(img, fresh);

    // Truncated, then one byte flipped in the middle: a warning, the right image, rebuilt.
    let good = std::fs::read(&cache).unwrap();
    let damaged = [good[..good.len() / 2].to_vec(), {
        let mut b = good.clone();
        let i = b.len() * 2 / 3;
        b[i] ^= 0x40;
        b
    }];
    for bad in damaged {
        std::fs::write(&cache, &bad).unwrap();
        let (img, e) = render(&scene, &out, &["--cache"]);
        assert!(
            e.contains("warning: geometry cache") && e.contains("unusable"),
            "{e}"
        );
        assert_eq!(img, fresh);
        assert_eq!(std::fs::read(&cache).unwrap(), good, "not rebuilt");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
