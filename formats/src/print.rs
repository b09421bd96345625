//! Parts of a scene description printed as RON fragments in the scene format's syntax: what
//! a scene file writes after `camera:`, inside `lights: [...]`, after a material's name, and so
//! on. [`crate::fragment`] reads them back; numbers are printed in Rust's shortest form
//! (`{:?}`), which reads back to the same bits, so `fragment::camera(&print::camera(&c))`
//! gives `c` again.
//!
//! The text is `luxon convert`'s (`ron_text`): a scene and its fragments are written by the
//! same code.

use std::path::Path;

use crate::desc::{
    AoDesc, CameraDesc, ClipPlaneDesc, FogDesc, LightDesc, MaterialDesc, RenderDesc, SceneDesc,
    VolumeRenderDesc,
};
use crate::ron_text;

/// A whole scene, as `luxon convert` writes it ([`crate::to_ron`]) to be read from directory
/// `base`: a retained scene's dump (`luxon::api::Scene::to_ron`).
pub fn scene(desc: &SceneDesc, base: &Path) -> Result<String, String> {
    ron_text::to_ron(desc, base)
}

/// `(position: (..), look_at: (..), up: (..), fov: ..)`, on one line.
pub fn camera(c: &CameraDesc) -> String {
    format!("({})", ron_text::camera_fields(c).join(", "))
}

/// `Point(position: (..), ...)`, `Spot(...)`, ... (without a `name`: that belongs to the scene).
pub fn light(l: &LightDesc) -> String {
    ron_text::light(l)
}

/// `(color: (..), diffuse: .., ...)`; texture names are printed as written (the scene that
/// holds the material defines them).
pub fn material(m: &MaterialDesc) -> String {
    ron_text::material(m)
}

/// `(mode: Exp(density: .., start: ..), color: (..), ...)`.
pub fn fog(f: &FogDesc) -> String {
    ron_text::fog_text(f)
}

/// `(samples: .., color: (..), intensity: .., direct: ..)`.
pub fn ambient_occlusion(a: &AoDesc) -> String {
    ron_text::ambient_occlusion_text(a)
}

/// A clip group's planes: `[(point: (..), normal: (..)), ...]`.
pub fn clip_planes(planes: &[ClipPlaneDesc]) -> String {
    ron_text::clip_planes(planes)
}

/// A volume's render block: `(transfer: (preset: "..."), step: .., ...)`.
pub fn volume_render(r: &VolumeRenderDesc) -> String {
    ron_text::volume_render(r)
}

/// The fields of a render block that an embedded scene does not take: the caller's target and
/// renderer decide them. With what decides each (the end of `fragment`'s message).
pub(crate) const NOT_RENDER_SETTINGS: &[(&str, &str)] = &[
    ("width", "the target's size decides it"),
    ("height", "the target's size decides it"),
    (
        "outputs",
        "write images with write_image (luxon_write_image)",
    ),
    (
        "parallel",
        "the renderer's options decide it (its threads and communicator)",
    ),
];

/// The fields of a render block that an embedded scene takes (all but `width`, `height`,
/// `outputs` and `parallel`): `(samples: .., max_depth: .., ...)`.
pub fn render_settings(r: &RenderDesc) -> String {
    let fields: Vec<String> = ron_text::render_fields(r, Path::new(""), true)
        .into_iter()
        .filter(|(name, _)| NOT_RENDER_SETTINGS.iter().all(|(not, _)| not != name))
        .map(|(_, field)| field)
        .collect();
    format!("({})", fields.join(", "))
}
