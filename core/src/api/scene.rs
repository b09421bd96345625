//! [`Scene`]: a retained scene, its description kept and its built form redone at each commit
//! only as far as the changes since the last one need.

use super::{Context, Renderer};
use crate::budget::Budget;
use crate::error::Error;
use crate::math::DVec3;
use crate::plugin::Registry;
use crate::scene::{Prebuilt, Scene as Built};
use luxon_formats::{fragment, BackgroundDesc, CameraDesc, RenderDesc, SceneDesc};
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What a commit did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CommitReport {
    /// Geometry builds (all of the scene's objects stored and their BVHs built): 1 when the
    /// commit built the scene, 0 when it only took new settings, camera or background.
    pub rebuilt: u32,
    /// Time spent building BVHs.
    pub bvh_time: Duration,
    /// Time the whole commit took.
    pub commit_time: Duration,
}

/// A scene kept between renders: its description (what it was loaded or built from, with the
/// changes made since) and its built form, redone by [`Scene::commit`] (which every render
/// runs) only where the changes need it. Changing the camera, the background or the render
/// settings that touch no geometry costs microseconds; changing render space's origin, or the
/// settings the build reads (`transparency`, `light_scale`, `volume_step`, `memory`,
/// `texture_cache`), builds the scene again.
///
/// Render space's origin (the world point coordinates are stored relative to, in f32) is fixed
/// at the first commit: [`Scene::set_origin`]'s point when given, else the camera's position
/// then. A camera that moves later keeps it, so its images are those of a scene built with that
/// origin. Call `set_origin` when the camera leaves the data far behind (by some 10⁴ times the
/// data's size): precision near the camera follows the distance to the origin.
///
/// A render that fails because a plugin panicked (or a bug in Luxon) leaves the built form
/// unusable; it is dropped, and the next commit builds the scene again from its description
/// (plugin objects created anew). A scene whose imported geometry was consumed at load
/// ([`Scene::from_desc_frozen`], [`Scene::from_prebuilt`]) cannot be built again and says so.
pub struct Scene {
    // Dropped before the registry whose plugins its objects belong to.
    built: Option<Built>,
    desc: SceneDesc,
    registry: Arc<Registry>,
    /// The budget of the first build (a caller's, [`Scene::set_budget`]); later builds get a
    /// fresh one from the render settings (a build's charges stay with its budget).
    budget: Option<Arc<Budget>>,
    /// A geometry cache's geometry, taken by the first build.
    prebuilt: Option<Prebuilt>,
    /// The first build takes the imported geometry out of the description.
    frozen: bool,
    /// Why the scene cannot be built again, once its imported geometry is gone.
    consumed: Option<&'static str>,
    origin: Option<DVec3>,
    /// The image size of the next render.
    size: (u32, u32),
    /// The build is out of date (origin, budget or a setting the build reads changed; a fault).
    stale: bool,
    /// An animated scene's frame to put it at, at the next commit.
    frame: Option<u32>,
}

const FROZEN: &str = "this scene's imported geometry was consumed at load \
    (Scene::from_desc_frozen) and it cannot be built again; load it with Scene::load to change it";
const PREBUILT: &str = "this scene's geometry came from a geometry cache and was consumed \
    (Scene::from_prebuilt); it cannot be built again; load it with Scene::load to change it";

impl Scene {
    /// Loads a scene file of any format Luxon reads (on the context's pool). The loader's
    /// warnings go to the log sink ([`crate::error::set_log`]).
    pub fn load(ctx: &Context, path: &Path) -> Result<Scene, Error> {
        let desc = ctx.install(|| luxon_formats::load(path))?;
        for w in &desc.warnings {
            crate::error::log(crate::error::Level::Warning, &w.to_string());
        }
        Scene::from_desc(ctx, desc)
    }

    /// A scene from its description; imported geometry stays in it (so the scene can be built
    /// again after a change).
    pub fn from_desc(ctx: &Context, desc: SceneDesc) -> Result<Scene, Error> {
        Ok(Scene {
            built: None,
            size: (desc.render.width, desc.render.height),
            desc,
            registry: ctx.registry.clone(),
            budget: None,
            prebuilt: None,
            frozen: false,
            consumed: None,
            origin: None,
            stale: true,
            frame: None,
        })
    }

    /// A scene whose imported geometry (NFF, OBJ...) the first commit takes out of the
    /// description, freeing each group once it is stored: a large import is never held twice.
    /// Such a scene cannot be built again (changes that need a build are refused).
    pub fn from_desc_frozen(ctx: &Context, desc: SceneDesc) -> Result<Scene, Error> {
        let mut s = Scene::from_desc(ctx, desc)?;
        s.frozen = true;
        Ok(s)
    }

    /// A scene whose native geometry and BVHs come from a geometry cache (`desc` holds the rest
    /// of the scene and no imported geometry). It cannot be built again.
    pub fn from_prebuilt(
        ctx: &Context,
        desc: SceneDesc,
        geometry: Prebuilt,
    ) -> Result<Scene, Error> {
        let mut s = Scene::from_desc(ctx, desc)?;
        s.prebuilt = Some(geometry);
        Ok(s)
    }

    /// The description as it is now (imported geometry gone once consumed).
    pub fn desc(&self) -> &SceneDesc {
        &self.desc
    }

    /// The built scene of the last commit, if any: for its statistics, settings and queries.
    pub fn built(&self) -> Option<&Built> {
        self.built.as_ref()
    }

    /// The memory budget the next build counts against (by default the render settings' own,
    /// [`Budget::for_render`]). Builds the scene again.
    pub fn set_budget(&mut self, budget: Arc<Budget>) {
        self.budget = Some(budget);
        self.stale = true;
    }

    /// The camera (checked by the scene files' rules). An animated scene's camera is its
    /// animation's.
    pub fn set_camera(&mut self, camera: CameraDesc) -> Result<(), Error> {
        self.camera_not_animated()?;
        fragment::check_camera(&camera).map_err(|m| Error::Api(format!("camera: {m}")))?;
        self.desc.camera.value = camera;
        Ok(())
    }

    /// The camera from RON text, e.g. `(position: (0, 0, 5), look_at: (0, 0, 0))`; errors
    /// point into the text as `<camera>:line:col`.
    pub fn set_camera_ron(&mut self, text: &str) -> Result<(), Error> {
        self.camera_not_animated()?;
        let camera = fragment::camera(text)?;
        self.set_camera(camera)
    }

    fn camera_not_animated(&self) -> Result<(), Error> {
        match self.desc.animation {
            Some(_) => Err(Error::Api(
                "this scene is animated: its frame places the camera (Scene::set_frame)".into(),
            )),
            None => Ok(()),
        }
    }

    /// The render settings (checked by the scene files' rules). The image size is the
    /// target's, and `outputs` and `parallel` are not an embedded scene's: those of `render`
    /// are ignored.
    pub fn set_render(&mut self, render: RenderDesc) -> Result<(), Error> {
        fragment::check_render_settings(&render)
            .map_err(|m| Error::Api(format!("render settings: {m}")))?;
        let old = &self.desc.render;
        let rebuild = old.transparency != render.transparency
            || old.volume_step != render.volume_step
            || old.light_scale != render.light_scale
            || old.memory != render.memory
            || old.texture_cache != render.texture_cache;
        let r = &mut self.desc.render;
        *r = RenderDesc {
            width: r.width,
            height: r.height,
            outputs: std::mem::take(&mut r.outputs),
            parallel: r.parallel.clone(),
            ..render
        };
        self.stale |= rebuild;
        Ok(())
    }

    /// The render settings from RON text, e.g. `(samples: 4, max_depth: 8)` (see
    /// [`Scene::set_render`]); errors point into the text as `<render_settings>:line:col`.
    pub fn set_render_ron(&mut self, text: &str) -> Result<(), Error> {
        let render = fragment::render_settings(text)?;
        self.set_render(render)
    }

    /// The colour of rays that hit nothing (linear RGB, each finite and ≥ 0).
    pub fn set_background(&mut self, rgb: [f64; 3]) -> Result<(), Error> {
        if rgb.iter().any(|c| !c.is_finite() || *c < 0.0) {
            return Err(Error::Api(format!(
                "background {rgb:?}: expected finite components ≥ 0"
            )));
        }
        self.desc.background = BackgroundDesc::Color(rgb);
        Ok(())
    }

    /// Render space's origin in world coordinates; `None`: the camera's position at the next
    /// build. Fixed at the first commit; changing it later builds the scene again.
    pub fn set_origin(&mut self, world: Option<[f64; 3]>) -> Result<(), Error> {
        if let Some(p) = world {
            if p.iter().any(|c| !c.is_finite()) {
                return Err(Error::Api(format!(
                    "origin {p:?}: expected finite coordinates"
                )));
            }
        }
        let origin = world.map(DVec3::from);
        if self.built.is_some() && origin != self.origin {
            self.stale = true;
        }
        self.origin = origin;
        Ok(())
    }

    /// Puts an animated scene at frame `k` at the next commit (camera, lights, keyed objects
    /// and colours); the commit fails, leaving the scene as it was, if the frame cannot be set.
    pub fn set_frame(&mut self, k: u32) -> Result<(), Error> {
        if self.desc.animation.is_none() {
            return Err(Error::Api(format!(
                "frame {k}: {} has no `animation:`",
                self.desc.source.display()
            )));
        }
        self.frame = Some(k);
        Ok(())
    }

    /// The image size of the next commit (a render sets it to its target's).
    pub(super) fn set_size(&mut self, width: u32, height: u32) {
        self.size = (width, height);
    }

    /// Brings the built scene up to date with the description, on `on`'s pool: a build when
    /// there is none yet or it is stale, else only the settings, camera and background.
    pub fn commit(&mut self, on: &Renderer) -> Result<CommitReport, Error> {
        let t0 = Instant::now();
        let mut report = on.pool.install(|| self.commit_here())?;
        report.commit_time = t0.elapsed();
        Ok(report)
    }

    fn commit_here(&mut self) -> Result<CommitReport, Error> {
        let mut report = CommitReport::default();
        if self.built.is_none() || self.stale {
            if let Some(why) = self.consumed {
                return Err(Error::Api(why.into()));
            }
            // The old build goes first: two are never held at once.
            self.built = None;
            let budget = self
                .budget
                .take()
                .unwrap_or_else(|| Arc::new(Budget::for_render(&self.desc.render, None, 1)));
            let prebuilt = self.prebuilt.take();
            if prebuilt.is_some() {
                self.consumed = Some(PREBUILT);
            } else if self.frozen && !self.desc.inline.is_empty() {
                self.consumed = Some(FROZEN);
            }
            let built = Built::build_retained(
                &mut self.desc,
                self.frozen,
                prebuilt,
                self.origin,
                &self.registry,
                budget,
            )?;
            self.origin = Some(built.world_offset);
            report.rebuilt = 1;
            report.bvh_time = built.bvh_time;
            self.built = Some(built);
            self.stale = false;
        }
        let Some(built) = self.built.as_mut() else {
            return Err(Error::Api("the scene is not built".into()));
        };
        let (w, h) = self.size;
        built.update_view(&self.desc, w, h)?;
        if let Some(k) = self.frame.take() {
            built.set_frame(k)?;
        }
        Ok(report)
    }

    /// The built scene, for a render right after a commit.
    pub(super) fn committed(&self) -> Result<&Built, Error> {
        self.built
            .as_ref()
            .ok_or_else(|| Error::Api("the scene is not built".into()))
    }

    /// After a render failed: a raised fault (a plugin's or Luxon's panic) makes the built
    /// scene unusable, so it is dropped and the next commit builds it again.
    pub(super) fn after_failure(&mut self) {
        if self
            .built
            .as_ref()
            .is_some_and(|b| b.customs.fault.is_raised())
        {
            self.built = None;
            self.stale = true;
        }
    }
}
