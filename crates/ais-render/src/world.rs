//! A scene ready to render: geometry in a BVH, the camera, and the settings.

use crate::camera::Camera;
use crate::error::InputError;
use crate::geometry::{Geometry, ShapeGeometry, ShapeInput};
use crate::mesh::{load_mesh, validate};
use crate::scene::{self, SceneDescription};
use crate::shapes;

/// Everything a render needs.
pub struct World {
    /// The geometry.
    pub geometry: Geometry,
    /// The camera.
    pub camera: Camera,
    /// Film width and height.
    pub resolution: (u32, u32),
    /// Samples per pixel from the scene file.
    pub sample_count: u32,
    /// The description it was built from (materials and emitters are carried here).
    pub description: SceneDescription,
    /// Warnings from reading the scene and its assets.
    pub warnings: Vec<String>,
}

impl World {
    /// Loads meshes, applies transforms and builds the BVH.
    pub fn from_description(description: SceneDescription) -> Result<Self, InputError> {
        let mut warnings = description.warnings.clone();
        let file = description.file.clone();
        let mut inputs = Vec::with_capacity(description.shapes.len());
        for shape in &description.shapes {
            let mesh = match &shape.geometry {
                scene::ShapeGeometry::Sphere { center, radius } => {
                    inputs.push(ShapeInput {
                        geometry: shapes::sphere(
                            &file,
                            shape.line,
                            *center,
                            *radius,
                            shape.to_world,
                        )?,
                        flip_normals: shape.flip_normals,
                    });
                    continue;
                }
                scene::ShapeGeometry::Rectangle => shapes::rectangle(),
                scene::ShapeGeometry::Disk => shapes::disk(),
                scene::ShapeGeometry::Cube => shapes::cube(),
                scene::ShapeGeometry::Mesh { path, format } => {
                    let loaded = load_mesh(path, *format)?;
                    warnings.extend(loaded.warnings);
                    loaded.mesh
                }
            };
            let mesh = mesh.transformed(shape.to_world, shape.face_normals, shape.flip_normals);
            // A transform can collapse triangles (e.g. a zero scale): validate again.
            let checked = validate(&file, mesh).map_err(|e| {
                InputError::at(
                    &file,
                    shape.line,
                    format!("shape became unusable after to_world: {}", e.message),
                )
            })?;
            warnings.extend(checked.warnings);
            inputs.push(ShapeInput {
                geometry: ShapeGeometry::Mesh(checked.mesh),
                flip_normals: shape.flip_normals,
            });
        }
        let geometry = Geometry::build(inputs);
        let (width, height) = description.resolution;
        Ok(World {
            geometry,
            camera: Camera::new(&description.camera, width, height),
            resolution: description.resolution,
            sample_count: description.sample_count,
            description,
            warnings,
        })
    }
}
