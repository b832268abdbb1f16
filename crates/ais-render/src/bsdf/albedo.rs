//! A BSDF's albedo given by a texture: the `reflectance` of `diffuse` and the
//! `diffuse_reflectance` of `roughplastic` (also inside `twosided`), as a nested `<texture>`
//! or a `<ref>` to a top-level one. The material read by [`super::Material::from_plugin`]
//! keeps the constant default; [`super::Material::with_albedo`] puts the texture's value at a
//! hit in its place.

use super::Material;
use crate::error::InputError;
use crate::scene::{FileResolver, Plugin};
use crate::texture::{read_texture, Texture};
use glam::Vec3;
use std::path::Path;

/// What reading a texture needs from its scene.
pub struct TextureScene<'a> {
    /// The scene file, for errors and warnings.
    pub file: &'a Path,
    /// Where image file names point.
    pub files: &'a FileResolver,
    /// The scene's BSDFs, which a `twosided`'s reference names.
    pub bsdfs: &'a [Plugin],
    /// The scene's top-level textures, which references name.
    pub textures: &'a [Plugin],
}

/// The parameter of a BSDF type that a texture may give.
pub(super) fn albedo_parameter(kind: &str) -> Option<&'static str> {
    match kind {
        "diffuse" => Some("reflectance"),
        "roughplastic" | "plastic" => Some("diffuse_reflectance"),
        _ => None,
    }
}

/// The texture that gives the albedo of the BSDF `plugin`, if one does.
pub fn albedo_texture(
    plugin: &Plugin,
    scene: &TextureScene,
    warnings: &mut Vec<String>,
) -> Result<Option<Texture>, InputError> {
    let mut current = plugin;
    // A twosided wraps one BSDF (nesting depth is checked when the material is read).
    for _ in 0..16 {
        if current.kind != "twosided" {
            break;
        }
        let nested = current.children.iter().find(|c| c.tag == "bsdf");
        let referenced = current.references.first().and_then(|(_, id, _)| {
            scene
                .bsdfs
                .iter()
                .find(|b| b.id.as_deref() == Some(id.as_str()))
        });
        match nested.or(referenced) {
            Some(inner) => current = inner,
            None => return Ok(None),
        }
    }
    let Some(parameter) = albedo_parameter(&current.kind) else {
        return Ok(None);
    };
    parameter_texture(current, parameter, scene, warnings)
}

/// The texture that gives `parameter` of `plugin`: a nested `<texture>` of that name, or a
/// `<ref>` of that name to a top-level one.
pub(crate) fn parameter_texture(
    plugin: &Plugin,
    parameter: &str,
    scene: &TextureScene,
    warnings: &mut Vec<String>,
) -> Result<Option<Texture>, InputError> {
    if let Some(child) = plugin
        .children
        .iter()
        .find(|c| c.tag == "texture" && c.name.as_deref() == Some(parameter))
    {
        return read_texture(scene.file, scene.files, child, warnings).map(Some);
    }
    let Some((_, id, line)) = plugin
        .references
        .iter()
        .find(|(name, _, _)| name.as_deref() == Some(parameter))
    else {
        return Ok(None);
    };
    let texture = scene
        .textures
        .iter()
        .find(|t| t.id.as_deref() == Some(id.as_str()))
        .ok_or_else(|| {
            InputError::at(scene.file, *line, format!("no <texture> with id \"{id}\""))
        })?;
    read_texture(scene.file, scene.files, texture, warnings).map(Some)
}

impl Material {
    /// This material with its albedo (a diffuse reflectance, or a rough plastic's base)
    /// replaced by `albedo`, as a texture gives it at a hit; other materials are unchanged.
    pub fn with_albedo(&self, albedo: Vec3) -> Material {
        let mut material = self.clone();
        let albedo = albedo.max(Vec3::ZERO).min(Vec3::ONE);
        match &mut material.scattering {
            super::Scattering::Diffuse { reflectance } => *reflectance = albedo,
            super::Scattering::RoughPlastic(plastic) => *plastic = plastic.with_diffuse(albedo),
            super::Scattering::Plastic(plastic) => *plastic = plastic.with_diffuse(albedo),
            super::Scattering::RoughConductor { .. }
            | super::Scattering::Conductor { .. }
            | super::Scattering::Dielectric(_)
            | super::Scattering::RoughDielectric(_) => {}
        }
        material
    }
}
