//! Closest hits of the smallest scenes (Tachyon's fog, spotlight, model2: a few spheres, at
//! most one triangle, planes) without the trees: the spheres' first test runs four at a
//! time, in lanes, instead of the node's box tests and their set-up.

use super::Scene;
use crate::geometry::set::Shape;
use crate::geometry::sphere::Sphere;
use crate::geometry::triangle::Triangle;
use crate::geometry::{clip_of, Counters, Hit};
use crate::ray::Ray;
use glam::Vec4;

/// Groups of four spheres.
const GROUPS: usize = 2;

/// The scene's spheres, four to a group by coordinate, for [`Few::closest`].
#[derive(Clone, Debug)]
pub struct Few {
    cx: [Vec4; GROUPS],
    cy: [Vec4; GROUPS],
    cz: [Vec4; GROUPS],
    r2: [Vec4; GROUPS],
    /// `-r² · 1e-4`: the margin of `intersect_sphere`'s first test.
    margin: [Vec4; GROUPS],
    /// The groups holding spheres.
    groups: usize,
    /// One bit per sphere (lane `4 g + k` of group `g`).
    live: u32,
}

impl Few {
    /// For a scene of at most eight spheres and one triangle besides planes, none in a clip
    /// group, and nothing else; `None` for any other.
    pub fn of(scene: &Scene) -> Option<Few> {
        let (spheres, tri) = (&scene.spheres, &scene.triangles.set);
        let unclipped = |m: &[u32]| m.iter().all(|&m| clip_of(m) == 0);
        let few = spheres.len() <= 4 * GROUPS
            && tri.len() <= 1
            && unclipped(&spheres.material)
            && unclipped(&tri.material)
            && scene.cones.is_empty()
            && scene.discs.is_empty()
            && scene.customs.is_empty()
            && scene.moving.is_empty()
            && scene.instances.is_empty()
            && scene.objects.is_empty();
        if !few {
            return None;
        }
        Some(Few::new(&spheres.data))
    }

    /// The lanes of up to eight spheres (also `Casters`' copy of the blocking ones).
    pub(super) fn new(spheres: &[Sphere]) -> Few {
        assert!(
            spheres.len() <= 4 * GROUPS,
            "at most {} spheres",
            4 * GROUPS
        );
        let mut lanes = [[0.0f32; 4 * GROUPS]; 5];
        for (i, s) in spheres.iter().enumerate() {
            let r2 = s.radius * s.radius;
            let v = [s.center.x, s.center.y, s.center.z, r2, -r2 * 1e-4];
            for (lane, v) in lanes.iter_mut().zip(v) {
                lane[i] = v;
            }
        }
        let group = |k: usize| std::array::from_fn(|g| Vec4::from_slice(&lanes[k][4 * g..]));
        Few {
            cx: group(0),
            cy: group(1),
            cz: group(2),
            r2: group(3),
            margin: group(4),
            groups: spheres.len().div_ceil(4),
            live: (1u32 << spheres.len()) - 1,
        }
    }

    /// The spheres that `intersect_sphere`'s first test (the ray's distance from the centre,
    /// in f32) does not reject, a bit each: the same operations in the same order, lane by
    /// lane, so the same answers.
    #[inline(always)]
    pub(super) fn near(&self, ray: &Ray) -> u32 {
        let (o, d) = (ray.origin, ray.dir);
        let (dx, dy, dz) = (Vec4::splat(d.x), Vec4::splat(d.y), Vec4::splat(d.z));
        let mut near = 0;
        for g in 0..self.groups {
            let fx = Vec4::splat(o.x) - self.cx[g];
            let fy = Vec4::splat(o.y) - self.cy[g];
            let fz = Vec4::splat(o.z) - self.cz[g];
            let fd = fx * dx + fy * dy + fz * dz;
            let (lx, ly, lz) = (fx - fd * dx, fy - fd * dy, fz - fd * dz);
            let ll = lx * lx + ly * ly + lz * lz;
            let far = (self.r2[g] - ll).cmplt(self.margin[g]).bitmask();
            near |= (!far & 0xf) << (4 * g);
        }
        near & self.live
    }

    /// The nearest sphere hit before `t_max`: its distance, index and `b1`, `b2`; `None` when
    /// two spheres tie for it.
    #[inline(always)]
    fn nearest(
        &self,
        spheres: &[Sphere],
        ray: &Ray,
        mut t_max: f32,
        c: &mut Counters,
    ) -> Option<Option<(f32, usize, f32, f32)>> {
        let mut near = self.near(ray);
        let mut best = None;
        // The order of the tests decides nothing but exact ties between two spheres: each
        // looks up to `t_max` inclusive to see them.
        let mut upto = t_max.next_up();
        while near != 0 {
            let i = near.trailing_zeros() as usize;
            near &= near - 1;
            c.tests += 1;
            if let Some((t, b1, b2)) = Sphere::hit(&spheres[i], ray, &(), upto) {
                if t < t_max {
                    best = Some((t, i, b1, b2));
                    (t_max, upto) = (t, t.next_up());
                } else if best.is_some() {
                    return None;
                }
            }
        }
        Some(best)
    }

    /// [`Scene::intersect`] for the scene this was made of: the hit its trees give. `None`
    /// when two spheres tie for the nearest hit (the tree takes the one whose box it enters
    /// first: the caller asks the trees then).
    #[inline(always)]
    pub fn closest(
        &self,
        scene: &Scene,
        ray: &Ray,
        mut t_max: f32,
        c: &mut Counters,
    ) -> Option<Option<Hit>> {
        let mut hit = None;
        // A ray with a NaN or infinite coordinate, or a NaN length, meets no sphere or
        // triangle, as in the trees; planes answer for themselves.
        if ray.finite() && !t_max.is_nan() {
            if let Some((t, i, b1, b2)) = self.nearest(&scene.spheres.data, ray, t_max, c)? {
                hit = Some(Hit {
                    b1,
                    b2,
                    ..Hit::new(t, Sphere::KIND, i)
                });
                t_max = t;
            }
            // At most one triangle: its test alone, with the spheres' nearest hit as the
            // tree is given it (its test compares before a division: no `upto` here).
            let tri = &scene.triangles.set;
            if let Some(shape) = tri.data.first() {
                c.tests += 1;
                if let Some((t, b1, b2)) = shape.hit(ray, &Triangle::prep(ray), t_max) {
                    hit = Some(Hit {
                        b1,
                        b2,
                        ..Hit::new(t, Triangle::KIND, 0)
                    });
                    t_max = t;
                }
            }
        }
        scene
            .planes
            .intersect(ray, &mut t_max, &mut hit, &scene.clips, c);
        Some(hit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::set::Set;
    use crate::geometry::sphere::intersect_sphere;
    use crate::geometry::Clips;
    use crate::math::Vec3A;
    use crate::scene::testing::rng;
    use glam::Vec3;

    #[test]
    fn the_lanes_find_the_trees_nearest_sphere() {
        let mut r = rng(0x9e37_79b9_7f4a_7c15);
        let mut ties = 0;
        for n in 1..=8 {
            let mut made: Vec<Sphere> = (0..n)
                .map(|_| Sphere {
                    center: Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, 3.0 + r() * 4.0),
                    radius: 0.2 + r(),
                })
                .collect();
            if n > 2 {
                // A copy: the same hits, tied (the tree picks one by its boxes).
                made[n - 1] = made[0];
            }
            let mut set = Set::default();
            for (k, s) in made.iter().enumerate() {
                set.push(*s, k as u32);
            }
            set.build();
            // In the tree's order, as the scene keeps them.
            let spheres = set.data.clone();
            let few = Few::new(&spheres);
            for _ in 0..2000 {
                let origin = Vec3A::new(r() - 0.5, r() - 0.5, r() * 2.0 - 1.0);
                let dir = Vec3A::new(r() - 0.5, r() - 0.5, 1.0).normalize();
                let ray = Ray::new(origin, dir, 0.0);
                let t_max = if r() < 0.2 {
                    4.0 + r() * 3.0
                } else {
                    f32::INFINITY
                };
                // What the first test rejects, the full test misses.
                let near = few.near(&ray);
                for (i, s) in spheres.iter().enumerate() {
                    if near & (1 << i) == 0 {
                        let t = intersect_sphere(s, ray.origin, ray.dir, 0.0, f32::INFINITY);
                        assert_eq!(t.0, None, "sphere {i} of {n} passed over");
                    }
                }
                let c = &mut Counters::default();
                let (mut t, mut hit) = (t_max, None);
                set.intersect(&ray, &mut t, &mut hit, &Clips::default(), c);
                let tree = hit.map(|h| (h.t, h.index as usize));
                match few.nearest(&spheres, &ray, t_max, c) {
                    Some(found) => assert_eq!(found.map(|f| (f.0, f.1)), tree),
                    None => {
                        // A tie: another sphere meets the ray where the tree's does.
                        let (t, i) = tree.expect("a tie is a hit");
                        let same = spheres.iter().enumerate().filter(|&(k, s)| {
                            k != i
                                && intersect_sphere(s, ray.origin, ray.dir, 0.0, t.next_up()).0
                                    == Some(t)
                        });
                        assert!(same.count() > 0, "no tie at {t}");
                        ties += 1;
                    }
                }
            }
        }
        assert!(ties > 0, "the copies should tie");
    }
}
