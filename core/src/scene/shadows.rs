//! Shadow rays in a scene whose surfaces each either block light or let it through unchanged:
//! Tachyon's scenes, opaque surfaces beside the light spheres Tachyon draws, which cast no
//! shadow. A shadow ray there is blocked or not, whatever the order it meets surfaces in, so
//! it is asked of the spheres that block only (the light spheres left out at build time, not
//! passed over one by one on every ray), and of small sets one primitive after another.

use super::few::Few;
use super::Scene;
use crate::bvh::BoxRay;
use crate::geometry::set::Set;
use crate::geometry::sphere::{solve_sphere, Sphere, Spheres};
use crate::geometry::triangle::Triangle;
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
    /// With `few`: a ball around each triangle, in the set's order (empty otherwise).
    balls: Vec<Ball>,
    /// `Some` when every kind is a handful of spheres or triangles tested one by one, or
    /// planes (fog, spotlight, model2: `few`): a shadow ray needs no box tests, so their
    /// set-up is not made. The blocking spheres again, as that query reads them.
    few: Option<FewSpheres>,
    /// With `few`: per scene sphere, the bits of `few`'s copies of it (a shadow ray leaving a
    /// sphere outward cannot meet it again; see [`Casters::own`]). Empty otherwise.
    own: Vec<u32>,
}

/// The blocking spheres of a `few` scene: in lanes for their first test, four at a time,
/// and as they are for the rest (one `match` and a register's worth of arguments per
/// shadow ray, not two `Option`s).
struct FewSpheres {
    lanes: Few,
    data: Vec<Sphere>,
}

/// Per sphere of `all` (the scene's), the bits of the spheres of `copied` with the same
/// centre and radius (a duplicate is the same surface, so either copy may be passed over).
fn own_bits(all: &[Sphere], copied: &[Sphere]) -> Vec<u32> {
    let key = |s: &Sphere| (s.center.to_array().map(f32::to_bits), s.radius.to_bits());
    all.iter()
        .map(|s| {
            let k = key(s);
            (copied.iter().enumerate())
                .filter(|(_, c)| key(c) == k)
                .fold(0, |bits, (j, _)| bits | 1 << j)
        })
        .collect()
}

/// A ball holding a triangle, with room to spare: a ray whose line passes outside it cannot
/// cross the triangle, so the ray is answered without the watertight test's shear set-up
/// (model2: one triangle, some 130 instructions on every shadow ray, which nearly all miss).
#[derive(Clone, Copy)]
struct Ball {
    center: Vec3A,
    /// The squared radius: the farthest vertex's distance from the centre, plus 1 %.
    r2: f32,
}

impl Ball {
    fn around(v: &[glam::Vec3; 3]) -> Ball {
        let v = v.map(|p| p.as_dvec3());
        // The radius from the centre as stored: its rounding (up to half a float step of
        // the coordinates, more than a small triangle far out) must not shrink the ball.
        let center = ((v[0] + v[1] + v[2]) / 3.0).as_vec3a();
        let c = center.as_dvec3();
        let r = v.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
        // A vertex that is not finite makes `r2` infinite or NaN: the ball never rejects.
        Ball {
            center,
            r2: (r * 1.01 * (r * 1.01)) as f32,
        }
    }

    /// Whether the line of `ray` (finite, unit direction) passes outside the ball, surely.
    /// The watertight test may take a point outside the triangle by its rounding, some
    /// 1e-6 of the vertices' distance from the origin; the 1 % on the radius and the
    /// 1e-8 |o - c|² (a distance of 1e-4 |o - c|) cover it, and the rounding here, many
    /// times over. A NaN radius compares false: the triangle is tested.
    #[inline(always)]
    fn missed_by(&self, ray: &Ray) -> bool {
        let f = ray.origin - self.center;
        let l = f - f.dot(ray.dir) * ray.dir;
        l.dot(l) > self.r2 + 1e-8 * f.dot(f)
    }
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
        let (balls, few, own) = match (&spheres, few) {
            (Some(spheres), true) => (
                tri.data.iter().map(|t| Ball::around(&t.v)).collect(),
                Some(FewSpheres {
                    lanes: Few::new(&spheres.data),
                    data: spheres.data.clone(),
                }),
                own_bits(&scene.spheres.data, &spheres.data),
            ),
            _ => (Vec::new(), None, Vec::new()),
        };
        Some(Casters {
            spheres,
            all_block,
            balls,
            few,
            own,
        })
    }

    /// The spheres a shadow ray may pass over when it leaves scene sphere `i` outward: as
    /// bits of the copied spheres (0: none, or not a `few` scene). See [`Casters::blocked`].
    #[inline(always)]
    pub(super) fn own(&self, i: u64) -> u32 {
        self.own.get(i as usize).copied().unwrap_or(0)
    }

    /// Whether something blocks `ray` before `t_max`. `skip`: bits of [`Casters::own`] for a
    /// ray that starts on the outer side of the tangent plane at a point of that sphere (the
    /// outward offset) and ends on that side too (toward a light above the horizon): the
    /// segment stays in the half-space, which holds none of the convex sphere, so its test
    /// (an answer of "no" after converting to f64) is not made. Only where rounding is
    /// coarser than the sphere or the light's distance (a sphere under 1e4 float steps of its
    /// position) could that test have answered "blocked", by the rounding: such a point is
    /// then lit, not darkened by its own sphere.
    #[inline(always)]
    pub(super) fn blocked(
        &self,
        scene: &Scene,
        ray: &Ray,
        t_max: f32,
        skip: u32,
        c: &mut Counters,
    ) -> bool {
        match &self.few {
            Some(few) => self.blocked_few(few, scene, ray, t_max, skip, c),
            None => self.blocked_tree(scene, ray, t_max, c),
        }
    }

    /// [`Casters::blocked`] with `few`: the same answer and test count as
    /// [`Casters::blocked_tree`].
    #[inline(never)]
    fn blocked_few(
        &self,
        spheres: &FewSpheres,
        scene: &Scene,
        ray: &Ray,
        t_max: f32,
        skip: u32,
        c: &mut Counters,
    ) -> bool {
        // A ray with a NaN or infinite coordinate, or a NaN length, meets no sphere or
        // triangle, as in the trees; planes answer for themselves.
        let meets = ray.finite() && !t_max.is_nan();
        let tri = &scene.triangles.set;
        let blocks = |m: u32, _: u32| scene.materials[m as usize].shadow.is_none();
        // No triangle, no ball: asked before the call (fog and spotlight have none).
        let triangles =
            |c: &mut Counters| !self.balls.is_empty() && self.triangles_few(tri, ray, t_max, c);
        (meets && (Self::spheres_few(spheres, ray, t_max, skip, c) || triangles(c)))
            || scene.planes.any(ray, t_max, &scene.clips, c, blocks)
    }

    /// `any_few` of the copy's spheres: the same answer and test count, with
    /// `intersect_sphere`'s first test made for all of them at once (`Few::near`, bit for bit
    /// the same) and the rest for those it keeps, in order, but those in `skip` (see
    /// [`Casters::blocked`]; counted as tested).
    #[inline(always)]
    fn spheres_few(
        spheres: &FewSpheres,
        ray: &Ray,
        t_max: f32,
        skip: u32,
        c: &mut Counters,
    ) -> bool {
        let mut near = spheres.lanes.near(ray) & !skip;
        while near != 0 {
            let i = near.trailing_zeros() as usize;
            near &= near - 1;
            let s = &spheres.data[i];
            if solve_sphere(s.center.into(), s.radius, ray.origin, ray.dir, 0.0, t_max).1 > 0 {
                // `any_few` stops at the first blocker, having tested those before it.
                c.tests += i as u64 + 1;
                return true;
            }
        }
        c.tests += spheres.data.len() as u64;
        false
    }

    /// `tri.any_few` (`tri`: the scene's triangles, [`Set::few`], all blocking) that first
    /// asks the triangles' balls: a ray outside every ball crosses none, and is counted as
    /// having tested each, as `any_few` counts a ray that crosses none.
    #[inline(always)]
    fn triangles_few(&self, tri: &Set<Triangle>, ray: &Ray, t_max: f32, c: &mut Counters) -> bool {
        if self.balls.iter().all(|b| b.missed_by(ray)) {
            c.tests += self.balls.len() as u64;
            return false;
        }
        tri.any_few(ray, t_max, c)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle::{intersect_triangle, TriRay};
    use crate::scene::testing::rng;
    use glam::Vec3;

    /// The lanes' sphere query gives `any_few`'s answer and test count: rays from the
    /// spheres' surfaces (shadow rays) and from around them, short and unbounded, with
    /// copies and spheres inside one another.
    #[test]
    fn lanes_answer_as_any_few() {
        let mut r = rng(0x2545_f491_4f6c_dd1d);
        let (mut blocked, mut open) = (0, 0);
        for n in 0..=4 {
            let mut set = Spheres::default();
            let mut made = Vec::new();
            for k in 0..n {
                let s = if k == 3 {
                    made[0]
                } else {
                    Sphere {
                        center: Vec3::new(r() * 4.0 - 2.0, r() * 4.0 - 2.0, r() * 4.0 - 2.0),
                        radius: 0.1 + r() * (k as f32 + 1.0) * 0.5,
                    }
                };
                made.push(s);
                set.push(s, k as u32);
            }
            set.build();
            let few = FewSpheres {
                lanes: Few::new(&set.data),
                data: set.data.clone(),
            };
            for i in 0..4000 {
                let dir = Vec3A::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
                let origin = match (i % 2, made.len()) {
                    (1, m) if m > 0 => {
                        // On a sphere, leaving it or going through it.
                        let s = made[i % m];
                        let w = Vec3A::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
                        Vec3A::from(s.center) + s.radius * w
                    }
                    _ => Vec3A::new(r() * 6.0 - 3.0, r() * 6.0 - 3.0, r() * 6.0 - 3.0),
                };
                let ray = Ray::new(origin, dir, 0.0);
                let t_max = if r() < 0.5 { r() * 3.0 } else { f32::INFINITY };
                let (a, b) = (&mut Counters::default(), &mut Counters::default());
                let want = set.any_few(&ray, t_max, a);
                let got = Casters::spheres_few(&few, &ray, t_max, 0, b);
                assert_eq!(
                    (got, b.tests),
                    (want, a.tests),
                    "{n} spheres, {ray:?} {t_max}"
                );
                (blocked, open) = if want {
                    (blocked + 1, open)
                } else {
                    (blocked, open + 1)
                };
            }
        }
        assert!(blocked > 1000 && open > 1000, "{blocked} {open}");
    }

    /// What `Casters::blocked` passes over is a test that answers "no": a shadow ray from a
    /// sphere's surface point (as shading computes it, offset outward) toward a target on the
    /// outer side never meets that sphere, for spheres from 1e-3 to 1e4 in radius up to 1e5
    /// from the origin (those at least 1e4 times the point's rounding), and targets from well
    /// above the horizon to grazing it.
    #[test]
    fn a_ray_leaving_a_sphere_outward_never_meets_it() {
        use crate::geometry::sphere::surface;
        use crate::ray::{offset_up, spawn_to_or};
        let mut r = rng(0x9e37_79b9_7f4a_7c15);
        fn unit(r: &mut impl FnMut() -> f32) -> Vec3A {
            Vec3A::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize()
        }
        let (mut tests, mut grazing) = (0, 0);
        for k in 0..3000 {
            let radius = 10f32.powf(-3.0 + 7.0 * (k % 100) as f32 / 99.0);
            let far = 10f32.powi(k % 6) * [0.0, 1.0, 3.0][k as usize % 3];
            let center = far * unit(&mut r);
            let s = Sphere {
                center: center.into(),
                radius,
            };
            // A camera ray from outside, aimed at a point of the sphere.
            let origin = center + (radius * (1.5 + 20.0 * r())) * unit(&mut r);
            let aim = center + radius * 0.999 * unit(&mut r);
            let ray = Ray::new(origin, (aim - origin).normalize(), 0.0);
            let Some(t) = solve_sphere(center, radius, ray.origin, ray.dir, 0.0, f32::INFINITY).0
            else {
                continue;
            };
            let hit = surface(s, t, &ray, false, 0);
            let (p, ng) = (hit.p, hit.ng);
            // Where rounding is coarser than the sphere the point may lie inside it, and its
            // own test may answer "blocked" (acne) that the skip does not give: not asked.
            let error = hit.p_error.max_element();
            if error * 1e4 > radius {
                continue;
            }
            let up = offset_up(p, hit.p_error, ng);
            for j in 0..8 {
                // Targets above the tangent plane, the last ones within a hair of it.
                let w = unit(&mut r);
                let along = w - w.dot(ng) * ng;
                let lift = [0.5, 0.1, 1e-2, 1e-4, 1e-6, 1e-7, 0.0, 3e-8][j];
                let target = p + radius * (3.0 * r() + 0.01) * (along + lift * ng);
                let (shadow, t_max, above) = spawn_to_or(p, hit.p_error, ng, target, 0.0, || up);
                if !above || !shadow.dir.is_finite() || (target - p).length() < error * 1e4 {
                    continue;
                }
                tests += 1;
                grazing += usize::from(lift < 1e-5);
                let got = solve_sphere(center, radius, shadow.origin, shadow.dir, 0.0, t_max);
                assert_eq!(got.1, 0, "{s:?} {p:?} {target:?}: {got:?}");
            }
        }
        assert!(tests > 12_000 && grazing > 5_000, "{tests} {grazing}");
    }

    /// No ray the watertight test takes is rejected by the triangle's ball: rays from near
    /// and far origins (also far from the world's origin) aimed at the corners, the edges
    /// and just outside them, where rounding decides. And rays well away are rejected.
    #[test]
    fn balls_keep_every_hit() {
        let triangles = [
            [(0.0, -4.0, 12.0), (4.0, -4.0, 8.0), (-4.0, -4.0, 8.0)],
            [
                (1e4, 2e4, -3e4),
                (1e4 + 0.01, 2e4, -3e4),
                (1e4, 2e4 + 1e-3, -3e4),
            ],
            [(-1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1e-4, 30.0)],
        ];
        let (mut hits, mut rejected) = (0, 0);
        for t in triangles {
            let v = t.map(|(x, y, z)| Vec3::new(x, y, z));
            let ball = Ball::around(&v);
            let w = v.map(Vec3A::from);
            let size = (w[1] - w[0]).length().max((w[2] - w[0]).length());
            for i in 0..40 {
                let a = i as f32 * 0.61;
                let dir = Vec3A::new(a.cos(), (0.8 * a).sin(), 0.5 - (1.7 * a).cos());
                for far in [0.01, 1.0, 1e3, 1e6] {
                    let origin = w[0] + far * size * dir.normalize();
                    for k in 0..3 {
                        for s in [0.0, 0.5, 1.0] {
                            for nudge in [-1e-4, 0.0, 1e-4] {
                                // Along edge k, at its ends and middle, nudged across.
                                let edge = w[(k + 1) % 3] - w[k];
                                let inward = w[(k + 2) % 3] - w[k];
                                let q = w[k] + s * edge + nudge * inward;
                                let ray = Ray::new(origin, (q - origin).normalize(), 0.0);
                                if !ray.finite() {
                                    continue;
                                }
                                let r = TriRay::new(&ray);
                                if intersect_triangle(&v, &r, f32::INFINITY).is_some() {
                                    hits += 1;
                                    assert!(!ball.missed_by(&ray), "{t:?} {ray:?}");
                                }
                                // The same ray moved aside by ten sizes misses the ball.
                                let aside =
                                    w[0] + 10.0 * size * Vec3A::Y.cross(ray.dir).normalize();
                                let away = Ray::new(origin + aside - w[0], ray.dir, 0.0);
                                rejected += usize::from(ball.missed_by(&away));
                            }
                        }
                    }
                }
            }
        }
        assert!(hits > 1000, "{hits}");
        assert!(rejected > 1000, "{rejected}");
    }
}
