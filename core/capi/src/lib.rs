//! Luxon's C API: the retained-scene API of `luxon::api` behind opaque handles, status codes
//! and a per-thread last error, for programs in C, C++, Fortran (through `bind(C)`) and any
//! language with a C FFI. The header `include/luxon.h` is generated from this crate's doc
//! comments by cbindgen and committed; `tests/header.rs` fails when it is stale.
//!
//! Rules every entry point keeps (see `guard`): it never unwinds into the caller (a panic
//! becomes `LUXON_ERROR_PANIC` and poisons the handles the call held), it sets the calling
//! thread's last error (empty on success), and a NULL, released or wrong-kind handle is an
//! error code, never a crash.

// The C names (`luxon_scene`, `luxon_status`...) are the API.
#![allow(non_camel_case_types)]

#[cfg(panic = "abort")]
compile_error!(
    "luxon-capi needs panic = \"unwind\": a panic must become LUXON_ERROR_PANIC, never end the host"
);

mod arrays;
mod context;
mod guard;
mod handles;
mod image;
mod mpi;
mod objects;
mod renderer;
mod scene;
mod status;
mod text;
mod version;

pub use arrays::*;
pub use context::*;
pub use guard::{luxon_last_error, luxon_last_error_copy};
pub use handles::{luxon_array, luxon_context, luxon_object, luxon_renderer, luxon_scene};
pub use image::*;
pub use mpi::*;
pub use objects::*;
pub use renderer::*;
pub use scene::*;
pub use status::*;
pub use version::*;
