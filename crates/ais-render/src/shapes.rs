//! Mitsuba's built-in shapes as world-space geometry: rectangles and cubes as exact
//! triangles, spheres analytic (disks and cylinders are exact quadrics: see the geometry's
//! `Quadric`).

use crate::error::InputError;
use crate::geometry::{ShapeGeometry, Sphere};
use crate::mesh::TriangleMesh;
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::path::Path;

/// The square [-1, 1]² at z = 0, normal +z, with Mitsuba's texture coordinates
/// ((x + 1) / 2, (y + 1) / 2).
pub fn rectangle() -> TriangleMesh {
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    TriangleMesh {
        positions: corners.map(|(x, y)| Vec3::new(x, y, 0.0)).to_vec(),
        normals: None,
        texcoords: Some(
            corners
                .map(|(x, y)| Vec2::new((x + 1.0) / 2.0, (y + 1.0) / 2.0))
                .to_vec(),
        ),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        attributes: Vec::new(),
    }
}

/// The cube [-1, 1]³ with outward faces.
pub fn cube() -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    let mut texcoords = Vec::new();
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
                let position = normal + a * u + b * v;
                mesh.positions.push(position);
                texcoords.push(cube_texcoords(axis, sign, position));
            }
            mesh.triangles.push([base, base + 1, base + 2]);
            mesh.triangles.push([base, base + 2, base + 3]);
        }
    }
    mesh.texcoords = Some(texcoords);
    mesh
}

/// Mitsuba's texture coordinates on the cube's face `sign` · `axis` (each face maps [0, 1]²
/// affinely; read from Mitsuba's own cube).
fn cube_texcoords(axis: usize, sign: f32, p: Vec3) -> Vec2 {
    let up = |c: f32| (c + 1.0) / 2.0;
    let down = |c: f32| (1.0 - c) / 2.0;
    match (axis, sign > 0.0) {
        (0, true) => Vec2::new(up(p.y), down(p.z)),
        (0, false) => Vec2::new(up(p.y), up(p.z)),
        (1, true) => Vec2::new(down(p.x), down(p.z)),
        (1, false) => Vec2::new(up(p.z), up(p.x)),
        (_, true) => Vec2::new(up(p.y), up(p.x)),
        (_, false) => Vec2::new(down(p.y), up(p.x)),
    }
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
