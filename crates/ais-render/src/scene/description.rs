//! The typed scene description: what the renderer needs from a Mitsuba XML file.

use super::file_resolver::FileResolver;
use super::properties::Plugin;
use super::xml;
use crate::error::InputError;
use crate::film::ReconstructionFilter;
use glam::{DMat4, DVec3};
use std::path::{Path, PathBuf};

/// Which image axis the field of view spans (Mitsuba's `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FovAxis {
    /// Horizontal.
    X,
    /// Vertical.
    Y,
    /// The diagonal.
    Diagonal,
    /// The shorter side.
    Smaller,
    /// The longer side.
    Larger,
}

/// How a camera projects the scene onto the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    /// A pinhole at the camera's origin (Mitsuba's `perspective`).
    Perspective,
    /// Parallel rays along the camera's +z from the rectangle [−1, 1] × [−1/aspect,
    /// 1/aspect] of its xy plane, before `to_world` (Mitsuba's `orthographic`).
    Orthographic,
}

/// A thin lens in front of a perspective camera (Mitsuba's `thinlens`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// The lens's radius, in world units.
    pub aperture_radius: f64,
    /// The distance of the plane in focus.
    pub focus_distance: f64,
}

/// A camera.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDescription {
    /// Camera to world (Mitsuba's convention: +z forward, +y up, +x left).
    pub to_world: DMat4,
    /// Perspective or orthographic.
    pub projection: Projection,
    /// Field of view in degrees (perspective).
    pub fov_degrees: f64,
    /// The axis `fov_degrees` spans (perspective).
    pub fov_axis: FovAxis,
    /// A thin lens (perspective; None: a pinhole).
    pub lens: Option<ThinLens>,
}

/// The mesh file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// Stanford PLY (ASCII or binary).
    Ply,
    /// Binary glTF (our extension to Mitsuba's format).
    Glb,
    /// Mitsuba's serialized format: the shape at `shape_index` in the file.
    Serialized {
        /// Which shape of the file.
        shape_index: u32,
    },
}

/// A `cylinder`: radius 1 from (0, 0, 0) to (0, 0, 1) unless told otherwise.
fn cylinder(shape: &Plugin) -> Result<ShapeGeometry, (u32, String)> {
    let radius = shape.float("radius", 1.0)?;
    let (p0, p1) = (
        shape.point("p0", DVec3::ZERO)?,
        shape.point("p1", DVec3::Z)?,
    );
    if !(radius > 0.0 && radius.is_finite()) {
        return Err((
            shape.line,
            format!("cylinder radius must be positive, got {radius}"),
        ));
    }
    if !(p0.is_finite() && p1.is_finite()) || p0 == p1 {
        return Err((
            shape.line,
            "cylinder p0 and p1 must be finite and distinct".into(),
        ));
    }
    Ok(ShapeGeometry::Cylinder { p0, p1, radius })
}

/// The geometry of a shape.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    /// A sphere (before `to_world`).
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
    },
    /// The square [-1, 1]² at z = 0, normal +z.
    Rectangle,
    /// The unit disk at z = 0, normal +z.
    Disk,
    /// The cube [-1, 1]³.
    Cube,
    /// An open cylinder (no caps) of `radius` around the segment from `p0` to `p1`.
    Cylinder {
        /// Centre of one end.
        p0: DVec3,
        /// Centre of the other end.
        p1: DVec3,
        /// Radius.
        radius: f64,
    },
    /// A mesh file.
    Mesh {
        /// Resolved path.
        path: PathBuf,
        /// Its format.
        format: MeshFormat,
        /// Whether to flip v (an OBJ's `flip_tex_coords`, true by default as in Mitsuba).
        flip_tex_coords: bool,
    },
}

/// A shape with its transform, material and optional area emitter.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDescription {
    /// What it is.
    pub geometry: ShapeGeometry,
    /// Object to world.
    pub to_world: DMat4,
    /// Mitsuba's `flip_normals`.
    pub flip_normals: bool,
    /// Mitsuba's `face_normals`: ignore vertex normals.
    pub face_normals: bool,
    /// Index into [`SceneDescription::bsdfs`]; `None` means Mitsuba's default diffuse.
    pub bsdf: Option<usize>,
    /// A nested `area` emitter, carried for the lighting code.
    pub emitter: Option<Plugin>,
    /// Line of the `<shape>` element.
    pub line: u32,
}

/// Everything read from a scene file.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    /// The file it came from.
    pub file: PathBuf,
    /// The sensor.
    pub camera: CameraDescription,
    /// Film width and height in pixels.
    pub resolution: (u32, u32),
    /// The film's reconstruction filter (Mitsuba's default: a Gaussian of σ = ½ pixel).
    pub filter: ReconstructionFilter,
    /// The sampler's `sample_count` (samples per pixel).
    pub sample_count: u32,
    /// Shapes placed in the scene itself.
    pub shapes: Vec<ShapeDescription>,
    /// Shape groups, which instances place.
    pub shape_groups: Vec<super::instancing::ShapeGroup>,
    /// Instances of the shape groups.
    pub instances: Vec<super::instancing::InstanceDescription>,
    /// BSDFs (top-level with ids, and those nested in shapes), carried for the shading code.
    pub bsdfs: Vec<Plugin>,
    /// Top-level textures, which BSDFs reference by id.
    pub textures: Vec<Plugin>,
    /// Top-level films and samplers, which a sensor references by id, and top-level area
    /// emitters, which shapes reference by id.
    pub referable: Vec<Plugin>,
    /// Scene-level emitters (`envmap`, `constant`, …), carried for the lighting code.
    pub emitters: Vec<Plugin>,
    /// Where its relative file names point (`<path>` elements, then its folder).
    pub files: FileResolver,
    /// The integrator element, if any.
    pub integrator: Option<Plugin>,
    /// Non-fatal problems.
    pub warnings: Vec<String>,
}

impl SceneDescription {
    /// A scene of nothing, with Mitsuba's defaults for what a file leaves out: its default
    /// sensor (a 50 mm lens on a 36 × 24 mm sensor at the origin: 46.79° diagonally), a
    /// 768 × 576 film with the Gaussian
    /// filter, and 4 samples per pixel.
    pub fn empty(file: &Path, files: FileResolver) -> Self {
        SceneDescription {
            file: file.to_path_buf(),
            camera: CameraDescription {
                to_world: DMat4::IDENTITY,
                projection: Projection::Perspective,
                lens: None,
                fov_degrees: 2.0 * (36f64.hypot(24.0) / 100.0).atan().to_degrees(),
                fov_axis: FovAxis::Diagonal,
            },
            resolution: (768, 576),
            filter: ReconstructionFilter::MITSUBA_DEFAULT,
            sample_count: 4,
            shapes: Vec::new(),
            shape_groups: Vec::new(),
            instances: Vec::new(),
            bsdfs: Vec::new(),
            textures: Vec::new(),
            referable: Vec::new(),
            emitters: Vec::new(),
            integrator: None,
            warnings: Vec::new(),
            files,
        }
    }
}

/// Reads a Mitsuba 3 XML scene file. `overrides` set `$param` values (`-D name=value`).
pub fn load_scene(
    path: &Path,
    overrides: &[(String, String)],
) -> Result<SceneDescription, InputError> {
    crate::error::check_input_file(path, "scene file")?;
    let text = std::fs::read_to_string(path)
        .map_err(|e| InputError::new(path, format!("cannot read the scene: {e}")))?;
    parse_scene(path, &text, overrides)
}

/// [`load_scene`] on text already read; relative file names resolve through `<path>`
/// elements and `path`'s folder ([`FileResolver`]).
pub fn parse_scene(
    path: &Path,
    text: &str,
    overrides: &[(String, String)],
) -> Result<SceneDescription, InputError> {
    let parsed = xml::parse(path, text, overrides)?;
    let mut scene = SceneDescription {
        warnings: parsed.warnings,
        ..SceneDescription::empty(path, FileResolver::new(path, &parsed.paths))
    };
    let files = scene.files.clone();
    // BSDFs and textures first so that shapes may reference ones declared after them.
    collect_referenced(path, &parsed.plugins, &mut scene);
    let mut sensor_seen = false;
    for plugin in &parsed.plugins {
        if plugin.tag == "sensor" {
            if sensor_seen {
                return Err(InputError::at(
                    path,
                    plugin.line,
                    "only one <sensor> is supported",
                ));
            }
            sensor_seen = true;
        }
        read_top_level(path, &files, plugin, &mut scene)?;
    }
    if !sensor_seen {
        scene.warnings.push(format!(
            "{}: no <sensor>; using Mitsuba's default camera at the origin",
            path.display()
        ));
    }
    Ok(scene)
}

/// The top-level BSDFs, textures, films and samplers, which other plugins reference by id.
fn collect_referenced(path: &Path, plugins: &[Plugin], scene: &mut SceneDescription) {
    for plugin in plugins.iter().filter(|p| p.tag == "bsdf") {
        if plugin.id.is_none() {
            scene.warnings.push(format!(
                "{}:{}: a top-level <bsdf> without an id can never be used",
                path.display(),
                plugin.line
            ));
        }
        scene.bsdfs.push(plugin.clone());
    }
    let of = |tags: &[&str]| -> Vec<Plugin> {
        plugins
            .iter()
            .filter(|p| tags.contains(&p.tag.as_str()))
            .cloned()
            .collect()
    };
    scene.textures = of(&["texture"]);
    scene.referable = of(&["film", "sampler"]);
    scene.referable.extend(
        plugins
            .iter()
            .filter(|p| p.tag == "emitter" && p.kind == "area" && p.id.is_some())
            .cloned(),
    );
}

/// One top-level element other than a BSDF (read before the rest).
fn read_top_level(
    path: &Path,
    files: &FileResolver,
    plugin: &Plugin,
    scene: &mut SceneDescription,
) -> Result<(), InputError> {
    let at = |(line, message): (u32, String)| InputError::at(path, line, message);
    match plugin.tag.as_str() {
        "bsdf" | "texture" | "film" | "sampler" => {}
        "sensor" => read_sensor(path, plugin, scene).map_err(at)?,
        "shape" if plugin.kind == "shapegroup" => {
            super::instancing::read_shape_group(path, files, plugin, scene).map_err(at)?
        }
        "shape" if plugin.kind == "instance" => {
            let instance = super::instancing::read_instance(path, plugin, scene).map_err(at)?;
            scene.instances.push(instance);
        }
        "shape" => {
            let shape = read_shape(path, files, plugin, scene).map_err(at)?;
            scene.shapes.push(shape);
        }
        // Shapes reference it by id.
        "emitter" if plugin.kind == "area" && plugin.id.is_some() => {}
        "emitter" if plugin.kind == "area" => {
            return Err(InputError::at(
                path,
                plugin.line,
                "an area emitter must be nested in a <shape> or have an id that shapes reference",
            ))
        }
        "emitter" => scene.emitters.push(plugin.clone()),
        "integrator" => scene.integrator = Some(plugin.clone()),
        other => {
            return Err(InputError::at(
                path,
                plugin.line,
                format!("<{other}> is not allowed at scene level"),
            ))
        }
    }
    Ok(())
}

fn read_sensor(
    path: &Path,
    sensor: &Plugin,
    scene: &mut SceneDescription,
) -> Result<(), (u32, String)> {
    scene.camera = read_camera(path, sensor, &mut scene.warnings)?;
    // A film or sampler may be declared at scene level and referenced by id.
    let mut parts: Vec<&Plugin> = sensor.children.iter().collect();
    for (_, id, line) in &sensor.references {
        let found = scene
            .referable
            .iter()
            .find(|p| p.id.as_deref() == Some(id.as_str()));
        parts.push(found.ok_or((*line, format!("no <film> or <sampler> with id \"{id}\"")))?);
    }
    for child in parts {
        match child.tag.as_str() {
            "film" => {
                (scene.resolution, scene.filter) = read_film(path, child, &mut scene.warnings)?
            }
            "sampler" => {
                warn_unknown(path, child, &["sample_count", "seed"], &mut scene.warnings);
                let count = child.integer("sample_count", 4)?;
                if count < 1 {
                    return Err((
                        child.line,
                        format!("sample_count must be at least 1, got {count}"),
                    ));
                }
                scene.sample_count = count as u32;
            }
            other => return Err((child.line, format!("<{other}> is not allowed in a sensor"))),
        }
    }
    Ok(())
}

/// A perspective sensor's field of view: `fov` and `fov_axis`, or, as Mitsuba does without
/// a `fov`, the diagonal view of a 36 × 24 mm sensor behind a lens of `focal_length`
/// (default `50mm`).
pub(crate) fn read_fov(sensor: &Plugin) -> Result<(f64, FovAxis), (u32, String)> {
    let has_fov = sensor.properties.contains_key("fov");
    if has_fov && sensor.properties.contains_key("focal_length") {
        return Err((
            sensor.line,
            "give either \"fov\" or \"focal_length\", not both".into(),
        ));
    }
    if !has_fov {
        return Ok((focal_length_fov(sensor)?, FovAxis::Diagonal));
    }
    let fov = sensor.float("fov", 0.0)?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err((
            sensor.line,
            format!("fov must be in (0, 180) degrees, got {fov}"),
        ));
    }
    let fov_axis = match sensor.string("fov_axis")?.unwrap_or("x") {
        "x" => FovAxis::X,
        "y" => FovAxis::Y,
        "diagonal" => FovAxis::Diagonal,
        "smaller" => FovAxis::Smaller,
        "larger" => FovAxis::Larger,
        other => return Err((sensor.line, format!("unknown fov_axis \"{other}\""))),
    };
    Ok((fov, fov_axis))
}

/// The diagonal field of view, in degrees, of a 36 × 24 mm sensor behind a lens of the
/// sensor's `focal_length` (`50mm` by default; the `mm` is optional).
fn focal_length_fov(sensor: &Plugin) -> Result<f64, (u32, String)> {
    let text = sensor.string("focal_length")?.unwrap_or("50mm");
    let millimetres = text.strip_suffix("mm").unwrap_or(text).trim();
    match millimetres.parse::<f64>() {
        Ok(f) if f > 0.0 && f.is_finite() => {
            Ok(2.0 * (36f64.hypot(24.0) / (2.0 * f)).atan().to_degrees())
        }
        _ => Err((
            sensor.line,
            format!("focal_length \"{text}\" must be a positive length in mm, like \"50mm\""),
        )),
    }
}

/// The camera of a `perspective`, `thinlens` or `orthographic` sensor.
fn read_camera(
    path: &Path,
    sensor: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<CameraDescription, (u32, String)> {
    if sensor.kind == "orthographic" {
        warn_unknown(
            path,
            sensor,
            &["to_world", "near_clip", "far_clip"],
            warnings,
        );
        return Ok(CameraDescription {
            to_world: sensor.transform("to_world")?,
            projection: Projection::Orthographic,
            fov_degrees: 0.0,
            fov_axis: FovAxis::X,
            lens: None,
        });
    }
    if sensor.kind != "perspective" && sensor.kind != "thinlens" {
        return Err((
            sensor.line,
            format!(
                "sensor type \"{}\" is not supported (perspective, orthographic)",
                sensor.kind
            ),
        ));
    }
    let lens = (sensor.kind == "thinlens")
        .then(|| read_lens(sensor))
        .transpose()?;
    let (fov, fov_axis) = read_fov(sensor)?;
    let camera = CameraDescription {
        to_world: sensor.transform("to_world")?,
        projection: Projection::Perspective,
        lens,
        fov_degrees: fov,
        fov_axis,
    };
    const KNOWN: [&str; 8] = [
        "fov",
        "fov_axis",
        "to_world",
        "near_clip",
        "far_clip",
        "focus_distance",
        "aperture_radius",
        "focal_length",
    ];
    warn_unknown(path, sensor, &KNOWN, warnings);
    Ok(camera)
}

/// A `thinlens` sensor's lens: `aperture_radius` (required, as in Mitsuba) and
/// `focus_distance` (Mitsuba's default, 10,000).
fn read_lens(sensor: &Plugin) -> Result<ThinLens, (u32, String)> {
    if !sensor.properties.contains_key("aperture_radius") {
        return Err((
            sensor.line,
            "a thinlens sensor needs \"aperture_radius\"".into(),
        ));
    }
    let aperture_radius = sensor.float("aperture_radius", 0.0)?;
    let focus_distance = sensor.float("focus_distance", 10_000.0)?;
    if !(aperture_radius.is_finite() && aperture_radius >= 0.0) {
        return Err((sensor.line, "aperture_radius must be finite and ≥ 0".into()));
    }
    if !(focus_distance.is_finite() && focus_distance > 0.0) {
        return Err((sensor.line, "focus_distance must be positive".into()));
    }
    Ok(ThinLens {
        aperture_radius,
        focus_distance,
    })
}

/// The size and reconstruction filter of an `hdrfilm`.
fn read_film(
    path: &Path,
    film: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<((u32, u32), ReconstructionFilter), (u32, String)> {
    if film.kind != "hdrfilm" {
        return Err((
            film.line,
            format!("film type \"{}\" is not supported (use hdrfilm)", film.kind),
        ));
    }
    let width = film.integer("width", 768)?;
    let height = film.integer("height", 576)?;
    if !(1..=65536).contains(&width) || !(1..=65536).contains(&height) {
        return Err((
            film.line,
            format!("film size {width}×{height} is out of range"),
        ));
    }
    const KNOWN: [&str; 6] = [
        "width",
        "height",
        "pixel_format",
        "component_format",
        "file_format",
        "rfilter",
    ];
    warn_unknown(path, film, &KNOWN, warnings);
    if let Some(format) = film.string("component_format")?.filter(|f| *f != "float32") {
        warnings.push(format!(
            "{}:{}: component_format \"{format}\" is not supported; the EXR holds float32",
            path.display(),
            film.line
        ));
    }
    let mut filter = ReconstructionFilter::MITSUBA_DEFAULT;
    for child in film.children.iter().filter(|c| c.tag == "rfilter") {
        filter = read_filter(path, child, warnings)?;
    }
    Ok(((width as u32, height as u32), filter))
}

/// A film's `<rfilter>`: `box`, `tent` (`radius`, default 1) or `gaussian` (`stddev`,
/// default ½); any other type is replaced by Mitsuba's default Gaussian, with a warning.
fn read_filter(
    path: &Path,
    filter: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<ReconstructionFilter, (u32, String)> {
    let (read, known): (_, &[&str]) = match filter.kind.as_str() {
        "box" => (ReconstructionFilter::Box, &[]),
        "tent" => {
            let radius = positive_filter_size(filter, "radius", 1.0, 16.0)?;
            (ReconstructionFilter::Tent { radius }, &["radius"])
        }
        "gaussian" => {
            // Mitsuba cuts the Gaussian off at 4σ: a radius of at most 16 pixels.
            let stddev = positive_filter_size(filter, "stddev", 0.5, 4.0)?;
            (ReconstructionFilter::Gaussian { stddev }, &["stddev"])
        }
        other => {
            warnings.push(format!(
                "{}:{}: reconstruction filter \"{other}\" replaced by a Gaussian of σ = ½ \
                 pixel (Mitsuba's default)",
                path.display(),
                filter.line
            ));
            return Ok(ReconstructionFilter::MITSUBA_DEFAULT);
        }
    };
    warn_unknown(path, filter, known, warnings);
    Ok(read)
}

/// A filter's size property, in (0, `most`] pixels.
fn positive_filter_size(
    filter: &Plugin,
    name: &str,
    default: f64,
    most: f64,
) -> Result<f32, (u32, String)> {
    let value = filter.float(name, default)?;
    if !(value > 0.0 && value <= most) {
        return Err((
            filter.line,
            format!("rfilter {name} must lie in (0, {most}] pixels, got {value}"),
        ));
    }
    Ok(value as f32)
}

pub(super) fn read_shape(
    path: &Path,
    files: &FileResolver,
    shape: &Plugin,
    scene: &mut SceneDescription,
) -> Result<ShapeDescription, (u32, String)> {
    let (geometry, known) = shape_geometry(files, shape)?;
    warn_unknown(path, shape, known, &mut scene.warnings);
    let attached = attachments(shape, scene)?;
    Ok(ShapeDescription {
        geometry,
        to_world: shape.transform("to_world")?,
        flip_normals: shape.boolean("flip_normals", false)?,
        face_normals: shape.boolean("face_normals", false)?,
        bsdf: attached.bsdf,
        emitter: attached.emitter,
        line: shape.line,
    })
}

/// A shape's geometry and the property names its type knows.
fn shape_geometry(
    files: &FileResolver,
    shape: &Plugin,
) -> Result<(ShapeGeometry, &'static [&'static str]), (u32, String)> {
    let mesh = |format: MeshFormat| -> Result<ShapeGeometry, (u32, String)> {
        let name = shape.string("filename")?.ok_or((
            shape.line,
            format!("shape \"{}\" needs a \"filename\" string", shape.kind),
        ))?;
        Ok(ShapeGeometry::Mesh {
            path: files.resolve(name),
            format,
            flip_tex_coords: shape.boolean("flip_tex_coords", true)?,
        })
    };
    Ok(match shape.kind.as_str() {
        "sphere" => {
            let radius = shape.float("radius", 1.0)?;
            if !(radius > 0.0 && radius.is_finite()) {
                return Err((shape.line, format!("sphere radius must be positive, got {radius}")));
            }
            (
                ShapeGeometry::Sphere {
                    center: shape.point("center", DVec3::ZERO)?,
                    radius,
                },
                &["radius", "center", "to_world", "flip_normals"],
            )
        }
        "rectangle" => (ShapeGeometry::Rectangle, &["to_world", "flip_normals"]),
        "disk" => (ShapeGeometry::Disk, &["to_world", "flip_normals"]),
        "cube" => (ShapeGeometry::Cube, &["to_world", "flip_normals"]),
        "cylinder" => (cylinder(shape)?, &["radius", "p0", "p1", "to_world", "flip_normals"]),
        "obj" => (mesh(MeshFormat::Obj)?, &["filename", "to_world", "flip_normals", "face_normals", "flip_tex_coords"]),
        "ply" => (mesh(MeshFormat::Ply)?, &["filename", "to_world", "flip_normals", "face_normals"]),
        "glb" | "gltf" => (mesh(MeshFormat::Glb)?, &["filename", "to_world", "flip_normals", "face_normals"]),
        "serialized" => {
            let index = shape.integer("shape_index", 0)?;
            let shape_index = u32::try_from(index).map_err(|_| (shape.line, format!("shape_index must be a non-negative integer, got {index}")))?;
            (mesh(MeshFormat::Serialized { shape_index })?, &["filename", "to_world", "flip_normals", "face_normals", "shape_index"])
        }
        other => return Err((shape.line, format!("shape type \"{other}\" is not supported (obj, ply, serialized, glb, sphere, rectangle, disk, cube, cylinder)"))),
    })
}

/// What a shape carries: its BSDF (an index into the scene's BSDFs) and area emitter.
struct Attachments {
    bsdf: Option<usize>,
    emitter: Option<Plugin>,
}

/// A shape's BSDF (referenced or nested; nested ones join the scene's list) and emitter.
fn attachments(shape: &Plugin, scene: &mut SceneDescription) -> Result<Attachments, (u32, String)> {
    let mut attached = Attachments {
        bsdf: None,
        emitter: None,
    };
    for (_, id, line) in &shape.references {
        let bsdf = scene
            .bsdfs
            .iter()
            .position(|b| b.id.as_deref() == Some(id.as_str()));
        let emitter = || {
            scene
                .referable
                .iter()
                .find(|p| p.tag == "emitter" && p.id.as_deref() == Some(id.as_str()))
        };
        if let Some(index) = bsdf {
            if attached.bsdf.replace(index).is_some() {
                return Err((*line, "a shape can have only one bsdf".into()));
            }
        } else if let Some(emitter) = emitter() {
            if attached.emitter.replace(emitter.clone()).is_some() {
                return Err((*line, "a shape can have only one area emitter".into()));
            }
        } else {
            return Err((
                *line,
                format!("no <bsdf> or area <emitter> with id \"{id}\""),
            ));
        }
    }
    for child in &shape.children {
        match child.tag.as_str() {
            "bsdf" => {
                scene.bsdfs.push(child.clone());
                if attached.bsdf.replace(scene.bsdfs.len() - 1).is_some() {
                    return Err((child.line, "a shape can have only one bsdf".into()));
                }
            }
            "emitter" if child.kind == "area" => {
                if attached.emitter.replace(child.clone()).is_some() {
                    return Err((child.line, "a shape can have only one area emitter".into()));
                }
            }
            "emitter" => {
                return Err((
                    child.line,
                    format!(
                        "a shape can only carry an area emitter, not \"{}\"",
                        child.kind
                    ),
                ))
            }
            other => return Err((child.line, format!("<{other}> is not allowed in a shape"))),
        }
    }
    Ok(attached)
}

/// Warns of the properties of `plugin` that are not in `known`, naming file and line.
pub(crate) fn warn_unknown(
    path: &Path,
    plugin: &Plugin,
    known: &[&str],
    warnings: &mut Vec<String>,
) {
    for (name, line) in plugin.unknown_properties(known) {
        warnings.push(format!(
            "{}:{line}: property \"{name}\" of {} \"{}\" is ignored",
            path.display(),
            plugin.tag,
            plugin.kind
        ));
    }
}
