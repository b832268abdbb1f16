//! The built-in default scene, made in code so that `ais render` needs no files: a grooved
//! sculpture of several hundred thousand triangles on a ground plane. Its deep, narrow
//! grooves occlude most directions from points inside them, the case AIS is for.

use crate::camera::Camera;
use crate::geometry::{Geometry, ShapeGeometry, ShapeInput};
use crate::mesh::TriangleMesh;
use crate::scene::{look_at, CameraDescription, FovAxis, SceneDescription};
use crate::shapes;
use crate::world::World;
use glam::{DMat4, DVec3, Vec3};
use std::f32::consts::{PI, TAU};

/// Rows and columns of the sculpture's latitude-longitude grid: 2 · 384 · 512 = 393,216 triangles.
const ROWS: u32 = 384;
const COLUMNS: u32 = 512;

/// The sculpture's radius in direction (θ, φ): a sphere cut by deep grooves along a twisted
/// lattice, plus a finer ripple.
fn radius(theta: f32, phi: f32) -> f32 {
    let lattice = ((6.0 * phi + 2.0 * (3.0 * theta).sin()).sin() * (5.0 * theta).sin()).abs();
    let groove = (1.0 - lattice).powi(8);
    let ripple = 0.03 * (23.0 * phi).sin() * (19.0 * theta).sin();
    1.0 - 0.35 * groove + ripple
}

/// The sculpture mesh, with smooth vertex normals, centred at the origin (y up).
pub fn sculpture() -> TriangleMesh {
    let mut positions = Vec::with_capacity(((ROWS + 1) * COLUMNS) as usize);
    for row in 0..=ROWS {
        let theta = PI * row as f32 / ROWS as f32;
        for column in 0..COLUMNS {
            let phi = TAU * column as f32 / COLUMNS as f32;
            let r = radius(theta, phi);
            positions.push(Vec3::new(
                r * theta.sin() * phi.cos(),
                r * theta.cos(),
                r * theta.sin() * phi.sin(),
            ));
        }
    }
    let index = |row: u32, column: u32| row * COLUMNS + column % COLUMNS;
    let mut triangles = Vec::with_capacity((2 * ROWS * COLUMNS) as usize);
    for row in 0..ROWS {
        for column in 0..COLUMNS {
            let (a, b) = (index(row, column), index(row, column + 1));
            let (c, d) = (index(row + 1, column), index(row + 1, column + 1));
            // Outward winding (y up, φ toward +z).
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for &[a, b, c] in &triangles {
        let n = (positions[b as usize] - positions[a as usize])
            .cross(positions[c as usize] - positions[a as usize]);
        for v in [a, b, c] {
            normals[v as usize] += n;
        }
    }
    // Pole rows collapse to points: their triangles have zero area and are dropped by
    // validation; their vertex normals point along the axis.
    for (i, n) in normals.iter_mut().enumerate() {
        *n = n.try_normalize().unwrap_or(positions[i].normalize());
    }
    TriangleMesh {
        positions,
        normals: Some(normals),
        triangles,
    }
}

/// The default scene's camera, looking at the sculpture from above the ground.
pub fn default_camera() -> CameraDescription {
    CameraDescription {
        to_world: look_at(
            DVec3::new(3.3, 2.0, 5.0),
            DVec3::new(0.0, -0.25, 0.0),
            DVec3::Y,
        )
        .expect("valid look-at"),
        fov_degrees: 40.0,
        fov_axis: FovAxis::X,
    }
}

/// The built-in default scene at `width × height` pixels.
pub fn default_world(width: u32, height: u32) -> World {
    let sculpture =
        crate::mesh::validate(std::path::Path::new("<built-in sculpture>"), sculpture())
            .expect("the procedural sculpture is valid")
            .mesh;
    let ground_transform = DMat4::from_translation(DVec3::new(0.0, -1.0, 0.0))
        * DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2)
        * DMat4::from_scale(DVec3::splat(8.0));
    let ground = shapes::rectangle().transformed(ground_transform, false, false);
    let geometry = Geometry::build(vec![
        ShapeInput {
            geometry: ShapeGeometry::Mesh(sculpture),
            flip_normals: false,
        },
        ShapeInput {
            geometry: ShapeGeometry::Mesh(ground),
            flip_normals: false,
        },
    ]);
    let camera_description = default_camera();
    let description = SceneDescription {
        file: "<built-in default scene>".into(),
        camera: camera_description.clone(),
        resolution: (width, height),
        sample_count: 4,
        shapes: Vec::new(),
        bsdfs: Vec::new(),
        emitters: Vec::new(),
        integrator: None,
        warnings: Vec::new(),
    };
    World {
        geometry,
        camera: Camera::new(&camera_description, width, height),
        resolution: (width, height),
        sample_count: 4,
        description,
        warnings: Vec::new(),
    }
}
