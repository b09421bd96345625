//! A [`SceneDesc`] written as a Luxon RON scene ([`to_ron`]): what `luxon convert` writes from
//! any format, so a scene imported from Tachyon, NFF or OBJ becomes an ordinary, editable RON
//! scene. Read back, the text gives the same description (positions aside): every field is
//! written, with numbers in Rust's shortest form that reads back exactly.
//!
//! Imported geometry (`inline`) has no RON form of its own: [`inline_as_objects`] turns each
//! group into the `luxon-shapes` objects that store the same primitives — `sphere` /
//! `spheres`, `cylinder` / `cone` (open), `ring`, `plane`, and one `mesh` of inline arrays
//! (positions, normals, uvs, colors, indices) per group — in the order the core stores them.
//!
//! What the source says that the description does not hold — each warning of the load (a
//! Tachyon feature Luxon does not render yet, an OBJ statement it does not draw, a missing
//! image map) — is listed in comments at the top of the text: once converted, only the comment
//! keeps it. Plugin parameters are copied as written (the importers write the image maps and
//! volume files they found as absolute paths).
//!
//! An animated scene keeps its `animation:` block, every track with its keys and interpolation;
//! the lights and objects it keys are written with their `name:` (the description holds no
//! other names: a name nothing keys changes nothing and is not written).
//!
//! The array layout (a few items per line) is shared with the SPD scenes' RON output
//! (`spd::ron_out`), which writes its numbers as `%g`.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::desc::*;
use crate::geometry::InlineGeometry;

/// Writes a number to `out` (the shortest round-trip form here, `%g` for SPD scenes).
pub(crate) type Number = fn(&mut Vec<u8>, f64);

/// Rust's shortest form of a finite `f64`, which RON reads back to the same bits.
pub(crate) fn exact(out: &mut Vec<u8>, x: f64) {
    let _ = write!(out, "{x:?}");
}

/// `(x, y, z)`.
pub(crate) fn tuple(out: &mut Vec<u8>, v: &[f64], num: Number) {
    out.push(b'(');
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            out.extend_from_slice(b", ");
        }
        num(out, *x);
    }
    out.push(b')');
}

/// The items of an array, `per_line` to a line indented by `indent`, each followed by a
/// comma; `item` writes item `k`. The caller writes the brackets.
pub(crate) fn items(
    out: &mut Vec<u8>,
    count: usize,
    per_line: usize,
    indent: &str,
    mut item: impl FnMut(&mut Vec<u8>, usize),
) {
    for k in 0..count {
        if k % per_line == 0 {
            out.push(b'\n');
            out.extend_from_slice(indent.as_bytes());
        } else {
            out.push(b' ');
        }
        item(out, k);
        out.push(b',');
    }
}

/// Indentation inside an object's `params` (objects sit at 8 spaces in `objects: [...]`).
const FIELD: &str = "            ";
const ITEM: &str = "                ";

/// `name: [ ... ],` of vectors, three to a line, as a field of multi-line params.
pub(crate) fn vector_field(out: &mut Vec<u8>, name: &str, v: &[[f64; 3]], num: Number) {
    let _ = write!(out, "\n{FIELD}{name}: [");
    items(out, v.len(), 3, ITEM, |o, k| tuple(o, &v[k], num));
    let _ = write!(out, "\n{FIELD}],");
}

/// `indices: [ ... ],` eight triangles to a line.
pub(crate) fn index_field(out: &mut Vec<u8>, tris: &[[u64; 3]]) {
    let _ = write!(out, "\n{FIELD}indices: [");
    items(out, tris.len(), 8, ITEM, |o, k| {
        let t = tris[k];
        let _ = write!(o, "({}, {}, {})", t[0], t[1], t[2]);
    });
    let _ = write!(out, "\n{FIELD}],");
}

/// Multi-line params text: `(` + fields + newline and the object's indentation + `)`.
fn params(fields: impl FnOnce(&mut Vec<u8>)) -> String {
    let mut out = b"(".to_vec();
    fields(&mut out);
    out.extend_from_slice(b"\n        )");
    String::from_utf8(out).unwrap_or_default()
}

fn one_line(f: impl FnOnce(&mut Vec<u8>)) -> String {
    let mut out = Vec::new();
    f(&mut out);
    String::from_utf8(out).unwrap_or_default()
}

fn v3(v: &[f64]) -> String {
    one_line(|o| tuple(o, v, exact))
}

fn num(x: f64) -> String {
    format!("{x:?}")
}

/// A RON string literal.
fn string(s: &str) -> String {
    ron::to_string(s).unwrap_or_else(|_| format!("{s:?}"))
}

/// The objects that store the primitives of `g` (see the module documentation), in the order
/// the core stores an inline group: spheres, cones, discs, planes, triangles.
pub fn inline_as_objects(g: &InlineGeometry, fallback: &Origin) -> Vec<Spanned<ObjectDesc>> {
    let at = g.at.clone().unwrap_or_else(|| fallback.clone());
    let object = |plugin: &str, params: String| Spanned {
        value: ObjectDesc {
            call: PluginCall {
                plugin: Spanned {
                    value: plugin.to_string(),
                    at: at.clone(),
                },
                params,
                params_at: at.clone(),
            },
            material: g.material.clone(),
            clip: g.clip.clone(),
            shadows: !g.shadowless,
        },
        at: at.clone(),
    };
    let mut out = Vec::new();
    match g.spheres.as_slice() {
        [] => {}
        [s] => out.push(object(
            "sphere",
            format!("(center: {}, radius: {})", v3(&s[..3]), num(s[3])),
        )),
        many => {
            let text = params(|o| {
                let _ = write!(o, "\n{FIELD}centers: [");
                items(o, many.len(), 4, ITEM, |o, k| {
                    tuple(o, &many[k][..3], exact)
                });
                let _ = write!(o, "\n{FIELD}],\n{FIELD}");
                let r0 = many[0][3];
                if many.iter().all(|s| s[3].to_bits() == r0.to_bits()) {
                    let _ = write!(o, "radius: {},", num(r0));
                } else {
                    o.extend_from_slice(b"radii: [");
                    items(o, many.len(), 8, ITEM, |o, k| exact(o, many[k][3]));
                    let _ = write!(o, "\n{FIELD}],");
                }
            });
            out.push(object("spheres", text));
        }
    }
    for c in &g.cones {
        let (base, apex) = (v3(&c[..3]), v3(&c[4..7]));
        out.push(if c[3].to_bits() == c[7].to_bits() {
            object(
                "cylinder",
                format!(
                    "(base: {base}, apex: {apex}, radius: {}, caps: false)",
                    num(c[3])
                ),
            )
        } else {
            object(
                "cone",
                format!(
                    "(base: {base}, base_radius: {}, apex: {apex}, apex_radius: {}, caps: false)",
                    num(c[3]),
                    num(c[7])
                ),
            )
        });
    }
    for d in &g.discs {
        out.push(object(
            "ring",
            format!(
                "(center: {}, normal: {}, inner: {}, outer: {})",
                v3(&d[..3]),
                v3(&d[3..6]),
                num(d[6]),
                num(d[7])
            ),
        ));
    }
    for p in &g.planes {
        out.push(object(
            "plane",
            format!("(point: {}, normal: {})", v3(&p[..3]), v3(&p[3..6])),
        ));
    }
    let m = &g.mesh;
    if !m.indices.is_empty() {
        let text = params(|o| {
            vector_field(o, "positions", &m.positions, exact);
            if !m.normals.is_empty() {
                vector_field(o, "normals", &m.normals, exact);
            }
            if !m.uvs.is_empty() {
                let _ = write!(o, "\n{FIELD}uvs: [");
                items(o, m.uvs.len(), 4, ITEM, |o, k| tuple(o, &m.uvs[k], exact));
                let _ = write!(o, "\n{FIELD}],");
            }
            if !m.colors.is_empty() {
                vector_field(o, "colors", &m.colors, exact);
            }
            index_field(o, &m.indices);
        });
        out.push(object("mesh", text));
    }
    out
}

/// Writes `desc` as a RON scene to be read from directory `base` (where the `.ron` file
/// goes): paths the loader resolves against the scene's directory (outputs, plugin
/// directories) are written relative to `base` when inside it, else absolute. The `objects`
/// come first, then the `inline` groups as objects ([`inline_as_objects`]), the order in which
/// the core stores them. Plugin parameters are written as they stand.
pub fn to_ron(desc: &SceneDesc, base: &Path) -> Result<String, String> {
    // Every field, by name: a field added to the description must be written here too.
    let SceneDesc {
        source,
        camera,
        background,
        lights,
        fog,
        ambient_occlusion,
        textures,
        materials,
        clip_groups,
        objects,
        inline,
        volumes,
        render,
        plugin_path,
        warnings,
        animation,
        prototypes,
        instances,
        series,
    } = desc;
    let anim = animation.as_ref().map(|a| &a.value);
    // The names the animation uses, by index in `lights` / `objects`.
    let light_name = |i: usize| {
        let keyed = anim.and_then(|a| a.lights.iter().find(|l| l.light == i));
        keyed.map(|l| l.name.value.as_str())
    };
    let object_name = |i: usize| {
        let keyed = anim.and_then(|a| a.objects.iter().find(|o| o.object == i));
        keyed.map(|o| o.name.value.as_str())
    };
    let mut w = Vec::new();
    let _ = writeln!(
        w,
        "// Written by Luxon (`luxon convert` or `api::Scene::to_ron`) from {}.",
        one_comment_line(&source.display().to_string())
    );
    if !warnings.is_empty() {
        w.extend_from_slice(
            b"// Not carried over: what the source says that this scene does not (the warnings on\n\
              // reading it).\n",
        );
        for warning in warnings {
            let _ = writeln!(w, "//   {}", one_comment_line(&warning.to_string()));
        }
    }
    w.extend_from_slice(b"Scene(\n");
    if !plugin_path.is_empty() {
        let dirs: Vec<String> = plugin_path
            .iter()
            .map(|p| string(&relative(p, base)))
            .collect();
        let _ = writeln!(w, "    plugin_path: [{}],", dirs.join(", "));
    }
    write_camera(&mut w, &camera.value);
    let _ = writeln!(w, "    background: {},", background_text(background));
    if !lights.is_empty() {
        w.extend_from_slice(b"    lights: [\n");
        for (i, l) in lights.iter().enumerate() {
            let _ = writeln!(w, "        {},", named_light(&l.value, light_name(i)));
        }
        w.extend_from_slice(b"    ],\n");
    }
    if let Some(f) = fog {
        let _ = writeln!(w, "    fog: {},", fog_text(f));
    }
    if let Some(a) = ambient_occlusion {
        let _ = writeln!(w, "    ambient_occlusion: {},", ambient_occlusion_text(a));
    }
    if !textures.is_empty() {
        w.extend_from_slice(b"    textures: {\n");
        for (name, t) in textures {
            let _ = writeln!(
                w,
                "        {}: (plugin: {}, params: {}),",
                string(name),
                string(&t.value.plugin.value),
                t.value.params
            );
        }
        w.extend_from_slice(b"    },\n");
    }
    if !materials.is_empty() {
        w.extend_from_slice(b"    materials: {\n");
        for (name, m) in materials {
            let _ = writeln!(w, "        {}: {},", string(name), material(&m.value));
        }
        w.extend_from_slice(b"    },\n");
    }
    if !clip_groups.is_empty() {
        w.extend_from_slice(b"    clip_groups: {\n");
        for (name, planes) in clip_groups {
            let _ = writeln!(
                w,
                "        {}: {},",
                string(name),
                clip_planes(&planes.value)
            );
        }
        w.extend_from_slice(b"    },\n");
    }
    if !volumes.is_empty() {
        w.extend_from_slice(b"    volumes: [\n");
        for v in volumes {
            let _ = writeln!(w, "        {},", volume(&v.value));
        }
        w.extend_from_slice(b"    ],\n");
    }
    let imported = inline.iter().flat_map(|g| inline_as_objects(g, &camera.at));
    let all: Vec<Spanned<ObjectDesc>> = objects.iter().cloned().chain(imported).collect();
    if !all.is_empty() {
        w.extend_from_slice(b"    objects: [\n");
        for (i, o) in all.iter().enumerate() {
            // Only the scene's own objects can be named (imported ones come after them).
            let name = object_name(i).filter(|_| i < objects.len());
            let _ = writeln!(w, "        {},", object(&o.value, name));
        }
        w.extend_from_slice(b"    ],\n");
    }
    write_instances(&mut w, prototypes, instances);
    write_series(&mut w, series, base);
    if let Some(a) = anim {
        write_animation(&mut w, a);
    }
    // An animated scene's frames set the frame and time: it takes neither.
    write_render(&mut w, render, base, anim.is_none());
    w.extend_from_slice(b")\n");
    String::from_utf8(w).map_err(|e| e.to_string())
}

/// `(plugin: ..., name: ..., params: ..., material: ..., clip: ..., shadows: false)`.
fn object(o: &ObjectDesc, name: Option<&str>) -> String {
    let mut w = Vec::new();
    let _ = write!(w, "(plugin: {}", string(&o.call.plugin.value));
    if let Some(name) = name {
        let _ = write!(w, ", name: {}", string(name));
    }
    let _ = write!(w, ", params: {}", o.call.params);
    if let Some(m) = &o.material {
        let _ = write!(w, ", material: {}", string(&m.value));
    }
    if let Some(c) = &o.clip {
        let _ = write!(w, ", clip: {}", string(&c.value));
    }
    if !o.shadows {
        w.extend_from_slice(b", shadows: false");
    }
    w.push(b')');
    String::from_utf8(w).unwrap_or_default()
}

/// `prototypes: { ... }` and `instances: [ ... ]`, each when not empty.
fn write_instances(
    w: &mut Vec<u8>,
    prototypes: &[(String, Spanned<PrototypeDesc>)],
    instances: &[Spanned<InstanceDesc>],
) {
    if !prototypes.is_empty() {
        w.extend_from_slice(b"    prototypes: {\n");
        for (name, p) in prototypes {
            let _ = writeln!(w, "        {}: (objects: [", string(name));
            // Its meshes as objects after its own, as for the scene's (see the module docs).
            let meshes = p
                .value
                .inline
                .iter()
                .flat_map(|g| inline_as_objects(g, &p.at));
            for o in p.value.objects.iter().cloned().chain(meshes) {
                let _ = writeln!(w, "            {},", object(&o.value, None));
            }
            w.extend_from_slice(b"        ]),\n");
        }
        w.extend_from_slice(b"    },\n");
    }
    if !instances.is_empty() {
        w.extend_from_slice(b"    instances: [\n");
        for i in instances {
            let i = &i.value;
            let _ = write!(w, "        (prototype: {}", string(&i.prototype.value));
            if let Some(n) = &i.name {
                let _ = write!(w, ", name: {}", string(&n.value));
            }
            if i.world_from_object.value != TransformDesc::IDENTITY {
                let _ = write!(
                    w,
                    ", world_from_object: {}",
                    transform(&i.world_from_object.value)
                );
            }
            if let Some(m) = &i.material {
                let _ = write!(w, ", material: {}", string(&m.value));
            }
            w.extend_from_slice(b"),\n");
        }
        w.extend_from_slice(b"    ],\n");
    }
}

/// `series: [ ... ]` when not empty, patterns relative to `base`.
fn write_series(w: &mut Vec<u8>, series: &[Spanned<SeriesDesc>], base: &Path) {
    if series.is_empty() {
        return;
    }
    let style = |a: &AtomStyle| match &a.material {
        Some(m) => format!(
            "(radius: {}, material: {})",
            num(a.radius),
            string(&m.value)
        ),
        None => format!("(radius: {})", num(a.radius)),
    };
    w.extend_from_slice(b"    series: [\n");
    for s in series {
        let s = &s.value;
        let files = relative(&s.dir.join(&s.files.value), base);
        let _ = write!(
            w,
            "        (name: {}, files: {}, first: {}, per_frame: {}",
            string(&s.name.value),
            string(&files),
            s.first,
            s.per_frame
        );
        match &s.kind {
            SeriesKind::Atoms { atoms, default } => {
                if !atoms.is_empty() {
                    let list: Vec<String> = atoms
                        .iter()
                        .map(|(n, a)| format!("{}: {}", string(n), style(a)))
                        .collect();
                    let _ = write!(w, ", atoms: {{{}}}", list.join(", "));
                }
                if let Some(d) = default {
                    let _ = write!(w, ", default_atom: {}", style(d));
                }
            }
            SeriesKind::Mesh { material: Some(m) } => {
                let _ = write!(w, ", material: {}", string(&m.value));
            }
            SeriesKind::Mesh { material: None } => {}
        }
        w.extend_from_slice(b"),\n");
    }
    w.extend_from_slice(b"    ],\n");
}

/// `(translate: ..., rotate: ..., scale: ...)` (the fields that are not the identity's) or
/// `(matrix: (...))`.
pub(crate) fn transform(t: &TransformDesc) -> String {
    match t {
        TransformDesc::Trs {
            translate,
            rotate,
            scale,
        } => {
            let mut f = Vec::new();
            if *translate != [0.0; 3] {
                f.push(format!("translate: {}", v3(translate)));
            }
            if let Some(r) = rotate {
                f.push(format!(
                    "rotate: (axis: {}, degrees: {})",
                    v3(&r.axis),
                    num(r.degrees)
                ));
            }
            if *scale != [1.0; 3] {
                f.push(format!("scale: {}", v3(scale)));
            }
            format!("({})", f.join(", "))
        }
        TransformDesc::Matrix(m) => {
            let rows: Vec<String> = m.iter().map(|r| v3(r)).collect();
            format!("(matrix: ({}))", rows.join(", "))
        }
    }
}

fn write_camera(w: &mut Vec<u8>, c: &CameraDesc) {
    w.extend_from_slice(b"    camera: (\n");
    for field in camera_fields(c) {
        let _ = writeln!(w, "        {field},");
    }
    w.extend_from_slice(b"    ),\n");
}

/// The camera's fields, `name: value` each (the scene writes them a line each, a fragment on
/// one line).
pub(crate) fn camera_fields(c: &CameraDesc) -> Vec<String> {
    let CameraDesc {
        position,
        look_at,
        up,
        projection,
        aspect,
        frustum,
        depth_of_field,
        stereo,
    } = c;
    let mut f = vec![
        format!("position: {}", v3(position)),
        format!("look_at: {}", v3(look_at)),
        format!("up: {}", v3(up)),
    ];
    // A frustum sizes the window itself: RON takes no fov, zoom or height beside it.
    let sized = frustum.is_none();
    match projection {
        Projection::Perspective { fov_deg } if sized => f.push(format!("fov: {}", num(*fov_deg))),
        Projection::PerspectiveZoom { zoom } if sized => f.push(format!("zoom: {}", num(*zoom))),
        Projection::Perspective { .. } | Projection::PerspectiveZoom { .. } => {}
        Projection::Orthographic { height } if sized => f.push(format!(
            "projection: Orthographic(height: {})",
            num(*height)
        )),
        Projection::Orthographic { .. } => f.push("projection: Orthographic()".into()),
        Projection::Fisheye { fov_deg } => {
            f.push(format!("projection: Fisheye(fov: {})", num(*fov_deg)))
        }
        Projection::Equirectangular => f.push("projection: Equirectangular".into()),
    }
    if let Some(a) = aspect {
        f.push(format!("aspect: {}", num(*a)));
    }
    if let Some(w) = frustum {
        f.push(format!(
            "frustum: (left: {}, right: {}, bottom: {}, top: {})",
            num(w.left),
            num(w.right),
            num(w.bottom),
            num(w.top)
        ));
    }
    if let Some(d) = depth_of_field {
        f.push(format!(
            "depth_of_field: (aperture: {}, focal_distance: {})",
            num(d.aperture),
            num(d.focal_distance)
        ));
    }
    if let Some(s) = stereo {
        let layout = match s.layout {
            StereoLayout::SideBySide => "SideBySide",
            StereoLayout::OverUnder => "OverUnder",
        };
        f.push(format!(
            "stereo: (layout: {layout}, eye_separation: {}, convergence: {})",
            num(s.eye_separation),
            num(s.convergence)
        ));
    }
    f
}

/// The background's RON text: `(r, g, b)` or `Gradient(...)`.
pub(crate) fn background_text(b: &BackgroundDesc) -> String {
    match b {
        BackgroundDesc::Color(c) => v3(c),
        BackgroundDesc::Gradient(g) => format!(
            "Gradient(kind: {:?}, up: {}, top: {}, bottom: {}, top_color: {}, bottom_color: {})",
            g.kind,
            v3(&g.up),
            num(g.top),
            num(g.bottom),
            v3(&g.top_color),
            v3(&g.bottom_color)
        ),
    }
}

/// Fog's RON text, `(mode: ..., ...)`.
pub(crate) fn fog_text(f: &FogDesc) -> String {
    let mode = match f.mode {
        FogMode::Linear { start, end } => {
            format!("Linear(start: {}, end: {})", num(start), num(end))
        }
        FogMode::Exp { density, start } => {
            format!("Exp(density: {}, start: {})", num(density), num(start))
        }
        FogMode::Exp2 { density, start } => {
            format!("Exp2(density: {}, start: {})", num(density), num(start))
        }
    };
    format!(
        "(mode: {mode}, color: {}, planar: {}, every_ray: {}, misses: {})",
        v3(&f.color),
        f.planar,
        f.every_ray,
        f.misses
    )
}

/// Ambient occlusion's RON text, `(samples: ..., ...)`.
pub(crate) fn ambient_occlusion_text(a: &AoDesc) -> String {
    let AoDesc {
        samples,
        max_distance,
        color,
        intensity,
        direct,
    } = a;
    // An unlimited distance is the default, which RON writes by leaving the field out.
    let distance = match max_distance.is_finite() {
        true => format!(" distance: {},", num(*max_distance)),
        false => String::new(),
    };
    format!(
        "(samples: {samples},{distance} color: {}, intensity: {}, direct: {})",
        v3(color),
        num(*intensity),
        num(*direct)
    )
}

/// A clip group's planes, `[(point: ..., normal: ...), ...]`.
pub(crate) fn clip_planes(planes: &[ClipPlaneDesc]) -> String {
    let planes: Vec<String> = planes
        .iter()
        .map(|p| format!("(point: {}, normal: {})", v3(&p.point), v3(&p.normal)))
        .collect();
    format!("[{}]", planes.join(", "))
}

fn attenuation(a: &Attenuation) -> String {
    v3(&[a.constant, a.linear, a.quadratic])
}

/// The light's RON text, with `name` when it has one.
fn named_light(l: &LightDesc, name: Option<&str>) -> String {
    let text = light(l);
    match name {
        // "Point(" + "name: ..., " + the fields.
        Some(n) => match text.split_once('(') {
            Some((kind, rest)) => format!("{kind}(name: {}, {rest}", string(n)),
            None => text,
        },
        None => text,
    }
}

/// A light's RON text, e.g. `Point(position: ..., ...)`.
pub(crate) fn light(l: &LightDesc) -> String {
    match l {
        LightDesc::Point {
            position,
            color,
            intensity,
            shadows,
            attenuation: a,
        } => format!(
            "Point(position: {}, color: {}, intensity: {}, shadows: {shadows}, attenuation: {})",
            v3(position),
            v3(color),
            num(*intensity),
            attenuation(a)
        ),
        LightDesc::Directional {
            direction,
            color,
            intensity,
            shadows,
        } => format!(
            "Directional(direction: {}, color: {}, intensity: {}, shadows: {shadows})",
            v3(direction),
            v3(color),
            num(*intensity)
        ),
        LightDesc::Spot {
            position,
            direction,
            cone_deg,
            falloff_deg,
            color,
            intensity,
            shadows,
            attenuation: a,
            fade,
        } => format!(
            "Spot(position: {}, direction: {}, angle: {}, falloff: {}, fade: {}, color: {}, \
             intensity: {}, shadows: {shadows}, attenuation: {})",
            v3(position),
            v3(direction),
            num(*cone_deg),
            num(*falloff_deg),
            match fade {
                SpotFade::Smooth => "Smooth",
                SpotFade::Linear => "Linear",
            },
            v3(color),
            num(*intensity),
            attenuation(a)
        ),
        LightDesc::Sphere {
            center,
            radius,
            samples,
            color,
            intensity,
            shadows,
            attenuation: a,
        } => format!(
            "SphereLight(center: {}, radius: {}, samples: {samples}, color: {}, intensity: {}, \
             shadows: {shadows}, attenuation: {})",
            v3(center),
            num(*radius),
            v3(color),
            num(*intensity),
            attenuation(a)
        ),
        LightDesc::Rect {
            corner,
            edge1,
            edge2,
            samples,
            color,
            intensity,
            shadows,
            attenuation: a,
        } => format!(
            "RectLight(corner: {}, edge1: {}, edge2: {}, samples: {samples}, color: {}, \
             intensity: {}, shadows: {shadows}, attenuation: {})",
            v3(corner),
            v3(edge1),
            v3(edge2),
            v3(color),
            num(*intensity),
            attenuation(a)
        ),
    }
}

/// A material's RON text, `(color: ..., ...)`.
pub(crate) fn material(m: &MaterialDesc) -> String {
    let MaterialDesc {
        color,
        texture,
        reflect_texture,
        transmit_texture,
        ambient,
        diffuse,
        specular,
        shininess,
        highlight,
        highlight_color,
        reflect,
        transmit,
        ior,
        transparency_angle,
        outline,
        outline_width,
        fog,
    } = m;
    let mut s = format!("(color: {}", v3(color));
    for (name, t) in [
        ("texture", texture),
        ("reflect_texture", reflect_texture),
        ("transmit_texture", transmit_texture),
    ] {
        if let Some(t) = t {
            s += &format!(", {name}: {}", string(&t.value));
        }
    }
    let highlight = match highlight {
        Highlight::Phong => "Phong",
        Highlight::Blinn => "Blinn",
        Highlight::BlinnFast => "BlinnFast",
    };
    let highlight_color = match highlight_color {
        HighlightColor::Light => "Light",
        HighlightColor::Surface => "Surface",
    };
    // Without highlights the exponent is unused and may be 0, which RON does not take: the
    // default stands in (and reads back as itself, so a second conversion writes the same).
    let shininess = match *specular == 0.0 && *shininess <= 0.0 {
        true => MaterialDesc::default().shininess,
        false => *shininess,
    };
    s += &format!(
        ", ambient: {}, diffuse: {}, specular: {}, shininess: {}, highlight: {highlight}, \
         highlight_color: {highlight_color}, reflect: {}, transmit: {}, ior: {}",
        num(*ambient),
        num(*diffuse),
        num(*specular),
        num(shininess),
        num(*reflect),
        num(*transmit),
        num(*ior)
    );
    if let Some(a) = transparency_angle {
        s += &format!(", transparency_angle: {}", angle(*a));
    }
    if *outline != 0.0 || *outline_width != 0.0 {
        s += &format!(
            ", outline: {}, outline_width: {}",
            num(*outline),
            num(*outline_width)
        );
    }
    if !fog {
        s += ", fog: false";
    }
    s + ")"
}

fn angle(a: TransparencyAngle) -> &'static str {
    match a {
        TransparencyAngle::Constant => "Constant",
        TransparencyAngle::Raster3D => "Raster3D",
    }
}

fn volume(v: &VolumeDescEntry) -> String {
    let VolumeDescEntry { call, name, render } = v;
    let mut s = format!(
        "(plugin: {}, params: {}",
        string(&call.plugin.value),
        call.params
    );
    if let Some(n) = name {
        s += &format!(", name: {}", string(&n.value));
    }
    if let Some(r) = render {
        s += &format!(", render: {}", volume_render(&r.value));
    }
    s + ")"
}

/// A volume's render block, `(transfer: (...), ...)`.
pub(crate) fn volume_render(r: &VolumeRenderDesc) -> String {
    let VolumeRenderDesc {
        transfer,
        step,
        interpolation,
        shading,
        clip,
        bounds,
    } = r;
    let TransferDesc {
        preset,
        points,
        range,
        opacity,
    } = transfer;
    // A preset's points come back from its name.
    let mut t = match preset {
        Some(p) => format!("preset: {}", string(p)),
        None => {
            let points: Vec<String> = points
                .iter()
                .map(|p| {
                    format!(
                        "(x: {}, color: {}, opacity: {})",
                        num(p.x),
                        v3(&p.color),
                        num(p.opacity)
                    )
                })
                .collect();
            format!("points: [{}]", points.join(", "))
        }
    };
    if let Some([a, b]) = range {
        t += &format!(", range: ({}, {})", num(*a), num(*b));
    }
    t += &format!(", opacity: {}", num(*opacity));
    let mut s = format!("(transfer: ({t})");
    if let Some(step) = step {
        s += &format!(", step: {}", num(*step));
    }
    s += match interpolation {
        Interpolation::Nearest => ", interpolation: Nearest",
        Interpolation::Trilinear => ", interpolation: Trilinear",
    };
    if let Some(sh) = shading {
        s += &format!(
            ", shading: (ambient: {}, diffuse: {}, specular: {}, shininess: {}, shadows: {})",
            num(sh.ambient),
            num(sh.diffuse),
            num(sh.specular),
            num(sh.shininess),
            sh.shadows
        );
    }
    if let Some(c) = clip {
        s += &format!(", clip: {}", string(&c.value));
    }
    if let Some((lo, hi)) = bounds {
        s += &format!(", bounds: (min: {}, max: {})", v3(lo), v3(hi));
    }
    s + ")"
}

/// `animation: (...)`: the frames, the shutter and every track.
fn write_animation(w: &mut Vec<u8>, a: &AnimationDesc) {
    let AnimationDesc {
        first,
        last,
        fps,
        shutter,
        camera,
        lights,
        materials,
        objects,
        instances,
    } = a;
    let _ = writeln!(w, "    animation: (");
    let _ = writeln!(
        w,
        "        frames: ({first}, {last}),\n        fps: {},",
        num(*fps)
    );
    if let Some(s) = shutter {
        let at = match s.value.at {
            ShutterAt::Start => "Start",
            ShutterAt::Centre => "Centre",
            ShutterAt::End => "End",
        };
        let length = num(s.value.length);
        let _ = writeln!(w, "        shutter: (length: {length}, at: {at}),");
    }
    let point = |v: &[f64; 3]| v3(v);
    let scalar = |x: &f64| num(*x);
    let rotation =
        |r: &RotationDesc| format!("(axis: {}, degrees: {})", v3(&r.axis), num(r.degrees));
    let CameraTracks {
        position,
        look_at,
        up,
        fov,
        focal_distance,
    } = camera;
    let fields = [
        track("position", position, point, CAMERA),
        track("look_at", look_at, point, CAMERA),
        track("up", up, point, CAMERA),
        track("fov", fov, scalar, CAMERA),
        track("focal_distance", focal_distance, scalar, CAMERA),
    ];
    write_tracks(w, "camera", &fields);
    let mut entries = Vec::new();
    for l in lights {
        let fields = [
            track("position", &l.position, point, KEYED),
            track("direction", &l.direction, point, KEYED),
            track("intensity", &l.intensity, scalar, KEYED),
            track("color", &l.color, point, KEYED),
        ];
        entries.push((&l.name.value, fields.into_iter().flatten().collect()));
    }
    write_keyed(w, "lights", entries);
    let mut entries = Vec::new();
    for m in materials {
        let fields = [track("color", &m.color, point, KEYED)];
        entries.push((&m.material.value, fields.into_iter().flatten().collect()));
    }
    write_keyed(w, "materials", entries);
    let mut entries = Vec::new();
    for o in objects.iter().chain(instances) {
        let fields = [
            track("translate", &o.translate, point, KEYED),
            track("rotate", &o.rotate, rotation, KEYED),
            track("scale", &o.scale, point, KEYED),
        ];
        entries.push((&o.name.value, fields.into_iter().flatten().collect()));
    }
    write_keyed(w, "objects", entries);
    w.extend_from_slice(b"    ),\n");
}

/// Indentation of the tracks of `camera: (...)` and of `lights: { "name": (...) }`'s entries.
const CAMERA: &str = "            ";
const KEYED: &str = "                ";

/// `name: (keys: [(frame, value), ...], interpolation: ...)`, or `None` without the track;
/// more than three keys go three to a line below the field's line (indented by `indent`).
fn track<T>(
    name: &str,
    t: &Option<Track<T>>,
    value: impl Fn(&T) -> String,
    indent: &str,
) -> Option<String> {
    let t = t.as_ref()?;
    let key = |k: &Key<T>| format!("({}, {})", num(k.frame), value(&k.value));
    let keys = if t.keys.len() <= 3 {
        let keys: Vec<String> = t.keys.iter().map(key).collect();
        keys.join(", ")
    } else {
        let mut out = Vec::new();
        let inner = format!("{indent}    ");
        items(&mut out, t.keys.len(), 3, &inner, |o, i| {
            o.extend_from_slice(key(&t.keys[i]).as_bytes())
        });
        let _ = write!(out, "\n{indent}");
        String::from_utf8(out).unwrap_or_default()
    };
    let interpolation = match t.interpolation {
        Interpolate::Linear => "Linear",
        Interpolate::CatmullRom => "CatmullRom",
    };
    Some(format!(
        "{name}: (keys: [{keys}], interpolation: {interpolation})"
    ))
}

/// `camera: (...)` of the tracks given, nothing when none is.
fn write_tracks(w: &mut Vec<u8>, name: &str, fields: &[Option<String>]) {
    let fields: Vec<&str> = fields.iter().flatten().map(String::as_str).collect();
    if !fields.is_empty() {
        let _ = writeln!(
            w,
            "        {name}: (\n            {},\n        ),",
            fields.join(",\n            ")
        );
    }
}

/// `lights: { "name": (tracks...), ... }`, nothing when empty.
fn write_keyed(w: &mut Vec<u8>, map: &str, entries: Vec<(&String, Vec<String>)>) {
    if entries.is_empty() {
        return;
    }
    let _ = writeln!(w, "        {map}: {{");
    for (name, fields) in entries {
        let _ = writeln!(
            w,
            "            {}: (\n                {},\n            ),",
            string(name),
            fields.join(",\n                ")
        );
    }
    w.extend_from_slice(b"        },\n");
}

/// `clock`: whether to write `frame` and `time` (an animated scene takes neither).
fn write_render(w: &mut Vec<u8>, r: &RenderDesc, base: &Path, clock: bool) {
    w.extend_from_slice(b"    render: (\n");
    for (_, field) in render_fields(r, base, clock) {
        let _ = writeln!(w, "        {field},");
    }
    w.extend_from_slice(b"    ),\n");
}

/// The render settings' fields, each `(name, "name: value")` (a scene writes them a line
/// each); `clock`: with `frame` and `time`; output paths relative to `base`.
pub(crate) fn render_fields(
    r: &RenderDesc,
    base: &Path,
    clock: bool,
) -> Vec<(&'static str, String)> {
    let RenderDesc {
        width,
        height,
        samples,
        max_depth,
        min_weight,
        outputs,
        parallel,
        frame,
        time,
        transparency,
        volume_step,
        volume_skip,
        adaptive,
        light_scale,
        tachyon,
        memory,
        texture_cache,
        instancing,
    } = r;
    let mut f = vec![
        ("width", format!("width: {width}")),
        ("height", format!("height: {height}")),
        ("samples", format!("samples: {samples}")),
        ("max_depth", format!("max_depth: {max_depth}")),
        ("min_weight", format!("min_weight: {}", num(*min_weight))),
    ];
    if clock {
        f.push(("frame", format!("frame: {frame}")));
        f.push(("time", format!("time: {}", num(*time))));
    }
    if !outputs.is_empty() {
        let mut list = String::from("outputs: [\n");
        for o in outputs {
            list += &format!("            (path: {}", string(&relative(&o.path, base)));
            if let Some(p) = &o.plugin {
                list += &format!(", plugin: {}", string(&p.value));
            }
            list += &format!(", params: {}),\n", o.params);
        }
        f.push(("outputs", list + "        ]"));
    }
    let ParallelDesc {
        mode,
        threads,
        decomposition,
        tile_size,
        io,
        frames,
    } = parallel;
    let mode = match mode {
        ParallelMode::Threads => "Threads",
        ParallelMode::Mpi => "Mpi",
        ParallelMode::Hybrid => "Hybrid",
    };
    let decomposition = match decomposition {
        Decomposition::PixelCyclic => "PixelCyclic",
        Decomposition::ScanlineCyclic => "ScanlineCyclic",
        Decomposition::BlockCyclic => "BlockCyclic",
        Decomposition::Dynamic => "Dynamic",
    };
    let io = match io {
        OutputIo::Async => "Async",
        OutputIo::Sync => "Sync",
        OutputIo::MpiIo => "MpiIo",
    };
    let threads = threads.map_or(String::new(), |t| format!(" threads: {t},"));
    let frames = match frames {
        FrameGroups::Auto => String::new(),
        FrameGroups::Whole => ", frames: Whole".into(),
        FrameGroups::Groups(n) => format!(", frames: Groups({n})"),
        FrameGroups::Shared => ", frames: Shared".into(),
    };
    f.push((
        "parallel",
        format!(
            "parallel: (mode: {mode},{threads} decomposition: {decomposition}, tile_size: \
             {tile_size}, io: {io}{frames})"
        ),
    ));
    let TransparencyDesc {
        mode,
        angle: transparency_angle,
        max_surfaces,
        beyond_max,
        shadows,
        scale_reflection,
    } = transparency;
    let mode = match mode {
        TransparencyMode::Filter => "Filter",
        TransparencyMode::AngleModulated => "AngleModulated",
        TransparencyMode::PostMultiplied => "PostMultiplied",
        TransparencyMode::Additive => "Additive",
    };
    let max = max_surfaces.map_or(String::new(), |n| format!(", max_surfaces: {n}"));
    let beyond_max = match beyond_max {
        BeyondMax::Opaque => "Opaque",
        BeyondMax::Skip => "Skip",
    };
    let shadows = match shadows {
        TransparentShadows::Tinted => "Tinted",
        TransparentShadows::Untinted => "Untinted",
        TransparentShadows::Off => "Off",
    };
    f.push((
        "transparency",
        format!(
            "transparency: (mode: {mode}, angle: {}{max}, beyond_max: {beyond_max}, shadows: \
             {shadows}, scale_reflection: {scale_reflection})",
            angle(*transparency_angle)
        ),
    ));
    let TachyonDesc {
        light_threshold,
        plain_highlights,
        depth_limit_background,
        centre_sample,
        additive_volumes,
        terminator_shadows,
    } = tachyon;
    f.push(("light_scale", format!("light_scale: {}", num(*light_scale))));
    f.push((
        "tachyon",
        format!(
            "tachyon: (light_threshold: {light_threshold}, plain_highlights: \
             {plain_highlights}, depth_limit_background: {depth_limit_background}, \
             centre_sample: {centre_sample}, additive_volumes: {additive_volumes}, \
             terminator_shadows: {terminator_shadows})"
        ),
    ));
    f.push(("volume_step", format!("volume_step: {}", num(*volume_step))));
    f.push(("volume_skip", format!("volume_skip: {volume_skip}")));
    if let Some(a) = adaptive {
        f.push((
            "adaptive",
            format!(
                "adaptive: (threshold: {}, max_depth: {})",
                num(a.threshold),
                a.max_depth
            ),
        ));
    }
    if let Some(m) = memory {
        f.push(("memory", format!("memory: \"{m}\"")));
    }
    if let Some(n) = texture_cache {
        f.push((
            "texture_cache",
            format!("texture_cache: \"{}\"", MemorySize::Bytes(*n)),
        ));
    }
    // Written only when not the default, so scenes without instances read as before.
    match instancing {
        Instancing::Auto => {}
        Instancing::Bake => f.push(("instancing", "instancing: Bake".into())),
        Instancing::Share => f.push(("instancing", "instancing: Share".into())),
    }
    f
}

/// `s` with line breaks (and other control characters) as spaces: it must stay in its `//`
/// comment.
fn one_comment_line(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// `path` as the loader will resolve it from `base`: relative when inside `base`.
fn relative(path: &Path, base: &Path) -> String {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (p, b): (PathBuf, PathBuf) = (abs(path), abs(base));
    match p.strip_prefix(&b) {
        Ok(rest) if !rest.as_os_str().is_empty() => rest.display().to_string(),
        _ => p.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_back_exactly() {
        for x in [0.1, -0.0, 1e-7, 3e300, 1.0 / 3.0, 5.0] {
            let mut b = Vec::new();
            exact(&mut b, x);
            let back: f64 = ron::from_str(std::str::from_utf8(&b).unwrap()).unwrap();
            assert_eq!(back.to_bits(), x.to_bits());
        }
    }

    #[test]
    fn paths_inside_the_base_are_relative() {
        let base = std::env::temp_dir().join("scenes");
        assert_eq!(relative(&base.join("out/a.png"), &base), "out/a.png");
        let other = std::env::temp_dir().join("elsewhere/a.png");
        assert_eq!(relative(&other, &base), other.display().to_string());
    }
}
