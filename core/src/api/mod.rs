//! # The Rust API: scenes kept between renders
//!
//! A program that renders from its own data (a simulation showing its state every few steps,
//! an application with a viewer) keeps a scene and renders it again and again. Three types do
//! it:
//!
//! - [`Context`]: the plugins found on the plugin path, and a thread pool of the size the
//!   program asks for (`threads: 0`: every CPU this process may use). Nothing Luxon does runs
//!   on rayon's global pool, and the pool's threads sleep between renders.
//! - [`Scene`] (this module's; [`crate::scene::Scene`] is the built form it keeps): a scene
//!   file or description, changed in place ([`Scene::set_camera`], [`Scene::set_render`],
//!   [`Scene::set_background`], [`Scene::set_origin`]) and brought up to date by
//!   [`Scene::commit`], which redoes only what the changes need: a new camera or sample count
//!   costs microseconds, no BVH is built again ([`CommitReport`] says what was done).
//! - [`Renderer`]: renders a scene on its context's pool or on one of its own, into the
//!   caller's memory ([`Target`]: RGBA8 sRGB, RGBA f32 linear, depth; any row stride). Every
//!   render commits the scene first. [`Renderer::cancel_handle`] stops a render from another
//!   thread; the next render is complete.
//!
//! [`write_image`] writes an RGBA f32 image with the writer plugins (PNG, EXR, PPM...), whole
//! or not at all. Errors are values ([`Error`]); the library prints nothing (its log lines go
//! to the sink [`crate::error::set_log`] installs).
//!
//! ```
//! use luxon::api::{Context, ContextOptions, Renderer, RendererOptions, Scene};
//! use luxon::framebuffer::{Color, Plane, Target};
//! # let dir = std::env::temp_dir().join(format!("luxon-api-guide-{}", std::process::id()));
//! # std::fs::create_dir_all(&dir)?;
//! # let path = dir.join("ball.nff");
//! # std::fs::write(&path, "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\n\
//! #     resolution 64 48\nb 0.2 0.3 0.6\nl 4 -4 6\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\n")?;
//! // Two threads for everything Luxon does; plugins from the default places.
//! let ctx = Context::new(ContextOptions { threads: 2, ..Default::default() })?;
//! let renderer = Renderer::new(&ctx, RendererOptions::default())?;
//! let mut scene = Scene::load(&ctx, &path)?;
//!
//! // The program's own RGBA8 buffer: rows of `w` pixels, sRGB, as a PNG holds them.
//! fn rgba8(pixels: &mut [[u8; 4]], w: usize, h: usize) -> Target<'_> {
//!     let color = Color::Rgba8Srgb(Plane::new(pixels, w));
//!     Target { width: w as u32, height: h as u32, color, depth: None }
//! }
//! let (w, h) = (64, 48);
//! let mut pixels = vec![[0u8; 4]; w * h];
//! renderer.render(&mut scene, rgba8(&mut pixels, w, h))?;
//! let first = pixels.clone();
//!
//! // Move the camera and render again: the BVHs are kept.
//! scene.set_camera_ron("(position: (3, -5, 2), look_at: (0, 0, 1), up: (0, 0, 1))")?;
//! let report = scene.commit(&renderer)?;
//! assert_eq!(report.rebuilt, 0);
//! renderer.render(&mut scene, rgba8(&mut pixels, w, h))?;
//! assert_ne!(pixels, first);
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The built scene's render-space origin is fixed at the first commit (see [`Scene`]), and a
//! render that fails because a plugin panicked makes the next commit build the scene again.

mod context;
mod image;
mod renderer;
mod scene;

pub use crate::error::Error;
pub use crate::framebuffer::{Color, Plane, Target};
pub use crate::render::{Progress, RenderStats};
pub use context::{Context, ContextOptions};
pub use image::write_image;
pub use renderer::{Cancel, Renderer, RendererOptions};
pub use scene::{CommitReport, Scene};
