//! Native geometry (intersected inline) and custom plugin geometry (called through its table),
//! each kind in its own BVH, so every traversal loop is monomorphic.

pub mod array_set;
pub mod cone;
// Calls into plugin objects.
#[allow(unsafe_code)]
pub mod custom;
pub mod disc;
pub mod group;
pub mod instance;
pub mod objects;
pub mod plane;
pub mod set;
pub mod sphere;
pub mod sweep;
// An unchecked axis index and a prefetch.
#[allow(unsafe_code)]
pub mod triangle;

#[cfg(test)]
mod props;

#[cfg(test)]
mod testing {
    use crate::math::DVec3;

    /// Deterministic numbers for the random cases.
    pub struct Lcg(pub u64);

    impl Lcg {
        /// Uniform in [0, 1).
        pub fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
        /// 10^x for x uniform in [lo, hi).
        pub fn log(&mut self, lo: f64, hi: f64) -> f64 {
            10f64.powf(self.range(lo, hi))
        }
        pub fn unit(&mut self) -> DVec3 {
            loop {
                let v = DVec3::new(
                    self.range(-1.0, 1.0),
                    self.range(-1.0, 1.0),
                    self.range(-1.0, 1.0),
                );
                if v.length() > 0.1 && v.length() <= 1.0 {
                    return v.normalize();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    /// A hit is copied on every closer find: the array objects' and the instances' numbers
    /// took padding and the room of the plugin objects' uv (kept in `b1`, `b2`).
    #[test]
    fn a_hit_stays_48_bytes() {
        assert_eq!(std::mem::size_of::<super::Hit>(), 48);
    }
}

use crate::math::Vec3A;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Sphere,
    Triangle,
    Plane,
    Cone,
    Disc,
    Custom,
}

/// Each primitive stores its material index and clip group in one u32 (no extra memory for
/// clipping): the low `CLIP_SHIFT` bits are the material, the rest the clip group (0: none).
pub const CLIP_SHIFT: u32 = 20;
pub const MAX_MATERIALS: u32 = 1 << CLIP_SHIFT;
pub const MAX_CLIP_GROUPS: u32 = 1 << (32 - CLIP_SHIFT);

pub fn pack(material: u32, clip: u32) -> u32 {
    material | (clip << CLIP_SHIFT)
}

pub fn material_of(packed: u32) -> u32 {
    packed & (MAX_MATERIALS - 1)
}

pub fn clip_of(packed: u32) -> u32 {
    packed >> CLIP_SHIFT
}

/// Clip groups in render space: group `k` is `groups[k - 1]`; a plane is (point, normal) and cuts
/// away what lies on the side its normal points to.
#[derive(Clone, Debug, Default)]
pub struct Clips {
    pub groups: Vec<Vec<(Vec3A, Vec3A)>>,
}

impl Clips {
    /// Whether point `p` of a primitive in clip group `clip` is cut away.
    #[inline]
    pub fn cut(&self, clip: u32, p: Vec3A) -> bool {
        clip != 0
            && self.groups[clip as usize - 1]
                .iter()
                .any(|(q, n)| (p - *q).dot(*n) > 0.0)
    }
}

/// `Hit::instance` of a hit outside every shared instance.
pub const NO_INSTANCE: u32 = u32::MAX;

/// The closest hit found so far. Kind-specific extras (`b1`, `b2`: triangle barycentrics;
/// `n`, `uv`: custom geometry's answer) are filled by the kind that found it.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub kind: Kind,
    /// On a keyed object (in the scene's moving group) rather than in the still geometry.
    pub moving: bool,
    /// On array object `object - 1` of the scene's [`objects::Objects`] (0: not on one; 16
    /// bits fit the padding after `kind` and `moving`, so a hit stays 48 bytes). On a
    /// `moving` hit: on the moving group's sweep `object - 1` (see `group`).
    pub object: u16,
    /// The shared instance hit (`NO_INSTANCE`: none; the primitive is in the scene's own
    /// geometry or its moving group).
    pub instance: u32,
    /// The primitive within its kind (64-bit: molecular scenes reach billions of atoms).
    pub index: u64,
    /// Barycentrics of a triangle hit; a plugin object's uv.
    pub b1: f32,
    pub b2: f32,
    pub n: Vec3A,
}

impl Hit {
    pub fn new(t: f32, kind: Kind, index: usize) -> Hit {
        Hit {
            t,
            kind,
            moving: false,
            object: 0,
            instance: NO_INSTANCE,
            index: index as u64,
            b1: 0.0,
            b2: 0.0,
            n: Vec3A::ZERO,
        }
    }
}

/// Everything shading needs about a hit point.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub p: Vec3A,
    /// Bound on the rounding error of `p`, per component (for spawning rays off the surface).
    pub p_error: Vec3A,
    /// Unit geometric normal as the geometry orients it (outward for closed shapes).
    pub ng: Vec3A,
    /// Unit shading normal, in the same hemisphere as `ng`.
    pub ns: Vec3A,
    pub uv: [f32; 2],
    /// uv units per world unit near `p` (0: unknown), to measure footprints in uv space.
    pub uv_scale: f32,
    pub material: u32,
    /// Per-vertex colour, when the mesh has one.
    pub color: Option<Vec3A>,
    /// From `p` to where light rays should start on the side `ng` points to: above a flat facet
    /// of a smooth-shaded mesh, at the curved surface its vertex normals describe, so the
    /// facets do not shadow themselves near the terminator (zero for every other shape).
    pub lift: Vec3A,
}

impl Surface {
    /// The surface of a solid shape: one normal for shading and geometry, no vertex colour,
    /// no lift, uv scale unknown.
    #[inline(always)]
    pub fn solid(p: Vec3A, p_error: Vec3A, n: Vec3A, uv: [f32; 2], material: u32) -> Surface {
        Surface {
            p,
            p_error,
            ng: n,
            ns: n,
            uv,
            uv_scale: 0.0,
            material,
            color: None,
            lift: Vec3A::ZERO,
        }
    }
}

/// Per-thread counters of work done (summed after the render; deterministic).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    pub primary: u64,
    pub shadow: u64,
    pub reflection: u64,
    pub refraction: u64,
    /// Ambient occlusion rays.
    pub occlusion: u64,
    /// Ray/primitive intersection tests (all kinds).
    pub tests: u64,
    /// Pixels whose value was NaN or infinite (clamped to 0).
    pub nan_pixels: u64,
    /// Volume samples taken (one per volume per step, camera and shadow rays alike).
    pub volume_samples: u64,
}

impl Counters {
    pub fn add(&mut self, o: &Counters) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.occlusion += o.occlusion;
        self.tests += o.tests;
        self.nan_pixels += o.nan_pixels;
        self.volume_samples += o.volume_samples;
    }

    pub fn rays(&self) -> u64 {
        self.primary + self.shadow + self.reflection + self.refraction + self.occlusion
    }
}
