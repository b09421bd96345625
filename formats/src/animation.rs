//! `animation:`: the frame range, the shutter and the keyed values, checked at their positions
//! (`Checker::animation`); and, once every file is merged, the names it uses resolved to the
//! lights and objects they name and the keyed properties matched against what those have
//! (`resolve`).

use crate::desc::*;
use crate::error::{quoted_list, shown, unknown_name, SceneError};
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

type Result<T> = std::result::Result<T, SceneError>;

/// Lights or objects named in one file: (index within the file's list, the name).
pub(crate) type ItemNames = Vec<(usize, Spanned<String>)>;

/// Stands for a light or object index until `resolve` finds it.
const UNRESOLVED: usize = usize::MAX;

/// Field `name` of `node`, or `node` itself when it has none (errors then point at `node`).
fn field<'n>(node: &'n Node, name: &str) -> &'n Node {
    node.field(name).unwrap_or(node)
}

fn length(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// What a track's values must be, and how they are named in messages.
#[derive(Clone, Copy)]
enum Check {
    /// Any vector.
    Point,
    /// A non-zero vector.
    Direction,
    /// Components >= 0.
    Colour,
    /// >= 0.
    NonNegative,
    /// > 0.
    Positive,
    /// Degrees in (0, 180).
    Fov,
    /// Components != 0.
    Scale,
}

impl Checker<'_> {
    /// The `animation:` block at `node`. Light and object indices are resolved after merging
    /// (`resolve`).
    pub(crate) fn animation(&self, a: raw::Animation, node: &Node) -> Result<AnimationDesc> {
        let field = |name: &str| field(node, name);
        let frames = field("frames");
        let first = self.whole(
            frames.item(0).unwrap_or(frames),
            "frames",
            a.frames.0,
            0,
            u32::MAX,
        )?;
        let last = self.whole(
            frames.item(1).unwrap_or(frames),
            "frames",
            a.frames.1,
            0,
            u32::MAX,
        )?;
        if first > last {
            return Err(self.error(
                frames,
                format!(
                    "the frame range {first}..{last} is empty; expected `frames: (first, last)` \
                     with first <= last"
                ),
            ));
        }
        let fps = match a.fps {
            Some(f) => self.positive(field("fps"), "fps", f)?,
            None => 24.0,
        };
        let shutter = match a.shutter {
            Some(s) => {
                let at = field("shutter");
                let length = s.length;
                let length =
                    self.range(at.field("length").unwrap_or(at), "length", length, 0.0, 2.0)?;
                let place = match s.at {
                    Some(raw::ShutterAt::Start) => ShutterAt::Start,
                    Some(raw::ShutterAt::Centre) | None => ShutterAt::Centre,
                    Some(raw::ShutterAt::End) => ShutterAt::End,
                };
                Some(self.spanned(ShutterDesc { length, at: place }, at))
            }
            None => None,
        };
        let camera = match a.camera {
            Some(c) => {
                let at = field("camera");
                let t = |name: &str| (at.field(name).unwrap_or(at), format!("camera.{name}"));
                CameraTracks {
                    position: self.track(c.position, t("position"), Check::Point)?,
                    look_at: self.track(c.look_at, t("look_at"), Check::Point)?,
                    up: self.track(c.up, t("up"), Check::Direction)?,
                    fov: self.track(c.fov, t("fov"), Check::Fov)?,
                    focal_distance: self.track(
                        c.focal_distance,
                        t("focal_distance"),
                        Check::Positive,
                    )?,
                }
            }
            None => CameraTracks::default(),
        };
        self.keyed_once(field("lights"), "light", &a.lights.0)?;
        self.keyed_once(field("materials"), "material", &a.materials.0)?;
        self.keyed_once(field("objects"), "object", &a.objects.0)?;
        let entry = |map: &str, i| field(map).entry(i).unwrap_or((node, node));
        let mut lights = Vec::new();
        for (i, (name, l)) in a.lights.0.into_iter().enumerate() {
            let (key, at) = entry("lights", i);
            let t = |p: &str| {
                (
                    at.field(p).unwrap_or(at),
                    format!("lights.{}.{p}", shown(&name)),
                )
            };
            lights.push(LightTracks {
                light: UNRESOLVED,
                position: self.track(l.position, t("position"), Check::Point)?,
                direction: self.track(l.direction, t("direction"), Check::Direction)?,
                intensity: self.track(l.intensity, t("intensity"), Check::NonNegative)?,
                color: self.track(l.color, t("color"), Check::Colour)?,
                name: self.spanned(name, key),
            });
        }
        let mut materials = Vec::new();
        for (i, (name, m)) in a.materials.0.into_iter().enumerate() {
            let (key, at) = entry("materials", i);
            let t = |p: &str| {
                (
                    at.field(p).unwrap_or(at),
                    format!("materials.{}.{p}", shown(&name)),
                )
            };
            materials.push(MaterialTracks {
                color: self.track(m.color, t("color"), Check::Colour)?,
                material: self.spanned(name, key),
            });
        }
        let mut objects = Vec::new();
        for (i, (name, o)) in a.objects.0.into_iter().enumerate() {
            let (key, at) = entry("objects", i);
            let t = |p: &str| {
                (
                    at.field(p).unwrap_or(at),
                    format!("objects.{}.{p}", shown(&name)),
                )
            };
            objects.push(ObjectTracks {
                object: UNRESOLVED,
                translate: self.track(o.translate, t("translate"), Check::Point)?,
                rotate: self.rotations(o.rotate, t("rotate"))?,
                scale: self.track(o.scale, t("scale"), Check::Scale)?,
                name: self.spanned(name, key),
            });
        }
        Ok(AnimationDesc {
            first,
            last,
            fps,
            shutter,
            camera,
            lights,
            materials,
            objects,
            instances: Vec::new(),
        })
    }

    /// Each name of an `animation` map (`node`) once.
    fn keyed_once<T>(&self, node: &Node, what: &str, entries: &[(String, T)]) -> Result<()> {
        for (i, (name, _)) in entries.iter().enumerate() {
            if let Some(first) = entries[..i].iter().position(|(n, _)| n == name) {
                let at = |k| node.entry(k).map_or(node, |(key, _)| key);
                let first = self.origin(at(first));
                return Err(self.error(
                    at(i),
                    format!(
                        "{what} `{}` is keyed twice in this `animation` (first at {}:{}); \
                         expected one entry per {what}",
                        shown(name),
                        first.line,
                        first.col
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The names given to the items of a list (`lights`, `objects`) at `node`: not empty.
    pub(crate) fn item_names<'n>(
        &self,
        node: &Node,
        names: impl Iterator<Item = Option<&'n str>>,
        what: &str,
    ) -> Result<ItemNames> {
        let mut out = Vec::new();
        for (i, name) in names.enumerate() {
            let Some(name) = name else { continue };
            let item = node.item(i).unwrap_or(node);
            let at = item.field("name").unwrap_or(item);
            if name.trim().is_empty() {
                return Err(self.error(
                    at,
                    format!(
                        "the {what} name is empty; expected a name such as \"key\" (or no `name`)"
                    ),
                ));
            }
            out.push((i, self.spanned(name.to_string(), at)));
        }
        Ok(out)
    }

    /// A track's keys in increasing frame order, each value checked.
    fn track<T: Copy + Value>(
        &self,
        track: Option<raw::Track<T>>,
        (node, what): (&Node, String),
        check: Check,
    ) -> Result<Option<Track<T>>> {
        let Some(track) = track else {
            return Ok(None);
        };
        let keys_node = node.field("keys").unwrap_or(node);
        let keys = self.keys(track.keys, keys_node, &what, |value, at| {
            value.check(self, at, &what, check)
        })?;
        Ok(Some(Track {
            keys,
            interpolation: interpolation(track.interpolation),
            at: self.origin(node),
        }))
    }

    /// Keys in increasing frame order (at least one), each value made by `value` from the raw
    /// value and its node.
    fn keys<'n, T, U>(
        &self,
        raw: Vec<(f64, T)>,
        node: &'n Node,
        what: &str,
        mut value: impl FnMut(T, &'n Node) -> Result<U>,
    ) -> Result<Vec<Key<U>>> {
        if raw.is_empty() {
            return Err(self.error(
                node,
                "the track has no keys; expected `keys: [(frame, value), ...]`",
            ));
        }
        let mut keys: Vec<Key<U>> = Vec::with_capacity(raw.len());
        for (i, (frame, v)) in raw.into_iter().enumerate() {
            let key = node.item(i).unwrap_or(node);
            let frame_at = key.item(0).unwrap_or(key);
            if let Some(before) = keys.last() {
                if frame == before.frame {
                    return Err(self.error(
                        frame_at,
                        format!(
                            "frame {} is keyed twice in `{what}` (first at {}:{}); expected one \
                             key per frame",
                            self.literal(frame_at),
                            before.at.line,
                            before.at.col
                        ),
                    ));
                }
                if frame < before.frame {
                    return Err(self.error(
                        frame_at,
                        format!(
                            "key frames must increase: frame {} comes after frame {} in \
                             `{what}`; expected keys in increasing frame order",
                            self.literal(frame_at),
                            before.frame
                        ),
                    ));
                }
            }
            let value = value(v, key.item(1).unwrap_or(key))?;
            keys.push(Key {
                frame,
                value,
                at: self.origin(frame_at),
            });
        }
        Ok(keys)
    }

    /// Rotation keys: non-zero axes (made unit length); a key about another axis than its
    /// neighbour's is reached by slerp the shorter way, so it may not ask for more than 180°.
    fn rotations(
        &self,
        track: Option<raw::Track<raw::Rotation>>,
        (node, what): (&Node, String),
    ) -> Result<Option<Track<RotationDesc>>> {
        let Some(track) = track else {
            return Ok(None);
        };
        let keys_node = node.field("keys").unwrap_or(node);
        let mut degrees_at = Vec::new();
        let keys = self.keys(track.keys, keys_node, &what, |r, at| {
            let axis_at = at.field("axis").unwrap_or(at);
            let n = length(r.axis);
            if n == 0.0 {
                return Err(self.error(
                    axis_at,
                    "the rotation's `axis` has zero length; expected a non-zero vector",
                ));
            }
            degrees_at.push(at.field("degrees").unwrap_or(at));
            Ok(RotationDesc {
                axis: r.axis.map(|c| c / n),
                degrees: r.degrees,
            })
        })?;
        for (i, pair) in keys.windows(2).enumerate() {
            let (a, b) = (&pair[0], &pair[1]);
            if a.value.axis == b.value.axis {
                continue;
            }
            for (k, at) in [(a, degrees_at[i]), (b, degrees_at[i + 1])] {
                let d = k.value.degrees;
                if d.abs() > 180.0 {
                    let short = d - 360.0 * (d / 360.0).round();
                    return Err(self.error(
                        at,
                        format!(
                            "the rotation keys at frames {} and {} in `{what}` turn about \
                             different axes, so slerp joins them the shorter way: {} degrees \
                             is reached as {short} degrees; write {short}, or key both about \
                             one axis to turn the long way",
                            a.frame,
                            b.frame,
                            self.literal(at)
                        ),
                    ));
                }
            }
        }
        Ok(Some(Track {
            keys,
            interpolation: interpolation(track.interpolation),
            at: self.origin(node),
        }))
    }
}

fn interpolation(i: Option<raw::Interpolate>) -> Interpolate {
    match i {
        Some(raw::Interpolate::CatmullRom) => Interpolate::CatmullRom,
        Some(raw::Interpolate::Linear) | None => Interpolate::Linear,
    }
}

/// A key's value, checked.
trait Value: Sized {
    fn check(self, c: &Checker, at: &Node, what: &str, check: Check) -> Result<Self>;
}

impl Value for f64 {
    fn check(self, c: &Checker, at: &Node, what: &str, check: Check) -> Result<f64> {
        let inf = f64::INFINITY;
        match check {
            Check::NonNegative => c.range(at, what, self, 0.0, inf),
            Check::Positive => c.positive(at, what, self),
            Check::Fov if !(self > 0.0 && self < 180.0) => Err(c.error(
                at,
                format!(
                    "`{what}` is {}; expected degrees between 0 and 180 (both excluded)",
                    c.literal(at)
                ),
            )),
            _ => Ok(self),
        }
    }
}

impl Value for [f64; 3] {
    fn check(self, c: &Checker, at: &Node, what: &str, check: Check) -> Result<[f64; 3]> {
        match check {
            Check::Colour => c.colour(at, what, self),
            Check::Direction if length(self) == 0.0 => Err(c.error(
                at,
                format!("`{what}` has zero length; expected a non-zero vector"),
            )),
            Check::Scale => {
                if let Some(i) = self.iter().position(|&s| s == 0.0) {
                    let at = at.item(i).unwrap_or(at);
                    return Err(c.error(
                        at,
                        format!(
                            "`{what}` has a zero component; expected non-zero scales (an \
                             object scaled to nothing cannot be turned back)"
                        ),
                    ));
                }
                Ok(self)
            }
            _ => Ok(self),
        }
    }
}

/// After merging: light and object names resolved to indices (unknown names, and names given
/// twice, are errors), and every keyed property checked against its target — material names
/// defined, the light kind having that property, `fov` on a perspective camera, and so on.
/// `lights`, `objects` and `instances` are the names in the merged lists; an entry of
/// `objects:` that names an instance moves to `AnimationDesc::instances`.
pub(crate) fn resolve_animation(
    scene: &mut SceneDesc,
    lights: &ItemNames,
    objects: &ItemNames,
    instances: &ItemNames,
) -> Result<()> {
    once(lights, "light")?;
    once(objects, "object")?;
    let Some(anim) = scene.animation.as_mut() else {
        return Ok(());
    };
    let a = &mut anim.value;
    let camera = &scene.camera.value;
    if let Some(fov) = &a.camera.fov {
        let perspective = matches!(camera.projection, Projection::Perspective { .. });
        if !perspective || camera.frustum.is_some() {
            return Err(SceneError::at(
                fov.at.clone(),
                "`fov` keys need a perspective camera sized by `fov` (without a `frustum`); \
                 expected `fov:` on the camera, or no `fov` keys",
            ));
        }
    }
    if let Some(f) = &a.camera.focal_distance {
        if camera.depth_of_field.is_none() {
            return Err(SceneError::at(
                f.at.clone(),
                "`focal_distance` keys need the camera's `depth_of_field`; expected \
                 `depth_of_field: (aperture: ...)` on the camera",
            ));
        }
    }
    for l in &mut a.lights {
        let Some((i, _)) = lights.iter().find(|(_, n)| n.value == l.name.value) else {
            let known = lights.iter().map(|(_, n)| n.value.as_str());
            let message = unknown_name("light", &l.name.value, "", known);
            return Err(SceneError::at(l.name.at.clone(), message));
        };
        l.light = *i;
        let (kind, has) = match &scene.lights[*i].value {
            LightDesc::Point { .. } => ("Point", ["position", "intensity", "color"].as_slice()),
            LightDesc::Directional { .. } => (
                "Directional",
                ["direction", "intensity", "color"].as_slice(),
            ),
            LightDesc::Spot { .. } => (
                "Spot",
                ["position", "direction", "intensity", "color"].as_slice(),
            ),
            LightDesc::Sphere { .. } => {
                ("SphereLight", ["position", "intensity", "color"].as_slice())
            }
            LightDesc::Rect { .. } => ("RectLight", ["position", "intensity", "color"].as_slice()),
        };
        let keyed = [
            ("position", l.position.as_ref().map(|t| &t.at)),
            ("direction", l.direction.as_ref().map(|t| &t.at)),
        ];
        for (property, at) in keyed {
            if let (Some(at), false) = (at, has.contains(&property)) {
                return Err(SceneError::at(
                    at.clone(),
                    format!(
                        "light `{}` is {kind}: it has no `{property}` to animate; expected one \
                         of {}",
                        shown(&l.name.value),
                        quoted_list(has.iter().copied())
                    ),
                ));
            }
        }
    }
    let materials: Vec<&str> = scene.materials.iter().map(|(n, _)| n.as_str()).collect();
    for m in &a.materials {
        if !materials.contains(&m.material.value.as_str()) {
            let message =
                unknown_name("material", &m.material.value, "", materials.iter().copied());
            return Err(SceneError::at(m.material.at.clone(), message));
        }
    }
    for mut o in std::mem::take(&mut a.objects) {
        let found = |names: &ItemNames| {
            let named = names.iter().find(|(_, n)| n.value == o.name.value);
            named.map(|(i, _)| *i)
        };
        if let Some(i) = found(objects) {
            o.object = i;
            a.objects.push(o);
        } else if let Some(i) = found(instances) {
            o.object = i;
            a.instances.push(o);
        } else {
            let known = objects
                .iter()
                .chain(instances)
                .map(|(_, n)| n.value.as_str());
            let message = unknown_name(
                "object",
                &o.name.value,
                " (objects and instances are named by `name:`)",
                known,
            );
            return Err(SceneError::at(o.name.at.clone(), message));
        }
    }
    Ok(())
}

/// Each light (object) name once in the merged scene: a second is an error naming the first.
fn once(names: &ItemNames, what: &str) -> Result<()> {
    for (k, (_, name)) in names.iter().enumerate() {
        if let Some((_, first)) = names[..k].iter().find(|(_, n)| n.value == name.value) {
            return Err(SceneError::at(
                name.at.clone(),
                format!(
                    "the {what} name `{}` is already used at {}; expected each {what} name once",
                    shown(&name.value),
                    first.at
                ),
            ));
        }
    }
    Ok(())
}
