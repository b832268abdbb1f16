//! Triangle meshes and their readers (OBJ, PLY, GLB).

mod attributes;
mod glb;
mod obj;
mod ply;
mod serialized;

use crate::error::InputError;
use crate::scene::MeshFormat;
pub use attributes::{AttributeSite, MeshAttribute};
use glam::{DMat4, Vec3};
use std::path::Path;

/// An indexed triangle mesh with optional per-vertex shading normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex normals (same length as `positions`), if the file had them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates (same length as `positions`), if the file had them.
    pub texcoords: Option<Vec<glam::Vec2>>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Named per-vertex and per-face values (PLY's other properties).
    pub attributes: Vec<MeshAttribute>,
}

/// A mesh read from a file, with the problems found that did not stop the read.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The mesh, validated: finite positions, indices in range, no degenerate triangles.
    pub mesh: TriangleMesh,
    /// Non-fatal problems (e.g. degenerate triangles dropped), naming the file.
    pub warnings: Vec<String>,
}

/// Reads a mesh file of the given format.
pub fn load_mesh(path: &Path, format: MeshFormat) -> Result<LoadedMesh, InputError> {
    crate::error::check_input_file(path, "mesh file")?;
    let mesh = match format {
        MeshFormat::Obj => obj::read(path)?,
        MeshFormat::Ply => ply::read(path)?,
        MeshFormat::Glb => glb::read(path)?,
        MeshFormat::Serialized { shape_index } => serialized::read(path, shape_index)?,
    };
    validate(path, mesh)
}

/// Refuses non-finite or absurdly large positions and indices beyond the vertices.
fn check_positions_and_indices(path: &Path, mesh: &TriangleMesh) -> Result<(), InputError> {
    if let Some(index) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(InputError::new(
            path,
            format!("vertex {index} has a non-finite position"),
        ));
    }
    if let Some(index) = mesh
        .positions
        .iter()
        .position(|p| p.abs().max_element() > LARGEST_COORDINATE)
    {
        return Err(InputError::new(
            path,
            format!(
                "vertex {index} lies at {}, beyond ±{LARGEST_COORDINATE:e}: coordinates this \
                 large break the BVH's precision; scale the scene down",
                mesh.positions[index]
            ),
        ));
    }
    let count = mesh.positions.len() as u32;
    if let Some((t, _)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i >= count))
    {
        return Err(InputError::new(
            path,
            format!("triangle {t} refers to a vertex beyond the {count} vertices"),
        ));
    }
    Ok(())
}

/// Whether a per-vertex attribute, if present, has one finite value per vertex; one that
/// has not is removed (and false returned).
fn usable<T>(attribute: &mut Option<Vec<T>>, vertices: usize, finite: impl Fn(&T) -> bool) -> bool {
    let bad = attribute
        .as_ref()
        .is_some_and(|values| values.len() != vertices || !values.iter().all(&finite));
    if bad {
        *attribute = None;
    }
    !bad
}

/// Refuses attributes whose number of values does not match their elements.
fn check_attributes(path: &Path, mesh: &TriangleMesh) -> Result<(), InputError> {
    for attribute in &mesh.attributes {
        let elements = if attribute.per_face() {
            mesh.triangles.len()
        } else {
            mesh.positions.len()
        };
        if attribute.values.len() != elements * attribute.dimension {
            let message = format!(
                "attribute \"{}\" has {} values for {elements} elements of {}",
                attribute.name,
                attribute.values.len(),
                attribute.dimension
            );
            return Err(InputError::new(path, message));
        }
    }
    Ok(())
}

/// Keeps the triangles (and their face attributes) where `kept` says so.
fn keep_triangles(mesh: &mut TriangleMesh, kept: &[bool]) {
    let mut index = 0;
    mesh.triangles.retain(|_| {
        index += 1;
        kept[index - 1]
    });
    for attribute in mesh.attributes.iter_mut().filter(|a| a.per_face()) {
        let dimension = attribute.dimension;
        let mut values = Vec::with_capacity(attribute.values.len());
        for (chunk, keep) in attribute.values.chunks(dimension).zip(kept) {
            if *keep {
                values.extend_from_slice(chunk);
            }
        }
        attribute.values = values;
    }
}

/// The largest coordinate a scene may use, in world units: beyond it the BVH's single
/// precision bounds lose every digit of a typical triangle.
pub const LARGEST_COORDINATE: f32 = 1e12;

/// Checks a mesh: positions finite and within ±[`LARGEST_COORDINATE`], indices in range,
/// normals usable; degenerate triangles (zero area) are dropped with a warning; an empty
/// result is an error.
pub fn validate(path: &Path, mut mesh: TriangleMesh) -> Result<LoadedMesh, InputError> {
    let mut warnings = Vec::new();
    check_positions_and_indices(path, &mesh)?;
    let vertices = mesh.positions.len();
    if !usable(&mut mesh.normals, vertices, |n| n.is_finite()) {
        warnings.push(format!(
            "{}: vertex normals are incomplete or not finite; using face normals",
            path.display()
        ));
    }
    if !usable(&mut mesh.texcoords, vertices, |t| t.is_finite()) {
        warnings.push(format!(
            "{}: texture coordinates are incomplete or not finite; the mesh has none",
            path.display()
        ));
    }
    let before = mesh.triangles.len();
    let positions = &mesh.positions;
    let kept: Vec<bool> = (mesh.triangles.iter())
        .map(|&[a, b, c]| {
            let (a, b, c) = (
                positions[a as usize],
                positions[b as usize],
                positions[c as usize],
            );
            (b - a).cross(c - a).length_squared() > 0.0
        })
        .collect();
    check_attributes(path, &mesh)?;
    keep_triangles(&mut mesh, &kept);
    let bad: usize = (mesh.attributes.iter_mut())
        .flat_map(|attribute| attribute.values.iter_mut())
        .filter(|value| !value.is_finite())
        .map(|value| *value = 0.0)
        .count();
    if bad > 0 {
        warnings.push(format!(
            "{}: {bad} attribute value(s) were NaN or infinite and were set to 0",
            path.display()
        ));
    }
    let dropped = before - mesh.triangles.len();
    if dropped > 0 {
        warnings.push(format!(
            "{}: dropped {dropped} degenerate (zero-area) triangle(s) of {before}",
            path.display()
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(InputError::new(
            path,
            if before == 0 {
                "the mesh has no triangles".to_string()
            } else {
                "every triangle of the mesh is degenerate".to_string()
            },
        ));
    }
    Ok(LoadedMesh { mesh, warnings })
}

impl TriangleMesh {
    /// Applies an object-to-world transform; normals use the inverse transpose. With
    /// `face_normals` the vertex normals are discarded; with `flip_normals` they are negated
    /// (face normals are flipped by the geometry that uses the mesh).
    pub fn transformed(mut self, to_world: DMat4, face_normals: bool, flip_normals: bool) -> Self {
        let m = to_world.as_mat4();
        let normal_matrix = to_world.inverse().transpose().as_mat4();
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        if face_normals {
            self.normals = None;
        }
        if let Some(normals) = &mut self.normals {
            for n in normals.iter_mut() {
                let t = normal_matrix.transform_vector3(*n).normalize_or_zero();
                *n = if flip_normals { -t } else { t };
            }
        }
        self
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let (a, b, c) = (
                    self.positions[a as usize],
                    self.positions[b as usize],
                    self.positions[c as usize],
                );
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .sum()
    }
}
