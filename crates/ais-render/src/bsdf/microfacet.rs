//! The isotropic GGX (Trowbridge-Reitz) microfacet distribution with Smith shadowing and
//! visible-normal sampling (Heitz 2018), in a local frame where the normal is +z.

use glam::Vec3;
use std::f32::consts::PI;

/// GGX with roughness `alpha` (Mitsuba's `alpha`, the distribution's width).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Roughness, clamped to [1e-4, 1].
    pub alpha: f32,
}

impl Ggx {
    /// A distribution of roughness `alpha`.
    pub fn new(alpha: f32) -> Self {
        Ggx {
            alpha: alpha.clamp(1e-4, 1.0),
        }
    }

    /// Density of microfacet normals `h` (per projected area).
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let denominator = (a2 - 1.0) * h.z * h.z + 1.0;
        a2 / (PI * denominator * denominator)
    }

    /// Smith's Λ for direction `w`.
    fn lambda(&self, w: Vec3) -> f32 {
        let cos2 = w.z * w.z;
        if cos2 <= 0.0 {
            return f32::INFINITY;
        }
        let tan2 = (1.0 - cos2).max(0.0) / cos2;
        0.5 * (-1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
    }

    /// Smith's masking for one direction.
    pub fn g1(&self, w: Vec3) -> f32 {
        if w.z <= 0.0 {
            0.0
        } else {
            1.0 / (1.0 + self.lambda(w))
        }
    }

    /// Separable masking-shadowing, G1(wi) G1(wo) (Mitsuba's choice).
    pub fn g(&self, wi: Vec3, wo: Vec3) -> f32 {
        self.g1(wi) * self.g1(wo)
    }

    /// A visible normal for viewing direction `wo` (z > 0).
    pub fn sample_visible(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        // Stretch the view so that the distribution becomes the unit hemisphere.
        let v = Vec3::new(self.alpha * wo.x, self.alpha * wo.y, wo.z).normalize();
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
        Vec3::new(self.alpha * n.x, self.alpha * n.y, n.z.max(1e-6)).normalize()
    }

    /// Density of [`Ggx::sample_visible`]: G1(wo) max(0, wo·h) D(h) / wo.z.
    pub fn pdf_visible(&self, wo: Vec3, h: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * wo.dot(h).max(0.0) * self.d(h) / wo.z
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
    fn ggx_normals_integrate_to_one_over_projected_area() {
        // ∫ D(h) cos θh dω = 1.
        let ggx = Ggx::new(0.3);
        let n = 400;
        let mut sum = 0.0;
        for i in 0..n {
            let cos = (i as f32 + 0.5) / n as f32;
            let h = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            sum += ggx.d(h) * cos * 2.0 * PI / n as f32;
        }
        assert!((sum - 1.0).abs() < 0.01, "{sum}");
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
