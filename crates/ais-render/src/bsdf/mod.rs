//! BSDFs: Mitsuba's `diffuse`, `roughconductor` and `roughplastic` (GGX, visible-normal
//! sampling) and the `twosided` adapter. `roughplastic` is a documented approximation of
//! Mitsuba's (see [`Scattering::RoughPlastic`]).

mod microfacet;

pub use microfacet::{fresnel_conductor, fresnel_dielectric, Ggx};

use crate::geometry::{basis, cosine_hemisphere};
use crate::scene::{Plugin, Property};
use glam::Vec3;
use std::f32::consts::PI;

/// How a surface scatters, in its local frame (normal +z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scattering {
    /// Lambertian reflection.
    Diffuse {
        /// Albedo.
        reflectance: Vec3,
    },
    /// GGX reflection off a conductor.
    RoughConductor {
        /// Microfacet roughness.
        ggx: Ggx,
        /// Real part of the complex index of refraction.
        eta: Vec3,
        /// Imaginary part; `eta = k = 0` stands for Mitsuba's `material = "none"` (F = 1).
        k: Vec3,
        /// Multiplier of the reflectance.
        specular: Vec3,
    },
    /// GGX specular reflection off a dielectric coating over a Lambertian base:
    /// `F(wi·h) D G / (4 cos θi cos θo)` plus `ρ_d / π · (1 − F(cos θi)) (1 − F(cos θo))`.
    /// Mitsuba's roughplastic adds internal scattering and a rough-interface transmittance
    /// table; this approximation is unbiased for itself but not identical to Mitsuba's.
    RoughPlastic {
        /// Microfacet roughness.
        ggx: Ggx,
        /// Relative index, interior over exterior.
        eta: f32,
        /// Albedo of the base.
        diffuse: Vec3,
        /// Multiplier of the specular lobe.
        specular: f32,
    },
}

/// A surface's scattering and sidedness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// The BSDF.
    pub scattering: Scattering,
    /// Whether both sides scatter (Mitsuba's `twosided`); otherwise only the side the
    /// shading normal points to.
    pub two_sided: bool,
}

impl Default for Material {
    /// Mitsuba's default BSDF: one-sided diffuse with reflectance 0.5.
    fn default() -> Self {
        Material::diffuse(Vec3::splat(0.5))
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

    /// World → local coordinates.
    pub fn to_local(&self, world: Vec3) -> Vec3 {
        Vec3::new(
            world.dot(self.tangent),
            world.dot(self.bitangent),
            world.dot(self.normal),
        )
    }
}

fn rgb(plugin: &Plugin, name: &str, default: Vec3) -> Result<Vec3, String> {
    match plugin.properties.get(name).map(|p| &p.value) {
        None => Ok(default),
        Some(Property::Rgb(c)) => Ok(Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)),
        Some(Property::Float(v)) => Ok(Vec3::splat(*v as f32)),
        Some(other) => Err(format!(
            "\"{name}\" must be an rgb or float, not a {}",
            other.kind()
        )),
    }
}

impl Material {
    /// One-sided diffuse of albedo `reflectance`.
    pub fn diffuse(reflectance: Vec3) -> Self {
        Material {
            scattering: Scattering::Diffuse { reflectance },
            two_sided: false,
        }
    }

    /// Reads a Mitsuba `<bsdf>`. Unsupported types and properties become the closest
    /// supported material, with a warning naming the file and line.
    pub fn from_plugin(
        plugin: &Plugin,
        file: &std::path::Path,
        warnings: &mut Vec<String>,
    ) -> Material {
        let mut warn = |message: String| {
            warnings.push(format!("{}:{}: {message}", file.display(), plugin.line))
        };
        let alpha = |warn: &mut dyn FnMut(String)| -> Ggx {
            if plugin.properties.contains_key("alpha_u")
                || plugin.properties.contains_key("alpha_v")
            {
                warn("anisotropic alpha_u/alpha_v are not supported; using alpha".into());
            }
            if let Ok(Some(d)) = plugin.string("distribution") {
                if d != "ggx" {
                    warn(format!("microfacet distribution \"{d}\" replaced by ggx"));
                }
            }
            Ggx::new(plugin.float("alpha", 0.1).unwrap_or(0.1) as f32)
        };
        let checked = |value: Result<Vec3, String>, warn: &mut dyn FnMut(String), default: Vec3| {
            match value {
                Ok(v) if v.is_finite() && v.min_element() >= 0.0 => v,
                Ok(_) => {
                    warn("a colour is negative or not finite; using the default".into());
                    default
                }
                Err(message) => {
                    warn(format!("{message}; using the default"));
                    default
                }
            }
        };
        match plugin.kind.as_str() {
            "diffuse" => {
                let reflectance = checked(
                    rgb(plugin, "reflectance", Vec3::splat(0.5)),
                    &mut warn,
                    Vec3::splat(0.5),
                );
                Material::diffuse(reflectance.min(Vec3::ONE))
            }
            "roughconductor" => {
                let ggx = alpha(&mut warn);
                let (eta, k) = if plugin.properties.contains_key("eta")
                    || plugin.properties.contains_key("k")
                {
                    (
                        checked(rgb(plugin, "eta", Vec3::ZERO), &mut warn, Vec3::ZERO),
                        checked(rgb(plugin, "k", Vec3::ONE), &mut warn, Vec3::ONE),
                    )
                } else {
                    match plugin.string("material") {
                        Ok(None) | Ok(Some("none")) => (Vec3::ZERO, Vec3::ZERO),
                        Ok(Some(name)) => match named_conductor(name) {
                            Some(ior) => ior,
                            None => {
                                warn(format!("conductor \"{name}\" is not in ais's table; using a perfect mirror (material \"none\")"));
                                (Vec3::ZERO, Vec3::ZERO)
                            }
                        },
                        Err((_, message)) => {
                            warn(message);
                            (Vec3::ZERO, Vec3::ZERO)
                        }
                    }
                };
                let specular = checked(
                    rgb(plugin, "specular_reflectance", Vec3::ONE),
                    &mut warn,
                    Vec3::ONE,
                );
                Material {
                    scattering: Scattering::RoughConductor {
                        ggx,
                        eta,
                        k,
                        specular,
                    },
                    two_sided: false,
                }
            }
            "roughplastic" => {
                let ggx = alpha(&mut warn);
                let int_ior = plugin.float("int_ior", 1.49).unwrap_or(1.49);
                let ext_ior = plugin.float("ext_ior", 1.000277).unwrap_or(1.000277);
                let diffuse = checked(
                    rgb(plugin, "diffuse_reflectance", Vec3::splat(0.5)),
                    &mut warn,
                    Vec3::splat(0.5),
                );
                let specular = checked(
                    rgb(plugin, "specular_reflectance", Vec3::ONE),
                    &mut warn,
                    Vec3::ONE,
                );
                if plugin.boolean("nonlinear", false).unwrap_or(false) {
                    warn(
                        "roughplastic nonlinear = true is not supported; using the linear model"
                            .into(),
                    );
                }
                Material {
                    scattering: Scattering::RoughPlastic {
                        ggx,
                        eta: (int_ior / ext_ior).max(1.0001) as f32,
                        diffuse: diffuse.min(Vec3::ONE),
                        specular: specular.max_element(),
                    },
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
                warn(format!(
                    "bsdf \"{other}\" is not implemented; rendered as diffuse 0.5"
                ));
                Material::default()
            }
        }
    }

    /// Whether `wi` can carry light to `wo`: both on the front side of the shading and
    /// geometric normals (the support of these reflection-only BSDFs).
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
        let (o, i) = (frame.to_local(wo), frame.to_local(wi));
        match self.scattering {
            Scattering::Diffuse { reflectance } => reflectance * (i.z / PI),
            Scattering::RoughConductor {
                ggx,
                eta,
                k,
                specular,
            } => {
                let h = (o + i).normalize();
                let fresnel = if eta == Vec3::ZERO && k == Vec3::ZERO {
                    Vec3::ONE
                } else {
                    fresnel_conductor(i.dot(h), eta, k)
                };
                specular * fresnel * (ggx.d(h) * ggx.g(i, o) / (4.0 * o.z))
            }
            Scattering::RoughPlastic {
                ggx,
                eta,
                diffuse,
                specular,
            } => {
                let h = (o + i).normalize();
                let glossy = specular * fresnel_dielectric(i.dot(h), eta) * ggx.d(h) * ggx.g(i, o)
                    / (4.0 * o.z);
                let base = diffuse
                    * ((1.0 - fresnel_dielectric(i.z, eta))
                        * (1.0 - fresnel_dielectric(o.z, eta))
                        * i.z
                        / PI);
                base + Vec3::splat(glossy)
            }
        }
    }

    /// Probability of choosing the specular lobe of a rough plastic when sampling.
    fn specular_probability(o: Vec3, eta: f32, diffuse: Vec3, specular: f32) -> f32 {
        let s = specular * fresnel_dielectric(o.z, eta);
        let d = crate::lights::luminance(diffuse) * (1.0 - fresnel_dielectric(o.z, eta));
        if s + d > 0.0 {
            (s / (s + d)).clamp(0.1, 0.9)
        } else {
            0.5
        }
    }

    /// A direction drawn from the BSDF for viewing direction `wo`, and its density.
    pub fn sample(&self, frame: &ShadingFrame, wo: Vec3, u: [f32; 2]) -> (Vec3, f64) {
        let o = frame.to_local(wo);
        let reflect = |h: Vec3| 2.0 * o.dot(h) * h - o;
        let local = match self.scattering {
            Scattering::Diffuse { .. } => cosine_hemisphere(u),
            Scattering::RoughConductor { ggx, .. } => {
                if o.z <= 0.0 {
                    return (frame.normal, 0.0);
                }
                reflect(ggx.sample_visible(o, u))
            }
            Scattering::RoughPlastic {
                ggx,
                eta,
                diffuse,
                specular,
            } => {
                let p = Self::specular_probability(o, eta, diffuse, specular);
                if u[0] < p && o.z > 0.0 {
                    reflect(ggx.sample_visible(o, [u[0] / p, u[1]]))
                } else {
                    cosine_hemisphere([((u[0] - p) / (1.0 - p)).clamp(0.0, 1.0 - 1e-7), u[1]])
                }
            }
        };
        let wi = frame.to_world(local).normalize();
        (wi, self.pdf(frame, wo, wi))
    }

    /// Density of [`Material::sample`] at `wi`.
    pub fn pdf(&self, frame: &ShadingFrame, wo: Vec3, wi: Vec3) -> f64 {
        let (o, i) = (frame.to_local(wo), frame.to_local(wi));
        if i.z <= 0.0 {
            return 0.0;
        }
        let cosine = i.z / PI;
        let microfacet = |ggx: Ggx| {
            if o.z <= 0.0 {
                return 0.0;
            }
            let h = (o + i).normalize();
            let oh = o.dot(h);
            if oh <= 0.0 {
                0.0
            } else {
                ggx.pdf_visible(o, h) / (4.0 * oh)
            }
        };
        (match self.scattering {
            Scattering::Diffuse { .. } => cosine,
            Scattering::RoughConductor { ggx, .. } => microfacet(ggx),
            Scattering::RoughPlastic {
                ggx,
                eta,
                diffuse,
                specular,
            } => {
                let p = Self::specular_probability(o, eta, diffuse, specular);
                if o.z > 0.0 {
                    p * microfacet(ggx) + (1.0 - p) * cosine
                } else {
                    cosine
                }
            }
        }) as f64
    }
}

/// Complex indices of refraction (at roughly 650, 550 and 450 nm) of common conductors.
fn named_conductor(name: &str) -> Option<(Vec3, Vec3)> {
    Some(match name {
        "Au" => (
            Vec3::new(0.143, 0.374, 1.442),
            Vec3::new(3.983, 2.385, 1.603),
        ),
        "Ag" => (
            Vec3::new(0.155, 0.117, 0.138),
            Vec3::new(4.828, 3.122, 2.147),
        ),
        "Cu" => (
            Vec3::new(0.200, 0.924, 1.102),
            Vec3::new(3.912, 2.452, 2.142),
        ),
        "Al" => (
            Vec3::new(1.657, 0.880, 0.521),
            Vec3::new(9.224, 6.270, 4.837),
        ),
        "Cr" => (
            Vec3::new(3.105, 3.182, 2.223),
            Vec3::new(3.324, 3.332, 3.109),
        ),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse_scene;
    use std::path::Path;

    fn materials(bsdfs: &str) -> (Vec<Material>, Vec<String>) {
        let xml = format!("<scene version=\"3.0.0\">{bsdfs}</scene>");
        let scene = parse_scene(Path::new("m.xml"), &xml, &[]).unwrap();
        let mut warnings = Vec::new();
        let materials = scene
            .bsdfs
            .iter()
            .map(|b| Material::from_plugin(b, Path::new("m.xml"), &mut warnings))
            .collect();
        (materials, warnings)
    }

    #[test]
    fn mitsuba_bsdfs_are_read() {
        let (m, warnings) = materials(
            r#"<bsdf type="roughconductor" id="a"><float name="alpha" value="0.3"/><string name="material" value="Au"/></bsdf>
               <bsdf type="roughconductor" id="b"/>
               <bsdf type="roughplastic" id="c"><rgb name="diffuse_reflectance" value="0.2, 0.4, 0.6"/><float name="int_ior" value="1.5"/></bsdf>
               <bsdf type="twosided" id="d"><bsdf type="diffuse"><float name="reflectance" value="0.3"/></bsdf></bsdf>"#,
        );
        assert!(warnings.is_empty(), "{warnings:?}");
        match m[0].scattering {
            Scattering::RoughConductor { ggx, eta, .. } => {
                assert_eq!(ggx.alpha, 0.3);
                assert!(eta.x < 0.2);
            }
            other => panic!("{other:?}"),
        }
        assert!(
            matches!(m[1].scattering, Scattering::RoughConductor { eta, k, .. } if eta == Vec3::ZERO && k == Vec3::ZERO)
        );
        match m[2].scattering {
            Scattering::RoughPlastic { eta, diffuse, .. } => {
                assert!((eta - 1.5 / 1.000277).abs() < 1e-5);
                assert_eq!(diffuse, Vec3::new(0.2, 0.4, 0.6));
            }
            other => panic!("{other:?}"),
        }
        assert!(m[3].two_sided);
        assert_eq!(
            m[3].scattering,
            Scattering::Diffuse {
                reflectance: Vec3::splat(0.3)
            }
        );
    }

    #[test]
    fn unsupported_bsdfs_and_properties_warn() {
        let (m, warnings) = materials(
            r#"<bsdf type="dielectric" id="a"/>
               <bsdf type="roughconductor" id="b"><string name="material" value="Unobtainium"/><float name="alpha_u" value="0.1"/></bsdf>"#,
        );
        assert_eq!(m[0], Material::default());
        let all = warnings.join("\n");
        assert!(
            all.contains("m.xml:1: bsdf \"dielectric\" is not implemented"),
            "{all}"
        );
        assert!(
            all.contains("Unobtainium") && all.contains("alpha_u"),
            "{all}"
        );
    }
}
