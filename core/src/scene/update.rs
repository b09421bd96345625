//! What a retained scene ([`crate::api::Scene`]) changes in a built [`Scene`] without building
//! it again: the render settings that touch no geometry, the image size, the background and the
//! camera. The rest of a change is a build (`build`).

use super::build::{self, settings};
use super::Scene;
use crate::error::Error;
use luxon_formats::SceneDesc;

impl Scene {
    /// Takes `desc`'s render settings (at `width`×`height`, the caller's image), outputs,
    /// background and, unless the scene is animated (its frame places the camera), camera.
    /// `desc` must be the description the scene was built from, changed only in what this sets
    /// (the rest is the build's: materials follow `transparency`, lights `light_scale`, volumes
    /// `volume_step`). An animated scene keeps its frame, and its camera is placed again when
    /// the size changes.
    pub(crate) fn update_view(
        &mut self,
        desc: &SceneDesc,
        width: u32,
        height: u32,
    ) -> Result<(), Error> {
        let r = &desc.render;
        let resized = (self.settings.width, self.settings.height) != (width, height);
        let frame = self.settings.frame;
        self.settings = settings(r);
        self.settings.width = width;
        self.settings.height = height;
        self.outputs = r.outputs.clone();
        self.background = build::background(&desc.background);
        self.sky = build::sky(&desc.background, self.world_offset);
        self.features.antialiasing = r.samples > 1 || r.adaptive.is_some();
        self.features.tachyon_lights =
            (r.tachyon.light_threshold || r.tachyon.plain_highlights) && !self.lights.is_empty();
        match &self.animation {
            None => self.set_camera(&desc.camera.value),
            Some(_) => {
                self.settings.frame = frame;
                if resized {
                    self.set_frame(frame)?;
                }
            }
        }
        Ok(())
    }
}
