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

/// The origin for a ray leaving a surface at `point` with geometric normal `normal` toward
/// `direction`: pushed off the surface on the side the ray goes to.
pub fn offset_origin(point: Vec3, normal: Vec3, direction: Vec3) -> Vec3 {
    let magnitude = point.abs().max_element().max(1.0);
    let offset = normal * (RELATIVE_OFFSET * magnitude);
    if normal.dot(direction) >= 0.0 {
        point + offset
    } else {
        point - offset
    }
}

/// A ray leaving a surface point.
pub fn spawn_ray(point: Vec3, normal: Vec3, direction: Vec3) -> Ray {
    Ray::new(offset_origin(point, normal, direction), direction)
}

/// A shadow ray from a surface point toward `target`, stopping just short of it.
pub fn spawn_ray_to(point: Vec3, normal: Vec3, target: Vec3) -> Ray {
    let origin = offset_origin(point, normal, target - point);
    let to_target = target - origin;
    let distance = to_target.length();
    Ray {
        origin,
        direction: to_target / distance,
        t_max: distance * (1.0 - 1e-4),
    }
}
