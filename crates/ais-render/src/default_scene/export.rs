//! The built-in default scene as a Mitsuba 3 scene folder: `default.xml`, the sculpture as a
//! binary PLY with vertex normals, and the sky as an EXR. Mitsuba 3 loads it unchanged, and
//! ais renders it as it renders the built-in scene, so both renderers can be timed and
//! compared on the same scene.

use super::{
    procedural_sky, valid_sculpture, CAMERA_FOV_X_DEGREES, CAMERA_ORIGIN, CAMERA_TARGET,
    GROUND_ALBEDO, GROUND_SCALE, PANEL_ORIGIN, PANEL_RADIANCE, PANEL_SCALE, PANEL_TARGET,
    SCULPTURE_ALBEDO, SKY_SIZE, SPHERE_LIGHTS,
};
use crate::atomic_write::write_atomically;
use crate::image_io::write_exr;
use crate::mesh::TriangleMesh;
use glam::{DVec3, Vec3};
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};
use std::fs::File;
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};

/// The scene file's name in the folder.
pub const SCENE_FILE: &str = "default.xml";
const SCULPTURE_FILE: &str = "sculpture.ply";
const SKY_FILE: &str = "sky.exr";

/// Writes the default scene into `folder` (created if missing) and returns the scene
/// file's path. Each file is written to a temporary name and renamed, so an existing
/// file is never left half-written.
pub fn write_mitsuba_scene(folder: &Path) -> Result<PathBuf, String> {
    std::fs::create_dir_all(folder)
        .map_err(|e| format!("cannot create {}: {e}", folder.display()))?;
    let sky = procedural_sky(SKY_SIZE.0, SKY_SIZE.1);
    write_exr(&folder.join(SKY_FILE), &sky).map_err(|e| e.to_string())?;
    let sculpture = folder.join(SCULPTURE_FILE);
    write_atomically(&sculpture, |temporary| {
        write_ply(temporary, &valid_sculpture())
    })
    .map_err(|e| format!("cannot write {}: {e}", sculpture.display()))?;
    let scene = folder.join(SCENE_FILE);
    write_atomically(&scene, |temporary| std::fs::write(temporary, scene_xml()))
        .map_err(|e| format!("cannot write {}: {e}", scene.display()))?;
    Ok(scene)
}

/// Writes `mesh` as a binary little-endian PLY with positions and vertex normals.
fn write_ply(path: &Path, mesh: &TriangleMesh) -> io::Result<()> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = Encoding::BinaryLittleEndian;
    let mut vertex = ElementDef::new("vertex".to_string());
    for name in ["x", "y", "z", "nx", "ny", "nz"] {
        let kind = PropertyType::Scalar(ScalarType::Float);
        vertex
            .properties
            .add(PropertyDef::new(name.to_string(), kind));
    }
    ply.header.elements.add(vertex);
    let mut face = ElementDef::new("face".to_string());
    let list = PropertyType::List(ScalarType::UChar, ScalarType::UInt);
    face.properties
        .add(PropertyDef::new("vertex_indices".to_string(), list));
    ply.header.elements.add(face);
    let normals = mesh.normals.as_deref().unwrap_or(&[]);
    let vertices = mesh.positions.iter().enumerate().map(|(i, p)| {
        let n = normals.get(i).copied().unwrap_or(Vec3::ZERO);
        let mut element = DefaultElement::new();
        for (name, value) in ["x", "y", "z", "nx", "ny", "nz"]
            .into_iter()
            .zip([p.x, p.y, p.z, n.x, n.y, n.z])
        {
            element.insert(name.to_string(), Property::Float(value));
        }
        element
    });
    ply.payload.insert("vertex".to_string(), vertices.collect());
    let faces = mesh.triangles.iter().map(|triangle| {
        let mut element = DefaultElement::new();
        let indices = Property::ListUInt(triangle.to_vec());
        element.insert("vertex_indices".to_string(), indices);
        element
    });
    ply.payload.insert("face".to_string(), faces.collect());
    let mut out = BufWriter::new(File::create(path)?);
    ply_rs_bw::writer::Writer::new().write_ply(&mut out, &mut ply)?;
    Ok(())
}

/// Three numbers as Mitsuba writes a point or a colour.
fn triple<T: std::fmt::Display>(x: T, y: T, z: T) -> String {
    format!("{x}, {y}, {z}")
}

/// A point in double precision, as Mitsuba reads it.
fn dvec(v: DVec3) -> String {
    triple(v.x, v.y, v.z)
}

/// A colour or a point in single precision, as Mitsuba reads it.
fn colour(v: Vec3) -> String {
    triple(v.x, v.y, v.z)
}

/// The scene file. Emitters carry Mitsuba's default diffuse BSDF, as the built-in scene's
/// do, so that both are the same scene.
fn scene_xml() -> String {
    format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<!-- ais's built-in default scene, written by `ais export-default`: a grooved sculpture of
     408,576 triangles on a ground plane, under a procedural sky with a sun, two sphere
     lights and a rectangle light. Direct light only. -->
<scene version="3.0.0">
    <default name="spp" value="4"/>
    <default name="res_x" value="640"/>
    <default name="res_y" value="360"/>

    <integrator type="direct"/>
{sensor}
    <emitter type="envmap">
        <string name="filename" value="{SKY_FILE}"/>
    </emitter>
{shapes}
</scene>
"#,
        sensor = sensor_xml(),
        shapes = shapes_xml(),
    )
}

/// The camera, with a box-filtered film as the built-in scene has.
fn sensor_xml() -> String {
    format!(
        r#"
    <sensor type="perspective">
        <float name="fov" value="{fov}"/>
        <string name="fov_axis" value="x"/>
        <transform name="to_world">
            <lookat origin="{origin}" target="{target}" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="$res_x"/>
            <integer name="height" value="$res_y"/>
            <rfilter type="box"/>
        </film>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
    </sensor>
"#,
        fov = CAMERA_FOV_X_DEGREES,
        origin = dvec(CAMERA_ORIGIN),
        target = dvec(CAMERA_TARGET),
    )
}

/// The sculpture, the ground, the rectangle light and the sphere lights.
fn shapes_xml() -> String {
    let spheres: String = SPHERE_LIGHTS
        .iter()
        .map(|light| {
            format!(
                r#"
    <shape type="sphere">
        <point name="center" value="{}"/>
        <float name="radius" value="{}"/>
        <bsdf type="diffuse"/>
        <emitter type="area"><rgb name="radiance" value="{}"/></emitter>
    </shape>"#,
                colour(light.center),
                light.radius,
                colour(light.radiance)
            )
        })
        .collect();
    format!(
        r#"
    <shape type="ply">
        <string name="filename" value="{SCULPTURE_FILE}"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="{sculpture_albedo}"/></bsdf>
    </shape>

    <shape type="rectangle">
        <transform name="to_world">
            <scale value="{GROUND_SCALE}"/>
            <rotate x="1" angle="-90"/>
            <translate y="-1"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="{ground_albedo}"/></bsdf>
    </shape>

    <shape type="rectangle">
        <transform name="to_world">
            <scale value="{PANEL_SCALE}"/>
            <lookat origin="{panel_origin}" target="{panel_target}" up="0, 1, 0"/>
        </transform>
        <bsdf type="diffuse"/>
        <emitter type="area"><rgb name="radiance" value="{panel_radiance}"/></emitter>
    </shape>
{spheres}"#,
        sculpture_albedo = colour(SCULPTURE_ALBEDO),
        ground_albedo = colour(GROUND_ALBEDO),
        panel_origin = dvec(PANEL_ORIGIN),
        panel_target = dvec(PANEL_TARGET),
        panel_radiance = colour(PANEL_RADIANCE),
    )
}
