//! Reading a Mitsuba `<bsdf>` into a [`Material`]: every parameter checked, and anything
//! unsupported replaced by the closest supported value with a warning naming the file and
//! line.

use super::{
    eta_from_specular, named_conductor, Dielectric, Material, Microfacet, MicrofacetKind,
    PolarizedPlastic, Principled, PrincipledThin, RoughDielectric, RoughPlastic, SamplingRates,
    Scattering, SmoothPlastic, ThinSamplingRates,
};
use crate::error::InputError;
use crate::scene::{ColourRole, Plugin, Property};
use glam::Vec3;

/// A `<bsdf>` being read, and where its warnings go.
pub(super) struct BsdfReader<'a> {
    /// The element.
    pub plugin: &'a Plugin,
    /// The scene file, for warnings.
    pub file: &'a std::path::Path,
    /// The scene's top-level BSDFs, which references name.
    pub bsdfs: &'a [Plugin],
    /// Warnings so far.
    pub warnings: &'a mut Vec<String>,
    /// How many BSDFs this one is nested in (through children or references).
    pub depth: usize,
}

/// The parameters of a plastic's coating and base.
struct Coating {
    /// Relative index, interior over exterior.
    eta: f32,
    /// Albedo of the base (at most 1).
    diffuse: Vec3,
    /// Multiplier of the coating's reflection.
    specular: Vec3,
    /// Mitsuba's `nonlinear`.
    nonlinear: bool,
}

/// Mitsuba's default exterior index of refraction (air).
const AIR: f64 = 1.000277;

/// The deepest a BSDF may be nested in others, references included: deeper is a cycle.
const DEEPEST_BSDF: usize = 16;

/// The properties each supported BSDF reads.
fn known_properties(kind: &str) -> &'static [&'static str] {
    match kind {
        "diffuse" => &["reflectance"],
        "roughconductor" => &[
            "distribution",
            "alpha",
            "alpha_u",
            "alpha_v",
            "material",
            "eta",
            "k",
            "specular_reflectance",
            "sample_visible",
        ],
        "conductor" => &["material", "eta", "k", "specular_reflectance"],
        "plastic" => &[
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "specular_reflectance",
            "nonlinear",
        ],
        "roughdielectric" => &[
            "distribution",
            "alpha",
            "alpha_u",
            "alpha_v",
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
            "sample_visible",
        ],
        "dielectric" | "thindielectric" => &[
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
        ],
        "pplastic" => &[
            "distribution",
            "alpha",
            "alpha_u",
            "alpha_v",
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "specular_reflectance",
            "sample_visible",
        ],
        "principled" => &[
            "base_color",
            "roughness",
            "anisotropic",
            "metallic",
            "spec_trans",
            "eta",
            "specular",
            "spec_tint",
            "sheen",
            "sheen_tint",
            "flatness",
            "clearcoat",
            "clearcoat_gloss",
            "diffuse_reflectance_sampling_rate",
            "main_specular_sampling_rate",
            "clearcoat_sampling_rate",
        ],
        "principledthin" => &[
            "base_color",
            "roughness",
            "anisotropic",
            "spec_trans",
            "diff_trans",
            "eta",
            "spec_tint",
            "sheen",
            "sheen_tint",
            "flatness",
            "specular_reflectance_sampling_rate",
            "specular_transmittance_sampling_rate",
            "diffuse_reflectance_sampling_rate",
            "diffuse_transmittance_sampling_rate",
        ],
        "roughplastic" => &[
            "distribution",
            "alpha",
            "int_ior",
            "ext_ior",
            "diffuse_reflectance",
            "specular_reflectance",
            "nonlinear",
            "sample_visible",
        ],
        _ => &[],
    }
}

/// An index of refraction given as a number or by name (the names Mitsuba accepts).
fn index_of_refraction(
    plugin: &Plugin,
    name: &str,
    default: f64,
    warn: &mut dyn FnMut(String),
) -> f64 {
    match plugin.properties.get(name).map(|p| &p.value) {
        None => default,
        Some(Property::Float(v)) if *v > 0.0 => *v,
        Some(Property::String(material)) => match named_index_of_refraction(material) {
            Some(v) => v,
            None => {
                warn(format!(
                    "\"{name}\": unknown material \"{material}\"; using {default}"
                ));
                default
            }
        },
        Some(Property::Float(v)) => {
            warn(format!(
                "\"{name}\" = {v} must be positive; using {default}"
            ));
            default
        }
        Some(other) => {
            warn(format!(
                "\"{name}\" must be a positive float or a material name, not a {}; using {default}",
                other.kind()
            ));
            default
        }
    }
}

/// Whether `plugin` gives parameter `name`: as a property, a nested element or a `<ref>`.
fn gives(plugin: &Plugin, name: &str) -> bool {
    let named = |n: &Option<String>| n.as_deref() == Some(name);
    plugin.properties.contains_key(name)
        || plugin.children.iter().any(|c| named(&c.name))
        || plugin.references.iter().any(|r| named(&r.0))
}

/// Indices of refraction of common dielectrics at about 589 nm.
fn named_index_of_refraction(material: &str) -> Option<f64> {
    Some(match material.to_ascii_lowercase().as_str() {
        "vacuum" => 1.0,
        "helium" => 1.00004,
        "hydrogen" => 1.00013,
        "air" => 1.000277,
        "carbon dioxide" => 1.00045,
        "water" => 1.333,
        "acetone" => 1.36,
        "ethanol" => 1.361,
        "carbon tetrachloride" => 1.461,
        "glycerol" => 1.4729,
        "benzene" => 1.501,
        "silicone oil" => 1.52045,
        "bromine" => 1.661,
        "water ice" => 1.31,
        "fused quartz" => 1.458,
        "pyrex" => 1.47,
        "acrylic glass" => 1.49,
        "polypropylene" => 1.49,
        "bk7" => 1.5046,
        "sodium chloride" => 1.544,
        "amber" => 1.55,
        "pet" => 1.575,
        "diamond" => 2.419,
        _ => return None,
    })
}

impl BsdfReader<'_> {
    fn warn(&mut self, message: String) {
        self.warnings.push(format!(
            "{}:{}: {message}",
            self.file.display(),
            self.plugin.line
        ));
    }

    /// The material this element describes.
    pub fn material(&mut self) -> Result<Material, InputError> {
        if self.depth > DEEPEST_BSDF {
            return Err(InputError::at(
                self.file,
                self.plugin.line,
                format!("BSDFs nest more than {DEEPEST_BSDF} deep: a cycle of references?"),
            ));
        }
        self.warn_ignored();
        Ok(match self.plugin.kind.as_str() {
            "diffuse" => {
                let reflectance = self.colour("reflectance", Vec3::splat(0.5));
                Material::diffuse(reflectance.min(Vec3::ONE))
            }
            "roughconductor" => self.rough_conductor(),
            "roughplastic" => self.rough_plastic(),
            "conductor" => self.smooth_conductor(),
            "plastic" => self.smooth_plastic(),
            "dielectric" => self.dielectric(false),
            "thindielectric" => self.dielectric(true),
            "roughdielectric" => self.rough_dielectric(),
            "pplastic" => self.polarized_plastic(),
            "principled" => self.principled()?,
            "principledthin" => self.principled_thin(),
            "twosided" => Material {
                two_sided: true,
                ..self.nested()?
            },
            other => {
                self.warn(format!(
                    "bsdf \"{other}\" is not implemented; rendered as diffuse 0.5"
                ));
                Material::default()
            }
        })
    }

    /// Warns of the properties and nested elements this BSDF does not read.
    fn warn_ignored(&mut self) {
        let plugin = self.plugin;
        if !known_properties(&plugin.kind).is_empty() {
            let known = known_properties(&plugin.kind);
            crate::scene::warn_unknown(self.file, plugin, known, self.warnings);
        }
        let textured = super::parameter_textures::textured_parameters(&plugin.kind);
        let is_textured = |name: Option<&str>| textured.iter().any(|(n, _)| Some(*n) == name);
        for child in plugin
            .children
            .iter()
            .filter(|c| c.tag == "texture" && !is_textured(c.name.as_deref()))
        {
            self.warnings.push(format!(
                "{}:{}: textures are not supported: {} \"{}\" keeps its default",
                self.file.display(),
                child.line,
                child.name.as_deref().unwrap_or("the parameter"),
                plugin.kind
            ));
        }
    }

    /// The BSDF a `twosided` wraps: its nested `<bsdf>` or the one its `<ref>` names.
    fn nested(&mut self) -> Result<Material, InputError> {
        let plugin = self.plugin;
        let inner = match (
            plugin.children.iter().find(|c| c.tag == "bsdf"),
            plugin.references.first(),
        ) {
            (Some(child), _) => child,
            (None, Some((_, id, line))) => self
                .bsdfs
                .iter()
                .find(|b| b.id.as_deref() == Some(id.as_str()))
                .ok_or_else(|| {
                    InputError::at(self.file, *line, format!("no <bsdf> with id \"{id}\""))
                })?,
            (None, None) => {
                self.warn("twosided holds no BSDF; using diffuse 0.5".into());
                return Ok(Material::default());
            }
        };
        BsdfReader {
            plugin: inner,
            file: self.file,
            bsdfs: self.bsdfs,
            warnings: self.warnings,
            depth: self.depth + 1,
        }
        .material()
    }

    /// A colour property (a reflectance, or an unbounded quantity for `eta` and `k`):
    /// non-negative and finite, else `default` with a warning.
    fn colour(&mut self, name: &str, default: Vec3) -> Vec3 {
        let role = match name {
            "eta" | "k" => ColourRole::Unbounded,
            _ => ColourRole::Reflectance,
        };
        match self.plugin.colour(name, role) {
            Ok(v) => self.checked_colour(v.unwrap_or(default), default),
            Err((_, message)) => {
                self.warn(format!("{message}; using the default"));
                default
            }
        }
    }

    /// `value` if it is non-negative and finite, else `default` with a warning.
    fn checked_colour(&mut self, value: Vec3, default: Vec3) -> Vec3 {
        match value {
            v if v.is_finite() && v.min_element() >= 0.0 => v,
            _ => {
                self.warn("a colour is negative or not finite; using the default".into());
                default
            }
        }
    }

    /// The microfacet distribution: Beckmann unless GGX is named (Mitsuba's default), of
    /// roughness `alpha` (default 0.1), or `alpha_u` and `alpha_v` (both, without `alpha`)
    /// for an anisotropic one where `anisotropic_allowed` (rough plastics are isotropic).
    fn microfacet(&mut self, anisotropic_allowed: bool) -> Microfacet {
        let plugin = self.plugin;
        let kind = match plugin.string("distribution") {
            Ok(None) => MicrofacetKind::Beckmann,
            Ok(Some(d)) if d.eq_ignore_ascii_case("beckmann") => MicrofacetKind::Beckmann,
            Ok(Some(d)) if d.eq_ignore_ascii_case("ggx") => MicrofacetKind::Ggx,
            Ok(Some(d)) => {
                self.warn(format!(
                    "microfacet distribution \"{d}\" is not beckmann or ggx; using beckmann"
                ));
                MicrofacetKind::Beckmann
            }
            Err((_, message)) => {
                self.warn(message);
                MicrofacetKind::Beckmann
            }
        };
        let has = |name: &str| plugin.properties.contains_key(name);
        let anisotropic = has("alpha_u")
            || has("alpha_v")
            || plugin
                .children
                .iter()
                .any(|c| matches!(c.name.as_deref(), Some("alpha_u" | "alpha_v")));
        if !(anisotropic && anisotropic_allowed) {
            return Microfacet::new(kind, self.roughness("alpha"));
        }
        if has("alpha") {
            self.warn("alpha_u/alpha_v are given: \"alpha\" is ignored".into());
        }
        let (alpha_u, alpha_v) = (self.roughness("alpha_u"), self.roughness("alpha_v"));
        Microfacet::anisotropic(kind, alpha_u, alpha_v)
    }

    /// A roughness property (default 0.1, as in Mitsuba): a number ≥ 0, else 0.1 with a
    /// warning. As in Mitsuba, roughness is at least 1e-4 (and at most 1 here).
    fn roughness(&mut self, name: &str) -> f32 {
        match self.plugin.float(name, 0.1) {
            Ok(alpha) if alpha.is_finite() && alpha >= 0.0 => alpha as f32,
            Ok(alpha) => {
                self.warn(format!("{name} = {alpha} must be a number ≥ 0; using 0.1"));
                0.1
            }
            Err((_, message)) => {
                self.warn(format!("{message}; using {name} = 0.1"));
                0.1
            }
        }
    }

    /// A conductor's complex index of refraction: `eta` and `k`, or a named `material`.
    fn conductor_ior(&mut self) -> (Vec3, Vec3) {
        let plugin = self.plugin;
        if gives(plugin, "eta") || gives(plugin, "k") {
            return (self.colour("eta", Vec3::ZERO), self.colour("k", Vec3::ONE));
        }
        match plugin.string("material") {
            Ok(None) | Ok(Some("none")) => (Vec3::ZERO, Vec3::ZERO),
            Ok(Some(name)) => named_conductor(name).unwrap_or_else(|| {
                self.warn(format!("conductor \"{name}\" is not in ais's table; using a perfect mirror (material \"none\")"));
                (Vec3::ZERO, Vec3::ZERO)
            }),
            Err((_, message)) => {
                self.warn(message);
                (Vec3::ZERO, Vec3::ZERO)
            }
        }
    }

    fn rough_conductor(&mut self) -> Material {
        let microfacet = self.microfacet(true);
        let (eta, k) = self.conductor_ior();
        let specular = self.colour("specular_reflectance", Vec3::ONE);
        Material {
            scattering: Scattering::RoughConductor {
                microfacet,
                eta,
                k,
                specular,
            },
            two_sided: false,
        }
    }

    fn rough_plastic(&mut self) -> Material {
        let microfacet = self.microfacet(false);
        let coat = self.coating();
        Material {
            scattering: Scattering::RoughPlastic(RoughPlastic::new(
                microfacet,
                coat.eta,
                coat.diffuse,
                coat.specular,
                coat.nonlinear,
            )),
            two_sided: false,
        }
    }

    /// What Mitsuba's `plastic` and `roughplastic` share: the coating's index (default
    /// polypropylene in air), the base's albedo, the coating's tint and `nonlinear`.
    fn coating(&mut self) -> Coating {
        Coating {
            eta: self.relative_ior(1.49),
            diffuse: self
                .colour("diffuse_reflectance", Vec3::splat(0.5))
                .min(Vec3::ONE),
            specular: self.colour("specular_reflectance", Vec3::ONE),
            nonlinear: self.plugin.boolean("nonlinear", false).unwrap_or(false),
        }
    }

    /// `pplastic` (unpolarized): Beckmann unless GGX is named, polypropylene in air.
    fn polarized_plastic(&mut self) -> Material {
        let microfacet = self.microfacet(true);
        let coat = self.coating();
        Material {
            scattering: Scattering::PolarizedPlastic(PolarizedPlastic::new(
                microfacet,
                coat.eta,
                coat.diffuse,
                coat.specular,
            )),
            two_sided: false,
        }
    }

    fn smooth_conductor(&mut self) -> Material {
        let (eta, k) = self.conductor_ior();
        let specular = self.colour("specular_reflectance", Vec3::ONE);
        Material {
            scattering: Scattering::Conductor { eta, k, specular },
            two_sided: false,
        }
    }

    fn smooth_plastic(&mut self) -> Material {
        let coat = self.coating();
        Material {
            scattering: Scattering::Plastic(SmoothPlastic::new(
                coat.eta,
                coat.diffuse,
                coat.specular,
                coat.nonlinear,
            )),
            two_sided: false,
        }
    }

    /// `dielectric` (Mitsuba's default interior: BK7 glass) or `thindielectric`; both
    /// scatter from either side.
    fn dielectric(&mut self, thin: bool) -> Material {
        let eta = self.relative_ior(1.5046);
        Material {
            scattering: Scattering::Dielectric(Dielectric {
                eta,
                reflectance: self.colour("specular_reflectance", Vec3::ONE),
                transmittance: self.colour("specular_transmittance", Vec3::ONE),
                thin,
            }),
            two_sided: false,
        }
    }

    /// `roughdielectric` (Mitsuba's default interior: BK7 glass), seen from either side.
    fn rough_dielectric(&mut self) -> Material {
        let microfacet = self.microfacet(true);
        let eta = self.relative_ior(1.5046);
        Material {
            scattering: Scattering::RoughDielectric(RoughDielectric {
                microfacet,
                eta,
                reflectance: self.colour("specular_reflectance", Vec3::ONE),
                transmittance: self.colour("specular_transmittance", Vec3::ONE),
            }),
            two_sided: false,
        }
    }

    /// `int_ior / ext_ior` (defaults `default_interior` and air), positive and not 1, else
    /// the defaults' ratio with a warning.
    fn relative_ior(&mut self, default_interior: f64) -> f32 {
        let plugin = self.plugin;
        let mut warn = |message: String| self.warn(message);
        let int_ior = index_of_refraction(plugin, "int_ior", default_interior, &mut warn);
        let ext_ior = index_of_refraction(plugin, "ext_ior", AIR, &mut warn);
        let eta = (int_ior / ext_ior) as f32;
        if eta.is_finite() && eta > 0.0 && eta != 1.0 {
            return eta;
        }
        let fallback = (default_interior / AIR) as f32;
        self.warn(format!(
            "int_ior / ext_ior = {eta} must be positive and not 1; using {fallback}"
        ));
        fallback
    }

    /// Mitsuba's `principled`: every weight in [0, 1] (else clamped, with a warning), the
    /// index from `eta` or from `specular` (both is an error, as in Mitsuba), and Mitsuba's
    /// nudges where light passes through (η = 1 becomes 1.001, `specular` 0 becomes 0.001).
    fn principled(&mut self) -> Result<Material, InputError> {
        let plugin = self.plugin;
        if plugin.properties.contains_key("eta") && plugin.properties.contains_key("specular") {
            return Err(InputError::at(
                self.file,
                plugin.line,
                "principled: give \"eta\" or \"specular\", not both".to_string(),
            ));
        }
        let defaults = Principled::default();
        let mut weight = |name: &str, default: f32| self.unit_weight(name, default);
        let mut principled = Principled {
            base_color: Vec3::ZERO,
            roughness: weight("roughness", defaults.roughness),
            anisotropic: weight("anisotropic", 0.0),
            metallic: weight("metallic", 0.0),
            spec_trans: weight("spec_trans", 0.0),
            eta: 1.5,
            spec_tint: weight("spec_tint", 0.0),
            sheen: weight("sheen", 0.0),
            sheen_tint: weight("sheen_tint", 0.0),
            flatness: weight("flatness", 0.0),
            clearcoat: weight("clearcoat", 0.0),
            clearcoat_gloss: weight("clearcoat_gloss", 0.0),
            rates: SamplingRates {
                diffuse: self.rate("diffuse_reflectance_sampling_rate"),
                specular: self.rate("main_specular_sampling_rate"),
                clearcoat: self.rate("clearcoat_sampling_rate"),
            },
        };
        principled.base_color = self
            .colour("base_color", defaults.base_color)
            .min(Vec3::ONE);
        // Mitsuba's flag: given, as a texture or a number other than 0.
        let zero = matches!(
            plugin.properties.get("spec_trans").map(|p| &p.value),
            Some(Property::Float(v)) if *v == 0.0
        );
        let transmits = gives(plugin, "spec_trans") && !zero;
        principled.eta = if plugin.properties.contains_key("eta") {
            let eta = self.positive("eta", 1.5);
            if transmits && eta == 1.0 {
                1.001
            } else {
                eta
            }
        } else {
            let specular = self.unit_weight("specular", 0.5);
            let specular = if transmits && specular == 0.0 {
                1e-3
            } else {
                specular
            };
            eta_from_specular(specular)
        };
        Ok(Material {
            scattering: Scattering::Principled(principled),
            two_sided: false,
        })
    }

    /// Mitsuba's `principledthin` (the same from both sides): every weight in [0, 1] but
    /// `diff_trans` in [0, 2] (else clamped, with a warning), η 1.5 by default.
    fn principled_thin(&mut self) -> Material {
        let defaults = PrincipledThin::default();
        let mut weight = |name: &str, default: f32| self.unit_weight(name, default);
        let mut thin = PrincipledThin {
            base_color: defaults.base_color,
            roughness: weight("roughness", defaults.roughness),
            anisotropic: weight("anisotropic", 0.0),
            spec_trans: weight("spec_trans", 0.0),
            diffuse_transmission: 0.0,
            eta: 1.5,
            spec_tint: weight("spec_tint", 0.0),
            sheen: weight("sheen", 0.0),
            sheen_tint: weight("sheen_tint", 0.0),
            flatness: weight("flatness", 0.0),
            rates: ThinSamplingRates {
                specular_reflection: self.rate("specular_reflectance_sampling_rate"),
                specular_transmission: self.rate("specular_transmittance_sampling_rate"),
                diffuse_reflection: self.rate("diffuse_reflectance_sampling_rate"),
                diffuse_transmission: self.rate("diffuse_transmittance_sampling_rate"),
            },
        };
        thin.base_color = self
            .colour("base_color", defaults.base_color)
            .min(Vec3::ONE);
        thin.diffuse_transmission = self.bounded("diff_trans", 0.0, 2.0) / 2.0;
        thin.eta = self.positive("eta", 1.5);
        Material {
            scattering: Scattering::PrincipledThin(thin),
            two_sided: true,
        }
    }

    /// A float property meant to lie in [0, 1]: clamped there, with a warning if outside;
    /// `default` with a warning if it is not a finite number.
    fn unit_weight(&mut self, name: &str, default: f32) -> f32 {
        self.bounded(name, default, 1.0)
    }

    /// A float property meant to lie in [0, `upper`]: clamped there, with a warning if
    /// outside; `default` with a warning if it is not a finite number.
    fn bounded(&mut self, name: &str, default: f32, upper: f64) -> f32 {
        match self.plugin.float(name, default as f64) {
            Ok(v) if (0.0..=upper).contains(&v) => v as f32,
            Ok(v) if v.is_finite() => {
                self.warn(format!(
                    "\"{name}\" = {v} lies outside [0, {upper}]; clamped"
                ));
                v.clamp(0.0, upper) as f32
            }
            Ok(v) => {
                self.warn(format!("\"{name}\" = {v} is not a number; using {default}"));
                default
            }
            Err((_, message)) => {
                self.warn(format!("{message}; using {name} = {default}"));
                default
            }
        }
    }

    /// A positive finite float property, else `default` with a warning.
    fn positive(&mut self, name: &str, default: f32) -> f32 {
        match self.plugin.float(name, default as f64) {
            Ok(v) if v.is_finite() && v > 0.0 => v as f32,
            Ok(v) => {
                self.warn(format!(
                    "\"{name}\" = {v} must be positive; using {default}"
                ));
                default
            }
            Err((_, message)) => {
                self.warn(format!("{message}; using {name} = {default}"));
                default
            }
        }
    }

    /// A lobe's sampling rate (default 1, as Mitsuba's code has it): ≥ 0.
    fn rate(&mut self, name: &str) -> f32 {
        match self.plugin.float(name, 1.0) {
            Ok(v) if v.is_finite() && v >= 0.0 => v as f32,
            Ok(v) => {
                self.warn(format!("\"{name}\" = {v} must be ≥ 0; using 1"));
                1.0
            }
            Err((_, message)) => {
                self.warn(format!("{message}; using {name} = 1"));
                1.0
            }
        }
    }
}
