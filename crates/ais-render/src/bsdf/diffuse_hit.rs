//! A diffuse material at a hit, for a gather that weighs many directions there: the numbers
//! of [`Material::in_support`], [`Material::eval`] and [`Material::pdf`] for a diffuse
//! material, to the bit, with what depends only on the viewing direction worked out once
//! and no dispatch over kinds of material.

use super::{Material, ShadingFrame};
use glam::Vec3;
use std::f32::consts::PI;

/// A diffuse material's frame and reflectance at a hit, seen from one direction.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseHit {
    /// The shading frame (its draws are cosine-weighted around its normal).
    pub frame: ShadingFrame,
    /// The reflectance at the hit.
    reflectance: Vec3,
    /// Whether the viewing direction lies in front of both normals: no light reaches the
    /// viewer otherwise.
    faces_viewer: bool,
}

impl DiffuseHit {
    /// `material` at a hit with shading frame `frame`, seen from `wo` (`None` unless the
    /// material is diffuse).
    pub fn new(material: &Material, frame: &ShadingFrame, wo: Vec3) -> Option<Self> {
        let reflectance = material.diffuse_reflectance()?;
        Some(DiffuseHit {
            frame: *frame,
            reflectance,
            faces_viewer: frame.normal.dot(wo) > 0.0 && frame.geometric.dot(wo) > 0.0,
        })
    }

    /// Whether light arriving along `wi` reaches the viewer ([`Material::in_support`]).
    #[inline]
    pub fn in_support(&self, wi: Vec3) -> bool {
        self.in_support_at(wi, self.cosine(wi))
    }

    /// The BSDF times |cos θi| at `wi` ([`Material::eval`]).
    #[inline]
    pub fn eval(&self, wi: Vec3) -> Vec3 {
        self.eval_at(wi, self.cosine(wi))
    }

    /// [`DiffuseHit::eval`] and the density of the material's draws at `wi`
    /// ([`Material::pdf`]).
    #[inline]
    pub fn eval_and_pdf(&self, wi: Vec3) -> (Vec3, f64) {
        let cosine = self.cosine(wi);
        let pdf = match cosine <= 0.0 {
            true => 0.0,
            false => (cosine / PI) as f64,
        };
        (self.eval_at(wi, cosine), pdf)
    }

    /// [`DiffuseHit::in_support`] for `wi`, whose cosine is `cosine`.
    #[inline]
    fn in_support_at(&self, wi: Vec3, cosine: f32) -> bool {
        self.faces_viewer && cosine > 0.0 && self.frame.geometric.dot(wi) > 0.0
    }

    /// [`DiffuseHit::eval`] for `wi`, whose cosine is `cosine`.
    #[inline]
    fn eval_at(&self, wi: Vec3, cosine: f32) -> Vec3 {
        match self.in_support_at(wi, cosine) {
            true => self.reflectance * (cosine / PI),
            false => Vec3::ZERO,
        }
    }

    /// The local frame's z of `wi`, as `ShadingFrame::to_local` works it out (the normal's
    /// dot product with it, the same products in the same order).
    #[inline]
    fn cosine(&self, wi: Vec3) -> f32 {
        wi.dot(self.frame.normal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::rng::Pcg32;
    use ais::sampling::uniform_sphere;

    /// Against the material's own numbers, to the bit, at directions all around frames
    /// whose shading normal leans off the geometric one, one-sided and two-sided, seen
    /// from both sides.
    #[test]
    fn a_diffuse_hit_gives_the_materials_numbers_to_the_bit() {
        let mut rng = Pcg32::new(17, 3);
        let mut direction = || uniform_sphere([rng.next_f32(), rng.next_f32()]);
        let mut compared = [0; 2];
        for trial in 0..400 {
            let mut material = Material::diffuse(Vec3::new(0.7, 0.5, 0.2));
            material.two_sided = trial % 2 == 0;
            let geometric = direction();
            let shading = (geometric + 0.4 * direction()).normalize();
            let wo = direction();
            let frame = ShadingFrame::new(&material, shading, geometric, wo);
            let hit = DiffuseHit::new(&material, &frame, wo).expect("a diffuse material");
            for _ in 0..20 {
                let wi = direction();
                let in_support = material.in_support(&frame, wo, wi);
                assert_eq!(hit.in_support(wi), in_support);
                let expected = (material.eval(&frame, wo, wi), material.pdf(&frame, wo, wi));
                assert_eq!(hit.eval_and_pdf(wi), expected);
                compared[in_support as usize] += 1;
            }
        }
        assert!(compared.iter().all(|&c| c > 1000), "{compared:?}");
    }
}
