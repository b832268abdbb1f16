//! Scene-level emitters read from their plugins, with Mitsuba's parameters and defaults:
//! `envmap` and `constant` (the environment: at most one), and any number of `point`,
//! `spot` (with its texture), `projector` and `directional` lights.

use super::delta::Projector;
use super::{DeltaLight, Environment, EnvironmentMap, Spot};
use crate::bsdf::{parameter_texture, TextureScene};
use crate::error::InputError;
use crate::image_io::read_image;
use crate::scene::{self, ColourRole, FileResolver, Plugin};
use crate::texture::Texture;
use glam::{DMat3, DVec3, Vec3};
use std::path::Path;
use std::sync::Arc;

/// The emitter types a scene may hold outside shapes.
const SUPPORTED: &str =
    "envmap, constant, point, spot, projector, directional; area inside a shape";

/// The scene-level emitters of `scene`'s file: its environment and its delta lights.
pub(crate) fn scene_emitters(
    scene: &TextureScene,
    plugins: &[Plugin],
    warnings: &mut Vec<String>,
) -> Result<(Option<Environment>, Vec<DeltaLight>), InputError> {
    let (file, files) = (scene.file, scene.files);
    let mut environment_found: Option<Environment> = None;
    let mut delta = Vec::new();
    for plugin in plugins {
        let textured: &[&str] = match plugin.kind.as_str() {
            "spot" => &["texture"],
            "projector" => &["irradiance"],
            _ => &[],
        };
        refuse_nested(file, plugin, textured)?;
        match plugin.kind.as_str() {
            "point" | "directional" => delta.push(delta_light(file, plugin, warnings)?),
            "spot" => delta.push(spot(scene, plugin, warnings)?),
            "projector" => delta.push(projector(scene, plugin, warnings)?),
            _ if environment_found.is_some() => {
                return Err(InputError::at(
                    file,
                    plugin.line,
                    "only one envmap or constant emitter is supported per scene",
                ))
            }
            _ => environment_found = Some(environment(file, files, plugin, warnings)?),
        }
    }
    Ok((environment_found, delta))
}

/// Refuses an emitter with nested plugins other than those filling `allowed` (a textured
/// intensity, a spot's texture): they would otherwise be dropped without a word.
pub(crate) fn refuse_nested(
    file: &Path,
    plugin: &Plugin,
    allowed: &[&str],
) -> Result<(), InputError> {
    let refused = (plugin.children.iter()).find(|c| {
        !c.name
            .as_deref()
            .is_some_and(|name| allowed.contains(&name))
    });
    match refused {
        Some(child) => Err(InputError::at(
            file,
            child.line,
            format!(
                "a nested <{}> in a \"{}\" emitter is not supported (only an area light's \
                 radiance may be a texture)",
                child.tag, plugin.kind
            ),
        )),
        None => Ok(()),
    }
}

/// A `point`, `spot` or `directional` emitter.
fn delta_light(
    file: &Path,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<DeltaLight, InputError> {
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    let to_world = plugin.transform("to_world").map_err(at)?;
    let known: &[&str] = match plugin.kind.as_str() {
        "point" => &["intensity", "position", "to_world"],
        _ => &["irradiance", "direction", "to_world"],
    };
    scene::warn_unknown(file, plugin, known, warnings);
    match plugin.kind.as_str() {
        "point" => {
            let origin = to_world.transform_point3(DVec3::ZERO);
            let position = plugin.point("position", origin).map_err(at)?;
            Ok(DeltaLight::Point {
                position: finite_point(file, plugin, position)?,
                intensity: spectrum_property(file, plugin, "intensity")?,
            })
        }
        _ => {
            let along_z = to_world.transform_vector3(DVec3::Z);
            let travel = plugin.point("direction", along_z).map_err(at)?;
            let travel = finite_point(file, plugin, travel)?.normalize_or_zero();
            if travel == Vec3::ZERO {
                return Err(InputError::at(
                    file,
                    plugin.line,
                    "directional light has no direction",
                ));
            }
            Ok(DeltaLight::Directional {
                travel,
                irradiance: spectrum_property(file, plugin, "irradiance")?,
            })
        }
    }
}

/// A `spot` emitter: angles in degrees, the beam width three quarters of the cutoff unless
/// given, the axis along `to_world`'s +z, and the texture spread over the cone if it has one.
fn spot(
    scene: &TextureScene,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<DeltaLight, InputError> {
    let file = scene.file;
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    let known = ["intensity", "cutoff_angle", "beam_width", "to_world"];
    let frame = pinhole(file, plugin, &known, warnings)?;
    let cutoff = plugin.float("cutoff_angle", 20.0).map_err(at)?;
    let beam = plugin.float("beam_width", cutoff * 0.75).map_err(at)?;
    if !(cutoff.is_finite() && beam.is_finite() && cutoff > 0.0 && cutoff <= 180.0 && beam >= 0.0) {
        return Err(InputError::at(
            file,
            plugin.line,
            "spot angles must be finite, with 0 < cutoff_angle <= 180 and beam_width >= 0",
        ));
    }
    let texture = parameter_texture(plugin, "texture", scene, warnings)?;
    if texture.is_some() && cutoff >= 90.0 {
        let message = "a textured spot's cutoff_angle must be below 90 degrees";
        return Err(InputError::at(file, plugin.line, message));
    }
    Ok(DeltaLight::Spot(Spot {
        position: frame.position,
        intensity: spectrum_property(file, plugin, "intensity")?,
        to_local: frame.to_local.as_mat3(),
        cutoff_angle: cutoff.to_radians() as f32,
        beam_width: beam.min(cutoff).to_radians() as f32,
        texture: texture.map(Arc::new),
    }))
}

/// Where a spot or projector sits.
struct Pinhole {
    /// Its position.
    position: Vec3,
    /// World to its frame (the rotation and scale of `to_world`, inverted).
    to_local: DMat3,
    /// Its `to_world`.
    to_world: glam::DMat4,
}

/// The frame of a spot or projector, whose properties not in `known` are warned of: its
/// `to_world`, which must be invertible, with a finite origin.
fn pinhole(
    file: &Path,
    plugin: &Plugin,
    known: &[&str],
    warnings: &mut Vec<String>,
) -> Result<Pinhole, InputError> {
    scene::warn_unknown(file, plugin, known, warnings);
    let to_world = (plugin.transform("to_world"))
        .map_err(|(line, message)| InputError::at(file, line, message))?;
    let rotation = DMat3::from_mat4(to_world);
    if rotation.determinant().abs() < 1e-12 {
        let message = format!("{} to_world is singular", plugin.kind);
        return Err(InputError::at(file, plugin.line, message));
    }
    let position = to_world.transform_point3(DVec3::ZERO);
    Ok(Pinhole {
        position: finite_point(file, plugin, position)?,
        to_local: rotation.inverse(),
        to_world,
    })
}

/// A `projector`: its `irradiance` image (a texture, or a colour: a 1 × 1 image), `scale`,
/// and field of view (`fov` and `fov_axis`, or `focal_length`) over the image's aspect.
fn projector(
    scene: &TextureScene,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<DeltaLight, InputError> {
    let file = scene.file;
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    let known = [
        "irradiance",
        "scale",
        "to_world",
        "fov",
        "fov_axis",
        "focal_length",
    ];
    let Pinhole {
        position, to_world, ..
    } = pinhole(file, plugin, &known, warnings)?;
    let irradiance = match parameter_texture(plugin, "irradiance", scene, warnings)? {
        Some(texture) => texture,
        None => Texture::Constant(spectrum_property(file, plugin, "irradiance")?),
    };
    let aspect = match &irradiance {
        Texture::Bitmap(bitmap) => bitmap.image.width as f64 / bitmap.image.height as f64,
        _ => 1.0,
    };
    let (fov_degrees, fov_axis) = scene::read_fov(plugin).map_err(at)?;
    let camera = scene::CameraDescription {
        to_world: glam::DMat4::IDENTITY,
        projection: scene::Projection::Perspective,
        lens: None,
        fov_degrees,
        fov_axis,
    };
    let (half_x, half_y) = crate::camera::perspective_half(&camera, aspect);
    let scale = plugin.float("scale", 1.0).map_err(at)? as f32;
    if !(scale.is_finite() && scale >= 0.0) {
        let message = "projector scale must be finite and non-negative";
        return Err(InputError::at(file, plugin.line, message));
    }
    Ok(DeltaLight::Projector(Projector {
        position,
        to_local: to_world.inverse().as_mat4(),
        axis: to_world.transform_vector3(DVec3::Z).as_vec3(),
        half: glam::Vec2::new(half_x as f32, half_y as f32),
        irradiance: Arc::new(irradiance),
        scale,
    }))
}

/// A position or direction as f32, which must be finite.
fn finite_point(file: &Path, plugin: &Plugin, point: DVec3) -> Result<Vec3, InputError> {
    let point = point.as_vec3();
    if point.is_finite() {
        Ok(point)
    } else {
        Err(InputError::at(
            file,
            plugin.line,
            format!(
                "{} emitter: position or direction is not finite",
                plugin.kind
            ),
        ))
    }
}

/// An rgb or float spectrum property (radiance, intensity, irradiance), which must be finite
/// and non-negative; Mitsuba's default of 1 where it is not given.
pub(crate) fn spectrum_property(
    file: &Path,
    plugin: &Plugin,
    name: &str,
) -> Result<Vec3, InputError> {
    let value = plugin
        .colour(name, ColourRole::Emission)
        .map_err(|(line, message)| InputError::at(file, line, message))?
        // Mitsuba's default for every emitter.
        .unwrap_or(Vec3::ONE);
    if !value.is_finite() || value.min_element() < 0.0 {
        return Err(InputError::at(
            file,
            plugin.line,
            format!("{name} must be finite and non-negative"),
        ));
    }
    Ok(value)
}

/// A scene-level `envmap` or `constant` emitter.
fn environment(
    file: &Path,
    files: &FileResolver,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<Environment, InputError> {
    match plugin.kind.as_str() {
        "constant" => {
            scene::warn_unknown(file, plugin, &["radiance"], warnings);
            Ok(Environment::Constant(spectrum_property(
                file, plugin, "radiance",
            )?))
        }
        "envmap" => environment_map(file, files, plugin, warnings),
        other => Err(InputError::at(
            file,
            plugin.line,
            format!("emitter type \"{other}\" is not supported ({SUPPORTED})"),
        )),
    }
}

/// A scene-level `envmap`: the image found through `files`, scaled and rotated.
fn environment_map(
    file: &Path,
    files: &FileResolver,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<Environment, InputError> {
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    scene::warn_unknown(file, plugin, &["filename", "scale", "to_world"], warnings);
    let name = plugin
        .string("filename")
        .map_err(at)?
        .ok_or_else(|| InputError::at(file, plugin.line, "envmap needs a \"filename\""))?;
    let loaded = read_image(&files.resolve(name))?;
    warnings.extend(loaded.warning);
    let scale = plugin.float("scale", 1.0).map_err(at)? as f32;
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(InputError::at(
            file,
            plugin.line,
            "envmap scale must be finite and non-negative",
        ));
    }
    let mut image = loaded.image;
    for p in &mut image.pixels {
        *p = p.map(|c| c * scale);
    }
    if image
        .pixels
        .iter()
        .flatten()
        .any(|&c| c > crate::image_io::LARGEST_TEXEL)
    {
        return Err(InputError::at(
            file,
            plugin.line,
            format!(
                "envmap scale {scale:e} makes texels exceed {:e}",
                crate::image_io::LARGEST_TEXEL
            ),
        ));
    }
    let rotation = DMat3::from_mat4(plugin.transform("to_world").map_err(at)?);
    Ok(Environment::Map(Box::new(EnvironmentMap::new(
        image, rotation,
    ))))
}
