//! Mitsuba 3's `principledthin`: the principled BSDF of a thin sheet (a leaf, paper, a
//! curtain), the same from both sides. In a local frame turned toward the viewer (normal
//! +z, `o` above), with `i` toward the light:
//!
//! - a specular reflection (GGX of α = roughness², stretched by `anisotropic`) with the
//!   dielectric's reflectance blended toward a tinted Schlick term by `spec_tint`, and a
//!   specular transmission straight through (no bending) of a GGX whose roughness is scaled
//!   by (0.65 η − 0.35), tinted by the base colour; both weighted by `spec_trans` (as in
//!   Mitsuba, a sheet with `spec_trans` 0 has no specular lobe at all);
//! - Burley's diffuse reflection with its retro-reflection, flattened by `flatness`, and a
//!   sheen, weighted by (1 − spec_trans)(1 − diff_trans / 2);
//! - a Lambertian transmission weighted by (1 − spec_trans) diff_trans / 2 (`diff_trans`
//!   runs from 0 to 2).
//!
//! Every value includes |cos θi|. Lobes are sampled with Mitsuba's probabilities (the
//! sampling rates times the lobes' weights, which do not depend on the directions, so the
//! density is exact).

use super::microfacet::{fresnel_dielectric, Microfacet};
use super::principled::{burley_diffuse, ggx, pick_lobe, reflect, schlick, sheen, tint};
use ais::sampling::cosine_hemisphere;
use glam::Vec3;
use std::f32::consts::PI;

/// The thin principled BSDF's parameters, as Mitsuba names them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledThin {
    /// `base_color`.
    pub base_color: Vec3,
    /// `roughness` (α = roughness²).
    pub roughness: f32,
    /// `anisotropic`: 0 is isotropic.
    pub anisotropic: f32,
    /// `spec_trans`: the specular lobes' share.
    pub spec_trans: f32,
    /// `diff_trans` over 2: the transmitting share of the diffuse part.
    pub diffuse_transmission: f32,
    /// The sheet's index of refraction `eta`.
    pub eta: f32,
    /// `spec_tint`.
    pub spec_tint: f32,
    /// `sheen`.
    pub sheen: f32,
    /// `sheen_tint`.
    pub sheen_tint: f32,
    /// `flatness`.
    pub flatness: f32,
    /// How often each lobe is sampled, relative to its weight.
    pub rates: ThinSamplingRates,
}

/// Mitsuba's sampling rates of the thin sheet's lobes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinSamplingRates {
    /// `specular_reflectance_sampling_rate`.
    pub specular_reflection: f32,
    /// `specular_transmittance_sampling_rate`.
    pub specular_transmission: f32,
    /// `diffuse_reflectance_sampling_rate`.
    pub diffuse_reflection: f32,
    /// `diffuse_transmittance_sampling_rate`.
    pub diffuse_transmission: f32,
}

impl Default for ThinSamplingRates {
    fn default() -> Self {
        ThinSamplingRates {
            specular_reflection: 1.0,
            specular_transmission: 1.0,
            diffuse_reflection: 1.0,
            diffuse_transmission: 1.0,
        }
    }
}

impl Default for PrincipledThin {
    /// Mitsuba's defaults: base colour 0.5, roughness 0.5, η 1.5, every weight 0.
    fn default() -> Self {
        PrincipledThin {
            base_color: Vec3::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            spec_trans: 0.0,
            diffuse_transmission: 0.0,
            eta: 1.5,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            rates: ThinSamplingRates::default(),
        }
    }
}

impl PrincipledThin {
    /// Whether light passes through the sheet.
    pub fn transmits(&self) -> bool {
        self.spec_trans > 0.0 || self.diffuse_transmission > 0.0
    }

    /// Whether the specular lobes' roughness differs along and across the tangent.
    pub fn is_anisotropic(&self) -> bool {
        self.anisotropic > 0.0
    }

    /// The specular transmission's distribution: roughness scaled by the index (Burley
    /// 2015).
    fn transmission_microfacet(&self) -> Microfacet {
        ggx((0.65 * self.eta - 0.35) * self.roughness, self.anisotropic)
    }

    /// The microfacet normal linking `o` (above) and `i`, the light mirrored above.
    fn half_vector(o: Vec3, i: Vec3) -> Vec3 {
        (o + Vec3::new(i.x, i.y, i.z.abs())).normalize()
    }

    /// BSDF times |cos θi| for viewer `o` and light direction `i` (local, either side).
    pub fn eval(&self, o: Vec3, i: Vec3) -> Vec3 {
        if o.z == 0.0 {
            return Vec3::ZERO;
        }
        let side = o.z.signum();
        let (o, i) = (o * side, i * side);
        let h = Self::half_vector(o, i);
        if !h.is_finite() {
            return Vec3::ZERO;
        }
        let (oh, ih) = (o.dot(h), i.dot(h));
        let specular = self.spec_trans;
        let diffuse = 1.0 - specular;
        let mut value = Vec3::ZERO;
        if specular > 0.0 && oh > 0.0 {
            let dielectric = fresnel_dielectric(oh, self.eta);
            if i.z > 0.0 && ih > 0.0 {
                let microfacet = ggx(self.roughness, self.anisotropic);
                let tinted = schlick(tint(self.base_color) * r0(self.eta), oh, self.eta);
                let fresnel = Vec3::splat(dielectric) + self.spec_tint * (tinted - dielectric);
                let dg = microfacet.d(h) * microfacet.g(o, i, h);
                value += fresnel * (specular * dg / (4.0 * o.z));
            } else if i.z < 0.0 && ih < 0.0 {
                let microfacet = self.transmission_microfacet();
                let dg = microfacet.d(h) * microfacet.g(o, i, h);
                value += self.base_color * (specular * (1.0 - dielectric) * dg / (4.0 * o.z));
            }
        }
        if diffuse <= 0.0 {
            return value;
        }
        let transmitted = self.diffuse_transmission;
        if i.z > 0.0 && transmitted < 1.0 {
            let cos_d = h.dot(i);
            let shape = burley_diffuse(self.roughness, self.flatness, o.z, i.z, cos_d);
            let reflected = diffuse * (1.0 - transmitted) * i.z;
            value += self.base_color * (reflected * shape / PI);
            if self.sheen > 0.0 {
                value += sheen(self.base_color, self.sheen_tint, cos_d) * (self.sheen * reflected);
            }
        } else if i.z < 0.0 && transmitted > 0.0 {
            value += self.base_color * (diffuse * transmitted * -i.z / PI);
        }
        value
    }

    /// The probabilities of sampling each lobe: specular reflection, specular transmission,
    /// diffuse reflection, diffuse transmission (`None`: no lobe has weight).
    fn lobe_probabilities(&self) -> Option<[f32; 4]> {
        let (specular, transmitted) = (self.spec_trans, self.diffuse_transmission);
        let rates = self.rates;
        let weights = [
            specular * rates.specular_reflection / 2.0,
            specular * rates.specular_transmission / 2.0,
            rates.diffuse_reflection * (1.0 - specular) * (1.0 - transmitted),
            rates.diffuse_transmission * (1.0 - specular) * transmitted,
        ];
        let total: f32 = weights.iter().sum();
        (total > 0.0 && total.is_finite()).then(|| weights.map(|w| w / total))
    }

    /// A light direction for viewer `o` (local; `None`: the sample scatters nowhere).
    pub fn sample(&self, o: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if o.z == 0.0 {
            return None;
        }
        let side = o.z.signum();
        let o = o * side;
        let (lobe, u0) = pick_lobe(self.lobe_probabilities()?, u[0]);
        let u = [u0, u[1]];
        let i = match lobe {
            0 => reflect(o, ggx(self.roughness, self.anisotropic).sample(o, u)),
            1 => {
                let r = reflect(o, self.transmission_microfacet().sample(o, u));
                Vec3::new(r.x, r.y, -r.z)
            }
            2 => cosine_hemisphere(u),
            _ => -cosine_hemisphere(u),
        };
        let h = Self::half_vector(o, i);
        let valid = match lobe {
            0 => i.z > 0.0 && o.dot(h) > 0.0 && i.dot(h) > 0.0,
            1 => i.z < 0.0 && o.dot(h) > 0.0 && i.dot(h) < 0.0,
            _ => i.z != 0.0,
        };
        (valid && i.is_finite()).then_some(i * side)
    }

    /// Density of [`PrincipledThin::sample`] at `i`.
    pub fn pdf(&self, o: Vec3, i: Vec3) -> f32 {
        let Some([reflection, transmission, diffuse, diffuse_through]) =
            self.lobe_probabilities().filter(|_| o.z != 0.0)
        else {
            return 0.0;
        };
        let side = o.z.signum();
        let (o, i) = (o * side, i * side);
        let h = Self::half_vector(o, i);
        if !h.is_finite() {
            return 0.0;
        }
        let (oh, ih) = (o.dot(h), i.dot(h));
        let jacobian = 1.0 / (4.0 * h.dot(Vec3::new(i.x, i.y, i.z.abs())).abs());
        if i.z > 0.0 {
            let specular = if oh > 0.0 && ih > 0.0 {
                reflection * ggx(self.roughness, self.anisotropic).pdf(o, h) * jacobian
            } else {
                0.0
            };
            specular + diffuse * i.z / PI
        } else if i.z < 0.0 {
            let specular = if oh > 0.0 && ih < 0.0 {
                transmission * self.transmission_microfacet().pdf(o, h) * jacobian
            } else {
                0.0
            };
            specular + diffuse_through * -i.z / PI
        } else {
            0.0
        }
    }
}

/// A dielectric's reflectance at normal incidence.
fn r0(eta: f32) -> Vec3 {
    Vec3::splat(((eta - 1.0) / (eta + 1.0)).powi(2))
}
