//! Mitsuba's `serialized` mesh format: one or more shapes, each a zlib stream behind a
//! 4-byte header, and a table of where each shape starts at the end of the file.
//!
//! A shape's header is the format identifier 0x041C and the version (3 or 4), both u16. Its
//! stream holds a u32 of flags, a NUL-terminated name (version 4 only), the vertex and
//! triangle counts (u64), then positions, normals (flag 0x0001), texture coordinates (flag
//! 0x0002) and vertex colours (flag 0x0008), in single (flag 0x1000) or double (0x2000)
//! precision, then the triangles' vertex indices (u32, or u64 beyond 2³² vertices). Flag
//! 0x0010 asks for face normals. The file ends with each shape's offset (u64 in version 4,
//! u32 in version 3) and the shape count (u32). Everything is little-endian.

use super::TriangleMesh;
use crate::error::InputError;
use flate2::read::ZlibDecoder;
use glam::{Vec2, Vec3};
use std::io::Read;
use std::path::Path;

const FORMAT_ID: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE_PRECISION: u32 = 0x1000;
const DOUBLE_PRECISION: u32 = 0x2000;

/// The most vertices or triangles a shape may declare (far beyond any scene that fits in
/// memory; a bound so that a corrupt count is an error, not an allocation failure).
const MOST_ELEMENTS: u64 = 1 << 32;

/// Reads shape `shape_index` of a serialized file.
pub fn read(path: &Path, shape_index: u32) -> Result<TriangleMesh, InputError> {
    let bytes = std::fs::read(path)
        .map_err(|e| InputError::new(path, format!("cannot read serialized mesh: {e}")))?;
    let error = |message: String| InputError::new(path, message);
    let (start, end) = shape_range(&bytes, shape_index).map_err(error)?;
    let version = u16::from_le_bytes([bytes[start + 2], bytes[start + 3]]);
    let stream = ZlibDecoder::new(&bytes[start + 4..end]);
    parse_shape(stream, version).map_err(|message| error(format!("shape {shape_index}: {message}")))
}

/// Where shape `index` lies in the file: from its header to the next shape (or the table).
fn shape_range(bytes: &[u8], index: u32) -> Result<(usize, usize), String> {
    if bytes.len() < 8 {
        return Err("the file is too short to be a serialized mesh".into());
    }
    let id = u16::from_le_bytes([bytes[0], bytes[1]]);
    let version = u16::from_le_bytes([bytes[2], bytes[3]]);
    if id != FORMAT_ID || !(3..=4).contains(&version) {
        return Err(format!(
            "not a serialized mesh (header {id:#06x}, version {version}; expected {FORMAT_ID:#06x}, 3 or 4)"
        ));
    }
    let count = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().expect("4 bytes")) as u64;
    let width: u64 = if version == 4 { 8 } else { 4 };
    let table_size = count * width + 4;
    if count == 0 || table_size > bytes.len() as u64 {
        return Err(format!(
            "the shape table at the end of the file is corrupt ({count} shapes)"
        ));
    }
    if index as u64 >= count {
        return Err(format!(
            "shape_index {index} is out of range: the file has {count} shape(s)"
        ));
    }
    let table = bytes.len() - table_size as usize;
    let offset = |i: u64| -> u64 {
        let at = table + (i * width) as usize;
        if width == 8 {
            u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
        } else {
            u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as u64
        }
    };
    let start = offset(index as u64);
    let end = if (index as u64) + 1 < count {
        offset(index as u64 + 1)
    } else {
        table as u64
    };
    if start + 4 > end || end > table as u64 {
        return Err(format!("the offsets of shape {index} are corrupt"));
    }
    Ok((start as usize, end as usize))
}

/// A shape's decompressed stream, read as it is needed.
struct Stream<R: Read> {
    reader: R,
}

impl<R: Read> Stream<R> {
    fn bytes<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut buffer = [0u8; N];
        self.reader
            .read_exact(&mut buffer)
            .map_err(|e| format!("the compressed data ends early or is corrupt ({e})"))?;
        Ok(buffer)
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.bytes()?))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.bytes()?))
    }

    fn real(&mut self, double: bool) -> Result<f32, String> {
        Ok(if double {
            f64::from_le_bytes(self.bytes()?) as f32
        } else {
            f32::from_le_bytes(self.bytes()?)
        })
    }

    /// `count` tuples of `N` reals. The vector grows as data arrives, so a corrupt count
    /// ends in an error when the data does, not in a huge allocation.
    fn reals<const N: usize>(&mut self, count: u64, double: bool) -> Result<Vec<[f32; N]>, String> {
        let mut tuples = Vec::new();
        for _ in 0..count {
            let mut tuple = [0.0; N];
            for value in &mut tuple {
                *value = self.real(double)?;
            }
            tuples.push(tuple);
        }
        Ok(tuples)
    }

    /// A vertex index (u64 when the shape has more vertices than u32 counts).
    fn index(&mut self, wide: bool) -> Result<u32, String> {
        let value = if wide {
            self.u64()?
        } else {
            self.u32()? as u64
        };
        u32::try_from(value).map_err(|_| format!("vertex index {value} is too large"))
    }

    /// Skips the NUL-terminated name (at most 64 KiB).
    fn skip_name(&mut self) -> Result<(), String> {
        for _ in 0..65536 {
            if self.bytes::<1>()?[0] == 0 {
                return Ok(());
            }
        }
        Err("the shape's name is not terminated".into())
    }
}

/// The mesh in a shape's stream.
fn parse_shape(reader: impl Read, version: u16) -> Result<TriangleMesh, String> {
    let mut stream = Stream { reader };
    let flags = stream.u32()?;
    let double = flags & DOUBLE_PRECISION != 0;
    if double == (flags & SINGLE_PRECISION != 0) {
        return Err(format!(
            "flags {flags:#x} give no single precision (0x1000) or double (0x2000)"
        ));
    }
    if version == 4 {
        stream.skip_name()?;
    }
    let (vertices, triangles) = (stream.u64()?, stream.u64()?);
    if vertices > MOST_ELEMENTS || triangles > MOST_ELEMENTS {
        return Err(format!(
            "{vertices} vertices and {triangles} triangles are more than ais reads"
        ));
    }
    let mut mesh = TriangleMesh {
        positions: stream
            .reals::<3>(vertices, double)?
            .into_iter()
            .map(Vec3::from)
            .collect(),
        ..TriangleMesh::default()
    };
    if flags & HAS_NORMALS != 0 {
        let normals = stream.reals::<3>(vertices, double)?;
        if flags & FACE_NORMALS == 0 {
            mesh.normals = Some(normals.into_iter().map(Vec3::from).collect());
        }
    }
    if flags & HAS_TEXCOORDS != 0 {
        let texcoords = stream.reals::<2>(vertices, double)?;
        mesh.texcoords = Some(texcoords.into_iter().map(Vec2::from).collect());
    }
    if flags & HAS_COLORS != 0 {
        stream.reals::<3>(vertices, double)?;
    }
    let wide = vertices > u32::MAX as u64;
    for _ in 0..triangles {
        let triangle = [
            stream.index(wide)?,
            stream.index(wide)?,
            stream.index(wide)?,
        ];
        mesh.triangles.push(triangle);
    }
    Ok(mesh)
}
