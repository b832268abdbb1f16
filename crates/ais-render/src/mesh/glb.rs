//! Binary glTF (GLB) meshes, through the gltf crate. Draco-compressed files
//! (`KHR_draco_mesh_compression`) carry no plain vertices and are refused with a clear error.

use super::TriangleMesh;
use crate::error::InputError;
use glam::{Mat4, Vec3};
use std::path::Path;

/// Refuses files that need an extension ais cannot decode.
fn check_extensions(path: &Path, gltf: &gltf::Gltf) -> Result<(), InputError> {
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
    Ok(())
}

/// The mesh being assembled from the file's primitives.
struct Assembly<'a> {
    path: &'a Path,
    blob: Option<&'a [u8]>,
    mesh: TriangleMesh,
    normals: Vec<Vec3>,
    all_have_normals: bool,
    /// glTF's texture coordinates already run down the image, as Mitsuba's do.
    texcoords: Vec<glam::Vec2>,
    all_have_texcoords: bool,
}

impl Assembly<'_> {
    /// Appends one triangle primitive under `transform`.
    fn add(
        &mut self,
        primitive: &gltf::Primitive,
        mesh_index: usize,
        transform: Mat4,
    ) -> Result<(), InputError> {
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            return Err(InputError::new(
                self.path,
                format!(
                    "mesh {mesh_index} has a {:?} primitive; only triangles are supported",
                    primitive.mode()
                ),
            ));
        }
        let blob = self.blob;
        let reader = primitive.reader(|buffer| match buffer.source() {
            gltf::buffer::Source::Bin => blob,
            gltf::buffer::Source::Uri(_) => None,
        });
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| {
                InputError::new(self.path, "a primitive has no readable POSITION data (external or compressed buffers are not supported)")
            })?
            .map(|p| transform.transform_point3(Vec3::from(p)))
            .collect();
        let base = self.mesh.positions.len() as u32;
        let normal_matrix = transform.inverse().transpose();
        match reader.read_normals() {
            Some(n) if self.all_have_normals => self.normals.extend(n.map(|n| {
                normal_matrix
                    .transform_vector3(Vec3::from(n))
                    .normalize_or_zero()
            })),
            _ => self.all_have_normals = false,
        }
        match reader.read_tex_coords(0) {
            Some(t) if self.all_have_texcoords => {
                self.texcoords.extend(t.into_f32().map(glam::Vec2::from))
            }
            _ => self.all_have_texcoords = false,
        }
        let count = positions.len() as u32;
        self.mesh.positions.extend(positions);
        let indices: Option<Vec<u32>> = reader.read_indices().map(|i| i.into_u32().collect());
        self.add_triangles(indices, base, count);
        Ok(())
    }

    /// Appends a primitive's triangles: from its `indices`, or (without them) its `count`
    /// vertices taken three by three; `base` is its first vertex in the mesh.
    fn add_triangles(&mut self, indices: Option<Vec<u32>>, base: u32, count: u32) {
        match indices {
            Some(indices) => self.mesh.triangles.extend(
                indices
                    .chunks_exact(3)
                    .map(|t| [base + t[0], base + t[1], base + t[2]]),
            ),
            None => self
                .mesh
                .triangles
                .extend((0..count / 3).map(|t| [base + 3 * t, base + 3 * t + 1, base + 3 * t + 2])),
        }
    }
}

/// Reads every triangle primitive of the default scene's nodes, with node transforms applied.
pub fn read(path: &Path) -> Result<TriangleMesh, InputError> {
    // The gltf crate panics on some malformed files (an accessor index out of range).
    crate::error::catch_panic(|| read_unguarded(path)).unwrap_or_else(|message| {
        Err(InputError::new(
            path,
            format!("the GLB is malformed (the glTF reader failed: {message})"),
        ))
    })
}

/// [`read`], which the gltf crate may make panic.
fn read_unguarded(path: &Path) -> Result<TriangleMesh, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::new(path, format!("cannot read GLB: {e}")))?;
    let gltf = gltf::Gltf::from_slice(&bytes)
        .map_err(|e| InputError::new(path, format!("cannot read GLB: {e}")))?;
    check_extensions(path, &gltf)?;
    let mut assembly = Assembly {
        path,
        blob: gltf.blob.as_deref(),
        mesh: TriangleMesh::default(),
        normals: Vec::new(),
        all_have_normals: true,
        texcoords: Vec::new(),
        all_have_texcoords: true,
    };
    let scene = gltf
        .default_scene()
        .or_else(|| gltf.scenes().next())
        .ok_or_else(|| InputError::new(path, "the GLB has no scene"))?;
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let transform = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        stack.extend(node.children().map(|c| (c, transform)));
        if let Some(gltf_mesh) = node.mesh() {
            for primitive in gltf_mesh.primitives() {
                assembly.add(&primitive, gltf_mesh.index(), transform)?;
            }
        }
    }
    let Assembly {
        mut mesh,
        normals,
        all_have_normals,
        texcoords,
        all_have_texcoords,
        ..
    } = assembly;
    if all_have_normals && normals.len() == mesh.positions.len() && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    if all_have_texcoords && texcoords.len() == mesh.positions.len() && !texcoords.is_empty() {
        mesh.texcoords = Some(texcoords);
    }
    Ok(mesh)
}
