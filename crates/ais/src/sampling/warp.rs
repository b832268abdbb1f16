//! Warps from the unit square to directions, shared by every sampler that needs them: each
//! with its density and its inverse.

use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, TAU};

/// A direction uniform over the sphere (density [`uniform_sphere_pdf`]).
#[inline]
pub fn uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = crate::fast_trig::sin_cos(TAU * u[1]);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

/// The density of [`uniform_sphere`], 1 / 4π per steradian.
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// The `u` that [`uniform_sphere`] maps to a unit `direction`.
pub fn uniform_sphere_invert(direction: Vec3) -> [f32; 2] {
    [(1.0 - direction.z) * 0.5, azimuth_fraction(direction)]
}

/// A uniform point of the unit disk (density 1/π), by polar coordinates.
#[inline]
pub fn uniform_disk(u: [f32; 2]) -> [f32; 2] {
    let r = u[0].sqrt();
    let (sin_phi, cos_phi) = crate::fast_trig::sin_cos(TAU * u[1]);
    [r * cos_phi, r * sin_phi]
}

/// A cosine-weighted direction around +z (density [`cosine_hemisphere_pdf`]), in local
/// coordinates: a uniform point of the disk, lifted to the hemisphere.
#[inline]
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let [x, y] = uniform_disk(u);
    Vec3::new(x, y, (1.0 - u[0]).max(0.0).sqrt())
}

/// The density of [`cosine_hemisphere`] at a local direction, cos θ / π (0 below).
#[inline]
pub fn cosine_hemisphere_pdf(direction: Vec3) -> f32 {
    direction.z.max(0.0) * FRAC_1_PI
}

/// The `u` that [`cosine_hemisphere`] maps to a unit local `direction` (z ≥ 0).
pub fn cosine_hemisphere_invert(direction: Vec3) -> [f32; 2] {
    let r2 = direction.x * direction.x + direction.y * direction.y;
    [r2.clamp(0.0, 1.0), azimuth_fraction(direction)]
}

/// φ / 2π in [0, 1).
fn azimuth_fraction(direction: Vec3) -> f32 {
    let fraction = direction.y.atan2(direction.x) / TAU;
    if fraction < 0.0 {
        (fraction + 1.0).min(1.0 - f32::EPSILON)
    } else {
        fraction
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warps_invert_what_they_sample() {
        for (i, j) in (1..10).flat_map(|i| (1..10).map(move |j| (i, j))) {
            let u = [i as f32 / 10.0, j as f32 / 10.0];
            for (warped, inverted) in [
                (uniform_sphere(u), uniform_sphere_invert(uniform_sphere(u))),
                (
                    cosine_hemisphere(u),
                    cosine_hemisphere_invert(cosine_hemisphere(u)),
                ),
            ] {
                assert!((warped.length() - 1.0).abs() < 1e-5);
                assert!(
                    (inverted[0] - u[0]).abs() < 1e-5 && (inverted[1] - u[1]).abs() < 1e-5,
                    "{u:?} -> {inverted:?}"
                );
            }
        }
    }

    #[test]
    fn densities_integrate_to_one() {
        // Midpoint rule over θ (the densities do not depend on φ).
        let steps = 2000;
        let (mut sphere, mut hemisphere) = (0.0f64, 0.0f64);
        for k in 0..steps {
            let theta = (k as f64 + 0.5) / steps as f64 * std::f64::consts::PI;
            let ring = std::f64::consts::TAU * theta.sin() * std::f64::consts::PI / steps as f64;
            let direction = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
            sphere += uniform_sphere_pdf() as f64 * ring;
            hemisphere += cosine_hemisphere_pdf(direction) as f64 * ring;
        }
        assert!((sphere - 1.0).abs() < 1e-4 && (hemisphere - 1.0).abs() < 1e-4);
    }
}
