//! The plugin host: discovery and handshake (`registry`), calls and sinks (`calls`).

pub mod calls;
pub mod registry;

pub use registry::{Entry, Library, LookupError, PluginKind, Problem, Registry};
