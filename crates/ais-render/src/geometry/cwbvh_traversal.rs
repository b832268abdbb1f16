//! obvhs's compressed wide BVH with its triangles in lanes: traversal visits the nodes as
//! obvhs does, and tests the primitives a node hands over all together, the triangles eight
//! at a time ([`TriangleLanes`]) and the rest one by one through the caller. A ground kept
//! out of the BVH ([`Ground`]) is tested first, as one more group.

use super::ground::Ground;
use super::outer_box::OuterBox;
use super::primitive::Packed;
use super::ray::Ray;
use super::shaft::Shaft;
use super::triangle_lanes::TriangleLanes;
use super::Closest;
use glam::{UVec2, Vec3A};
use obvhs::cwbvh::{node::CwBvhNode, CwBvh, Traversal};

/// obvhs's traversal loop over the nodes of `$laned` (a [`LanedBvh`]) for `$ray` (obvhs's
/// ray), each node's children tested by [`children_hit`]; `$primitives` runs for each group
/// of primitives a node hands over, with the traversal's state in `$state`.
macro_rules! walk {
    ($laned:expr, $ray:expr, $state:ident, $primitives:block) => {{
        let mut $state = $laned.bvh.new_traversal($ray.direction);
        let mut node;
        obvhs::traverse!(
            $laned.bvh,
            node,
            $state,
            children_hit(node, &$ray, $state.oct_inv4),
            $primitives
        );
    }};
}

/// The most nodes a shaft's traversal holds to visit (eight children per level, so enough
/// for a BVH deeper than obvhs allows).
const SHAFT_STACK: usize = 256;

/// A CWBVH and its primitives' triangles in lanes, and a ground kept out of it.
pub(super) struct LanedBvh {
    bvh: CwBvh,
    lanes: TriangleLanes,
    /// The box around the BVH's primitives, which a ray that passes it by need not
    /// traverse.
    outer: OuterBox,
    /// Boxed: it is larger than the other accelerators.
    ground: Option<Box<Ground>>,
}

impl LanedBvh {
    /// `bvh` over `packed`, the primitives in the BVH's order, then those of `ground`.
    pub(super) fn new(bvh: CwBvh, packed: &[Packed], ground: Option<Ground>) -> Self {
        LanedBvh {
            lanes: TriangleLanes::new(packed),
            // The BVH's own box is the union of its primitives' boxes.
            outer: OuterBox::around(&bvh.total_aabb),
            bvh,
            ground: ground.map(Box::new),
        }
    }

    /// The ground's primitives that `ray` may meet, as a BVH node hands them over (none
    /// when there is no ground, or the ray leaves it).
    #[inline(always)]
    fn ground_group(&self, ray: &Ray) -> Option<(u32, u32)> {
        let ground = self.ground.as_ref()?;
        ground.may_meet(ray).then(|| ground.group())
    }

    /// Whether `ray` passes by the box around the BVH's primitives (it may still meet the
    /// ground).
    #[inline(always)]
    pub(super) fn passes_box(&self, ray: &Ray) -> bool {
        self.outer.passed_by(ray, ray.t_max)
    }

    /// Whether `ray` may meet the ground (not when there is none).
    #[inline(always)]
    pub(super) fn may_meet_ground(&self, ray: &Ray) -> bool {
        (self.ground.as_ref()).is_some_and(|ground| ground.may_meet(ray))
    }

    /// The primitive that blocks `ray` before its end, if any (the first found, not the
    /// nearest). `blocks(index, t_max)` answers for the primitives that are not triangles;
    /// `passes_box` is [`LanedBvh::passes_box`], where already known.
    pub(super) fn blocker(
        &self,
        ray: &Ray,
        mut blocks: impl FnMut(usize, f32) -> bool,
        passes_box: Option<bool>,
    ) -> Option<usize> {
        if let Some((base, group)) = self.ground_group(ray) {
            if let Some(index) = self.lanes.any_hit(base, group, ray, ray.t_max) {
                return Some(index);
            }
        }
        if passes_box.unwrap_or_else(|| self.passes_box(ray)) {
            return None;
        }
        let bvh_ray = ray.to_bvh(ray.t_max);
        let mut blocker = None;
        'traversal: {
            walk!(self, bvh_ray, state, {
                let (base, group) = take_group(&mut state);
                blocker = self.lanes.any_hit(base, group, ray, ray.t_max).or_else(|| {
                    indices(base, self.lanes.others(base, group))
                        .find(|&index| blocks(index, ray.t_max))
                });
                if blocker.is_some() {
                    break 'traversal;
                }
            });
        }
        blocker
    }

    /// Whether primitive `index` blocks `ray` before its end, or, for a triangle, any
    /// triangle of its run of eight (neighbours in the BVH's order, so mostly neighbours in
    /// space). `blocks(index, t_max)` answers for the primitives that are not triangles.
    pub(super) fn near_blocks(
        &self,
        index: usize,
        ray: &Ray,
        blocks: impl FnOnce(usize, f32) -> bool,
    ) -> bool {
        if self.is_triangle(index) {
            self.lanes.run_blocks(index, ray, ray.t_max)
        } else {
            blocks(index, ray.t_max)
        }
    }

    /// What names the test [`LanedBvh::near_blocks`] makes for primitive `index`: its run
    /// of eight for a triangle, the primitive itself otherwise (the high bit set).
    pub(super) fn near_test(&self, index: usize) -> u32 {
        if self.is_triangle(index) {
            (index / 8) as u32
        } else {
            index as u32 | 1 << 31
        }
    }

    /// Whether every primitive lies outside `shaft` or is passed over by `outside(index)`,
    /// which answers for each primitive in a node box that reaches into the shaft; stops
    /// at the first that does not.
    pub(super) fn clear_of(&self, shaft: &Shaft, mut outside: impl FnMut(usize) -> bool) -> bool {
        // The ground last: a shaft that is not clear is mostly found so in the BVH first.
        self.bvh_clear_of(shaft, &mut outside)
            && (self.ground.as_ref()).is_none_or(|ground| ground.clear_of(shaft, &mut outside))
    }

    /// [`LanedBvh::clear_of`] for the primitives in the BVH.
    fn bvh_clear_of(&self, shaft: &Shaft, outside: &mut impl FnMut(usize) -> bool) -> bool {
        let total = &self.bvh.total_aabb;
        let margin = shaft.margin_for_box(total);
        if self.bvh.nodes.is_empty() || shaft.excludes_box(total, margin) {
            return true;
        }
        let mut stack = [0u32; SHAFT_STACK];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = &self.bvh.nodes[stack[depth] as usize];
            for child in 0..8 {
                if node.is_child_empty(child) || shaft.excludes_box(&node.child_aabb(child), margin)
                {
                    continue;
                }
                if node.is_leaf(child) {
                    let (first, count) = node.child_primitives(child);
                    if !(first..first + count).all(|index| outside(index as usize)) {
                        return false;
                    }
                } else if depth == SHAFT_STACK {
                    // Deeper than any BVH obvhs validates: give no answer rather than a
                    // wrong one.
                    return false;
                } else {
                    stack[depth] = node.child_node_index(child);
                    depth += 1;
                }
            }
        }
        true
    }

    /// Whether primitive `index` is a triangle (in the lanes).
    fn is_triangle(&self, index: usize) -> bool {
        self.lanes.others(index as u32, 1) == 0
    }

    /// The nearest primitive along `ray` before its end. `hit(index, t_max)` answers for the
    /// primitives that are not triangles.
    pub(super) fn nearest(
        &self,
        ray: &Ray,
        mut hit: impl FnMut(usize, f32) -> Option<Closest>,
    ) -> Option<Closest> {
        let mut bvh_ray = ray.to_bvh(ray.t_max);
        let mut nearest = None;
        if let Some((base, group)) = self.ground_group(ray) {
            if let Some(lane_hit) = self.lanes.nearest(base, group, ray, bvh_ray.tmax) {
                bvh_ray.tmax = lane_hit.t;
                nearest = Some(Closest::of(lane_hit));
            }
        }
        if self.outer.passed_by(ray, bvh_ray.tmax) {
            return nearest;
        }
        walk!(self, bvh_ray, state, {
            let (base, group) = take_group(&mut state);
            if let Some(lane_hit) = self.lanes.nearest(base, group, ray, bvh_ray.tmax) {
                bvh_ray.tmax = lane_hit.t;
                nearest = Some(Closest::of(lane_hit));
            }
            for index in indices(base, self.lanes.others(base, group)) {
                if let Some(closest) = hit(index, bvh_ray.tmax) {
                    bvh_ray.tmax = closest.t();
                    nearest = Some(closest);
                }
            }
        });
        nearest
    }
}

/// The primitives of the node the traversal is at, all taken at once: the first index and
/// a mask of those to test (bit k: primitive `base + k`).
#[inline(always)]
fn take_group(state: &mut Traversal) -> (u32, u32) {
    let base = state.primitive_group.x;
    let group = state.primitive_group.y | 1 << (state.primitive_id - base);
    state.primitive_group = UVec2::new(base, 0);
    (base, group)
}

/// The primitive indices that `mask`'s bits stand for, from the highest down.
fn indices(base: u32, mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let k = 31 - mask.leading_zeros();
            mask &= !(1 << k);
            (base + k) as usize
        })
    })
}

/// Which of `node`'s eight children `ray` enters, as obvhs's traversal wants it: the bits of
/// the hit children (their primitives' bits in the low 24, an inner child's in the high 8).
///
/// obvhs's own test (`CwBvhNode::intersect_ray`) does the same arithmetic four children at a
/// time with SSE; here the eight children's boxes are tested in one pass that the compiler
/// vectorises (AVX), each comparison as the SSE instruction makes it (`max(a, b)` is
/// `a > b ? a : b`), so the same children are entered. One difference: a box is entered
/// from the ray's own `tmin` (0 for this renderer's rays), where obvhs starts every box at
/// 1e-4. Otherwise a blocker within 1e-4 of a ray's origin was found or not depending on
/// whether its leaf's box reached past 1e-4, and [`super::RecentBlockers`], which tests a
/// remembered triangle directly, disagreed with the traversal there.
#[inline(always)]
fn children_hit(node: &CwBvhNode, ray: &obvhs::ray::Ray, oct_inv4: u32) -> u32 {
    let scale = node.compute_extent() * ray.inv_direction;
    let shift = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    // Per axis, the near and far planes: the ray's sign picks which quantised bound is which.
    let near_far = |min: &[u8; 8], max: &[u8; 8], negative: bool| {
        if negative {
            (*max, *min)
        } else {
            (*min, *max)
        }
    };
    let (near_x, far_x) = near_far(&node.child_min_x, &node.child_max_x, ray.direction.x < 0.0);
    let (near_y, far_y) = near_far(&node.child_min_y, &node.child_max_y, ray.direction.y < 0.0);
    let (near_z, far_z) = near_far(&node.child_min_z, &node.child_max_z, ray.direction.z < 0.0);
    let mut entered = [false; 8];
    for child in 0..8 {
        let plane = |q: u8, axis: usize| q as f32 * scale[axis] + shift[axis];
        let t_near = sse_max(
            plane(near_x[child], 0),
            sse_max(plane(near_y[child], 1), plane(near_z[child], 2)),
        );
        let t_far = sse_min(
            plane(far_x[child], 0),
            sse_min(plane(far_y[child], 1), plane(far_z[child], 2)),
        );
        entered[child] = sse_max(t_near, ray.tmin) <= sse_min(t_far, ray.tmax);
    }
    let (child_bits, bit_index) = node.get_child_and_index_bits(oct_inv4);
    (0..8).fold(0, |mask, child| {
        let byte = |bits: u64| ((bits >> (child * 8)) & 0xff) as u32;
        mask | (byte(child_bits) * entered[child] as u32) << byte(bit_index)
    })
}

/// SSE's `maxps`: `b` unless `a > b` (so `b` when either is NaN).
#[inline(always)]
fn sse_max(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// SSE's `minps`: `b` unless `a < b` (so `b` when either is NaN).
#[inline(always)]
fn sse_min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitive::Triangle;
    use ais::rng::Pcg32;
    use glam::Vec3;
    use std::time::Duration;

    #[test]
    fn children_hit_enters_the_children_obvhs_enters() {
        let mut rng = Pcg32::new(8, 21);
        let mut point =
            |scale: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
        let triangles: Vec<Triangle> = (0..3000u32)
            .map(|index| {
                let v0 = point(20.0);
                Triangle {
                    vertices: [v0, v0 + point(1.0), v0 + point(1.0)],
                    mesh: 0,
                    index,
                }
            })
            .collect();
        let bvh = obvhs::cwbvh::builder::build_cwbvh(
            &triangles,
            obvhs::BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let mut entered = 0;
        for i in 0..2000 {
            let mut direction = (point(2.0) - Vec3::ONE).normalize();
            // Directions along an axis or a plane: infinite inverse components.
            if i % 4 == 1 {
                direction.x = 0.0;
            }
            if i % 8 == 2 {
                direction = Vec3::new(0.0, -1.0, 0.0);
            }
            let mut ray = Ray::new(point(22.0) - Vec3::ONE, direction.normalize());
            ray.t_max = if i % 2 == 0 {
                f32::INFINITY
            } else {
                10.0 * rng_free(i)
            };
            let mut bvh_ray = ray.to_bvh(ray.t_max);
            // obvhs starts every box at 1e-4 whatever the ray's tmin.
            bvh_ray.tmin = 1e-4;
            let state = bvh.new_traversal(bvh_ray.direction);
            for node in &bvh.nodes {
                let expected = node.intersect_ray(&bvh_ray, state.oct_inv4);
                assert_eq!(
                    children_hit(node, &bvh_ray, state.oct_inv4),
                    expected,
                    "ray {i}"
                );
                entered += (expected != 0) as usize;
            }
        }
        assert!(entered > 8_000, "the test must enter nodes: {entered}");
    }

    /// A distance in (0, 1] that varies with `i` (kept apart from the point generator).
    fn rng_free(i: usize) -> f32 {
        ((i * 37) % 100 + 1) as f32 / 100.0
    }
}
