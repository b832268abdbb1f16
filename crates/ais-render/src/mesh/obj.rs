//! Wavefront OBJ, through tobj.

use super::TriangleMesh;
use crate::error::InputError;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Refuses faces of fewer than three vertices, naming their line (tobj would turn them into
/// degenerate triangles, and the error would blame the geometry).
fn check_faces(path: &Path, bytes: &[u8]) -> Result<(), InputError> {
    for (number, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        if words.next() == Some(b"f".as_slice()) {
            let vertices = words.count();
            if vertices < 3 {
                return Err(InputError::at(
                    path,
                    number as u32 + 1,
                    format!("a face needs at least 3 vertices, this one has {vertices}"),
                ));
            }
        }
    }
    Ok(())
}

/// Reads every object of an OBJ file into one mesh (polygons are triangulated). The file is
/// read once; its materials are not needed.
pub fn read(path: &Path) -> Result<TriangleMesh, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::new(path, format!("cannot read OBJ: {e}")))?;
    check_faces(path, &bytes)?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut bytes.as_slice(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| InputError::new(path, format!("cannot read OBJ: {e}")))?;
    let mut mesh = TriangleMesh::default();
    let mut all_have_normals = true;
    let mut normals = Vec::new();
    let mut all_have_texcoords = true;
    let mut texcoords = Vec::new();
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if m.normals.len() == m.positions.len() && !m.normals.is_empty() {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        } else {
            all_have_normals = false;
        }
        if m.texcoords.len() / 2 == m.positions.len() / 3 && !m.texcoords.is_empty() {
            // Mitsuba flips v on import (OBJ's v runs up the image, Mitsuba's down).
            texcoords.extend(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0], 1.0 - t[1])),
            );
        } else {
            all_have_texcoords = false;
        }
        mesh.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    if all_have_normals && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    if all_have_texcoords && !texcoords.is_empty() {
        mesh.texcoords = Some(texcoords);
    }
    Ok(mesh)
}
