//! The plugin host: discovery and handshake (`registry`), a library's file checked before it
//! is loaded (`elf`), one call with its errors mapped to the scene (`calls`), and per kind of plugin the call and the host side of its sink: primitives
//! filling the scene's geometry, textures, volume readers filling volumes, writers.

pub mod calls;
pub mod elf;
pub mod primitive;
pub mod registry;
pub mod texture;
pub mod volume_reader;
pub mod writer;

pub use registry::{Entry, Library, LookupError, PluginKind, Problem, Registry};
pub use volume_reader::read_volume;
