//! A BVH over triangles alone (an emitting mesh's), traversed as the scene's is, with the
//! triangles tested eight at a time: the nearest crossing of a ray, and every crossing.

use super::cwbvh_traversal::LanedBvh;
use super::primitive::{Packed, Triangle};
use super::ray::Ray;
use super::Closest;
use glam::Vec2;
use std::time::Duration;

/// Triangles in a laned CWBVH, numbered in the BVH's order.
#[derive(Clone)]
pub struct TriangleBvh {
    laned: LanedBvh,
}

/// Where a ray crosses a triangle of a [`TriangleBvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleCrossing {
    /// The triangle's index in the BVH's order.
    pub index: usize,
    /// Distance along the ray.
    pub t: f32,
    /// Barycentrics (b1, b2).
    pub barycentrics: Vec2,
}

impl TriangleBvh {
    /// The BVH over `triangles` (at least one), and the order it numbers them in: its
    /// triangle `i` is `triangles[order[i]]`.
    pub fn new(triangles: &[Triangle]) -> (Self, Vec<u32>) {
        let bvh = obvhs::cwbvh::builder::build_cwbvh(
            triangles,
            obvhs::BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let order = bvh.primitive_indices.clone();
        let packed: Vec<Packed> = (order.iter())
            .map(|&i| {
                let [v0, v1, v2] = triangles[i as usize].vertices;
                Packed::Triangle([v0, v1 - v0, v2 - v0])
            })
            .collect();
        let laned = LanedBvh::new(bvh, &packed);
        (TriangleBvh { laned }, order)
    }

    /// The nearest triangle `ray` crosses before its end.
    pub fn nearest(&self, ray: &Ray) -> Option<TriangleCrossing> {
        match self.laned.nearest(ray, |_, _| None)? {
            Closest::Primitive {
                index,
                t,
                barycentrics,
            } => Some(TriangleCrossing {
                index,
                t,
                barycentrics,
            }),
            Closest::Instance(_) => unreachable!("a triangle BVH holds no instance"),
        }
    }

    /// Calls `crossing(index, t)` for every triangle `ray` crosses before its end.
    pub fn each_crossing(&self, ray: &Ray, crossing: impl FnMut(usize, f32)) {
        self.laned.each_triangle_crossing(ray, crossing);
    }
}

impl std::fmt::Debug for TriangleBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TriangleBvh").finish_non_exhaustive()
    }
}
