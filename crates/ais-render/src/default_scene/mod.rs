//! The built-in default scene, made in code so that `ais render` needs no files: the talk's
//! setup. A grooved sculpture of several hundred thousand triangles on a ground plane, lit by
//! an HDRI-like procedural sky with a sun, two sphere lights and one rectangle light. The
//! deep, narrow grooves occlude most directions from points inside them, the case AIS is for.
//! [`export`] writes it as a Mitsuba 3 scene folder, for Mitsuba and for the benchmarks.

pub mod export;

use crate::bsdf::Material;
use crate::camera::Camera;
use crate::film::ReconstructionFilter;
use crate::geometry::{Geometry, ShapeGeometry, ShapeInput, Sphere};
use crate::image_io::RgbImage;
use crate::lights::{AreaLight, AreaShape, Emitters, Environment, EnvironmentMap, Lights};
use crate::mesh::TriangleMesh;
use crate::scene::{look_at, CameraDescription, FovAxis, SceneDescription};
use crate::shapes;
use crate::world::World;
use crate::world::{area_light, Emission};
use glam::{DMat4, DVec3, Vec3};
use std::f32::consts::{PI, TAU};

/// Rows and columns of the sculpture's latitude-longitude grid: 2 · 400 · 512 = 409,600 triangles
/// (408,576 after the pole rows' degenerate ones are dropped), above the talk's 400k.
const ROWS: u32 = 400;
const COLUMNS: u32 = 512;

/// Where the camera stands and what it looks at (y up), and its horizontal field of view.
const CAMERA_ORIGIN: DVec3 = DVec3::new(3.3, 2.0, 5.0);
const CAMERA_TARGET: DVec3 = DVec3::new(0.0, -0.25, 0.0);
const CAMERA_FOV_X_DEGREES: f64 = 40.0;

/// The ground: Mitsuba's rectangle scaled by this, turned to face +y, lowered by 1.
const GROUND_SCALE: f64 = 8.0;
/// The rectangle light: Mitsuba's rectangle scaled by this (0.7 × 0.7), at this origin
/// looking at this target, with this radiance.
const PANEL_SCALE: f64 = 0.35;
const PANEL_ORIGIN: DVec3 = DVec3::new(-1.6, 1.9, 1.5);
const PANEL_TARGET: DVec3 = DVec3::new(0.0, 0.2, 0.0);
const PANEL_RADIANCE: Vec3 = Vec3::new(12.0, 12.0, 11.0);

/// A sphere light of the default scene.
struct SphereLight {
    center: Vec3,
    radius: f32,
    radiance: Vec3,
}

/// The two sphere lights: a warm one and a cool one.
const SPHERE_LIGHTS: [SphereLight; 2] = [
    SphereLight {
        center: Vec3::new(1.55, 0.55, 1.25),
        radius: 0.14,
        radiance: Vec3::new(30.0, 20.0, 10.0),
    },
    SphereLight {
        center: Vec3::new(-1.45, 0.1, -1.1),
        radius: 0.18,
        radiance: Vec3::new(8.0, 12.0, 25.0),
    },
];

/// Diffuse albedos of the sculpture and the ground.
const SCULPTURE_ALBEDO: Vec3 = Vec3::splat(0.7);
const GROUND_ALBEDO: Vec3 = Vec3::new(0.45, 0.42, 0.38);

/// The sky image's size (lat-long).
const SKY_SIZE: (usize, usize) = (512, 256);

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
        texcoords: None,
        triangles,
        attributes: Vec::new(),
    }
}

/// The default scene's camera, looking at the sculpture from above the ground.
pub fn default_camera() -> CameraDescription {
    CameraDescription {
        projection: crate::scene::Projection::Perspective,
        lens: None,
        to_world: look_at(CAMERA_ORIGIN, CAMERA_TARGET, DVec3::Y).expect("valid look-at"),
        fov_degrees: CAMERA_FOV_X_DEGREES,
        fov_axis: FovAxis::X,
    }
}

/// A procedural lat-long sky (Mitsuba orientation, +y up): a horizon-bright blue gradient,
/// a dim ground below the horizon, and a small, very bright sun.
pub fn procedural_sky(width: usize, height: usize) -> RgbImage {
    let sun = Vec3::new(0.55, 0.62, 0.56).normalize();
    let sun_cos = (1.5f32).to_radians().cos();
    let mut image = RgbImage::new(width, height);
    for row in 0..height {
        let theta = PI * (row as f32 + 0.5) / height as f32;
        for column in 0..width {
            let phi = TAU * (column as f32 + 0.5) / width as f32;
            let d = Vec3::new(
                phi.sin() * theta.sin(),
                theta.cos(),
                -phi.cos() * theta.sin(),
            );
            let value = if d.dot(sun) >= sun_cos {
                Vec3::new(900.0, 820.0, 700.0)
            } else if d.y >= 0.0 {
                let horizon = (1.0 - d.y).powi(3);
                Vec3::new(0.35, 0.55, 1.0) * (0.6 + 0.8 * horizon)
            } else {
                Vec3::new(0.18, 0.16, 0.14)
            };
            image.pixels[row * width + column] = value.to_array();
        }
    }
    image
}

/// The sculpture with its degenerate pole triangles dropped, as a reader would.
fn valid_sculpture() -> TriangleMesh {
    crate::mesh::validate(std::path::Path::new("<built-in sculpture>"), sculpture())
        .expect("the procedural sculpture is valid")
        .mesh
}

/// The shapes and area lights of the default scene: the sculpture, the ground, the
/// rectangle light and two sphere lights, in that order.
fn shapes_and_lights() -> (Vec<ShapeInput>, Vec<AreaLight>) {
    let ground_transform = DMat4::from_translation(DVec3::new(0.0, -1.0, 0.0))
        * DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2)
        * DMat4::from_scale(DVec3::splat(GROUND_SCALE));
    let ground = shapes::rectangle().transformed(ground_transform, false, false);
    // The rectangle light, facing the sculpture.
    let panel_transform = look_at(PANEL_ORIGIN, PANEL_TARGET, DVec3::Y).expect("valid look-at")
        * DMat4::from_scale(DVec3::splat(PANEL_SCALE));
    let panel = shapes::rectangle().transformed(panel_transform, false, false);
    let panel_light = area_light(&panel, true, false, Emission::constant(PANEL_RADIANCE), 2);
    let mesh = |mesh| ShapeInput {
        geometry: ShapeGeometry::Mesh(mesh),
        flip_normals: false,
        rotation: None,
    };
    let mut inputs = vec![mesh(valid_sculpture()), mesh(ground), mesh(panel)];
    let mut lights = vec![panel_light];
    for (index, light) in SPHERE_LIGHTS.iter().enumerate() {
        let sphere = Sphere {
            center: light.center,
            radius: light.radius,
        };
        inputs.push(ShapeInput {
            geometry: ShapeGeometry::Sphere(sphere),
            flip_normals: false,
            rotation: None,
        });
        lights.push(AreaLight {
            shape: AreaShape::Sphere {
                sphere,
                flipped: false,
            },
            radiance: light.radiance,
            texture: None,
            shape_index: 3 + index as u32,
        });
    }
    (inputs, lights)
}

/// The built-in default scene at `width × height` pixels.
pub fn default_world(width: u32, height: u32) -> World {
    let (inputs, area) = shapes_and_lights();
    let geometry = Geometry::build(inputs);
    let environment = Environment::Map(Box::new(EnvironmentMap::new(
        procedural_sky(SKY_SIZE.0, SKY_SIZE.1),
        glam::DMat3::IDENTITY,
    )));
    let (_, scene_radius) = geometry.bounding_sphere();
    let lights = Lights::new(
        Emitters {
            environment: Some(environment),
            area,
            delta: Vec::new(),
        },
        5,
        scene_radius as f64,
    );
    let materials = vec![
        Material::diffuse(SCULPTURE_ALBEDO),
        Material::diffuse(GROUND_ALBEDO),
        Material::default(),
        Material::default(),
        Material::default(),
    ];
    let camera_description = default_camera();
    let name = std::path::Path::new(crate::request::BUILT_IN_NAME);
    let files = crate::scene::FileResolver::new(std::path::Path::new("."), &[]);
    let description = SceneDescription {
        camera: camera_description.clone(),
        resolution: (width, height),
        filter: ReconstructionFilter::Box,
        ..SceneDescription::empty(name, files)
    };
    World {
        geometry,
        lights,
        surfaces: materials
            .into_iter()
            .map(|m| std::sync::Arc::new(m.into()))
            .collect(),
        camera: Camera::new(&camera_description, width, height),
        resolution: (width, height),
        filter: ReconstructionFilter::Box,
        sample_count: 4,
        description,
        warnings: Vec::new(),
    }
}
