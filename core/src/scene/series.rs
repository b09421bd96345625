//! Time-sampled data (`series:`) in a scene: at each frame, the data frame each series shows
//! is read (`luxon_formats::load_frame`) and stored in the scene's moving group, like the keyed
//! objects, with BVHs of its own. When no keyed object moves and every series shows the data
//! frames the group already holds, the group is kept (`Animation` decides).
//!
//! Parsed data frames are pure data, so a small cache of the last few ([`CACHE_FRAMES`])
//! cannot change a frame: frame k holds the same spheres and triangles whether it is read
//! fresh or from the cache.

use super::place::Sets;
use crate::budget::Budget;
use crate::error::Error;
use crate::geometry::pack;
use crate::geometry::triangle::MeshInput;
use crate::math::DVec3;
use luxon_formats::{
    load_frame, LoadOptions, SceneDesc, SeriesDesc, SeriesFrame, SeriesKind, Spanned,
};
use std::sync::{Arc, Mutex};

/// Parsed data frames by (series, data frame), most recent last.
type Cache = Vec<((usize, u32), Arc<SeriesFrame>)>;

/// A material name (`None`: the default) to its index in the scene's materials.
type MaterialOf<'a> = dyn FnMut(&Option<Spanned<String>>) -> Result<usize, Error> + 'a;

/// How many parsed data frames the cache keeps.
const CACHE_FRAMES: usize = 8;

/// A series and the packed material of each of its styles (`.xyz`: each element of `atoms`,
/// then `default_atom`; `.obj`: one).
struct Entry {
    desc: SeriesDesc,
    materials: Vec<u32>,
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
        Ok(SeriesSet {
            list,
            range,
            cache: Mutex::new(Vec::new()),
        })
    }

    pub(super) fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The data frame each series shows at movie frame `k`.
    pub(super) fn data_frames(&self, k: u32) -> Vec<u32> {
        (self.list.iter())
            .map(|e| e.desc.data_frame(k, self.range))
            .collect()
    }

    /// The data of every series at movie frame `k`, read or taken from the cache. An error
    /// names the file and the frame.
    pub(super) fn load(&self, k: u32) -> Result<Vec<Arc<SeriesFrame>>, Error> {
        let options = LoadOptions::default();
        let mut out = Vec::with_capacity(self.list.len());
        for (i, e) in self.list.iter().enumerate() {
            let d = e.desc.data_frame(k, self.range);
            let cached = self.cached(i, d);
            let frame = match cached {
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
            out.push(frame);
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

    /// Stores `frames` (one per series, as `load` gives them) into `sets`, in render space
    /// (`offset`: the world position of its origin), charging `budget` as the sets grow.
    /// Returns the zero-area triangles dropped.
    pub(super) fn store(
        &self,
        frames: &[Arc<SeriesFrame>],
        k: u32,
        mut sets: Sets,
        offset: DVec3,
        budget: &Arc<Budget>,
    ) -> Result<u64, Error> {
        let mut dropped = 0;
        for (e, f) in self.list.iter().zip(frames) {
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
    let colors: Vec<f32> = m.colors.iter().flat_map(|c| c.map(|x| x as f32)).collect();
    let uvs: Vec<f32> = m.uvs.iter().flat_map(|u| u.map(|x| x as f32)).collect();
    let input = MeshInput {
        positions: m.positions.as_flattened(),
        indices: m.indices.as_flattened(),
        normals: m.normals.as_flattened(),
        colors: &colors,
        uvs: &uvs,
    };
    sets.triangles.push_mesh(&input, offset, material)
}
