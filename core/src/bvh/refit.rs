//! Refitting: new bounds for the same primitives put into a built tree without rebuilding it
//! (each leaf keeps its primitives; every box is recomputed bottom-up), and the tree's
//! normalised SAH cost, which says when a refitted tree has degraded enough to rebuild.
//!
//! Nodes are stored depth first with children after their parent, so one pass in reverse index
//! order meets every child before its parent, and the subtree of each of the root's inner
//! children is a contiguous range of nodes: those ranges are refitted in parallel.
//!
//! The cost of a tree `T` is `C(T) = (Σ nodes A(node) + Σ leaf lanes A(lane) · count) / A(root)`
//! with `A` the half surface area: one unit per wide-node visit, one per primitive test, over
//! the probability that a ray meeting the root meets the box (a node's box is its lane in the
//! parent; the root's is the union of its lanes). Dividing by the root's area makes a cloud that
//! only moves or grows uniformly keep its cost, and one whose primitives swap places (so that
//! boxes grow into each other) lose it.

use super::build::PARALLEL_CUTOFF;
use super::wide::{Wide, EMPTY};
use super::{count_of, offset_of, Bvh, LANES};
use crate::math::Aabb;
use std::ops::Range;

/// A refitted tree whose cost exceeds this multiple of its cost when built should be rebuilt.
/// Ray cost is close to proportional to the SAH cost, so 1.3 keeps a refitted tree at 1/1.3 ≈
/// 77 % or more of a fresh tree's throughput: a margin, for the model's error, over the 70 %
/// that in-situ rendering asks of a refitted tree (issue 20).
pub const REBUILD_RATIO: f32 = 1.3;

/// Trees of fewer nodes than this (about `PARALLEL_CUTOFF` primitives: there are 4 to 7
/// primitives per wide node) are refitted on the calling thread.
const PARALLEL_NODES: usize = PARALLEL_CUTOFF / 5;

impl Bvh {
    /// Puts new primitive bounds into the tree: `bound(i)` is the box of the i-th primitive in
    /// leaf order (the primitive `order[i]` of the build), leaves keep their primitives, and
    /// every box is recomputed from them, so traversal stays exact for the new bounds. Returns
    /// the refitted tree's normalised SAH cost ([`Bvh::sah_cost`], equal to it bit for bit,
    /// summed in the same pass). The result is the same on any number of threads.
    pub fn refit(&mut self, bound: impl Fn(usize) -> Aabb + Sync) -> f32 {
        use rayon::prelude::*;
        if self.nodes.is_empty() {
            return 0.0;
        }
        let parts = self.subtrees();
        let mut sums = None;
        if self.nodes.len() >= PARALLEL_NODES && parts.len() > 1 {
            let mut slices = Vec::with_capacity(parts.len());
            let mut rest = &mut self.nodes[1..];
            for part in &parts {
                let (these, after) = std::mem::take(&mut rest).split_at_mut(part.len());
                slices.push((part.start, these));
                rest = after;
            }
            // A part whose links leave it (only possible in a tree read from cached words, which
            // need not be a tree) is refused here and refitted serially below.
            sums = slices
                .into_par_iter()
                .map(|(base, nodes)| refit_nodes(nodes, base, 0..nodes.len(), &bound))
                .collect::<Option<Vec<f64>>>();
        }
        let sums = sums.unwrap_or_else(|| {
            // The last part first: links only point forward, so every child is refitted before
            // its parent whatever the part it lies in.
            let mut sums = vec![0.0; parts.len()];
            for (k, part) in parts.iter().enumerate().rev() {
                // Links stay within the array (`collapse` and `from_words` make them so).
                sums[k] = refit_nodes(&mut self.nodes, 0, part.clone(), &bound).unwrap_or(0.0);
            }
            sums
        });
        let root = refit_nodes(&mut self.nodes, 0, 0..1, &bound).unwrap_or(0.0);
        self.total_cost(root, &sums)
    }

    /// The normalised SAH cost of the tree as it is (see the module's documentation); 0 for
    /// an empty tree or one whose boxes have no area.
    pub fn sah_cost(&self) -> f32 {
        if self.nodes.is_empty() {
            return 0.0;
        }
        let sums: Vec<f64> = self
            .subtrees()
            .into_iter()
            .map(|part| sum_costs(&self.nodes[part]))
            .collect();
        self.total_cost(node_cost(&self.nodes[0]), &sums)
    }

    /// The ranges of nodes after the root, split where each of the root's inner children starts
    /// (each range is that child's subtree in a built tree).
    fn subtrees(&self) -> Vec<Range<usize>> {
        let n = self.nodes.len();
        let root = &self.nodes[0];
        let mut starts: Vec<usize> = (0..LANES)
            .map(|l| root.link[l])
            .filter(|&link| link != EMPTY && count_of(link) == 0)
            .map(offset_of)
            .filter(|&i| i > 1 && i < n)
            .collect();
        starts.push(1);
        starts.sort_unstable();
        starts.dedup();
        starts.push(n);
        starts
            .windows(2)
            .filter(|w| w[0] < w[1])
            .map(|w| w[0]..w[1])
            .collect()
    }

    /// The cost from the root node's own lanes and the sums of the parts, added in one order
    /// by both [`Bvh::refit`] and [`Bvh::sah_cost`].
    fn total_cost(&self, root: f64, parts: &[f64]) -> f32 {
        let area = self.nodes[0].bounds().half_area();
        let mut total = f64::from(area) + root;
        for s in parts {
            total += s;
        }
        (total / f64::from(area.max(f32::MIN_POSITIVE))) as f32
    }
}

/// Refits the nodes `range` of `nodes` (which holds the tree's nodes `base..`) in reverse
/// order and returns the sum of their costs; `None` if a link leads outside `nodes`.
fn refit_nodes(
    nodes: &mut [Wide],
    base: usize,
    range: Range<usize>,
    bound: &impl Fn(usize) -> Aabb,
) -> Option<f64> {
    let mut sum = 0.0;
    for j in range.rev() {
        for l in 0..LANES {
            let link = nodes[j].link[l];
            if link == EMPTY {
                // Stays inverted: the traversal relies on no ray entering an empty lane.
                continue;
            }
            let (offset, count) = (offset_of(link), count_of(link));
            let b = if count > 0 {
                (offset..offset + count).fold(Aabb::EMPTY, |acc, i| acc.union(bound(i)))
            } else {
                nodes.get(offset.checked_sub(base)?)?.bounds()
            };
            nodes[j].set_box(l, &b);
        }
        sum += node_cost(&nodes[j]);
    }
    Some(sum)
}

/// The sum of the nodes' costs, in the order [`refit_nodes`] adds them.
fn sum_costs(nodes: &[Wide]) -> f64 {
    nodes.iter().rev().fold(0.0, |sum, n| sum + node_cost(n))
}

/// What a node's lanes add to the cost: the area of each inner child (one visit) and of each
/// leaf times its primitives (one test each).
fn node_cost(node: &Wide) -> f64 {
    let mut cost = 0.0;
    for l in 0..LANES {
        let link = node.link[l];
        if link != EMPTY {
            let tests = count_of(link).max(1) as f64;
            cost += f64::from(node.lane_box(l).half_area()) * tests;
        }
    }
    cost
}

#[cfg(test)]
mod tests {
    use super::super::tests::boxes;
    use super::*;
    use crate::math::Vec3A;

    /// A deterministic pseudo-random source in [0, 1).
    fn rng(seed: u32) -> impl FnMut() -> f32 {
        let mut s = seed;
        move || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    fn words(bvh: &Bvh) -> Vec<u32> {
        let mut w = Vec::new();
        bvh.to_words(&mut |x| w.push(x));
        w
    }

    fn relative(a: f32, b: f32) -> f32 {
        (a - b).abs() / a.abs().max(b.abs())
    }

    /// Boxes on a grid of quarters (exact in f32, and after adding whole numbers).
    fn grid_boxes(n: usize) -> Vec<Aabb> {
        let mut r = rng(99);
        let mut q = |scale: f32| (r() * scale * 4.0).floor() / 4.0;
        (0..n)
            .map(|_| {
                let c = Vec3A::new(q(100.0), q(100.0), q(100.0));
                let h = Vec3A::new(q(1.0), q(1.0), q(1.0)) + 0.25;
                Aabb::new(c - h, c + h)
            })
            .collect()
    }

    #[test]
    fn refitting_the_same_bounds_changes_nothing() {
        for n in [1, 3, 9, 100, 10_000] {
            let b = boxes(n);
            let (mut bvh, order) = Bvh::build(&b);
            let before = words(&bvh);
            let cost = bvh.sah_cost();
            let refitted = bvh.refit(|i| b[order[i] as usize]);
            assert_eq!(words(&bvh), before, "{n} boxes");
            assert_eq!(refitted.to_bits(), cost.to_bits(), "{n} boxes");
            assert!(cost >= 1.0, "{n} boxes: cost {cost}");
        }
    }

    /// Every box moved by one vector: the refitted tree is the tree a fresh build makes of the
    /// moved boxes (the build depends only on differences, exact here), with the same cost.
    #[test]
    fn a_translated_refit_equals_a_fresh_build_of_the_translated_boxes() {
        let b = grid_boxes(20_000);
        let (mut bvh, order) = Bvh::build(&b);
        assert!(
            bvh.nodes.len() >= PARALLEL_NODES,
            "the parallel refit is tested"
        );
        let built_cost = bvh.sah_cost();
        let shift = Vec3A::new(37.0, -12.0, 5.0);
        let moved: Vec<Aabb> = b
            .iter()
            .map(|x| Aabb::new(x.min + shift, x.max + shift))
            .collect();
        let cost = bvh.refit(|i| moved[order[i] as usize]);
        let (fresh, fresh_order) = Bvh::build(&moved);
        assert_eq!(fresh_order, order);
        assert_eq!(words(&bvh), words(&fresh));
        assert!(relative(cost, fresh.sah_cost()) <= 1e-5);
        assert!(
            relative(cost, built_cost) <= 1e-5,
            "{cost} against {built_cost}"
        );
    }

    /// The exact closest hit of a ray with a box, at t ≥ 0.
    fn hit_box(b: &Aabb, o: Vec3A, d: Vec3A) -> Option<f32> {
        let inv = d.recip();
        let t0 = (b.min - o) * inv;
        let t1 = (b.max - o) * inv;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element();
        (near <= far).then_some(near)
    }

    /// Random rays against randomly moved and resized boxes: the refitted tree finds the same
    /// closest hit and the same any-hit answers as testing every box. The tree left as built
    /// misses some (so the test sees a lane that is not refitted).
    #[test]
    fn a_refitted_tree_finds_what_brute_force_finds() {
        let b = boxes(2000);
        let (mut bvh, order) = Bvh::build(&b);
        let stale = bvh.clone();
        let mut r = rng(5);
        let moved: Vec<Aabb> = b
            .iter()
            .map(|x| {
                let c = x.centroid() + (Vec3A::new(r(), r(), r()) - 0.5) * 16.0;
                let h = Vec3A::new(r(), r(), r()) * 1.5;
                Aabb::new(c - h, c + h)
            })
            .collect();
        bvh.refit(|i| moved[order[i] as usize]);
        let mut stale_wrong = 0;
        for k in 0..10_000 {
            let o = Vec3A::new(r(), r(), r()) * 140.0 - 20.0;
            let d = (Vec3A::new(r(), r(), r()) - 0.5).normalize_or(Vec3A::X);
            let t_max = if k % 2 == 0 {
                f32::INFINITY
            } else {
                r() * 60.0
            };
            let brute = moved
                .iter()
                .filter_map(|x| hit_box(x, o, d))
                .fold(f32::INFINITY, f32::min);
            let brute_any = moved
                .iter()
                .any(|x| hit_box(x, o, d).is_some_and(|h| h <= t_max));
            let closest = |tree: &Bvh| {
                tree.intersect(o, d, f32::INFINITY, |p, t| {
                    hit_box(&moved[order[p] as usize], o, d).filter(|&h| h < t)
                })
            };
            let any = |tree: &Bvh| {
                tree.any(o, d, t_max, |p| {
                    hit_box(&moved[order[p] as usize], o, d).is_some_and(|h| h <= t_max)
                })
            };
            assert_eq!(closest(&bvh), brute, "ray {k}: closest hit");
            assert_eq!(any(&bvh), brute_any, "ray {k}: any hit");
            if closest(&stale) != brute || any(&stale) != brute_any {
                stale_wrong += 1;
            }
        }
        assert!(
            stale_wrong > 100,
            "the unrefitted tree erred {stale_wrong} times"
        );
    }

    /// Positions shuffled among the primitives (the worst case for a refit) cost more than
    /// `REBUILD_RATIO` times the build; the whole cloud scaled by 2 costs the same.
    #[test]
    fn shuffled_positions_degrade_the_tree_and_a_uniform_expansion_does_not() {
        let b = boxes(20_000);
        let (bvh, order) = Bvh::build(&b);
        let built = bvh.sah_cost();
        let mut perm: Vec<usize> = (0..b.len()).collect();
        let mut r = rng(11);
        for i in (1..perm.len()).rev() {
            let j = ((r() * (i + 1) as f32) as usize).min(i);
            perm.swap(i, j);
        }
        let shuffled = bvh.clone().refit(|i| b[perm[order[i] as usize]]);
        assert!(
            shuffled > REBUILD_RATIO * built,
            "shuffled {shuffled}, built {built}"
        );
        let doubled = bvh.clone().refit(|i| {
            Aabb::new(
                b[order[i] as usize].min * 2.0,
                b[order[i] as usize].max * 2.0,
            )
        });
        assert!(
            relative(doubled, built) <= 1e-5,
            "doubled {doubled}, built {built}"
        );
        // Spread apart with the boxes kept their size: cheaper, if anything.
        let spread = bvh.clone().refit(|i| {
            let x = b[order[i] as usize];
            let c = x.centroid();
            Aabb::new(x.min + c, x.max + c)
        });
        assert!(
            spread <= REBUILD_RATIO * built,
            "spread {spread}, built {built}"
        );
    }

    #[test]
    fn empty_single_leaf_and_point_trees_refit_to_finite_costs() {
        let (mut empty, _) = Bvh::build(&[]);
        assert_eq!(empty.refit(|_| unreachable!("no primitives")), 0.0);
        assert_eq!(empty.sah_cost(), 0.0);
        assert!(!empty.any(Vec3A::ZERO, Vec3A::X, f32::INFINITY, |_| true));

        // One leaf of two, in two lanes of one: the root visit and a test per box its ray
        // enters.
        let b = boxes(2);
        let (mut one, order) = Bvh::build(&b);
        assert_eq!(one.leaf_sizes().collect::<Vec<_>>(), [1, 1]);
        let far = Vec3A::splat(1000.0);
        let cost = one.refit(|i| {
            Aabb::new(
                b[order[i] as usize].min + far,
                b[order[i] as usize].max + far,
            )
        });
        let want = 1.0 + (b[0].half_area() + b[1].half_area()) / b[0].union(b[1]).half_area();
        assert!((cost - want).abs() < 1e-4, "cost {cost}, want {want}");
        let o = b[0].centroid() + far - Vec3A::new(0.0, 0.0, 10.0);
        assert!(one.any(o, Vec3A::Z, f32::INFINITY, |_| true));
        assert!(!one.any(o - far, Vec3A::Z, f32::INFINITY, |_| true));

        // Every box a point: no area anywhere, cost 0, never NaN; then spread out again.
        let p = Vec3A::new(1.0, 2.0, 3.0);
        let points = vec![Aabb::new(p, p); 5000];
        let (mut tree, order) = Bvh::build(&points);
        assert_eq!(tree.sah_cost(), 0.0);
        assert_eq!(tree.refit(|_| Aabb::new(-p, -p)), 0.0);
        assert_eq!(tree.bounds(), Aabb::new(-p, -p));
        let spread = boxes(5000);
        let cost = tree.refit(|i| spread[order[i] as usize]);
        assert!(cost.is_finite() && cost > 1.0, "cost {cost}");
        let mut spread_tree = Bvh::build(&boxes(5000)).0;
        let points_cost = spread_tree.refit(|_| Aabb::new(p, p));
        assert_eq!(points_cost, 0.0);
    }

    #[test]
    fn one_and_two_threads_refit_alike() {
        let b = boxes(50_000);
        let (bvh, order) = Bvh::build(&b);
        assert!(bvh.nodes.len() >= PARALLEL_NODES && bvh.subtrees().len() > 1);
        let mut r = rng(3);
        let moved: Vec<Aabb> = b
            .iter()
            .map(|x| {
                let d = (Vec3A::new(r(), r(), r()) - 0.5) * 4.0;
                Aabb::new(x.min + d, x.max + d)
            })
            .collect();
        let refit_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut tree = bvh.clone();
            let cost = pool.install(|| tree.refit(|i| moved[order[i] as usize]));
            (words(&tree), cost.to_bits(), tree.sah_cost().to_bits())
        };
        let (one, two) = (refit_on(1), refit_on(2));
        assert_eq!(one, two);
        assert_eq!(one.1, one.2, "refit returns sah_cost's value");
        assert_ne!(one.0, words(&bvh), "the boxes moved");
    }

    /// A tree read back from cached words refits as the tree it was written from.
    #[test]
    fn a_tree_from_words_refits_like_the_original() {
        let b = boxes(8000);
        let (mut bvh, order) = Bvh::build(&b);
        let mut cached = Bvh::from_words(&words(&bvh), b.len()).unwrap();
        let moved = |i: usize| {
            let x = b[order[i] as usize];
            Aabb::new(x.min * 1.5, x.max * 1.5 + 1.0)
        };
        assert_eq!(bvh.refit(moved).to_bits(), cached.refit(moved).to_bits());
        assert_eq!(words(&bvh), words(&cached));
    }
}
