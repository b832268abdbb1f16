//! Mitsuba 3's `principled` BSDF: Burley's "Disney" BSDF as Mitsuba evaluates it, lobe by
//! lobe, in a local frame (normal +z) with `o` toward the viewer and `i` toward the light:
//!
//! - a main specular lobe (GGX of α = roughness², stretched by `anisotropic`), reflecting on
//!   the front side with a Fresnel term that blends the dielectric's exact reflectance with
//!   Schlick's approximation tinted by the base colour (`metallic`, `spec_tint`); seen from
//!   inside, only the dielectric's reflectance weighed by the transmitting share;
//! - its transmission (share `spec_trans` of the non-metallic part), tinted by √base colour;
//! - a diffuse lobe with Burley's retro-reflection, blended toward a flattened lobe
//!   (`flatness`), and a sheen lobe, both on the front side only;
//! - a clearcoat (GTR1, roughness from 0.1 to 0.001 as `clearcoat_gloss` goes from 0 to 1)
//!   with Schlick's Fresnel of reflectance 0.04, as Mitsuba writes it (no 1 / (4 cos θo cos θi)).
//!
//! Every value includes cos θi, as the gather needs. Samples pick a lobe with probabilities
//! of Mitsuba's form (the sampling rates times the lobes' weights), with the dielectric
//! reflectance taken at the macro normal so that the density is exact, then a direction
//! from that lobe: cosine-weighted, GGX's visible normals, or GTR1's normals.

use super::microfacet::{fresnel_dielectric, Microfacet, MicrofacetKind};
use super::rough_dielectric::refract;
use crate::texture::luminance;
use ais::sampling::cosine_hemisphere;
use glam::Vec3;
use std::f32::consts::PI;

/// The principled BSDF's parameters, as Mitsuba names them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    /// `base_color`.
    pub base_color: Vec3,
    /// `roughness` of the main specular lobes (α = roughness²).
    pub roughness: f32,
    /// `anisotropic`: 0 is isotropic.
    pub anisotropic: f32,
    /// `metallic`.
    pub metallic: f32,
    /// `spec_trans`: the transmitting share of the non-metallic part.
    pub spec_trans: f32,
    /// Relative index of refraction, interior over exterior (`eta`, or from `specular`).
    pub eta: f32,
    /// `spec_tint`: how much the dielectric reflection is tinted by the base colour.
    pub spec_tint: f32,
    /// `sheen`.
    pub sheen: f32,
    /// `sheen_tint`.
    pub sheen_tint: f32,
    /// `flatness`: 0 is Burley's diffuse, 1 the flattened one.
    pub flatness: f32,
    /// `clearcoat`.
    pub clearcoat: f32,
    /// `clearcoat_gloss`.
    pub clearcoat_gloss: f32,
    /// How often each lobe is sampled, relative to its weight.
    pub rates: SamplingRates,
}

/// Mitsuba's sampling rates of the lobes (they change the noise, never the expectation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplingRates {
    /// `diffuse_reflectance_sampling_rate`.
    pub diffuse: f32,
    /// `main_specular_sampling_rate`.
    pub specular: f32,
    /// `clearcoat_sampling_rate`.
    pub clearcoat: f32,
}

impl Default for SamplingRates {
    fn default() -> Self {
        SamplingRates {
            diffuse: 1.0,
            specular: 1.0,
            clearcoat: 1.0,
        }
    }
}

impl Default for Principled {
    /// Mitsuba's defaults: base colour 0.5, roughness 0.5, `specular` 0.5 (η = 1.5), every
    /// other weight 0.
    fn default() -> Self {
        Principled {
            base_color: Vec3::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            metallic: 0.0,
            spec_trans: 0.0,
            eta: eta_from_specular(0.5),
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            clearcoat: 0.0,
            clearcoat_gloss: 0.0,
            rates: SamplingRates::default(),
        }
    }
}

/// The index of refraction that `specular` stands for (Mitsuba's one-to-one mapping).
pub fn eta_from_specular(specular: f32) -> f32 {
    2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
}

/// Which lobe a sample picked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lobe {
    Diffuse,
    Clearcoat,
    Transmission,
    Reflection,
}

/// The geometry of a pair of directions: the microfacet normal linking them (turned to
/// +z), the index ratio seen from the viewer's side, and which lobes it is valid for.
struct Pair {
    h: Vec3,
    eta_path: f32,
    /// Same side, and the microfacet faces both directions.
    reflects: bool,
    /// Opposite sides, and the microfacet faces the viewer and is crossed by the light.
    refracts: bool,
}

impl Principled {
    /// The weights of the diffuse (reflecting) and transmitting parts.
    fn part_weights(&self) -> (f32, f32) {
        let dielectric = 1.0 - self.metallic;
        (
            dielectric * (1.0 - self.spec_trans),
            dielectric * self.spec_trans,
        )
    }

    /// Whether light passes through the surface (then it scatters from either side).
    pub fn transmits(&self) -> bool {
        self.part_weights().1 > 0.0
    }

    /// Whether the main lobes' roughness differs along and across the tangent.
    pub fn is_anisotropic(&self) -> bool {
        self.anisotropic > 0.0
    }

    /// The main lobes' GGX distribution.
    fn microfacet(&self) -> Microfacet {
        ggx(self.roughness, self.anisotropic)
    }

    fn tint(&self) -> Vec3 {
        tint(self.base_color)
    }

    fn pair(&self, o: Vec3, i: Vec3) -> Pair {
        let front = o.z > 0.0;
        let same_side = o.z * i.z > 0.0;
        let eta_path = if front { self.eta } else { 1.0 / self.eta };
        let h = (o + i * if same_side { 1.0 } else { eta_path }).normalize();
        let h = if h.z < 0.0 { -h } else { h };
        let side = o.z.signum();
        let (oh, ih) = (o.dot(h) * side, i.dot(h) * side);
        let finite = h.is_finite();
        Pair {
            h,
            eta_path,
            reflects: finite && same_side && oh > 0.0 && ih > 0.0,
            refracts: finite && o.z * i.z < 0.0 && oh > 0.0 && ih < 0.0,
        }
    }

    /// The main lobes' Fresnel term for light arriving from `o` at microfacet `h`: on the
    /// front side the dielectric's reflectance blended with tinted and metallic Schlick
    /// terms; from inside, the dielectric's reflectance of the transmitting part.
    fn fresnel(&self, dielectric: f32, oh: f32, front: bool) -> Vec3 {
        let (_, transmitting) = self.part_weights();
        if !front {
            return Vec3::splat(transmitting * dielectric);
        }
        let eta_it = if oh >= 0.0 { self.eta } else { 1.0 / self.eta };
        let r0 = ((eta_it - 1.0) / (eta_it + 1.0)).powi(2);
        let metal = self.metallic * schlick(self.base_color, oh, self.eta);
        let tinted =
            (1.0 - self.metallic) * self.spec_tint * schlick(self.tint() * r0, oh, self.eta);
        Vec3::splat((1.0 - self.metallic) * (1.0 - self.spec_tint) * dielectric) + metal + tinted
    }

    /// BSDF times |cos θi| for viewer `o` and light direction `i` (local).
    pub fn eval(&self, o: Vec3, i: Vec3) -> Vec3 {
        if o.z == 0.0 {
            return Vec3::ZERO;
        }
        let front = o.z > 0.0;
        let pair = self.pair(o, i);
        let h = pair.h;
        let oh = o.dot(h);
        let dielectric = dielectric_fresnel(oh, self.eta);
        let microfacet = self.microfacet();
        let mut value = Vec3::ZERO;
        if pair.reflects && dielectric > 0.0 {
            let dg = microfacet.d(h) * microfacet.g(o, i, h);
            value += self.fresnel(dielectric, oh, front) * (dg / (4.0 * o.z.abs()));
        }
        let (reflecting, transmitting) = self.part_weights();
        if pair.refracts && transmitting > 0.0 && dielectric < 1.0 {
            let ih = i.dot(h);
            let denominator = oh + pair.eta_path * ih;
            let dg = microfacet.d(h) * microfacet.g(o, i, h);
            // Mitsuba's 1 / η² for radiance cancels the η² of the change of variables.
            let t = (1.0 - dielectric) * dg * (oh * ih / (o.z * denominator * denominator)).abs();
            value += self.base_color.max(Vec3::ZERO).powf(0.5) * (transmitting * t);
        }
        if !(front && i.z > 0.0) {
            return value;
        }
        if pair.reflects && self.clearcoat > 0.0 {
            value += Vec3::splat(self.clearcoat_value(o, i, h));
        }
        if reflecting > 0.0 {
            value += self.diffuse_and_sheen(o, i, h, reflecting);
        }
        value
    }

    /// The clearcoat's value (times cos θi, as Mitsuba writes it).
    fn clearcoat_value(&self, o: Vec3, i: Vec3, h: Vec3) -> f32 {
        let fresnel = schlick(Vec3::splat(0.04), o.dot(h), self.eta).x;
        let masking = Microfacet::ggx(0.25).g(o, i, h);
        0.25 * self.clearcoat * fresnel * gtr1(h, self.clearcoat_alpha()) * masking * i.z
    }

    /// GTR1's roughness for the clearcoat.
    fn clearcoat_alpha(&self) -> f32 {
        0.1 + self.clearcoat_gloss * (0.001 - 0.1)
    }

    /// The diffuse lobe (Burley's, with retro-reflection, blended toward the flattened one)
    /// and the sheen, front side only.
    fn diffuse_and_sheen(&self, o: Vec3, i: Vec3, h: Vec3, reflecting: f32) -> Vec3 {
        let cos_d = h.dot(i);
        let shape = burley_diffuse(self.roughness, self.flatness, o.z, i.z, cos_d);
        let mut value = self.base_color * (reflecting * i.z / PI * shape);
        let dielectric = 1.0 - self.metallic;
        if self.sheen > 0.0 && dielectric > 0.0 {
            let sheen = sheen(self.base_color, self.sheen_tint, cos_d);
            value += sheen * (self.sheen * dielectric * i.z);
        }
        value
    }

    /// The probabilities of sampling each lobe for viewer `o` (diffuse, clearcoat,
    /// transmission, reflection; `None` where nothing scatters toward `o`).
    fn lobe_probabilities(&self, o: Vec3) -> Option<[f32; 4]> {
        let (reflecting, transmitting) = self.part_weights();
        let dielectric = dielectric_fresnel(o.z, self.eta);
        let rates = self.rates;
        let weights = if o.z > 0.0 {
            [
                reflecting * rates.diffuse,
                0.25 * self.clearcoat * rates.clearcoat,
                rates.specular * transmitting * (1.0 - dielectric),
                rates.specular * (1.0 - transmitting * (1.0 - dielectric)),
            ]
        } else if transmitting > 0.0 {
            [0.0, 0.0, 1.0 - dielectric, dielectric]
        } else {
            return None;
        };
        let total: f32 = weights.iter().sum();
        (total > 0.0 && total.is_finite()).then(|| weights.map(|w| w / total))
    }

    /// A light direction for viewer `o` (local; `None`: the sample scatters nowhere).
    pub fn sample(&self, o: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if o.z == 0.0 {
            return None;
        }
        let probabilities = self.lobe_probabilities(o)?;
        const LOBES: [Lobe; 4] = [
            Lobe::Diffuse,
            Lobe::Clearcoat,
            Lobe::Transmission,
            Lobe::Reflection,
        ];
        let (index, u0) = pick_lobe(probabilities, u[0]);
        let lobe = LOBES[index];
        let u = [u0, u[1]];
        let upper = o * o.z.signum();
        let i = match lobe {
            Lobe::Diffuse => cosine_hemisphere(u),
            Lobe::Clearcoat => reflect(o, sample_gtr1(self.clearcoat_alpha(), u)),
            Lobe::Reflection => reflect(o, self.microfacet().sample(upper, u)),
            Lobe::Transmission => {
                let h = self.microfacet().sample(upper, u);
                let eta_path = if o.z > 0.0 { self.eta } else { 1.0 / self.eta };
                refract(o, h, eta_path)?
            }
        };
        let pair = self.pair(o, i);
        let valid = match lobe {
            Lobe::Diffuse => i.z > 0.0,
            Lobe::Transmission => pair.refracts,
            Lobe::Clearcoat | Lobe::Reflection => pair.reflects,
        };
        (valid && i.is_finite()).then_some(i)
    }

    /// Density of [`Principled::sample`] at `i`.
    pub fn pdf(&self, o: Vec3, i: Vec3) -> f32 {
        if o.z == 0.0 {
            return 0.0;
        }
        let Some([diffuse, clearcoat, transmission, reflection]) = self.lobe_probabilities(o)
        else {
            return 0.0;
        };
        let pair = self.pair(o, i);
        let h = pair.h;
        let upper = o * o.z.signum();
        let mut pdf = 0.0;
        if pair.reflects {
            let jacobian = 1.0 / (4.0 * i.dot(h).abs());
            let normals = reflection * self.microfacet().pdf(upper, h)
                + clearcoat * h.z * gtr1(h, self.clearcoat_alpha());
            pdf += normals * jacobian;
            if o.z > 0.0 {
                pdf += diffuse * i.z / PI;
            }
        }
        if pair.refracts && transmission > 0.0 {
            let ih = i.dot(h);
            let denominator = o.dot(h) + pair.eta_path * ih;
            let jacobian = pair.eta_path * pair.eta_path * ih.abs() / (denominator * denominator);
            pdf += transmission * self.microfacet().pdf(upper, h) * jacobian;
        }
        pdf
    }
}

/// The index of the lobe that `u` picks among `probabilities` (summing to 1), and `u`
/// rescaled to [0, 1) within it.
pub(super) fn pick_lobe(probabilities: [f32; 4], u: f32) -> (usize, f32) {
    let last = (0..4).rev().find(|&k| probabilities[k] > 0.0).unwrap_or(3);
    let mut start = 0.0;
    for (k, &p) in probabilities.iter().enumerate().take(last + 1) {
        if p > 0.0 && (u < start + p || k == last) {
            return (k, ((u - start) / p).clamp(0.0, 1.0 - 1e-7));
        }
        start += p;
    }
    (last, 0.0)
}

/// The GGX distribution of `roughness` and `anisotropic` (Mitsuba's `calc_dist_params`:
/// α = roughness², stretched by anisotropy; α may exceed 1 when anisotropic, as in
/// Mitsuba).
pub(super) fn ggx(roughness: f32, anisotropic: f32) -> Microfacet {
    let alpha = roughness * roughness;
    let aspect = (1.0 - 0.9 * anisotropic).max(0.0).sqrt();
    let (alpha_u, alpha_v) = if anisotropic > 0.0 {
        (alpha / aspect, alpha * aspect)
    } else {
        (alpha, alpha)
    };
    Microfacet {
        kind: MicrofacetKind::Ggx,
        alpha_u: alpha_u.max(1e-3),
        alpha_v: alpha_v.max(1e-3),
    }
}

/// The base colour over its luminance (white where it is black).
pub(super) fn tint(base_color: Vec3) -> Vec3 {
    let lum = luminance(base_color);
    if lum > 0.0 {
        base_color / lum
    } else {
        Vec3::ONE
    }
}

/// Burley's diffuse shape (times π / albedo): Fresnel-shaped, with retro-reflection that
/// grows with `roughness`, blended toward the flattened (fake subsurface) lobe by
/// `flatness`; `cos_o`, `cos_i` at the normal (both above), `cos_d` between the half
/// vector and the light.
pub(super) fn burley_diffuse(
    roughness: f32,
    flatness: f32,
    cos_o: f32,
    cos_i: f32,
    cos_d: f32,
) -> f32 {
    let (fo, fi) = (schlick_weight(cos_i), schlick_weight(cos_o));
    let diffuse = (1.0 - 0.5 * fi) * (1.0 - 0.5 * fo);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let retro = rr * (fo + fi + fo * fi * (rr - 1.0));
    let fss90 = rr / 2.0;
    let fss = (1.0 + (fss90 - 1.0) * fo) * (1.0 + (fss90 - 1.0) * fi);
    let flat = 1.25 * (fss * (1.0 / (cos_i + cos_o) - 0.5) + 0.5);
    diffuse + retro + flatness * (flat - diffuse - retro)
}

/// The sheen's colour times its Fresnel-like weight at `cos_d`.
pub(super) fn sheen(base_color: Vec3, sheen_tint: f32, cos_d: f32) -> Vec3 {
    let colour = Vec3::ONE + sheen_tint * (tint(base_color) - Vec3::ONE);
    colour * schlick_weight(cos_d.abs())
}

/// `o` mirrored about the microfacet `h`.
pub(super) fn reflect(o: Vec3, h: Vec3) -> Vec3 {
    2.0 * o.dot(h) * h - o
}

/// The dielectric's exact reflectance for light arriving from the side `cos_theta` is on.
fn dielectric_fresnel(cos_theta: f32, eta: f32) -> f32 {
    if cos_theta >= 0.0 {
        fresnel_dielectric(cos_theta, eta)
    } else {
        fresnel_dielectric(-cos_theta, 1.0 / eta)
    }
}

/// (1 − cos)⁵, clamped.
fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's approximation from normal reflectance `r0`, at the refracted angle where the
/// light leaves the denser side (Mitsuba's `calc_schlick`).
pub(super) fn schlick(r0: Vec3, cos_i: f32, eta: f32) -> Vec3 {
    let eta_it = if cos_i >= 0.0 { eta } else { 1.0 / eta };
    let weight = if eta_it > 1.0 {
        schlick_weight(cos_i.abs())
    } else {
        let cos_t2 = 1.0 - (1.0 - cos_i * cos_i) / (eta_it * eta_it);
        schlick_weight(cos_t2.max(0.0).sqrt())
    };
    r0 + (Vec3::ONE - r0) * weight
}

/// Burley's GTR1 density of microfacet normals (the clearcoat's), per projected area.
fn gtr1(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let value = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * h.z * h.z));
    if value * h.z > 1e-20 {
        value
    } else {
        0.0
    }
}

/// A normal drawn from GTR1 times cos θh.
fn sample_gtr1(alpha: f32, u: [f32; 2]) -> Vec3 {
    let a2 = alpha * alpha;
    let cos2 = (1.0 - a2.powf(1.0 - u[1])) / (1.0 - a2);
    let (sin, cos) = ((1.0 - cos2).max(0.0).sqrt(), cos2.max(0.0).sqrt());
    let phi = 2.0 * PI * u[0];
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_specular_parameter_maps_to_an_index() {
        assert!((eta_from_specular(0.5) - 1.5).abs() < 1e-5);
    }
}
