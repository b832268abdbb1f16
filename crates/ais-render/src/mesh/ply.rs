//! Stanford PLY (ASCII and binary), through ply-rs-bw.

use super::attributes::{group_properties, MeshAttribute};
use super::TriangleMesh;
use crate::error::InputError;
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use std::path::Path;

fn scalar(element: &DefaultElement, name: &str) -> Option<f32> {
    element.get(name).and_then(Property::to_f32_lossy)
}

/// A vertex's texture coordinates, under any of the names PLY writers use.
fn texcoord(vertex: &DefaultElement) -> Option<Vec2> {
    [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ]
    .iter()
    .find_map(|(u, v)| Some(Vec2::new(scalar(vertex, u)?, scalar(vertex, v)?)))
}

/// The `vertex` element's positions, and its normals and texture coordinates if every
/// vertex has them.
fn read_vertices(
    path: &Path,
    vertices: &[DefaultElement],
    mesh: &mut TriangleMesh,
) -> Result<(), InputError> {
    let mut normals = Vec::with_capacity(vertices.len());
    let mut texcoords = Vec::with_capacity(vertices.len());
    for (index, vertex) in vertices.iter().enumerate() {
        let coordinate = |name| {
            scalar(vertex, name).ok_or_else(|| {
                InputError::new(
                    path,
                    format!("PLY vertex {index} has no numeric \"{name}\""),
                )
            })
        };
        mesh.positions.push(Vec3::new(
            coordinate("x")?,
            coordinate("y")?,
            coordinate("z")?,
        ));
        if let (Some(x), Some(y), Some(z)) = (
            scalar(vertex, "nx"),
            scalar(vertex, "ny"),
            scalar(vertex, "nz"),
        ) {
            normals.push(Vec3::new(x, y, z));
        }
        texcoords.extend(texcoord(vertex));
    }
    if normals.len() == mesh.positions.len() && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    if texcoords.len() == mesh.positions.len() && !texcoords.is_empty() {
        mesh.texcoords = Some(texcoords);
    }
    mesh.attributes = read_attributes("vertex_", vertices, |_| 1);
    Ok(())
}

/// The properties a vertex or face holds that are not its geometry.
const GEOMETRY: [&str; 16] = [
    "x",
    "y",
    "z",
    "nx",
    "ny",
    "nz",
    "u",
    "v",
    "s",
    "t",
    "texture_u",
    "texture_v",
    "texture_s",
    "texture_t",
    "vertex_indices",
    "vertex_index",
];

/// The attributes (named with `prefix`) that the elements' other numeric properties make,
/// each element's value repeated `repeats(element)` times.
fn read_attributes(
    prefix: &str,
    elements: &[DefaultElement],
    repeats: impl Fn(usize) -> usize,
) -> Vec<MeshAttribute> {
    let Some(first) = elements.first() else {
        return Vec::new();
    };
    let names: Vec<String> = (first.iter())
        .filter(|(name, value)| {
            !GEOMETRY.contains(&name.as_str()) && value.to_f32_lossy().is_some()
        })
        .map(|(name, _)| name.clone())
        .collect();
    let groups = group_properties(prefix, &names);
    (groups.into_iter())
        .map(|(name, indices)| {
            let mut values = Vec::new();
            for (index, element) in elements.iter().enumerate() {
                let value: Vec<f32> = (indices.iter())
                    .map(|&i| scalar(element, &names[i]).unwrap_or(0.0))
                    .collect();
                for _ in 0..repeats(index) {
                    values.extend_from_slice(&value);
                }
            }
            MeshAttribute {
                name,
                dimension: indices.len(),
                values,
            }
        })
        .collect()
}

/// The `face` element's polygons, fanned into triangles.
fn read_faces(
    path: &Path,
    faces: &[DefaultElement],
    mesh: &mut TriangleMesh,
) -> Result<(), InputError> {
    let mut fanned = Vec::with_capacity(faces.len());
    for (index, face) in faces.iter().enumerate() {
        let property = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .ok_or_else(|| {
                InputError::new(path, format!("PLY face {index} has no vertex_indices list"))
            })?;
        let list = property.to_u32_list().ok_or_else(|| {
            InputError::new(
                path,
                format!("PLY face {index} has a vertex index that is negative or not an integer"),
            )
        })?;
        if list.len() < 3 {
            return Err(InputError::new(
                path,
                format!("PLY face {index} has fewer than 3 vertices"),
            ));
        }
        for k in 1..list.len() - 1 {
            mesh.triangles.push([list[0], list[k], list[k + 1]]);
        }
        fanned.push(list.len() - 2);
    }
    let attributes = read_attributes("face_", faces, |face| fanned[face]);
    mesh.attributes.extend(attributes);
    Ok(())
}

/// Reads the `vertex` (x, y, z and optional nx, ny, nz) and `face` (vertex_indices or
/// vertex_index; polygons are fanned into triangles) elements.
pub fn read(path: &Path) -> Result<TriangleMesh, InputError> {
    let file = std::fs::File::open(path)
        .map_err(|e| InputError::new(path, format!("cannot open PLY: {e}")))?;
    let mut reader = std::io::BufReader::new(file);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut reader)
        .map_err(|e| InputError::new(path, format!("cannot read PLY: {e}")))?;
    let element = |name: &str| {
        ply.payload
            .get(name)
            .ok_or_else(|| InputError::new(path, format!("PLY has no \"{name}\" element")))
    };
    let mut mesh = TriangleMesh::default();
    read_vertices(path, element("vertex")?, &mut mesh)?;
    read_faces(path, element("face")?, &mut mesh)?;
    Ok(mesh)
}
