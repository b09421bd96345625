//! The frames of an animated scene: [`Scene::set_frame`] puts every keyed value at a frame —
//! the camera, the lights, material colours, and the keyed objects, whose geometry is placed
//! anew from what their plugins gave once (recorded at the build, in f64) and stored in the
//! scene's moving group with BVHs of its own, charged to the memory budget like the still
//! geometry (and given back when the next frame's group replaces it).
//!
//! **A frame is a function of its number alone.** `set_frame` overwrites every value it
//! touches and rebuilds the moving group from scratch (never refits what an earlier frame
//! left), so frame k renders the same bits whether it comes first, after other frames, or in
//! another process. Everything else (still geometry, volumes, textures, the world offset) is
//! built once and never changes with the frame.
//!
//! Render space stays where the build put it: `world_offset` is the camera's position at the
//! scene's first frame (not the frame being rendered, which would move every coordinate), and
//! each frame's camera is placed relative to it.

use super::build::{shadow_filter, Build};
use super::place::place;
use super::series::SeriesSet;
use super::{Light, Scene};
use crate::budget::{Budget, Use};
use crate::camera::Camera;
use crate::error::Error;
use crate::geometry::group::Group;
use crate::math::{DVec3, Vec3A};
use crate::motion::keys::value;
use crate::motion::Placement;
use crate::plugin::primitive::Recorded;
use glam::DAffine3;
use luxon_formats::{
    AnimationDesc, CameraDesc, LightDesc, ObjectTracks, Origin, Projection, SceneDesc, ShutterDesc,
    Spanned, Track, TransparentShadows,
};
use std::sync::Arc;

/// A keyed object as the build recorded it.
pub(super) struct Keyed {
    pub tracks: ObjectTracks,
    pub geometry: Recorded,
    /// Material and clip group, packed.
    pub material: u32,
    /// Where the object is written.
    pub at: Origin,
}

/// What an animated scene needs to go to any frame: the tracks, and the unanimated camera,
/// lights and keyed objects they change.
pub struct Animation {
    desc: AnimationDesc,
    camera: Spanned<CameraDesc>,
    lights: Vec<Spanned<LightDesc>>,
    /// The render's light scale, which every frame's lights carry.
    light_scale: f64,
    /// How transparent surfaces filter shadows (by their colour, when `Tinted`).
    shadows: TransparentShadows,
    /// Keyed material colours: index in `Scene::materials`, that of its copy that casts no
    /// shadow (if objects use one), and the track.
    materials: Vec<(usize, Option<usize>, Track<[f64; 3]>)>,
    objects: Vec<Keyed>,
    /// Keyed shared instances (`Scene::instances` index) and their tracks.
    instances: Vec<(u32, ObjectTracks)>,
    /// Time-sampled data, stored in the moving group with the keyed objects.
    pub(super) series: SeriesSet,
    /// The data frames (and their times) the moving group holds (`None`: not known, build it
    /// anew).
    shown: Option<Vec<Vec<super::series::Step>>>,
    frame: u32,
    /// The shutter (open, close) in frames from the frame's time, when time is sampled (see
    /// [`shutter`]).
    shutter: Option<(f64, f64)>,
}

/// Whether a track's keys take more than one value (so it moves somewhere).
fn moves<T: PartialEq>(t: &Option<Track<T>>) -> bool {
    t.as_ref()
        .is_some_and(|t| t.keys.iter().any(|k| k.value != t.keys[0].value))
}

/// Whether a track changes somewhere in `(t0, t1)`: it moves, and the interval meets its
/// keys' span (outside it the value holds).
fn changes_in<T: PartialEq>(t: &Option<Track<T>>, t0: f64, t1: f64) -> bool {
    moves(t)
        && t.as_ref().is_some_and(|t| {
            let k = &t.keys;
            t0 < k[k.len() - 1].frame && t1 > k[0].frame
        })
}

/// Whether keyed tracks of an object or instance move it somewhere.
pub(super) fn object_moves(t: &ObjectTracks) -> bool {
    moves(&t.translate) || moves(&t.rotate) || moves(&t.scale)
}

/// The shutter (open, close), in frames from the frame's time, when the scene samples time:
/// it has a shutter and something keyed that moves (an object, an instance, the camera) or
/// time-sampled data (`series:`, which moves from one data frame to the next). `None`
/// otherwise — a still scene, or nothing that could blur — and then no time is sampled.
pub fn shutter(desc: &SceneDesc) -> Option<(f64, f64)> {
    let a = &desc.animation.as_ref()?.value;
    let s = a.shutter.as_ref()?.value;
    let c = &a.camera;
    let camera = moves(&c.position)
        || moves(&c.look_at)
        || moves(&c.up)
        || moves(&c.fov)
        || moves(&c.focal_distance);
    let objects = a.objects.iter().chain(&a.instances).any(object_moves);
    (camera || objects || !desc.series.is_empty()).then(|| s.interval())
}

/// Whether keyed objects and instances that move are placed at each ray's time (traced as
/// shared instances): a shutter that stays open for some time and something that moves in it.
pub(super) fn per_ray(desc: &SceneDesc) -> bool {
    shutter(desc).is_some_and(|(open, close)| close > open)
}

/// Keyed objects that move, as bottom levels of their own in object space, each traced
/// through its tracks at every ray's time (motion blur); the others stay keyed as they were.
/// A keyed object in a clip group cannot be blurred (bottom levels do not clip).
pub(super) fn blur_objects(
    objects: Vec<Keyed>,
    instances: &mut crate::geometry::instance::Instances,
    budget: &Arc<Budget>,
) -> Result<Vec<Keyed>, Error> {
    let mut kept = Vec::new();
    for o in objects {
        if !object_moves(&o.tracks) {
            kept.push(o);
            continue;
        }
        let name = &o.tracks.name.value;
        if crate::geometry::clip_of(o.material) != 0 {
            return Err(Error::at(
                &o.at,
                format!(
                    "object `{name}` is keyed and clipped: motion blur traces moving objects \
                     as instances, which cannot be clipped; expected no `clip` on it, or \
                     `shutter: (length: 0)`"
                ),
            ));
        }
        let mut group = Group::default();
        let before = budget.used(Use::Geometry);
        let identity = Placement::from_desc(&luxon_formats::TransformDesc::IDENTITY);
        let placed = place(
            &o.geometry,
            &identity,
            DVec3::ZERO,
            o.material,
            group.sets(),
            budget,
        );
        let grown = budget.used(Use::Geometry).saturating_sub(before);
        group.charges.push(budget.guard(Use::Geometry, grown));
        placed.map_err(|m| Error::at(&o.at, format!("object `{name}`: {m}")))?;
        group
            .build(budget)
            .map_err(|e| Error::Render(format!("object `{name}`: {}", e.0)))?;
        instances.push_keyed(group, o.tracks);
    }
    Ok(kept)
}

/// Where render space's origin sits in an animated scene: the camera's position at the first
/// frame (a property of the scene, so every frame and every subset of frames agrees).
pub(super) fn world_offset(desc: &SceneDesc) -> DVec3 {
    let camera = &desc.camera.value;
    let keyed = desc.animation.as_ref().and_then(|a| {
        let a = &a.value;
        a.camera
            .position
            .as_ref()
            .map(|p| value(p, f64::from(a.first)))
    });
    DVec3::from(keyed.unwrap_or(camera.position))
}

impl Animation {
    /// The animation of `desc`, with the objects the build recorded; `shadowless`: each
    /// material's copy that casts no shadow (`Scene::materials` index). A scale that would
    /// turn a sphere, cone or disc into something it cannot store is refused.
    pub(super) fn new(
        desc: &SceneDesc,
        material_names: &[String],
        shadowless: &[Option<usize>],
        objects: Vec<Keyed>,
        instances: Vec<(u32, ObjectTracks)>,
    ) -> Result<Animation, Error> {
        let a = desc
            .animation
            .as_ref()
            .ok_or_else(|| Error::Render("the scene has no animation".into()))?;
        for o in &objects {
            let g = &o.geometry;
            let round = !(g.spheres.is_empty() && g.cones.is_empty() && g.discs.is_empty());
            let Some(scale) = o.tracks.scale.as_ref().filter(|_| round) else {
                continue;
            };
            for k in &scale.keys {
                let s = k.value.map(f64::abs);
                if s[0] != s[1] || s[1] != s[2] {
                    return Err(Error::at(
                        &k.at,
                        format!(
                            "object `{}` holds spheres, cones or discs, which keep their shape \
                             only under a uniform scale, but this key scales by ({}, {}, {}); \
                             expected the same size on every axis",
                            o.tracks.name.value, k.value[0], k.value[1], k.value[2]
                        ),
                    ));
                }
            }
        }
        let materials = a
            .value
            .materials
            .iter()
            .filter_map(|m| {
                let color = m.color.clone()?;
                let i = material_names.iter().position(|n| *n == m.material.value)?;
                Some((i, shadowless.get(i).copied().flatten(), color))
            })
            .collect();
        Ok(Animation {
            desc: a.value.clone(),
            camera: desc.camera.clone(),
            lights: desc.lights.clone(),
            light_scale: desc.render.light_scale,
            shadows: desc.render.transparency.shadows,
            materials,
            objects,
            instances,
            series: SeriesSet::default(),
            shown: None,
            frame: a.value.first,
            shutter: shutter(desc),
        })
    }

    /// The first and last frame of the scene's range (inclusive).
    pub fn frames(&self) -> (u32, u32) {
        (self.desc.first, self.desc.last)
    }

    pub fn fps(&self) -> f64 {
        self.desc.fps
    }

    pub fn shutter(&self) -> Option<ShutterDesc> {
        self.desc.shutter.as_ref().map(|s| s.value)
    }

    /// The shutter (open, close) in frames from the frame's time when time is sampled.
    pub fn sampled_shutter(&self) -> Option<(f64, f64)> {
        self.shutter
    }

    /// Whether the camera changes during frame `k`'s shutter: then each camera ray is cast
    /// by the camera at its own time.
    fn camera_moves_in(&self, k: u32) -> bool {
        let Some((open, close)) = self.shutter.filter(|(o, c)| c > o) else {
            return false;
        };
        let (t0, t1) = (f64::from(k) + open, f64::from(k) + close);
        let c = &self.desc.camera;
        changes_in(&c.position, t0, t1)
            || changes_in(&c.look_at, t0, t1)
            || changes_in(&c.up, t0, t1)
            || changes_in(&c.fov, t0, t1)
            || changes_in(&c.focal_distance, t0, t1)
    }

    /// The camera at frame-relative time `time` of the current frame, in render space;
    /// `None` where it degenerates (the frame's camera is used there).
    pub(super) fn camera_at_time(
        &self,
        time: f32,
        world_offset: DVec3,
        w: u32,
        h: u32,
    ) -> Option<Camera> {
        let t = f64::from(self.frame) + f64::from(time);
        let c = self.camera_at(t, self.frame).ok()?;
        let origin = Vec3A::from((DVec3::from(c.position) - world_offset).as_vec3());
        Some(Camera::new(&c, origin, w, h))
    }

    /// The frame the scene is at.
    pub fn frame(&self) -> u32 {
        self.frame
    }

    pub fn desc(&self) -> &AnimationDesc {
        &self.desc
    }

    /// The camera at time `t` (frames), checked: a keyed view can degenerate at some frames.
    fn camera_at(&self, t: f64, k: u32) -> Result<CameraDesc, Error> {
        let tracks = &self.desc.camera;
        let mut c = self.camera.value.clone();
        let at = |track: &Option<Track<[f64; 3]>>| track.as_ref().map(|tr| value(tr, t));
        if let Some(p) = at(&tracks.position) {
            c.position = p;
        }
        if let Some(p) = at(&tracks.look_at) {
            c.look_at = p;
        }
        if let Some(u) = at(&tracks.up) {
            c.up = u;
        }
        if let (Some(fov), Projection::Perspective { fov_deg }) = (&tracks.fov, &mut c.projection) {
            // Catmull-Rom may overshoot the keys' range.
            *fov_deg = value(fov, t).clamp(0.01, 179.99);
        }
        if let (Some(f), Some(dof)) = (&tracks.focal_distance, &mut c.depth_of_field) {
            dof.focal_distance = value(f, t).max(1e-9);
        }
        let view = DVec3::from(c.look_at) - DVec3::from(c.position);
        let up = DVec3::from(c.up);
        let fail = |m: String| Err(Error::at(&self.camera.at, format!("frame {k}: {m}")));
        if view.length() == 0.0 {
            return fail(format!(
                "the camera's `look_at` equals its `position` {:?} at this frame; expected \
                 keys that keep them apart",
                c.position
            ));
        }
        if view.cross(up).length() <= 1e-9 * view.length() * up.length() {
            return fail(format!(
                "the camera's `up` {:?} is parallel to its view direction at this frame; \
                 expected an `up` at an angle to it",
                c.up
            ));
        }
        Ok(c)
    }

    /// The lights at time `t`, in render space.
    fn lights_at(&self, t: f64, k: u32, world_offset: DVec3) -> Result<Vec<Light>, Error> {
        let mut lights = self.lights.clone();
        for keys in &self.desc.lights {
            let Some(light) = lights.get_mut(keys.light) else {
                continue;
            };
            let at = |track: &Option<Track<[f64; 3]>>| track.as_ref().map(|tr| value(tr, t));
            let position = at(&keys.position);
            let direction = at(&keys.direction);
            if let Some(d) = direction {
                if DVec3::from(d).length() == 0.0 {
                    return Err(Error::at(
                        &keys.name.at,
                        format!(
                            "frame {k}: light `{}`'s `direction` passes through zero length \
                             at this frame; expected keys that keep it a direction",
                            keys.name.value
                        ),
                    ));
                }
            }
            let intensity = keys.intensity.as_ref().map(|tr| value(tr, t).max(0.0));
            let color = at(&keys.color).map(|c| c.map(|x| x.max(0.0)));
            let (p, d, i, c) = match &mut light.value {
                LightDesc::Point {
                    position,
                    intensity,
                    color,
                    ..
                }
                | LightDesc::Sphere {
                    center: position,
                    intensity,
                    color,
                    ..
                }
                | LightDesc::Rect {
                    corner: position,
                    intensity,
                    color,
                    ..
                } => (Some(position), None, intensity, color),
                LightDesc::Directional {
                    direction,
                    intensity,
                    color,
                    ..
                } => (None, Some(direction), intensity, color),
                LightDesc::Spot {
                    position,
                    direction,
                    intensity,
                    color,
                    ..
                } => (Some(position), Some(direction), intensity, color),
            };
            // The loader made sure a keyed property exists on its light.
            if let (Some(slot), Some(v)) = (p, position) {
                *slot = v;
            }
            if let (Some(slot), Some(v)) = (d, direction) {
                *slot = v;
            }
            if let Some(v) = intensity {
                *i = v;
            }
            if let Some(v) = color {
                *c = v;
            }
        }
        Ok(Build::lights_from(&lights, world_offset, self.light_scale))
    }

    /// The keyed shared instances' transforms at time `t` (each checked invertible).
    fn instances_at(&self, t: f64, k: u32) -> Result<Vec<(u32, DAffine3)>, Error> {
        (self.instances.iter())
            .map(|(i, tracks)| {
                let m = Placement::at(tracks, t).world_from_object;
                let det = m.matrix3.determinant();
                if det.is_finite() && det != 0.0 {
                    Ok((*i, m))
                } else {
                    Err(Error::at(
                        &tracks.name.at,
                        format!(
                            "frame {k}: instance `{}`: its transform is singular (a scale of 0?)",
                            tracks.name.value
                        ),
                    ))
                }
            })
            .collect()
    }

    /// The keyed objects placed at time `t` and the series' data of frame `k` (`data`, as
    /// `SeriesSet::load` gives it; empty: none), in render space, with their BVHs, charged to
    /// `budget` (the group keeps the charges).
    fn group_at(
        &self,
        t: f64,
        k: u32,
        world_offset: DVec3,
        budget: &Arc<Budget>,
        data: &[Vec<(f64, Arc<luxon_formats::SeriesFrame>)>],
    ) -> Result<Group, Error> {
        let mut group = Group::default();
        // The sets charge their arrays as they grow, for good; the group takes that charge
        // over (nothing else stores geometry while a frame is set), so it is given back with
        // the group, or at once if placing fails.
        let before = budget.used(Use::Geometry);
        let placed = self.objects.iter().try_for_each(|o| {
            let p = Placement::at(&o.tracks, t);
            place(
                &o.geometry,
                &p,
                world_offset,
                o.material,
                group.sets(),
                budget,
            )
            .map(|_| ())
            .map_err(|m| {
                Error::at(
                    &o.at,
                    format!("frame {k}: object `{}`: {m}", o.tracks.name.value),
                )
            })
        });
        // Zero-area triangles of the data are dropped, as in any mesh.
        let placed = placed.and_then(|()| {
            (self.series)
                .store(data, k, &mut group, world_offset, budget)
                .map(|_| ())
        });
        let grown = budget.used(Use::Geometry).saturating_sub(before);
        group.charges.push(budget.guard(Use::Geometry, grown));
        placed?;
        group
            .build(budget)
            .map_err(|e| Error::Render(format!("frame {k}: the keyed objects: {}", e.0)))?;
        Ok(group)
    }
}

impl Scene {
    /// Puts every keyed value at frame `k`: the camera, lights, material colours and keyed
    /// objects (placed anew, with fresh BVHs), and the sampler's frame number. A function of
    /// `k` alone (see the module documentation). Frames outside the scene's range hold the
    /// values of its ends. On an error (a camera or object that degenerates at this frame) the
    /// scene is left as it was.
    pub fn set_frame(&mut self, k: u32) -> Result<(), Error> {
        self.set_frame_with(k, false)
    }

    /// `set_frame`; `tolerant`: a series whose data cannot be read (or stored) leaves the
    /// moving group without series data instead of failing (the build's first frame: a missing data file
    /// fails the frame that shows it, when a sequence sets it, not the whole build).
    pub(super) fn set_frame_with(&mut self, k: u32, tolerant: bool) -> Result<(), Error> {
        let Some(anim) = &self.animation else {
            return Err(Error::Render(format!(
                "frame {k}: {} has no `animation:`",
                self.source.display()
            )));
        };
        let t = f64::from(k);
        let camera = anim.camera_at(t, k)?;
        let lights = anim.lights_at(t, k, self.world_offset)?;
        // Series data that did not change since the group was built keeps the group (keyed
        // objects move with every frame, so they rebuild it). Under an open shutter a series
        // reads the data frames its shutter spans.
        let open = anim.shutter.filter(|(o, c)| c > o);
        let wanted = anim.series.steps(k, open);
        let keep = !anim.series.is_empty()
            && anim.objects.is_empty()
            && anim.shown.as_ref() == Some(&wanted);
        let mut read = true;
        let moving = if keep {
            None
        } else {
            let data = match anim.series.load(&wanted, k) {
                Ok(data) => data,
                Err(_) if tolerant => {
                    read = false;
                    Vec::new()
                }
                Err(e) => return Err(e),
            };
            let group = anim.group_at(t, k, self.world_offset, &self.budget, &data);
            Some(match group {
                // Data that cannot be stored (data frames that differ in what they hold)
                // fails the frame showing it, like a missing file, not the build.
                Err(_) if tolerant && !data.is_empty() => {
                    read = false;
                    anim.group_at(t, k, self.world_offset, &self.budget, &[])?
                }
                group => group?,
            })
        };
        let shown = read.then_some(wanted);
        let placed = anim.instances_at(t, k)?;
        let shadows = anim.shadows;
        let camera_moves = anim.camera_moves_in(k);
        let shutter = anim.shutter.unwrap_or((0.0, 0.0));
        let colors: Vec<(usize, Option<usize>, Vec3A)> = anim
            .materials
            .iter()
            .map(|(i, copy, track)| {
                let c = value(track, t).map(|x| x.max(0.0));
                (*i, *copy, Vec3A::new(c[0] as f32, c[1] as f32, c[2] as f32))
            })
            .collect();
        self.set_camera(&camera);
        self.lights = lights;
        // The previous frame's group goes, and its charges with it.
        if let Some(moving) = moving {
            self.moving = moving;
        }
        if !placed.is_empty() {
            self.instances.place(&placed);
        }
        if self.instances.has_keyed() {
            // Moving instances: their boxes cover this frame's shutter.
            self.instances.set_time(t, shutter);
        }
        self.camera_moves = camera_moves;
        for (i, copy, c) in colors {
            let m = &mut self.materials[i];
            m.color = c;
            // A tinted shadow takes the colour too (the copy casting no shadow keeps its none).
            m.shadow = shadow_filter(m.transmit, c, shadows);
            if let Some(j) = copy {
                self.materials[j].color = c;
            }
        }
        self.settings.frame = k;
        if let Some(anim) = &mut self.animation {
            anim.frame = k;
            anim.shown = shown;
        }
        Ok(())
    }
}
