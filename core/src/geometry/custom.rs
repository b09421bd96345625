//! Custom geometry from primitive plugins: the plugin's bounds go into a BVH of their own and
//! its `intersect`/`occluded` are called through its function table (Embree's user geometry).
//! Rays cross the boundary in f64 world coordinates (the core works re-centred in f32).

use super::{clip_of, material_of, Clips, Counters, Hit, Kind, Surface};
use crate::budget::{Budget, Use};
use crate::bvh::Bvh;
use crate::math::{gamma, Aabb, DVec3, Vec3A};
use crate::ray::Ray;
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;

std::thread_local! {
    /// The message a plugin logged about a panic it caught in a call without an error sink
    /// (custom geometry's `bounds`, `intersect`, `occluded`), on the thread of that call.
    static PLUGIN_PANIC: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// How the SDK begins the log message of a panic caught where no error sink can carry it
/// ("panicked in `intersect`: ..."). Hosts before this convention print it as an error line.
pub const PANIC_LOG_PREFIX: &str = "panicked in `";

/// Keeps a plugin's panic message for [`take_plugin_panic`] when `message` is one (see
/// [`PANIC_LOG_PREFIX`]); false when it is an ordinary log message.
pub(crate) fn keep_plugin_panic(level: u32, message: &str) -> bool {
    if level != 0 || !message.starts_with(PANIC_LOG_PREFIX) {
        return false;
    }
    // The plugin's own words follow the call's name: "panicked in `intersect`: {words}".
    let words = message.split_once("`: ").map_or(message, |(_, w)| w);
    PLUGIN_PANIC.with(|p| *p.borrow_mut() = Some(words.to_string()));
    true
}

/// The panic message a plugin logged during the call this thread just made, if it sent one
/// (for "panicked in `intersect`: index out of bounds", "index out of bounds").
pub fn take_plugin_panic() -> Option<String> {
    PLUGIN_PANIC.with(|p| p.borrow_mut().take())
}

/// One object handed over by a plugin; destroyed through the plugin when the scene drops.
pub struct CustomObject {
    /// Live until `drop` passes it to `vtable.destroy`.
    object: *mut c_void,
    vtable: &'static abi::CustomVTable,
    pub plugin: String,
    pub count: u64,
    /// The scene's object that made it ("object 3") and where that is in the scene.
    pub name: String,
    pub at: Origin,
    /// Hits answered with a NaN distance or normal (ignored as misses), for the warning.
    pub nan_hits: AtomicU64,
}

impl CustomObject {
    /// Takes ownership of a plugin's object, made for the scene's object `name` at `at`.
    ///
    /// # Safety
    /// `object` is a live object of the plugin that `vtable` serves, handed over to the host
    /// (no one else destroys it); `vtable` is that plugin's table for it.
    pub unsafe fn new(
        object: *mut c_void,
        vtable: &'static abi::CustomVTable,
        plugin: String,
        count: u64,
        (name, at): (String, Origin),
    ) -> CustomObject {
        CustomObject {
            object,
            vtable,
            plugin,
            count,
            name,
            at,
            nan_hits: AtomicU64::new(0),
        }
    }

    /// "scene.ron:7:9: object 3 (plugin `torus`)", as messages begin.
    pub fn label(&self) -> String {
        format!("{}: {} (plugin `{}`)", self.at, self.name, self.plugin)
    }

    /// The plugin's answer to a hit: counts NaN in it (the hit is then ignored).
    fn is_nan(&self, h: &abi::HitF64) -> bool {
        let nan = h.t.is_nan() || h.normal.iter().any(|v| v.is_nan());
        if nan {
            self.nan_hits.fetch_add(1, Ordering::Relaxed);
        }
        nan
    }
}

// SAFETY: the ABI requires a plugin's custom objects to take `bounds`, `intersect` and
// `occluded` from several threads at once and `destroy` from any thread (the SDK makes that
// `CustomShape: Send + Sync`); the host owns the object and touches it only through its table.
unsafe impl Send for CustomObject {}
// SAFETY: see `Send`: `&CustomObject` only ever calls the table's thread-safe functions.
unsafe impl Sync for CustomObject {}

impl Drop for CustomObject {
    fn drop(&mut self) {
        // SAFETY: `object` is live (`new`'s contract) and this is the last use of it: the host
        // owns it, and `drop` runs once, after every borrow that could call into it.
        unsafe { (self.vtable.destroy)(self.object) };
    }
}

/// Set when plugin code panics during rendering; the render stops and reports it.
#[derive(Default)]
pub struct PluginFault {
    raised: AtomicBool,
    /// The first message, and whether it carries the plugin's own words.
    message: Mutex<Option<(String, bool)>>,
}

impl PluginFault {
    pub fn raise(&self, message: String) {
        self.raise_with(message, true);
    }

    /// Raises the fault; a message without the plugin's own words (`told` false: another
    /// thread's panic in the same object carried them) gives way to one with them.
    pub fn raise_with(&self, message: String, told: bool) {
        self.raised.store(true, Ordering::SeqCst);
        let mut m = self.message.lock().unwrap_or_else(|e| e.into_inner());
        if m.as_ref().is_none_or(|(_, had)| !had && told) {
            *m = Some((message, told));
        }
    }

    pub fn is_raised(&self) -> bool {
        self.raised.load(Ordering::Relaxed)
    }

    pub fn message(&self) -> Option<String> {
        self.message
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .as_ref()
            .map(|(m, _)| m.clone())
    }
}

#[derive(Default)]
pub struct Customs {
    pub objects: Vec<CustomObject>,
    /// (object, index within it) per BVH primitive.
    pub refs: Vec<(u32, u64)>,
    pub material: Vec<u32>,
    /// World position of the re-centred origin.
    pub world_offset: DVec3,
    pub fault: PluginFault,
    bvh: Bvh,
}

impl Customs {
    pub fn new(world_offset: DVec3) -> Customs {
        Customs {
            world_offset,
            ..Default::default()
        }
    }

    pub fn is_empty(&self) -> bool {
        self.refs.is_empty()
    }

    pub fn len(&self) -> usize {
        self.refs.len()
    }

    /// Room for `n` more primitives, charged to `budget` (see `Set::reserve`).
    pub fn reserve(
        &mut self,
        n: usize,
        budget: &Budget,
        what: &dyn Fn() -> String,
    ) -> Result<(), String> {
        budget.grow(&mut self.refs, n, Use::Geometry, what)?;
        budget.grow(&mut self.material, n, Use::Geometry, what)?;
        Ok(())
    }

    /// Bytes of the primitive references and materials (capacities).
    pub fn bytes(&self) -> u64 {
        (self.refs.capacity() * std::mem::size_of::<(u32, u64)>() + self.material.capacity() * 4)
            as u64
    }

    /// Bytes of the built BVH.
    pub fn bvh_bytes(&self) -> u64 {
        self.bvh.memory_bytes()
    }

    /// Asks the plugin for every primitive's bounds; an error names the plugin.
    pub fn build(&mut self) -> Result<(), String> {
        let mut bounds = Vec::with_capacity(self.refs.len());
        for &(o, i) in &self.refs {
            let obj = &self.objects[o as usize];
            let (mut min, mut max) = ([0.0f64; 3], [0.0f64; 3]);
            // SAFETY: `obj` is live (see `CustomObject`) and the out-pointers are our locals.
            let status = unsafe { (obj.vtable.bounds)(obj.object, i, &mut min, &mut max) };
            if status != abi::STATUS_OK {
                let said = take_plugin_panic().map_or(String::new(), |m| format!(": {m}"));
                return Err(format!(
                    "{} panicked computing bounds of primitive {i}{said}",
                    obj.label()
                ));
            }
            if min.iter().chain(&max).any(|v| v.is_nan()) || (0..3).any(|k| min[k] > max[k]) {
                return Err(format!(
                    "{} gave invalid bounds {min:?}..{max:?} for primitive {i}; expected \
                     finite min <= max on every axis",
                    obj.label()
                ));
            }
            let lo = (DVec3::from(min) - self.world_offset).as_vec3();
            let hi = (DVec3::from(max) - self.world_offset).as_vec3();
            // Round outward so f32 bounds still contain the f64 ones.
            bounds.push(Aabb::new(
                Vec3A::from(lo) - Vec3A::from(lo).abs() * gamma(2),
                Vec3A::from(hi) + Vec3A::from(hi).abs() * gamma(2),
            ));
        }
        let (bvh, order) = Bvh::build(&bounds);
        self.refs = order.iter().map(|&i| self.refs[i as usize]).collect();
        self.material = order.iter().map(|&i| self.material[i as usize]).collect();
        self.bvh = bvh;
        Ok(())
    }

    fn world_ray(&self, ray: &Ray, t_max: f32) -> abi::RayF64 {
        let o = ray.origin.as_dvec3() + self.world_offset;
        abi::RayF64 {
            origin: o.into(),
            direction: ray.dir.as_dvec3().into(),
            tmin: 0.0,
            tmax: t_max as f64,
            time: ray.time as f64,
        }
    }

    /// Raises the fault for a panic in object `o`'s `intersect` or `occluded`, with the
    /// plugin's message when it sent one (the SDK does, once per object).
    fn panicked(&self, o: u32) {
        let label = self.objects[o as usize].label();
        match take_plugin_panic() {
            Some(m) => self
                .fault
                .raise(format!("{label} panicked while intersecting a ray: {m}")),
            None => self
                .fault
                .raise_with(format!("{label} panicked while intersecting a ray"), false),
        }
    }

    /// Objects whose plugin answered hits with NaN: (object, how many hits).
    pub fn nan_hits(&self) -> impl Iterator<Item = (&CustomObject, u64)> {
        self.objects
            .iter()
            .map(|o| (o, o.nan_hits.load(Ordering::Relaxed)))
            .filter(|&(_, n)| n > 0)
    }

    #[inline]
    /// A clipped custom hit counts as a miss (the plugin returns one root only).
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        hit: &mut Option<Hit>,
        clips: &Clips,
        c: &mut Counters,
    ) {
        if self.refs.is_empty() {
            return;
        }
        *t_max = self.bvh.intersect(ray.origin, ray.dir, *t_max, |i, tm| {
            c.tests += 1;
            let (o, idx) = self.refs[i];
            let obj = &self.objects[o as usize];
            let wr = self.world_ray(ray, tm);
            let mut h = abi::HitF64::default();
            // SAFETY: `obj` is live (see `CustomObject`), the ray and hit are our locals, and
            // the ABI allows concurrent calls.
            match unsafe { (obj.vtable.intersect)(obj.object, idx, &wr, &mut h) } {
                1 if obj.is_nan(&h) => None,
                1 => {
                    let t = h.t as f32;
                    let n = Vec3A::from(DVec3::from(h.normal).normalize_or_zero().as_vec3());
                    if !(t > 0.0 && t < tm) || n == Vec3A::ZERO {
                        return None;
                    }
                    if clips.cut(clip_of(self.material[i]), ray.at(t)) {
                        return None;
                    }
                    let mut hh = Hit::new(t, Kind::Custom, i);
                    hh.n = n;
                    // A plugin object has no barycentrics: its uv takes their place.
                    [hh.b1, hh.b2] = h.uv;
                    *hit = Some(hh);
                    Some(t)
                }
                abi::HIT_PANIC => {
                    self.panicked(o);
                    None
                }
                _ => None,
            }
        });
    }

    #[inline]
    pub fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        clips: &Clips,
        c: &mut Counters,
        mut on_hit: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.refs.is_empty() {
            return false;
        }
        // Occlusion through the plugin gives no hit point: clipped primitives use intersect.
        let clipped = |i: usize| clip_of(self.material[i]) != 0;
        let wr = self.world_ray(ray, t_max);
        self.bvh.any(ray.origin, ray.dir, t_max, |i| {
            c.tests += 1;
            let (o, idx) = self.refs[i];
            let obj = &self.objects[o as usize];
            if clipped(i) {
                let mut h = abi::HitF64::default();
                let mut r = wr;
                r.tmax = t_max as f64;
                // SAFETY: as in `intersect`.
                return match unsafe { (obj.vtable.intersect)(obj.object, idx, &r, &mut h) } {
                    1 => {
                        !clips.cut(clip_of(self.material[i]), ray.at(h.t as f32))
                            && on_hit(material_of(self.material[i]), 1)
                    }
                    abi::HIT_PANIC => {
                        self.panicked(o);
                        false
                    }
                    _ => false,
                };
            }
            // SAFETY: as in `intersect`.
            match unsafe { (obj.vtable.occluded)(obj.object, idx, &wr) } {
                1 => on_hit(material_of(self.material[i]), 1),
                abi::HIT_PANIC => {
                    self.panicked(o);
                    false
                }
                _ => false,
            }
        })
    }

    pub fn surface(&self, hit: &Hit, ray: &Ray) -> Surface {
        let p = ray.at(hit.t);
        // The plugin's root is as good as f64 allows; rounding to f32 and its unknown method
        // get a generous relative bound.
        let p_error = gamma(64) * (p.abs() + ray.origin.abs());
        let material = material_of(self.material[hit.index as usize]);
        Surface::solid(p, p_error, hit.n, [hit.b1, hit.b2], material)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic message logged by a plugin is kept for the thread's next `take`, once; other
    /// log messages are not.
    #[test]
    fn a_logged_panic_is_taken_once_on_its_thread() {
        assert!(!keep_plugin_panic(0, "panicked at src/lib.rs:3"));
        assert!(!keep_plugin_panic(1, "panicked in `intersect`: boom"));
        assert_eq!(take_plugin_panic(), None);
        assert!(keep_plugin_panic(0, "panicked in `intersect`: boom: at 3"));
        assert_eq!(std::thread::spawn(take_plugin_panic).join().unwrap(), None);
        assert_eq!(take_plugin_panic().as_deref(), Some("boom: at 3"));
        assert_eq!(take_plugin_panic(), None);
    }

    /// The first message with the plugin's words wins; one without them gives way to it.
    #[test]
    fn a_fault_keeps_the_first_message_with_the_plugins_words() {
        let f = PluginFault::default();
        assert!(!f.is_raised());
        f.raise_with("object 0 panicked".into(), false);
        assert!(f.is_raised());
        assert_eq!(f.message().as_deref(), Some("object 0 panicked"));
        f.raise("object 0 panicked: index out of bounds".into());
        f.raise("object 1 panicked: later".into());
        f.raise_with("object 2 panicked".into(), false);
        assert_eq!(
            f.message().as_deref(),
            Some("object 0 panicked: index out of bounds")
        );
    }
}
