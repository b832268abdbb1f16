//! Textures on a BSDF's parameters, as Mitsuba accepts them: the albedo (`reflectance` of
//! `diffuse`, `diffuse_reflectance` of the plastics), `specular_reflectance` (conductors,
//! plastics, dielectrics), `specular_transmittance` (dielectrics) and the roughness `alpha`
//! (`roughconductor`, `roughdielectric`), a conductor's `eta` and `k`, the principled BSDFs'
//! weights, also inside `twosided`, as a nested `<texture>` or
//! a `<ref>` to a top-level one. The material read by [`super::Material::from_plugin`] keeps
//! the constant default; [`super::Material::set_parameter`] puts a texture's value at a hit
//! in its place.

use super::{Material, Scattering};
use crate::error::InputError;
use crate::scene::{FileResolver, Plugin};
use crate::texture::{read_texture, Texture};
use glam::Vec3;
use std::path::Path;
use std::sync::Arc;

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

/// A material parameter that a texture may give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexturedParameter {
    /// The diffuse albedo (colour).
    Albedo,
    /// The specular reflectance (colour).
    SpecularReflectance,
    /// The specular transmittance (colour).
    SpecularTransmittance,
    /// The microfacet roughness α (one channel).
    Roughness,
    /// The roughness along the tangent, α_u (one channel).
    RoughnessU,
    /// The roughness across the tangent, α_v (one channel).
    RoughnessV,
    /// A weight of the principled BSDF (one channel).
    Principled(PrincipledWeight),
    /// A conductor's index of refraction, real part (colour, unbounded).
    ConductorEta,
    /// A conductor's index of refraction, imaginary part (colour, unbounded).
    ConductorK,
}

/// The principled BSDF's one-channel parameters that textures may give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrincipledWeight {
    /// `roughness`.
    Roughness,
    /// `anisotropic`.
    Anisotropic,
    /// `metallic`.
    Metallic,
    /// `spec_trans`.
    SpecTrans,
    /// `spec_tint`.
    SpecTint,
    /// `sheen`.
    Sheen,
    /// `sheen_tint`.
    SheenTint,
    /// `flatness`.
    Flatness,
    /// `clearcoat`.
    Clearcoat,
    /// `clearcoat_gloss`.
    ClearcoatGloss,
    /// `diff_trans` of the thin sheet (from 0 to 2).
    DiffTrans,
}

impl TexturedParameter {
    /// Whether a texture gives it as one channel (a roughness) rather than a colour.
    pub fn is_scalar(self) -> bool {
        matches!(
            self,
            Self::Roughness | Self::RoughnessU | Self::RoughnessV | Self::Principled(_)
        )
    }
}

/// A texture on one parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterTexture {
    /// The parameter.
    pub parameter: TexturedParameter,
    /// Its texture.
    pub texture: Arc<Texture>,
}

/// The parameters of a BSDF type that textures may give, by property name.
pub(super) fn textured_parameters(kind: &str) -> &'static [(&'static str, TexturedParameter)] {
    use TexturedParameter::*;
    match kind {
        "diffuse" => &[("reflectance", Albedo)],
        "roughplastic" | "plastic" => &[
            ("diffuse_reflectance", Albedo),
            ("specular_reflectance", SpecularReflectance),
        ],
        "conductor" => &[
            ("specular_reflectance", SpecularReflectance),
            ("eta", ConductorEta),
            ("k", ConductorK),
        ],
        "pplastic" => &[
            ("diffuse_reflectance", Albedo),
            ("specular_reflectance", SpecularReflectance),
            ("alpha", Roughness),
            ("alpha_u", RoughnessU),
            ("alpha_v", RoughnessV),
        ],
        "roughconductor" => &[
            ("specular_reflectance", SpecularReflectance),
            ("eta", ConductorEta),
            ("k", ConductorK),
            ("alpha", Roughness),
            ("alpha_u", RoughnessU),
            ("alpha_v", RoughnessV),
        ],
        "principled" => &[
            ("base_color", Albedo),
            ("roughness", Principled(PrincipledWeight::Roughness)),
            ("anisotropic", Principled(PrincipledWeight::Anisotropic)),
            ("metallic", Principled(PrincipledWeight::Metallic)),
            ("spec_trans", Principled(PrincipledWeight::SpecTrans)),
            ("spec_tint", Principled(PrincipledWeight::SpecTint)),
            ("sheen", Principled(PrincipledWeight::Sheen)),
            ("sheen_tint", Principled(PrincipledWeight::SheenTint)),
            ("flatness", Principled(PrincipledWeight::Flatness)),
            ("clearcoat", Principled(PrincipledWeight::Clearcoat)),
            (
                "clearcoat_gloss",
                Principled(PrincipledWeight::ClearcoatGloss),
            ),
        ],
        "principledthin" => &[
            ("base_color", Albedo),
            ("roughness", Principled(PrincipledWeight::Roughness)),
            ("anisotropic", Principled(PrincipledWeight::Anisotropic)),
            ("spec_trans", Principled(PrincipledWeight::SpecTrans)),
            ("diff_trans", Principled(PrincipledWeight::DiffTrans)),
            ("spec_tint", Principled(PrincipledWeight::SpecTint)),
            ("sheen", Principled(PrincipledWeight::Sheen)),
            ("sheen_tint", Principled(PrincipledWeight::SheenTint)),
            ("flatness", Principled(PrincipledWeight::Flatness)),
        ],
        "dielectric" | "thindielectric" => &[
            ("specular_reflectance", SpecularReflectance),
            ("specular_transmittance", SpecularTransmittance),
        ],
        "roughdielectric" => &[
            ("specular_reflectance", SpecularReflectance),
            ("specular_transmittance", SpecularTransmittance),
            ("alpha", Roughness),
            ("alpha_u", RoughnessU),
            ("alpha_v", RoughnessV),
        ],
        _ => &[],
    }
}

/// The textures on the parameters of the BSDF `plugin` (through `twosided`).
pub fn material_textures(
    plugin: &Plugin,
    scene: &TextureScene,
    warnings: &mut Vec<String>,
) -> Result<Vec<ParameterTexture>, InputError> {
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
            None => return Ok(Vec::new()),
        }
    }
    let mut textures = Vec::new();
    for &(name, parameter) in textured_parameters(&current.kind) {
        if let Some(texture) = parameter_texture(current, name, scene, warnings)? {
            textures.push(ParameterTexture {
                parameter,
                texture: Arc::new(texture),
            });
        }
    }
    Ok(textures)
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
    /// Sets `parameter` to `value` (a colour, or for the roughness its first component), as
    /// a texture gives it at a hit. A parameter the material does not have is left alone.
    pub fn set_parameter(&mut self, parameter: TexturedParameter, value: Vec3) {
        use TexturedParameter::*;
        let colour = value.max(Vec3::ZERO);
        let albedo = colour.min(Vec3::ONE);
        match (&mut self.scattering, parameter) {
            (Scattering::Diffuse { reflectance }, Albedo) => *reflectance = albedo,
            (Scattering::RoughPlastic(plastic), Albedo) => *plastic = plastic.with_diffuse(albedo),
            (Scattering::Plastic(plastic), Albedo) => *plastic = plastic.with_diffuse(albedo),
            (Scattering::RoughPlastic(plastic), SpecularReflectance) => {
                *plastic = plastic.with_specular(colour)
            }
            (Scattering::Plastic(plastic), SpecularReflectance) => {
                *plastic = plastic.with_specular(colour)
            }
            (Scattering::PolarizedPlastic(plastic), Albedo) => {
                *plastic = plastic.with_diffuse(albedo)
            }
            (Scattering::PolarizedPlastic(plastic), SpecularReflectance) => {
                *plastic = plastic.with_specular(colour)
            }
            (Scattering::PolarizedPlastic(plastic), Roughness | RoughnessU | RoughnessV) => {
                plastic.microfacet = with_roughness(plastic.microfacet, parameter, value.x)
            }
            (
                Scattering::RoughConductor { specular, .. }
                | Scattering::Conductor { specular, .. },
                SpecularReflectance,
            ) => *specular = colour,
            (Scattering::Dielectric(d), SpecularReflectance) => d.reflectance = colour,
            (Scattering::Dielectric(d), SpecularTransmittance) => d.transmittance = colour,
            (Scattering::RoughDielectric(d), SpecularReflectance) => d.reflectance = colour,
            (Scattering::RoughDielectric(d), SpecularTransmittance) => d.transmittance = colour,
            (
                Scattering::RoughConductor { microfacet, .. },
                Roughness | RoughnessU | RoughnessV,
            ) => *microfacet = with_roughness(*microfacet, parameter, value.x),
            (Scattering::RoughDielectric(d), Roughness | RoughnessU | RoughnessV) => {
                d.microfacet = with_roughness(d.microfacet, parameter, value.x)
            }
            (
                Scattering::RoughConductor { eta, .. } | Scattering::Conductor { eta, .. },
                ConductorEta,
            ) => *eta = colour,
            (
                Scattering::RoughConductor { k, .. } | Scattering::Conductor { k, .. },
                ConductorK,
            ) => *k = colour,
            (Scattering::Principled(p), Albedo) => p.base_color = albedo,
            (Scattering::Principled(p), Principled(weight)) => {
                set_principled_weight(p, weight, value.x.clamp(0.0, 1.0))
            }
            (Scattering::PrincipledThin(p), Albedo) => p.base_color = albedo,
            (Scattering::PrincipledThin(p), Principled(weight)) => {
                set_thin_weight(p, weight, value.x)
            }
            _ => {}
        }
    }
}

/// Sets one of the principled BSDF's weights.
fn set_principled_weight(principled: &mut super::Principled, weight: PrincipledWeight, value: f32) {
    use PrincipledWeight::*;
    let field = match weight {
        Roughness => &mut principled.roughness,
        Anisotropic => &mut principled.anisotropic,
        Metallic => &mut principled.metallic,
        SpecTrans => &mut principled.spec_trans,
        SpecTint => &mut principled.spec_tint,
        Sheen => &mut principled.sheen,
        SheenTint => &mut principled.sheen_tint,
        Flatness => &mut principled.flatness,
        Clearcoat => &mut principled.clearcoat,
        ClearcoatGloss => &mut principled.clearcoat_gloss,
        DiffTrans => return,
    };
    *field = value;
}

/// Sets one of the thin principled BSDF's weights (`diff_trans` runs from 0 to 2; the others
/// from 0 to 1).
fn set_thin_weight(thin: &mut super::PrincipledThin, weight: PrincipledWeight, value: f32) {
    use PrincipledWeight::*;
    let unit = value.clamp(0.0, 1.0);
    match weight {
        Roughness => thin.roughness = unit,
        Anisotropic => thin.anisotropic = unit,
        SpecTrans => thin.spec_trans = unit,
        DiffTrans => thin.diffuse_transmission = value.clamp(0.0, 2.0) / 2.0,
        SpecTint => thin.spec_tint = unit,
        Sheen => thin.sheen = unit,
        SheenTint => thin.sheen_tint = unit,
        Flatness => thin.flatness = unit,
        Metallic | Clearcoat | ClearcoatGloss => {}
    }
}

/// `microfacet` with the roughness `parameter` (both, or one axis) set to `alpha`.
fn with_roughness(
    microfacet: super::Microfacet,
    parameter: TexturedParameter,
    alpha: f32,
) -> super::Microfacet {
    let (u, v) = match parameter {
        TexturedParameter::RoughnessU => (alpha, microfacet.alpha_v),
        TexturedParameter::RoughnessV => (microfacet.alpha_u, alpha),
        _ => (alpha, alpha),
    };
    super::Microfacet::anisotropic(microfacet.kind, u, v)
}
