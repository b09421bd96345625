//! `SceneDesc`: what a scene file says, as plain data with source positions. It knows nothing of
//! plugins; the core resolves plugin names and instantiates objects from it.
//!
//! Coordinates stay `f64` here: the core re-centres the world before storing `f32`.

use std::path::PathBuf;

pub use crate::error::Warning;
use crate::geometry::InlineGeometry;
pub use crate::origin::{Origin, Spanned};

/// A plugin named in a scene and the RON text of its `params` subtree.
#[derive(Clone, Debug, PartialEq)]
pub struct PluginCall {
    /// The plugin name as written, with its position.
    pub plugin: Spanned<String>,
    /// RON text of `params: (...)`, exactly as in the file ("()" when absent).
    pub params: String,
    /// Where `params` text starts (line/col of its first character): the core adds a plugin's
    /// in-params error positions to this to report scene positions.
    pub params_at: Origin,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SceneDesc {
    /// The file the scene was loaded from (the first of `include`s).
    pub source: PathBuf,
    pub camera: Spanned<CameraDesc>,
    pub background: BackgroundDesc,
    pub lights: Vec<Spanned<LightDesc>>,
    pub fog: Option<FogDesc>,
    pub ambient_occlusion: Option<AoDesc>,
    /// Named textures, in file order (later definitions of a name replace earlier ones).
    pub textures: Vec<(String, Spanned<PluginCall>)>,
    /// Named materials, in file order (later definitions of a name replace earlier ones).
    pub materials: Vec<(String, Spanned<MaterialDesc>)>,
    /// Named groups of clip planes (Tachyon's clip groups), in file order.
    pub clip_groups: Vec<(String, Spanned<Vec<ClipPlaneDesc>>)>,
    pub objects: Vec<Spanned<ObjectDesc>>,
    /// Native geometry from importers (NFF, OBJ...), stored by the core without plugins.
    pub inline: Vec<InlineGeometry>,
    /// Volumes read by volume-reader plugins, in file order (includes first).
    pub volumes: Vec<Spanned<VolumeDescEntry>>,
    pub render: RenderDesc,
    /// Extra plugin directories (or files), already resolved against the scene file's directory.
    pub plugin_path: Vec<PathBuf>,
    /// Problems that did not stop the load (an OBJ's missing material library, an NFF sphere
    /// with a negative radius...), in the order found. The CLI prints them.
    pub warnings: Vec<Warning>,
    /// The `animation:` block (RON scenes only); `None`: a still scene.
    pub animation: Option<Spanned<AnimationDesc>>,
    /// Named groups of objects that `instances` place (RON scenes only), in file order (later
    /// definitions of a name replace earlier ones).
    pub prototypes: Vec<(String, Spanned<PrototypeDesc>)>,
    /// Copies of prototypes, in file order (includes first); stored after `objects` and
    /// `inline`.
    pub instances: Vec<Spanned<InstanceDesc>>,
    /// Time-sampled data (`series:`), in file order (includes first); only in animated
    /// scenes.
    pub series: Vec<Spanned<SeriesDesc>>,
}

/// What a ray that hits nothing shows (`background:`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BackgroundDesc {
    /// One colour, linear RGB: `background: (r, g, b)`.
    Color([f64; 3]),
    /// `background: Gradient(...)`: Tachyon's BACKGROUND_GRADIENT.
    Gradient(GradientDesc),
}

impl Default for BackgroundDesc {
    fn default() -> Self {
        BackgroundDesc::Color([0.0; 3])
    }
}

/// A background that blends two colours along `up`: with x = `up`·(the missed ray's direction)
/// (`Sphere`) or `up`·(its origin) (`OrthoPlane`), the mix (x − bottom) / (top − bottom),
/// clamped to 0..1, runs from `bottom_color` to `top_color` (`top` = `bottom`: a sharp
/// horizon).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradientDesc {
    pub kind: GradientKind,
    /// Not normalised: its length scales x.
    pub up: [f64; 3],
    pub top: f64,
    pub bottom: f64,
    pub top_color: [f64; 3],
    pub bottom_color: [f64; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GradientKind {
    /// By the ray's direction: a sky around the scene, the same from everywhere.
    Sphere,
    /// By where the ray starts: camera rays of an orthographic view sweep the gradient across
    /// the picture (a perspective camera's all start at its position: one colour).
    OrthoPlane,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    pub position: [f64; 3],
    pub look_at: [f64; 3],
    pub up: [f64; 3],
    pub projection: Projection,
    /// Width / height of the image plane (of one eye's image in stereo); `None`: the image's
    /// width / height. Not used by `Equirectangular` nor with a `frustum`.
    pub aspect: Option<f64>,
    /// An explicit image window; replaces the size `projection` gives (with `Perspective`,
    /// `PerspectiveZoom`, `Orthographic`, and `Equirectangular`, where it is a window in
    /// degrees of longitude and latitude).
    pub frustum: Option<Frustum>,
    pub depth_of_field: Option<DepthOfField>,
    pub stereo: Option<Stereo>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Projection {
    /// Full vertical field of view in degrees, in (0, 180).
    Perspective { fov_deg: f64 },
    /// Tachyon's zoom: the image plane's half-height at unit distance is `0.5 / zoom`
    /// (zoom 1: a window 1 unit high at unit distance, as in Tachyon).
    PerspectiveZoom { zoom: f64 },
    /// Parallel rays; `height` is the view window's full height in world units.
    Orthographic { height: f64 },
    /// Angular (equidistant) fisheye: the angle from the view direction grows linearly with
    /// the distance from the image centre; `fov_deg` (in (0, 360]) spans the image height.
    Fisheye { fov_deg: f64 },
    /// Latitude-longitude panorama: 360° across the width, 180° down the height, or the
    /// `frustum`'s window (degrees of longitude left to right, latitude bottom to top).
    Equirectangular,
}

/// The image window: at unit distance from the eye for perspective cameras, in world units
/// around the camera position for orthographic ones, in degrees of longitude (left, right) and
/// latitude (bottom, top) for equirectangular ones. `left < right`, `bottom < top`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    pub left: f64,
    pub right: f64,
    pub bottom: f64,
    pub top: f64,
}

/// A thin lens: points at `focal_distance` are sharp; the blur grows with `aperture`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthOfField {
    /// Lens radius in world units, `>= 0` (0: a pinhole).
    pub aperture: f64,
    /// Distance of the sharp plane along the view direction (perspective, orthographic) or of
    /// the sharp sphere around the camera (fisheye, equirectangular), `> 0`.
    pub focal_distance: f64,
}

/// Two eyes in one image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stereo {
    pub layout: StereoLayout,
    /// Distance between the eyes in world units, `>= 0`.
    pub eye_separation: f64,
    /// Distance at which the eyes' views coincide (zero parallax), `> 0`.
    pub convergence: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StereoLayout {
    /// Left eye in the left half, right eye in the right half.
    SideBySide,
    /// Left eye in the top half, right eye in the bottom half.
    OverUnder,
}

/// Light falling off with distance `d` as 1 / (constant + linear·d + quadratic·d²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    pub constant: f64,
    pub linear: f64,
    pub quadratic: f64,
}

impl Default for Attenuation {
    /// No fall-off: the classic Whitted light.
    fn default() -> Self {
        Attenuation {
            constant: 1.0,
            linear: 0.0,
            quadratic: 0.0,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum LightDesc {
    Point {
        position: [f64; 3],
        color: [f64; 3],
        intensity: f64,
        shadows: bool,
        attenuation: Attenuation,
    },
    /// Light arriving along `direction` (pointing from the light into the scene).
    Directional {
        direction: [f64; 3],
        color: [f64; 3],
        intensity: f64,
        shadows: bool,
    },
    /// A point light shining into a cone: full strength inside `cone_deg - falloff_deg`
    /// (full angles), fading to nothing at `cone_deg` as `fade` says.
    Spot {
        position: [f64; 3],
        direction: [f64; 3],
        cone_deg: f64,
        falloff_deg: f64,
        fade: SpotFade,
        color: [f64; 3],
        intensity: f64,
        shadows: bool,
        attenuation: Attenuation,
    },
    /// A spherical area light: soft shadows from `samples` shadow rays per shading point.
    Sphere {
        center: [f64; 3],
        radius: f64,
        samples: u32,
        color: [f64; 3],
        intensity: f64,
        shadows: bool,
        attenuation: Attenuation,
    },
    /// A rectangular area light `corner + s·edge1 + t·edge2` (s, t in [0, 1]), shining to the
    /// side of `edge1 × edge2`.
    Rect {
        corner: [f64; 3],
        edge1: [f64; 3],
        edge2: [f64; 3],
        samples: u32,
        color: [f64; 3],
        intensity: f64,
        shadows: bool,
        attenuation: Attenuation,
    },
}

/// How a spot light fades across its falloff band.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpotFade {
    /// A smoothstep in the cosine of the angle from the axis: no visible edge.
    #[default]
    Smooth,
    /// Linear in the angle from the axis (Tachyon's spot lights).
    Linear,
}

/// Fog over the distance a camera ray travels to its first hit (`every_ray`: every ray, over
/// its own segment).
#[derive(Clone, Debug, PartialEq)]
pub struct FogDesc {
    pub mode: FogMode,
    pub color: [f64; 3],
    /// Distance measured along the view direction (VMD's planar fog) instead of along the ray
    /// (radial). With `every_ray`, for camera rays only.
    pub planar: bool,
    /// Tachyon's fog: every ray's hit is fogged over that ray's own segment, and what is fogged
    /// is the hit's whole colour, its reflection and refraction included (so light seen in a
    /// mirror is fogged on its way to the mirror, then again on the way to the eye). Otherwise
    /// only camera rays are fogged, and only the hit's own shading.
    pub every_ray: bool,
    /// Rays that hit nothing are fogged as at infinite distance: they show the fog colour
    /// (camera rays; with `every_ray`, every ray). Otherwise they show the background.
    pub misses: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FogMode {
    /// No fog before `start`, all fog after `end`.
    Linear { start: f64, end: f64 },
    /// Visibility exp(-density·(d - start)), 1 before `start`.
    Exp { density: f64, start: f64 },
    /// Visibility exp(-(density·(d - start))²), 1 before `start`.
    Exp2 { density: f64, start: f64 },
}

/// Ambient occlusion: the ambient term lit by a sky of `color`, seen through `samples` rays
/// over the hemisphere up to `max_distance`.
#[derive(Clone, Debug, PartialEq)]
pub struct AoDesc {
    pub samples: u32,
    pub max_distance: f64,
    pub color: [f64; 3],
    /// Scale of the sky light (VMD's `aoambient`).
    pub intensity: f64,
    /// Scale of every light's direct contribution while occlusion is on (VMD's `aodirect`).
    pub direct: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Highlight {
    /// (reflected light · view)^shininess.
    Phong,
    /// (normal · half vector)^shininess.
    Blinn,
    /// Tachyon's cheap Blinn: x / (s − s·x + x) for x = normal · half vector, s = shininess.
    BlinnFast,
}

/// The colour a highlight takes (times the light's colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum HighlightColor {
    /// White: the light's own colour (plastic; Tachyon's PHONG PLASTIC).
    #[default]
    Light,
    /// The surface's colour (metal; Tachyon's PHONG METAL, where with
    /// `TachyonDesc::plain_highlights` it replaces the light's colour).
    Surface,
}

/// The thesis's shading model. Coefficients are in [0, 1] except `shininess` and `ior`.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDesc {
    /// Linear RGB base colour.
    pub color: [f64; 3],
    /// Name of a texture that replaces `color`.
    pub texture: Option<Spanned<String>>,
    /// Name of a texture whose mean of R, G, B scales `reflect` at each point.
    pub reflect_texture: Option<Spanned<String>>,
    /// Name of a texture whose mean of R, G, B scales `transmit` at each point.
    pub transmit_texture: Option<Spanned<String>>,
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    /// Highlight exponent (> 0).
    pub shininess: f64,
    pub highlight: Highlight,
    pub highlight_color: HighlightColor,
    /// Mirror reflection coefficient.
    pub reflect: f64,
    /// Fraction of light passing through (0 = opaque).
    pub transmit: f64,
    /// Index of refraction (1 = no bending).
    pub ior: f64,
    /// How transmission changes with the viewing angle, for this material; `None`: the
    /// render's `transparency.angle` (Tachyon's per-texture `TRANSMODE R3D`).
    pub transparency_angle: Option<TransparencyAngle>,
    /// Silhouette darkening in [0, 1] (Tachyon's OUTLINE): the diffuse light (lights and
    /// occlusion, not ambient) is scaled by (1 − outline) + outline·(1 − (1 − (N·V)²)^k),
    /// k = 32·(1 − outline_width).
    pub outline: f64,
    /// In [0, 1]: wider outlines as it grows.
    pub outline_width: f64,
    /// Whether fog covers the surface (false: a light's visible sphere, which Tachyon never
    /// fogs).
    pub fog: bool,
}

impl Default for MaterialDesc {
    fn default() -> Self {
        MaterialDesc {
            color: [0.8, 0.8, 0.8],
            texture: None,
            reflect_texture: None,
            transmit_texture: None,
            ambient: 0.1,
            diffuse: 0.9,
            specular: 0.0,
            shininess: 32.0,
            highlight: Highlight::Phong,
            highlight_color: HighlightColor::Light,
            reflect: 0.0,
            transmit: 0.0,
            ior: 1.0,
            transparency_angle: None,
            outline: 0.0,
            outline_width: 0.0,
            fog: true,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ObjectDesc {
    pub call: PluginCall,
    /// Material name; `None`: the built-in default material.
    pub material: Option<Spanned<String>>,
    /// Clip group name: the object is cut away on the far side of the group's planes.
    pub clip: Option<Spanned<String>>,
    /// Whether the object casts shadows (false: shadow and occlusion rays pass through it, as
    /// through a light's visible sphere).
    pub shadows: bool,
}

/// A named group of objects and meshes, placed any number of times by instances. Its objects
/// use no clip groups (clip planes are in world space).
#[derive(Clone, Debug, PartialEq)]
pub struct PrototypeDesc {
    pub objects: Vec<Spanned<ObjectDesc>>,
    /// The geometry of its `meshes:` files (read after merging, like the scene's), in file
    /// order, in the prototype's coordinates.
    pub inline: Vec<InlineGeometry>,
    /// The `meshes:` entries, until the loader reads them into `inline` (then empty).
    pub mesh_files: Vec<MeshFile>,
}

impl PrototypeDesc {
    /// Whether it holds nothing to place.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty() && self.inline.iter().all(InlineGeometry::is_empty)
    }
}

/// A mesh file named by a scene: the path resolved against that scene file, at the `file`
/// string; the material that replaces the file's own, at its string.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFile {
    pub file: Spanned<PathBuf>,
    pub material: Option<Spanned<String>>,
}

/// Time-sampled data: one file per data frame. Movie frame `k` shows data frame
/// `first + (k - animation.first) * per_frame`, `k` clamped to the animation's range (so any
/// subset of frames reads the same files).
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesDesc {
    pub name: Spanned<String>,
    /// The pattern as written (relative to `dir`), where it is written.
    pub files: Spanned<String>,
    pub pattern: crate::pattern::FramePattern,
    /// The directory of the scene file that names the series.
    pub dir: PathBuf,
    /// The data frame shown at the animation's first frame.
    pub first: u32,
    /// Data frames per movie frame (>= 1).
    pub per_frame: u32,
    pub kind: SeriesKind,
}

/// What a series' files hold.
#[derive(Clone, Debug, PartialEq)]
pub enum SeriesKind {
    /// `.xyz` trajectories: spheres drawn by element (`atoms`), else `default`.
    Atoms {
        atoms: Vec<(String, AtomStyle)>,
        default: Option<AtomStyle>,
    },
    /// One `.obj` mesh per data frame, in `material` (`None`: the default material).
    Mesh { material: Option<Spanned<String>> },
}

/// An element's sphere: its radius (a fifth column of the file overrides it) and material.
#[derive(Clone, Debug, PartialEq)]
pub struct AtomStyle {
    pub radius: f64,
    pub material: Option<Spanned<String>>,
}

impl SeriesDesc {
    /// The data frame movie frame `k` shows (`range`: the animation's first and last frame).
    pub fn data_frame(&self, k: u32, range: (u32, u32)) -> u32 {
        let k = k.clamp(range.0, range.1);
        let d = u64::from(self.first) + u64::from(k - range.0) * u64::from(self.per_frame);
        // The loader checked that the range's last data frame fits.
        u32::try_from(d).unwrap_or(u32::MAX)
    }

    /// The file of data frame `d`.
    pub fn path(&self, d: u32) -> PathBuf {
        self.dir.join(self.pattern.name(d))
    }
}

/// A copy of a prototype in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceDesc {
    /// The prototype's name, where the instance names it.
    pub prototype: Spanned<String>,
    /// Names the instance for `animation: (objects: ...)`.
    pub name: Option<Spanned<String>>,
    pub world_from_object: Spanned<TransformDesc>,
    /// Replaces the material of every object of the prototype.
    pub material: Option<Spanned<String>>,
}

/// Where an instance's prototype goes: `world_from_object`, in f64. Always invertible (the
/// loader checks it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformDesc {
    /// Scaled by `scale`, then rotated by `rotate`, then moved by `translate` (the order of
    /// keyed transforms).
    Trs {
        translate: [f64; 3],
        rotate: Option<RotationDesc>,
        scale: [f64; 3],
    },
    /// The rows of a 3x4 matrix: `p' = M · (x, y, z, 1)`.
    Matrix([[f64; 4]; 3]),
}

impl TransformDesc {
    pub const IDENTITY: TransformDesc = TransformDesc::Trs {
        translate: [0.0; 3],
        rotate: None,
        scale: [1.0; 3],
    };
}

/// A clip plane: what lies on the side its normal points to is cut away.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipPlaneDesc {
    pub point: [f64; 3],
    pub normal: [f64; 3],
}

/// A volume: a volume-reader plugin call and the scene's name for the grid it reads.
///
/// ```ron
/// volumes: [ (plugin: "raw", params: (file: "head.raw", dims: (256, 256, 109)), name: "head") ],
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeDescEntry {
    pub call: PluginCall,
    /// The scene's name for the volume (unique among the scene's volumes, not empty); `None`:
    /// unnamed (the core calls it by its index).
    pub name: Option<Spanned<String>>,
    /// How to draw it; `None`: the volume is data only (read, checked and described by
    /// `luxon check`, not drawn).
    pub render: Option<Spanned<VolumeRenderDesc>>,
}

/// How a volume is drawn by ray casting (emission and absorption, front to back).
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeRenderDesc {
    pub transfer: TransferDesc,
    /// Distance between samples along a ray in world units (> 0); `None`: half the smallest
    /// voxel edge. The render setting `volume_step` multiplies it.
    pub step: Option<f64>,
    pub interpolation: Interpolation,
    /// Gradient (central differences) shading; `None`: unshaded (each sample glows with its
    /// transfer-function colour).
    pub shading: Option<VolumeShadingDesc>,
    /// A clip group of the scene: the volume is cut away on the far side of its planes.
    pub clip: Option<Spanned<String>>,
    /// World-space box (min, max) the volume is cropped to.
    pub bounds: Option<([f64; 3], [f64; 3])>,
}

/// Scalar to colour and opacity: piecewise-linear over `x = (s - range.0) / (range.1 -
/// range.0)`, clamped to [0, 1].
#[derive(Clone, Debug, PartialEq)]
pub struct TransferDesc {
    /// The preset the points came from, if any.
    pub preset: Option<String>,
    /// Control points, `x` strictly increasing in [0, 1]; at least one.
    pub points: Vec<TransferPoint>,
    /// Scalar window mapped to x in [0, 1]; `None`: the volume's smallest to largest value.
    pub range: Option<[f64; 2]>,
    /// Multiplies every point's opacity (>= 0).
    pub opacity: f64,
}

/// One control point of a transfer function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransferPoint {
    /// Position in the window, in [0, 1].
    pub x: f64,
    /// Linear RGB colour emitted (>= 0).
    pub color: [f64; 3],
    /// Extinction: opacity per unit of world length (>= 0); a slab of thickness L with this
    /// opacity lets exp(-opacity L) of the light through.
    pub opacity: f64,
}

/// A preset's control points: (x, colour, opacity).
pub type PresetPoints = &'static [(f64, [f64; 3], f64)];

/// The transfer-function presets, by name.
pub const TRANSFER_PRESETS: &[(&str, PresetPoints)] = &[
    ("grayscale", &[(0.0, [0.0; 3], 0.0), (1.0, [1.0; 3], 1.0)]),
    (
        "ct-bone",
        &[
            (0.0, [0.0; 3], 0.0),
            (0.25, [0.6, 0.25, 0.2], 0.0),
            (0.35, [0.8, 0.45, 0.35], 0.04),
            (0.5, [0.9, 0.8, 0.65], 0.15),
            (0.7, [1.0, 0.97, 0.9], 1.0),
            (1.0, [1.0, 1.0, 1.0], 1.0),
        ],
    ),
    (
        "mri",
        &[
            (0.0, [0.0; 3], 0.0),
            (0.12, [0.0; 3], 0.0),
            (0.2, [0.85, 0.55, 0.45], 0.06),
            (0.35, [0.9, 0.75, 0.65], 0.1),
            (0.5, [0.95, 0.9, 0.85], 0.6),
            (1.0, [1.0, 1.0, 1.0], 1.0),
        ],
    ),
    (
        "hot",
        &[
            (0.0, [0.0; 3], 0.0),
            (0.35, [0.8, 0.05, 0.0], 0.35),
            (0.7, [1.0, 0.75, 0.0], 0.7),
            (1.0, [1.0, 1.0, 1.0], 1.0),
        ],
    ),
    (
        "cool-warm",
        &[
            (0.0, [0.23, 0.3, 0.75], 0.0),
            (0.5, [0.86, 0.86, 0.86], 0.5),
            (1.0, [0.71, 0.02, 0.15], 1.0),
        ],
    ),
];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The nearest voxel's value (blocky, faster).
    Nearest,
    /// Trilinear between the 8 surrounding voxel centres.
    Trilinear,
}

/// Gradient shading of volume samples: the normal is the negated, normalised gradient of the
/// interpolated field (central differences); lighting is two-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeShadingDesc {
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    pub shininess: f64,
    /// Shadow rays from each visible sample toward each light, through volumes and geometry.
    pub shadows: bool,
}

impl Default for VolumeShadingDesc {
    fn default() -> Self {
        VolumeShadingDesc {
            ambient: 0.3,
            diffuse: 0.7,
            specular: 0.2,
            shininess: 20.0,
            shadows: false,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct OutputDesc {
    /// Output file, resolved against the scene file's directory.
    pub path: PathBuf,
    /// Writer plugin name; `None`: chosen by the file extension.
    pub plugin: Option<Spanned<String>>,
    /// RON text of the writer's params ("()" when absent).
    pub params: String,
    pub params_at: Origin,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderDesc {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel (1 = one ray through each pixel centre).
    pub samples: u32,
    /// Maximum ray depth: 0 = primary rays only... a ray at depth `max_depth` is not traced
    /// further and sees the background colour.
    pub max_depth: u32,
    /// A ray whose contribution to its pixel falls below this is not traced.
    pub min_weight: f64,
    pub outputs: Vec<OutputDesc>,
    pub parallel: ParallelDesc,
    /// Animation frame number (seeds the sampler).
    pub frame: u32,
    /// Shutter time of the frame (rays carry it).
    pub time: f64,
    pub transparency: TransparencyDesc,
    /// Multiplies every volume's step (> 0): 2 samples half as often.
    pub volume_step: f64,
    /// Skip bricks the transfer function makes fully transparent (same image, faster).
    pub volume_skip: bool,
    /// Adaptive supersampling; `None`: every pixel gets `samples` samples.
    pub adaptive: Option<AdaptiveDesc>,
    /// Multiplies every light's direct contribution, diffuse and highlight (not the ambient
    /// term or occlusion): Tachyon's `-rescale_lights`.
    pub light_scale: f64,
    /// Rules of Tachyon's shading that Tachyon scenes render with (all off by default).
    pub tachyon: TachyonDesc,
    /// The memory budget (`memory: "6 GiB"` or `"50%"`); `None`: the default share of the
    /// machine's memory (the core works it out).
    pub memory: Option<MemorySize>,
    /// Bytes of decoded texture data kept at once (`texture_cache: "1 GiB"`); `None`: 1 GiB,
    /// or a quarter of the memory budget when that is less.
    pub texture_cache: Option<u64>,
    /// How instances of prototypes are realised (`instancing: Auto`).
    pub instancing: Instancing,
}

/// How instances of prototypes are realised: flat copies of the prototype's geometry in the
/// scene's own sets (bitwise the same picture as the geometry written out flat), or one copy
/// per prototype shared by its instances through a two-level BVH (little memory; the picture
/// within rounding of the flat one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Instancing {
    /// Bake a prototype's static instances where baking is exact and small (every instance
    /// a similarity when the prototype holds spheres, cones or discs, and at most
    /// `2^20` primitives in all its copies); share them otherwise.
    #[default]
    Auto,
    /// Always bake (an error names an instance that cannot be).
    Bake,
    /// Always share.
    Share,
}

/// Tachyon's shading rules that have no other use: the Tachyon importer turns them on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TachyonDesc {
    /// A light counts at a point only where its term N·L · attenuation · spot weight · light
    /// scale exceeds 1/510 (and a highlight only where its cosine does); mirror and
    /// transmission coefficients of 1/510 or less are ignored.
    pub light_threshold: bool,
    /// Highlights take the light's whole colour: no distance attenuation, spot fade or
    /// filtering by transparent surfaces in the way (they still need the light in front of
    /// the surface and not blocked by an opaque one); a `Surface`-coloured highlight takes the
    /// surface's colour in place of the light's (Tachyon's METAL).
    pub plain_highlights: bool,
    /// A reflected or transmitted ray past `max_depth` adds the background colour unscaled
    /// (not times the mirror or transmission coefficient).
    pub depth_limit_background: bool,
    /// A pixel's first sample is its centre and the others fall anywhere in it, uniformly
    /// (Tachyon's antialiasing, whose pixels weight the centre by 1/samples), not stratified.
    pub centre_sample: bool,
    /// Volumes composite as Tachyon's SCALARVOL: each sample adds its opacity σ·dt and its
    /// colour times that, without attenuation, until the sum S reaches 1, and the volume
    /// counts twice (Tachyon shades its box's front face, then through it the back face from
    /// inside): C·(2 − S) + (1 − S)² × what lies behind. Samples take their transfer
    /// function's colour unshaded (as Tachyon's); shadow rays are as before.
    pub additive_volumes: bool,
    /// Smooth meshes shadow themselves near the terminator as their flat facets do: light
    /// and occlusion rays start at the hit point, not lifted onto the smooth surface.
    pub terminator_shadows: bool,
}

/// A memory size as a scene (`render: (memory: ...)`) or the command line (`--memory`) gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MemorySize {
    Bytes(u64),
    /// A share of the machine's memory limit, in percent (above 0, at most 100).
    Percent(f64),
}

impl std::fmt::Display for MemorySize {
    /// As a scene writes it, in the largest unit that divides it ("6 GiB", "100 B", "50%"):
    /// [`parse_memory_size`] reads it back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            MemorySize::Bytes(n) => {
                let unit = [(40, "TiB"), (30, "GiB"), (20, "MiB"), (10, "KiB")]
                    .into_iter()
                    .find(|&(shift, _)| n >= 1 << shift && n % (1 << shift) == 0);
                match unit {
                    Some((shift, name)) => write!(f, "{} {name}", n >> shift),
                    None => write!(f, "{n} B"),
                }
            }
            MemorySize::Percent(p) => write!(f, "{p}%"),
        }
    }
}

/// What a size looks like, for messages.
pub const MEMORY_SIZE_EXAMPLES: &str = "a size such as 512M, 6G, \"1.5 GiB\" or 50%";

/// Parses a memory size: a number with a binary unit (`K`, `M`, `G`, `T`, also written `KiB`,
/// `MiB`, `GiB`, `TiB`, or `KB`... with the same binary meaning; `B` for bytes), or a
/// percentage of the machine's memory (`50%`). Spaces between number and unit are allowed.
/// The error says what is wrong, without the text itself (callers quote it with its place).
pub fn parse_memory_size(text: &str) -> Result<MemorySize, String> {
    let t = text.trim();
    let end = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = (&t[..end], t[end..].trim());
    let value: f64 = match number.parse() {
        Ok(v) if number.chars().next().is_some_and(|c| c.is_ascii_digit()) => v,
        _ => return Err("it does not start with a number".into()),
    };
    if unit == "%" {
        if !(value > 0.0 && value <= 100.0) {
            return Err("a percentage must be above 0 and at most 100".into());
        }
        return Ok(MemorySize::Percent(value));
    }
    let shift = match unit.to_ascii_uppercase().as_str() {
        "" => return Err("it has no unit".into()),
        "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        "T" | "TB" | "TIB" => 40,
        _ => return Err(format!("`{}` is not a unit", crate::error::shown(unit))),
    };
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes >= 1.0 && bytes < 2f64.powi(63)) {
        return Err("the size must be at least 1 byte and below 8 EiB".into());
    }
    Ok(MemorySize::Bytes(bytes as u64))
}

/// Adaptive supersampling (Stone's thesis, II.E): a pixel starts with a jittered 2x2 grid per
/// cell and a cell whose samples differ by more than `threshold` is split into four, each
/// sampled in turn, down to `max_depth` splits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveDesc {
    /// Largest difference (any colour channel, clamped to [0, 1]) between the samples of a cell
    /// that is still accepted without splitting it.
    pub threshold: f64,
    /// How many times a cell may be split (0: never, so only the base samples).
    pub max_depth: u32,
}

/// The deepest split allowed: 4^(6+1) samples per base cell at most.
pub const ADAPTIVE_MAX_DEPTH: u32 = 6;

/// How transparent surfaces combine with what is behind them, and shadow through them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransparencyDesc {
    pub mode: TransparencyMode,
    /// How the transmit coefficient changes with the viewing angle (materials may override
    /// it); must be `Constant` with `AngleModulated`, which has its own rule.
    pub angle: TransparencyAngle,
    /// The most transparent surfaces a path shows (Tachyon's limit: deep stacks of molecular
    /// surfaces stay legible); `beyond_max` says what becomes of the next ones. `None`: no
    /// limit.
    pub max_surfaces: Option<u32>,
    pub beyond_max: BeyondMax,
    /// What a shadow ray keeps through a transparent surface.
    pub shadows: TransparentShadows,
    /// `PostMultiplied` only: the mirror reflection is scaled by opacity too (VMD's Tachyon).
    pub scale_reflection: bool,
}

impl Default for TransparencyDesc {
    fn default() -> Self {
        TransparencyDesc {
            mode: TransparencyMode::Filter,
            angle: TransparencyAngle::Constant,
            max_surfaces: None,
            beyond_max: BeyondMax::Opaque,
            shadows: TransparentShadows::Tinted,
            scale_reflection: false,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransparencyMode {
    /// Ambient and diffuse scaled by opacity, highlights kept, light from behind filtered by
    /// the surface colour (Luxon's default).
    Filter,
    /// `Filter`, and a surface is more opaque seen edge-on (its transmittance t becomes
    /// t^(1/|cos θ|), a slab seen at angle θ).
    AngleModulated,
    /// VMD's post-multiplied: the fully shaded colour (highlights too) times opacity, plus the
    /// unfiltered light from behind times transmittance.
    PostMultiplied,
    /// Tachyon's original (`TRANS_ORIG`): the surface's shading as if opaque, plus the
    /// unfiltered light from behind times transmittance.
    Additive,
}

/// How a surface's transmit coefficient changes with the angle it is seen at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransparencyAngle {
    /// It does not.
    Constant,
    /// Tachyon's Raster3D rule: opacity o seen along D becomes ¼(1 + cos(π(1 − o)(N·D)))²,
    /// more transparent edge-on.
    Raster3D,
}

/// What becomes of transparent surfaces past `max_surfaces`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeyondMax {
    /// The next one is shown opaque.
    Opaque,
    /// They are not shown at all: rays pass through them (Tachyon's).
    Skip,
}

/// What a shadow (or occlusion) ray keeps through each transparent surface it crosses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransparentShadows {
    /// transmit × colour: coloured glass casts coloured shadows.
    Tinted,
    /// transmit, grey (Tachyon's).
    Untinted,
    /// All of it: transparent surfaces cast no shadow (Tachyon's SHADOW_FILTER_OFF).
    Off,
}

impl Default for RenderDesc {
    fn default() -> Self {
        RenderDesc {
            width: 512,
            height: 512,
            samples: 1,
            max_depth: 8,
            min_weight: 1.0 / 512.0,
            outputs: Vec::new(),
            parallel: ParallelDesc::default(),
            frame: 0,
            time: 0.0,
            transparency: TransparencyDesc::default(),
            volume_step: 1.0,
            volume_skip: true,
            adaptive: None,
            light_scale: 1.0,
            tachyon: TachyonDesc::default(),
            memory: None,
            texture_cache: None,
            instancing: Instancing::Auto,
        }
    }
}

/// How the work is spread: threads in one process, MPI ranks, or both (hybrid), and how pixels are dealt.
#[derive(Clone, Debug, PartialEq)]
pub struct ParallelDesc {
    pub mode: ParallelMode,
    /// Threads per process; `None`: every CPU the process may use.
    pub threads: Option<u32>,
    pub decomposition: Decomposition,
    /// Tile or block edge in pixels.
    pub tile_size: u32,
    /// How finished pixels reach the output files.
    pub io: OutputIo,
    /// How the MPI ranks share the frames of a sequence.
    pub frames: FrameGroups,
}

impl Default for ParallelDesc {
    fn default() -> Self {
        ParallelDesc {
            mode: ParallelMode::Threads,
            threads: None,
            decomposition: Decomposition::Dynamic,
            tile_size: 16,
            io: OutputIo::Async,
            frames: FrameGroups::Auto,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ParallelMode {
    #[default]
    Threads,
    Mpi,
    Hybrid,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Decomposition {
    PixelCyclic,
    ScanlineCyclic,
    BlockCyclic,
    #[default]
    Dynamic,
}

/// How finished pixels reach the output files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum OutputIo {
    /// Rank 0 hands finished rows to a writer thread while rendering goes on.
    #[default]
    Async,
    /// Rank 0 writes every output after the whole image is rendered.
    Sync,
    /// Every MPI rank writes its own pixels of 8-bit PPM outputs (`MPI_File_write_at_all`);
    /// other outputs, and runs without MPI, as `Async`.
    MpiIo,
}

/// How the MPI ranks of a job share the frames of a sequence (`render: (parallel: (frames:
/// ...))`). Every choice gives the same images; they differ in speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrameGroups {
    /// `Whole` when the run has at least as many frames as ranks, else `Shared`.
    #[default]
    Auto,
    /// Each rank renders whole frames taken from a queue (groups of one rank).
    Whole,
    /// Consecutive ranks form groups of this many (the last may be smaller); each group takes
    /// frames from the queue and shares each frame's pixels by `decomposition`.
    Groups(u32),
    /// Every rank works on every frame (one group of all ranks).
    Shared,
}

impl FrameGroups {
    /// Ranks per group for a run of `frames` frames on `ranks` ranks (at least 1, at most
    /// `ranks`).
    pub fn group_size(self, frames: usize, ranks: usize) -> usize {
        let ranks = ranks.max(1);
        let n = match self {
            FrameGroups::Auto if frames >= ranks => 1,
            FrameGroups::Auto | FrameGroups::Shared => ranks,
            FrameGroups::Whole => 1,
            FrameGroups::Groups(n) => n as usize,
        };
        n.clamp(1, ranks)
    }
}

/// A scene's time: which frames it has and how keyed values change from frame to frame. Time is
/// counted in frames (keys may sit at fractional frames); `fps` only converts to seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationDesc {
    /// The first and last frame, inclusive (`first <= last`).
    pub first: u32,
    pub last: u32,
    /// Frames per second (> 0).
    pub fps: f64,
    /// The shutter, in frames; `None`: none given (no motion blur).
    pub shutter: Option<Spanned<ShutterDesc>>,
    pub camera: CameraTracks,
    /// Keyed lights, at most one entry per light.
    pub lights: Vec<LightTracks>,
    /// Keyed materials, at most one entry per material.
    pub materials: Vec<MaterialTracks>,
    /// Keyed objects (by their `name`), at most one entry per object.
    pub objects: Vec<ObjectTracks>,
    /// Keyed instances: written in `objects:` by the instance's `name`; here `object` is the
    /// index in `SceneDesc::instances`.
    pub instances: Vec<ObjectTracks>,
}

/// How long the shutter stays open (in frames, from 0 to 2) and where that interval sits
/// around the frame's time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShutterDesc {
    pub length: f64,
    pub at: ShutterAt,
}

impl ShutterDesc {
    /// (open, close) relative to the frame's time, in frames.
    pub fn interval(&self) -> (f64, f64) {
        let l = self.length;
        match self.at {
            ShutterAt::Start => (0.0, l),
            ShutterAt::Centre => (-0.5 * l, 0.5 * l),
            ShutterAt::End => (-l, 0.0),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShutterAt {
    Start,
    Centre,
    End,
}

/// How a track moves between its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Interpolate {
    /// Straight from key to key (rotations: slerp along the shorter arc).
    #[default]
    Linear,
    /// The smooth curve through every key (non-uniform Catmull-Rom in the key times).
    CatmullRom,
}

/// A value at a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Key<T> {
    pub frame: f64,
    pub value: T,
    /// Where the key is written.
    pub at: Origin,
}

/// Keys in strictly increasing frame order (at least one). Before the first key and after the
/// last the value holds; one key is a constant.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    pub keys: Vec<Key<T>>,
    pub interpolation: Interpolate,
    /// Where the track is written.
    pub at: Origin,
}

/// A rotation by `degrees` about `axis` (unit length), counter-clockwise looking down the axis
/// (right-handed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotationDesc {
    pub axis: [f64; 3],
    pub degrees: f64,
}

/// The camera's keyed values; each replaces the camera's own value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraTracks {
    pub position: Option<Track<[f64; 3]>>,
    pub look_at: Option<Track<[f64; 3]>>,
    pub up: Option<Track<[f64; 3]>>,
    /// Vertical field of view in degrees (a perspective camera given by `fov`).
    pub fov: Option<Track<f64>>,
    /// The sharp distance of the camera's `depth_of_field`.
    pub focal_distance: Option<Track<f64>>,
}

impl CameraTracks {
    pub fn is_empty(&self) -> bool {
        self.position.is_none()
            && self.look_at.is_none()
            && self.up.is_none()
            && self.fov.is_none()
            && self.focal_distance.is_none()
    }
}

/// A light's keyed values. `position` is a point or spot light's position, a sphere light's
/// centre or a rectangle light's corner; `direction` a directional or spot light's.
#[derive(Clone, Debug, PartialEq)]
pub struct LightTracks {
    /// Index in `SceneDesc::lights`.
    pub light: usize,
    /// The light's `name`, where the animation names it.
    pub name: Spanned<String>,
    pub position: Option<Track<[f64; 3]>>,
    pub direction: Option<Track<[f64; 3]>>,
    pub intensity: Option<Track<f64>>,
    pub color: Option<Track<[f64; 3]>>,
}

/// A material's keyed colour.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialTracks {
    /// The material's name, where the animation names it.
    pub material: Spanned<String>,
    pub color: Option<Track<[f64; 3]>>,
}

/// A named object's keyed transform: `world_from_object = translate · rotate · scale` (scaled
/// first, then rotated, then moved), applied to the coordinates its plugin gives. A missing
/// track is the identity.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectTracks {
    /// Index in `SceneDesc::objects`.
    pub object: usize,
    /// The object's `name`, where the animation names it.
    pub name: Spanned<String>,
    pub translate: Option<Track<[f64; 3]>>,
    pub rotate: Option<Track<RotationDesc>>,
    pub scale: Option<Track<[f64; 3]>>,
}
