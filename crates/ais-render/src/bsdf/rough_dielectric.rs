//! Mitsuba 3's `roughdielectric`: a rough interface that reflects and transmits, the
//! microfacet model of Walter et al. (2007), seen from either side.
//!
//! In a local frame (normal +z), with `o` toward the viewer and `i` toward the light, and η
//! the ratio of the indices beyond and before the interface as seen from `o`'s side:
//!
//! ```text
//! reflection (o, i on one side):    F(o·h) D(h) G(o, i) / (4 |cos θo|),   h ∝ o + i
//! transmission (opposite sides):    (1 − F(o·h)) D(h) G(o, i) |o·h| |i·h|
//!                                   / (|cos θo| (o·h + η i·h)²),            h ∝ o + η i
//! ```
//!
//! each times cos θi already (what the gather multiplies radiance by), with `h` turned to
//! the macro normal's side. The transmitted term is for radiance (Mitsuba's factor 1/η²
//! cancels the η² of the change of variables). Samples pick reflection with probability
//! F(cos θo) at the macro normal (kept within [0.05, 0.95] so that both lobes are drawn),
//! then a microfacet normal from the distribution's own sampler.

use super::microfacet::{fresnel_dielectric, Microfacet};
use glam::Vec3;

/// A rough dielectric interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// Microfacet distribution of the interface.
    pub microfacet: Microfacet,
    /// Relative index, interior over exterior.
    pub eta: f32,
    /// Multiplier of the reflection.
    pub reflectance: Vec3,
    /// Multiplier of the transmission.
    pub transmittance: Vec3,
}

/// The geometry of a pair of directions: the microfacet normal that links them, whether
/// they lie on one side, and the index ratio seen from the viewer's side.
struct Pair {
    h: Vec3,
    reflect: bool,
    eta: f32,
}

impl RoughDielectric {
    /// The index ratio beyond over before the interface, seen from `o`'s side.
    fn eta_from(&self, o: Vec3) -> f32 {
        if o.z > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        }
    }

    /// The microfacet normal linking `o` and `i` (`None` where the micro- and macro-surface
    /// disagree on a side, or at grazing angles).
    fn pair(&self, o: Vec3, i: Vec3) -> Option<Pair> {
        if o.z == 0.0 || i.z == 0.0 {
            return None;
        }
        let reflect = o.z * i.z > 0.0;
        let eta = self.eta_from(o);
        let h = (o + i * if reflect { 1.0 } else { eta }).normalize();
        let h = if h.z < 0.0 { -h } else { h };
        let agrees = o.dot(h) * o.z > 0.0 && i.dot(h) * i.z > 0.0;
        (agrees && h.is_finite()).then_some(Pair { h, reflect, eta })
    }

    /// Fresnel reflectance of the microfacet `h` (on `o`'s side of it) for light arriving
    /// from `o`.
    fn fresnel(&self, o: Vec3, h: Vec3) -> f32 {
        fresnel_dielectric(o.dot(h).abs(), self.eta_from(o))
    }

    /// The probability that a sample from `o` reflects.
    fn reflect_probability(&self, o: Vec3) -> f32 {
        fresnel_dielectric(o.z.abs(), self.eta_from(o)).clamp(0.05, 0.95)
    }

    /// BSDF times |cos θi|, in the local frame.
    pub fn eval(&self, o: Vec3, i: Vec3) -> Vec3 {
        let Some(Pair { h, reflect, eta }) = self.pair(o, i) else {
            return Vec3::ZERO;
        };
        let d = self.microfacet.d(h);
        let g = self.microfacet.g(i, o, h);
        let f = self.fresnel(o, h);
        if reflect {
            return self.reflectance * (f * d * g / (4.0 * o.z.abs()));
        }
        let (oh, ih) = (o.dot(h), i.dot(h));
        let denominator = oh + eta * ih;
        let value = (1.0 - f) * d * g * (oh * ih).abs() / (o.z.abs() * denominator * denominator);
        self.transmittance * value
    }

    /// The density of [`RoughDielectric::sample`] at `i`.
    pub fn pdf(&self, o: Vec3, i: Vec3) -> f32 {
        let Some(Pair { h, reflect, eta }) = self.pair(o, i) else {
            return 0.0;
        };
        let upper = o * o.z.signum();
        let normal_density = self.microfacet.pdf(upper, h);
        let ih = i.dot(h);
        let (lobe, jacobian) = if reflect {
            (self.reflect_probability(o), 1.0 / (4.0 * ih.abs()))
        } else {
            let denominator = o.dot(h) + eta * ih;
            (
                1.0 - self.reflect_probability(o),
                eta * eta * ih.abs() / (denominator * denominator),
            )
        };
        lobe * normal_density * jacobian
    }

    /// A direction toward the light: a lobe, then a microfacet normal, reflected or
    /// refracted (`None` under total internal reflection or off the lobe's side).
    pub fn sample(&self, o: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if o.z == 0.0 {
            return None;
        }
        let p = self.reflect_probability(o);
        let (reflect, u0) = if u[0] < p {
            (true, u[0] / p)
        } else {
            (false, ((u[0] - p) / (1.0 - p)).min(1.0 - 1e-7))
        };
        let upper = o * o.z.signum();
        let h = self.microfacet.sample(upper, [u0, u[1]]);
        let oh = o.dot(h);
        // A microfacet facing away from the viewer scatters nothing (G is zero there).
        if oh * o.z <= 0.0 {
            return None;
        }
        let i = if reflect {
            2.0 * oh * h - o
        } else {
            refract(o, h, self.eta_from(o))?
        };
        let on_its_side = if reflect {
            i.z * o.z > 0.0
        } else {
            i.z * o.z < 0.0
        };
        (on_its_side && i.is_finite()).then_some(i)
    }
}

/// `o` refracted through the microfacet `h` into a medium of relative index `eta` (beyond
/// over before, seen from `o`), by Snell's law (`None` under total internal reflection).
pub(super) fn refract(o: Vec3, h: Vec3, eta: f32) -> Option<Vec3> {
    let oh = o.dot(h);
    let (facing, cos_o) = (h * oh.signum(), oh.abs());
    let sin2_t = (1.0 - cos_o * cos_o) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((facing * (cos_o / eta - cos_t) - o / eta).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glass(alpha: f32) -> RoughDielectric {
        RoughDielectric {
            microfacet: Microfacet::ggx(alpha),
            eta: 1.5,
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
        }
    }

    #[test]
    fn refraction_at_a_flat_microfacet_follows_snell() {
        let rough = glass(0.001);
        let o = Vec3::new(0.6, 0.0, 0.8);
        // A transmission sample: u[0] above the reflection probability.
        let i = rough.sample(o, [0.99, 0.5]).expect("transmits");
        assert!(i.z < 0.0);
        assert!((i.x + 0.6 / 1.5).abs() < 0.02, "{i:?}");
        // Seen from inside along i, the light comes back along o.
        let back = rough.sample(i, [0.99, 0.5]).expect("transmits back");
        assert!((back - o).length() < 0.05, "{back:?}");
    }

    #[test]
    fn the_density_is_consistent_with_the_samples_on_both_sides() {
        // ∫ pdf over the sphere, by a fine grid, equals the share of samples that are not
        // refused (total internal reflection, off-side samples).
        let rough = glass(0.4);
        for o in [Vec3::new(0.5, 0.1, 0.86), Vec3::new(0.3, -0.2, -0.93)] {
            let o = o.normalize();
            let n = 400;
            let mut integral = 0.0f64;
            for a in 0..n {
                for b in 0..2 * n {
                    let cos = 1.0 - 2.0 * (a as f64 + 0.5) / n as f64;
                    let phi = std::f64::consts::PI * (b as f64 + 0.5) / n as f64;
                    let sin = (1.0 - cos * cos).sqrt();
                    let i = Vec3::new(
                        (sin * phi.cos()) as f32,
                        (sin * phi.sin()) as f32,
                        cos as f32,
                    );
                    integral += rough.pdf(o, i) as f64;
                }
            }
            integral *= 4.0 * std::f64::consts::PI / (2 * n * n) as f64;
            let mut drawn = 0;
            let count = 20_000;
            for k in 0..count {
                let u = [
                    ((k as f32 + 0.5) / count as f32),
                    ((k * 7919 % count) as f32 + 0.5) / count as f32,
                ];
                drawn += usize::from(rough.sample(o, u).is_some());
            }
            let share = drawn as f64 / count as f64;
            assert!(
                (integral - share).abs() < 0.02,
                "{o:?}: ∫pdf {integral}, drawn {share}"
            );
        }
    }
}
