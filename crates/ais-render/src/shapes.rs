//! Mitsuba's built-in shapes as world-space geometry: rectangles and cubes as exact
//! triangles, disks as a fine triangle fan, spheres analytic.

use crate::error::InputError;
use crate::geometry::{ShapeGeometry, Sphere};
use crate::mesh::TriangleMesh;
use glam::{DMat4, DVec3, Vec3};
use std::path::Path;

/// Segments of the triangle fan that stands for a disk (area error below 0.04%).
pub const DISK_SEGMENTS: u32 = 256;

/// The square [-1, 1]² at z = 0, normal +z.
pub fn rectangle() -> TriangleMesh {
    TriangleMesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: None,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// The unit disk at z = 0, normal +z, as a fan of [`DISK_SEGMENTS`] triangles.
pub fn disk() -> TriangleMesh {
    let mut positions = vec![Vec3::ZERO];
    positions.extend((0..DISK_SEGMENTS).map(|i| {
        let phi = std::f32::consts::TAU * i as f32 / DISK_SEGMENTS as f32;
        Vec3::new(phi.cos(), phi.sin(), 0.0)
    }));
    let triangles = (0..DISK_SEGMENTS)
        .map(|i| [0, 1 + i, 1 + (i + 1) % DISK_SEGMENTS])
        .collect();
    TriangleMesh {
        positions,
        normals: None,
        triangles,
    }
}

/// The cube [-1, 1]³ with outward faces.
pub fn cube() -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let normal =
                Vec3::from_array(std::array::from_fn(|i| if i == axis { sign } else { 0.0 }));
            let u = Vec3::from_array(std::array::from_fn(|i| {
                if i == (axis + 1) % 3 {
                    1.0
                } else {
                    0.0
                }
            }));
            let v = normal.cross(u);
            let base = mesh.positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                mesh.positions.push(normal + a * u + b * v);
            }
            mesh.triangles.push([base, base + 1, base + 2]);
            mesh.triangles.push([base, base + 2, base + 3]);
        }
    }
    mesh
}

/// A sphere under `to_world`, which must scale uniformly.
pub fn sphere(
    file: &Path,
    line: u32,
    center: DVec3,
    radius: f64,
    to_world: DMat4,
) -> Result<ShapeGeometry, InputError> {
    let scales = [to_world.x_axis, to_world.y_axis, to_world.z_axis].map(|a| a.truncate().length());
    if (scales[0] - scales[1]).abs() > 1e-6 * scales[0]
        || (scales[0] - scales[2]).abs() > 1e-6 * scales[0]
    {
        return Err(InputError::at(
            file,
            line,
            "a sphere's to_world must scale uniformly",
        ));
    }
    let sphere = Sphere {
        center: to_world.transform_point3(center).as_vec3(),
        radius: (radius * scales[0]) as f32,
    };
    let extent = sphere.center.abs().max_element() + sphere.radius;
    if !(extent.is_finite() && extent <= crate::mesh::LARGEST_COORDINATE) {
        return Err(InputError::at(
            file,
            line,
            format!(
                "the sphere reaches {extent:e}, beyond ±{:e}: coordinates this large break the \
                 BVH's precision; scale the scene down",
                crate::mesh::LARGEST_COORDINATE
            ),
        ));
    }
    Ok(ShapeGeometry::Sphere(sphere))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_shapes_have_the_right_areas() {
        assert!((rectangle().area() - 4.0).abs() < 1e-9);
        assert!((cube().area() - 24.0).abs() < 1e-6);
        assert!((disk().area() - std::f64::consts::PI).abs() / std::f64::consts::PI < 4e-4);
        // Every face of the cube points outward.
        let c = cube();
        for &[a, b, d] in &c.triangles {
            let (a, b, d) = (
                c.positions[a as usize],
                c.positions[b as usize],
                c.positions[d as usize],
            );
            let n = (b - a).cross(d - a);
            assert!(n.dot(a + b + d) > 0.0);
        }
    }
}
