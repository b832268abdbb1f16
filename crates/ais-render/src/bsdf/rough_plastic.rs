//! Mitsuba 3's `roughplastic`: a rough dielectric coating over a Lambertian base.
//!
//! In a local frame (normal +z), with `o` toward the viewer and `i` toward the light, the
//! BSDF times cos θi is
//!
//! ```text
//! specular · F(o·h) D(h) G(i, o) / (4 cos θo)
//!   + ρ / (1 − R_int) · cos θi / (π η²) · T(cos θo) T(cos θi)
//! ```
//!
//! where T(μ) is the energy that enters the rough interface from direction μ (transmitted
//! and not masked on the way in, single scattering), and R_int is the interface's
//! reflectance seen from inside, averaged over a cosine-weighted hemisphere. With
//! `nonlinear = true` the denominator is 1 − ρ R_int. Both are integrated here over the
//! visible normals and follow Mitsuba's definitions, including its discrete
//! average for R_int (twice the mean of R(μ) μ over 64 equally spaced μ in [0, 1]), which
//! is about 1.5% below the exact integral for η = 1.5 and changes the diffuse term by 2%.

use super::microfacet::{fresnel_dielectric, Microfacet, MicrofacetKind};
use ais::sampling::cosine_hemisphere;
use glam::Vec3;
use std::collections::HashMap;
use std::f32::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Entries of the transmittance table over μ = cos θ ∈ [0, 1] (Mitsuba's resolution).
const TABLE_SIZE: usize = 64;
/// Quadrature points per axis over the visible-normal sample square.
const QUADRATURE: usize = 64;

/// A rough plastic's parameters and its precomputed interface terms.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughPlastic {
    /// Microfacet distribution of the coating.
    pub microfacet: Microfacet,
    /// Relative index, interior over exterior.
    pub eta: f32,
    /// Albedo of the base.
    pub diffuse: Vec3,
    /// Multiplier of the specular lobe.
    pub specular: Vec3,
    /// Mitsuba's `nonlinear`: the base's colour also tints its inter-reflections.
    pub nonlinear: bool,
    interface: Arc<Interface>,
    specular_weight: f32,
}

/// The share of samples the specular lobe gets: its mean reflectance over both lobes'.
pub(super) fn specular_weight(diffuse: Vec3, specular: Vec3) -> f32 {
    let d_mean = (diffuse.x + diffuse.y + diffuse.z) / 3.0;
    let s_mean = (specular.x + specular.y + specular.z) / 3.0;
    if d_mean + s_mean > 0.0 {
        s_mean / (d_mean + s_mean)
    } else {
        0.5
    }
}

#[derive(Debug, PartialEq)]
struct Interface {
    transmittance: [f32; TABLE_SIZE],
    internal_reflectance: f32,
}

impl RoughPlastic {
    /// A rough plastic; the interface terms for (`microfacet`, `eta`) are computed once per
    /// process.
    pub fn new(
        microfacet: Microfacet,
        eta: f32,
        diffuse: Vec3,
        specular: Vec3,
        nonlinear: bool,
    ) -> Self {
        RoughPlastic {
            interface: Interface::cached(microfacet, eta),
            microfacet,
            eta,
            diffuse,
            specular,
            nonlinear,
            specular_weight: specular_weight(diffuse, specular),
        }
    }

    /// The same plastic with base albedo `diffuse` (the interface terms are shared).
    pub fn with_diffuse(&self, diffuse: Vec3) -> Self {
        RoughPlastic {
            diffuse,
            specular_weight: specular_weight(diffuse, self.specular),
            ..self.clone()
        }
    }

    /// The same plastic with coating tint `specular` (the interface terms are shared).
    pub fn with_specular(&self, specular: Vec3) -> Self {
        RoughPlastic {
            specular,
            specular_weight: specular_weight(self.diffuse, specular),
            ..self.clone()
        }
    }

    /// T(μ), interpolated linearly in the table.
    fn transmittance(&self, mu: f32) -> f32 {
        let x = mu.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f32;
        let index = (x as usize).min(TABLE_SIZE - 2);
        let table = &self.interface.transmittance;
        table[index] + (x - index as f32) * (table[index + 1] - table[index])
    }

    /// BSDF times cos θi, in the local frame (both directions above the surface).
    pub fn eval(&self, o: Vec3, i: Vec3) -> Vec3 {
        let h = (o + i).normalize();
        let glossy = self.specular
            * (fresnel_dielectric(o.dot(h), self.eta)
                * self.microfacet.d(h)
                * self.microfacet.g(i, o, h)
                / (4.0 * o.z));
        let inter_reflection = if self.nonlinear {
            Vec3::ONE - self.diffuse * self.interface.internal_reflectance
        } else {
            Vec3::splat(1.0 - self.interface.internal_reflectance)
        };
        let base = self.diffuse / inter_reflection
            * (i.z / (PI * self.eta * self.eta)
                * self.transmittance(o.z)
                * self.transmittance(i.z));
        glossy + base
    }

    /// Probability of sampling the specular lobe for a view at cos θ = `mu` (Mitsuba's
    /// choice: the reflected share of the energy, weighted by the lobes' mean albedos).
    fn specular_probability(&self, mu: f32) -> f32 {
        let t = self.transmittance(mu);
        let specular = (1.0 - t) * self.specular_weight;
        let diffuse = t * (1.0 - self.specular_weight);
        if specular + diffuse > 0.0 {
            specular / (specular + diffuse)
        } else {
            0.5
        }
    }

    /// A local direction for view `o` (o.z > 0) from `u`.
    pub fn sample(&self, o: Vec3, u: [f32; 2]) -> Vec3 {
        let p = self.specular_probability(o.z);
        if u[0] < p {
            let h = self.microfacet.sample(o, [u[0] / p, u[1]]);
            2.0 * o.dot(h) * h - o
        } else {
            cosine_hemisphere([((u[0] - p) / (1.0 - p)).clamp(0.0, 1.0 - 1e-7), u[1]])
        }
    }

    /// Density of [`RoughPlastic::sample`] at local direction `i` (i.z > 0), given the
    /// specular lobe's density `microfacet`.
    pub fn pdf(&self, o: Vec3, i: Vec3, microfacet: f32) -> f32 {
        let p = self.specular_probability(o.z);
        p * microfacet + (1.0 - p) * i.z / PI
    }
}

impl Interface {
    /// The terms for (`ggx`, `eta`), computed on first use and shared afterwards.
    fn cached(microfacet: Microfacet, eta: f32) -> Arc<Interface> {
        type Key = (MicrofacetKind, u32, u32);
        static CACHE: OnceLock<Mutex<HashMap<Key, Arc<Interface>>>> = OnceLock::new();
        let cache = CACHE.get_or_init(Default::default);
        let key = (microfacet.kind, microfacet.alpha_u.to_bits(), eta.to_bits());
        if let Some(found) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return found.clone();
        }
        let computed = Arc::new(Interface::compute(microfacet, eta));
        cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry(key)
            .or_insert(computed)
            .clone()
    }

    fn compute(microfacet: Microfacet, eta: f32) -> Interface {
        let nodes = || (0..TABLE_SIZE).map(|j| (j as f32 / (TABLE_SIZE - 1) as f32).max(1e-6));
        let mut transmittance = [0.0; TABLE_SIZE];
        for (entry, mu) in transmittance.iter_mut().zip(nodes()) {
            *entry = interface_energy(microfacet, eta, mu).1;
        }
        let reflected: f32 = nodes()
            .map(|mu| interface_energy(microfacet, 1.0 / eta, mu).0 * mu)
            .sum();
        Interface {
            transmittance,
            internal_reflectance: 2.0 * reflected / TABLE_SIZE as f32,
        }
    }
}

/// (reflected, transmitted) energy of light from cos θ = `mu` on a rough interface of
/// relative index `eta` (the far side over this side): the visible-normal expectation of
/// F·G1(reflected) and (1 − F)·G1(refracted), by importance-sampled midpoint quadrature.
fn interface_energy(microfacet: Microfacet, eta: f32, mu: f32) -> (f32, f32) {
    let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (mut reflected, mut transmitted) = (0.0f64, 0.0f64);
    for a in 0..QUADRATURE {
        for b in 0..QUADRATURE {
            let u = [
                (a as f32 + 0.5) / QUADRATURE as f32,
                (b as f32 + 0.5) / QUADRATURE as f32,
            ];
            let m = microfacet.sample(wi, u);
            let cos = wi.dot(m);
            let density = microfacet.pdf(wi, m);
            if cos <= 0.0 || density <= 0.0 {
                continue;
            }
            // Visible-normal density over the sampler's density.
            let weight = (microfacet.g1(wi, m) * cos * microfacet.d(m) / (mu * density)) as f64;
            let fresnel = fresnel_dielectric(cos, eta);
            let reflection = 2.0 * cos * m - wi;
            if reflection.z > 0.0 {
                reflected += weight * (fresnel * microfacet.g1(reflection, m)) as f64;
            }
            let sin2_t = (1.0 - cos * cos) / (eta * eta);
            if sin2_t < 1.0 {
                let cos_t = (1.0 - sin2_t).sqrt();
                let refraction = -wi / eta + (cos / eta - cos_t) * m;
                if refraction.z < 0.0 {
                    transmitted += weight * ((1.0 - fresnel) * microfacet.g1(refraction, m)) as f64;
                }
            }
        }
    }
    let n = (QUADRATURE * QUADRATURE) as f64;
    ((reflected / n) as f32, (transmitted / n) as f32)
}
