//! Reading a shape's `<bsdf>` into a [`Surface`]: `mask`, `blendbsdf`, `null` and
//! `twosided` around them read here; every other type is one material
//! ([`Material::from_plugin`]) with the textures on its parameters.

use super::parameter_textures::{material_textures, parameter_texture, TextureScene};
use super::surface::{Fraction, Surface, TiltedNormals};
use super::{Material, NormalMapOptions};
use crate::error::InputError;
use crate::scene::{ColourRole, Plugin};
use crate::texture::{luminance, read_texture, Texture};
use std::sync::Arc;

/// The deepest surfaces may nest (through children or references): deeper is a cycle.
const DEEPEST_SURFACE: usize = 16;

/// The types read here rather than as one material.
fn is_composite(kind: &str) -> bool {
    matches!(
        kind,
        "mask" | "blendbsdf" | "null" | "twosided" | "normalmap" | "bumpmap"
    )
}

/// Reads the `<bsdf>` `plugin` of `scene` (a top-level one, a nested one, or one that a
/// reference names).
pub fn read_surface(
    plugin: &Plugin,
    scene: &TextureScene,
    warnings: &mut Vec<String>,
) -> Result<Surface, InputError> {
    SurfaceReader { scene, warnings }.read(plugin, 0)
}

struct SurfaceReader<'a, 'w> {
    scene: &'a TextureScene<'a>,
    warnings: &'w mut Vec<String>,
}

impl<'a> SurfaceReader<'a, '_> {
    fn read(&mut self, plugin: &'a Plugin, depth: usize) -> Result<Surface, InputError> {
        let error = |message: String| InputError::at(self.scene.file, plugin.line, message);
        if depth > DEEPEST_SURFACE {
            return Err(error(format!(
                "BSDFs nest more than {DEEPEST_SURFACE} deep: a cycle of references?"
            )));
        }
        if !is_composite(&plugin.kind) {
            return self.material(plugin);
        }
        let nested = self.nested(plugin)?;
        let known: &[&str] = match plugin.kind.as_str() {
            "mask" => &["opacity"],
            "blendbsdf" => &["weight"],
            "normalmap" => &["flip_invalid_normals", "use_shadowing_function"],
            "bumpmap" => &["scale", "flip_invalid_normals", "use_shadowing_function"],
            _ => &[],
        };
        crate::scene::warn_unknown(self.scene.file, plugin, known, self.warnings);
        match (plugin.kind.as_str(), nested.as_slice()) {
            ("null", []) => Ok(Surface::Null),
            ("twosided", [inner]) if is_composite(&inner.kind) => {
                Ok(self.read(inner, depth + 1)?.two_sided())
            }
            // A twosided of one material, or with no BSDF (which the material warns of).
            ("twosided", _) => self.material(plugin),
            ("mask", [inner]) => Ok(Surface::Mask {
                opacity: self.fraction(plugin, "opacity", Some(0.5))?,
                inner: Box::new(self.read(inner, depth + 1)?),
            }),
            ("normalmap" | "bumpmap", [inner]) => Ok(Surface::Tilted {
                normals: self.tilted_normals(plugin)?,
                options: NormalMapOptions {
                    flip_invalid_normals: self.flag(plugin, "flip_invalid_normals")?,
                    use_shadowing_function: self.flag(plugin, "use_shadowing_function")?,
                },
                inner: Box::new(self.read(inner, depth + 1)?),
            }),
            ("blendbsdf", [first, second]) => Ok(Surface::Blend {
                weight: self.fraction(plugin, "weight", None)?,
                first: Box::new(self.read(first, depth + 1)?),
                second: Box::new(self.read(second, depth + 1)?),
            }),
            (kind, found) => {
                let wanted = match kind {
                    "null" => "no BSDF",
                    "blendbsdf" => "two BSDFs",
                    _ => "one BSDF",
                };
                Err(error(format!(
                    "a \"{kind}\" holds {wanted}, not {}",
                    found.len()
                )))
            }
        }
    }

    /// One material, with the textures on its parameters.
    fn material(&mut self, plugin: &Plugin) -> Result<Surface, InputError> {
        let scene = self.scene;
        let material = Material::from_plugin(plugin, scene.file, scene.bsdfs, self.warnings)?;
        let textures = material_textures(plugin, scene, self.warnings)?;
        Ok(Surface::Material { material, textures })
    }

    /// The BSDFs nested in `plugin` or named by its references, in the file's order.
    fn nested(&self, plugin: &'a Plugin) -> Result<Vec<&'a Plugin>, InputError> {
        let mut found: Vec<(u32, &Plugin)> = plugin
            .children
            .iter()
            .filter(|c| c.tag == "bsdf")
            .map(|c| (c.line, c))
            .collect();
        for (name, id, line) in &plugin.references {
            let is_parameter = matches!(name.as_deref(), Some("opacity" | "weight" | "normalmap"));
            let bsdf = self
                .scene
                .bsdfs
                .iter()
                .find(|b| b.id.as_deref() == Some(id.as_str()));
            let texture =
                (self.scene.textures.iter()).any(|t| t.id.as_deref() == Some(id.as_str()));
            match bsdf {
                Some(bsdf) if !is_parameter => found.push((*line, bsdf)),
                None if !is_parameter && !texture => {
                    let message = format!("no <bsdf> with id \"{id}\"");
                    return Err(InputError::at(self.scene.file, *line, message));
                }
                _ => {}
            }
        }
        found.sort_by_key(|(line, _)| *line);
        Ok(found.into_iter().map(|(_, bsdf)| bsdf).collect())
    }

    /// A normal map's texture, or a bump map's (its one nested or referenced texture, a
    /// bitmap) and scale.
    fn tilted_normals(&mut self, plugin: &Plugin) -> Result<TiltedNormals, InputError> {
        if plugin.kind == "normalmap" {
            return Ok(TiltedNormals::NormalMap(
                self.required_texture(plugin, "normalmap")?,
            ));
        }
        let error = |message: String| InputError::at(self.scene.file, plugin.line, message);
        let scale = plugin
            .float("scale", 1.0)
            .map_err(|(line, message)| InputError::at(self.scene.file, line, message))?;
        if !scale.is_finite() {
            return Err(error(format!(
                "a bumpmap's scale must be finite, not {scale}"
            )));
        }
        let scene = self.scene;
        let referenced = plugin.references.iter().find_map(|(_, id, _)| {
            (scene.textures.iter()).find(|t| t.id.as_deref() == Some(id.as_str()))
        });
        let texture = (plugin.children.iter())
            .find(|c| c.tag == "texture")
            .or(referenced)
            .ok_or_else(|| error("a \"bumpmap\" needs a nested <texture>".into()))?;
        let height = read_texture(scene.file, scene.files, texture, self.warnings)?;
        if !matches!(height, Texture::Bitmap(_)) {
            return Err(error(
                "a \"bumpmap\"'s texture must be a bitmap (its heights' gradient is a bitmap's)"
                    .into(),
            ));
        }
        Ok(TiltedNormals::BumpMap {
            height: Arc::new(height),
            scale: scale as f32,
        })
    }

    /// The texture `name` of `plugin`, which must have one.
    fn required_texture(
        &mut self,
        plugin: &Plugin,
        name: &str,
    ) -> Result<Arc<Texture>, InputError> {
        match parameter_texture(plugin, name, self.scene, self.warnings)? {
            Some(texture) => Ok(Arc::new(texture)),
            None => Err(InputError::at(
                self.scene.file,
                plugin.line,
                format!("a \"{}\" needs a <texture name=\"{name}\">", plugin.kind),
            )),
        }
    }

    /// A boolean property that defaults to true.
    fn flag(&self, plugin: &Plugin, name: &str) -> Result<bool, InputError> {
        plugin
            .boolean(name, true)
            .map_err(|(line, message)| InputError::at(self.scene.file, line, message))
    }

    /// A share in [0, 1]: a texture, a float, or a colour's luminance (`None`: required).
    fn fraction(
        &mut self,
        plugin: &Plugin,
        name: &str,
        default: Option<f32>,
    ) -> Result<Fraction, InputError> {
        if let Some(texture) = parameter_texture(plugin, name, self.scene, self.warnings)? {
            return Ok(Fraction::Texture(Arc::new(texture)));
        }
        let at = |(line, message): (u32, String)| InputError::at(self.scene.file, line, message);
        let value = match plugin.properties.get(name).map(|p| &p.value) {
            Some(crate::scene::Property::Float(_) | crate::scene::Property::Integer(_)) => {
                plugin.float(name, 0.0).map_err(at)? as f32
            }
            Some(_) => luminance(
                plugin
                    .colour(name, ColourRole::Reflectance)
                    .map_err(at)?
                    .unwrap_or_default(),
            ),
            None => default.ok_or_else(|| {
                let message = format!("a \"{}\" needs its \"{name}\"", plugin.kind);
                InputError::at(self.scene.file, plugin.line, message)
            })?,
        };
        if !(0.0..=1.0).contains(&value) {
            self.warnings.push(format!(
                "{}:{}: \"{name}\" = {value} is outside [0, 1]; clamped as Mitsuba does",
                self.scene.file.display(),
                plugin.line
            ));
        }
        Ok(Fraction::Constant(value))
    }
}
