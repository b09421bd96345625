//! # Luxon: a parallel ray tracing library
//!
//! The renderer is a library first; the `luxon` command is a thin shell over it. Data flows one
//! way: scene file → [`luxon_formats::SceneDesc`] → [`Scene`] (plugins resolved, geometry built,
//! BVHs) → [`render`] (tiles over threads, Whitted integrator) → pixels → writer plugins
//! ([`output`]). Programs use it through [`api`] (its module documentation is the user guide):
//! a [`api::Context`] (plugins, a thread pool), an [`api::Scene`] kept between renders (which
//! holds the built [`Scene`]) and an [`api::Renderer`].
//!
//! ```no_run
//! use luxon::api::{write_image, Color, Context, Plane, Renderer, Scene, Target};
//! let ctx = Context::new(Default::default())?;
//! let renderer = Renderer::new(&ctx, Default::default())?;
//! let mut scene = Scene::load(&ctx, "scenes/spheres.ron".as_ref())?;
//! let (w, h) = (480, 320);
//! let mut rgba = vec![[0f32; 4]; w * h];
//! let color = Color::Rgba32fLinear(Plane::new(&mut rgba, w));
//! let target = Target { width: w as u32, height: h as u32, color, depth: None };
//! renderer.render(&mut scene, target)?;
//! write_image(&ctx, "spheres.png".as_ref(), rgba.as_flattened(), w as u32, h as u32)?;
//! # Ok::<(), luxon::Error>(())
//! ```
//!
//! ## Layers
//!
//! The modules form layers (listed from the top down); a module imports only modules of lower
//! layers, never one of its own layer or above, so nothing runs in a circle (`tests/layers.rs`
//! keeps this). A new module goes in the lowest layer that has everything it needs.
//!
//! | layer | modules | what they hold |
//! |---|---|---|
//! | cli | `main.rs`, `cli` (the binary) | the command line |
//! | api | [`api`] | the Rust API: a context (plugins, thread pool), retained scenes, renderers |
//! | output | [`output`], [`sweep`] | writer plugins, outputs committed all or nothing, asynchronous PPM output; accuracy sweeps |
//! | render | [`render`] | a whole image in this process, into a framebuffer or the caller's buffers |
//! | schedule | [`schedule`] | which thread or MPI rank renders which pixels |
//! | integrator | [`integrator`] | a pixel's value: Whitted shading, volume marching, the pixel kernel |
//! | cache | [`cache`] | the scene's built geometry on disk |
//! | scene | [`scene`] | the built scene and its build stages; hit, surface and shadow queries |
//! | plugin | [`plugin`] | the plugin host: loading, calls, the sinks that fill geometry and volumes |
//! | volume_render | [`volume_render`] | volumes prepared for ray casting (transfer functions, skip cells) |
//! | volume | [`volume`] | sparse voxel grids |
//! | geometry | [`geometry`] | primitives and their sets, each with its BVH |
//! | bvh | [`bvh`] | the wide BVH over boxes |
//! | camera | [`camera`], [`adaptive`] | camera rays; where a pixel's samples go |
//! | image | [`framebuffer`], [`ppm`], [`metrics`], [`files`] | pixels, spans and chunks, the caller's buffers (targets); PPM bytes; image error measures; files written whole, claims between processes |
//! | ray | [`ray`] | rays and robust ray spawning |
//! | memory | [`budget`] | the memory budget: what the input may make Luxon allocate, the machine's limits |
//! | motion | [`motion`] | keyed values at any time: interpolation, rotations, object transforms |
//! | arrays | [`arrays`] | arrays read in place or copied: strided views, shared vectors, generations |
//! | math | [`math`], [`sampler`], [`error`] | vectors and rounding bounds; sample hashing; the error type and the log sink |

// Unsafe code only in the modules that allow it by name below (each block says why it is sound).
#![deny(unsafe_code)]

pub mod adaptive;
pub mod api;
// Reads of memory shared with the caller (strided, unaligned, or handed over from C).
#[allow(unsafe_code)]
pub mod arrays;
// The process's resource limits (getrlimit, sysconf).
#[allow(unsafe_code)]
pub mod budget;
pub mod bvh;
// The memory-mapped cache file.
#[allow(unsafe_code)]
pub mod cache;
// SSE lane arithmetic: a pinhole camera's rays four at a time.
#[allow(unsafe_code)]
pub mod camera;
pub mod error;
// Locks on temporary output files (flock) and whether their process lives (kill 0).
#[allow(unsafe_code)]
pub mod files;
pub mod framebuffer;
pub mod geometry;
pub mod integrator;
pub mod math;
pub mod metrics;
pub mod motion;
pub mod output;
// Every call across the plugin ABI.
#[allow(unsafe_code)]
pub mod plugin;
pub mod ppm;
// SSE2 lane arithmetic on float bits (the offset of a spawned ray's origin).
#[allow(unsafe_code)]
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
