//! Mitsuba's built-in shapes as world-space geometry: rectangles and cubes as exact
//! triangles, disks as a fine triangle fan, spheres analytic.

use crate::error::InputError;
use crate::geometry::{ShapeGeometry, Sphere};
use crate::mesh::TriangleMesh;
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::path::Path;

/// Segments of the triangle fan that stands for a disk (area error below 0.04%).
pub const DISK_SEGMENTS: u32 = 256;

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

/// The unit disk at z = 0, normal +z, as a fan of [`DISK_SEGMENTS`] triangles, with
/// Mitsuba's texture coordinates (radius, angle / 2π). Each triangle has its own vertices, so
/// that the angle does not wrap inside a triangle and the centre takes its triangle's angle.
pub fn disk() -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    let rim = |i: u32| {
        let phi = std::f32::consts::TAU * i as f32 / DISK_SEGMENTS as f32;
        Vec3::new(phi.cos(), phi.sin(), 0.0)
    };
    let segments = DISK_SEGMENTS as f32;
    let mut texcoords = Vec::new();
    for i in 0..DISK_SEGMENTS {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([Vec3::ZERO, rim(i), rim(i + 1)]);
        texcoords.extend([
            Vec2::new(0.0, (i as f32 + 0.5) / segments),
            Vec2::new(1.0, i as f32 / segments),
            Vec2::new(1.0, (i + 1) as f32 / segments),
        ]);
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    mesh.texcoords = Some(texcoords);
    mesh
}

/// Facets around a cylinder. The flat facets lie within 1.2e-3 radii of the true surface
/// and their normals within 2.8° of its normals; they keep their own normals (interpolated
/// vertex normals send rays from near a facet's edge below its plane, into the cylinder).
/// Finer facets meet at angles so shallow (under about 3°) that a shadow ray leaving near
/// an edge, offset from the surface as every ray is, can still hit the next facet: at 256
/// facets that darkened streaks along the cylinder by 30 standard errors against Mitsuba.
pub const CYLINDER_SEGMENTS: u32 = 64;

/// Mitsuba's cylinder of `radius` from `p0` to `p1` as flat-shaded triangles, open at both
/// ends, normals outward, with texture coordinates (azimuth / 2π, distance along the axis / length). The
/// azimuth's origin follows our basis around the axis, which matches Mitsuba's for an axis
/// along z.
pub fn cylinder(p0: DVec3, p1: DVec3, radius: f64) -> TriangleMesh {
    let axis = p1 - p0;
    let (x, y) = crate::geometry::basis(axis.normalize().as_vec3());
    let (x, y) = (x.as_dvec3() * radius, y.as_dvec3() * radius);
    let mut mesh = TriangleMesh::default();
    let mut texcoords = Vec::new();
    for i in 0..=CYLINDER_SEGMENTS {
        let u = i as f64 / CYLINDER_SEGMENTS as f64;
        let (sin, cos) = (std::f64::consts::TAU * u).sin_cos();
        let radial = x * cos + y * sin;
        for (end, v) in [(p0, 0.0), (p1, 1.0)] {
            mesh.positions.push((end + radial).as_vec3());
            texcoords.push(Vec2::new(u as f32, v));
        }
    }
    for i in 0..CYLINDER_SEGMENTS {
        let (a, b) = (2 * i, 2 * i + 2);
        mesh.triangles.push([a, b, b + 1]);
        mesh.triangles.push([a, b + 1, a + 1]);
    }
    mesh.texcoords = Some(texcoords);
    mesh
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
