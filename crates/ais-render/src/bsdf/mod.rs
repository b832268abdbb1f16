//! BSDFs: Mitsuba's `diffuse`, `roughconductor` and `roughplastic` (GGX, visible-normal
//! sampling), the smooth `conductor`, `plastic`, `dielectric` and `thindielectric`, and the
//! `twosided` adapter, and Mitsuba's `principled` and `principledthin`, each evaluating as Mitsuba 3 does.

mod conductors;
mod diffuse_hit;
mod hit;
mod microfacet;
mod parameter_textures;
mod polarized_plastic;
mod principled;
mod principled_thin;
mod reader;
mod rough_dielectric;
mod rough_plastic;
mod specular;
mod surface;
mod surface_reader;
mod tilted_normals;

pub use conductors::named_conductor;
pub use diffuse_hit::DiffuseHit;
pub use hit::{HitBsdf, Mixture, MixturePart};
pub use microfacet::{fresnel_conductor, fresnel_dielectric, Microfacet, MicrofacetKind};
pub(crate) use parameter_textures::parameter_texture;
pub use parameter_textures::{
    material_textures, ParameterTexture, PrincipledWeight, TextureScene, TexturedParameter,
};
pub use polarized_plastic::PolarizedPlastic;
pub use principled::{eta_from_specular, Principled, SamplingRates};
pub use principled_thin::{PrincipledThin, ThinSamplingRates};
pub use rough_dielectric::RoughDielectric;
pub use rough_plastic::RoughPlastic;
pub use specular::{diffuse_fresnel_reflectance, Dielectric, SmoothPlastic};
pub use surface::{Fraction, Surface, SurfacePoint, TiltedNormals};
pub use surface_reader::read_surface;
pub use tilted_normals::NormalMapOptions;

use crate::geometry::basis;
use crate::scene::Plugin;
use ais::sampling::cosine_hemisphere;
use glam::Vec3;
use std::f32::consts::PI;

/// How a surface scatters, in its local frame (normal +z).
#[derive(Clone, Debug, PartialEq)]
pub enum Scattering {
    /// Lambertian reflection.
    Diffuse {
        /// Albedo.
        reflectance: Vec3,
    },
    /// Microfacet reflection off a conductor.
    RoughConductor {
        /// Microfacet distribution.
        microfacet: Microfacet,
        /// Real part of the complex index of refraction.
        eta: Vec3,
        /// Imaginary part; `eta = k = 0` stands for Mitsuba's `material = "none"` (F = 1).
        k: Vec3,
        /// Multiplier of the reflectance.
        specular: Vec3,
    },
    /// Mitsuba's `roughplastic`: a GGX dielectric coating over a Lambertian base.
    RoughPlastic(RoughPlastic),
    /// Mitsuba's `conductor`: a smooth mirror (a specular lobe only).
    Conductor {
        /// Real part of the complex index of refraction.
        eta: Vec3,
        /// Imaginary part; `eta = k = 0` stands for `material = "none"` (F = 1).
        k: Vec3,
        /// Multiplier of the reflectance.
        specular: Vec3,
    },
    /// Mitsuba's `plastic`: a smooth coating (a specular lobe) over a Lambertian base.
    Plastic(SmoothPlastic),
    /// Mitsuba's `dielectric` and `thindielectric` (specular lobes only).
    Dielectric(Dielectric),
    /// Mitsuba's `roughdielectric`: rough reflection and transmission, from either side.
    RoughDielectric(RoughDielectric),
    /// Mitsuba's `pplastic`, unpolarized: microfacet reflection over a diffuse base.
    PolarizedPlastic(PolarizedPlastic),
    /// Mitsuba's `principled`: Burley's BSDF with its specular, transmitting, diffuse,
    /// sheen and clearcoat lobes.
    Principled(Principled),
    /// Mitsuba's `principledthin`: the principled BSDF of a thin sheet, the same from both
    /// sides, with diffuse and specular transmission.
    PrincipledThin(PrincipledThin),
}

/// A direction drawn from a BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The direction (world space, unit).
    pub direction: Vec3,
    /// When a specular lobe was picked: its mass and the probability of picking it.
    pub specular: Option<SpecularMass>,
}

/// A specular lobe picked by a BSDF sample: a point mass over directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularMass {
    /// What the lobe multiplies the radiance arriving along it by (cosine included).
    pub weight: Vec3,
    /// The probability that the BSDF sample picked it.
    pub probability: f32,
}

/// A surface's scattering and sidedness.
#[derive(Clone, Debug, PartialEq)]
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
        Self::oriented(shading_normal, geometric_normal, wo, material.two_sided)
    }

    /// The frame at a hit seen from `wo`, turned toward the viewer if `two_sided`.
    pub fn oriented(
        shading_normal: Vec3,
        geometric_normal: Vec3,
        wo: Vec3,
        two_sided: bool,
    ) -> Self {
        let flip = two_sided && geometric_normal.dot(wo) < 0.0;
        let (normal, geometric) = if flip {
            (-shading_normal, -geometric_normal)
        } else {
            (shading_normal, geometric_normal)
        };
        Self::with_normal(normal, geometric)
    }

    /// [`ShadingFrame::oriented`] with its tangent along `dp_du` (made perpendicular to the
    /// shading normal), as an anisotropic material needs: Mitsuba's shading frame. Seen from
    /// behind a two-sided material, the normal turns and the tangents stay (the directions
    /// are mirrored through the surface, as Mitsuba's `twosided` mirrors them).
    pub fn along_tangent(
        shading_normal: Vec3,
        geometric_normal: Vec3,
        wo: Vec3,
        two_sided: bool,
        dp_du: Vec3,
    ) -> Self {
        let projected = dp_du - shading_normal * shading_normal.dot(dp_du);
        let tangent = projected
            .try_normalize()
            .unwrap_or_else(|| basis(shading_normal).0);
        let bitangent = shading_normal.cross(tangent);
        let flip = two_sided && geometric_normal.dot(wo) < 0.0;
        let sign = if flip { -1.0 } else { 1.0 };
        Self::from_axes(
            shading_normal * sign,
            geometric_normal * sign,
            tangent,
            bitangent,
        )
    }

    /// A frame of unit, orthogonal `tangent`, `bitangent` and `normal`, with `geometric` on
    /// the normal's side.
    pub fn from_axes(normal: Vec3, geometric: Vec3, tangent: Vec3, bitangent: Vec3) -> Self {
        ShadingFrame {
            normal,
            geometric,
            tangent,
            bitangent,
        }
    }

    /// A frame around `normal` (unit), with `geometric` on its side.
    pub fn with_normal(normal: Vec3, geometric: Vec3) -> Self {
        let (tangent, bitangent) = basis(normal);
        Self::from_axes(normal, geometric, tangent, bitangent)
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

impl Material {
    /// Whether its roughness differs along and across the tangent (it then needs the
    /// frame of [`ShadingFrame::along_tangent`]).
    pub fn is_anisotropic(&self) -> bool {
        match &self.scattering {
            Scattering::RoughConductor { microfacet, .. } => microfacet.is_anisotropic(),
            Scattering::RoughDielectric(rough) => rough.microfacet.is_anisotropic(),
            Scattering::PolarizedPlastic(plastic) => plastic.microfacet.is_anisotropic(),
            Scattering::Principled(principled) => principled.is_anisotropic(),
            Scattering::PrincipledThin(thin) => thin.is_anisotropic(),
            _ => false,
        }
    }

    /// One-sided diffuse of albedo `reflectance`.
    pub fn diffuse(reflectance: Vec3) -> Self {
        Material {
            scattering: Scattering::Diffuse { reflectance },
            two_sided: false,
        }
    }

    /// Reads a Mitsuba `<bsdf>` of a scene read from `file`, whose top-level BSDFs `bsdfs`
    /// its references name. Unsupported types and properties become the closest supported
    /// material, with a warning naming the file and line; a reference to no BSDF, or a cycle
    /// of references, is an error.
    pub fn from_plugin(
        plugin: &Plugin,
        file: &std::path::Path,
        bsdfs: &[Plugin],
        warnings: &mut Vec<String>,
    ) -> Result<Material, crate::InputError> {
        reader::BsdfReader {
            plugin,
            file,
            bsdfs,
            warnings,
            depth: 0,
        }
        .material()
    }

    /// Whether light can pass through the surface (a continuous transmission lobe).
    fn transmits(&self) -> bool {
        match &self.scattering {
            Scattering::RoughDielectric(_) => true,
            Scattering::Principled(principled) => principled.transmits(),
            Scattering::PrincipledThin(thin) => thin.transmits(),
            _ => false,
        }
    }

    /// A normal `m` such that no direction `wi` with `m · wi <= 0` lies in the support
    /// ([`Material::in_support`]): the geometric normal of a surface that only reflects, or
    /// `None` for one that transmits.
    pub fn support_side(&self, frame: &ShadingFrame) -> Option<Vec3> {
        (!self.transmits()).then_some(frame.geometric)
    }

    /// Whether `wi` can carry light to `wo` through the BSDF's continuous part: both on the
    /// front side of the shading and geometric normals. Smooth conductors and dielectrics
    /// have no continuous part: only their specular lobes ([`Material::sample_lobe`]) carry.
    pub fn in_support(&self, frame: &ShadingFrame, wo: Vec3, wi: Vec3) -> bool {
        if self.transmits() {
            // Either side, where the shading and geometric normals agree on it.
            let agrees = |w: Vec3| frame.normal.dot(w) * frame.geometric.dot(w) > 0.0;
            return agrees(wo) && agrees(wi);
        }
        !matches!(
            self.scattering,
            Scattering::Conductor { .. } | Scattering::Dielectric(_)
        ) && frame.normal.dot(wo) > 0.0
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
                microfacet,
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
                specular * fresnel * (microfacet.d(h) * microfacet.g(i, o, h) / (4.0 * o.z))
            }
            Scattering::RoughPlastic(ref plastic) => plastic.eval(o, i),
            Scattering::Plastic(ref plastic) => plastic.eval(o, i),
            Scattering::RoughDielectric(ref rough) => rough.eval(o, i),
            Scattering::PolarizedPlastic(ref plastic) => plastic.eval(o, i),
            Scattering::Principled(ref principled) => principled.eval(o, i),
            Scattering::PrincipledThin(ref thin) => thin.eval(o, i),
            // No continuous part (outside the support).
            Scattering::Conductor { .. } | Scattering::Dielectric(_) => Vec3::ZERO,
        }
    }

    /// A direction drawn from the BSDF's continuous part for viewing direction `wo`, and its
    /// density; a sample that picks a specular lobe comes back with density 0 (see
    /// [`Material::sample_lobe`]).
    pub fn sample(&self, frame: &ShadingFrame, wo: Vec3, u: [f32; 2]) -> (Vec3, f64) {
        match self.sample_lobe(frame, wo, u) {
            Some(BsdfSample {
                direction,
                specular: None,
            }) => (direction, self.pdf(frame, wo, direction)),
            _ => (frame.normal, 0.0),
        }
    }

    /// Whether the BSDF is diffuse: its draws are then cosine-weighted around the shading
    /// normal whatever the viewing direction ([`diffuse_direction`]).
    pub fn is_diffuse(&self) -> bool {
        self.diffuse_reflectance().is_some()
    }

    /// A diffuse material's reflectance (`None` for other materials).
    pub fn diffuse_reflectance(&self) -> Option<Vec3> {
        match self.scattering {
            Scattering::Diffuse { reflectance } => Some(reflectance),
            _ => None,
        }
    }

    /// A direction drawn from the BSDF for viewing direction `wo`: from its continuous part,
    /// or a specular lobe with its mass (`None`: nothing scatters toward `wo`).
    pub fn sample_lobe(&self, frame: &ShadingFrame, wo: Vec3, u: [f32; 2]) -> Option<BsdfSample> {
        let o = frame.to_local(wo);
        let reflect = |h: Vec3| 2.0 * o.dot(h) * h - o;
        let local = match self.scattering {
            Scattering::Diffuse { .. } => {
                return Some(BsdfSample {
                    direction: diffuse_direction(frame, u),
                    specular: None,
                })
            }
            Scattering::RoughConductor { microfacet, .. } => (o.z > 0.0)
                .then(|| specular::LobeSample::Continuous(reflect(microfacet.sample(o, u))))?,
            Scattering::RoughPlastic(ref plastic) => {
                (o.z > 0.0).then(|| specular::LobeSample::Continuous(plastic.sample(o, u)))?
            }
            Scattering::Plastic(ref plastic) => plastic.sample(o, u)?,
            Scattering::RoughDielectric(ref rough) => {
                specular::LobeSample::Continuous(rough.sample(o, u)?)
            }
            Scattering::PolarizedPlastic(ref plastic) => {
                specular::LobeSample::Continuous(plastic.sample(o, u)?)
            }
            Scattering::Principled(ref principled) => {
                specular::LobeSample::Continuous(principled.sample(o, u)?)
            }
            Scattering::PrincipledThin(ref thin) => {
                specular::LobeSample::Continuous(thin.sample(o, u)?)
            }
            Scattering::Conductor { eta, k, specular } => {
                specular::LobeSample::Specular(specular::conductor_lobe(o, eta, k, specular)?)
            }
            Scattering::Dielectric(dielectric) => {
                specular::LobeSample::Specular(dielectric.sample(o, u[0])?)
            }
        };
        Some(match local {
            specular::LobeSample::Continuous(local) => BsdfSample {
                direction: frame.to_world(local).normalize(),
                specular: None,
            },
            specular::LobeSample::Specular(lobe) => BsdfSample {
                direction: frame.to_world(lobe.local).normalize(),
                specular: Some(SpecularMass {
                    weight: lobe.weight,
                    probability: lobe.probability,
                }),
            },
        })
    }

    /// Density of [`Material::sample`] at `wi`.
    pub fn pdf(&self, frame: &ShadingFrame, wo: Vec3, wi: Vec3) -> f64 {
        let (o, i) = (frame.to_local(wo), frame.to_local(wi));
        match self.scattering {
            Scattering::RoughDielectric(ref rough) => return rough.pdf(o, i) as f64,
            Scattering::Principled(ref principled) => return principled.pdf(o, i) as f64,
            Scattering::PrincipledThin(ref thin) => return thin.pdf(o, i) as f64,
            _ => {}
        }
        if i.z <= 0.0 {
            return 0.0;
        }
        let cosine = i.z / PI;
        let reflection_pdf = |microfacet: Microfacet| {
            if o.z <= 0.0 {
                return 0.0;
            }
            let h = (o + i).normalize();
            let oh = o.dot(h);
            if oh <= 0.0 {
                0.0
            } else {
                microfacet.pdf(o, h) / (4.0 * oh)
            }
        };
        (match self.scattering {
            Scattering::Diffuse { .. } => cosine,
            Scattering::RoughConductor { microfacet, .. } => reflection_pdf(microfacet),
            Scattering::RoughPlastic(ref plastic) => {
                if o.z <= 0.0 {
                    return 0.0;
                }
                plastic.pdf(o, i, reflection_pdf(plastic.microfacet))
            }
            Scattering::Plastic(ref plastic) => {
                if o.z <= 0.0 {
                    return 0.0;
                }
                plastic.pdf(o, i)
            }
            Scattering::PolarizedPlastic(ref plastic) => plastic.pdf(o, i),
            // Point masses only: no density over directions (the rough dielectric and the
            // principled BSDFs returned above).
            Scattering::Conductor { .. }
            | Scattering::Dielectric(_)
            | Scattering::RoughDielectric(_)
            | Scattering::Principled(_)
            | Scattering::PrincipledThin(_) => 0.0,
        }) as f64
    }
}

/// A diffuse BSDF's draw from `u`: cosine-weighted around `frame`'s normal. Inline, so that a
/// run's draws in a loop are worked out in lanes.
#[inline(always)]
pub fn diffuse_direction(frame: &ShadingFrame, u: [f32; 2]) -> Vec3 {
    frame.to_world(cosine_hemisphere(u)).normalize()
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
            .map(|b| {
                Material::from_plugin(b, Path::new("m.xml"), &scene.bsdfs, &mut warnings).unwrap()
            })
            .collect();
        (materials, warnings)
    }

    #[test]
    fn mitsuba_bsdfs_are_read() {
        let (m, warnings) = materials(
            r#"<bsdf type="roughconductor" id="a"><float name="alpha" value="0.3"/><string name="material" value="Au"/></bsdf>
               <bsdf type="roughconductor" id="b"/>
               <bsdf type="roughplastic" id="c"><rgb name="diffuse_reflectance" value="0.2, 0.4, 0.6"/><float name="int_ior" value="1.5"/><string name="ext_ior" value="air"/></bsdf>
               <bsdf type="twosided" id="d"><bsdf type="diffuse"><float name="reflectance" value="0.3"/></bsdf></bsdf>"#,
        );
        assert!(warnings.is_empty(), "{warnings:?}");
        match &m[0].scattering {
            Scattering::RoughConductor {
                microfacet, eta, ..
            } => {
                assert_eq!(*microfacet, Microfacet::beckmann(0.3));
                assert!(eta.x < 0.2);
            }
            other => panic!("{other:?}"),
        }
        assert!(
            matches!(m[1].scattering, Scattering::RoughConductor { eta, k, .. } if eta == Vec3::ZERO && k == Vec3::ZERO)
        );
        match &m[2].scattering {
            Scattering::RoughPlastic(plastic) => {
                assert!((plastic.eta - 1.5 / 1.000277).abs() < 1e-5);
                assert_eq!(plastic.diffuse, Vec3::new(0.2, 0.4, 0.6));
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
            r#"<bsdf type="measured" id="a"/>
               <bsdf type="roughconductor" id="b"><string name="material" value="Unobtainium"/><float name="sheen" value="0.1"/></bsdf>
               <bsdf type="roughplastic" id="c"><string name="int_ior" value="kryptonite"/></bsdf>"#,
        );
        assert_eq!(m[0], Material::default());
        let all = warnings.join("\n");
        assert!(
            all.contains("m.xml:1: bsdf \"measured\" is not implemented"),
            "{all}"
        );
        assert!(
            all.contains("Unobtainium") && all.contains("sheen") && all.contains("kryptonite"),
            "{all}"
        );
    }

    #[test]
    fn principled_reads_its_defaults_and_refuses_eta_with_specular() {
        let (m, warnings) = materials(
            r#"<bsdf type="principled" id="a"/>
               <bsdf type="principled" id="b"><float name="metallic" value="1.5"/><float name="eta" value="1.33"/></bsdf>"#,
        );
        assert_eq!(
            m[0].scattering,
            Scattering::Principled(Principled::default())
        );
        match &m[1].scattering {
            Scattering::Principled(p) => assert!(p.metallic == 1.0 && p.eta == 1.33),
            other => panic!("{other:?}"),
        }
        assert!(
            warnings
                .join("\n")
                .contains("m.xml:2: \"metallic\" = 1.5 lies outside [0, 1]"),
            "{warnings:?}"
        );
        let xml = r#"<scene version="3.0.0"><bsdf type="principled" id="c"><float name="eta" value="1.5"/><float name="specular" value="0.5"/></bsdf></scene>"#;
        let scene = parse_scene(Path::new("m.xml"), xml, &[]).unwrap();
        let error = Material::from_plugin(
            &scene.bsdfs[0],
            Path::new("m.xml"),
            &scene.bsdfs,
            &mut Vec::new(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            error.contains("m.xml:1") && error.contains("not both"),
            "{error}"
        );
    }
}
