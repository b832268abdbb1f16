//! A scene ready to render: geometry in a BVH, the camera, and the settings.

use crate::bsdf::{read_surface, Material, Surface, TextureScene};
use crate::camera::Camera;
use crate::error::InputError;
use crate::geometry::{
    Geometry, InstanceInput, Quadric, SceneShapes, ShapeGeometry, ShapeGroupInput, ShapeInput,
    Triangle,
};
use crate::lights::reader::{refuse_nested, scene_emitters, spectrum_property};
use crate::lights::{AreaLight, AreaShape, Emitters, Lights, MeshEmitter, Rectangle};
use crate::mesh::{load_mesh, validate, TriangleMesh};
use crate::scene::{self, SceneDescription};
use crate::shapes;
use crate::texture::Texture;
use glam::Vec3;
use std::collections::HashMap;
use std::sync::Arc;

/// Everything a render needs.
pub struct World {
    /// The geometry.
    pub geometry: Geometry,
    /// The camera.
    pub camera: Camera,
    /// Film width and height.
    pub resolution: (u32, u32),
    /// How camera samples become pixels.
    pub filter: crate::film::ReconstructionFilter,
    /// Samples per pixel from the scene file.
    pub sample_count: u32,
    /// The emitters.
    pub lights: Lights,
    /// The scattering of each shape's surface.
    pub surfaces: Vec<Arc<Surface>>,
    /// The description it was built from.
    pub description: SceneDescription,
    /// Warnings from reading the scene and its assets.
    pub warnings: Vec<String>,
}

/// One shape, ready for the BVH, and its area light if it emits.
struct BuiltShape {
    input: ShapeInput,
    light: Option<AreaLight>,
}

/// The surfaces of a scene's shapes: each shape's BSDF or, as in Mitsuba, diffuse 0.5
/// without one, or black when it emits (so that a light does not also reflect the other
/// lights). Each BSDF is read once (its warnings given once, its images loaded once) however
/// many shapes use it.
#[derive(Default)]
struct ShapeSurfaces {
    per_shape: Vec<Arc<Surface>>,
    by_bsdf: HashMap<usize, Arc<Surface>>,
}

impl ShapeSurfaces {
    /// Adds the surface of `shape`.
    fn add(
        &mut self,
        description: &SceneDescription,
        shape: &scene::ShapeDescription,
        warnings: &mut Vec<String>,
    ) -> Result<(), InputError> {
        let surface = match shape.bsdf {
            Some(index) => match self.by_bsdf.get(&index) {
                Some(surface) => surface.clone(),
                None => {
                    let scene = TextureScene {
                        file: &description.file,
                        files: &description.files,
                        bsdfs: &description.bsdfs,
                        textures: &description.textures,
                    };
                    let surface = read_surface(&description.bsdfs[index], &scene, warnings)?;
                    let surface = Arc::new(surface);
                    self.by_bsdf.insert(index, surface.clone());
                    surface
                }
            },
            None if shape.emitter.is_some() => Arc::new(Material::diffuse(Vec3::ZERO).into()),
            None => Arc::new(Material::default().into()),
        };
        self.per_shape.push(surface);
        Ok(())
    }
}

/// Refuses a shape whose surface reads a mesh attribute that its mesh does not have.
fn check_attributes(
    file: &std::path::Path,
    shape: &scene::ShapeDescription,
    input: &ShapeInput,
    surface: &Surface,
) -> Result<(), InputError> {
    let names = surface.attribute_names();
    let available = match &input.geometry {
        ShapeGeometry::Mesh(mesh) => mesh.attributes.iter().map(|a| a.name.as_str()).collect(),
        ShapeGeometry::Sphere(_) | ShapeGeometry::Quadric(_) => Vec::new(),
    };
    match names
        .iter()
        .find(|name| !available.contains(&name.as_str()))
    {
        None => Ok(()),
        Some(name) => Err(InputError::at(
            file,
            shape.line,
            format!(
                "the shape has no mesh attribute \"{name}\" (it has: {})",
                if available.is_empty() {
                    "none".to_string()
                } else {
                    available.join(", ")
                }
            ),
        )),
    }
}

/// The rotation in a sphere's `to_world` (its uniform scale divided out), if it rotates.
fn sphere_rotation(shape: &scene::ShapeDescription) -> Option<glam::Mat3> {
    let linear = glam::DMat3::from_mat4(shape.to_world);
    let scale = linear.x_axis.length();
    let rotation = linear * (1.0 / scale.max(f64::MIN_POSITIVE));
    let identity = (rotation - glam::DMat3::IDENTITY).to_cols_array();
    let rotates = identity.iter().any(|x| x.abs() > 1e-9);
    (rotates && rotation.is_finite()).then(|| rotation.as_mat3())
}

/// What an area emitter sends from its front side: a radiance, times a texture's value
/// over the surface when one gives it.
#[derive(Clone, Debug)]
pub struct Emission {
    /// The radiance (one when a texture gives it).
    pub radiance: Vec3,
    /// The texture, if one gives the radiance.
    pub texture: Option<Arc<Texture>>,
}

impl Emission {
    /// The same radiance everywhere.
    pub fn constant(radiance: Vec3) -> Self {
        Emission {
            radiance,
            texture: None,
        }
    }
}

/// The emission of the area emitter `emitter`: its `radiance`, a colour or a texture
/// (nested or referenced); any other nested plugin is refused.
fn read_emission(
    description: &SceneDescription,
    emitter: &scene::Plugin,
    warnings: &mut Vec<String>,
) -> Result<Emission, InputError> {
    let file = &description.file;
    scene::warn_unknown(file, emitter, &["radiance"], warnings);
    let scene = TextureScene {
        file,
        files: &description.files,
        bsdfs: &description.bsdfs,
        textures: &description.textures,
    };
    let texture = crate::bsdf::parameter_texture(emitter, "radiance", &scene, warnings)?;
    refuse_nested(file, emitter, &["radiance"])?;
    Ok(match texture {
        Some(texture) => Emission {
            radiance: Vec3::ONE,
            texture: Some(Arc::new(texture)),
        },
        None => Emission::constant(spectrum_property(file, emitter, "radiance")?),
    })
}

/// An analytic sphere (centre, radius) under the shape's `to_world`, with its area light.
fn sphere_shape(
    file: &std::path::Path,
    shape: &scene::ShapeDescription,
    (center, radius): (glam::DVec3, f64),
    emission: Option<Emission>,
    index: u32,
) -> Result<BuiltShape, InputError> {
    let geometry = shapes::sphere(file, shape.line, center, radius, shape.to_world)?;
    let light = match (emission, &geometry) {
        (Some(emission), ShapeGeometry::Sphere(sphere)) => Some(AreaLight {
            shape: AreaShape::Sphere {
                sphere: *sphere,
                flipped: shape.flip_normals,
            },
            radiance: emission.radiance,
            texture: emission.texture,
            shape_index: index,
        }),
        _ => None,
    };
    let input = ShapeInput {
        geometry,
        flip_normals: shape.flip_normals,
        rotation: sphere_rotation(shape),
    };
    Ok(BuiltShape { input, light })
}

/// An exact disk or cylinder under the shape's `to_world`, with its area light.
fn quadric_shape(
    file: &std::path::Path,
    shape: &scene::ShapeDescription,
    quadric: Option<Quadric>,
    emission: Option<Emission>,
    index: u32,
) -> Result<BuiltShape, InputError> {
    let quadric = quadric.ok_or_else(|| {
        InputError::at(
            file,
            shape.line,
            "the shape is degenerate (zero radius, length or scale)",
        )
    })?;
    let bounds = quadric.bounds();
    let extent = bounds.min.abs().max(bounds.max.abs()).max_element();
    if !(extent.is_finite() && extent <= crate::mesh::LARGEST_COORDINATE) {
        return Err(InputError::at(
            file,
            shape.line,
            format!(
                "the shape reaches {extent:e}, beyond ±{:e}: coordinates this large break the \
                 BVH's precision; scale the scene down",
                crate::mesh::LARGEST_COORDINATE
            ),
        ));
    }
    let light = emission.map(|emission| AreaLight {
        shape: AreaShape::Quadric {
            quadric,
            flipped: shape.flip_normals,
        },
        radiance: emission.radiance,
        texture: emission.texture,
        shape_index: index,
    });
    let input = ShapeInput {
        geometry: ShapeGeometry::Quadric(quadric),
        flip_normals: shape.flip_normals,
        rotation: None,
    };
    Ok(BuiltShape { input, light })
}

/// Loads, transforms and validates shape number `index`, with its area light.
fn build_shape(
    description: &SceneDescription,
    shape: &scene::ShapeDescription,
    index: u32,
    warnings: &mut Vec<String>,
) -> Result<BuiltShape, InputError> {
    let file = &description.file;
    let emission = (shape.emitter.as_ref())
        .map(|e| read_emission(description, e, warnings))
        .transpose()?;
    let mesh = match &shape.geometry {
        scene::ShapeGeometry::Sphere { center, radius } => {
            return sphere_shape(file, shape, (*center, *radius), emission, index)
        }
        scene::ShapeGeometry::Disk => {
            let disk = Quadric::disk(shape.to_world);
            return quadric_shape(file, shape, disk, emission, index);
        }
        scene::ShapeGeometry::Cylinder { p0, p1, radius } => {
            let cylinder = Quadric::cylinder(shape.to_world, *p0, *p1, *radius);
            return quadric_shape(file, shape, cylinder, emission, index);
        }
        scene::ShapeGeometry::Rectangle => shapes::rectangle(),
        scene::ShapeGeometry::Cube => shapes::cube(),
        scene::ShapeGeometry::Mesh {
            path,
            format,
            flip_tex_coords,
        } => mesh_file(path, *format, *flip_tex_coords, warnings)?,
    };
    let mesh = mesh.transformed(shape.to_world, shape.face_normals, shape.flip_normals);
    // A transform can collapse triangles (e.g. a zero scale): validate again.
    let checked = validate(file, mesh).map_err(|e| {
        InputError::at(
            file,
            shape.line,
            format!("shape became unusable after to_world: {}", e.message),
        )
    })?;
    warnings.extend(checked.warnings);
    let light = emission.map(|emission| {
        let is_rectangle = shape.geometry == scene::ShapeGeometry::Rectangle;
        area_light(
            &checked.mesh,
            is_rectangle,
            shape.flip_normals,
            emission,
            index,
        )
    });
    let input = ShapeInput {
        geometry: ShapeGeometry::Mesh(checked.mesh),
        flip_normals: shape.flip_normals,
        rotation: None,
    };
    Ok(BuiltShape { input, light })
}

/// Every shape of a scene, ready for the BVH: the scene's own, then each shape group's (in
/// the group's frame), numbered in that order.
struct BuiltShapes {
    /// The scene's shapes, then one set per group.
    sets: Vec<Vec<ShapeInput>>,
    area_lights: Vec<AreaLight>,
    surfaces: ShapeSurfaces,
    /// Shapes in all.
    count: usize,
}

/// Loads, transforms and checks every shape of `description`, with its surface and light.
fn build_shapes(
    description: &SceneDescription,
    warnings: &mut Vec<String>,
) -> Result<BuiltShapes, InputError> {
    let mut built = BuiltShapes {
        sets: Vec::new(),
        area_lights: Vec::new(),
        surfaces: ShapeSurfaces::default(),
        count: 0,
    };
    let grouped = (description.shape_groups.iter()).map(|group| group.shapes.iter());
    for shapes in std::iter::once(description.shapes.iter()).chain(grouped) {
        let mut inputs = Vec::with_capacity(shapes.len());
        for shape in shapes {
            let index = built.count;
            built.surfaces.add(description, shape, warnings)?;
            let one = build_shape(description, shape, index as u32, warnings)?;
            let surface = &built.surfaces.per_shape[index];
            check_attributes(&description.file, shape, &one.input, surface)?;
            inputs.push(one.input);
            built.area_lights.extend(one.light);
            built.count += 1;
        }
        built.sets.push(inputs);
    }
    Ok(built)
}

impl World {
    /// Renders at `resolution` from now on: the film's size and the camera's aspect.
    pub fn set_resolution(&mut self, resolution: (u32, u32)) {
        self.resolution = resolution;
        self.camera = Camera::new(&self.description.camera, resolution.0, resolution.1);
    }

    /// Loads meshes, applies transforms and builds the BVH.
    pub fn from_description(description: SceneDescription) -> Result<Self, InputError> {
        let mut warnings = description.warnings.clone();
        let file = description.file.clone();
        let BuiltShapes {
            sets,
            area_lights,
            surfaces,
            count,
        } = build_shapes(&description, &mut warnings)?;
        let triangles = (sets.iter().flatten())
            .map(|input| match &input.geometry {
                ShapeGeometry::Mesh(mesh) => mesh.triangles.len(),
                ShapeGeometry::Sphere(_) | ShapeGeometry::Quadric(_) => 1,
            })
            .sum();
        crate::limits::check_geometry_memory(triangles)
            .map_err(|message| InputError::new(&file, message))?;
        let mut sets = sets.into_iter();
        let geometry = Geometry::build_instanced(SceneShapes {
            shapes: sets.next().unwrap_or_default(),
            groups: sets.map(|shapes| ShapeGroupInput { shapes }).collect(),
            instances: (description.instances.iter())
                .map(|instance| InstanceInput {
                    group: instance.group as u32,
                    to_world: glam::Affine3A::from_mat4(instance.to_world.as_mat4()),
                })
                .collect(),
        });
        let scene = TextureScene {
            file: &file,
            files: &description.files,
            bsdfs: &description.bsdfs,
            textures: &description.textures,
        };
        let (environment, delta) = scene_emitters(&scene, &description.emitters, &mut warnings)?;
        let (_, radius) = geometry.bounding_sphere();
        let emitters = Emitters {
            environment,
            area: area_lights,
            delta,
        };
        let lights = Lights::new(emitters, count, radius.max(1e-3) as f64);
        let (width, height) = description.resolution;
        Ok(World {
            geometry,
            lights,
            surfaces: surfaces.per_shape,
            camera: Camera::new(&description.camera, width, height),
            resolution: description.resolution,
            filter: description.filter,
            sample_count: description.sample_count,
            description,
            warnings,
        })
    }
}

/// A mesh file's mesh, with v unflipped for an OBJ that says `flip_tex_coords = false` (the
/// OBJ reader flips it, as Mitsuba does by default).
fn mesh_file(
    path: &std::path::Path,
    format: scene::MeshFormat,
    flip_tex_coords: bool,
    warnings: &mut Vec<String>,
) -> Result<TriangleMesh, InputError> {
    let mut loaded = load_mesh(path, format)?;
    warnings.extend(loaded.warnings);
    if format == scene::MeshFormat::Obj && !flip_tex_coords {
        for t in loaded.mesh.texcoords.iter_mut().flatten() {
            t.y = 1.0 - t.y;
        }
    }
    Ok(loaded.mesh)
}

/// A mesh as an area light: a rectangle (Mitsuba's `rectangle` shape, edges still
/// orthogonal after `to_world`) is sampled by solid angle, anything else by area.
pub fn area_light(
    mesh: &TriangleMesh,
    is_rectangle: bool,
    flip_normals: bool,
    emission: Emission,
    shape_index: u32,
) -> AreaLight {
    if is_rectangle && mesh.positions.len() == 4 {
        let p = &mesh.positions;
        if let Some(rectangle) = Rectangle::new(p[0], p[1] - p[0], p[3] - p[0], flip_normals) {
            return AreaLight {
                shape: AreaShape::Rectangle(rectangle),
                radiance: emission.radiance,
                texture: emission.texture,
                shape_index,
            };
        }
    }
    // Texture coordinates per triangle, in the light's order, only where a texture reads them.
    let texcoords = (emission.texture.as_ref().zip(mesh.texcoords.as_ref())).map(|(_, uv)| {
        (mesh.triangles.iter())
            .map(|triangle| triangle.map(|i| uv[i as usize]))
            .map(|[a, b, c]| if flip_normals { [a, c, b] } else { [a, b, c] })
            .collect()
    });
    AreaLight {
        shape: AreaShape::Triangles(Box::new(MeshEmitter::new(
            emitting_triangles(mesh, flip_normals),
            texcoords,
        ))),
        radiance: emission.radiance,
        texture: emission.texture,
        shape_index,
    }
}

/// The triangles of a mesh as a light, wound toward the emitting side.
pub fn emitting_triangles(mesh: &TriangleMesh, flip_normals: bool) -> Vec<Triangle> {
    mesh.triangles
        .iter()
        .enumerate()
        .map(|(index, &[a, b, c])| {
            let (a, b, c) = if flip_normals { (a, c, b) } else { (a, b, c) };
            Triangle {
                vertices: [a, b, c].map(|i| mesh.positions[i as usize]),
                mesh: 0,
                index: index as u32,
            }
        })
        .collect()
}
