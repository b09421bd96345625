//! The RON scene loader on arbitrary text. Relative includes and meshes resolve in a private
//! temporary directory holding the shipped include files (so `include:` is followed) and
//! nothing else: every other path is a missing file.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

fn scene_path() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("luxon-fuzz-ron-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("include")).unwrap();
        for (name, text) in [
            (
                "studio.ron",
                include_str!("../../../scenes/include/studio.ron"),
            ),
            (
                "camera-world.ron",
                include_str!("../../../scenes/include/camera-world.ron"),
            ),
        ] {
            std::fs::write(dir.join("include").join(name), text).unwrap();
        }
        dir.join("scene.ron")
    })
}

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        // Ok or a SceneError: both fine; a panic, hang or runaway allocation is the bug.
        let _ = luxon_formats::load_ron_str(text, scene_path());
    }
});
