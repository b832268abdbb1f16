//! The box around everything a BVH holds, tried before its traversal. Under an open sky
//! most shadow rays pass by every object, and a traversal pays for setting up and for the
//! root's eight children (decoded from 8-bit offsets) to learn that; one exact box test
//! learns it for less. Rays that start among the objects (a room's) always enter the box,
//! which six comparisons of their origin show. Where a gather's rays mostly pass the box
//! by, it is tried before the blockers its earlier rays met, too
//! ([`super::RecentBlockers::tries_box_first`]): a ray that passes everything by needs no
//! blocker's test.

use super::ray::Ray;
use glam::Vec3A;
use obvhs::aabb::Aabb;

/// The relative error of a product of three rounded f32 operations (γ₃ = 3u / (1 − 3u), u =
/// 2⁻²⁴): a box test's far distance, grown by 2γ₃, is never below the exact one
/// (Ize, "Robust BVH Ray Traversal", 2013).
const GAMMA_3: f32 = 3.0 * f32::EPSILON / 2.0 / (1.0 - 3.0 * f32::EPSILON / 2.0);

/// How much the box is grown, as a fraction of its size plus its largest coordinate: far
/// above the rounding of a primitive's own test (a few units of 2⁻²⁴ of its coordinates),
/// which may find a hit a hair outside the primitive's box.
const MARGIN: f32 = 1.0 / 65_536.0;

/// A box around every primitive of a BVH, grown for rounding, that a ray surely misses
/// everything inside of when it misses the box.
#[derive(Clone, Copy, Debug)]
pub(super) struct OuterBox {
    min: Vec3A,
    max: Vec3A,
}

impl OuterBox {
    /// The box `bounds`, grown by [`MARGIN`]; one that no ray passes by if `bounds` is
    /// empty or not finite.
    pub(super) fn around(bounds: &Aabb) -> Self {
        let (min, max) = (bounds.min, bounds.max);
        if !(min.is_finite() && max.is_finite() && min.cmple(max).all()) {
            return OuterBox {
                min: Vec3A::NEG_INFINITY,
                max: Vec3A::INFINITY,
            };
        }
        let reach = (max - min).max_element() + min.abs().max(max.abs()).max_element();
        let grown = Vec3A::splat(reach * MARGIN);
        OuterBox {
            min: min - grown,
            max: max + grown,
        }
    }

    /// Whether `ray`, up to `t_max`, surely passes by the box (an answer of `false` says
    /// nothing). Exact up to the test's own rounding, which only makes it say `false` more:
    /// an axis along which the ray runs in one of the box's planes bounds nothing.
    #[inline(always)]
    pub(super) fn passed_by(&self, ray: &Ray, t_max: f32) -> bool {
        let origin = Vec3A::from(ray.origin);
        // A ray from inside (every ray in a room) enters: known without a division.
        if (origin.cmpge(self.min) & origin.cmple(self.max)).all() {
            return false;
        }
        let inverse = Vec3A::ONE / Vec3A::from(ray.direction);
        let to_min = (self.min - origin) * inverse;
        let to_max = (self.max - origin) * inverse;
        // 0 × ∞: the ray lies in a plane of the box along that axis.
        let unbounded = to_min.is_nan_mask() | to_max.is_nan_mask();
        let near = Vec3A::select(unbounded, Vec3A::NEG_INFINITY, to_min.min(to_max));
        let far = Vec3A::select(unbounded, Vec3A::INFINITY, to_min.max(to_max));
        let grow = 1.0 + 2.0 * GAMMA_3;
        near.max_element().max(0.0) > (far.min_element() * grow).min(t_max * grow)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::rng::Pcg32;
    use ais::sampling::uniform_sphere;
    use glam::Vec3;

    fn unit_box() -> OuterBox {
        OuterBox::around(&Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)))
    }

    fn ray(origin: Vec3, direction: Vec3) -> Ray {
        Ray {
            origin,
            direction,
            t_max: f32::INFINITY,
        }
    }

    /// Rays from all around toward points sampled inside the box never pass it by; rays
    /// that point away from it, or end before it, do.
    #[test]
    fn rays_into_the_box_never_pass_it_by() {
        let outer = unit_box();
        let mut rng = Pcg32::new(5, 0);
        for _ in 0..100_000 {
            let origin = uniform_sphere([rng.next_f32(), rng.next_f32()]) * 6.0;
            let inside = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
            let toward = inside - origin;
            let distance = toward.length();
            let direction = toward / distance;
            assert!(!outer.passed_by(&ray(origin, direction), distance * 1.0001));
            assert!(outer.passed_by(&ray(origin, -direction), f32::INFINITY));
            assert!(outer.passed_by(&ray(origin, direction), distance - 3.5));
        }
    }

    /// Rays that run in the plane of a face (directions with zero components, so 0 × ∞ in
    /// the test) are not passed by, nor rays a hair outside the box, within its growth;
    /// rays clearly outside are.
    #[test]
    fn rays_along_a_face_are_left_to_the_traversal() {
        let exact = OuterBox {
            min: Vec3A::splat(-1.0),
            max: Vec3A::splat(1.0),
        };
        let grown = unit_box();
        for direction in [Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0).normalize()] {
            let along = |height: f32| ray(Vec3::new(0.0, 0.0, height) - 3.0 * direction, direction);
            assert!(!exact.passed_by(&along(1.0), f32::INFINITY));
            assert!(!exact.passed_by(&along(-1.0), f32::INFINITY));
            assert!(exact.passed_by(&along(1.001), f32::INFINITY));
            assert!(!grown.passed_by(&along(1.0 + 1e-5), f32::INFINITY));
            assert!(grown.passed_by(&along(1.001), f32::INFINITY));
        }
        let inside = ray(Vec3::ZERO, Vec3::X);
        assert!(!grown.passed_by(&inside, 1e-3));
    }

    /// An empty box lets no ray pass by untested.
    #[test]
    fn an_empty_box_is_passed_by_by_no_ray() {
        let outer = OuterBox::around(&Aabb::empty());
        assert!(!outer.passed_by(&ray(Vec3::splat(5.0), Vec3::X), f32::INFINITY));
    }
}
