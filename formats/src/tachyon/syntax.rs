//! The syntax tree of a Tachyon scene: every statement and option as written, in file order,
//! each with its source position. Nothing is mapped or dropped here; the mapping to Luxon
//! (`map.rs` and its helpers) reads this tree, so a feature Luxon cannot render yet is still
//! in the tree for the day it can.
//!
//! Coordinates are Tachyon's own (left-handed world, z not mirrored yet).

use std::path::PathBuf;

use crate::origin::{Origin, Spanned};

/// A point, direction or colour: three numbers.
pub type V3 = [f64; 3];

/// A whole scene: the main file with its includes spliced in.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The main file.
    pub source: PathBuf,
    /// `BEGIN_SCENE`.
    pub begin: Origin,
    /// `RESOLUTION x y`, at the keyword.
    pub resolution: Spanned<[u32; 2]>,
    /// In file order; an `INCLUDE` statement is followed by the included file's statements.
    pub statements: Vec<Statement>,
    /// `END_SCENE` of the main file, if the file has one.
    pub end: Option<Origin>,
    /// Problems found while reading that did not stop it (missing image maps...).
    pub warnings: Vec<Spanned<String>>,
}

/// A statement and where its keyword is.
#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    pub at: Origin,
    pub kind: Kind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    ShaderMode(ShaderMode),
    Camera(Camera),
    Background(V3),
    BackgroundGradient(Gradient),
    Fog(Fog),
    Light(Light),
    DirectionalLight {
        direction: V3,
        color: V3,
    },
    Spotlight(Spotlight),
    SkyLight {
        samples: u32,
        color: V3,
    },
    TexDef {
        name: Spanned<String>,
        body: TexBody,
    },
    TexAlias {
        name: Spanned<String>,
        target: Spanned<String>,
    },
    ImageDef(ImageDef),
    /// `INCLUDE path`: the included file's statements follow this one.
    Include {
        path: Spanned<String>,
        file: PathBuf,
    },
    Sphere {
        center: V3,
        rad: f64,
        tex: TexRef,
    },
    Tri {
        v: [V3; 3],
        tex: TexRef,
    },
    Stri {
        v: [V3; 3],
        n: [V3; 3],
        tex: TexRef,
    },
    /// A smooth triangle with vertex colours and a surface without colour or TEXFUNC.
    Vcstri {
        v: [V3; 3],
        n: [V3; 3],
        c: [V3; 3],
        surface: Surface,
    },
    VertexArray(VertexArray),
    /// An open cylinder from `base` to `apex`.
    Fcylinder {
        base: V3,
        apex: V3,
        rad: f64,
        tex: TexRef,
    },
    /// An infinite cylinder around the line through `center` along `axis`.
    Cylinder {
        center: V3,
        axis: V3,
        rad: f64,
        tex: TexRef,
    },
    Ring {
        center: V3,
        normal: V3,
        inner: f64,
        outer: f64,
        tex: TexRef,
    },
    Plane {
        center: V3,
        normal: V3,
        tex: TexRef,
    },
    Box {
        min: V3,
        max: V3,
        tex: TexRef,
    },
    Polycylinder {
        points: Vec<V3>,
        rad: f64,
        tex: TexRef,
    },
    /// Generated terrain: `res` grid points, `scale` world size, heights along y.
    Scape {
        res: [u32; 2],
        scale: [f64; 2],
        center: V3,
        tex: TexRef,
    },
    ScalarVol {
        min: V3,
        max: V3,
        dim: [u32; 3],
        file: Spanned<String>,
        /// The file found (working directory first, then beside the scene); `None`: missing.
        path: Option<PathBuf>,
        tex: TexRef,
    },
    TpolyFile {
        scale: V3,
        rot: V3,
        center: V3,
        file: Spanned<String>,
        path: PathBuf,
        /// The file's triangles as read (before SCALE, ROT and CENTER).
        triangles: Vec<[V3; 3]>,
        tex: TexRef,
    },
    /// Clip planes `a x + b y + c z > d` cut away what follows, up to `END_CLIPGROUP`.
    StartClipGroup {
        planes: Vec<[f64; 4]>,
    },
    EndClipGroup,
}

/// `SHADER_MODE level { option } END_SHADER_MODE`.
#[derive(Clone, Debug, PartialEq)]
pub struct ShaderMode {
    pub level: Spanned<ShadeLevel>,
    pub options: Vec<Spanned<ShaderOption>>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadeLevel {
    Full,
    Medium,
    Low,
    Lowest,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ShaderOption {
    /// `SHADOW_FILTER_ON` (true) / `SHADOW_FILTER_OFF`.
    ShadowFilter(bool),
    TransMaxSurfaces(u32),
    TransOrig,
    TransRaster3d,
    TransVmd,
    FogVmd,
    AmbientOcclusion {
        color: V3,
        rescale_direct: f64,
        samples: u32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// `PROJECTION ...`; `None`: perspective.
    pub projection: Option<Spanned<Projection>>,
    pub zoom: f64,
    pub aspect: f64,
    pub antialiasing: u32,
    pub raydepth: u32,
    pub center: V3,
    pub viewdir: V3,
    pub updir: V3,
    /// `FRUSTUM left right bottom top`.
    pub frustum: Option<Spanned<[f64; 4]>>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    Perspective,
    Orthographic,
    Fisheye,
    /// `PERSPECTIVE_DOF FOCALLENGTH f APERTURE a` (Tachyon 0.99b6), or VMD's `FOCALDIST f
    /// APERTURE a` (`focal_dist` true).
    PerspectiveDof {
        focal: f64,
        focal_dist: bool,
        aperture: f64,
    },
}

/// `BACKGROUND_GRADIENT`.
#[derive(Clone, Debug, PartialEq)]
pub struct Gradient {
    pub kind: Spanned<SkyKind>,
    pub updir: V3,
    pub topval: f64,
    pub bottomval: f64,
    pub topcolor: V3,
    pub bottomcolor: V3,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkyKind {
    Sphere,
    OrthoPlane,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Fog {
    pub mode: Spanned<FogMode>,
    pub start: f64,
    pub end: f64,
    pub density: f64,
    pub color: V3,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FogMode {
    Linear,
    Exp,
    Exp2,
    Off,
}

/// `LIGHT`: a point light; with `rad > 0` Tachyon also draws it as a sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub center: V3,
    pub rad: f64,
    /// `ATTENUATION CONSTANT c LINEAR l QUADRATIC q`.
    pub attenuation: Option<Spanned<V3>>,
    pub color: V3,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Spotlight {
    pub center: V3,
    pub rad: f64,
    pub direction: V3,
    /// Half-angles from the axis in degrees: full light inside `falloff_start`, none beyond
    /// `falloff_end`.
    pub falloff_start: f64,
    pub falloff_end: f64,
    pub attenuation: Option<Spanned<V3>>,
    pub color: V3,
}

/// A texture reference: an inline body (`TEXTURE body`) or a name (`TEXDEF`, `TEXALIAS`).
#[derive(Clone, Debug, PartialEq)]
pub enum TexRef {
    Body(Box<TexBody>),
    Name(Spanned<String>),
}

/// A texture body: surface coefficients, colour and texture function.
#[derive(Clone, Debug, PartialEq)]
pub struct TexBody {
    /// The body's first word (`AMBIENT`).
    pub at: Origin,
    pub surface: Surface,
    pub color: V3,
    pub texfunc: Spanned<TexFunc>,
}

/// `AMBIENT DIFFUSE SPECULAR OPACITY [TRANSMODE] [OUTLINE OUTLINE_WIDTH] [PHONG PHONG_SIZE]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    pub ambient: f64,
    pub diffuse: f64,
    /// Mirror reflectance.
    pub specular: f64,
    pub opacity: f64,
    /// `TRANSMODE word` (only `R3D` means anything to Tachyon).
    pub transmode: Option<Spanned<String>>,
    /// `OUTLINE o OUTLINE_WIDTH w`.
    pub outline: Option<Spanned<[f64; 2]>>,
    pub phong: Option<Spanned<Phong>>,
}

/// `PHONG kind phong PHONG_SIZE size`.
#[derive(Clone, Debug, PartialEq)]
pub struct Phong {
    pub kind: PhongKind,
    pub phong: f64,
    pub size: f64,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PhongKind {
    Plastic,
    Metal,
    /// Any other word: plastic to Tachyon.
    Other(String),
}

/// `TEXFUNC n [arguments]`.
#[derive(Clone, Debug, PartialEq)]
pub enum TexFunc {
    /// 0, or any number without a meaning (plain colour, no arguments).
    Plain(i64),
    /// 1 to 6: solid textures placed by CENTER, ROTATE, SCALE.
    Solid { kind: SolidKind, frame: Frame },
    /// 7, 8, 9: image maps.
    Image {
        kind: ImageKind,
        file: Spanned<String>,
        /// The file found (working directory first, then beside the scene); `None`: missing.
        path: Option<PathBuf>,
        frame: Frame,
        /// UAXIS, VAXIS (planar maps only).
        axes: Option<[V3; 2]>,
    },
    /// 10: a volume texture from an `IMAGEDEF` block.
    Volume {
        image: Spanned<String>,
        frame: Frame,
        /// UAXIS, VAXIS, WAXIS.
        axes: [V3; 3],
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolidKind {
    Checker = 1,
    Grit = 2,
    Marble = 3,
    Wood = 4,
    Gnoise = 5,
    CylChecker = 6,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    Cylindrical = 7,
    Spherical = 8,
    Planar = 9,
}

/// CENTER, ROTATE, SCALE of a texture function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub center: V3,
    pub rotate: V3,
    pub scale: V3,
}

/// `IMAGEDEF name FORMAT RGB24 RESOLUTION x y z ENCODING HEX texels`.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageDef {
    pub name: Spanned<String>,
    pub res: [u32; 3],
    /// x fastest, then y, then z.
    pub texels: Vec<[u8; 3]>,
}

/// `VERTEXARRAY NUMVERTS n COORDS ... NORMALS ... { block } END_VERTEXARRAY`.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexArray {
    pub coords: Vec<V3>,
    pub normals: Vec<V3>,
    pub blocks: Vec<Spanned<VertexBlock>>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum VertexBlock {
    /// One colour per vertex, for the meshes that follow.
    Colors(Vec<V3>),
    /// The texture of the meshes that follow.
    Texture(Box<TexBody>),
    TriMesh(Vec<[u32; 3]>),
    /// `k` indices: `k - 2` triangles.
    TriStrip(Vec<u32>),
}
