#![doc = include_str!("../README.md")]
//!
//! ## The API
//!
//! [`load`] reads any supported file, [`load_ron_str`] RON text; both give a [`SceneDesc`]
//! (module [`desc`]) or a [`SceneError`]. The importers are [`nff`], [`obj`] and [`tachyon`]; [`spd`]
//! generates the SPD scenes; [`geometry`] holds the inline arrays importers hand the core.
//!
//! Modules import only modules of lower layers (bottom first; `tests/layers.rs` keeps this):
//!
//! | layer       | modules                                          |
//! |-------------|--------------------------------------------------|
//! | origin      | `origin`                                         |
//! | leaves      | `error`, `geometry`, `spans`, `raw`              |
//! | description | `desc`                                           |
//! | scanner     | `scanner`                                        |
//! | checks      | `validate`, `ron_error`                          |
//! | conversion  | `convert`, `camera`, `effects`, `volume_render`  |
//! | importers   | `nff`, `obj`, `tachyon`                          |
//! | formats     | `ron_scene`, `spd`                               |
//! | front door  | `load`                                           |

mod camera;
mod convert;
pub mod desc;
mod effects;
mod error;
pub mod geometry;
mod load;
pub mod nff;
pub mod obj;
mod origin;
mod raw;
mod ron_error;
mod ron_scene;
mod scanner;
mod spans;
pub mod spd;
pub mod tachyon;
mod validate;
mod volume_render;

pub use desc::*;
pub use error::{suggest, SceneError};
pub use geometry::{InlineGeometry, InlineMesh};
pub use load::load;
pub use ron_scene::load_ron_str;
