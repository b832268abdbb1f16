//! A slab that holds flat triangles: the space between two parallel planes. A ray that
//! starts outside it and points away from it, or ends before reaching it, hits none of
//! them, which lets a ray that leaves a ground skip the ground's triangles with a test of
//! one plane.

use super::ray::Ray;
use glam::{DVec3, Vec3};

/// How far a ray's origin must lie outside a slab before the slab is trusted to exclude the
/// ray, as a fraction of the sum of the terms of its height (`Σ |normal_i · (origin −
/// centre)_i|`): four times the rounding of that height in f32 (at most 4 units of 2⁻²⁴
/// of that sum), and well below the offset that pushes a ray off the surface it leaves
/// (2⁻¹⁶ of that surface point's largest coordinate).
const ORIGIN_MARGIN: f32 = 1.0 / 1_048_576.0;

/// The least cosine between a ray and the slab's normal for the ray to count as pointing
/// away: a ray that runs nearly along the slab is left to the triangle test, which decides
/// the grazing cases its own rounding makes.
const DIRECTION_MARGIN: f32 = 1e-6;

/// The points within `half_thickness` of the plane through `center` with normal `normal`
/// (heights measured in f32's `normal` exactly); an infinitely thick one holds everything
/// and excludes no ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Slab {
    center: Vec3,
    normal: Vec3,
    half_thickness: f32,
}

impl Default for Slab {
    /// The slab that excludes no ray.
    fn default() -> Self {
        Slab {
            center: Vec3::ZERO,
            normal: Vec3::Y,
            half_thickness: f32::INFINITY,
        }
    }
}

impl Slab {
    /// The thinnest slab, normal to the largest triangle's, that holds every triangle
    /// `(v0, e1, e2)` (corners `v0`, `v0 + e1`, `v0 + e2`); the one that excludes no ray if
    /// no triangle has an area.
    pub(crate) fn around(triangles: &[[Vec3; 3]]) -> Self {
        let widest = triangles
            .iter()
            .map(|&[_, e1, e2]| e1.as_dvec3().cross(e2.as_dvec3()))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
        let Some(normal) = widest.and_then(DVec3::try_normalize) else {
            return Slab::default();
        };
        // Corners in f64 are exact sums of f32s, and heights are measured along the normal
        // and from the centre as they are stored, so the slab holds the triangles exactly.
        let corners = || {
            triangles.iter().flat_map(|&[v0, e1, e2]| {
                let v0 = v0.as_dvec3();
                [v0, v0 + e1.as_dvec3(), v0 + e2.as_dvec3()]
            })
        };
        let low = corners().fold(DVec3::INFINITY, DVec3::min);
        let high = corners().fold(DVec3::NEG_INFINITY, DVec3::max);
        let (center, normal) = ((0.5 * (low + high)).as_vec3(), normal.as_vec3());
        let height = |corner: DVec3| normal.as_dvec3().dot(corner - center.as_dvec3()).abs();
        let thickest = corners().map(height).fold(0.0, f64::max);
        Slab {
            center,
            normal,
            // Widened by the f64 arithmetic's own rounding, then rounded up to an f32.
            half_thickness: ((thickest * (1.0 + 1e-9) + 1e-30) as f32).next_up(),
        }
    }

    /// Whether `ray` stays clear of the slab: it starts outside the slab, and points away
    /// from it or ends before it reaches it.
    #[inline(always)]
    pub(crate) fn excludes(&self, ray: &Ray) -> bool {
        let relative = ray.origin - self.center;
        let height = self.normal.dot(relative);
        let clearance = self.half_thickness + ORIGIN_MARGIN * self.normal.abs().dot(relative.abs());
        let along = self.normal.dot(ray.direction);
        let leaves = (height > clearance && along > DIRECTION_MARGIN)
            | (height < -clearance && along < -DIRECTION_MARGIN);
        // Both ends on the same side (an unbounded ray's end is infinite or NaN, and never
        // counts): the heights along a segment lie between those of its ends.
        let rise = along * ray.t_max;
        let end = height + rise;
        let end_clearance = clearance + ORIGIN_MARGIN * rise.abs();
        let stays = (height > clearance && end > end_clearance)
            | (height < -clearance && end < -end_clearance);
        leaves | stays
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitive::Packed;
    use crate::geometry::ray::offset_origin;
    use ais::rng::Pcg32;

    fn unit(rng: &mut Pcg32) -> Vec3 {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        v.normalize_or(Vec3::Z)
    }

    /// Two triangles of a square of side `size` in the plane through `center` with
    /// normal `normal`.
    fn square(center: Vec3, normal: Vec3, size: f32) -> [[Vec3; 3]; 2] {
        let u = normal.any_orthonormal_vector() * size;
        let v = normal.cross(u);
        let corner = center - 0.5 * (u + v);
        [[corner, u, v], [corner + u + v, -u, -v]]
    }

    #[test]
    fn a_slab_holds_every_corner_of_its_triangles() {
        let mut rng = Pcg32::new(4, 1);
        for _ in 0..200 {
            let triangles: Vec<[Vec3; 3]> = (0..5)
                .map(|_| [unit(&mut rng) * 30.0, unit(&mut rng), unit(&mut rng) * 3.0])
                .collect();
            let slab = Slab::around(&triangles);
            for [v0, e1, e2] in triangles {
                let v0 = v0.as_dvec3();
                for corner in [v0, v0 + e1.as_dvec3(), v0 + e2.as_dvec3()] {
                    let height = slab.normal.as_dvec3().dot(corner - slab.center.as_dvec3());
                    assert!(height.abs() <= f64::from(slab.half_thickness), "{height}");
                }
            }
        }
        assert_eq!(Slab::around(&[]), Slab::default());
        assert_eq!(
            Slab::around(&[[Vec3::ONE, Vec3::X, Vec3::X]]),
            Slab::default()
        );
    }

    /// Rays near a square floor, some grazing it, some from points near its rim: half of
    /// them leave the floor (offset as the renderer offsets them), half start a random
    /// distance (up to three offsets) to either side of it. Whenever the slab excludes a
    /// ray, the triangle test finds no hit; every ray that leaves the floor at more than a
    /// grazing angle, from a point not far from the floor's centre, is excluded.
    #[test]
    fn a_ray_near_a_floor_is_excluded_only_where_it_misses_the_floor() {
        let mut rng = Pcg32::new(8, 3);
        let (mut excluded, mut leaving, mut hits) = (0, 0, 0);
        for i in 0..200_000 {
            let normal = unit(&mut rng);
            let center = unit(&mut rng) * (1.0 + 40.0 * rng.next_f32());
            let size = 0.01 + 50.0 * rng.next_f32();
            let triangles = square(center, normal, size);
            let slab = Slab::around(&triangles);
            let [b1, b2] = [rng.next_f32(), rng.next_f32()];
            let [v0, e1, e2] = triangles[0];
            let point = v0 + 1.1 * b1 * e1 + 1.1 * b2 * e2;
            let mut direction = unit(&mut rng);
            if i % 3 == 0 {
                // Grazing: within 2e-6 of the floor's plane, either way.
                direction = (direction - normal * direction.dot(normal)).normalize_or(normal)
                    + normal * (rng.next_f32() - 0.5) * 4e-6;
                direction = direction.normalize();
            }
            let origin = if i % 2 == 0 {
                offset_origin(point, normal, direction)
            } else {
                let offset = offset_origin(point, normal, normal) - point;
                point + offset * (6.0 * rng.next_f32() - 3.0)
            };
            let mut ray = Ray::new(origin, direction);
            if i % 5 == 1 {
                // Ending anywhere up to twice as far as the plane, along the ray.
                let to_plane = ((point - origin).dot(normal) / direction.dot(normal)).abs();
                ray.t_max = 2.0 * rng.next_f32() * to_plane.min(1e3);
            }
            let hit = triangles
                .iter()
                .any(|&t| Packed::Triangle(t).intersect(&ray, ray.t_max).is_some());
            hits += hit as usize;
            if slab.excludes(&ray) {
                assert!(!hit, "ray {i}: {ray:?} excluded but hits");
                excluded += 1;
            }
            let near_centre = (point - center).length() < 4.0 * point.abs().max_element().max(1.0);
            if i % 2 == 0 && direction.dot(normal).abs() > 1e-5 && near_centre {
                leaving += 1;
                assert!(slab.excludes(&ray), "ray {i} not excluded");
            }
        }
        assert!(
            excluded > 60_000 && leaving > 40_000,
            "{excluded} {leaving}"
        );
        assert!(hits > 20_000, "the rays must hit the floor too: {hits}");
    }
}
