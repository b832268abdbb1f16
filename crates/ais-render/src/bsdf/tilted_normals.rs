//! Mitsuba's `normalmap` and `bumpmap`: a material's shading normal tilted by a texture.
//!
//! At a hit, the tilted normal n is expressed in the frame (s, t, n_s) of the surface, where
//! s is ∂p/∂u made perpendicular to the shading normal n_s and t = n_s × s:
//! - a normal map's value c gives n = 2c − 1;
//! - a bump map's height h (times `scale`) moves the surface along n_s: its gradient
//!   (h_u, h_v) replaces the normal component of ∂p/∂u and ∂p/∂v, n is their cross
//!   product, turned to the geometric normal's side (Mitsuba's construction).
//!
//! Then, as in Mitsuba:
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

use super::{ShadingFrame, SurfacePoint};
use crate::geometry::basis;
use glam::{Vec2, Vec3};

/// A tilt applied to a part's frame: what the unperturbed frame still decides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tilt {
    /// The unperturbed shading normal, toward the viewer's side.
    base_normal: Vec3,
    /// α² of the shadowing term (zero without it).
    alpha2: f32,
}

/// How a normal or bump map is applied.
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

/// The unit tangent s and bitangent t of the frame that tilted normals are given in.
fn tangent_frame(shading_normal: Vec3, dp_du: Vec3) -> (Vec3, Vec3) {
    let s = (dp_du - shading_normal * shading_normal.dot(dp_du)).normalize_or_zero();
    let s = if s == Vec3::ZERO {
        basis(shading_normal).0
    } else {
        s
    };
    (s, shading_normal.cross(s))
}

/// The normal a normal map's value `texel` gives, in the frame (s, t, n_s).
pub fn normal_map_normal(texel: Vec3) -> Vec3 {
    texel * 2.0 - Vec3::ONE
}

/// The normal a bump map gives at `point`, in the frame (s, t, n_s), from the gradient of
/// its (scaled) height over (u, v).
pub fn bump_map_normal(point: &SurfacePoint, gradient: Vec2) -> Vec3 {
    let n = point.shading_normal;
    let dp_du = point.dp_du + n * (gradient.x - n.dot(point.dp_du));
    let dp_dv = point.dp_dv + n * (gradient.y - n.dot(point.dp_dv));
    let mut bumped = dp_du.cross(dp_dv).normalize_or(n);
    if point.geometric_normal.dot(bumped) < 0.0 {
        bumped = -bumped;
    }
    let (s, t) = tangent_frame(n, point.dp_du);
    Vec3::new(bumped.dot(s), bumped.dot(t), bumped.dot(n))
}

/// The frame of a material seen from `point.wo`, `base` (its oriented frame at the hit),
/// tilted to `local` (a normal in the unoriented frame (s, t, n_s)); and the tilt that
/// evaluating in it still needs.
pub fn tilted_frame(
    base: &ShadingFrame,
    point: &SurfacePoint,
    local: Vec3,
    options: NormalMapOptions,
) -> (ShadingFrame, Tilt) {
    let (s, t) = tangent_frame(point.shading_normal, point.dp_du);
    // The viewer in the unperturbed frame, mirrored to the front behind a two-sided one.
    let wo = point.wo;
    let wo_z = base.normal.dot(wo);
    let wo_local = Vec3::new(s.dot(wo), t.dot(wo), wo_z);
    let mut local = local;
    if options.flip_invalid_normals && wo_z * wo_local.dot(local) <= 0.0 {
        local = Vec3::new(-local.x, -local.y, local.z);
    }
    let local = local.normalize_or(Vec3::Z);
    let to_world = |v: Vec3| s * v.x + t * v.y + base.normal * v.z;
    let normal = to_world(local).normalize();
    // Mitsuba's tilted tangent: the frame's x axis made perpendicular to the tilted normal
    // (what an anisotropic material's roughness is measured along).
    let tangent_local = (Vec3::X - local * local.x).normalize_or(Vec3::X);
    let tangent = to_world(tangent_local).normalize();
    let bitangent = normal.cross(tangent);
    let alpha2 = if options.use_shadowing_function {
        let z2 = local.z * local.z;
        (0.125 * (1.0 - z2) / z2.max(f32::MIN_POSITIVE)).min(1.0)
    } else {
        0.0
    };
    let frame = ShadingFrame::from_axes(normal, base.geometric, tangent, bitangent);
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
        let point = SurfacePoint {
            uv: Vec2::ZERO,
            shading_normal: Vec3::Z,
            geometric_normal: Vec3::Z,
            wo,
            dp_du: Vec3::new(2.0, 0.0, 0.3),
            dp_dv: Vec3::new(0.0, 1.0, 0.0),
            attributes: None,
        };
        tilted_frame(&base, &point, normal_map_normal(texel), MITSUBA)
    }

    #[test]
    fn a_bump_leans_the_normal_against_the_slope() {
        let point = SurfacePoint {
            uv: Vec2::ZERO,
            shading_normal: Vec3::Z,
            geometric_normal: Vec3::Z,
            wo: Vec3::Z,
            dp_du: Vec3::X,
            dp_dv: Vec3::Y,
            attributes: None,
        };
        // Height rising with u at slope 1: the normal leans 45° toward -u.
        let local = bump_map_normal(&point, Vec2::new(1.0, 0.0));
        let expected = Vec3::new(-1.0, 0.0, 1.0).normalize();
        assert!((local - expected).length() < 1e-6, "{local}");
        assert!(bump_map_normal(&point, Vec2::ZERO).abs_diff_eq(Vec3::Z, 1e-6));
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
