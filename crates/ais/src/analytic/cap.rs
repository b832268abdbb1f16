//! Spherical caps and their exact moments.

use glam::DVec3;
use std::f64::consts::PI;

/// The set of unit directions within `half_angle` of `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cap {
    axis: DVec3,
    half_angle: f64,
    cos_half_angle: f64,
}

impl Cap {
    /// A cap around `axis` (normalised here) with half-angle `half_angle` radians in (0, π).
    pub fn new(axis: DVec3, half_angle: f64) -> Self {
        Cap {
            axis: axis.normalize(),
            half_angle,
            cos_half_angle: half_angle.cos(),
        }
    }

    /// A cap whose axis has elevation `elevation` above the horizon and azimuth `azimuth`
    /// (radians), with half-angle `half_angle`.
    pub fn at(elevation: f64, azimuth: f64, half_angle: f64) -> Self {
        let (sin_e, cos_e) = elevation.sin_cos();
        Cap::new(
            DVec3::new(cos_e * azimuth.cos(), cos_e * azimuth.sin(), sin_e),
            half_angle,
        )
    }

    /// The unit axis.
    pub fn axis(&self) -> DVec3 {
        self.axis
    }

    /// The half-angle in radians.
    pub fn half_angle(&self) -> f64 {
        self.half_angle
    }

    /// Whether a unit direction lies in the cap.
    #[inline]
    pub fn contains(&self, direction: DVec3) -> bool {
        self.axis.dot(direction) >= self.cos_half_angle
    }

    /// Angular distance between the axes of two caps.
    pub fn axis_angle(&self, other: &Cap) -> f64 {
        self.axis.dot(other.axis).clamp(-1.0, 1.0).acos()
    }

    /// Whether the whole cap lies in the upper hemisphere (z ≥ 0).
    pub fn is_above_horizon(&self) -> bool {
        self.axis.z.clamp(-1.0, 1.0).acos() + self.half_angle <= PI / 2.0 + 1e-12
    }

    /// Solid angle, 2π (1 − cos α).
    pub fn solid_angle(&self) -> f64 {
        2.0 * PI * (1.0 - self.cos_half_angle)
    }

    /// ∫_cap w dω = axis · π sin²α.
    pub fn first_moment(&self) -> DVec3 {
        self.axis * PI * (1.0 - self.cos_half_angle * self.cos_half_angle)
    }

    /// ∫_cap (a·w)(b·w) dω. In the cap's frame the second moment is diagonal: the axial term
    /// is 2π (1 − cos³α) / 3 and each transverse term is half of what remains of the solid angle.
    pub fn second_moment(&self, a: DVec3, b: DVec3) -> f64 {
        let axial = 2.0 * PI * (1.0 - self.cos_half_angle.powi(3)) / 3.0;
        let transverse = (self.solid_angle() - axial) / 2.0;
        transverse * a.dot(b) + (axial - transverse) * a.dot(self.axis) * b.dot(self.axis)
    }

    /// Fraction of the cosine-weighted hemisphere it covers, (1/π) ∫_cap w_z dω (cap above horizon).
    pub fn cosine_mass(&self) -> f64 {
        self.first_moment().z / PI
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    /// Monte Carlo integral over the sphere of `g` restricted to the cap.
    fn monte_carlo(cap: &Cap, g: impl Fn(DVec3) -> f64) -> f64 {
        let mut rng = Pcg32::new(11, 3);
        let n = 400_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let z = 1.0 - 2.0 * rng.next_f64();
            let phi = 2.0 * PI * rng.next_f64();
            let r = (1.0 - z * z).sqrt();
            let w = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            if cap.contains(w) {
                sum += g(w);
            }
        }
        sum * 4.0 * PI / n as f64
    }

    #[test]
    fn moments_match_monte_carlo() {
        let cap = Cap::at(0.6, 1.1, 0.5);
        let a = DVec3::new(0.3, -0.4, 0.8);
        let b = DVec3::Z;
        let tolerance = 0.01;
        assert!((monte_carlo(&cap, |_| 1.0) - cap.solid_angle()).abs() < tolerance);
        let m = cap.first_moment();
        assert!((monte_carlo(&cap, |w| w.x) - m.x).abs() < tolerance);
        assert!((monte_carlo(&cap, |w| w.z) - m.z).abs() < tolerance);
        let second = monte_carlo(&cap, |w| a.dot(w) * b.dot(w));
        assert!(
            (second - cap.second_moment(a, b)).abs() < tolerance,
            "{second}"
        );
    }

    #[test]
    fn horizon_check() {
        assert!(Cap::at(0.8, 0.0, 0.7).is_above_horizon());
        assert!(!Cap::at(0.3, 0.0, 0.4).is_above_horizon());
    }
}
