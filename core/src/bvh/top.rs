//! The top level of a two-level BVH: a [`Bvh`] over the bounds of instances (its primitive `i`
//! is instance `i`), and the instances whose bounds are not finite (prototypes holding
//! infinite planes), which no box can hold and every ray tests. The tests are closures, so the
//! caller decides what testing instance `i` means (transforming the ray into its prototype's
//! space and traversing that prototype's own BVHs).

use super::{BoxRay, Bvh};
use crate::math::Aabb;

#[derive(Clone, Debug, Default)]
pub struct TopLevel {
    bvh: Bvh,
    /// Leaf order: `order[p]` is the instance at the BVH's primitive position `p`.
    order: Vec<u32>,
    /// Instances tested on every ray, in instance order.
    unbounded: Vec<u32>,
}

impl TopLevel {
    /// The top level over instance bounds; instances with a non-finite (or NaN) box go to the
    /// list every ray tests, and empty ones (an instance of nothing) nowhere.
    pub fn build(bounds: &[Aabb]) -> TopLevel {
        let finite = |b: &Aabb| b.min.is_finite() && b.max.is_finite();
        let (boxed, unbounded): (Vec<u32>, Vec<u32>) = (0..bounds.len() as u32)
            .filter(|&i| bounds[i as usize] != Aabb::EMPTY)
            .partition(|&i| finite(&bounds[i as usize]));
        let (bvh, order) = Bvh::build_with(boxed.len(), |i| bounds[boxed[i] as usize]);
        let order = order.iter().map(|&p| boxed[p as usize]).collect();
        TopLevel {
            bvh,
            order,
            unbounded,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty() && self.unbounded.is_empty()
    }

    /// Closest hit: `test(instance, t_max)` returns `Some(t)` for a hit in that instance closer
    /// than `t_max`; boxed instances first (nearest box first), then the unbounded ones.
    /// Returns the final `t_max`.
    #[inline]
    pub fn intersect(
        &self,
        ray: &BoxRay,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        let order = &self.order;
        let mut t_max = self.bvh.intersect_ray(ray, t_max, |p, t| test(order[p], t));
        for &i in &self.unbounded {
            if let Some(t) = test(i, t_max) {
                t_max = t;
            }
        }
        t_max
    }

    /// Any hit: whether `test(instance)` returned true for some instance whose box the ray
    /// meets before `t_max` (or an unbounded one); stops at the first.
    #[inline]
    pub fn any(&self, ray: &BoxRay, t_max: f32, mut test: impl FnMut(u32) -> bool) -> bool {
        let order = &self.order;
        self.bvh.any_ray(ray, t_max, |p| test(order[p])) || self.unbounded.iter().any(|&i| test(i))
    }

    /// Bytes of the nodes and the index lists.
    pub fn memory_bytes(&self) -> u64 {
        self.bvh.memory_bytes() + 4 * (self.order.capacity() + self.unbounded.capacity()) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3A;

    /// Every instance whose box a ray meets is offered, each once, and unbounded ones always.
    #[test]
    fn offers_each_met_instance_once_and_the_unbounded_always() {
        let mut bounds = super::super::tests::boxes(300);
        bounds[7] = Aabb::new(Vec3A::splat(f32::NEG_INFINITY), Vec3A::splat(f32::INFINITY));
        bounds[100] = Aabb::new(Vec3A::new(0.0, f32::NEG_INFINITY, 0.0), Vec3A::ONE);
        let top = TopLevel::build(&bounds);
        let ray = BoxRay::new(Vec3A::new(-1.0, 50.0, 50.0), Vec3A::X);
        let mut seen = vec![0u32; bounds.len()];
        top.intersect(&ray, f32::INFINITY, |i, _| {
            seen[i as usize] += 1;
            None
        });
        assert_eq!((seen[7], seen[100]), (1, 1));
        for (i, b) in bounds.iter().enumerate() {
            let met = b.min.y <= 50.0 && b.max.y >= 50.0 && b.min.z <= 50.0 && b.max.z >= 50.0;
            if i != 7 && i != 100 {
                assert_eq!(seen[i], u32::from(met), "instance {i}");
            }
        }
        let mut any_seen = Vec::new();
        assert!(!top.any(&ray, f32::INFINITY, |i| {
            any_seen.push(i);
            false
        }));
        any_seen.sort_unstable();
        let mut want: Vec<u32> = (0..300).filter(|&i| seen[i as usize] == 1).collect();
        want.sort_unstable();
        assert_eq!(any_seen, want);
        assert!(top.any(&ray, f32::INFINITY, |i| i == 100));
    }
}
