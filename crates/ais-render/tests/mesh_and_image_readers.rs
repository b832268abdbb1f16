//! Mesh and image readers on files the tests generate.

mod common;
mod serialized_files;

use ais_render::image_io::{read_image, write_exr, RgbImage};
use ais_render::mesh::load_mesh;
use ais_render::scene::MeshFormat;
use glam::Vec3;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("readers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn obj_with_normals_and_a_quad() {
    let path = scratch("quad.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n",
    )
    .unwrap();
    let loaded = load_mesh(&path, MeshFormat::Obj).unwrap();
    assert_eq!(loaded.mesh.triangles.len(), 2);
    assert!((loaded.mesh.area() - 1.0).abs() < 1e-6);
    assert!(loaded
        .mesh
        .normals
        .as_ref()
        .unwrap()
        .iter()
        .all(|&n| n == Vec3::Z));
}

#[test]
fn obj_errors_name_the_file() {
    let path = scratch("broken.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    let e = load_mesh(&path, MeshFormat::Obj).unwrap_err();
    assert!(e.to_string().contains("broken.obj"), "{e}");
    let missing = load_mesh(&scratch("missing.obj"), MeshFormat::Obj).unwrap_err();
    assert!(missing.to_string().contains("not found"), "{missing}");
    let empty = scratch("empty.obj");
    std::fs::write(&empty, "v 0 0 0\n").unwrap();
    assert!(load_mesh(&empty, MeshFormat::Obj)
        .unwrap_err()
        .to_string()
        .contains("no triangles"));
}

#[test]
fn degenerate_triangles_are_dropped_with_a_warning() {
    let path = scratch("degenerate.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n",
    )
    .unwrap();
    let loaded = load_mesh(&path, MeshFormat::Obj).unwrap();
    assert_eq!(loaded.mesh.triangles.len(), 1);
    assert!(
        loaded.warnings[0].contains("dropped 1 degenerate"),
        "{:?}",
        loaded.warnings
    );
    let all_bad = scratch("all_degenerate.obj");
    std::fs::write(&all_bad, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    let e = load_mesh(&all_bad, MeshFormat::Obj).unwrap_err();
    assert!(
        e.to_string()
            .contains("every triangle of the mesh is degenerate"),
        "{e}"
    );
}

#[test]
fn ply_ascii_and_binary() {
    let ascii = scratch("quad_ascii.ply");
    std::fs::write(
        &ascii,
        common::PLY_HEADER.replace("{FORMAT}", "ascii") + "0 0 0\n2 0 0\n2 2 0\n0 2 0\n4 0 1 2 3\n",
    )
    .unwrap();
    let loaded = load_mesh(&ascii, MeshFormat::Ply).unwrap();
    assert_eq!(loaded.mesh.triangles.len(), 2);
    assert!((loaded.mesh.area() - 4.0).abs() < 1e-6);

    let binary = scratch("quad_binary.ply");
    let mut bytes = common::PLY_HEADER
        .replace("{FORMAT}", "binary_little_endian")
        .into_bytes();
    for v in [
        [0.0f32, 0.0, 0.0],
        [3.0, 0.0, 0.0],
        [3.0, 3.0, 0.0],
        [0.0, 3.0, 0.0],
    ] {
        for c in v {
            bytes.extend(c.to_le_bytes());
        }
    }
    bytes.push(4);
    for i in [0i32, 1, 2, 3] {
        bytes.extend(i.to_le_bytes());
    }
    std::fs::write(&binary, bytes).unwrap();
    let loaded = load_mesh(&binary, MeshFormat::Ply).unwrap();
    assert!((loaded.mesh.area() - 9.0).abs() < 1e-6);

    let truncated = scratch("truncated.ply");
    std::fs::write(
        &truncated,
        common::PLY_HEADER.replace("{FORMAT}", "ascii") + "0 0 0\n",
    )
    .unwrap();
    let e = load_mesh(&truncated, MeshFormat::Ply).unwrap_err();
    assert!(e.to_string().contains("truncated.ply"), "{e}");
}

#[test]
fn ply_attributes_follow_fanned_and_dropped_faces() {
    let path = scratch("attributes.ply");
    let header = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n\
                  property float z\nproperty float r\nproperty float g\nproperty float b\n\
                  element face 2\nproperty list uchar int vertex_indices\nproperty float w_0\n\
                  end_header\n";
    let body = "0 0 0 1 0 0\n1 0 0 0 1 0\n1 1 0 0 0 1\n0 1 0 1e39 1 1\n2 2 2 1 1 1\n\
                4 0 1 2 3 0.25\n3 4 4 4 0.75\n";
    std::fs::write(&path, format!("{header}{body}")).unwrap();
    let loaded = load_mesh(&path, MeshFormat::Ply).unwrap();
    let mesh = &loaded.mesh;
    // The quad fans into two triangles that keep its weight; the degenerate face is dropped.
    assert_eq!(mesh.triangles.len(), 2);
    let names: Vec<&str> = mesh.attributes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["vertex_color", "face_w"]);
    assert_eq!(mesh.attributes[1].values, [0.25, 0.25]);
    // An infinite value becomes 0, with a warning.
    assert_eq!(mesh.attributes[0].values[9], 0.0);
    assert!(loaded
        .warnings
        .iter()
        .any(|w| w.contains("1 attribute value(s) were NaN")));
}

#[test]
fn glb_plain_and_draco() {
    let plain = scratch("triangle.glb");
    std::fs::write(&plain, common::glb(false)).unwrap();
    let loaded = load_mesh(&plain, MeshFormat::Glb).unwrap();
    assert_eq!(loaded.mesh.triangles.len(), 1);
    assert!(
        loaded.mesh.positions.iter().all(|p| p.z == 2.0),
        "node transform applied"
    );
    let draco = scratch("draco.glb");
    std::fs::write(&draco, common::glb(true)).unwrap();
    let e = load_mesh(&draco, MeshFormat::Glb).unwrap_err().to_string();
    assert!(
        e.contains("KHR_draco_mesh_compression") && e.contains("draco.glb"),
        "{e}"
    );
}

#[test]
fn exr_round_trip_and_sanitising() {
    let path = scratch("image.exr");
    let mut image = RgbImage::new(3, 2);
    image.pixels[4] = [1.5, 0.25, 8.0];
    write_exr(&path, &image).unwrap();
    let loaded = read_image(&path).unwrap();
    assert_eq!(loaded.image, image);
    assert!(loaded.warning.is_none());

    // A file with NaN, infinite and negative texels, written directly with the exr crate.
    let bad = scratch("bad.exr");
    exr::prelude::write_rgb_file(&bad, 2, 1, |x, _| match x {
        0 => (f32::NAN, -3894.0, 1.0),
        _ => (f32::INFINITY, 0.5, 2.0),
    })
    .unwrap();
    let loaded = read_image(&bad).unwrap();
    assert_eq!(loaded.image.pixels, vec![[0.0, 0.0, 1.0], [0.0, 0.5, 2.0]]);
    assert!(loaded.warning.unwrap().contains("3 texel channel(s)"));
}

#[test]
fn exr_writer_refuses_nan_and_keeps_the_old_file() {
    let path = scratch("keep.exr");
    let good = RgbImage::new(2, 2);
    write_exr(&path, &good).unwrap();
    let mut bad = RgbImage::new(2, 2);
    bad.pixels[1][0] = f32::NAN;
    let e = write_exr(&path, &bad).unwrap_err();
    assert!(e.to_string().contains("pixel (1, 0) is not finite"), "{e}");
    assert_eq!(read_image(&path).unwrap().image, good);
}

#[test]
fn radiance_hdr_is_read() {
    let path = scratch("image.hdr");
    let pixels = vec![image::Rgb([0.5f32, 1.0, 2.0]); 4];
    let file = std::fs::File::create(&path).unwrap();
    image::codecs::hdr::HdrEncoder::new(file)
        .encode(&pixels, 2, 2)
        .unwrap();
    let loaded = read_image(&path).unwrap();
    assert_eq!((loaded.image.width, loaded.image.height), (2, 2));
    assert!(loaded
        .image
        .pixels
        .iter()
        .all(|p| (p[2] - 2.0).abs() < 0.02 && (p[0] - 0.5).abs() < 0.01));
    let unknown = scratch("image.png");
    std::fs::write(&unknown, b"x").unwrap();
    assert!(read_image(&unknown)
        .unwrap_err()
        .to_string()
        .contains("unsupported image format"));
}

#[test]
fn a_glb_that_crashed_the_gltf_reader_gives_an_error() {
    // Found by tests/fuzz_readers.rs: a mutated GLB whose POSITION names a missing accessor
    // made the gltf crate panic (an index out of bounds in its validation).
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/accessor-out-of-range.glb");
    let error = load_mesh(&path, MeshFormat::Glb).unwrap_err();
    assert!(error.to_string().contains("malformed"), "{error}");
}

#[test]
fn malformed_files_are_named_for_what_is_wrong() {
    let obj = scratch("two.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n").unwrap();
    let e = load_mesh(&obj, MeshFormat::Obj).unwrap_err().to_string();
    assert!(
        e.contains("two.obj:4: a face needs at least 3 vertices"),
        "{e}"
    );

    let ply = scratch("negative.ply");
    let mut bytes = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".as_bytes().to_vec();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend(c.to_le_bytes());
    }
    bytes.push(3);
    for i in [0i32, -1, 2] {
        bytes.extend(i.to_le_bytes());
    }
    std::fs::write(&ply, bytes).unwrap();
    let e = load_mesh(&ply, MeshFormat::Ply).unwrap_err().to_string();
    assert!(e.contains("negative or not an integer"), "{e}");

    let luminance = scratch("luminance.exr");
    use exr::prelude::*;
    let channel = AnyChannel::new("Y", FlatSamples::F32(vec![1.0; 8]));
    let mut channels = SmallVec::new();
    channels.push(channel);
    Image::from_channels((4, 2), AnyChannels::sort(channels))
        .write()
        .to_file(&luminance)
        .unwrap();
    let e = read_image(&luminance).unwrap_err().to_string();
    assert!(e.contains("channels Y but no R, G or B"), "{e}");

    let huge = scratch("huge.exr");
    let image = RgbImage {
        width: 2,
        height: 1,
        pixels: vec![[3e38, 1.0, 1.0], [1.0, 1.0, 1.0]],
    };
    write_exr(&huge, &image).unwrap();
    let loaded = read_image(&huge).unwrap();
    assert_eq!(loaded.image.pixels[0], [0.0, 1.0, 1.0]);
    assert!(loaded.warning.unwrap().contains("above 1e20"));
}

#[test]
fn texture_coordinates_follow_mitsubas_readers() {
    // OBJ's v runs up the image and Mitsuba flips it on import; PLY's u, v (or s, t) are
    // taken as they are (both read from Mitsuba 3.9.1's own loaders on these files).
    let obj = scratch("uv.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.1 0.2\nvt 0.3 0.4\nvt 0.5 0.6\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let texcoords = load_mesh(&obj, MeshFormat::Obj).unwrap().mesh.texcoords;
    let expected = [(0.1, 0.8), (0.3, 0.6), (0.5, 0.4)].map(|(u, v)| glam::Vec2::new(u, v));
    let texcoords = texcoords.expect("the OBJ has texture coordinates");
    for (got, want) in texcoords.iter().zip(expected) {
        assert!((*got - want).length() < 1e-6, "{got} vs {want}");
    }
    let ply = scratch("uv.ply");
    let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nproperty float s\nproperty float t\nelement face 1\n\
                  property list uchar int vertex_indices\nend_header\n";
    std::fs::write(
        &ply,
        format!("{header}0 0 0 0.1 0.2\n1 0 0 0.3 0.4\n0 1 0 0.5 0.6\n3 0 1 2\n"),
    )
    .unwrap();
    let texcoords = load_mesh(&ply, MeshFormat::Ply)
        .unwrap()
        .mesh
        .texcoords
        .unwrap();
    assert!((texcoords[2] - glam::Vec2::new(0.5, 0.6)).length() < 1e-6);
}

#[test]
fn serialized_files_of_both_versions_and_precisions() {
    use serialized_files::{serialized, serialized_body};
    let square = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 2.0, 0.0],
        [0.0, 2.0, 0.0],
    ];
    let triangles = [[0, 1, 2], [0, 2, 3]];
    let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    for version in [3u16, 4] {
        let first = serialized_body(&square[..3], &triangles[..1], None, false, version);
        let second = serialized_body(&square, &triangles, Some(&uv), true, version);
        let path = scratch(&format!("shapes_v{version}.serialized"));
        std::fs::write(&path, serialized(&[first, second], version)).unwrap();
        let one = load_mesh(&path, MeshFormat::Serialized { shape_index: 0 }).unwrap();
        assert!((one.mesh.area() - 2.0).abs() < 1e-6, "version {version}");
        let two = load_mesh(&path, MeshFormat::Serialized { shape_index: 1 }).unwrap();
        assert!((two.mesh.area() - 4.0).abs() < 1e-6, "version {version}");
        assert_eq!(two.mesh.texcoords.unwrap()[2], glam::Vec2::ONE);
        let e = load_mesh(&path, MeshFormat::Serialized { shape_index: 2 }).unwrap_err();
        assert!(
            e.to_string()
                .contains("shape_index 2 is out of range: the file has 2 shape(s)"),
            "{e}"
        );
    }
}

#[test]
fn corrupt_serialized_files_are_refused_with_the_reason() {
    use serialized_files::{serialized, serialized_body};
    let body = serialized_body(
        &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2]],
        None,
        false,
        4,
    );
    let good = serialized(std::slice::from_ref(&body), 4);
    let mut wrong_header = good.clone();
    wrong_header[0] = 0;
    let mut short_body = body.clone();
    short_body.truncate(body.len() - 4);
    let mut huge_count = body.clone();
    huge_count[10..18].copy_from_slice(&u64::MAX.to_le_bytes());
    let mut no_precision = body;
    no_precision[1] = 0;
    let cases = [
        (wrong_header, "not a serialized mesh"),
        (good[..6].to_vec(), "too short"),
        (serialized(&[short_body], 4), "ends early or is corrupt"),
        (serialized(&[huge_count], 4), "more than ais reads"),
        (serialized(&[no_precision], 4), "no single precision"),
        (
            good[..good.len() - 1].to_vec(),
            "shape table at the end of the file is corrupt",
        ),
    ];
    let path = scratch("corrupt.serialized");
    for (bytes, expected) in cases {
        std::fs::write(&path, bytes).unwrap();
        let e = load_mesh(&path, MeshFormat::Serialized { shape_index: 0 }).unwrap_err();
        assert!(e.to_string().contains(expected), "want {expected}, got {e}");
        assert!(e.to_string().contains("corrupt.serialized"), "{e}");
    }
}
