//! Time-sampled data (`series:`) in a scene: at each frame, the data frame each series shows
//! is read (`luxon_formats::load_frame`) and stored in the scene's moving group, like the keyed
//! objects, with BVHs of its own. When no keyed object moves and every series shows the data
//! frames the group already holds, the group is kept (`Animation` decides).
//!
//! Under an open shutter a frame reads every data frame its shutter spans (the steps) and
//! stores each series that moves across several as a sweep (`sweep`): spheres and vertices
//! blended between the steps at each ray's time.
//!
//! Parsed data frames are pure data, so a small cache of the last few ([`CACHE_FRAMES`])
//! cannot change a frame: frame k holds the same spheres and triangles whether it is read
//! fresh or from the cache.

use super::place::Sets;
use crate::budget::Budget;
use crate::error::Error;
use crate::geometry::group::Group;
use crate::geometry::pack;
use crate::geometry::triangle::MeshInput;
use crate::math::DVec3;
use luxon_formats::{
    load_frame, LoadOptions, SceneDesc, SeriesDesc, SeriesFrame, SeriesKind, Spanned,
};
use std::sync::{Arc, Mutex};

/// One series' data frames during a movie frame, each with its time.
type TimedFrames = Vec<(f64, Arc<SeriesFrame>)>;

/// Parsed data frames by (series, data frame), most recent last.
type Cache = Vec<((usize, u32), Arc<SeriesFrame>)>;

/// A material name (`None`: the default) to its index in the scene's materials.
type MaterialOf<'a> = dyn FnMut(&Option<Spanned<String>>) -> Result<usize, Error> + 'a;

/// How many parsed data frames the cache keeps.
const CACHE_FRAMES: usize = 8;

/// A data frame a series shows during a frame, and when: (data frame, frames from the
/// frame's time).
pub(super) type Step = (u32, f64);

/// A series and the packed material of each of its styles (`.xyz`: each element of `atoms`,
/// then `default_atom`; `.obj`: one).
struct Entry {
    desc: SeriesDesc,
    materials: Vec<u32>,
}

/// The data frames series `s` shows during movie frame `k` of an animation over `range`.
/// Without a shutter (or one of no length) one: the frame's own, at time 0. Under an open
/// `shutter` (open, close), frames from `k`: every data frame from the last at or before the
/// shutter opens to the first at or after it closes, at their own times; the animation's
/// first and last data frames bound them (beyond its range the data holds), and a single one
/// is shown at 0.
pub(super) fn steps(
    s: &SeriesDesc,
    range: (u32, u32),
    k: u32,
    shutter: Option<(f64, f64)>,
) -> Vec<Step> {
    let still = vec![(s.data_frame(k, range), 0.0)];
    let Some((open, close)) = shutter.filter(|(o, c)| c > o) else {
        return still;
    };
    let (first, per) = (f64::from(s.first), f64::from(s.per_frame));
    let start = f64::from(range.0);
    let (lo, hi) = (
        f64::from(s.data_frame(range.0, range)),
        f64::from(s.data_frame(range.1, range)),
    );
    // The data frame (a real number) shown at movie time t.
    let at = |t: f64| first + (t - start) * per;
    let k = f64::from(k);
    let a = at(k + open).floor().clamp(lo, hi) as u32;
    let b = at(k + close).ceil().clamp(lo, hi) as u32;
    if a >= b {
        return vec![(a, 0.0)];
    }
    // Exact for whole numbers: the frame's own data frame is at 0.
    let time = |d: u32| (f64::from(d) - first) / per + start - k;
    (a..=b).map(|d| (d, time(d))).collect()
}

/// Which data files each frame of a scene reads (every series' data frames during the
/// frame's shutter), for a resumed sequence to notice an edited one.
#[derive(Clone, Debug, Default)]
pub struct DataFiles {
    series: Vec<SeriesDesc>,
    range: (u32, u32),
    shutter: Option<(f64, f64)>,
}

impl DataFiles {
    pub fn new(desc: &SceneDesc) -> DataFiles {
        let Some(a) = &desc.animation else {
            return DataFiles::default();
        };
        DataFiles {
            series: desc.series.iter().map(|s| s.value.clone()).collect(),
            range: (a.value.first, a.value.last),
            shutter: super::frame::shutter(desc),
        }
    }

    /// The data files frame `k` reads.
    pub fn of(&self, k: u32) -> Vec<std::path::PathBuf> {
        (self.series.iter())
            .flat_map(|s| {
                steps(s, self.range, k, self.shutter)
                    .into_iter()
                    .map(|(d, _)| s.path(d))
            })
            .collect()
    }
}

/// The series of an animated scene and the data frames read lately.
#[derive(Default)]
pub(super) struct SeriesSet {
    list: Vec<Entry>,
    /// The animation's first and last frame.
    range: (u32, u32),
    /// (series, data frame) to its parsed file, most recent last.
    cache: Mutex<Cache>,
}

impl SeriesSet {
    /// The series of `desc`; `material(name)` gives a material's index, and marks it used.
    pub(super) fn new(desc: &SceneDesc, material: &mut MaterialOf) -> Result<SeriesSet, Error> {
        let range = desc
            .animation
            .as_ref()
            .map_or((0, 0), |a| (a.value.first, a.value.last));
        let mut list = Vec::new();
        for s in &desc.series {
            let s = &s.value;
            let mut materials = Vec::new();
            match &s.kind {
                SeriesKind::Atoms { atoms, default } => {
                    for a in atoms.iter().map(|(_, a)| a).chain(default) {
                        materials.push(pack(material(&a.material)? as u32, 0));
                    }
                }
                SeriesKind::Mesh { material: m } => materials.push(pack(material(m)? as u32, 0)),
            }
            list.push(Entry {
                desc: s.clone(),
                materials,
            });
        }
        // A hit on a blurred series names it in 16 bits (`Hit::object`).
        if list.len() >= usize::from(u16::MAX) {
            return Err(Error::Render(format!(
                "{} series; expected fewer than {}",
                list.len(),
                u16::MAX
            )));
        }
        Ok(SeriesSet {
            list,
            range,
            cache: Mutex::new(Vec::new()),
        })
    }

    pub(super) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The data frames each series shows during movie frame `k` (see [`steps`]).
    pub(super) fn steps(&self, k: u32, shutter: Option<(f64, f64)>) -> Vec<Vec<Step>> {
        (self.list.iter())
            .map(|e| steps(&e.desc, self.range, k, shutter))
            .collect()
    }

    /// The data of every series at its `steps` during movie frame `k` (as `steps` gives
    /// them), read or taken from the cache. An error names the file and the frame.
    pub(super) fn load(&self, steps: &[Vec<Step>], k: u32) -> Result<Vec<TimedFrames>, Error> {
        let options = LoadOptions::default();
        let mut out = Vec::with_capacity(self.list.len());
        for (i, (e, steps)) in self.list.iter().zip(steps).enumerate() {
            let mut frames = Vec::with_capacity(steps.len());
            for &(d, time) in steps {
                let frame = match self.cached(i, d) {
                    Some(f) => f,
                    None => {
                        let f = Arc::new(load_frame(&e.desc, d, k, &options)?);
                        let mut cache = self.cache.lock().unwrap_or_else(|p| p.into_inner());
                        if cache.len() >= CACHE_FRAMES {
                            cache.remove(0);
                        }
                        cache.push(((i, d), f.clone()));
                        f
                    }
                };
                frames.push((time, frame));
            }
            out.push(frames);
        }
        Ok(out)
    }

    /// Series `i`'s data frame `d` from the cache (now the most recent), if there.
    fn cached(&self, i: usize, d: u32) -> Option<Arc<SeriesFrame>> {
        let mut cache = self.cache.lock().unwrap_or_else(|p| p.into_inner());
        let at = cache.iter().position(|(key, _)| *key == (i, d))?;
        let entry = cache.remove(at);
        let frame = entry.1.clone();
        cache.push(entry);
        Some(frame)
    }

    /// Stores `frames` (each series' steps, as `load` gives them) into `group`, in render
    /// space (`offset`: the world position of its origin), charging `budget` as the sets
    /// grow: a series at one step into the group's sets, one at several as a sweep. Returns
    /// the zero-area triangles dropped.
    pub(super) fn store(
        &self,
        frames: &[Vec<(f64, Arc<SeriesFrame>)>],
        k: u32,
        group: &mut Group,
        offset: DVec3,
        budget: &Arc<Budget>,
    ) -> Result<u64, Error> {
        let mut dropped = 0;
        for (e, steps) in self.list.iter().zip(frames) {
            let f = match steps.as_slice() {
                [] => continue,
                [(_, f)] => f,
                _ => {
                    let name = &e.desc.name.value;
                    let fail = |m: String| {
                        Error::at(&e.desc.files.at, format!("series `{name}`, frame {k}: {m}"))
                    };
                    let sweep =
                        super::sweep::sweep(steps, &e.materials, offset, budget).map_err(fail)?;
                    group.sweeps.push(sweep);
                    continue;
                }
            };
            let mut sets = group.sets();
            let fail = |m: String| {
                Error::at(
                    &e.desc.files.at,
                    format!(
                        "series `{}`, frame {k}: `{}`: {m}",
                        e.desc.name.value,
                        f.file.display()
                    ),
                )
            };
            let n = f.spheres.len();
            let what = move || format!("{n} spheres");
            sets.spheres.reserve(n, budget, &what).map_err(fail)?;
            for (i, (style, s)) in f.spheres.iter().enumerate() {
                let m = e.materials.get(*style as usize).copied().unwrap_or(0);
                sets.spheres.push_world(i, *s, offset, m).map_err(fail)?;
            }
            let m = e.materials.first().copied().unwrap_or(0);
            for g in &f.meshes {
                dropped += store_mesh(g, sets.reborrow(), offset, m, budget).map_err(fail)?;
            }
        }
        Ok(dropped)
    }
}

/// One mesh of an `.obj` data frame into `sets`.
fn store_mesh(
    g: &luxon_formats::InlineGeometry,
    sets: Sets,
    offset: DVec3,
    material: u32,
    budget: &Budget,
) -> Result<u64, String> {
    let m = &g.mesh;
    if m.indices.is_empty() {
        return Ok(0);
    }
    let (triangles, vertices) = (m.indices.len(), m.positions.len());
    let what = move || format!("{triangles} triangles");
    let attrs = !(m.normals.is_empty() && m.colors.is_empty() && m.uvs.is_empty());
    (sets.triangles).reserve_mesh(triangles, vertices, attrs, budget, &what)?;
    with_mesh_input(g, |input| sets.triangles.push_mesh(input, offset, material))
}

/// A data frame's mesh as the triangle code reads it (colours and uvs in f32), lent to `with`.
pub(super) fn with_mesh_input<R>(
    g: &luxon_formats::InlineGeometry,
    with: impl FnOnce(&MeshInput) -> R,
) -> R {
    let m = &g.mesh;
    let colors: Vec<f32> = m.colors.iter().flat_map(|c| c.map(|x| x as f32)).collect();
    let uvs: Vec<f32> = m.uvs.iter().flat_map(|u| u.map(|x| x as f32)).collect();
    with(&MeshInput {
        positions: m.positions.as_flattened(),
        indices: m.indices.as_flattened(),
        normals: m.normals.as_flattened(),
        colors: &colors,
        uvs: &uvs,
    })
}
