#![doc = include_str!("../README.md")]
//!
//! ## The API
//!
//! [`load`] reads any supported file, [`load_ron_str`] RON text; both give a [`SceneDesc`]
//! (module [`desc`]) or a [`SceneError`]. The importers are [`nff`] and [`obj`]; [`spd`]
//! generates the SPD scenes; [`geometry`] holds the inline arrays importers hand the core.

mod camera;
mod convert;
pub mod desc;
mod effects;
mod error;
pub mod geometry;
pub mod nff;
pub mod obj;
mod raw;
mod ron_error;
mod ron_scene;
mod scanner;
mod spans;
pub mod spd;
mod validate;
mod volume_render;

use std::path::Path;

pub use desc::*;
pub use error::{suggest, SceneError};
pub use geometry::{InlineGeometry, InlineMesh};
pub use ron_scene::load_ron_str;

/// Loads a scene file, choosing the format by its extension (`.ron`; `.nff` and `.nff.gz`
/// through the [`nff`] importer; `.obj` (with its `.mtl` files) through the [`obj`] importer;
/// any case).
pub fn load(path: &Path) -> Result<SceneDesc, SceneError> {
    if nff::is_nff_path(path) {
        return nff::load(path);
    }
    if obj::is_obj_path(path) {
        return obj::load(path);
    }
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !extension.eq_ignore_ascii_case("ron") {
        let found = match extension {
            "" => "a scene file name without an extension".to_string(),
            e => format!("unsupported scene file extension `.{e}`"),
        };
        let message = format!(
            "{found}; expected one of {}, `.nff`, `.nff.gz`, `.obj`",
            ron_scene::supported_extensions()
        );
        return Err(SceneError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::Unsupported, message),
        });
    }
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    load_ron_str(&text, path)
}
