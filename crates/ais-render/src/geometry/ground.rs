//! A ground kept out of the BVH. A scene of objects on a large floor (a ground plane under
//! a sky) has most of its gather points on the floor, and most of their shadow rays leave
//! it upward. Inside the BVH, the floor's box spans the scene: every such ray starts
//! inside it (the CWBVH stores child boxes in 8 bits relative to their node, rounded
//! outward, so even a flat box has a thickness) and tests the floor's own triangles, and
//! the BVH's root box, stretched over the floor, holds every ray's origin. Kept apart, the
//! floor is skipped by one plane test for a ray that leaves it, and the BVH is left tight
//! around the objects, which most of those rays pass by.

use super::primitive::{Packed, Primitive};
use super::ray::Ray;
use super::shaft::Shaft;
use super::slab::Slab;
use glam::{DVec3, Vec3};
use obvhs::aabb::Aabb;

/// The most triangles a ground holds: one run of the triangle lanes.
const MOST_TRIANGLES: usize = 8;

/// The least share of all the triangles' area a ground holds.
const LEAST_SHARE: f64 = 0.5;

/// How far, as a fraction of a triangle's largest coordinate, another triangle's corners may
/// lie from its plane and still count as lying in it: the rounding of a modelled floor's
/// corners to f32, not a bend a ray could slip through unseen by the slab (the slab holds
/// every corner exactly).
const FLATNESS: f64 = 1.0 / 1_048_576.0;

/// Which of `primitives` (by index) to keep apart as the ground: the largest flat part of
/// the eight largest triangles, if it holds at least half of all the triangles' area, and
/// if something else is left for the BVH. None otherwise.
pub(super) fn choose(primitives: &[Primitive]) -> Vec<usize> {
    let area = |triangle: &[Vec3; 3]| triangle[1].cross(triangle[2]).length() as f64;
    let mut triangles: Vec<(usize, [Vec3; 3])> = primitives
        .iter()
        .enumerate()
        .filter_map(|(index, primitive)| match Packed::new(primitive) {
            Packed::Triangle(triangle) => Some((index, triangle)),
            _ => None,
        })
        .collect();
    let total: f64 = triangles.iter().map(|(_, triangle)| area(triangle)).sum();
    triangles.sort_by(|a, b| area(&b.1).total_cmp(&area(&a.1)));
    triangles.truncate(MOST_TRIANGLES);
    let largest: Vec<[Vec3; 3]> = triangles.iter().map(|&(_, triangle)| triangle).collect();
    let part = largest_flat_part(&largest);
    let chosen: Vec<(usize, [Vec3; 3])> = (0..triangles.len())
        .filter(|&k| part & 1 << k != 0)
        .map(|k| triangles[k])
        .collect();
    let held: f64 = chosen.iter().map(|(_, triangle)| area(triangle)).sum();
    match held >= LEAST_SHARE * total && held > 0.0 && chosen.len() < primitives.len() {
        true => chosen.into_iter().map(|(index, _)| index).collect(),
        false => Vec::new(),
    }
}

/// The largest flat part of `triangles` (the most area in one plane, among the planes of
/// the triangles themselves), as a bit for each triangle in it; triangles without an area
/// belong to no part. At most 32 triangles.
fn largest_flat_part(triangles: &[[Vec3; 3]]) -> u32 {
    assert!(triangles.len() <= 32, "a part is named by 32 bits");
    let normals: Vec<DVec3> = triangles
        .iter()
        .map(|&[_, e1, e2]| e1.as_dvec3().cross(e2.as_dvec3()))
        .collect();
    let in_plane_of = |i: usize| -> u32 {
        let Some(normal) = normals[i].try_normalize() else {
            return 0;
        };
        let [v0, e1, e2] = triangles[i];
        let magnitude = v0.abs().max((v0 + e1).abs()).max((v0 + e2).abs());
        let tolerance = FLATNESS * f64::from(magnitude.max_element());
        let height = |corner: DVec3| normal.dot(corner - v0.as_dvec3()).abs();
        (0..triangles.len())
            .filter(|&j| {
                let [w0, f1, f2] = triangles[j].map(Vec3::as_dvec3);
                normals[j].length_squared() > 0.0
                    && [w0, w0 + f1, w0 + f2]
                        .into_iter()
                        .all(|c| height(c) <= tolerance)
            })
            .fold(0, |bits, j| bits | 1 << j)
    };
    let area = |bits: u32| {
        (0..normals.len())
            .filter(|&j| bits & 1 << j != 0)
            .map(|j| normals[j].length())
            .sum::<f64>()
    };
    (0..triangles.len())
        .map(in_plane_of)
        .max_by(|&a, &b| area(a).total_cmp(&area(b)))
        .unwrap_or(0)
}

/// The ground: the packed primitives `first..first + count`, after the BVH's own, all
/// triangles, and a slab that holds them.
#[derive(Debug)]
pub(super) struct Ground {
    first: u32,
    count: u32,
    slab: Slab,
    bounds: Aabb,
}

impl Ground {
    /// The ground of `packed`'s primitives from `first` on (triangles, at most eight).
    pub(super) fn new(packed: &[Packed], first: usize) -> Self {
        let triangles: Vec<[Vec3; 3]> = packed[first..]
            .iter()
            .map(|primitive| match primitive {
                Packed::Triangle(triangle) => *triangle,
                _ => unreachable!("a ground holds only triangles"),
            })
            .collect();
        assert!(
            triangles.len() <= MOST_TRIANGLES,
            "a ground fits in one run"
        );
        let corners = triangles
            .iter()
            .flat_map(|&[v0, e1, e2]| [v0, v0 + e1, v0 + e2]);
        let bounds = corners.fold(Aabb::empty(), |bounds, corner| {
            bounds.union(&Aabb::from_point(corner.into()))
        });
        Ground {
            first: first as u32,
            count: triangles.len() as u32,
            slab: Slab::around(&triangles),
            bounds,
        }
    }

    /// Its primitives as a BVH node hands them over: the first index, and a bit for each.
    #[inline]
    pub(super) fn group(&self) -> (u32, u32) {
        (self.first, (1 << self.count) - 1)
    }

    /// Whether its box lies outside `shaft`, or each of its primitives is passed over by
    /// `outside(index)` (as [`super::Geometry::shaft_is_clear`] asks).
    pub(super) fn clear_of(&self, shaft: &Shaft, outside: impl FnMut(usize) -> bool) -> bool {
        let indices = self.first as usize..(self.first + self.count) as usize;
        shaft.excludes_box(&self.bounds, shaft.margin_for_box(&self.bounds))
            || indices.into_iter().all(outside)
    }

    /// Whether `ray` may meet the ground: not if it stays clear of the ground's slab.
    #[inline(always)]
    pub(super) fn may_meet(&self, ray: &Ray) -> bool {
        !self.slab.excludes(ray)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitive::{Sphere, Triangle};

    fn triangle(vertices: [Vec3; 3]) -> Primitive {
        Primitive::Triangle(Triangle {
            vertices,
            mesh: 0,
            index: 0,
        })
    }

    /// A square floor of side `size` at height `y`, as two triangles.
    fn floor(size: f32, y: f32) -> [Primitive; 2] {
        let [a, b, c, d] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, z)| Vec3::new(x * size, y, z * size));
        [triangle([a, b, c]), triangle([a, c, d])]
    }

    /// A box's twelve triangles, of side `size` around `centre`.
    fn cube(centre: Vec3, size: f32) -> Vec<Primitive> {
        let corner = |i: usize| {
            let bit = |k: usize| if i & 1 << k != 0 { 0.5 } else { -0.5 };
            centre + Vec3::new(bit(0), bit(1), bit(2)) * size
        };
        let faces = [
            [0, 1, 3, 2],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 3, 7, 5],
        ];
        faces
            .iter()
            .flat_map(|&[a, b, c, d]| {
                [
                    triangle([corner(a), corner(b), corner(c)]),
                    triangle([corner(a), corner(c), corner(d)]),
                ]
            })
            .collect()
    }

    #[test]
    fn a_floor_with_most_of_the_area_is_the_ground() {
        let mut primitives = cube(Vec3::new(5.0, 1.5, 5.0), 2.0);
        primitives.extend(floor(10.0, 0.0));
        primitives.push(Primitive::Sphere(Sphere {
            center: Vec3::splat(3.0),
            radius: 1.0,
        }));
        let mut chosen = choose(&primitives);
        chosen.sort();
        assert_eq!(chosen, vec![12, 13]);
    }

    #[test]
    fn no_ground_without_a_floor_of_half_the_area_or_without_anything_else() {
        // The floor holds less than half: four boxes of side 3 have 216 of 316.
        let mut primitives: Vec<Primitive> = (0..4)
            .flat_map(|k| cube(Vec3::new(2.0 + 2.0 * k as f32, 1.5, 5.0), 3.0))
            .collect();
        primitives.extend(floor(10.0, 0.0));
        assert_eq!(choose(&primitives), Vec::<usize>::new());
        // A floor alone: nothing would be left for the BVH.
        assert_eq!(choose(&floor(10.0, 0.0)), Vec::<usize>::new());
        // Large triangles that are not flat together: a tent of two steep halves.
        let tent = [
            triangle([
                Vec3::ZERO,
                Vec3::new(10.0, 0.0, 0.0),
                Vec3::new(5.0, 8.0, 5.0),
            ]),
            triangle([
                Vec3::new(0.0, 0.0, 10.0),
                Vec3::new(10.0, 0.0, 10.0),
                Vec3::new(5.0, 8.0, 5.0),
            ]),
        ];
        let mut primitives = tent.to_vec();
        primitives.extend(cube(Vec3::splat(1.0), 0.5));
        assert_eq!(choose(&primitives).len(), 0);
    }
}
