//! What a retained scene ([`crate::api::Scene`]) changes in a built [`Scene`] without building
//! it again: the render settings that touch no geometry, the image size, the background, the
//! camera, the lights, the materials (while the geometry's material numbers stay valid), fog
//! and ambient occlusion. The rest of a change is a build (`build`). Each runs the build's own
//! stage on the description's part, so the scene is what a build would make of it.

use super::build::{self, features, settings, Build};
use super::{Casters, Few, Scene};
use crate::error::Error;
use crate::geometry::material_of;
use crate::geometry::objects::Objects;
use crate::volume::Volume;
use crate::volume_render::{RenderVolume, MAX_RENDERED_VOLUMES};
use luxon_formats::{RenderDesc, SceneDesc, Spanned, VolumeRenderDesc};

/// A volume a retained scene read from an array, with how it is drawn (`None`: not drawn)
/// and the number of its clip group (0: none).
pub(crate) struct ArrayVolume<'a> {
    pub volume: Volume,
    pub look: Option<&'a VolumeRenderDesc>,
    pub clip: u32,
    /// `object 3 (volume)`, for messages.
    pub label: &'a str,
}

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
        // The shutter is the animation's (the build's), not a render setting.
        let shutter = self.settings.shutter;
        self.settings = settings(r);
        self.settings.shutter = shutter;
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

    /// Takes `desc`'s lights, in this build's render space. Not for an animated scene (its
    /// animation holds the lights it moves).
    pub(crate) fn update_lights(&mut self, desc: &SceneDesc) {
        let r = &desc.render;
        self.lights = Build::lights_from(&desc.lights, self.world_offset, r.light_scale);
        self.update_features(r);
    }

    /// Takes `desc`'s fog and ambient occlusion.
    pub(crate) fn update_effects(&mut self, desc: &SceneDesc) {
        (self.fog, self.ao) = Build::effects(&desc.fog, &desc.ambient_occlusion);
        self.update_features(&desc.render);
    }

    /// Takes `desc`'s materials (`shadowless_groups`: the build's, see `shadowless_groups`) if
    /// the geometry's material numbers stay valid: the same names, or names added while no
    /// material has a copy that casts no shadow (copies come after the names, so new names
    /// would move them). `Ok(false)`: they would not; the scene must be built again. Not for an
    /// animated scene (its animation holds the colours it keys).
    pub(crate) fn update_materials(
        &mut self,
        desc: &SceneDesc,
        shadowless_groups: &[Option<Spanned<String>>],
    ) -> Result<bool, Error> {
        let p = Build::materials(desc, &self.texture_names, &self.textures, shadowless_groups)?;
        let copies = self.materials.len() - self.material_names.len();
        let appended = copies == 0
            && p.materials.len() == p.names.len()
            && p.names.starts_with(&self.material_names);
        if p.names != self.material_names && !appended {
            return Ok(false);
        }
        // New materials are used by nothing yet.
        self.used_materials.resize(p.materials.len(), false);
        self.materials = p.materials;
        self.material_names = p.names;
        self.update_features(&desc.render);
        Ok(true)
    }

    /// Takes a retained scene's array objects (their materials must be this scene's) and
    /// finds the features again with their materials used.
    pub(crate) fn set_objects(&mut self, objects: Objects, r: &RenderDesc) {
        self.objects = objects;
        self.update_features(r);
    }

    /// Takes out the volumes a retained scene read from arrays (in the order it gave them),
    /// with their render volumes.
    pub(crate) fn take_array_volumes(&mut self) -> Vec<Volume> {
        let first = self.volumes.len() - self.array_volumes;
        self.render_volumes.retain(|rv| rv.volume < first);
        self.array_volumes = 0;
        self.volumes.split_off(first)
    }

    /// Puts a retained scene's volumes read from arrays after the scene's own (which
    /// [`Scene::take_array_volumes`] must have left alone) and prepares those drawn for ray
    /// casting in this build's render space, as the build does for a plugin's volume.
    pub(crate) fn set_array_volumes(
        &mut self,
        volumes: Vec<ArrayVolume<'_>>,
        r: &RenderDesc,
    ) -> Result<(), Error> {
        debug_assert_eq!(self.array_volumes, 0);
        let mut drawn = Vec::new();
        let first = self.volumes.len();
        for (k, v) in volumes.iter().enumerate() {
            let Some(look) = v.look else { continue };
            if self.render_volumes.len() + drawn.len() == MAX_RENDERED_VOLUMES {
                return Err(Error::Api(format!(
                    "{}: more than {MAX_RENDERED_VOLUMES} volumes are drawn; at most \
                     {MAX_RENDERED_VOLUMES} may have render settings",
                    v.label
                )));
            }
            let rv = RenderVolume::new(
                look,
                &v.volume,
                first + k,
                r.volume_step,
                self.world_offset,
                v.clip,
            )
            .map_err(|m| Error::Api(format!("{}: {m}", v.label)))?;
            drawn.push(rv);
        }
        self.array_volumes = volumes.len();
        self.volumes.extend(volumes.into_iter().map(|v| v.volume));
        self.render_volumes.extend(drawn);
        self.update_features(r);
        Ok(())
    }

    /// The features, as the build's last stage finds them (with the array objects' materials
    /// and geometry).
    fn update_features(&mut self, r: &RenderDesc) {
        let mut used = self.used_materials.clone();
        for o in self.objects.list() {
            if let Some(u) = used.get_mut(material_of(o.material()) as usize) {
                *u = true;
            }
        }
        self.features = features(
            r,
            &self.materials,
            &used,
            self.has_geometry || !self.objects.is_empty(),
            &self.lights,
            &self.fog,
            &self.ao,
            &self.render_volumes,
        );
        // Set by the build from the animation, which `features` does not see.
        self.features.motion_blur = self.settings.shutter.is_some();
        self.casters = Casters::of(self);
        self.more_kinds = self.has_more_kinds();
        self.few = Few::of(self);
    }
}
