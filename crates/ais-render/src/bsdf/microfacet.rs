//! Microfacet distributions, Beckmann and GGX (Trowbridge-Reitz), isotropic or anisotropic,
//! with Smith masking, in a local frame where the normal is +z and +x the tangent (∂p/∂u).
//! As in Mitsuba 3: `alpha` (or `alpha_u` along the tangent and `alpha_v` across it) is the
//! distribution's width, Beckmann is the default when a scene names none, Beckmann's
//! masking uses Walter et al.'s rational approximation of Smith's G1, and shadowing-masking
//! is the separable product G1(wi) G1(wo). GGX is sampled by its visible normals (Heitz
//! 2018); Beckmann by its normal distribution D(h) cos θh (exact, though noisier at grazing
//! views than Mitsuba's visible-normal sampler).

use glam::Vec3;
use std::f32::consts::PI;

/// Which distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MicrofacetKind {
    /// exp(−tan²θ/α²) / (π α² cos⁴θ), Mitsuba's default.
    Beckmann,
    /// α² / (π cos⁴θ (α² + tan²θ)²).
    Ggx,
}

/// A microfacet distribution of roughness `alpha_u` along the tangent and `alpha_v` across.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    /// The distribution's shape.
    pub kind: MicrofacetKind,
    /// Roughness along the shading frame's tangent (∂p/∂u), clamped to [1e-4, 1].
    pub alpha_u: f32,
    /// Roughness along the bitangent; equal to `alpha_u` for an isotropic surface.
    pub alpha_v: f32,
}

impl Microfacet {
    /// A distribution of roughness `alpha`.
    pub fn new(kind: MicrofacetKind, alpha: f32) -> Self {
        Microfacet::anisotropic(kind, alpha, alpha)
    }

    /// A distribution of roughness `alpha_u` along the tangent and `alpha_v` across it.
    pub fn anisotropic(kind: MicrofacetKind, alpha_u: f32, alpha_v: f32) -> Self {
        // A roughness that is not a number (a texture's NaN) counts as the roughest.
        let clamp = |alpha: f32| {
            if alpha.is_nan() {
                1.0
            } else {
                alpha.clamp(1e-4, 1.0)
            }
        };
        Microfacet {
            kind,
            alpha_u: clamp(alpha_u),
            alpha_v: clamp(alpha_v),
        }
    }

    /// Whether the roughness differs along the tangent and across it.
    pub fn is_anisotropic(&self) -> bool {
        self.alpha_u != self.alpha_v
    }

    /// GGX of roughness `alpha`.
    pub fn ggx(alpha: f32) -> Self {
        Microfacet::new(MicrofacetKind::Ggx, alpha)
    }

    /// Beckmann of roughness `alpha`.
    pub fn beckmann(alpha: f32) -> Self {
        Microfacet::new(MicrofacetKind::Beckmann, alpha)
    }

    /// Density of microfacet normals `h` (per projected area).
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        if self.is_anisotropic() {
            return self.anisotropic_d(h);
        }
        let a2 = self.alpha_u * self.alpha_u;
        let cos2 = h.z * h.z;
        match self.kind {
            MicrofacetKind::Ggx => {
                // (α² − 1) cos² + 1, written as sin² + α² cos²: in f32, α² − 1 rounds to −1
                // for α below about 2.4e-4, and the denominator would vanish at the peak.
                let sin2 = h.x * h.x + h.y * h.y;
                let denominator = sin2 + a2 * cos2;
                a2 / (PI * denominator * denominator)
            }
            MicrofacetKind::Beckmann => {
                let tan2 = (1.0 - cos2).max(0.0) / cos2;
                (-tan2 / a2).exp() / (PI * a2 * cos2 * cos2)
            }
        }
    }

    /// [`Microfacet::d`] with different roughness along and across the tangent.
    fn anisotropic_d(&self, h: Vec3) -> f32 {
        let (au, av) = (self.alpha_u, self.alpha_v);
        let cos2 = h.z * h.z;
        // tan²θ (cos²φ / α_u² + sin²φ / α_v²)
        let e = (h.x * h.x / (au * au) + h.y * h.y / (av * av)) / cos2;
        let scale = PI * au * av * cos2 * cos2;
        match self.kind {
            MicrofacetKind::Ggx => 1.0 / (scale * (1.0 + e) * (1.0 + e)),
            MicrofacetKind::Beckmann => (-e).exp() / scale,
        }
    }

    /// Smith's masking of direction `w` (either side of the surface) by microfacet `m`:
    /// zero when `w` sees the back of `m`.
    pub fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        if w.dot(m) * w.z <= 0.0 {
            return 0.0;
        }
        let xy2 = w.x * w.x + w.y * w.y;
        if xy2 == 0.0 {
            return 1.0;
        }
        // tan²θ times the roughness projected on the direction's azimuth.
        let tan2_alpha2 = if self.is_anisotropic() {
            let (au, av) = (self.alpha_u, self.alpha_v);
            (au * au * w.x * w.x + av * av * w.y * w.y) / (w.z * w.z)
        } else {
            self.alpha_u * self.alpha_u * xy2 / (w.z * w.z)
        };
        match self.kind {
            MicrofacetKind::Ggx => 2.0 / (1.0 + (1.0 + tan2_alpha2).sqrt()),
            MicrofacetKind::Beckmann => {
                let a = 1.0 / tan2_alpha2.sqrt();
                if a >= 1.6 {
                    1.0
                } else {
                    (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)
                }
            }
        }
    }

    /// Separable masking-shadowing G1(wi, h) G1(wo, h).
    pub fn g(&self, wi: Vec3, wo: Vec3, h: Vec3) -> f32 {
        self.g1(wi, h) * self.g1(wo, h)
    }

    /// A microfacet normal for viewing direction `wo` (z > 0): visible normals for GGX,
    /// D(h) cos θh for Beckmann.
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        match self.kind {
            MicrofacetKind::Ggx => self.sample_visible_ggx(wo, u),
            MicrofacetKind::Beckmann if self.is_anisotropic() => {
                // Slopes of the unit distribution, stretched by the roughness.
                let radius = (-(1.0 - u[0]).max(1e-30).ln()).sqrt();
                let phi = 2.0 * PI * u[1];
                let slope = (
                    self.alpha_u * radius * phi.cos(),
                    self.alpha_v * radius * phi.sin(),
                );
                Vec3::new(-slope.0, -slope.1, 1.0).normalize()
            }
            MicrofacetKind::Beckmann => {
                let tan2 = -self.alpha_u * self.alpha_u * (1.0 - u[0]).max(1e-30).ln();
                let cos = 1.0 / (1.0 + tan2).sqrt();
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                let phi = 2.0 * PI * u[1];
                Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
            }
        }
    }

    /// Density of [`Microfacet::sample`] at normal `h`.
    pub fn pdf(&self, wo: Vec3, h: Vec3) -> f32 {
        match self.kind {
            MicrofacetKind::Ggx => {
                if wo.z <= 0.0 {
                    return 0.0;
                }
                self.g1(wo, h) * wo.dot(h).max(0.0) * self.d(h) / wo.z
            }
            MicrofacetKind::Beckmann => self.d(h) * h.z.max(0.0),
        }
    }

    fn sample_visible_ggx(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        // Stretch the view so that the distribution becomes the unit hemisphere.
        let v = Vec3::new(self.alpha_u * wo.x, self.alpha_v * wo.y, wo.z).normalize();
        let length2 = v.x * v.x + v.y * v.y;
        let t1 = if length2 > 0.0 {
            Vec3::new(-v.y, v.x, 0.0) / length2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = v.cross(t1);
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + v.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let n = t1 * p1 + t2 * p2 + v * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        Vec3::new(self.alpha_u * n.x, self.alpha_v * n.y, n.z.max(1e-6)).normalize()
    }
}

/// Fresnel reflectance of a conductor with complex index `eta + i k`, per channel.
pub fn fresnel_conductor(cos_theta: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c = cos_theta.clamp(0.0, 1.0);
    let cos2 = c * c;
    let sin2 = 1.0 - cos2;
    let channel = |eta: f32, k: f32| {
        let (eta2, k2) = (eta * eta, k * k);
        let t0 = eta2 - k2 - sin2;
        let a2b2 = (t0 * t0 + 4.0 * eta2 * k2).max(0.0).sqrt();
        let t1 = a2b2 + cos2;
        let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
        let t2 = 2.0 * c * a;
        let rs = (t1 - t2) / (t1 + t2);
        let t3 = cos2 * a2b2 + sin2 * sin2;
        let t4 = t2 * sin2;
        let rp = rs * (t3 - t4) / (t3 + t4);
        (0.5 * (rp + rs)).clamp(0.0, 1.0)
    };
    Vec3::new(
        channel(eta.x, k.x),
        channel(eta.y, k.y),
        channel(eta.z, k.z),
    )
}

/// Fresnel reflectance of a dielectric interface of relative index `eta` (inside over
/// outside), for light arriving from outside at `cos_theta`.
pub fn fresnel_dielectric(cos_theta: f32, eta: f32) -> f32 {
    let c = cos_theta.clamp(0.0, 1.0);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_integrate_to_one_over_projected_area() {
        // ∫ D(h) cos θh dω = 1.
        for distribution in [Microfacet::ggx(0.3), Microfacet::beckmann(0.3)] {
            let n = 4000;
            let mut sum = 0.0;
            for i in 0..n {
                let cos = (i as f32 + 0.5) / n as f32;
                let h = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
                sum += distribution.d(h) * cos * 2.0 * PI / n as f32;
            }
            assert!((sum - 1.0).abs() < 0.01, "{distribution:?}: {sum}");
        }
    }

    #[test]
    fn anisotropic_normals_integrate_to_one_over_projected_area() {
        for kind in [MicrofacetKind::Ggx, MicrofacetKind::Beckmann] {
            let distribution = Microfacet::anisotropic(kind, 0.15, 0.5);
            let (rows, columns) = (2000, 256);
            let mut sum = 0.0f64;
            for i in 0..rows {
                let cos = (i as f32 + 0.5) / rows as f32;
                let sin = (1.0 - cos * cos).sqrt();
                for j in 0..columns {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / columns as f32;
                    let h = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
                    let cell = (1.0 / rows as f32) * (2.0 * PI / columns as f32);
                    sum += (distribution.d(h) * cos * cell) as f64;
                }
            }
            assert!((sum - 1.0).abs() < 0.01, "{kind:?}: {sum}");
        }
    }

    #[test]
    fn fresnel_limits() {
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-4);
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-4);
        let gold = fresnel_conductor(
            1.0,
            Vec3::new(0.18, 0.42, 1.37),
            Vec3::new(3.42, 2.35, 1.77),
        );
        assert!(gold.x > 0.9 && gold.z < 0.7, "{gold:?}");
        // Normal incidence: ((η−1)² + k²) / ((η+1)² + k²).
        let expected = (0.5f32.powi(2) + 4.0) / (2.5f32.powi(2) + 4.0);
        assert!(
            (fresnel_conductor(1.0, Vec3::splat(1.5), Vec3::splat(2.0)).x - expected).abs() < 1e-4
        );
    }
}
