//! What serde reads: the scene grammar as private structs. Positions come from `spans`.
//! Whole numbers are read as `f64` so that `width: 1.5` or `-1` gets our own message.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer};

pub(crate) type Vec3 = [f64; 3];

#[derive(Deserialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub(crate) struct Scene {
    #[serde(default)]
    pub include: Vec<String>,
    #[serde(default)]
    pub plugin_path: Vec<String>,
    #[serde(default)]
    pub camera: Option<Camera>,
    #[serde(default)]
    pub background: Option<Background>,
    #[serde(default)]
    pub lights: Vec<Light>,
    #[serde(default)]
    pub fog: Option<Fog>,
    #[serde(default)]
    pub ambient_occlusion: Option<Ao>,
    #[serde(default)]
    pub textures: Named<Texture>,
    #[serde(default)]
    pub materials: Named<Material>,
    #[serde(default)]
    pub clip_groups: Named<Vec<ClipPlane>>,
    #[serde(default)]
    pub objects: Vec<Object>,
    #[serde(default)]
    pub volumes: Vec<Volume>,
    #[serde(default)]
    pub meshes: Vec<Mesh>,
    #[serde(default)]
    pub render: Option<Render>,
    #[serde(default)]
    pub animation: Option<Animation>,
    #[serde(default)]
    pub prototypes: Named<Prototype>,
    #[serde(default)]
    pub instances: Vec<Instance>,
    #[serde(default)]
    pub series: Vec<Series>,
}

#[derive(Deserialize)]
#[serde(rename = "Camera", deny_unknown_fields)]
pub(crate) struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    #[serde(default)]
    pub up: Option<Vec3>,
    #[serde(default)]
    pub fov: Option<f64>,
    #[serde(default)]
    pub zoom: Option<f64>,
    #[serde(default)]
    pub aspect: Option<f64>,
    #[serde(default)]
    pub projection: Option<Projection>,
    #[serde(default)]
    pub frustum: Option<Frustum>,
    #[serde(default)]
    pub depth_of_field: Option<DepthOfField>,
    #[serde(default)]
    pub stereo: Option<Stereo>,
}

#[derive(Deserialize)]
#[serde(rename = "Projection", deny_unknown_fields)]
pub(crate) enum Projection {
    Perspective {
        #[serde(default)]
        fov: Option<f64>,
        #[serde(default)]
        zoom: Option<f64>,
    },
    Orthographic {
        #[serde(default)]
        height: Option<f64>,
    },
    Fisheye {
        #[serde(default)]
        fov: Option<f64>,
    },
    Equirectangular,
}

#[derive(Deserialize)]
#[serde(rename = "Frustum", deny_unknown_fields)]
pub(crate) struct Frustum {
    pub left: f64,
    pub right: f64,
    pub bottom: f64,
    pub top: f64,
}

#[derive(Deserialize)]
#[serde(rename = "DepthOfField", deny_unknown_fields)]
pub(crate) struct DepthOfField {
    pub aperture: f64,
    #[serde(default)]
    pub focal_distance: Option<f64>,
}

#[derive(Deserialize)]
#[serde(rename = "Stereo", deny_unknown_fields)]
pub(crate) struct Stereo {
    #[serde(default)]
    pub layout: Option<StereoLayout>,
    #[serde(default)]
    pub eye_separation: Option<f64>,
    #[serde(default)]
    pub convergence: Option<f64>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "StereoLayout")]
pub(crate) enum StereoLayout {
    SideBySide,
    OverUnder,
}

// The scene syntax says `SphereLight(...)`: the names read well in a `lights:` list.
#[allow(clippy::enum_variant_names)]
#[derive(Deserialize)]
#[serde(rename = "Light", deny_unknown_fields)]
pub(crate) enum Light {
    Point {
        #[serde(default)]
        name: Option<String>,
        position: Vec3,
        #[serde(default)]
        color: Option<Vec3>,
        #[serde(default)]
        intensity: Option<f64>,
        #[serde(default)]
        shadows: Option<bool>,
        #[serde(default)]
        attenuation: Option<Vec3>,
    },
    Directional {
        #[serde(default)]
        name: Option<String>,
        direction: Vec3,
        #[serde(default)]
        color: Option<Vec3>,
        #[serde(default)]
        intensity: Option<f64>,
        #[serde(default)]
        shadows: Option<bool>,
    },
    Spot {
        #[serde(default)]
        name: Option<String>,
        position: Vec3,
        direction: Vec3,
        /// Full cone angle, degrees.
        angle: f64,
        #[serde(default)]
        falloff: Option<f64>,
        #[serde(default)]
        fade: Option<SpotFade>,
        #[serde(default)]
        color: Option<Vec3>,
        #[serde(default)]
        intensity: Option<f64>,
        #[serde(default)]
        shadows: Option<bool>,
        #[serde(default)]
        attenuation: Option<Vec3>,
    },
    SphereLight {
        #[serde(default)]
        name: Option<String>,
        center: Vec3,
        radius: f64,
        #[serde(default)]
        samples: Option<f64>,
        #[serde(default)]
        color: Option<Vec3>,
        #[serde(default)]
        intensity: Option<f64>,
        #[serde(default)]
        shadows: Option<bool>,
        #[serde(default)]
        attenuation: Option<Vec3>,
    },
    RectLight {
        #[serde(default)]
        name: Option<String>,
        corner: Vec3,
        edge1: Vec3,
        edge2: Vec3,
        #[serde(default)]
        samples: Option<f64>,
        #[serde(default)]
        color: Option<Vec3>,
        #[serde(default)]
        intensity: Option<f64>,
        #[serde(default)]
        shadows: Option<bool>,
        #[serde(default)]
        attenuation: Option<Vec3>,
    },
}

impl Light {
    pub fn name(&self) -> Option<&str> {
        match self {
            Light::Point { name, .. }
            | Light::Directional { name, .. }
            | Light::Spot { name, .. }
            | Light::SphereLight { name, .. }
            | Light::RectLight { name, .. } => name.as_deref(),
        }
    }
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "SpotFade")]
pub(crate) enum SpotFade {
    Smooth,
    Linear,
}

/// `background: (r, g, b)` or `background: Gradient(...)`.
pub(crate) enum Background {
    Color(Vec3),
    Gradient(Gradient),
}

#[derive(Deserialize)]
#[serde(rename = "Gradient", deny_unknown_fields)]
pub(crate) struct Gradient {
    pub kind: GradientKind,
    #[serde(default)]
    pub up: Option<Vec3>,
    pub top: f64,
    pub bottom: f64,
    pub top_color: Vec3,
    pub bottom_color: Vec3,
}

#[derive(Deserialize)]
#[serde(rename = "GradientKind")]
pub(crate) enum GradientKind {
    Sphere,
    OrthoPlane,
}

impl<'de> Deserialize<'de> for Background {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct BackgroundVisitor;

        impl<'de> Visitor<'de> for BackgroundVisitor {
            type Value = Background;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a colour `(r, g, b)` or `Gradient(kind: ..., ...)`")
            }

            // A tuple is a colour; a struct (its name is checked against the span tree) a
            // gradient: RON hands both to `deserialize_any` without their names.
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                let rgb = Vec3::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))?;
                Ok(Background::Color(rgb))
            }

            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let g = Gradient::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                Ok(Background::Gradient(g))
            }
        }

        deserializer.deserialize_any(BackgroundVisitor)
    }
}

#[derive(Deserialize)]
#[serde(rename = "Fog", deny_unknown_fields)]
pub(crate) struct Fog {
    pub mode: FogMode,
    #[serde(default)]
    pub color: Option<Vec3>,
    #[serde(default)]
    pub planar: Option<bool>,
    #[serde(default)]
    pub every_ray: Option<bool>,
    #[serde(default)]
    pub misses: Option<bool>,
}

#[derive(Deserialize)]
#[serde(rename = "FogMode", deny_unknown_fields)]
pub(crate) enum FogMode {
    Linear {
        start: f64,
        end: f64,
    },
    Exp {
        density: f64,
        #[serde(default)]
        start: Option<f64>,
    },
    Exp2 {
        density: f64,
        #[serde(default)]
        start: Option<f64>,
    },
}

#[derive(Deserialize)]
#[serde(rename = "AmbientOcclusion", deny_unknown_fields)]
pub(crate) struct Ao {
    #[serde(default)]
    pub samples: Option<f64>,
    #[serde(default)]
    pub distance: Option<f64>,
    #[serde(default)]
    pub color: Option<Vec3>,
    #[serde(default)]
    pub intensity: Option<f64>,
    #[serde(default)]
    pub direct: Option<f64>,
}

/// `params` is only skipped here; its text is taken verbatim from the source.
#[derive(Deserialize)]
#[serde(rename = "Texture", deny_unknown_fields)]
pub(crate) struct Texture {
    pub plugin: String,
    #[serde(default, rename = "params")]
    pub _params: IgnoredAny,
}

#[derive(Deserialize)]
#[serde(rename = "Material", deny_unknown_fields)]
pub(crate) struct Material {
    pub color: Option<Vec3>,
    pub texture: Option<String>,
    pub reflect_texture: Option<String>,
    pub transmit_texture: Option<String>,
    pub ambient: Option<f64>,
    pub diffuse: Option<f64>,
    pub specular: Option<f64>,
    pub shininess: Option<f64>,
    pub highlight: Option<Highlight>,
    pub highlight_color: Option<HighlightColor>,
    pub reflect: Option<f64>,
    pub transmit: Option<f64>,
    pub ior: Option<f64>,
    pub transparency_angle: Option<TransparencyAngle>,
    pub outline: Option<f64>,
    pub outline_width: Option<f64>,
    pub fog: Option<bool>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "Highlight")]
pub(crate) enum Highlight {
    Phong,
    Blinn,
    BlinnFast,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "HighlightColor")]
pub(crate) enum HighlightColor {
    Light,
    Surface,
}

#[derive(Deserialize)]
#[serde(rename = "Object", deny_unknown_fields)]
pub(crate) struct Object {
    pub plugin: String,
    /// Names the object for `animation: (objects: ...)`.
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default, rename = "params")]
    pub _params: IgnoredAny,
    #[serde(default)]
    pub material: Option<String>,
    #[serde(default)]
    pub clip: Option<String>,
    #[serde(default)]
    pub shadows: Option<bool>,
}

/// A named group of objects and mesh files placed by `instances:`. Lights, volumes and other
/// instances have no place in it (serde rejects them by name).
#[derive(Deserialize)]
#[serde(rename = "Prototype", deny_unknown_fields)]
pub(crate) struct Prototype {
    #[serde(default)]
    pub objects: Vec<Object>,
    #[serde(default)]
    pub meshes: Vec<Mesh>,
}

/// Time-sampled data: one file per data frame, named by a pattern (`traj_%04d.xyz`).
#[derive(Deserialize)]
#[serde(rename = "Series", deny_unknown_fields)]
pub(crate) struct Series {
    pub name: String,
    pub files: String,
    #[serde(default)]
    pub first: Option<f64>,
    #[serde(default)]
    pub per_frame: Option<f64>,
    /// `.xyz` files: element name to its sphere.
    #[serde(default)]
    pub atoms: Option<Named<AtomStyle>>,
    #[serde(default)]
    pub default_atom: Option<AtomStyle>,
    /// `.obj` files: the material of every triangle.
    #[serde(default)]
    pub material: Option<String>,
}

/// How an element of an `.xyz` file is drawn.
#[derive(Deserialize)]
#[serde(rename = "AtomStyle", deny_unknown_fields)]
pub(crate) struct AtomStyle {
    pub radius: f64,
    #[serde(default)]
    pub material: Option<String>,
}

/// A copy of a prototype, placed by `world_from_object` (the identity when absent).
#[derive(Deserialize)]
#[serde(rename = "Instance", deny_unknown_fields)]
pub(crate) struct Instance {
    pub prototype: String,
    /// Names the instance for `animation: (objects: ...)`.
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub world_from_object: Option<Transform>,
    /// Replaces the material of every object of the prototype.
    #[serde(default)]
    pub material: Option<String>,
}

/// `(translate: ..., rotate: (axis: ..., degrees: ...), scale: ...)` (scaled, then rotated,
/// then moved) or `(matrix: ((..4..), (..4..), (..4..)))`, the rows of a 3x4 matrix.
#[derive(Deserialize)]
#[serde(rename = "Transform", deny_unknown_fields)]
pub(crate) struct Transform {
    #[serde(default)]
    pub translate: Option<Vec3>,
    #[serde(default)]
    pub rotate: Option<Rotation>,
    #[serde(default)]
    pub scale: Option<Vec3>,
    #[serde(default)]
    pub matrix: Option<[[f64; 4]; 3]>,
}

/// Keeps the side of the plane its normal points away from; cuts away the other.
#[derive(Deserialize)]
#[serde(rename = "ClipPlane", deny_unknown_fields)]
pub(crate) struct ClipPlane {
    pub point: Vec3,
    pub normal: Vec3,
}

/// A mesh file (`.obj`) whose triangles join the scene.
#[derive(Deserialize)]
#[serde(rename = "Mesh", deny_unknown_fields)]
pub(crate) struct Mesh {
    pub file: String,
    /// Replaces the file's own (MTL) materials.
    #[serde(default)]
    pub material: Option<String>,
}

#[derive(Deserialize)]
#[serde(rename = "Volume", deny_unknown_fields)]
pub(crate) struct Volume {
    pub plugin: String,
    #[serde(default, rename = "params")]
    pub _params: IgnoredAny,
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub render: Option<VolumeRender>,
}

#[derive(Deserialize)]
#[serde(rename = "VolumeRender", deny_unknown_fields)]
pub(crate) struct VolumeRender {
    pub transfer: Transfer,
    #[serde(default)]
    pub step: Option<f64>,
    #[serde(default)]
    pub interpolation: Option<Interpolation>,
    #[serde(default)]
    pub shading: Option<VolumeShading>,
    #[serde(default)]
    pub clip: Option<String>,
    #[serde(default)]
    pub bounds: Option<Bounds>,
}

#[derive(Deserialize)]
#[serde(rename = "Transfer", deny_unknown_fields)]
pub(crate) struct Transfer {
    #[serde(default)]
    pub preset: Option<String>,
    #[serde(default)]
    pub points: Option<Vec<TransferPoint>>,
    #[serde(default)]
    pub range: Option<[f64; 2]>,
    #[serde(default)]
    pub opacity: Option<f64>,
}

#[derive(Deserialize)]
#[serde(rename = "TransferPoint", deny_unknown_fields)]
pub(crate) struct TransferPoint {
    pub x: f64,
    pub color: Vec3,
    pub opacity: f64,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "Interpolation")]
pub(crate) enum Interpolation {
    Nearest,
    Trilinear,
}

#[derive(Deserialize)]
#[serde(rename = "VolumeShading", deny_unknown_fields)]
pub(crate) struct VolumeShading {
    #[serde(default)]
    pub ambient: Option<f64>,
    #[serde(default)]
    pub diffuse: Option<f64>,
    #[serde(default)]
    pub specular: Option<f64>,
    #[serde(default)]
    pub shininess: Option<f64>,
    #[serde(default)]
    pub shadows: Option<bool>,
}

#[derive(Deserialize)]
#[serde(rename = "Bounds", deny_unknown_fields)]
pub(crate) struct Bounds {
    pub min: Vec3,
    pub max: Vec3,
}

#[derive(Deserialize)]
#[serde(rename = "Render", deny_unknown_fields)]
pub(crate) struct Render {
    pub width: Option<f64>,
    pub height: Option<f64>,
    pub samples: Option<f64>,
    pub max_depth: Option<f64>,
    pub min_weight: Option<f64>,
    pub frame: Option<f64>,
    pub time: Option<f64>,
    #[serde(default)]
    pub outputs: Vec<Output>,
    pub parallel: Option<Parallel>,
    pub transparency: Option<Transparency>,
    pub volume_step: Option<f64>,
    pub volume_skip: Option<bool>,
    pub adaptive: Option<Adaptive>,
    pub light_scale: Option<f64>,
    pub tachyon: Option<Tachyon>,
    pub memory: Option<String>,
    pub texture_cache: Option<String>,
    pub instancing: Option<Instancing>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "Instancing")]
pub(crate) enum Instancing {
    Auto,
    Bake,
    Share,
}

#[derive(Deserialize)]
#[serde(rename = "Tachyon", deny_unknown_fields)]
pub(crate) struct Tachyon {
    pub light_threshold: Option<bool>,
    pub plain_highlights: Option<bool>,
    pub depth_limit_background: Option<bool>,
    pub centre_sample: Option<bool>,
    pub additive_volumes: Option<bool>,
    pub terminator_shadows: Option<bool>,
}

#[derive(Deserialize)]
#[serde(rename = "Adaptive", deny_unknown_fields)]
pub(crate) struct Adaptive {
    pub threshold: f64,
    pub max_depth: Option<f64>,
}

#[derive(Deserialize)]
#[serde(rename = "Transparency", deny_unknown_fields)]
pub(crate) struct Transparency {
    pub mode: Option<TransparencyMode>,
    pub angle: Option<TransparencyAngle>,
    pub max_surfaces: Option<f64>,
    pub beyond_max: Option<BeyondMax>,
    pub shadows: Option<TransparentShadows>,
    pub scale_reflection: Option<bool>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "TransparencyMode")]
pub(crate) enum TransparencyMode {
    Filter,
    AngleModulated,
    PostMultiplied,
    Additive,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "TransparencyAngle")]
pub(crate) enum TransparencyAngle {
    Constant,
    Raster3D,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "BeyondMax")]
pub(crate) enum BeyondMax {
    Opaque,
    Skip,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "TransparentShadows")]
pub(crate) enum TransparentShadows {
    Tinted,
    Untinted,
    Off,
}

#[derive(Deserialize)]
#[serde(rename = "Output", deny_unknown_fields)]
pub(crate) struct Output {
    pub path: String,
    #[serde(default)]
    pub plugin: Option<String>,
    #[serde(default, rename = "params")]
    pub _params: IgnoredAny,
}

#[derive(Deserialize)]
#[serde(rename = "Parallel", deny_unknown_fields)]
pub(crate) struct Parallel {
    pub mode: Option<Mode>,
    pub threads: Option<f64>,
    pub decomposition: Option<Decomposition>,
    pub tile_size: Option<f64>,
    pub io: Option<IoMode>,
    pub frames: Option<Frames>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "FrameGroups")]
pub(crate) enum Frames {
    Whole,
    Groups(f64),
    Shared,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "OutputIo")]
pub(crate) enum IoMode {
    Async,
    Sync,
    MpiIo,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "ParallelMode")]
pub(crate) enum Mode {
    Threads,
    Mpi,
    Hybrid,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "Decomposition")]
pub(crate) enum Decomposition {
    PixelCyclic,
    ScanlineCyclic,
    BlockCyclic,
    Dynamic,
}

/// `animation: (...)`: the frame range, the shutter and the keyed values. The keyed structs
/// list exactly what can be animated, so serde itself rejects a key on anything else (reworded
/// by `ron_error`).
#[derive(Deserialize)]
#[serde(rename = "Animation", deny_unknown_fields)]
pub(crate) struct Animation {
    pub frames: (f64, f64),
    #[serde(default)]
    pub fps: Option<f64>,
    #[serde(default)]
    pub shutter: Option<Shutter>,
    #[serde(default)]
    pub camera: Option<CameraKeys>,
    #[serde(default)]
    pub lights: Named<LightKeys>,
    #[serde(default)]
    pub materials: Named<MaterialKeys>,
    #[serde(default)]
    pub objects: Named<ObjectKeys>,
}

#[derive(Deserialize)]
#[serde(rename = "Shutter", deny_unknown_fields)]
pub(crate) struct Shutter {
    pub length: f64,
    #[serde(default)]
    pub at: Option<ShutterAt>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "ShutterAt")]
pub(crate) enum ShutterAt {
    Start,
    Centre,
    End,
}

/// `(keys: [(frame, value), ...], interpolation: ...)`.
#[derive(Deserialize)]
#[serde(rename = "Track", deny_unknown_fields)]
pub(crate) struct Track<T> {
    pub keys: Vec<(f64, T)>,
    #[serde(default)]
    pub interpolation: Option<Interpolate>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename = "Interpolate")]
pub(crate) enum Interpolate {
    Linear,
    CatmullRom,
}

#[derive(Deserialize)]
#[serde(rename = "CameraKeys", deny_unknown_fields)]
pub(crate) struct CameraKeys {
    #[serde(default)]
    pub position: Option<Track<Vec3>>,
    #[serde(default)]
    pub look_at: Option<Track<Vec3>>,
    #[serde(default)]
    pub up: Option<Track<Vec3>>,
    #[serde(default)]
    pub fov: Option<Track<f64>>,
    #[serde(default)]
    pub focal_distance: Option<Track<f64>>,
}

#[derive(Deserialize)]
#[serde(rename = "LightKeys", deny_unknown_fields)]
pub(crate) struct LightKeys {
    #[serde(default)]
    pub position: Option<Track<Vec3>>,
    #[serde(default)]
    pub direction: Option<Track<Vec3>>,
    #[serde(default)]
    pub intensity: Option<Track<f64>>,
    #[serde(default)]
    pub color: Option<Track<Vec3>>,
}

#[derive(Deserialize)]
#[serde(rename = "MaterialKeys", deny_unknown_fields)]
pub(crate) struct MaterialKeys {
    #[serde(default)]
    pub color: Option<Track<Vec3>>,
}

#[derive(Deserialize)]
#[serde(rename = "ObjectKeys", deny_unknown_fields)]
pub(crate) struct ObjectKeys {
    #[serde(default)]
    pub translate: Option<Track<Vec3>>,
    #[serde(default)]
    pub rotate: Option<Track<Rotation>>,
    #[serde(default)]
    pub scale: Option<Track<Vec3>>,
}

/// `(axis: (x, y, z), degrees: d)`.
#[derive(Deserialize)]
#[serde(rename = "Rotation", deny_unknown_fields)]
pub(crate) struct Rotation {
    pub axis: Vec3,
    pub degrees: f64,
}

/// A `{ "name": value }` map in file order, duplicates kept (the checker reports them at their
/// place, which a map type would lose).
pub(crate) struct Named<T>(pub Vec<(String, T)>);

impl<T> Default for Named<T> {
    fn default() -> Self {
        Named(Vec::new())
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Named<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct NamedVisitor<T>(PhantomData<T>);

        impl<'de, T: Deserialize<'de>> Visitor<'de> for NamedVisitor<T> {
            type Value = Named<T>;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a map `{ \"name\": (...), ... }`")
            }

            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut entries = Vec::new();
                while let Some(entry) = map.next_entry()? {
                    entries.push(entry);
                }
                Ok(Named(entries))
            }
        }

        deserializer.deserialize_map(NamedVisitor(PhantomData))
    }
}
