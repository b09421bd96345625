//! # Luxon: a parallel ray tracing library
//!
//! The renderer is a library first; the `luxon` command is a thin shell over it. Data flows one
//! way: scene file → [`luxon_formats::SceneDesc`] → [`Scene`] (plugins resolved, geometry built,
//! BVHs) → [`render::render`] (tiles over threads, Whitted integrator) → [`Framebuffer`] →
//! writer plugins ([`output`]).
//!
//! ```no_run
//! use luxon::{plugin::Registry, Scene};
//! let desc = luxon_formats::load("scenes/spheres.ron".as_ref())?;
//! let registry = Registry::discover(&desc.plugin_path);
//! let scene = Scene::build(&desc, &registry)?;
//! let (image, stats) = luxon::render::render(&scene, &|_, _| {})?;
//! let outputs = luxon::output::resolve(&scene.outputs, &registry)?;
//! luxon::output::write_all(&outputs, &image, &registry, ".".as_ref())?;
//! # Ok::<(), luxon::Error>(())
//! ```

pub mod adaptive;
pub mod bvh;
pub mod cache;
pub mod camera;
pub mod error;
pub mod files;
pub mod framebuffer;
pub mod geometry;
pub mod integrator;
pub mod math;
pub mod metrics;
pub mod output;
pub mod plugin;
pub mod ppm;
pub mod ray;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod schedule;
pub mod sweep;
pub mod volume;
pub mod volume_render;

pub use error::Error;
pub use framebuffer::Framebuffer;
pub use scene::Scene;
