//! The statements of a Tachyon 0.99b6 scene file, read into the syntax tree (`syntax.rs`).
//!
//! The grammar is Tachyon's, measured on `tachyon-nox` (word order fixed inside a statement,
//! optional parts in Tachyon's order); where Tachyon reads past a mistake and renders something
//! else, this parser stops with an error at `file:line:col` saying what was expected and what
//! was found. Where Tachyon's leniency is what real files rely on, the parser warns and goes
//! on: missing image maps (white) and volume files (a box in the texture's colour).

use std::fmt::{self, Display};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::files;
use super::lex::{self, is, Lexer, NumberError, Word};
use super::syntax::*;
use crate::error::{suggest, SceneError};
use crate::origin::{Origin, Spanned};

type Result<T> = std::result::Result<T, SceneError>;

/// How deep INCLUDEs may nest.
const MAX_INCLUDE_DEPTH: usize = 32;

/// Statement keywords, for "did you mean".
const STATEMENTS: &[&str] = &[
    "SHADER_MODE",
    "CAMERA",
    "BACKGROUND",
    "BACKGROUND_GRADIENT",
    "FOG",
    "LIGHT",
    "DIRECTIONAL_LIGHT",
    "SPOTLIGHT",
    "SKY_LIGHT",
    "TEXDEF",
    "TEXALIAS",
    "IMAGEDEF",
    "INCLUDE",
    "SPHERE",
    "TRI",
    "STRI",
    "VCSTRI",
    "VERTEXARRAY",
    "FCYLINDER",
    "CYLINDER",
    "RING",
    "PLANE",
    "BOX",
    "POLYCYLINDER",
    "SCAPE",
    "SCALARVOL",
    "TPOLYFILE",
    "START_CLIPGROUP",
    "END_CLIPGROUP",
    "END_SCENE",
];

/// Words the Tachyon manual (or newer Tachyons) name that 0.99b6 does not read.
const NOT_IN_099: &[&str] = &[
    "SPHEREARRAY",
    "QUADRIC",
    "HEIGHTFIELD",
    "TRIMESH",
    "MGFFILE",
];

/// Reads the scene file at `path` and everything it includes, `max_text` bytes of text at most
/// (the scene, its INCLUDEs and `.tpoly` files together).
pub(super) fn parse_file(path: &Path, max_text: u64) -> Result<Scene> {
    let text = files::read_text(path, max_text).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut cx = Context {
        statements: Vec::new(),
        warnings: Vec::new(),
        chain: vec![canonical(path)],
        text_left: max_text.saturating_sub(text.len() as u64),
    };
    let file = Arc::new(path.to_path_buf());
    let mut p = Parser {
        lex: Lexer::new(&text, file),
        dir: directory_of(path),
        form: "",
        cx: &mut cx,
    };
    let (begin, resolution) = p.header()?;
    let end = p.statements()?;
    Ok(Scene {
        source: path.to_path_buf(),
        begin,
        resolution,
        statements: cx.statements,
        end,
        warnings: cx.warnings,
    })
}

/// Reads the triangles of a `.tpoly` file: records of `3` and three vertices (9 numbers),
/// until a count other than 3 or the end of the file (Tachyon's rule). At most `text_left`
/// bytes, which its size is taken from.
pub(super) fn read_tpoly(path: &Path, text_left: &mut u64) -> Result<Vec<[V3; 3]>> {
    let text = files::read_text(path, *text_left).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    *text_left = text_left.saturating_sub(text.len() as u64);
    let mut lex = Lexer::new(&text, Arc::new(path.to_path_buf()));
    let mut triangles = Vec::new();
    while let Some(w) = lex.next_word() {
        match lex::int(w.text) {
            Ok(3) => {}
            Ok(_) => break,
            Err(_) => {
                return Err(SceneError::at(
                    lex.origin(&w),
                    format!(
                        "expected the vertex count `3` of a triangle record, found `{}`",
                        lex::show(w.text)
                    ),
                ))
            }
        }
        let mut t = [[0.0; 3]; 3];
        for (i, corner) in t.iter_mut().enumerate() {
            for (k, x) in corner.iter_mut().enumerate() {
                let Some(w) = lex.next_word() else {
                    let end = lex.end();
                    return Err(SceneError::at(
                        end,
                        "expected 9 numbers after `3` (three vertices x y z), found the end of the file",
                    ));
                };
                *x = lex::float(w.text).map_err(|_| {
                    SceneError::at(
                        lex.origin(&w),
                        format!(
                            "expected a number ({} of vertex {i}), found `{}`",
                            ["x", "y", "z"][k],
                            lex::show(w.text)
                        ),
                    )
                })?;
            }
        }
        triangles.push(t);
    }
    Ok(triangles)
}

fn directory_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn canonical(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}

/// `` `kw` `` in messages.
#[derive(Clone, Copy)]
struct Quoted<'x>(&'x str);

impl Display for Quoted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "`{}`", self.0)
    }
}

/// `prefix` then `D`.
#[derive(Clone, Copy)]
struct Prefixed<D>(&'static str, D);

impl<D: Display> Display for Prefixed<D> {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}{}", self.0, self.1)
    }
}

/// A component of a field: "CENTER (x)".
#[derive(Clone, Copy)]
struct Part<D>(D, &'static str);

impl<D: Display> Display for Part<D> {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{} ({})", self.0, self.1)
    }
}

/// An element of a list: "vertex 3 of COORDS".
#[derive(Clone, Copy)]
struct Item<'x>(&'static str, u32, &'x str);

impl Display for Item<'_> {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{} {} of {}", self.0, self.1, self.2)
    }
}

/// What all files of one scene add to.
struct Context {
    statements: Vec<Statement>,
    warnings: Vec<Spanned<String>>,
    /// The files being read, outermost first (canonical paths): INCLUDE cycles.
    chain: Vec<PathBuf>,
    /// Bytes of text the files not yet read may hold.
    text_left: u64,
}

/// One file's reader.
struct Parser<'a, 'c> {
    lex: Lexer<'a>,
    /// Directory of this file: the second place relative paths are looked for.
    dir: PathBuf,
    /// The form of what is being read, for messages ("SPHERE CENTER x y z RAD r texture").
    form: &'static str,
    cx: &'c mut Context,
}

const TEXTURE_FORM: &str = "a texture: TEXTURE AMBIENT a DIFFUSE d SPECULAR s OPACITY o \
    [TRANSMODE R3D] [OUTLINE o OUTLINE_WIDTH w] [PHONG PLASTIC|METAL p PHONG_SIZE n] \
    COLOR r g b TEXFUNC n ..., or a texture name";

impl<'a> Parser<'a, '_> {
    // ----- words -------------------------------------------------------------------------

    fn origin(&self, w: &Word) -> Origin {
        self.lex.origin(w)
    }

    /// " (in FORM)" for messages.
    fn context(&self) -> String {
        if self.form.is_empty() {
            String::new()
        } else {
            format!(" (in {})", self.form)
        }
    }

    fn error<T>(&self, at: Origin, message: String) -> Result<T> {
        Err(SceneError::at(at, format!("{message}{}", self.context())))
    }

    /// The next word; at the end of the file an error saying `expected` was.
    fn word(&mut self, expected: impl Display) -> Result<Word<'a>> {
        match self.lex.next_word() {
            Some(w) => Ok(w),
            None => {
                let end = self.lex.end();
                self.error(
                    end,
                    format!("expected {expected}, found the end of the file"),
                )
            }
        }
    }

    /// The keyword `kw` (any case).
    fn keyword(&mut self, kw: &str) -> Result<Origin> {
        let w = self.word(Quoted(kw))?;
        if is(w.text, kw) {
            Ok(self.origin(&w))
        } else {
            self.error(
                self.origin(&w),
                format!("expected `{kw}`, found `{}`", lex::show(w.text)),
            )
        }
    }

    /// Whether the next word is `kw`; if so it is read.
    fn optional(&mut self, kw: &str) -> Option<Origin> {
        let w = self.lex.peek()?;
        if is(w.text, kw) {
            self.lex.next_word();
            Some(self.origin(&w))
        } else {
            None
        }
    }

    fn number_error<T>(&self, w: &Word, what: impl Display, e: NumberError) -> Result<T> {
        let found = lex::show(w.text);
        let message = match e {
            NumberError::NotANumber => format!("expected a number for {what}, found `{found}`"),
            NumberError::NotFinite => {
                format!("expected a finite number for {what}, found `{found}`")
            }
            NumberError::NotWhole => format!(
                "expected a whole number for {what}, found `{found}` (Tachyon reads this field \
                 as an integer)"
            ),
            NumberError::TooLarge => format!("{what} `{found}` is too large"),
        };
        self.error(self.origin(w), message)
    }

    /// A number; `what` names it in messages (formatted only for one).
    fn float(&mut self, what: impl Display + Copy) -> Result<f64> {
        let w = self.word(Prefixed("a number for ", what))?;
        lex::float(w.text).or_else(|e| self.number_error(&w, what, e))
    }

    fn vec3(&mut self, what: impl Display + Copy) -> Result<V3> {
        Ok([
            self.float(Part(what, "x"))?,
            self.float(Part(what, "y"))?,
            self.float(Part(what, "z"))?,
        ])
    }

    fn color(&mut self, what: impl Display + Copy) -> Result<V3> {
        Ok([
            self.float(Part(what, "red"))?,
            self.float(Part(what, "green"))?,
            self.float(Part(what, "blue"))?,
        ])
    }

    /// `KW x y z`.
    fn kv(&mut self, kw: &str) -> Result<V3> {
        self.keyword(kw)?;
        self.vec3(kw)
    }

    /// `KW r g b`.
    fn kc(&mut self, kw: &str) -> Result<V3> {
        self.keyword(kw)?;
        self.color(kw)
    }

    /// `KW f`.
    fn kf(&mut self, kw: &str) -> Result<f64> {
        self.keyword(kw)?;
        self.float(kw)
    }

    /// A whole number in `[min, max]` (C's `int` at most).
    fn whole(&mut self, what: impl Display + Copy, min: i64, max: i64) -> Result<i64> {
        let w = self.word(Prefixed("a whole number for ", what))?;
        let n = lex::int(w.text).or_else(|e| self.number_error(&w, what, e))?;
        if n < min || n > max {
            return self.error(
                self.origin(&w),
                format!("{what} is {n}; expected a whole number from {min} to {max}"),
            );
        }
        Ok(n)
    }

    /// A whole number in `[min, max]`, `min >= 0`.
    fn int(&mut self, what: impl Display + Copy, min: i64, max: i64) -> Result<u32> {
        Ok(self.whole(what, min.max(0), max)? as u32)
    }

    /// `KW n`.
    fn ki(&mut self, kw: &str, min: i64, max: i64) -> Result<u32> {
        self.keyword(kw)?;
        self.int(kw, min, max)
    }

    /// A name or path: any word.
    fn name(&mut self, what: &str) -> Result<Spanned<String>> {
        let w = self.word(what)?;
        Ok(Spanned {
            value: w.text.to_string(),
            at: self.origin(&w),
        })
    }

    fn warn(&mut self, at: Origin, message: String) {
        self.cx.warnings.push(Spanned { value: message, at });
    }

    // ----- the file ----------------------------------------------------------------------

    /// `BEGIN_SCENE RESOLUTION x y`, after any `#` comments.
    fn header(&mut self) -> Result<(Origin, Spanned<[u32; 2]>)> {
        let first = loop {
            match self.lex.next_word() {
                Some(w) if w.text == "#" => self.lex.skip_line(),
                Some(w) => break w,
                None => {
                    let end = self.lex.end();
                    return Err(SceneError::at(
                        end,
                        "expected `BEGIN_SCENE` (the first word of a Tachyon scene), found an \
                         empty file",
                    ));
                }
            }
        };
        if !is(first.text, "BEGIN_SCENE") {
            return Err(SceneError::at(
                self.origin(&first),
                format!(
                    "expected `BEGIN_SCENE` (the first word of a Tachyon scene; `.dat` files are \
                     read as Tachyon scenes), found `{}`",
                    lex::show(first.text)
                ),
            ));
        }
        let begin = self.origin(&first);
        self.form = "BEGIN_SCENE RESOLUTION x y";
        let at = self.keyword("RESOLUTION")?;
        let x = self.int("RESOLUTION (x)", 1, 65536)?;
        let y = self.int("RESOLUTION (y)", 1, 65536)?;
        self.form = "";
        Ok((begin, Spanned { value: [x, y], at }))
    }

    /// Statements up to `END_SCENE` (its position) or the end of the file (`None`).
    fn statements(&mut self) -> Result<Option<Origin>> {
        loop {
            let Some(w) = self.lex.next_word() else {
                return Ok(None);
            };
            if w.text == "#" {
                self.lex.skip_line();
                continue;
            }
            if is(w.text, "END_SCENE") {
                return Ok(Some(self.origin(&w)));
            }
            self.statement(w)?;
            self.form = "";
        }
    }

    fn push(&mut self, at: Origin, kind: Kind) {
        self.cx.statements.push(Statement { at, kind });
    }

    fn statement(&mut self, w: Word<'a>) -> Result<()> {
        let at = self.origin(&w);
        let k = w.text.to_ascii_uppercase();
        let kind = match k.as_str() {
            "SHADER_MODE" => Kind::ShaderMode(self.shader_mode()?),
            "CAMERA" => Kind::Camera(self.camera()?),
            "BACKGROUND" => {
                self.form = "BACKGROUND r g b";
                Kind::Background(self.color("BACKGROUND")?)
            }
            "BACKGROUND_GRADIENT" => Kind::BackgroundGradient(self.gradient()?),
            "FOG" => Kind::Fog(self.fog()?),
            "LIGHT" => Kind::Light(self.light()?),
            "DIRECTIONAL_LIGHT" => {
                self.form = "DIRECTIONAL_LIGHT DIRECTION x y z COLOR r g b";
                Kind::DirectionalLight {
                    direction: self.kv("DIRECTION")?,
                    color: self.kc("COLOR")?,
                }
            }
            "SPOTLIGHT" => Kind::Spotlight(self.spotlight()?),
            "SKY_LIGHT" => {
                self.form = "SKY_LIGHT NUMSAMPLES n COLOR r g b";
                Kind::SkyLight {
                    samples: self.ki("NUMSAMPLES", 0, i32::MAX as i64)?,
                    color: self.kc("COLOR")?,
                }
            }
            "TEXDEF" => {
                self.form = "TEXDEF name body";
                let name = self.name("a texture name after TEXDEF")?;
                Kind::TexDef {
                    name,
                    body: self.body()?,
                }
            }
            "TEXALIAS" => {
                self.form = "TEXALIAS newname existing";
                Kind::TexAlias {
                    name: self.name("the new texture name after TEXALIAS")?,
                    target: self.name("the existing texture name after TEXALIAS")?,
                }
            }
            "IMAGEDEF" => Kind::ImageDef(self.imagedef()?),
            "INCLUDE" => return self.include(at),
            "SPHERE" => {
                self.form = "SPHERE CENTER x y z RAD r texture";
                Kind::Sphere {
                    center: self.kv("CENTER")?,
                    rad: self.kf("RAD")?,
                    tex: self.texref()?,
                }
            }
            "TRI" => {
                self.form = "TRI V0 x y z V1 x y z V2 x y z texture";
                Kind::Tri {
                    v: [self.kv("V0")?, self.kv("V1")?, self.kv("V2")?],
                    tex: self.texref()?,
                }
            }
            "STRI" => {
                self.form = "STRI V0 .. V1 .. V2 .. N0 .. N1 .. N2 x y z texture";
                Kind::Stri {
                    v: [self.kv("V0")?, self.kv("V1")?, self.kv("V2")?],
                    n: [self.kv("N0")?, self.kv("N1")?, self.kv("N2")?],
                    tex: self.texref()?,
                }
            }
            "VCSTRI" => self.vcstri()?,
            "VERTEXARRAY" => Kind::VertexArray(self.vertex_array()?),
            "FCYLINDER" => {
                self.form = "FCYLINDER BASE x y z APEX x y z RAD r texture";
                Kind::Fcylinder {
                    base: self.kv("BASE")?,
                    apex: self.kv("APEX")?,
                    rad: self.kf("RAD")?,
                    tex: self.texref()?,
                }
            }
            "CYLINDER" => {
                self.form = "CYLINDER CENTER x y z AXIS x y z RAD r texture";
                Kind::Cylinder {
                    center: self.kv("CENTER")?,
                    axis: self.kv("AXIS")?,
                    rad: self.kf("RAD")?,
                    tex: self.texref()?,
                }
            }
            "RING" => {
                self.form = "RING CENTER x y z NORMAL x y z INNER r OUTER r texture";
                Kind::Ring {
                    center: self.kv("CENTER")?,
                    normal: self.kv("NORMAL")?,
                    inner: self.kf("INNER")?,
                    outer: self.kf("OUTER")?,
                    tex: self.texref()?,
                }
            }
            "PLANE" => {
                self.form = "PLANE CENTER x y z NORMAL x y z texture";
                Kind::Plane {
                    center: self.kv("CENTER")?,
                    normal: self.kv("NORMAL")?,
                    tex: self.texref()?,
                }
            }
            "BOX" => {
                self.form = "BOX MIN x y z MAX x y z texture";
                Kind::Box {
                    min: self.kv("MIN")?,
                    max: self.kv("MAX")?,
                    tex: self.texref()?,
                }
            }
            "POLYCYLINDER" => {
                self.form = "POLYCYLINDER POINTS n x y z ... RAD r texture";
                let n = self.ki("POINTS", 0, i32::MAX as i64)?;
                let mut points = Vec::with_capacity(n.min(4096) as usize);
                for i in 0..n {
                    points.push(self.vec3(Item("point", i, "POINTS"))?);
                }
                Kind::Polycylinder {
                    points,
                    rad: self.kf("RAD")?,
                    tex: self.texref()?,
                }
            }
            "SCAPE" => {
                self.form = "SCAPE RES m n SCALE wx wy CENTER x y z texture";
                self.keyword("RES")?;
                let res = [
                    self.int("RES (x)", 2, 65536)?,
                    self.int("RES (y)", 2, 65536)?,
                ];
                self.keyword("SCALE")?;
                let scale = [self.float("SCALE (x)")?, self.float("SCALE (y)")?];
                Kind::Scape {
                    res,
                    scale,
                    center: self.kv("CENTER")?,
                    tex: self.texref()?,
                }
            }
            "SCALARVOL" => self.scalarvol()?,
            "TPOLYFILE" => self.tpolyfile()?,
            "START_CLIPGROUP" => {
                self.form = "START_CLIPGROUP NUMPLANES n a b c d ...";
                let n = self.ki("NUMPLANES", 0, i32::MAX as i64)?;
                let mut planes = Vec::with_capacity(n.min(4096) as usize);
                for i in 0..n {
                    let what = |c| format!("plane {i} ({c} of a x + b y + c z = d)");
                    planes.push([
                        self.float(&what("a"))?,
                        self.float(&what("b"))?,
                        self.float(&what("c"))?,
                        self.float(&what("d"))?,
                    ]);
                }
                Kind::StartClipGroup { planes }
            }
            "END_CLIPGROUP" => Kind::EndClipGroup,
            _ => return self.unknown_statement(&w),
        };
        self.push(at, kind);
        Ok(())
    }

    fn unknown_statement<T>(&self, w: &Word) -> Result<T> {
        let found = lex::show(w.text);
        let at = self.origin(w);
        let upper = w.text.to_ascii_uppercase();
        let message = if w.text.starts_with('#') {
            format!(
                "expected a statement, found `{found}`: a comment is `#` as a word of its own \
                 (followed by a space), at the start of a statement; `#include` is `INCLUDE file`"
            )
        } else if NOT_IN_099.contains(&upper.as_str()) {
            format!(
                "`{found}` is not a statement of Tachyon 0.99b6's scene format (the manual or \
                 newer Tachyons mention it), nor of Luxon's Tachyon reader"
            )
        } else if lex::float(w.text).is_ok() {
            format!(
                "expected a statement keyword, found the number `{found}` (the statement before \
                 it has more numbers than it takes?)"
            )
        } else {
            match suggest(&upper, STATEMENTS.iter().copied()) {
                Some(close) => {
                    format!("unknown statement `{found}`; did you mean `{close}`?")
                }
                None => format!(
                    "unknown statement `{found}`; expected a statement keyword such as SPHERE, \
                     TRI, PLANE, LIGHT, CAMERA, TEXDEF or END_SCENE"
                ),
            }
        };
        Err(SceneError::at(at, message))
    }

    // ----- settings ----------------------------------------------------------------------

    fn shader_mode(&mut self) -> Result<ShaderMode> {
        self.form = "SHADER_MODE FULL|MEDIUM|LOW|LOWEST { option } END_SHADER_MODE";
        let w = self.word("a shading level (FULL, MEDIUM, LOW or LOWEST)")?;
        let level = match w.text.to_ascii_uppercase().as_str() {
            "FULL" => ShadeLevel::Full,
            "MEDIUM" => ShadeLevel::Medium,
            "LOW" => ShadeLevel::Low,
            "LOWEST" => ShadeLevel::Lowest,
            _ => {
                return self.error(
                    self.origin(&w),
                    format!(
                        "expected a shading level (FULL, MEDIUM, LOW or LOWEST) after \
                         SHADER_MODE, found `{}`",
                        lex::show(w.text)
                    ),
                )
            }
        };
        let level = Spanned {
            value: level,
            at: self.origin(&w),
        };
        const OPTIONS: &[&str] = &[
            "SHADOW_FILTER_ON",
            "SHADOW_FILTER_OFF",
            "TRANS_MAX_SURFACES",
            "TRANS_ORIG",
            "TRANS_RASTER3D",
            "TRANS_VMD",
            "FOG_VMD",
            "AMBIENT_OCCLUSION",
            "END_SHADER_MODE",
        ];
        let mut options = Vec::new();
        loop {
            let w = self.word("a shader option or END_SHADER_MODE")?;
            let at = self.origin(&w);
            let option = match w.text.to_ascii_uppercase().as_str() {
                "END_SHADER_MODE" => break,
                "SHADOW_FILTER_ON" => ShaderOption::ShadowFilter(true),
                "SHADOW_FILTER_OFF" => ShaderOption::ShadowFilter(false),
                "TRANS_MAX_SURFACES" => ShaderOption::TransMaxSurfaces(self.int(
                    "TRANS_MAX_SURFACES",
                    0,
                    i32::MAX as i64,
                )?),
                "TRANS_ORIG" => ShaderOption::TransOrig,
                "TRANS_RASTER3D" => ShaderOption::TransRaster3d,
                "TRANS_VMD" => ShaderOption::TransVmd,
                "FOG_VMD" => ShaderOption::FogVmd,
                "AMBIENT_OCCLUSION" => ShaderOption::AmbientOcclusion {
                    color: self.kc("AMBIENT_COLOR")?,
                    rescale_direct: self.kf("RESCALE_DIRECT")?,
                    samples: self.ki("SAMPLES", 0, i32::MAX as i64)?,
                },
                other => {
                    let hint = suggest(other, OPTIONS.iter().copied())
                        .map(|c| format!("; did you mean `{c}`?"))
                        .unwrap_or_else(|| format!("; expected one of {}", OPTIONS.join(", ")));
                    return self.error(
                        at,
                        format!("unknown shader option `{}`{hint}", lex::show(w.text)),
                    );
                }
            };
            options.push(Spanned { value: option, at });
        }
        Ok(ShaderMode { level, options })
    }

    fn camera(&mut self) -> Result<Camera> {
        self.form = "CAMERA [PROJECTION p] ZOOM z ASPECTRATIO a ANTIALIASING n RAYDEPTH n \
                     CENTER x y z VIEWDIR x y z UPDIR x y z [FRUSTUM l r b t] END_CAMERA";
        let projection = match self.optional("PROJECTION") {
            Some(_) => Some(self.projection()?),
            None => None,
        };
        let zoom = self.kf("ZOOM")?;
        let aspect = self.kf("ASPECTRATIO")?;
        let antialiasing = self.ki("ANTIALIASING", 0, 65535)?;
        let raydepth = self.ki("RAYDEPTH", 0, i32::MAX as i64)?;
        let center = self.kv("CENTER")?;
        let viewdir = self.kv("VIEWDIR")?;
        let updir = self.kv("UPDIR")?;
        let frustum = match self.optional("FRUSTUM") {
            Some(at) => Some(Spanned {
                value: [
                    self.float("FRUSTUM (left)")?,
                    self.float("FRUSTUM (right)")?,
                    self.float("FRUSTUM (bottom)")?,
                    self.float("FRUSTUM (top)")?,
                ],
                at,
            }),
            None => None,
        };
        self.keyword("END_CAMERA")?;
        Ok(Camera {
            projection,
            zoom,
            aspect,
            antialiasing,
            raydepth,
            center,
            viewdir,
            updir,
            frustum,
        })
    }

    fn projection(&mut self) -> Result<Spanned<Projection>> {
        let w = self.word("a projection")?;
        let at = self.origin(&w);
        let value = match w.text.to_ascii_uppercase().as_str() {
            "PERSPECTIVE" => Projection::Perspective,
            "ORTHOGRAPHIC" => Projection::Orthographic,
            "FISHEYE" => Projection::Fisheye,
            "PERSPECTIVE_DOF" => {
                let f = self.word("FOCALLENGTH (or VMD's FOCALDIST)")?;
                let focal_dist = match f.text.to_ascii_uppercase().as_str() {
                    "FOCALLENGTH" => false,
                    "FOCALDIST" => true,
                    _ => {
                        return self.error(
                            self.origin(&f),
                            format!(
                                "expected `FOCALLENGTH` (or VMD's `FOCALDIST`) after \
                                 PERSPECTIVE_DOF, found `{}`",
                                lex::show(f.text)
                            ),
                        )
                    }
                };
                let focal = self.float(if focal_dist {
                    "FOCALDIST"
                } else {
                    "FOCALLENGTH"
                })?;
                Projection::PerspectiveDof {
                    focal,
                    focal_dist,
                    aperture: self.kf("APERTURE")?,
                }
            }
            _ => {
                return self.error(
                    at,
                    format!(
                        "expected a projection (PERSPECTIVE, ORTHOGRAPHIC, FISHEYE or \
                         PERSPECTIVE_DOF), found `{}`",
                        lex::show(w.text)
                    ),
                )
            }
        };
        Ok(Spanned { value, at })
    }

    fn gradient(&mut self) -> Result<Gradient> {
        self.form = "BACKGROUND_GRADIENT SKY_SPHERE|SKY_ORTHO_PLANE UPDIR x y z TOPVAL t \
                     BOTTOMVAL b TOPCOLOR r g b BOTTOMCOLOR r g b";
        let w = self.word("SKY_SPHERE or SKY_ORTHO_PLANE")?;
        let kind = match w.text.to_ascii_uppercase().as_str() {
            "SKY_SPHERE" => SkyKind::Sphere,
            "SKY_ORTHO_PLANE" => SkyKind::OrthoPlane,
            _ => {
                return self.error(
                    self.origin(&w),
                    format!(
                        "expected SKY_SPHERE or SKY_ORTHO_PLANE after BACKGROUND_GRADIENT, found \
                         `{}`",
                        lex::show(w.text)
                    ),
                )
            }
        };
        Ok(Gradient {
            kind: Spanned {
                value: kind,
                at: self.origin(&w),
            },
            updir: self.kv("UPDIR")?,
            topval: self.kf("TOPVAL")?,
            bottomval: self.kf("BOTTOMVAL")?,
            topcolor: self.kc("TOPCOLOR")?,
            bottomcolor: self.kc("BOTTOMCOLOR")?,
        })
    }

    fn fog(&mut self) -> Result<Fog> {
        self.form = "FOG LINEAR|EXP|EXP2|OFF START s END e DENSITY d COLOR r g b";
        let w = self.word("a fog mode (LINEAR, EXP, EXP2 or OFF)")?;
        let mode = match w.text.to_ascii_uppercase().as_str() {
            "LINEAR" => FogMode::Linear,
            "EXP" => FogMode::Exp,
            "EXP2" => FogMode::Exp2,
            "OFF" => FogMode::Off,
            _ => {
                return self.error(
                    self.origin(&w),
                    format!(
                        "expected a fog mode (LINEAR, EXP, EXP2 or OFF), found `{}`",
                        lex::show(w.text)
                    ),
                )
            }
        };
        Ok(Fog {
            mode: Spanned {
                value: mode,
                at: self.origin(&w),
            },
            start: self.kf("START")?,
            end: self.kf("END")?,
            density: self.kf("DENSITY")?,
            color: self.kc("COLOR")?,
        })
    }

    /// `[ATTENUATION CONSTANT c LINEAR l QUADRATIC q]`.
    fn attenuation(&mut self) -> Result<Option<Spanned<V3>>> {
        let Some(at) = self.optional("ATTENUATION") else {
            return Ok(None);
        };
        Ok(Some(Spanned {
            value: [
                self.kf("CONSTANT")?,
                self.kf("LINEAR")?,
                self.kf("QUADRATIC")?,
            ],
            at,
        }))
    }

    fn light(&mut self) -> Result<Light> {
        self.form = "LIGHT CENTER x y z RAD r [ATTENUATION CONSTANT c LINEAR l QUADRATIC q] \
                     COLOR r g b";
        Ok(Light {
            center: self.kv("CENTER")?,
            rad: self.kf("RAD")?,
            attenuation: self.attenuation()?,
            color: self.kc("COLOR")?,
        })
    }

    fn spotlight(&mut self) -> Result<Spotlight> {
        self.form = "SPOTLIGHT CENTER x y z RAD r DIRECTION x y z FALLOFF_START a FALLOFF_END b \
                     [ATTENUATION CONSTANT c LINEAR l QUADRATIC q] COLOR r g b";
        Ok(Spotlight {
            center: self.kv("CENTER")?,
            rad: self.kf("RAD")?,
            direction: self.kv("DIRECTION")?,
            falloff_start: self.kf("FALLOFF_START")?,
            falloff_end: self.kf("FALLOFF_END")?,
            attenuation: self.attenuation()?,
            color: self.kc("COLOR")?,
        })
    }

    // ----- textures ----------------------------------------------------------------------

    /// `TEXTURE body` or a texture name.
    fn texref(&mut self) -> Result<TexRef> {
        let w = self.word("a texture (TEXTURE followed by its body, or a texture name)")?;
        if is(w.text, "TEXTURE") {
            return Ok(TexRef::Body(Box::new(self.body()?)));
        }
        Ok(TexRef::Name(Spanned {
            value: w.text.to_string(),
            at: self.origin(&w),
        }))
    }

    /// `AMBIENT a DIFFUSE d SPECULAR s OPACITY o [TRANSMODE w] [OUTLINE o OUTLINE_WIDTH w]
    /// [PHONG kind p PHONG_SIZE n]`.
    fn surface(&mut self) -> Result<(Origin, Surface)> {
        let at = self.keyword("AMBIENT")?;
        let ambient = self.float("AMBIENT")?;
        let diffuse = self.kf("DIFFUSE")?;
        let specular = self.kf("SPECULAR")?;
        let opacity = self.kf("OPACITY")?;
        let transmode = match self.optional("TRANSMODE") {
            Some(_) => Some(self.name("a transparency mode after TRANSMODE (R3D)")?),
            None => None,
        };
        let outline = match self.optional("OUTLINE") {
            Some(at) => Some(Spanned {
                value: [self.float("OUTLINE")?, self.kf("OUTLINE_WIDTH")?],
                at,
            }),
            None => None,
        };
        let phong = match self.optional("PHONG") {
            Some(at) => {
                let w = self.word("PLASTIC or METAL after PHONG")?;
                let kind = match w.text.to_ascii_uppercase().as_str() {
                    "PLASTIC" => PhongKind::Plastic,
                    "METAL" => PhongKind::Metal,
                    _ => PhongKind::Other(w.text.to_string()),
                };
                Some(Spanned {
                    value: Phong {
                        kind,
                        phong: self.float("PHONG")?,
                        size: self.kf("PHONG_SIZE")?,
                    },
                    at,
                })
            }
            None => None,
        };
        Ok((
            at,
            Surface {
                ambient,
                diffuse,
                specular,
                opacity,
                transmode,
                outline,
                phong,
            },
        ))
    }

    /// A texture body: surface, `COLOR r g b`, `TEXFUNC n [arguments]`.
    fn body(&mut self) -> Result<TexBody> {
        let outer = std::mem::replace(&mut self.form, TEXTURE_FORM);
        let (at, surface) = self.surface()?;
        let color = self.kc("COLOR")?;
        let texfunc = self.texfunc()?;
        self.form = outer;
        Ok(TexBody {
            at,
            surface,
            color,
            texfunc,
        })
    }

    fn frame(&mut self) -> Result<Frame> {
        Ok(Frame {
            center: self.kv("CENTER")?,
            rotate: self.kv("ROTATE")?,
            scale: self.kv("SCALE")?,
        })
    }

    fn texfunc(&mut self) -> Result<Spanned<TexFunc>> {
        let at = self.keyword("TEXFUNC")?;
        let n = self.whole("TEXFUNC", i32::MIN as i64, i32::MAX as i64)?;
        let solid = |k| match k {
            1 => Some(SolidKind::Checker),
            2 => Some(SolidKind::Grit),
            3 => Some(SolidKind::Marble),
            4 => Some(SolidKind::Wood),
            5 => Some(SolidKind::Gnoise),
            6 => Some(SolidKind::CylChecker),
            _ => None,
        };
        let value = if let Some(kind) = solid(n) {
            self.form = "TEXFUNC 1..6 CENTER x y z ROTATE x y z SCALE x y z";
            TexFunc::Solid {
                kind,
                frame: self.frame()?,
            }
        } else if (7..=9).contains(&n) {
            let kind = match n {
                7 => ImageKind::Cylindrical,
                8 => ImageKind::Spherical,
                _ => ImageKind::Planar,
            };
            self.form = if n == 9 {
                "TEXFUNC 9 file CENTER x y z ROTATE x y z SCALE x y z UAXIS x y z VAXIS x y z"
            } else {
                "TEXFUNC 7|8 file CENTER x y z ROTATE x y z SCALE x y z"
            };
            let file = self.name("an image file after TEXFUNC")?;
            let rest = (|| -> Result<(Frame, Option<[V3; 2]>)> {
                let frame = self.frame()?;
                let axes = if n == 9 {
                    Some([self.kv("UAXIS")?, self.kv("VAXIS")?])
                } else {
                    None
                };
                Ok((frame, axes))
            })();
            let (frame, axes) = rest.map_err(|e| misread_word(e, &file, n))?;
            let path = match files::find(&file.value, &self.dir) {
                Ok(p) => Some(p),
                Err(why) => {
                    self.warn(
                        file.at.clone(),
                        format!(
                            "image map {why}; Tachyon renders the surface white (its message \
                             says solid gray), and so does Luxon"
                        ),
                    );
                    None
                }
            };
            TexFunc::Image {
                kind,
                file,
                path,
                frame,
                axes,
            }
        } else if n == 10 {
            self.form = "TEXFUNC 10 imagename CENTER x y z ROTATE x y z SCALE x y z UAXIS x y z \
                         VAXIS x y z WAXIS x y z";
            let image = self.name("an IMAGEDEF name after TEXFUNC 10")?;
            let rest = (|| -> Result<(Frame, [V3; 3])> {
                let frame = self.frame()?;
                Ok((
                    frame,
                    [self.kv("UAXIS")?, self.kv("VAXIS")?, self.kv("WAXIS")?],
                ))
            })();
            let (frame, axes) = rest.map_err(|e| misread_word(e, &image, n))?;
            TexFunc::Volume { image, frame, axes }
        } else {
            TexFunc::Plain(n)
        };
        Ok(Spanned { value, at })
    }

    fn imagedef(&mut self) -> Result<ImageDef> {
        self.form = "IMAGEDEF name FORMAT RGB24 RESOLUTION x y z ENCODING HEX texels";
        let name = self.name("an image name after IMAGEDEF")?;
        self.keyword("FORMAT")?;
        let w = self.word("RGB24")?;
        if !is(w.text, "RGB24") {
            return self.error(
                self.origin(&w),
                format!(
                    "expected `RGB24` (the only IMAGEDEF format), found `{}`",
                    lex::show(w.text)
                ),
            );
        }
        self.keyword("RESOLUTION")?;
        let res = [
            self.int("RESOLUTION (x)", 1, 1 << 16)?,
            self.int("RESOLUTION (y)", 1, 1 << 16)?,
            self.int("RESOLUTION (z)", 1, 1 << 16)?,
        ];
        let count = res.iter().map(|&n| n as u64).product::<u64>();
        if count > 1 << 28 {
            return self.error(
                name.at.clone(),
                format!(
                    "IMAGEDEF `{}` has {count} texels; at most 2^28 are read",
                    name.value
                ),
            );
        }
        self.keyword("ENCODING")?;
        let w = self.word("HEX")?;
        if !is(w.text, "HEX") {
            return self.error(
                self.origin(&w),
                format!(
                    "expected `HEX` (the only IMAGEDEF encoding), found `{}`",
                    lex::show(w.text)
                ),
            );
        }
        let mut texels = Vec::with_capacity(count.min(1 << 16) as usize);
        for i in 0..count {
            let w = self.word("a texel (3, 6, 9 or 12 hexadecimal digits)")?;
            match hex_texel(w.text) {
                Some(t) => texels.push(t),
                None => {
                    return self.error(
                        self.origin(&w),
                        format!(
                            "expected texel {i} of {count} (3, 6, 9 or 12 hexadecimal digits: \
                             1 to 4 per channel), found `{}`",
                            lex::show(w.text)
                        ),
                    )
                }
            }
        }
        Ok(ImageDef { name, res, texels })
    }

    // ----- primitives --------------------------------------------------------------------

    fn vcstri(&mut self) -> Result<Kind> {
        self.form = "VCSTRI V0 .. V1 .. V2 .. N0 .. N1 .. N2 .. C0 r g b C1 .. C2 .. AMBIENT a \
                     DIFFUSE d SPECULAR s OPACITY o [TRANSMODE w] [OUTLINE o OUTLINE_WIDTH w] \
                     [PHONG kind p PHONG_SIZE n] VCST";
        let v = [self.kv("V0")?, self.kv("V1")?, self.kv("V2")?];
        let n = [self.kv("N0")?, self.kv("N1")?, self.kv("N2")?];
        let c = [self.kc("C0")?, self.kc("C1")?, self.kc("C2")?];
        let (_, surface) = self.surface()?;
        self.keyword("VCST")?;
        Ok(Kind::Vcstri { v, n, c, surface })
    }

    fn vertex_array(&mut self) -> Result<VertexArray> {
        self.form = "VERTEXARRAY NUMVERTS n COORDS x y z ... NORMALS x y z ... { COLORS r g b \
                     ... | TEXTURE body | TRIMESH m i j k ... | TRISTRIP k i ... } \
                     END_VERTEXARRAY";
        let n = self.ki("NUMVERTS", 0, i32::MAX as i64)?;
        let form = self.form;
        let list = |p: &mut Self, kw: &str| -> Result<Vec<V3>> {
            p.keyword(kw)?;
            let mut out = Vec::with_capacity(n.min(1 << 16) as usize);
            for i in 0..n {
                out.push(if kw == "COLORS" {
                    p.color(Item("colour", i, "COLORS"))?
                } else {
                    p.vec3(Item("vertex", i, kw))?
                });
            }
            Ok(out)
        };
        let coords = list(self, "COORDS")?;
        let normals = list(self, "NORMALS")?;
        let mut blocks = Vec::new();
        loop {
            self.form = form;
            let w = self.word("COLORS, TEXTURE, TRIMESH, TRISTRIP or END_VERTEXARRAY")?;
            let at = self.origin(&w);
            let block = match w.text.to_ascii_uppercase().as_str() {
                "END_VERTEXARRAY" => break,
                "COLORS" => {
                    let mut colors = Vec::with_capacity(n.min(1 << 16) as usize);
                    for i in 0..n {
                        colors.push(self.color(Item("colour", i, "COLORS"))?);
                    }
                    VertexBlock::Colors(colors)
                }
                "TEXTURE" => VertexBlock::Texture(Box::new(self.body()?)),
                "TRIMESH" => {
                    let m = self.int("TRIMESH (triangle count)", 0, i32::MAX as i64)?;
                    let mut tris = Vec::with_capacity(m.min(1 << 16) as usize);
                    for _ in 0..m {
                        tris.push([self.index(n)?, self.index(n)?, self.index(n)?]);
                    }
                    VertexBlock::TriMesh(tris)
                }
                "TRISTRIP" => {
                    let k = self.int("TRISTRIP (index count)", 0, i32::MAX as i64)?;
                    let mut strip = Vec::with_capacity(k.min(1 << 16) as usize);
                    for _ in 0..k {
                        strip.push(self.index(n)?);
                    }
                    VertexBlock::TriStrip(strip)
                }
                _ => {
                    return self.error(
                        at,
                        format!(
                            "expected COLORS, TEXTURE, TRIMESH, TRISTRIP or END_VERTEXARRAY, \
                             found `{}`",
                            lex::show(w.text)
                        ),
                    )
                }
            };
            blocks.push(Spanned { value: block, at });
        }
        Ok(VertexArray {
            coords,
            normals,
            blocks,
        })
    }

    /// A vertex index below `n`.
    fn index(&mut self, n: u32) -> Result<u32> {
        let w = self.word("a vertex index")?;
        let i = lex::int(w.text).or_else(|e| self.number_error(&w, "a vertex index", e))?;
        if i < 0 || i >= n as i64 {
            return self.error(
                self.origin(&w),
                format!(
                    "vertex index {i} is out of range: the VERTEXARRAY has {n} vertices (0 to {})",
                    n as i64 - 1
                ),
            );
        }
        Ok(i as u32)
    }

    fn scalarvol(&mut self) -> Result<Kind> {
        self.form = "SCALARVOL MIN x y z MAX x y z DIM nx ny nz FILE path texture";
        let min = self.kv("MIN")?;
        let max = self.kv("MAX")?;
        self.keyword("DIM")?;
        let dim = [
            self.int("DIM (x)", 1, 1 << 20)?,
            self.int("DIM (y)", 1, 1 << 20)?,
            self.int("DIM (z)", 1, 1 << 20)?,
        ];
        self.keyword("FILE")?;
        let file = self.name("a volume file after FILE")?;
        let tex = self.texref()?;
        let path = match files::find(&file.value, &self.dir) {
            Ok(p) => Some(p),
            Err(why) => {
                self.warn(
                    file.at.clone(),
                    format!(
                        "volume file {why}; Tachyon draws the volume's box in its texture's \
                         colour instead, and so does Luxon"
                    ),
                );
                None
            }
        };
        Ok(Kind::ScalarVol {
            min,
            max,
            dim,
            file,
            path,
            tex,
        })
    }

    fn tpolyfile(&mut self) -> Result<Kind> {
        self.form = "TPOLYFILE SCALE x y z ROT x y z CENTER x y z FILE path texture";
        let scale = self.kv("SCALE")?;
        let rot = self.kv("ROT")?;
        let center = self.kv("CENTER")?;
        self.keyword("FILE")?;
        let file = self.name("a .tpoly file after FILE")?;
        let tex = self.texref()?;
        let path = files::find(&file.value, &self.dir)
            .map_err(|why| SceneError::at(file.at.clone(), format!("TPOLYFILE: {why}")))?;
        let triangles = read_tpoly(&path, &mut self.cx.text_left).map_err(|e| match e {
            SceneError::Io { path, source } => SceneError::at(
                file.at.clone(),
                format!("TPOLYFILE: cannot read {}: {source}", path.display()),
            ),
            other => other,
        })?;
        Ok(Kind::TpolyFile {
            scale,
            rot,
            center,
            file,
            path,
            triangles,
            tex,
        })
    }

    /// `INCLUDE path`: the file's statements are read here, up to its END_SCENE or its end.
    fn include(&mut self, at: Origin) -> Result<()> {
        self.form = "INCLUDE path";
        let written = self.name("a file name after INCLUDE")?;
        let path = files::find(&written.value, &self.dir)
            .map_err(|why| SceneError::at(written.at.clone(), format!("INCLUDE: {why}")))?;
        let key = canonical(&path);
        if let Some(i) = self.cx.chain.iter().position(|p| *p == key) {
            let chain: Vec<String> = self.cx.chain[i..]
                .iter()
                .chain(std::iter::once(&key))
                .map(|p| p.display().to_string())
                .collect();
            return Err(SceneError::at(
                written.at,
                format!(
                    "INCLUDE cycle: {}; expected each file to be included at most once along a \
                     chain",
                    chain.join(" -> ")
                ),
            ));
        }
        if self.cx.chain.len() > MAX_INCLUDE_DEPTH {
            return Err(SceneError::at(
                written.at,
                format!("INCLUDEs nest deeper than {MAX_INCLUDE_DEPTH} files"),
            ));
        }
        let text = files::read_text(&path, self.cx.text_left).map_err(|e| {
            SceneError::at(
                written.at.clone(),
                format!("INCLUDE: cannot read {}: {e}", path.display()),
            )
        })?;
        self.cx.text_left = self.cx.text_left.saturating_sub(text.len() as u64);
        self.push(
            at,
            Kind::Include {
                path: written,
                file: path.clone(),
            },
        );
        self.cx.chain.push(key);
        let mut child = Parser {
            lex: Lexer::new(&text, Arc::new(path.clone())),
            dir: directory_of(&path),
            form: "",
            cx: &mut *self.cx,
        };
        child.statements()?;
        self.cx.chain.pop();
        Ok(())
    }
}

/// Adds to an error inside a TEXFUNC's arguments that its file or image name was a statement
/// keyword: the file name was probably left out (Tachyon rejects such files too).
fn misread_word(e: SceneError, word: &Spanned<String>, n: i64) -> SceneError {
    let upper = word.value.to_ascii_uppercase();
    if !STATEMENTS.contains(&upper.as_str()) {
        return e;
    }
    match e {
        SceneError::At { at, message } => SceneError::At {
            at,
            message: format!(
                "{message}; note: `{}` at {} was read as TEXFUNC {n}'s {}: is it missing?",
                word.value,
                word.at,
                if n == 10 { "image name" } else { "image file" }
            ),
        },
        other => other,
    }
}

/// An IMAGEDEF texel: 3, 6, 9 or 12 hexadecimal digits, 1 to 4 per channel (1: the digit
/// doubled; 3 and 4: the top 8 bits kept).
fn hex_texel(text: &str) -> Option<[u8; 3]> {
    let len = text.len();
    if !matches!(len, 3 | 6 | 9 | 12) || !text.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let per = len / 3;
    let mut out = [0u8; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let v = u32::from_str_radix(&text[c * per..(c + 1) * per], 16).ok()?;
        *o = match per {
            1 => (v * 17) as u8,
            2 => v as u8,
            3 => (v >> 4) as u8,
            _ => (v >> 8) as u8,
        };
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::hex_texel;

    #[test]
    fn texels_of_every_width() {
        assert_eq!(hex_texel("f08"), Some([255, 0, 136]));
        assert_eq!(hex_texel("ff0080"), Some([255, 0, 128]));
        assert_eq!(hex_texel("fff000801"), Some([255, 0, 128]));
        assert_eq!(hex_texel("ffff00008000"), Some([255, 0, 128]));
        assert_eq!(hex_texel("ff"), None);
        assert_eq!(hex_texel("ggg"), None);
    }
}
