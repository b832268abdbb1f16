//! Binary glTF (GLB) meshes, through the gltf crate. Draco-compressed files
//! (`KHR_draco_mesh_compression`) carry no plain vertices and are refused with a clear error.

use super::TriangleMesh;
use crate::error::InputError;
use glam::{Mat4, Vec3};
use std::path::Path;

/// Reads every triangle primitive of the default scene's nodes, with node transforms applied.
pub fn read(path: &Path) -> Result<TriangleMesh, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::new(path, format!("cannot read GLB: {e}")))?;
    let gltf = gltf::Gltf::from_slice(&bytes)
        .map_err(|e| InputError::new(path, format!("cannot read GLB: {e}")))?;
    for extension in gltf.extensions_required() {
        if extension == "KHR_draco_mesh_compression" {
            return Err(InputError::new(
                path,
                "the GLB is Draco-compressed (KHR_draco_mesh_compression), which ais cannot decode; \
                 decompress it first (e.g. `npx gltf-transform copy in.glb out.glb`)",
            ));
        }
        if extension == "EXT_meshopt_compression" || extension == "KHR_mesh_quantization" {
            return Err(InputError::new(
                path,
                format!("the GLB requires {extension}, which ais does not support"),
            ));
        }
    }
    let blob = gltf.blob.as_deref();
    let mut mesh = TriangleMesh::default();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut all_have_normals = true;
    let scene = gltf
        .default_scene()
        .or_else(|| gltf.scenes().next())
        .ok_or_else(|| InputError::new(path, "the GLB has no scene"))?;
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let transform = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        stack.extend(node.children().map(|c| (c, transform)));
        let Some(gltf_mesh) = node.mesh() else {
            continue;
        };
        let normal_matrix = transform.inverse().transpose();
        for primitive in gltf_mesh.primitives() {
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                return Err(InputError::new(
                    path,
                    format!(
                        "mesh {} has a {:?} primitive; only triangles are supported",
                        gltf_mesh.index(),
                        primitive.mode()
                    ),
                ));
            }
            let reader = primitive.reader(|buffer| match buffer.source() {
                gltf::buffer::Source::Bin => blob,
                gltf::buffer::Source::Uri(_) => None,
            });
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| {
                    InputError::new(path, "a primitive has no readable POSITION data (external or compressed buffers are not supported)")
                })?
                .map(|p| transform.transform_point3(Vec3::from(p)))
                .collect();
            let base = mesh.positions.len() as u32;
            match reader.read_normals() {
                Some(n) if all_have_normals => normals.extend(n.map(|n| {
                    normal_matrix
                        .transform_vector3(Vec3::from(n))
                        .normalize_or_zero()
                })),
                _ => all_have_normals = false,
            }
            let count = positions.len() as u32;
            mesh.positions.extend(positions);
            match reader.read_indices() {
                Some(indices) => {
                    let indices: Vec<u32> = indices.into_u32().collect();
                    mesh.triangles.extend(
                        indices
                            .chunks_exact(3)
                            .map(|t| [base + t[0], base + t[1], base + t[2]]),
                    );
                }
                None => mesh.triangles.extend(
                    (0..count / 3).map(|t| [base + 3 * t, base + 3 * t + 1, base + 3 * t + 2]),
                ),
            }
        }
    }
    if all_have_normals && normals.len() == mesh.positions.len() && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    Ok(mesh)
}
