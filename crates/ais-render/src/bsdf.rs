//! BSDFs. This first version has Mitsuba's `diffuse` (one-sided, as in Mitsuba) and
//! `twosided`; other types are rendered as diffuse with a warning until they land.

use crate::integrator::basis;
use crate::scene::{Plugin, Property};
use glam::Vec3;
use std::f32::consts::PI;

/// A surface's scattering.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse reflectance (albedo), linear RGB.
    pub reflectance: Vec3,
    /// Whether both sides scatter (Mitsuba's `twosided`); otherwise only the side the
    /// shading normal points to.
    pub two_sided: bool,
}

impl Default for Material {
    /// Mitsuba's default BSDF: one-sided diffuse with reflectance 0.5.
    fn default() -> Self {
        Material {
            reflectance: Vec3::splat(0.5),
            two_sided: false,
        }
    }
}

/// The local frame of a shading point.
#[derive(Clone, Copy, Debug)]
pub struct ShadingFrame {
    /// Shading normal, flipped toward the viewer for two-sided materials.
    pub normal: Vec3,
    /// Geometric normal, on the same side as `normal`.
    pub geometric: Vec3,
    tangent: Vec3,
    bitangent: Vec3,
}

impl ShadingFrame {
    /// The frame at a hit, seen from direction `wo` (pointing away from the surface).
    pub fn new(
        material: &Material,
        shading_normal: Vec3,
        geometric_normal: Vec3,
        wo: Vec3,
    ) -> Self {
        let flip = material.two_sided && geometric_normal.dot(wo) < 0.0;
        let (normal, geometric) = if flip {
            (-shading_normal, -geometric_normal)
        } else {
            (shading_normal, geometric_normal)
        };
        let (tangent, bitangent) = basis(normal);
        ShadingFrame {
            normal,
            geometric,
            tangent,
            bitangent,
        }
    }

    /// Local coordinates → world.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.tangent * local.x + self.bitangent * local.y + self.normal * local.z
    }
}

impl Material {
    /// Reads a Mitsuba `<bsdf>`: `diffuse` (rgb or float reflectance), `twosided` around
    /// one. Anything else becomes the default diffuse, with a warning.
    pub fn from_plugin(
        plugin: &Plugin,
        file: &std::path::Path,
        warnings: &mut Vec<String>,
    ) -> Material {
        match plugin.kind.as_str() {
            "diffuse" => {
                let reflectance = match plugin.properties.get("reflectance").map(|p| &p.value) {
                    Some(Property::Rgb(c)) => Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32),
                    Some(Property::Float(v)) => Vec3::splat(*v as f32),
                    None => Vec3::splat(0.5),
                    Some(_) => {
                        warnings.push(format!(
                            "{}:{}: diffuse reflectance must be an rgb or float here; using 0.5",
                            file.display(),
                            plugin.line
                        ));
                        Vec3::splat(0.5)
                    }
                };
                Material {
                    reflectance: reflectance.clamp(Vec3::ZERO, Vec3::ONE),
                    two_sided: false,
                }
            }
            "twosided" => {
                let inner = plugin
                    .children
                    .first()
                    .map(|c| Material::from_plugin(c, file, warnings))
                    .unwrap_or_default();
                Material {
                    two_sided: true,
                    ..inner
                }
            }
            other => {
                warnings.push(format!(
                    "{}:{}: bsdf \"{other}\" is not implemented yet; rendered as diffuse 0.5",
                    file.display(),
                    plugin.line
                ));
                Material::default()
            }
        }
    }

    /// Whether `wi` can carry light to `wo`: both on the front side of the shading and
    /// geometric normals (the support of the BSDF).
    pub fn in_support(&self, frame: &ShadingFrame, wo: Vec3, wi: Vec3) -> bool {
        frame.normal.dot(wo) > 0.0
            && frame.normal.dot(wi) > 0.0
            && frame.geometric.dot(wi) > 0.0
            && frame.geometric.dot(wo) > 0.0
    }

    /// BSDF times |cos θi| (zero outside the support).
    pub fn eval(&self, frame: &ShadingFrame, wo: Vec3, wi: Vec3) -> Vec3 {
        if !self.in_support(frame, wo, wi) {
            return Vec3::ZERO;
        }
        self.reflectance * (frame.normal.dot(wi) / PI)
    }

    /// Cosine-weighted sampling around the shading normal: direction and density.
    pub fn sample(&self, frame: &ShadingFrame, u: [f32; 2]) -> (Vec3, f64) {
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let z = (1.0 - u[0]).max(0.0).sqrt();
        let wi = frame
            .to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z))
            .normalize();
        (wi, self.pdf(frame, wi))
    }

    /// Density of [`Material::sample`].
    pub fn pdf(&self, frame: &ShadingFrame, wi: Vec3) -> f64 {
        (frame.normal.dot(wi).max(0.0) / PI) as f64
    }
}
