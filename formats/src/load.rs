//! The front door: a scene file of any supported format, chosen by its extension.

use std::path::Path;

use crate::desc::SceneDesc;
use crate::error::SceneError;
use crate::input::{DiskSource, LoadOptions};
use crate::{nff, obj, ron_scene, tachyon};

/// Loads a scene file, choosing the format by its extension (`.ron`; `.nff` and `.nff.gz`
/// through the [`nff`] importer; `.obj` (with its `.mtl` files) through the [`obj`] importer;
/// `.dat` through the [`tachyon`] importer; any case), within the default [`LoadOptions`].
pub fn load(path: &Path) -> Result<SceneDesc, SceneError> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] within the limits of `options`.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<SceneDesc, SceneError> {
    if nff::is_nff_path(path) {
        return nff::load_with(path, options);
    }
    if obj::is_obj_path(path) {
        return obj::load_with(path, options);
    }
    if tachyon::is_tachyon_path(path) {
        let mut o = tachyon::Options::new(crate::origin::Origin {
            file: std::sync::Arc::new(path.to_path_buf()),
            line: 1,
            col: 1,
        });
        o.max_text = options.max_scene_bytes;
        return tachyon::load_with(path, &o);
    }
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !extension.eq_ignore_ascii_case("ron") {
        let found = match extension {
            "" => "a scene file name without an extension".to_string(),
            e => format!("unsupported scene file extension `.{e}`"),
        };
        let message = format!(
            "{found}; expected one of {}, `.nff`, `.nff.gz`, `.obj`, `.dat` (Tachyon)",
            ron_scene::supported_extensions()
        );
        return Err(SceneError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::Unsupported, message),
        });
    }
    ron_scene::load_ron_with(&mut DiskSource, path, options)
}
