//! The perspective and orthographic cameras, following Mitsuba's conventions.

use crate::geometry::Ray;
use crate::scene::{CameraDescription, FovAxis, Projection};
use glam::{Mat4, Vec3};

/// A camera: image point → world ray.
#[derive(Clone, Debug)]
pub struct Camera {
    to_world: Mat4,
    /// Perspective or orthographic.
    projection: Projection,
    /// Half the film's extent along camera x and y: tan(half field of view) for the
    /// perspective camera, half the width and height of the viewed rectangle (before
    /// `to_world`) for the orthographic one.
    half: (f32, f32),
    /// A thin lens: its radius and the distance in focus (camera space).
    lens: Option<(f32, f32)>,
}

/// tan(half field of view) along x and y of a perspective camera with this aspect.
pub(crate) fn perspective_half(description: &CameraDescription, aspect: f64) -> (f64, f64) {
    let tan = (description.fov_degrees.to_radians() / 2.0).tan();
    let axis = match description.fov_axis {
        FovAxis::Smaller if aspect >= 1.0 => FovAxis::Y,
        FovAxis::Smaller => FovAxis::X,
        FovAxis::Larger if aspect >= 1.0 => FovAxis::X,
        FovAxis::Larger => FovAxis::Y,
        other => other,
    };
    match axis {
        FovAxis::X => (tan, tan / aspect),
        FovAxis::Y => (tan * aspect, tan),
        _ => {
            let diagonal = (aspect * aspect + 1.0).sqrt();
            (tan * aspect / diagonal, tan / diagonal)
        }
    }
}

impl Camera {
    /// The camera of a scene description for a film of `width × height` pixels.
    pub fn new(description: &CameraDescription, width: u32, height: u32) -> Self {
        let aspect = width as f64 / height as f64;
        let (half_x, half_y) = match description.projection {
            Projection::Perspective => perspective_half(description, aspect),
            Projection::Orthographic => (1.0, 1.0 / aspect),
        };
        Camera {
            to_world: description.to_world.as_mat4(),
            projection: description.projection,
            half: (half_x as f32, half_y as f32),
            lens: description
                .lens
                .filter(|lens| lens.aperture_radius > 0.0)
                .map(|lens| (lens.aperture_radius as f32, lens.focus_distance as f32)),
        }
    }

    /// Whether rays start anywhere on a lens (and need two more random numbers).
    pub fn has_aperture(&self) -> bool {
        self.lens.is_some()
    }

    /// [`Camera::ray`] from the point of the lens chosen by `lens_sample` ∈ [0, 1)²: the
    /// rays through one film position all meet on the plane in focus.
    pub fn ray_through_lens(&self, u: f32, v: f32, lens_sample: [f32; 2]) -> Ray {
        let Some((radius, focus)) = self.lens else {
            return self.ray(u, v);
        };
        let x = -(2.0 * u - 1.0) * self.half.0;
        let y = -(2.0 * v - 1.0) * self.half.1;
        let in_focus = Vec3::new(x, y, 1.0) * focus;
        let [lx, ly] = ais::sampling::warp::uniform_disk(lens_sample);
        let on_lens = Vec3::new(lx * radius, ly * radius, 0.0);
        let origin = self.to_world.transform_point3(on_lens);
        let direction = self.to_world.transform_vector3(in_focus - on_lens);
        Ray::new(origin, direction.normalize())
    }

    /// The width of one pixel of a `width`-pixel-wide film at `distance` from the camera,
    /// near the image centre: what a gather's neighbourhood is scaled by.
    pub fn footprint(&self, distance: f32, width: u32) -> f32 {
        let across = 2.0 * self.half.0 / width.max(1) as f32;
        match self.projection {
            Projection::Perspective => distance * across,
            Projection::Orthographic => across * self.to_world.x_axis.truncate().length(),
        }
    }

    /// The ray through film position (`u`, `v`) ∈ [0, 1]², `u` to the right and `v` down.
    /// Camera space has +z forward, +y up and +x to the left (Mitsuba's look-at).
    pub fn ray(&self, u: f32, v: f32) -> Ray {
        let x = -(2.0 * u - 1.0) * self.half.0;
        let y = -(2.0 * v - 1.0) * self.half.1;
        match self.projection {
            Projection::Perspective => {
                let origin = self.to_world.transform_point3(Vec3::ZERO);
                let direction = self.to_world.transform_vector3(Vec3::new(x, y, 1.0));
                Ray::new(origin, direction.normalize())
            }
            Projection::Orthographic => {
                let origin = self.to_world.transform_point3(Vec3::new(x, y, 0.0));
                let direction = self.to_world.transform_vector3(Vec3::Z);
                Ray::new(origin, direction.normalize())
            }
        }
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
            projection: Projection::Perspective,
            lens: None,
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

    #[test]
    fn orthographic_rays_are_parallel_over_the_scaled_rectangle() {
        let to_world = look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y).unwrap()
            * glam::DMat4::from_scale(DVec3::new(3.0, 3.0, 1.0));
        let description = CameraDescription {
            to_world,
            projection: Projection::Orthographic,
            fov_degrees: 0.0,
            fov_axis: FovAxis::X,
            lens: None,
        };
        let camera = Camera::new(&description, 200, 100);
        let centre = camera.ray(0.5, 0.5);
        let corner = camera.ray(1.0, 0.0);
        assert!((centre.direction - Vec3::NEG_Z).length() < 1e-6);
        assert!((corner.direction - Vec3::NEG_Z).length() < 1e-6);
        // x spans [−1, 1] and y [−1/aspect, 1/aspect] before the scale of 3; the image's
        // right is +x when looking down −z.
        assert!(
            (corner.origin - Vec3::new(3.0, 1.5, 5.0)).length() < 1e-4,
            "{:?}",
            corner.origin
        );
        assert!((camera.footprint(100.0, 200) - 0.03).abs() < 1e-6);
    }
}
