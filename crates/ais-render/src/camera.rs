//! The perspective camera, following Mitsuba's conventions.

use crate::geometry::Ray;
use crate::scene::{CameraDescription, FovAxis};
use glam::{Mat4, Vec3};

/// A pinhole camera: image point → world ray.
#[derive(Clone, Debug)]
pub struct Camera {
    to_world: Mat4,
    /// tan(half field of view) along x and y.
    tan_half: (f32, f32),
}

impl Camera {
    /// The camera of a scene description for a film of `width × height` pixels.
    pub fn new(description: &CameraDescription, width: u32, height: u32) -> Self {
        let aspect = width as f64 / height as f64;
        let tan = (description.fov_degrees.to_radians() / 2.0).tan();
        let axis = match description.fov_axis {
            FovAxis::Smaller if aspect >= 1.0 => FovAxis::Y,
            FovAxis::Smaller => FovAxis::X,
            FovAxis::Larger if aspect >= 1.0 => FovAxis::X,
            FovAxis::Larger => FovAxis::Y,
            other => other,
        };
        let (tan_x, tan_y) = match axis {
            FovAxis::X => (tan, tan / aspect),
            FovAxis::Y => (tan * aspect, tan),
            _ => {
                let diagonal = (aspect * aspect + 1.0).sqrt();
                (tan * aspect / diagonal, tan / diagonal)
            }
        };
        Camera {
            to_world: description.to_world.as_mat4(),
            tan_half: (tan_x as f32, tan_y as f32),
        }
    }

    /// The angle one pixel of a `width`-pixel-wide film subtends at the image centre.
    pub fn pixel_angle(&self, width: u32) -> f32 {
        2.0 * self.tan_half.0 / width.max(1) as f32
    }

    /// The ray through film position (`u`, `v`) ∈ [0, 1]², `u` to the right and `v` down.
    /// Camera space has +z forward, +y up and +x to the left (Mitsuba's look-at).
    pub fn ray(&self, u: f32, v: f32) -> Ray {
        let local = Vec3::new(
            -(2.0 * u - 1.0) * self.tan_half.0,
            -(2.0 * v - 1.0) * self.tan_half.1,
            1.0,
        );
        let origin = self.to_world.transform_point3(Vec3::ZERO);
        let direction = self.to_world.transform_vector3(local).normalize();
        Ray::new(origin, direction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::look_at;
    use glam::DVec3;

    #[test]
    fn centre_ray_looks_at_the_target_and_right_is_right() {
        let description = CameraDescription {
            to_world: look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y).unwrap(),
            fov_degrees: 90.0,
            fov_axis: FovAxis::X,
        };
        let camera = Camera::new(&description, 200, 100);
        let centre = camera.ray(0.5, 0.5);
        assert!((centre.direction - Vec3::NEG_Z).length() < 1e-6);
        // Looking down -z with +y up, the right of the image is +x.
        assert!(camera.ray(1.0, 0.5).direction.x > 0.5);
        assert!(camera.ray(0.5, 0.0).direction.y > 0.2);
        // 90° horizontal fov: the right edge is at 45°.
        let edge = camera.ray(1.0, 0.5).direction;
        assert!((edge.x - edge.z.abs()).abs() < 1e-5);
    }
}
