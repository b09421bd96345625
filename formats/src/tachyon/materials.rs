//! Texture bodies to Luxon materials (and image textures): `TEXDEF` names, `TEXALIAS`, inline
//! bodies shared when they map to the same material, and the default texture Tachyon uses for
//! undefined names.

use std::collections::{HashMap, HashSet};

use super::notes::Notes;
use super::ron::{float, string, vec2, vec3};
use super::syntax::{
    Frame, ImageDef, ImageKind, PhongKind, SolidKind, Surface, TexBody, TexFunc, TexRef, V3,
};
use super::{mirror, Warnings};
use crate::desc::{Highlight, HighlightColor, MaterialDesc, PluginCall, TransparencyAngle};
use crate::error::SceneError;
use crate::origin::{Origin, Spanned};

type Result<T> = std::result::Result<T, SceneError>;

/// Tachyon's texture for undefined names: AMBIENT 0.1 DIFFUSE 0.9 SPECULAR 0 OPACITY 1,
/// COLOR 1 1 1, TEXFUNC 0.
fn default_surface() -> Surface {
    Surface {
        ambient: 0.1,
        diffuse: 0.9,
        specular: 0.0,
        opacity: 1.0,
        transmode: None,
        outline: None,
        phong: None,
    }
}

/// What the mapping of a scene's textures has made so far.
pub(super) struct Materials {
    /// Names TEXDEF and TEXALIAS give (generated names avoid them).
    reserved: HashSet<String>,
    /// TEXDEF/TEXALIAS name → material name and where it was defined.
    named: HashMap<String, (String, Origin)>,
    /// A mapped material's content → its name: identical inline bodies share one.
    shared: HashMap<String, String>,
    /// An inline body as written ([`body_key`]) → its material.
    bodies: HashMap<Vec<u8>, String>,
    /// The default texture's material, once made.
    default: Option<String>,
    next: usize,
    /// IMAGEDEFs defined so far: name → (size, texels); the first definition of a name stays.
    imagedefs: HashMap<String, ([u32; 3], Vec<[u8; 3]>)>,
    pub materials: Vec<(String, Spanned<MaterialDesc>)>,
    pub textures: Vec<(String, Spanned<PluginCall>)>,
}

impl Materials {
    /// `reserved`: every TEXDEF and TEXALIAS name of the scene.
    pub fn new(reserved: HashSet<String>) -> Materials {
        Materials {
            reserved,
            named: HashMap::new(),
            shared: HashMap::new(),
            bodies: HashMap::new(),
            default: None,
            next: 0,
            imagedefs: HashMap::new(),
            materials: Vec::new(),
            textures: Vec::new(),
        }
    }

    pub fn imagedef(&mut self, def: &ImageDef) {
        self.imagedefs
            .entry(def.name.value.clone())
            .or_insert_with(|| (def.res, def.texels.clone()));
    }

    /// `TEXDEF name body`: the first definition of a name stays (Tachyon's rule).
    pub fn define(
        &mut self,
        name: &Spanned<String>,
        body: &TexBody,
        notes: &mut Notes,
        warnings: &mut Warnings,
    ) -> Result<()> {
        if let Some((_, first)) = self.named.get(&name.value) {
            redefined(notes, name, first);
            return Ok(());
        }
        let (material, texture) = self.map_body(body, notes, warnings)?;
        self.add(name.value.clone(), material, texture, body.at.clone());
        self.named
            .insert(name.value.clone(), (name.value.clone(), name.at.clone()));
        Ok(())
    }

    /// `TEXALIAS name target`.
    pub fn alias(&mut self, name: &Spanned<String>, target: &Spanned<String>, notes: &mut Notes) {
        if let Some((_, first)) = self.named.get(&name.value) {
            redefined(notes, name, first);
            return;
        }
        let material = self.by_name(target, notes);
        self.named
            .insert(name.value.clone(), (material, name.at.clone()));
    }

    /// The material a texture reference stands for.
    pub fn resolve(
        &mut self,
        tex: &TexRef,
        notes: &mut Notes,
        warnings: &mut Warnings,
    ) -> Result<String> {
        match tex {
            TexRef::Name(name) => Ok(self.by_name(name, notes)),
            TexRef::Body(body) => {
                // Files repeat the same body on every primitive: map each distinct one once.
                let key = body_key(body);
                if let Some(name) = self.bodies.get(&key) {
                    note_surface(&body.surface, notes);
                    return Ok(name.clone());
                }
                let (m, t) = self.map_body(body, notes, warnings)?;
                let name = self.shared_material(m, t, &body.at);
                self.bodies.insert(key, name.clone());
                Ok(name)
            }
        }
    }

    /// The default texture (for meshes of a VERTEXARRAY before its first TEXTURE).
    pub fn default_material(&mut self, at: &Origin) -> String {
        if let Some(name) = &self.default {
            return name.clone();
        }
        let m = material_of(&default_surface(), [1.0; 3]);
        let name = self.shared_material(m, None, at);
        self.default = Some(name.clone());
        name
    }

    /// A VCSTRI's material: its surface with a white colour (the vertex colours are the
    /// surface's colour).
    pub fn surface_material(
        &mut self,
        surface: &Surface,
        at: &Origin,
        notes: &mut Notes,
    ) -> Result<String> {
        note_surface(surface, notes);
        let mut key = surface_key(surface);
        key.extend_from_slice(b"\0vcstri");
        if let Some(name) = self.bodies.get(&key) {
            return Ok(name.clone());
        }
        check_surface(surface, at)?;
        let m = material_of(surface, [1.0; 3]);
        let name = self.shared_material(m, None, at);
        self.bodies.insert(key, name.clone());
        Ok(name)
    }

    /// `material` with vertex colours in place of its colour and texture (VERTEXARRAY COLORS):
    /// white, untextured, the rest as it is.
    pub fn vertex_colored(&mut self, material: &str, at: &Origin) -> String {
        let Some(m) = self
            .materials
            .iter()
            .find(|(n, _)| n == material)
            .map(|(_, m)| m.value.clone())
        else {
            return material.to_string();
        };
        let m = MaterialDesc {
            color: [1.0; 3],
            texture: None,
            ..m
        };
        self.shared_material(m, None, at)
    }

    /// `material`'s colour, unlit (ambient 1, nothing else): what Tachyon draws for a volume
    /// whose file is missing.
    pub fn unlit(&mut self, material: &str, at: &Origin) -> String {
        let color = self
            .materials
            .iter()
            .find(|(n, _)| n == material)
            .map_or([1.0; 3], |(_, m)| m.value.color);
        let m = MaterialDesc {
            color,
            ambient: 1.0,
            diffuse: 0.0,
            specular: 0.0,
            reflect: 0.0,
            transmit: 0.0,
            ..MaterialDesc::default()
        };
        self.shared_material(m, None, at)
    }

    /// A light's visible sphere: its colour, unlit (ambient 1, nothing else) and unfogged, as
    /// Tachyon draws it.
    pub fn light(&mut self, color: V3, at: &Origin) -> String {
        let m = MaterialDesc {
            color,
            ambient: 1.0,
            diffuse: 0.0,
            specular: 0.0,
            reflect: 0.0,
            transmit: 0.0,
            fog: false,
            ..MaterialDesc::default()
        };
        self.shared_material(m, None, at)
    }

    fn by_name(&mut self, name: &Spanned<String>, notes: &mut Notes) -> String {
        if let Some((material, _)) = self.named.get(&name.value) {
            return material.clone();
        }
        notes.add(
            "undefined texture names",
            &format!(
                "(`{}` here): Tachyon uses its default texture (AMBIENT 0.1 DIFFUSE 0.9, white) \
                 for them, and so does Luxon",
                name.value
            ),
            &name.at,
        );
        self.default_material(&name.at)
    }

    /// A material for mapped content, shared with identical content mapped before.
    fn shared_material(
        &mut self,
        material: MaterialDesc,
        texture: Option<(String, String)>,
        at: &Origin,
    ) -> String {
        let key = format!("{material:?}|{texture:?}");
        if let Some(name) = self.shared.get(&key) {
            return name.clone();
        }
        let name = loop {
            let name = format!("tachyon-{}", self.next);
            self.next += 1;
            if !self.reserved.contains(&name) {
                break name;
            }
        };
        self.add(name.clone(), material, texture, at.clone());
        self.shared.insert(key, name.clone());
        name
    }

    /// Adds material `name` (and its texture, named like it).
    fn add(
        &mut self,
        name: String,
        mut material: MaterialDesc,
        texture: Option<(String, String)>,
        at: Origin,
    ) {
        if let Some((plugin, params)) = texture {
            material.texture = Some(Spanned {
                value: name.clone(),
                at: at.clone(),
            });
            self.textures.push((
                name.clone(),
                Spanned {
                    value: PluginCall {
                        plugin: Spanned {
                            value: plugin,
                            at: at.clone(),
                        },
                        params,
                        params_at: at.clone(),
                    },
                    at: at.clone(),
                },
            ));
        }
        self.materials.push((
            name,
            Spanned {
                value: material,
                at,
            },
        ));
    }

    /// A body's material (without its texture name) and texture (plugin, params).
    fn map_body(
        &mut self,
        body: &TexBody,
        notes: &mut Notes,
        warnings: &mut Warnings,
    ) -> Result<(MaterialDesc, Option<(String, String)>)> {
        check_surface(&body.surface, &body.at)?;
        if body.color.iter().any(|&c| c < 0.0) {
            return Err(SceneError::at(
                body.at.clone(),
                format!(
                    "COLOR {:?} has a negative component; expected components of 0 or more",
                    body.color
                ),
            ));
        }
        note_surface(&body.surface, notes);
        let (color, texture) = self.texfunc(body, notes, warnings);
        Ok((material_of(&body.surface, color), texture))
    }

    /// The colour and texture a TEXFUNC gives.
    fn texfunc(
        &mut self,
        body: &TexBody,
        notes: &mut Notes,
        warnings: &mut Warnings,
    ) -> (V3, Option<(String, String)>) {
        let at = &body.texfunc.at;
        let c = body.color;
        // Tachyon says "Faking it using solid gray" but renders the surface white (measured).
        const FAKE: V3 = [1.0; 3];
        match &body.texfunc.value {
            TexFunc::Plain(_) => (c, None),
            TexFunc::Solid { kind, frame } => match kind {
                SolidKind::Checker => (c, Some(checker(frame))),
                SolidKind::Grit => (c, Some(grit(c))),
                // Tachyon clamps its noise, which is almost always above 1: plain COLOR.
                SolidKind::Gnoise => (c, None),
                // Tachyon's marble ignores every parameter and COLOR.
                SolidKind::Marble => (c, Some(("tachyon_marble".into(), "()".into()))),
                SolidKind::Wood => match wood(frame) {
                    Some(t) => (c, Some(t)),
                    None => {
                        notes.add(
                            "TEXFUNC 4 (wood) with a SCALE of 0",
                            "divides by zero in Tachyon; its COLOR is shown instead",
                            at,
                        );
                        (c, None)
                    }
                },
                SolidKind::CylChecker => (c, Some(cylinder_checker(frame))),
            },
            TexFunc::Image {
                kind,
                path,
                frame,
                axes,
                ..
            } => match path {
                None => (FAKE, None),
                Some(path) => match image(*kind, path, frame, axes.as_ref()) {
                    Ok(params) => (c, Some(("image".into(), params))),
                    Err(why) => {
                        notes.add(
                            "image map placement",
                            &format!("{why}; its COLOR is shown instead"),
                            at,
                        );
                        (c, None)
                    }
                },
            },
            TexFunc::Volume { image, frame, axes } => {
                let Some((size, texels)) = self.imagedefs.get(&image.value) else {
                    warnings.push(Spanned {
                        value: format!(
                            "no IMAGEDEF named `{}` precedes this; Tachyon renders the texture \
                             white (its message says solid gray), and so does Luxon",
                            image.value
                        ),
                        at: image.at.clone(),
                    });
                    return (FAKE, None);
                };
                if texels.len() > MAX_VOLUME_TEXELS {
                    notes.add(
                        "TEXFUNC 10 (volume image)",
                        &format!(
                            "with more than {MAX_VOLUME_TEXELS} texels is not rendered; its \
                             COLOR is shown instead"
                        ),
                        at,
                    );
                    return (c, None);
                }
                (c, Some(volume_image(*size, texels, frame, axes)))
            }
        }
    }
}

/// A texture body's content as bytes (numbers by their bits, words as written), positions
/// left out: equal keys map to the same material.
fn body_key(b: &TexBody) -> Vec<u8> {
    let mut k = surface_key(&b.surface);
    let num = |k: &mut Vec<u8>, x: f64| k.extend_from_slice(&x.to_bits().to_le_bytes());
    let word = |k: &mut Vec<u8>, w: &str| {
        k.extend_from_slice(&(w.len() as u64).to_le_bytes());
        k.extend_from_slice(w.as_bytes());
    };
    for x in b.color {
        num(&mut k, x);
    }
    let frame = |k: &mut Vec<u8>, f: &Frame| {
        for v in [f.center, f.rotate, f.scale] {
            for x in v {
                k.extend_from_slice(&x.to_bits().to_le_bytes());
            }
        }
    };
    match &b.texfunc.value {
        TexFunc::Plain(n) => k.extend_from_slice(&n.to_le_bytes()),
        TexFunc::Solid { kind, frame: f } => {
            k.push(*kind as u8);
            frame(&mut k, f);
        }
        TexFunc::Image {
            kind,
            file,
            path,
            frame: f,
            axes,
        } => {
            k.push(*kind as u8);
            // The file found: the same word may name different files in different INCLUDEs.
            word(&mut k, &file.value);
            word(
                &mut k,
                &path
                    .as_ref()
                    .map(|p| p.to_string_lossy())
                    .unwrap_or_default(),
            );
            frame(&mut k, f);
            for v in axes.iter().flatten() {
                for &x in v {
                    num(&mut k, x);
                }
            }
        }
        TexFunc::Volume {
            image,
            frame: f,
            axes,
        } => {
            k.push(10);
            word(&mut k, &image.value);
            frame(&mut k, f);
            for v in axes {
                for &x in v {
                    num(&mut k, x);
                }
            }
        }
    }
    k
}

/// A surface's content as bytes (see [`body_key`]).
fn surface_key(s: &Surface) -> Vec<u8> {
    let mut k = Vec::with_capacity(128);
    let num = |k: &mut Vec<u8>, x: f64| k.extend_from_slice(&x.to_bits().to_le_bytes());
    let word = |k: &mut Vec<u8>, w: &str| {
        k.extend_from_slice(&(w.len() as u64).to_le_bytes());
        k.extend_from_slice(w.as_bytes());
    };
    for x in [s.ambient, s.diffuse, s.specular, s.opacity] {
        num(&mut k, x);
    }
    word(
        &mut k,
        s.transmode.as_ref().map_or("", |t| t.value.as_str()),
    );
    for x in s.outline.as_ref().map_or([-1.0; 2], |o| o.value) {
        num(&mut k, x);
    }
    match &s.phong {
        Some(p) => {
            let kind = match &p.value.kind {
                PhongKind::Plastic => "\0plastic",
                PhongKind::Metal => "\0metal",
                PhongKind::Other(w) => w.as_str(),
            };
            word(&mut k, kind);
            num(&mut k, p.value.phong);
            num(&mut k, p.value.size);
        }
        None => word(&mut k, "\0none"),
    }
    k
}

/// A TEXDEF or TEXALIAS of a name already defined.
fn redefined(notes: &mut Notes, name: &Spanned<String>, first: &Origin) {
    notes.add(
        "TEXDEF/TEXALIAS of a name already defined",
        &format!(
            "(`{}` here, first defined at {first}): Tachyon keeps the first definition, and so \
             does Luxon",
            name.value
        ),
        &name.at,
    );
}

/// Negative coefficients are refused (Luxon's materials take none).
fn check_surface(s: &Surface, at: &Origin) -> Result<()> {
    let phong = s.phong.as_ref().map_or(0.0, |p| p.value.phong);
    for (name, v) in [
        ("AMBIENT", s.ambient),
        ("DIFFUSE", s.diffuse),
        ("SPECULAR", s.specular),
        ("OPACITY", s.opacity),
        ("PHONG", phong),
    ] {
        if v < 0.0 {
            return Err(SceneError::at(
                at.clone(),
                format!("{name} is {v}; expected 0 or more"),
            ));
        }
    }
    Ok(())
}

/// Notes for the parts of a surface Luxon renders otherwise: OUTLINE values outside what the
/// formula is meant for are clamped to [0, 1].
fn note_surface(s: &Surface, notes: &mut Notes) {
    if let Some(o) = &s.outline {
        if o.value.iter().any(|v| !(0.0..=1.0).contains(v)) {
            notes.add(
                "OUTLINE or OUTLINE_WIDTH outside 0..1",
                "is clamped into 0..1",
                &o.at,
            );
        }
    }
}

/// Tachyon's shading coefficients as a Luxon material: ambient and diffuse as they are,
/// SPECULAR the mirror reflectance, PHONG the (Blinn) highlight in the light's colour
/// (PLASTIC) or the surface's (METAL), OPACITY o a transmission of 1 - o without refraction,
/// TRANSMODE R3D the Raster3D angle rule, OUTLINE the outline.
fn material_of(s: &Surface, color: V3) -> MaterialDesc {
    let (specular, shininess, metal) = match &s.phong {
        Some(p) => (
            p.value.phong,
            p.value.size.max(1e-9),
            p.value.kind == PhongKind::Metal,
        ),
        None => (0.0, 100.0, false),
    };
    let r3d = s
        .transmode
        .as_ref()
        .is_some_and(|t| t.value.eq_ignore_ascii_case("R3D"));
    let [outline, outline_width] = s
        .outline
        .as_ref()
        .map_or([0.0; 2], |o| o.value.map(|v| v.clamp(0.0, 1.0)));
    MaterialDesc {
        color,
        texture: None,
        reflect_texture: None,
        transmit_texture: None,
        ambient: s.ambient,
        diffuse: s.diffuse,
        specular,
        shininess,
        highlight: Highlight::Blinn,
        highlight_color: if metal {
            HighlightColor::Surface
        } else {
            HighlightColor::Light
        },
        reflect: s.specular,
        transmit: (1.0 - s.opacity).clamp(0.0, 1.0),
        ior: 1.0,
        transparency_angle: r3d.then_some(TransparencyAngle::Raster3D),
        outline,
        outline_width,
        fog: true,
    }
}

/// TEXFUNC 1: cells a third wide on every axis, their boundaries a sixth from CENTER (Tachyon
/// counts cells from CENTER by |q|, which gives the same parity as a grid shifted by half a
/// cell); odd cells (1, 0.2, 0), even (0, 0.2, 1). COLOR, ROTATE and SCALE are ignored, as in
/// Tachyon.
fn checker(frame: &Frame) -> (String, String) {
    let c = mirror(frame.center);
    let corner = c.map(|x| x - 1.0 / 6.0);
    (
        "checker".into(),
        format!(
            "(scale: {}, translate: {}, even: (0.0, 0.2, 1.0), odd: (1.0, 0.2, 0.0))",
            float(1.0 / 3.0),
            vec3(corner)
        ),
    )
}

/// TEXFUNC 4: Tachyon's rings about the y axis through CENTER, the point divided by SCALE
/// (ROTATE and COLOR ignored). The world is mirrored in z, so CENTER is mirrored and SCALE.z
/// negated: the texture then sees Tachyon's coordinates. `None` for a SCALE with a 0.
fn wood(frame: &Frame) -> Option<(String, String)> {
    let [sx, sy, sz] = frame.scale;
    if frame.scale.contains(&0.0) {
        return None;
    }
    Some((
        "tachyon_wood".into(),
        format!(
            "(center: {}, scale: {})",
            vec3(mirror(frame.center)),
            vec3([sx, sy, -sz])
        ),
    ))
}

/// IMAGEDEF blocks larger than this (a 100³ block) are not passed to the texture: their texels
/// would travel as RON text.
const MAX_VOLUME_TEXELS: usize = 1_000_000;

/// TEXFUNC 10: `u = UAXIS·(p − CENTER)·SCALE.x + ROTATE.x` and likewise v, w, in Tachyon's
/// world; in the mirrored one the same with CENTER and the axes mirrored.
fn volume_image(
    size: [u32; 3],
    texels: &[[u8; 3]],
    frame: &Frame,
    axes: &[V3; 3],
) -> (String, String) {
    let [u, v, w] = [0, 1, 2].map(|k| vec3(mirror(axes[k]).map(|x| x * frame.scale[k])));
    let mut rgb = String::with_capacity(texels.len() * 12);
    for (i, b) in texels.iter().flatten().enumerate() {
        if i > 0 {
            rgb.push_str(", ");
        }
        rgb.push_str(&b.to_string());
    }
    (
        "tachyon_volume_image".into(),
        format!(
            "(size: ({}, {}, {}), center: {}, u: {u}, v: {v}, w: {w}, offset: {}, rgb: [{rgb}])",
            size[0],
            size[1],
            size[2],
            vec3(mirror(frame.center)),
            vec3(frame.rotate),
        ),
    )
}

/// TEXFUNC 6: Tachyon's sectors about the z axis through CENTER (symmetric in z, so the
/// mirrored CENTER is all the mirror needs); ROTATE, SCALE and COLOR ignored, as in Tachyon.
fn cylinder_checker(frame: &Frame) -> (String, String) {
    (
        "tachyon_cylinder_checker".into(),
        format!("(center: {})", vec3(mirror(frame.center))),
    )
}

/// TEXFUNC 2: Tachyon scales COLOR by a fresh random number in [0.8, 1] at every lookup;
/// Luxon's fine-grained noise between 0.8·COLOR and COLOR looks the same (and stays the same
/// from frame to frame).
fn grit(c: V3) -> (String, String) {
    (
        "noise".into(),
        format!(
            "(from: {}, to: {}, scale: 0.01, octaves: 1)",
            vec3(c.map(|x| 0.8 * x)),
            vec3(c)
        ),
    )
}

/// TEXFUNC 7, 8, 9 as the `image` texture's parameters, or why they do not fit it.
///
/// Tachyon: (u, v) from the mapping, then u·SCALE.x + ROTATE.x and v·SCALE.y + ROTATE.y,
/// wrapped into [0, 1). v = 0 is the first row of the image in memory: the top row of a PPM
/// file, the bottom row of a TGA (its origin flag honoured). Luxon's image coordinates have
/// (0, 0) at the bottom-left, so v is flipped for every format but TGA.
fn image(
    kind: ImageKind,
    path: &std::path::Path,
    frame: &Frame,
    axes: Option<&[V3; 2]>,
) -> std::result::Result<String, String> {
    let tga = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tga"));
    let (su, sv) = (frame.scale[0], frame.scale[1]);
    let (ru, rv) = (frame.rotate[0], frame.rotate[1]);
    // Tachyon's blur: 0.05 × the distance travelled × its larger scale (see the filter's doc).
    let filter = format!("tachyon({})", float(0.05 * su.abs().max(sv.abs())));
    // v' = v·sv + rv, flipped to 1 - v' for top-row-first images.
    let (sv, rv) = if tga { (sv, rv) } else { (-sv, 1.0 - rv) };
    let file = string(&path.to_string_lossy());
    let c = mirror(frame.center);
    match kind {
        ImageKind::Planar => {
            let [ua, va] = axes.copied().unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
            let u = mirror(ua).map(|x| x * su);
            let v = mirror(va).map(|x| x * sv);
            planar(&file, &filter, c, u, v, ru, rv)
        }
        ImageKind::Cylindrical | ImageKind::Spherical => {
            // Luxon's longitude about +y from +x toward Tachyon's +z (Luxon's -z) is Tachyon's
            // u; its height (cylindrical) and latitude (spherical) are Tachyon's v.
            if su == 0.0 || sv == 0.0 {
                return Err("an image map with SCALE 0 cannot be placed".into());
            }
            // s = (u - o) / k must equal u·su + ru: k = 1/su (negative: mirrored), o = -ru/su.
            let mapping = if kind == ImageKind::Cylindrical {
                "cylindrical"
            } else {
                "spherical"
            };
            Ok(format!(
                "(file: {file}, srgb: false, filter: {filter}, mapping: {mapping}, center: {}, axis: (0.0, 1.0, 0.0), \
                 scale: {}, offset: {})",
                vec3(c),
                vec2([1.0 / su, 1.0 / sv]),
                vec2([-ru / su, -rv / sv])
            ))
        }
    }
}

/// A planar map `s = u·d + ru`, `t = v·d + rv` (`d` = point - `c`) in the image texture's
/// terms: its plane frame is fixed by the axis (`e1` = world x made perpendicular to it,
/// `e2 = axis × e1`), so the axis is `u × v`, the turn is `u`'s angle in that frame, and the
/// lengths of `u` and `v` become the scale. `u` and `v` must be perpendicular.
fn planar(
    file: &str,
    filter: &str,
    c: V3,
    u: V3,
    v: V3,
    ru: f64,
    rv: f64,
) -> std::result::Result<String, String> {
    let dot = |a: V3, b: V3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: V3, b: V3| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let (lu, lv) = (dot(u, u).sqrt(), dot(v, v).sqrt());
    if lu == 0.0 || lv == 0.0 {
        return Err("a planar image map with a zero UAXIS, VAXIS or SCALE cannot be placed".into());
    }
    let (uh, vh) = (u.map(|x| x / lu), v.map(|x| x / lv));
    if dot(uh, vh).abs() > 1e-6 {
        return Err(
            "a planar image map whose UAXIS and VAXIS are not perpendicular cannot be placed by \
             Luxon's image texture yet"
                .into(),
        );
    }
    let n = cross(uh, vh);
    // The image texture's frame for axis n (textures plugin, mapping.rs).
    let reference = if n[0].abs() > 0.999 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let k = dot(reference, n);
    let e1 = [
        reference[0] - k * n[0],
        reference[1] - k * n[1],
        reference[2] - k * n[2],
    ];
    let l1 = dot(e1, e1).sqrt();
    let e1 = e1.map(|x| x / l1);
    let e2 = cross(n, e1);
    let theta = dot(uh, e2).atan2(dot(uh, e1));
    // R(-θ)·offset = (-ru/lu, -rv/lv)  ⇒  offset = R(θ)·(-ru/lu, -rv/lv).
    let (p, q) = (-ru / lu, -rv / lv);
    let (s, co) = theta.sin_cos();
    let offset = [co * p - s * q, s * p + co * q];
    Ok(format!(
        "(file: {file}, srgb: false, filter: {filter}, mapping: planar, center: {}, axis: {}, scale: {}, \
         rotate: {}, offset: {})",
        vec3(c),
        vec3(n),
        vec2([1.0 / lu, 1.0 / lv]),
        float(theta.to_degrees()),
        vec2(offset)
    ))
}
