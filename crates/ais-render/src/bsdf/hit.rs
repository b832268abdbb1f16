//! The BSDF at one hit: a single material in its shading frame, or a weighted mixture of
//! materials (Mitsuba's `blendbsdf` and `mask`) with, for `mask` and `null`, a share of
//! light that passes straight through.
//!
//! A mixture evaluates as the weighted sum of its parts and draws a part in proportion to
//! its weight: its continuous density is the weighted sum of the parts' densities, and a
//! point mass it picks (a part's specular lobe, or the straight-through lobe) keeps its
//! weight and probability scaled by the part's weight. Light passing straight through is a
//! point mass along `-wo` (what Mitsuba's direct integrator sees through it: the emitters
//! behind, not the surfaces).

use super::tilted_normals::Tilt;
use super::{BsdfSample, DiffuseHit, Material, ShadingFrame, SpecularMass};
use glam::Vec3;
use std::borrow::Cow;

/// The BSDF at a hit.
#[derive(Clone, Debug)]
pub enum HitBsdf<'a> {
    /// One material (the common case: nothing to mix).
    Single {
        /// The material, with its textures' values at the hit.
        material: Cow<'a, Material>,
        /// Its shading frame.
        frame: ShadingFrame,
    },
    /// Several materials, and light passing through.
    Mixture(Box<Mixture>),
}

/// Weighted materials, and the weight of light passing straight through; the weights sum
/// to 1.
#[derive(Clone, Debug, Default)]
pub struct Mixture {
    /// The materials, each in its own frame.
    pub parts: Vec<MixturePart>,
    /// The share of light that passes straight through.
    pub pass_through: f32,
}

/// One material of a [`Mixture`].
#[derive(Clone, Debug)]
pub struct MixturePart {
    /// Its share.
    pub weight: f32,
    /// The material.
    pub material: Material,
    /// Its shading frame.
    pub frame: ShadingFrame,
    /// When a normal map tilted the frame: what the unperturbed one still decides.
    pub tilt: Option<Tilt>,
}

impl MixturePart {
    /// Whether `wi` can carry light to `wo` through the part's continuous part.
    #[inline]
    fn in_support(&self, wo: Vec3, wi: Vec3) -> bool {
        self.weight > 0.0
            && self.material.in_support(&self.frame, wo, wi)
            && self
                .tilt
                .is_none_or(|tilt| tilt.factor(self.frame.normal, wi) > 0.0)
    }

    /// The part's BSDF times |cos θi|, weighted.
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let tilt = self
            .tilt
            .map_or(1.0, |tilt| tilt.factor(self.frame.normal, wi));
        if tilt == 0.0 {
            return Vec3::ZERO;
        }
        self.weight * tilt * self.material.eval(&self.frame, wo, wi)
    }
}

impl HitBsdf<'_> {
    /// Whether `wi` can carry light to `wo` through a continuous part of the BSDF.
    #[inline]
    pub fn in_support(&self, wo: Vec3, wi: Vec3) -> bool {
        match self {
            HitBsdf::Single { material, frame } => material.in_support(frame, wo, wi),
            HitBsdf::Mixture(mixture) => mixture.parts.iter().any(|p| p.in_support(wo, wi)),
        }
    }

    /// A normal `m` such that no direction `wi` with `m · wi <= 0` lies in the support
    /// ([`HitBsdf::in_support`]), where there is one: a single material that only reflects.
    #[inline]
    pub fn support_side(&self) -> Option<Vec3> {
        match self {
            HitBsdf::Single { material, frame } => material.support_side(frame),
            HitBsdf::Mixture(_) => None,
        }
    }

    /// BSDF times |cos θi| (zero outside the support).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            HitBsdf::Single { material, frame } => material.eval(frame, wo, wi),
            HitBsdf::Mixture(mixture) => mixture.parts.iter().map(|p| p.eval(wo, wi)).sum(),
        }
    }

    /// Density of [`HitBsdf::sample`] at `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f64 {
        match self {
            HitBsdf::Single { material, frame } => material.pdf(frame, wo, wi),
            HitBsdf::Mixture(mixture) => mixture
                .parts
                .iter()
                .map(|p| p.weight as f64 * p.material.pdf(&p.frame, wo, wi))
                .sum(),
        }
    }

    /// A direction drawn from the BSDF's continuous part and its density; a sample that
    /// picks a point mass comes back with density 0.
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> (Vec3, f64) {
        if let HitBsdf::Single { material, frame } = self {
            return material.sample(frame, wo, u);
        }
        match self.sample_lobe(wo, u) {
            Some(BsdfSample {
                direction,
                specular: None,
            }) => (direction, self.pdf(wo, direction)),
            Some(BsdfSample { direction, .. }) => (direction, 0.0),
            None => (-wo, 0.0),
        }
    }

    /// A single diffuse material, seen from `wo`, for many directions' numbers at once
    /// (`None` for other BSDFs).
    #[inline]
    pub fn diffuse(&self, wo: Vec3) -> Option<DiffuseHit> {
        match self {
            HitBsdf::Single { material, frame } => DiffuseHit::new(material, frame, wo),
            HitBsdf::Mixture(_) => None,
        }
    }

    /// The shading frame of a single diffuse material, whose draws are
    /// [`diffuse_direction`](super::diffuse_direction)s around it (`None`: another BSDF).
    #[inline]
    pub fn diffuse_frame(&self) -> Option<&ShadingFrame> {
        match self {
            HitBsdf::Single { material, frame } if material.is_diffuse() => Some(frame),
            _ => None,
        }
    }

    /// A direction drawn from the BSDF: from a continuous part, or a point mass with its
    /// weight and probability (`None`: nothing scatters toward `wo`).
    #[inline]
    pub fn sample_lobe(&self, wo: Vec3, u: [f32; 2]) -> Option<BsdfSample> {
        match self {
            HitBsdf::Single { material, frame } => material.sample_lobe(frame, wo, u),
            HitBsdf::Mixture(mixture) => mixture.sample_lobe(wo, u),
        }
    }
}

impl Mixture {
    /// Picks a part (or passing through) with `u[0]`, reused for the part's own sample.
    fn sample_lobe(&self, wo: Vec3, u: [f32; 2]) -> Option<BsdfSample> {
        let mut start = 0.0;
        let last = self.parts.len().wrapping_sub(1);
        for (index, part) in self.parts.iter().enumerate() {
            let end = start + part.weight;
            // Without light passing through, the last part takes what rounding left over.
            let picked = u[0] < end || (index == last && self.pass_through <= 0.0);
            if picked && part.weight > 0.0 {
                let reused = ((u[0] - start) / part.weight).clamp(0.0, 1.0 - 1e-7);
                let sample = part.material.sample_lobe(&part.frame, wo, [reused, u[1]])?;
                let tilt = part
                    .tilt
                    .map_or(1.0, |tilt| tilt.factor(part.frame.normal, sample.direction));
                return Some(BsdfSample {
                    direction: sample.direction,
                    specular: sample.specular.map(|mass| SpecularMass {
                        weight: mass.weight * (part.weight * tilt),
                        probability: mass.probability * part.weight,
                    }),
                });
            }
            start = end;
        }
        (self.pass_through > 0.0).then(|| BsdfSample {
            direction: -wo,
            specular: Some(SpecularMass {
                weight: Vec3::splat(self.pass_through),
                probability: self.pass_through,
            }),
        })
    }
}
