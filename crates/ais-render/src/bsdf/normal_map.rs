//! Mitsuba's `normalmap`: a material's shading normal tilted by a tangent-space texture.
//!
//! At a hit, the texture's value c gives the normal n = 2c − 1 in the frame (s, t, n_s) of
//! the surface, where s is ∂p/∂u made perpendicular to the shading normal n_s and
//! t = n_s × s. As in Mitsuba:
//! - a normal that faces away from the viewer is mirrored about the frame's z axis
//!   (`flip_invalid_normals`, default true);
//! - a direction counts only where it lies on the same side of both normals;
//! - the BSDF is multiplied by Estevez et al.'s shadowing term (`use_shadowing_function`,
//!   default true), 2 / (1 + √(1 + α² tan²θ)), with α² = min(tan²θ_n / 8, 1) for the
//!   tilted normal's angle θ_n to n_s and θ the direction's angle to n_s; it darkens grazing
//!   light on strongly tilted normals (the bump terminator).
//!
//! Behind a two-sided material the frame is mirrored through the surface first, as
//! Mitsuba's `twosided` mirrors the directions.

use super::ShadingFrame;
use crate::geometry::basis;
use glam::Vec3;

/// A tilt applied to a part's frame: what the unperturbed frame still decides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tilt {
    /// The unperturbed shading normal, toward the viewer's side.
    base_normal: Vec3,
    /// α² of the shadowing term (zero without it).
    alpha2: f32,
}

/// How a normal map is applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalMapOptions {
    /// Mirror normals that face away from the viewer.
    pub flip_invalid_normals: bool,
    /// Multiply by the shadowing term.
    pub use_shadowing_function: bool,
}

impl Tilt {
    /// What the BSDF is multiplied by toward `wi`: zero where `wi` lies on different sides
    /// of the tilted normal `normal` and the unperturbed one, else the shadowing term.
    #[inline]
    pub fn factor(&self, normal: Vec3, wi: Vec3) -> f32 {
        let base = self.base_normal.dot(wi);
        if base * normal.dot(wi) <= 0.0 {
            return 0.0;
        }
        if self.alpha2 == 0.0 {
            return 1.0;
        }
        let cos2 = base * base;
        let tan2 = ((1.0 - cos2) / cos2).max(0.0);
        2.0 / (1.0 + (1.0 + self.alpha2 * tan2).sqrt())
    }
}

/// The frame of a material seen from `wo`, `base` (its oriented frame at the hit, whose
/// unoriented shading normal is `shading_normal`), tilted by the map's value `texel`; and
/// the tilt that evaluating in it still needs.
pub fn tilted_frame(
    base: &ShadingFrame,
    shading_normal: Vec3,
    dp_du: Vec3,
    texel: Vec3,
    wo: Vec3,
    options: NormalMapOptions,
) -> (ShadingFrame, Tilt) {
    let s = (dp_du - shading_normal * shading_normal.dot(dp_du)).normalize_or_zero();
    let s = if s == Vec3::ZERO {
        basis(shading_normal).0
    } else {
        s
    };
    let t = shading_normal.cross(s);
    // The viewer in the unperturbed frame, mirrored to the front behind a two-sided one.
    let wo_z = base.normal.dot(wo);
    let wo_local = Vec3::new(s.dot(wo), t.dot(wo), wo_z);
    let mut local = texel * 2.0 - Vec3::ONE;
    if options.flip_invalid_normals && wo_z * wo_local.dot(local) <= 0.0 {
        local = Vec3::new(-local.x, -local.y, local.z);
    }
    let local = local.normalize_or(Vec3::Z);
    let normal = (s * local.x + t * local.y + base.normal * local.z).normalize();
    let alpha2 = if options.use_shadowing_function {
        let z2 = local.z * local.z;
        (0.125 * (1.0 - z2) / z2.max(f32::MIN_POSITIVE)).min(1.0)
    } else {
        0.0
    };
    let frame = ShadingFrame::with_normal(normal, base.geometric);
    let tilt = Tilt {
        base_normal: base.normal,
        alpha2,
    };
    (frame, tilt)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MITSUBA: NormalMapOptions = NormalMapOptions {
        flip_invalid_normals: true,
        use_shadowing_function: true,
    };

    fn frame_at(texel: Vec3, wo: Vec3) -> (ShadingFrame, Tilt) {
        let base = ShadingFrame::with_normal(Vec3::Z, Vec3::Z);
        tilted_frame(&base, Vec3::Z, Vec3::new(2.0, 0.0, 0.3), texel, wo, MITSUBA)
    }

    #[test]
    fn a_flat_texel_keeps_the_frame_and_the_bsdf() {
        let (frame, tilt) = frame_at(Vec3::new(0.5, 0.5, 1.0), Vec3::Z);
        assert!((frame.normal - Vec3::Z).length() < 1e-6);
        for wi in [Vec3::Z, Vec3::new(0.99, 0.0, 0.1).normalize()] {
            assert_eq!(tilt.factor(frame.normal, wi), 1.0);
        }
    }

    #[test]
    fn a_tilted_texel_leans_along_u_and_shadows_grazing_light() {
        // n = (0.6, 0, 0.8) in the frame whose s is ∂p/∂u (here +x).
        let texel = (Vec3::new(0.6, 0.0, 0.8) + 1.0) * 0.5;
        let (frame, tilt) = frame_at(texel, Vec3::Z);
        assert!((frame.normal - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-2);
        let grazing = Vec3::new(0.995, 0.0, 0.1).normalize();
        let factor = tilt.factor(frame.normal, grazing);
        assert!(factor > 0.0 && factor < 0.9, "{factor}");
        // Below the tilted normal's horizon but above the surface's: no light.
        let behind = Vec3::new(-0.9, 0.0, 0.3).normalize();
        assert_eq!(tilt.factor(frame.normal, behind), 0.0);
        // Seen from where the tilted normal faces away, it is mirrored toward the viewer.
        let wo = Vec3::new(-0.95, 0.0, 0.3).normalize();
        let (flipped, _) = frame_at(texel, wo);
        assert!(flipped.normal.x < 0.0 && flipped.normal.dot(wo) > 0.0);
    }
}
