//! Smooth surfaces: Mitsuba 3's `conductor`, `plastic`, `dielectric` and `thindielectric`,
//! whose mirror and refraction lobes scatter light into single directions.
//!
//! Such a lobe is a point mass: it has no density over directions, so light sampling can
//! never find it (as in Mitsuba's `direct`, only BSDF samples see what a mirror reflects).
//! A BSDF sample that picks it comes back as a [`SpecularLobe`]: its direction, the lobe's
//! mass (the reflectance or transmittance it carries, the cosine included) and the
//! probability that the sampler picked it, so that the sample weighs mass / probability.
//! All formulas follow Mitsuba's plugins of the same names, in a local frame (normal +z,
//! `o` toward the viewer).

use super::microfacet::{fresnel_conductor, fresnel_dielectric};
use ais::sampling::cosine_hemisphere;
use glam::Vec3;
use std::f32::consts::PI;

/// One lobe of a smooth surface, chosen by a BSDF sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularLobe {
    /// The direction it scatters into (local frame).
    pub local: Vec3,
    /// Its mass: what it multiplies the radiance arriving from `local` by.
    pub weight: Vec3,
    /// The probability that the BSDF sample picked it.
    pub probability: f32,
}

/// What a BSDF sample of a surface with a specular lobe gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LobeSample {
    /// A direction from the continuous part (local frame).
    Continuous(Vec3),
    /// A specular lobe.
    Specular(SpecularLobe),
}

/// The mirror direction of `o` (local frame).
fn reflect(o: Vec3) -> Vec3 {
    Vec3::new(-o.x, -o.y, o.z)
}

/// A smooth conductor's mirror lobe (`eta = k = 0`: Mitsuba's `material = "none"`, F = 1);
/// `None` seen from behind.
pub fn conductor_lobe(o: Vec3, eta: Vec3, k: Vec3, specular: Vec3) -> Option<SpecularLobe> {
    if o.z <= 0.0 {
        return None;
    }
    let fresnel = if eta == Vec3::ZERO && k == Vec3::ZERO {
        Vec3::ONE
    } else {
        fresnel_conductor(o.z, eta, k)
    };
    Some(SpecularLobe {
        local: reflect(o),
        weight: specular * fresnel,
        probability: 1.0,
    })
}

/// Mitsuba's `dielectric` or `thindielectric`: a smooth interface that reflects and
/// transmits; seen from either side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Relative index, interior over exterior.
    pub eta: f32,
    /// Multiplier of the reflection.
    pub reflectance: Vec3,
    /// Multiplier of the transmission.
    pub transmittance: Vec3,
    /// A thin sheet (`thindielectric`): light passes straight through, and the reflectance
    /// counts the light bounced inside the sheet.
    pub thin: bool,
}

/// At a dielectric interface of relative index `eta` (interior over exterior), for light
/// arriving at signed `cos_i` (negative from inside): the Fresnel reflectance, the signed
/// cosine of the transmitted direction, and the ratio of the indices on the arriving side
/// over the far side.
fn fresnel_refraction(cos_i: f32, eta: f32) -> (f32, f32, f32) {
    let outside = cos_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let reflectance = fresnel_dielectric(cos_i.abs(), eta_it);
    let sin2_t = eta_ti * eta_ti * (1.0 - cos_i * cos_i);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    (reflectance, if outside { -cos_t } else { cos_t }, eta_ti)
}

impl Dielectric {
    /// The lobe a sample `u` in [0, 1) picks: reflection with probability R, else
    /// transmission (for a thick interface, radiance scaled by (η_i / η_t)², as Mitsuba
    /// does in radiance mode).
    pub fn sample(&self, o: Vec3, u: f32) -> Option<SpecularLobe> {
        if o.z == 0.0 {
            return None;
        }
        if self.thin {
            let r = fresnel_dielectric(o.z.abs(), self.eta);
            // Light bounced inside the sheet: r + t²r / (1 − r²).
            let r = if r < 1.0 {
                r + (1.0 - r) * (1.0 - r) * r / (1.0 - r * r)
            } else {
                r
            };
            return Some(if u < r {
                self.lobe(reflect(o), self.reflectance * r, r)
            } else {
                self.lobe(-o, self.transmittance * (1.0 - r), 1.0 - r)
            });
        }
        let (r, cos_t, eta_ti) = fresnel_refraction(o.z, self.eta);
        Some(if u < r {
            self.lobe(reflect(o), self.reflectance * r, r)
        } else {
            let refracted = Vec3::new(-eta_ti * o.x, -eta_ti * o.y, cos_t);
            let weight = self.transmittance * ((1.0 - r) * eta_ti * eta_ti);
            self.lobe(refracted.normalize(), weight, 1.0 - r)
        })
    }

    fn lobe(&self, local: Vec3, weight: Vec3, probability: f32) -> SpecularLobe {
        SpecularLobe {
            local,
            weight,
            probability,
        }
    }
}

/// Mitsuba's `plastic`: a smooth dielectric coating over a Lambertian base. Its mirror lobe
/// reflects F(θo) of the light; its base is
///
/// ```text
/// ρ / (1 − F_dr) · (1 − F(θo)) (1 − F(θi)) · cos θi / (π η²)
/// ```
///
/// with F_dr the coating's reflectance seen from inside, averaged over a cosine-weighted
/// hemisphere (`nonlinear = true`: 1 − ρ F_dr in the denominator).
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothPlastic {
    /// Relative index, interior over exterior.
    pub eta: f32,
    /// Albedo of the base.
    pub diffuse: Vec3,
    /// Multiplier of the mirror lobe.
    pub specular: Vec3,
    /// Mitsuba's `nonlinear`.
    pub nonlinear: bool,
    internal_reflectance: f32,
    specular_weight: f32,
}

impl SmoothPlastic {
    /// A smooth plastic.
    pub fn new(eta: f32, diffuse: Vec3, specular: Vec3, nonlinear: bool) -> Self {
        SmoothPlastic {
            eta,
            diffuse,
            specular,
            nonlinear,
            internal_reflectance: diffuse_fresnel_reflectance(1.0 / eta),
            specular_weight: super::rough_plastic::specular_weight(diffuse, specular),
        }
    }

    /// The same plastic with base albedo `diffuse`.
    pub fn with_diffuse(&self, diffuse: Vec3) -> Self {
        SmoothPlastic::new(self.eta, diffuse, self.specular, self.nonlinear)
    }

    /// The same plastic with coating tint `specular`.
    pub fn with_specular(&self, specular: Vec3) -> Self {
        SmoothPlastic::new(self.eta, self.diffuse, specular, self.nonlinear)
    }

    /// The probability that a sample seen from `o` picks the mirror lobe: its reflectance
    /// F(θo) weighed against the base's share, as Mitsuba's sampler does.
    fn mirror_probability(&self, o: Vec3) -> f32 {
        let f = fresnel_dielectric(o.z, self.eta);
        let mirror = f * self.specular_weight;
        let base = (1.0 - f) * (1.0 - self.specular_weight);
        if mirror + base > 0.0 {
            mirror / (mirror + base)
        } else {
            0.0
        }
    }

    /// The base's BSDF times cos θi (both directions above the surface).
    pub fn eval(&self, o: Vec3, i: Vec3) -> Vec3 {
        let inter_reflection = if self.nonlinear {
            Vec3::ONE - self.diffuse * self.internal_reflectance
        } else {
            Vec3::splat(1.0 - self.internal_reflectance)
        };
        let through =
            (1.0 - fresnel_dielectric(o.z, self.eta)) * (1.0 - fresnel_dielectric(i.z, self.eta));
        self.diffuse / inter_reflection * (through * i.z / (PI * self.eta * self.eta))
    }

    /// The density of the base's samples (both directions above the surface).
    pub fn pdf(&self, o: Vec3, i: Vec3) -> f32 {
        (1.0 - self.mirror_probability(o)) * i.z / PI
    }

    /// A sample: the mirror lobe, or a cosine-weighted direction for the base.
    pub fn sample(&self, o: Vec3, u: [f32; 2]) -> Option<LobeSample> {
        if o.z <= 0.0 {
            return None;
        }
        let mirror = self.mirror_probability(o);
        Some(if u[0] < mirror {
            LobeSample::Specular(SpecularLobe {
                local: reflect(o),
                weight: self.specular * fresnel_dielectric(o.z, self.eta),
                probability: mirror,
            })
        } else {
            let rescaled = ((u[0] - mirror) / (1.0 - mirror)).min(1.0 - 1e-7);
            LobeSample::Continuous(cosine_hemisphere([rescaled, u[1]]))
        })
    }
}

/// The reflectance of a dielectric interface of relative index `eta` to light arriving
/// uniformly over a cosine-weighted hemisphere: 2 ∫₀¹ F(μ) μ dμ (midpoint rule, 1,024
/// points; within 0.1% of the fits Mitsuba uses for η in [1, 2]).
pub fn diffuse_fresnel_reflectance(eta: f32) -> f32 {
    const POINTS: usize = 1024;
    let sum: f64 = (0..POINTS)
        .map(|k| {
            let mu = (k as f64 + 0.5) / POINTS as f64;
            fresnel_dielectric(mu as f32, eta) as f64 * mu
        })
        .sum();
    (2.0 * sum / POINTS as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_lobes_carry_what_fresnel_says_and_conserve_energy() {
        let glass = Dielectric {
            eta: 1.5,
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
            thin: false,
        };
        let o = Vec3::new(0.6, 0.0, 0.8);
        let reflected = glass.sample(o, 0.0).unwrap();
        assert_eq!(reflected.local, Vec3::new(-0.6, 0.0, 0.8));
        // Both lobes weigh mass / probability = 1, the transmitted one times 1/η².
        assert!((reflected.weight.x / reflected.probability - 1.0).abs() < 1e-6);
        let refracted = glass.sample(o, 0.999).unwrap();
        assert!(refracted.local.z < 0.0);
        // Snell: sin θt = sin θi / η.
        assert!(
            (refracted.local.x + 0.6 / 1.5).abs() < 1e-5,
            "{refracted:?}"
        );
        let ratio = refracted.weight.x / refracted.probability;
        assert!((ratio - 1.0 / 2.25).abs() < 1e-5);
        assert!((reflected.probability + refracted.probability - 1.0).abs() < 1e-6);
        // From inside beyond the critical angle, everything reflects.
        let grazing_inside = Vec3::new(0.9, 0.0, -(1.0f32 - 0.81).sqrt());
        let inside = glass.sample(grazing_inside, 0.999).unwrap();
        assert_eq!(inside.probability, 1.0);
        assert!(inside.local.z < 0.0, "it stays inside");
    }

    #[test]
    fn a_thin_sheet_passes_light_straight_and_counts_its_inner_bounces() {
        let sheet = Dielectric {
            eta: 1.5,
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
            thin: true,
        };
        let o = Vec3::new(0.0, 0.0, 1.0);
        let through = sheet.sample(o, 0.999).unwrap();
        assert_eq!(through.local, -o);
        // At normal incidence r = 0.04, and the sheet reflects 2r / (1 + r).
        let reflected = sheet.sample(o, 0.0).unwrap();
        assert!(
            (reflected.probability - 0.08 / 1.04).abs() < 1e-5,
            "{reflected:?}"
        );
    }

    #[test]
    fn the_diffuse_fresnel_reflectance_matches_known_values() {
        // Seen from inside glass (η = 1/1.5) most diffuse light is reflected back:
        // 1 − (1 − F_dr(1.5)) / η² with F_dr(1.5) ≈ 0.0918.
        let outside = diffuse_fresnel_reflectance(1.5);
        assert!((outside - 0.0918).abs() < 1e-3, "{outside}");
        let inside = diffuse_fresnel_reflectance(1.0 / 1.5);
        assert!(
            (inside - (1.0 - (1.0 - outside) / 2.25)).abs() < 1e-3,
            "{inside}"
        );
    }

    #[test]
    fn a_plastic_sample_picks_the_mirror_as_often_as_it_weighs() {
        let plastic = SmoothPlastic::new(1.5, Vec3::splat(0.5), Vec3::ONE, false);
        let o = Vec3::new(0.0, 0.8, 0.6);
        let mirror = plastic.mirror_probability(o);
        match plastic.sample(o, [mirror * 0.5, 0.3]).unwrap() {
            LobeSample::Specular(lobe) => {
                assert_eq!(lobe.local, Vec3::new(0.0, -0.8, 0.6));
                assert!((lobe.weight.x - fresnel_dielectric(0.6, 1.5)).abs() < 1e-7);
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            plastic.sample(o, [0.99, 0.3]),
            Some(LobeSample::Continuous(_))
        ));
        assert!(plastic.sample(-o, [0.5, 0.5]).is_none());
    }
}
