//! Stanford PLY (ASCII and binary), through ply-rs-bw.

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
    Ok(())
}

/// The `face` element's polygons, fanned into triangles.
fn read_faces(
    path: &Path,
    faces: &[DefaultElement],
    mesh: &mut TriangleMesh,
) -> Result<(), InputError> {
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
    }
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
