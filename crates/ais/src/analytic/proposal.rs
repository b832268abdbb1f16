//! Proposal samplers for the analytic scenes.

use crate::sampling::warp::{cosine_hemisphere, uniform_sphere};
use glam::DVec3;
use std::f64::consts::PI;

/// A proposal distribution over directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Proposal {
    /// Uniform over the whole sphere: half of its candidates fall outside a diffuse BSDF's
    /// support, which exercises unconditional rejection.
    UniformSphere,
    /// Cosine-weighted over the upper hemisphere (BSDF sampling for a diffuse surface).
    CosineHemisphere,
}

impl Proposal {
    /// Maps `u` ∈ [0, 1)² to a unit direction and its density (per steradian).
    pub fn sample(self, u: [f32; 2]) -> (DVec3, f64) {
        let direction = match self {
            Proposal::UniformSphere => uniform_sphere(u),
            Proposal::CosineHemisphere => cosine_hemisphere(u),
        }
        .as_dvec3()
        .normalize();
        (direction, self.pdf(direction))
    }

    /// Density of a unit direction.
    pub fn pdf(self, direction: DVec3) -> f64 {
        match self {
            Proposal::UniformSphere => 0.25 / PI,
            Proposal::CosineHemisphere => direction.z.max(0.0) / PI,
        }
    }

    /// A short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Proposal::UniformSphere => "uniform",
            Proposal::CosineHemisphere => "cosine",
        }
    }
}
