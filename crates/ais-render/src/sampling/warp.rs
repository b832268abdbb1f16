//! Warps from the unit square to directions, shared by every sampler that needs them.

use glam::Vec3;
use std::f32::consts::TAU;

/// A direction uniform over the sphere (density 1 / 4π).
#[inline]
pub fn uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A cosine-weighted direction around +z (density cos θ / π), in local coordinates.
#[inline]
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let r = u[0].sqrt();
    let phi = TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u[0]).max(0.0).sqrt())
}
