#![doc = include_str!("../README.md")]
//!
//! ## The API
//!
//! [`load`] reads any supported file, [`load_ron_str`] RON text; both give a [`SceneDesc`]
//! (module [`desc`]) or a [`SceneError`]. The importers are [`nff`], [`obj`] and [`tachyon`]; [`spd`]
//! generates the SPD scenes; [`geometry`] holds the inline arrays importers hand the core.
//! [`fragment`] reads one part of a scene (a camera, a light, a material...) from a RON
//! fragment, by the scene loader's own rules, and checks typed values by the same rules;
//! [`print`](mod@print) writes those parts as fragments (with `luxon convert`'s writer, `to_ron`).
//!
//! Modules import only modules of lower layers (bottom first; `tests/layers.rs` keeps this):
//!
//! | layer       | modules                                          |
//! |-------------|--------------------------------------------------|
//! | origin      | `origin`                                         |
//! | leaves      | `error`, `geometry`, `spans`, `raw`, `pattern`   |
//! | description | `desc`                                           |
//! | text        | `ron_text`                                       |
//! | input       | `input`, `print`                                 |
//! | scanner     | `scanner`                                        |
//! | checks      | `validate`, `ron_error`                          |
//! | conversion  | `convert`, `camera`, `effects`, `volume_render`, `animation`, `instances`, `series` |
//! | importers   | `nff`, `obj`, `tachyon`                          |
//! | includes    | `includes`                                       |
//! | formats     | `ron_scene`, `spd`, `data_frames`                |
//! | front door  | `load`, `fragment`                               |

#![forbid(unsafe_code)]

mod animation;
mod camera;
mod convert;
pub mod data_frames;
pub mod desc;
mod effects;
mod error;
pub mod fragment;
pub mod geometry;
mod includes;
pub mod input;
mod instances;
mod load;
pub mod nff;
pub mod obj;
mod origin;
mod pattern;
pub mod print;
mod raw;
mod ron_error;
mod ron_scene;
mod ron_text;
mod scanner;
mod series;
mod spans;
pub mod spd;
pub mod tachyon;
mod validate;
mod volume_render;

pub use data_frames::{load_frame, missing_files, SeriesFrame};
pub use desc::*;
pub use error::{shown, suggest, SceneError, Warning};
pub use geometry::{InlineGeometry, InlineMesh};
pub use includes::MAX_DEPTH as MAX_INCLUDE_DEPTH;
pub use input::{DiskSource, LoadOptions, MemorySource, Source};
pub use load::{load, load_with};
pub use pattern::FramePattern;
pub use ron_scene::{load_ron_str, load_ron_with};
pub use ron_text::{inline_as_objects, to_ron};
