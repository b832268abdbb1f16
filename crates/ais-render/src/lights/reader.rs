//! Scene-level emitters read from their plugins, with Mitsuba's parameters and defaults:
//! `envmap` and `constant` (the environment: at most one), and any number of `point`,
//! `spot` and `directional` lights.

use super::{DeltaLight, Environment, EnvironmentMap, Spot};
use crate::error::InputError;
use crate::image_io::read_image;
use crate::scene::{self, ColourRole, FileResolver, Plugin};
use glam::{DMat3, DVec3, Vec3};
use std::path::Path;

/// The emitter types a scene may hold outside shapes.
const SUPPORTED: &str = "envmap, constant, point, spot, directional; area inside a shape";

/// The scene-level emitters of a scene: its environment and its delta lights.
pub(crate) fn scene_emitters(
    file: &Path,
    files: &FileResolver,
    plugins: &[Plugin],
    warnings: &mut Vec<String>,
) -> Result<(Option<Environment>, Vec<DeltaLight>), InputError> {
    let mut environment_found: Option<Environment> = None;
    let mut delta = Vec::new();
    for plugin in plugins {
        refuse_nested(file, plugin, &[])?;
        match plugin.kind.as_str() {
            "point" | "spot" | "directional" => delta.push(delta_light(file, plugin, warnings)?),
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
        "spot" => &["intensity", "cutoff_angle", "beam_width", "to_world"],
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
        "spot" => spot(file, plugin, to_world),
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
/// given, the axis along `to_world`'s +z.
fn spot(file: &Path, plugin: &Plugin, to_world: glam::DMat4) -> Result<DeltaLight, InputError> {
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    let cutoff = plugin.float("cutoff_angle", 20.0).map_err(at)?;
    let beam = plugin.float("beam_width", cutoff * 0.75).map_err(at)?;
    if !(cutoff.is_finite() && beam.is_finite() && cutoff > 0.0 && cutoff <= 180.0 && beam >= 0.0) {
        return Err(InputError::at(
            file,
            plugin.line,
            "spot angles must be finite, with 0 < cutoff_angle <= 180 and beam_width >= 0",
        ));
    }
    let rotation = DMat3::from_mat4(to_world);
    if rotation.determinant().abs() < 1e-12 {
        return Err(InputError::at(
            file,
            plugin.line,
            "spot to_world is singular",
        ));
    }
    let position = to_world.transform_point3(DVec3::ZERO);
    Ok(DeltaLight::Spot(Spot {
        position: finite_point(file, plugin, position)?,
        intensity: spectrum_property(file, plugin, "intensity")?,
        to_local: rotation.inverse().as_mat3(),
        cutoff_angle: cutoff.to_radians() as f32,
        beam_width: beam.min(cutoff).to_radians() as f32,
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
