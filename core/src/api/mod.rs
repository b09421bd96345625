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
//!   file or description, or an empty scene ([`Scene::new`]), changed in place
//!   ([`Scene::set_camera`], [`Scene::set_render`], [`Scene::set_background`],
//!   [`Scene::set_origin`]; lights, materials, fog, ambient occlusion and plugin objects by
//!   id, below) and brought up to date by [`Scene::commit`], which redoes only what the
//!   changes need: a new camera, sample count, light or material costs microseconds, no BVH
//!   is built again ([`CommitReport`] says what was done).
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
//!
//! ## Editing by id
//!
//! Lights and objects get ids when they are added ([`Scene::add_light`],
//! [`Scene::add_plugin_object`]; a loaded scene's are [`Scene::lights`] and
//! [`Scene::objects`], in file order; volumes read by plugins too, [`Scene::add_plugin_volume`]);
//! materials, textures and clip groups are named ([`Scene::material`], [`Scene::set_material`],
//! [`Scene::set_texture`], [`Scene::set_clip_group`], [`Scene::clip_group`]) and never
//! removed. Every typed value is checked by the scene files' rules, and each setter has a
//! `_ron` form whose errors point into its text (`<light>:1:7: unknown field ...`). A removed
//! part's id is refused, as is another scene's. Lights, materials, fog and ambient occlusion
//! change without touching the geometry; adding or removing objects or plugin volumes, and
//! new textures or clip groups, build the scene again at the next commit, once: plugin
//! objects are for what does not change every step.
//!
//! The BVHs of array objects and the bricks of volumes from arrays are charged to the memory
//! budget ([`Scene::set_budget`], else the render settings' `memory`) before they are made: a
//! request beyond it fails the commit with a message naming it, not an abort. [`Scene::to_ron`] writes the
//! scene as a scene file (for a bug report, or to render it with the command line).
//!
//! ```
//! use luxon::api::{Context, ContextOptions, Renderer, RendererOptions, Scene};
//! # let dir = std::env::temp_dir().join(format!("luxon-api-edit-{}", std::process::id()));
//! # std::fs::create_dir_all(&dir)?;
//! # let path = dir.join("ball.nff");
//! # std::fs::write(&path, "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\n\
//! #     resolution 64 48\nb 0.2 0.3 0.6\nl 4 -4 6\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\n")?;
//! let ctx = Context::new(ContextOptions { threads: 2, ..Default::default() })?;
//! let renderer = Renderer::new(&ctx, RendererOptions::default())?;
//! let mut scene = Scene::load(&ctx, &path)?;
//! assert_eq!(scene.commit(&renderer)?.rebuilt, 1);
//!
//! // The file's light moves, another is added, and fog rolls in: nothing is built again.
//! let lamp = scene.lights()[0];
//! scene.set_light_ron(lamp, "Point(position: (-4, -4, 6), intensity: 0.8)")?;
//! let fill = scene.add_light_ron("Directional(direction: (0, 1, -1), intensity: 0.3)")?;
//! scene.set_fog_ron("(mode: Exp(density: 0.05), color: (0.2, 0.3, 0.6))")?;
//! let report = scene.commit(&renderer)?;
//! assert_eq!((report.rebuilt, report.shading), (0, true));
//!
//! // A removed light's id is refused from then on.
//! scene.remove_light(fill)?;
//! let e = scene.remove_light(fill).unwrap_err();
//! assert_eq!(e.to_string(), "light 1 was removed from this scene");
//! // Text is checked as in a scene file, and errors point into it.
//! let e = scene.add_light_ron("Point(positon: (0, 0, 5))").unwrap_err();
//! assert!(e.to_string().starts_with("<light>:1:7: unknown field `positon`"));
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A scene made in code, with the primitive plugins of `luxon-shapes`:
//!
//! ```no_run
//! # use luxon::api::{Context, Renderer, Scene};
//! # let ctx = Context::new(Default::default())?;
//! # let renderer = Renderer::new(&ctx, Default::default())?;
//! let mut scene = Scene::new(&ctx);
//! scene.set_camera_ron("(position: (0, 1, -5), look_at: (0, 0.5, 0))")?;
//! scene.add_light_ron("Point(position: (-4, 6, -5))")?;
//! let red = scene.set_material_ron("red", "(color: (0.8, 0.1, 0.1), specular: 0.5)")?;
//! let ball = scene.add_plugin_object("sphere", "(center: (0, 0.8, 0), radius: 0.8)", Some(red), None)?;
//! scene.add_plugin_object("plane", "(point: (0, 0, 0), normal: (0, 1, 0))", None, None)?;
//! assert_eq!(scene.commit(&renderer)?.rebuilt, 1);
//! // A material changes in place; removing the ball builds the scene again.
//! scene.set_material_ron("red", "(color: (0.1, 0.3, 0.9))")?;
//! assert_eq!(scene.commit(&renderer)?.rebuilt, 0);
//! scene.remove(ball)?;
//! assert_eq!(scene.commit(&renderer)?.rebuilt, 1);
//! std::fs::write("dump.ron", scene.to_ron()?)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Arrays read in place
//!
//! A simulation hands its arrays over once ([`crate::arrays`]: a shared vector, a field of a
//! vector of structs, Luxon's copy, or memory of its own from C) and Luxon reads them where
//! they are at every commit and render, holding writers off meanwhile. After the data moved,
//! a commit refits the object's BVH; when the count changed, or the refitted tree became
//! more than [`crate::bvh::REBUILD_RATIO`] times as costly as a fresh one, it builds it again
//! ([`CommitReport`] counts both). Array objects are tested after the scene's other geometry;
//! [`Scene::to_ron`] refuses a scene that has them.
//!
//! Volumes come from arrays too ([`VolumeGrid`]: f32, f64, u8 or u16 values in any strided
//! layout, placed by origin and spacing as the `raw` reader places its voxels), drawn as a
//! scene file's volume `render:` says ([`Scene::add_volume_ron`]). They are copied into
//! bricks at the commit that first sees them and again after their values changed
//! ([`CommitReport::volumes_read`]), never read in place: the array is free between commits.
//!
//! ```
//! use luxon::api::{Context, ContextOptions, Radius, Renderer, RendererOptions, Scene, Spheres};
//! use luxon::arrays::{Array, SharedVec};
//! let ctx = Context::new(ContextOptions { threads: 2, ..Default::default() })?;
//! let renderer = Renderer::new(&ctx, RendererOptions::default())?;
//! let mut scene = Scene::new(&ctx);
//! scene.set_camera_ron("(position: (0, 0, 8), look_at: (0, 0, 0))")?;
//! scene.add_light_ron("Point(position: (5, 5, 10))")?;
//!
//! // The simulation's particles, shared with Luxon: positions read in place.
//! #[derive(Clone, Copy)]
//! struct Particle { pos: [f64; 3], vel: [f64; 3] }
//! let particles = SharedVec::new(
//!     (0..100)
//!         .map(|i| Particle { pos: [(i % 10) as f64 - 4.5, (i / 10) as f64 - 4.5, 0.0], vel: [0.0, 0.0, 0.1] })
//!         .collect::<Vec<_>>(),
//! );
//! let centers = Array::field(&particles, |p: &Particle| &p.pos)?;
//! scene.add_spheres(Spheres::new(centers, Radius::Const(0.3)))?;
//! assert_eq!(scene.commit(&renderer)?.rebuilt, 2); // the scene, and the spheres' BVH
//!
//! // A step of the simulation: the guard marks the array modified when it drops.
//! for p in particles.write().iter_mut() {
//!     for k in 0..3 {
//!         p.pos[k] += p.vel[k];
//!     }
//! }
//! let report = scene.commit(&renderer)?;
//! assert_eq!((report.refitted, report.rebuilt), (1, 0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## MPI owned by the caller
//!
//! With the `mpi` feature, a simulation that runs under MPI gives a renderer its communicator
//! (`Renderer::with_communicator`, `Renderer::set_communicator`, or a Fortran handle with
//! `Renderer::set_fortran_communicator`). Its renders are then image-parallel over the ranks of
//! that communicator with the scene's decomposition: every rank holds the whole scene
//! (replicated data: gather the simulation's data first, e.g. with `MPI_Allgatherv`), calls
//! `render` with a target of the same size, and renders its share; rank 0 of the communicator
//! receives the whole image, bit for bit the image of one process (other ranks' targets are
//! not written: give them [`Color::None`]). The rules:
//!
//! - **The caller owns MPI.** Luxon never calls `MPI_Init` or `MPI_Finalize`, never uses
//!   `MPI_COMM_WORLD` on its own, never aborts the job and installs no panic hook. It works on
//!   a duplicate of the communicator (`MPI_Comm_dup`), so its messages never meet the caller's;
//!   setting the communicator and each render are collective over it (every rank calls them,
//!   in the same order). Other ranks of the job may meanwhile do anything, e.g. collectives on
//!   a communicator of their own.
//! - **Release renderers with a communicator before `MPI_Finalize`** (dropping one frees its
//!   duplicate). Setting a communicator before `MPI_Init_thread` or after `MPI_Finalize` is an
//!   [`Error::Mpi`].
//! - **Thread levels.** Only the thread that calls Luxon makes its MPI calls (render threads
//!   never do). With `MPI_THREAD_SERIALIZED` or `MPI_THREAD_MULTIPLE` any thread may call
//!   (with `SERIALIZED`, none of the caller's MPI calls may run at the same time); with
//!   `MPI_THREAD_FUNNELED` (or `SINGLE`) only the thread that initialised MPI, else the call
//!   returns `Error::Mpi` on that rank without any MPI call, and the other ranks wait for it.
//! - **Errors are values on every rank.** A failure on one rank (a scene that cannot be
//!   built, a plugin's error, a panic in a render thread) stops its part; the ranks finish the
//!   render's messages and agree, and every rank returns the same error naming the first
//!   failing rank (`rank 1: …`); a cancel ([`Cancel`]) on any rank makes every rank return
//!   [`Error::Cancelled`]. The renderer can render again.
//! - **What cannot be caught:** a rank killed by a signal (or one that never calls `render`)
//!   leaves the others waiting in the render, as with any collective MPI call.
//! - Progress is reported on rank 0 only, for every rank's pixels; `render_chunks` refuses a
//!   renderer with a communicator. A renderer without a communicator renders alone on each
//!   rank: the library never reads the launcher's environment (`OMPI_COMM_WORLD_SIZE`…).

mod context;
pub mod ids;
mod image;
mod objects;
mod renderer;
mod scene;
mod volumes;

pub use crate::error::Error;
pub use crate::framebuffer::{Color, Plane, Target};
pub use crate::render::{Progress, RenderStats};
pub use context::{Context, ContextOptions};
pub use ids::{ClipId, LightId, MaterialId, ObjectId};
pub use image::write_image;
pub use objects::{Cylinders, Mesh, Radius, Spheres, VolumeGrid};
pub use renderer::{Cancel, Renderer, RendererOptions};
pub use scene::{CommitReport, Scene};
