//! Rays and the offsets that keep secondary rays from hitting the surface they leave.

use glam::Vec3;

/// A ray `origin + t · direction` for `t` in `[0, t_max)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Unit direction.
    pub direction: Vec3,
    /// Farthest distance of interest.
    pub t_max: f32,
}

impl Ray {
    /// The same ray for obvhs's traversal, ending at `t_max`.
    pub fn to_bvh(&self, t_max: f32) -> obvhs::ray::Ray {
        obvhs::ray::Ray::new(
            glam::Vec3A::from(self.origin),
            glam::Vec3A::from(self.direction),
            0.0,
            t_max,
        )
    }

    /// An unbounded ray.
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Ray {
            origin,
            direction,
            t_max: f32::INFINITY,
        }
    }

    /// The point at distance `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }
}

/// Relative size of the offset, in units of the point's largest coordinate magnitude. Single
/// precision intersection points carry errors of a few ulps of their coordinates; 2^-16 is
/// far above that and far below any feature size the scenes use.
const RELATIVE_OFFSET: f32 = 1.0 / 65536.0;

/// The two origins of rays leaving a surface at `point` with geometric normal `normal`:
/// pushed off the surface to the side each ray goes to. Worked out once, they serve every
/// ray a gather sends from the point.
#[derive(Clone, Copy, Debug)]
pub struct RayOrigins {
    point: Vec3,
    normal: Vec3,
    above: Vec3,
    below: Vec3,
}

impl RayOrigins {
    /// The origins of rays leaving the surface at `point` with geometric normal `normal`.
    #[inline]
    pub fn new(point: Vec3, normal: Vec3) -> Self {
        let magnitude = point.abs().max_element().max(1.0);
        let offset = normal * (RELATIVE_OFFSET * magnitude);
        RayOrigins {
            point,
            normal,
            above: point + offset,
            below: point - offset,
        }
    }

    /// The origin of a ray toward `direction`.
    #[inline]
    pub fn toward(&self, direction: Vec3) -> Vec3 {
        if self.normal.dot(direction) >= 0.0 {
            self.above
        } else {
            self.below
        }
    }

    /// An unbounded ray toward `direction`.
    #[inline]
    pub fn ray(&self, direction: Vec3) -> Ray {
        Ray::new(self.toward(direction), direction)
    }

    /// A shadow ray toward `target`, stopping just short of it.
    #[inline]
    pub fn ray_to(&self, target: Vec3) -> Ray {
        let origin = self.toward(target - self.point);
        let to_target = target - origin;
        let distance = to_target.length();
        Ray {
            origin,
            direction: to_target / distance,
            t_max: distance * (1.0 - 1e-4),
        }
    }

    /// A shadow ray along `direction`, free up to `target` if given. Aimed at the target
    /// from the offset origin, so that the ray ends just short of it whatever the offset
    /// (a ray along the direction from the offset origin can meet a curved light well
    /// before the point, near its rim).
    #[inline]
    pub fn aimed(&self, direction: Vec3, target: Option<Vec3>) -> Ray {
        match target {
            Some(target) => self.ray_to(target),
            None => self.ray(direction),
        }
    }
}

/// The origin for a ray leaving a surface at `point` with geometric normal `normal` toward
/// `direction`: pushed off the surface on the side the ray goes to.
pub fn offset_origin(point: Vec3, normal: Vec3, direction: Vec3) -> Vec3 {
    RayOrigins::new(point, normal).toward(direction)
}

/// A ray leaving a surface point.
pub fn spawn_ray(point: Vec3, normal: Vec3, direction: Vec3) -> Ray {
    RayOrigins::new(point, normal).ray(direction)
}

/// A shadow ray from a surface point toward `target`, stopping just short of it.
pub fn spawn_ray_to(point: Vec3, normal: Vec3, target: Vec3) -> Ray {
    RayOrigins::new(point, normal).ray_to(target)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::rng::Pcg32;
    use ais::sampling::uniform_sphere;

    /// A ray leaves from the side of the surface it goes to, pushed off by the offset
    /// along the normal, and a ray aimed at a target ends just short of it.
    #[test]
    fn rays_leave_from_the_side_they_go_to_and_end_short_of_their_target() {
        let mut rng = Pcg32::new(12, 5);
        let mut unit = || uniform_sphere([rng.next_f32(), rng.next_f32()]);
        for trial in 0..2000 {
            let point = unit() * [0.5, 30.0, 4000.0][trial % 3];
            let (normal, direction) = (unit(), unit());
            let origins = RayOrigins::new(point, normal);
            let magnitude = point.abs().max_element().max(1.0);
            let expected = RELATIVE_OFFSET * magnitude;
            let height = normal.dot(origins.toward(direction) - point);
            let side = normal.dot(direction).signum();
            assert!(
                // Within the rounding of the point's coordinates.
                (height - side * expected).abs() <= 4.0 * f32::EPSILON * magnitude,
                "trial {trial}: {height} vs {}",
                side * expected
            );
            let ray = origins.aimed(direction, None);
            assert_eq!((ray.direction, ray.t_max), (direction, f32::INFINITY));
            let target = point + 3.0 * unit();
            let ray = origins.aimed(direction, Some(target));
            let end = ray.at(ray.t_max);
            assert!((end - target).length() < 1e-3 * (target - ray.origin).length());
            assert!(ray.t_max < (target - ray.origin).length());
        }
    }
}
