//! Shadow rays in a scene whose surfaces each either block light or let it through unchanged:
//! Tachyon's scenes, opaque surfaces beside the light spheres Tachyon draws, which cast no
//! shadow. A shadow ray there is blocked or not, whatever the order it meets surfaces in, so
//! it is asked of the spheres that block only (the light spheres left out at build time, not
//! passed over one by one on every ray), and of small sets one primitive after another.

use super::Scene;
use crate::bvh::BoxRay;
use crate::geometry::sphere::Spheres;
use crate::geometry::{material_of, Counters};
use crate::math::Vec3A;
use crate::ray::Ray;

/// Most spheres copied into [`Casters`] (tens of kilobytes, not charged to the memory
/// budget): more would take a second BVH build; those pass the light spheres over one by one
/// as before. Worth the copy: a shadow ray towards a point light drawn as a sphere ends inside
/// that sphere's box, so the shared tree leads every such ray down to it (820spheres: 1.15
/// light spheres passed over per shadow ray).
const MAX_COPIED: usize = 1024;

/// What shadow rays test in such a scene.
pub struct Casters {
    /// The spheres that block light, in their own BVH (`None`: too many to copy).
    spheres: Option<Spheres>,
    /// Per kind (triangles, cones, discs): every primitive blocks, so the kind is asked
    /// without looking at materials.
    all_block: [bool; 3],
    /// Every kind is a handful of spheres or triangles tested one by one, or planes (fog,
    /// spotlight, model2): a shadow ray needs no box tests, so their set-up is not made.
    few: bool,
}

impl Casters {
    /// The casters of `scene` when every used material either blocks shadow rays or lets them
    /// through unchanged, and some used one does the latter (otherwise the general query
    /// costs no more). Not for an animated scene, whose frames may change a material's shadow,
    /// nor for one with shared instances or array objects (not in the copy).
    pub(super) fn of(scene: &Scene) -> Option<Casters> {
        let used = scene.materials.iter().zip(&scene.used_materials);
        let mut used = used.filter(|(_, u)| **u).map(|(m, _)| m.shadow);
        if !scene.features.see_through
            || scene.animation.is_some()
            || !scene.instances.is_empty()
            || !scene.objects.is_empty()
            || !used.all(|s| s.is_none() || s == Some(Vec3A::ONE))
        {
            return None;
        }
        let blocks = |packed: u32| {
            scene.materials[material_of(packed) as usize]
                .shadow
                .is_none()
        };
        let all = |m: &[u32]| m.iter().all(|&p| blocks(p));
        let spheres = (scene.spheres.len() <= MAX_COPIED).then(|| scene.spheres.filtered(blocks));
        let all_block = [
            all(&scene.triangles.set.material),
            all(&scene.cones.material),
            all(&scene.discs.material),
        ];
        let tri = &scene.triangles.set;
        let few = spheres.as_ref().is_some_and(|s| s.few())
            && (tri.is_empty() || (tri.few() && all_block[0]))
            && scene.cones.is_empty()
            && scene.discs.is_empty()
            && scene.customs.is_empty()
            && scene.moving.is_empty();
        Some(Casters {
            spheres,
            all_block,
            few,
        })
    }

    /// Whether something blocks `ray` before `t_max`.
    #[inline(always)]
    pub(super) fn blocked(&self, scene: &Scene, ray: &Ray, t_max: f32, c: &mut Counters) -> bool {
        match (&self.spheres, self.few) {
            (Some(spheres), true) => Self::blocked_few(spheres, scene, ray, t_max, c),
            _ => self.blocked_tree(scene, ray, t_max, c),
        }
    }

    /// [`Casters::blocked`] when `few` holds: the same tests in the same order
    /// (so the same answer and test count) as [`Casters::blocked_tree`].
    #[inline(never)]
    fn blocked_few(
        spheres: &Spheres,
        scene: &Scene,
        ray: &Ray,
        t_max: f32,
        c: &mut Counters,
    ) -> bool {
        // A ray with a NaN or infinite coordinate, or a NaN length, meets no sphere or
        // triangle, as in the trees; planes answer for themselves.
        let meets = ray.finite() && !t_max.is_nan();
        let tri = &scene.triangles.set;
        let blocks = |m: u32, _: u32| scene.materials[m as usize].shadow.is_none();
        (meets && (spheres.any_few(ray, t_max, c) || tri.any_few(ray, t_max, c)))
            || scene.planes.any(ray, t_max, &scene.clips, c, blocks)
    }

    /// [`Casters::blocked`] through the kinds' trees.
    #[inline(never)]
    fn blocked_tree(&self, scene: &Scene, ray: &Ray, t_max: f32, c: &mut Counters) -> bool {
        // The box tests' set-up, once for every kind.
        let boxes = BoxRay::new(ray.origin, ray.dir);
        let (b, clips) = (&boxes, &scene.clips);
        let blocks = |m: u32, _: u32| scene.materials[m as usize].shadow.is_none();
        let [triangles, cones, discs] = self.all_block;
        let tri = &scene.triangles.set;
        let passes = |m: u32| scene.materials[m as usize].shadow.is_some();
        let spheres = match &self.spheres {
            Some(s) => s.any_opaque(ray, b, t_max, clips, c),
            None => (scene.spheres).any_skipping(ray, b, t_max, clips, c, passes, |_, _| true),
        };
        // Empty kinds are passed over here, not in a call each: a Tachyon scene uses two or
        // three kinds of the seven.
        spheres
            || (!tri.is_empty()
                && if triangles {
                    tri.any_opaque(ray, b, t_max, clips, c)
                } else {
                    tri.any_prepared(ray, b, t_max, clips, c, blocks)
                })
            || scene.planes.any(ray, t_max, clips, c, blocks)
            || (!scene.cones.is_empty()
                && if cones {
                    (scene.cones).any_opaque(ray, b, t_max, clips, c)
                } else {
                    (scene.cones).any_prepared(ray, b, t_max, clips, c, blocks)
                })
            || (!scene.discs.is_empty()
                && if discs {
                    (scene.discs).any_opaque(ray, b, t_max, clips, c)
                } else {
                    (scene.discs).any_prepared(ray, b, t_max, clips, c, blocks)
                })
            || (!scene.customs.is_empty() && scene.customs.any(ray, t_max, clips, c, blocks))
            || (!scene.moving.is_empty() && scene.moving.any(ray, t_max, clips, c, &mut { blocks }))
    }
}
