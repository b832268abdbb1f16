//! Mitsuba's `pplastic` as its RGB (unpolarized) variants evaluate it: a microfacet
//! reflection off a dielectric interface, F(ωo·h) D G / (4 cos θo cos θi), plus a diffuse
//! base seen through the interface twice, (1 − F(cos θo)) (1 − F(cos θi)) ρ / π, both on
//! the front side only. Unlike `roughplastic`, no light is reflected back and forth inside
//! the coating.
//!
//! Sampled as a mixture: the microfacet reflection (the distribution's own sampler) with
//! the share the specular tint has of the two tints' means (Mitsuba's weight), otherwise a
//! cosine-weighted direction.

use super::{fresnel_dielectric, Microfacet};
use ais::sampling::cosine_hemisphere;
use glam::Vec3;
use std::f32::consts::PI;

/// The polarized plastic, unpolarized.
#[derive(Clone, Debug, PartialEq)]
pub struct PolarizedPlastic {
    /// The interface's microfacets.
    pub microfacet: Microfacet,
    /// Relative index of refraction, interior over exterior.
    pub eta: f32,
    /// Albedo of the base.
    pub diffuse: Vec3,
    /// Tint of the interface's reflection.
    pub specular: Vec3,
    /// The probability of sampling the microfacet reflection.
    specular_probability: f32,
}

impl PolarizedPlastic {
    /// A polarized plastic.
    pub fn new(microfacet: Microfacet, eta: f32, diffuse: Vec3, specular: Vec3) -> Self {
        let mean = |c: Vec3| (c.x + c.y + c.z) / 3.0;
        let (d, s) = (mean(diffuse), mean(specular));
        let specular_probability = if d + s > 0.0 { s / (d + s) } else { 0.5 };
        PolarizedPlastic {
            microfacet,
            eta,
            diffuse,
            specular,
            specular_probability: specular_probability.clamp(0.05, 0.95),
        }
    }

    /// The same plastic with base albedo `diffuse`.
    pub fn with_diffuse(&self, diffuse: Vec3) -> Self {
        PolarizedPlastic::new(self.microfacet, self.eta, diffuse, self.specular)
    }

    /// The same plastic with interface tint `specular`.
    pub fn with_specular(&self, specular: Vec3) -> Self {
        PolarizedPlastic::new(self.microfacet, self.eta, self.diffuse, specular)
    }

    /// BSDF times cos θi for viewer `o` and light direction `i` (local, both above).
    pub fn eval(&self, o: Vec3, i: Vec3) -> Vec3 {
        if o.z <= 0.0 || i.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (o + i).normalize();
        let reflection = fresnel_dielectric(o.dot(h), self.eta)
            * self.microfacet.d(h)
            * self.microfacet.g(o, i, h)
            / (4.0 * o.z);
        let through =
            (1.0 - fresnel_dielectric(o.z, self.eta)) * (1.0 - fresnel_dielectric(i.z, self.eta));
        self.specular * reflection + self.diffuse * (through * i.z / PI)
    }

    /// A light direction for viewer `o` (local; `None`: the sample left the front side).
    pub fn sample(&self, o: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if o.z <= 0.0 {
            return None;
        }
        let p = self.specular_probability;
        if u[0] < p {
            let reused = (u[0] / p).min(1.0 - 1e-7);
            let h = self.microfacet.sample(o, [reused, u[1]]);
            let i = 2.0 * o.dot(h) * h - o;
            return (i.z > 0.0).then_some(i);
        }
        let reused = ((u[0] - p) / (1.0 - p)).min(1.0 - 1e-7);
        Some(cosine_hemisphere([reused, u[1]]))
    }

    /// Density of [`PolarizedPlastic::sample`] at `i`.
    pub fn pdf(&self, o: Vec3, i: Vec3) -> f32 {
        if o.z <= 0.0 || i.z <= 0.0 {
            return 0.0;
        }
        let h = (o + i).normalize();
        let oh = o.dot(h);
        let reflection = if oh > 0.0 {
            self.microfacet.pdf(o, h) / (4.0 * oh)
        } else {
            0.0
        };
        let p = self.specular_probability;
        p * reflection + (1.0 - p) * i.z / PI
    }
}
