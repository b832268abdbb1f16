//! Lights that send all their light to a point from one direction: Mitsuba's `point`, `spot`
//! (optionally projecting a texture across its cone), `projector` and `directional` emitters.
//!
//! Only light sampling can find them: a direction drawn from a BSDF or from another light
//! meets a point or a parallel beam with probability zero. In the gather's mixture they are
//! point masses. A candidate drawn toward one is weighed by the probability of choosing it,
//! not by a density, and brings the light's intensity over the squared distance (or the
//! directional light's irradiance), times the BSDF and cosine, if nothing is in the way.
//! This is what Mitsuba's `direct` integrator does with its emitter samples. BSDF sampling
//! alone (`strategy = bsdf` or `uniform`) sees none of their light, in both renderers.

use crate::texture::Texture;
use glam::{Mat3, Mat4, Vec2, Vec3};
use std::f64::consts::PI;
use std::sync::Arc;

/// A point, spot or directional light.
#[derive(Clone, Debug)]
pub enum DeltaLight {
    /// Mitsuba's `point`: the same intensity in every direction.
    Point {
        /// Where it is.
        position: Vec3,
        /// Radiant intensity (power per steradian).
        intensity: Vec3,
    },
    /// Mitsuba's `spot`: a point whose intensity falls off from its axis to a cutoff.
    Spot(Spot),
    /// Mitsuba's `projector`: a pinhole that projects an image.
    Projector(Projector),
    /// Mitsuba's `directional`: parallel light from infinitely far away.
    Directional {
        /// The direction the light travels in (unit).
        travel: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Vec3,
    },
}

/// A spot light, in Mitsuba's terms.
#[derive(Clone, Debug)]
pub struct Spot {
    /// Where it is.
    pub position: Vec3,
    /// Intensity on the axis.
    pub intensity: Vec3,
    /// World to the light's frame, whose +z is the axis.
    pub to_local: Mat3,
    /// Beyond this angle from the axis (radians), no light.
    pub cutoff_angle: f32,
    /// Within this angle, the full intensity; between it and the cutoff, a linear falloff
    /// in angle.
    pub beam_width: f32,
    /// A texture spread over the cone (Mitsuba's `texture`): (½, ½) on the axis, the square
    /// [0, 1]² filling tan(cutoff) either side.
    pub texture: Option<Arc<Texture>>,
}

/// A projector, in Mitsuba's terms: the image `irradiance` on the plane at z = 1 in front of
/// a pinhole, seen through a perspective frustum; a point receives the texture's value where
/// it projects, times π `scale` / (z² cos θ), so that a plane facing it is lit as the image.
#[derive(Clone, Debug)]
pub struct Projector {
    /// Where it is.
    pub position: Vec3,
    /// World to the projector's frame (+z forward, +x left, +y up, as a camera's).
    pub to_local: Mat4,
    /// Its axis in world space (`to_world` applied to +z, as Mitsuba takes it).
    pub axis: Vec3,
    /// tan of the half field of view along x and y.
    pub half: Vec2,
    /// The image.
    pub irradiance: Arc<Texture>,
    /// What the image is multiplied by.
    pub scale: f32,
}

impl Projector {
    /// What the projector sends to `point`, toward it (zero outside the image).
    fn light_at(&self, point: Vec3) -> Vec3 {
        let local = self.to_local.transform_point3(point);
        if local.z <= 0.0 {
            return Vec3::ZERO;
        }
        let uv = Vec2::new(
            0.5 - 0.5 * local.x / (local.z * self.half.x),
            0.5 - 0.5 * local.y / (local.z * self.half.y),
        );
        if !(uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all()) {
            return Vec3::ZERO;
        }
        let cosine = self.axis.dot((point - self.position).normalize_or_zero());
        if cosine <= 0.0 {
            return Vec3::ZERO;
        }
        let factor = std::f32::consts::PI * self.scale / (local.z * local.z * cosine);
        self.irradiance.eval(uv) * factor
    }
}

/// What a delta light sends to a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaArrival {
    /// Unit direction from the point toward the light.
    pub direction: Vec3,
    /// How far the ray must be free (infinite for a directional light).
    pub distance: f32,
    /// Intensity over the squared distance, or irradiance: what multiplies the BSDF and the
    /// cosine.
    pub light: Vec3,
}

impl Spot {
    /// The fraction of the axis intensity sent along `direction` (world, from the light),
    /// times the texture's value there if it has one.
    fn falloff(&self, direction: Vec3) -> Vec3 {
        let local = (self.to_local * direction).normalize_or_zero();
        let angle = local.z.clamp(-1.0, 1.0).acos();
        let falloff = if angle >= self.cutoff_angle {
            return Vec3::ZERO;
        } else if angle <= self.beam_width {
            1.0
        } else {
            (self.cutoff_angle - angle) / (self.cutoff_angle - self.beam_width)
        };
        match &self.texture {
            None => Vec3::splat(falloff),
            Some(texture) => {
                let spread = self.cutoff_angle.tan() * local.z;
                let uv = Vec2::new(0.5 + 0.5 * local.x / spread, 0.5 + 0.5 * local.y / spread);
                texture.eval(uv) * falloff
            }
        }
    }
}

impl DeltaLight {
    /// What the light sends to `point` (None: nothing, e.g. outside a spot's cone or at the
    /// light itself).
    pub fn arrival(&self, point: Vec3) -> Option<DeltaArrival> {
        let from_point = |position: Vec3, intensity: Vec3| {
            let offset = position - point;
            let distance_squared = offset.length_squared();
            (distance_squared > 0.0 && distance_squared.is_finite()).then(|| DeltaArrival {
                direction: offset / distance_squared.sqrt(),
                distance: distance_squared.sqrt(),
                light: intensity / distance_squared,
            })
        };
        let arrival = match self {
            DeltaLight::Point {
                position,
                intensity,
            } => from_point(*position, *intensity)?,
            DeltaLight::Spot(spot) => {
                let arrival = from_point(spot.position, spot.intensity)?;
                let falloff = spot.falloff(-arrival.direction);
                DeltaArrival {
                    light: arrival.light * falloff,
                    ..arrival
                }
            }
            DeltaLight::Projector(projector) => DeltaArrival {
                light: projector.light_at(point),
                ..from_point(projector.position, Vec3::ONE)?
            },
            DeltaLight::Directional { travel, irradiance } => DeltaArrival {
                direction: -*travel,
                distance: f32::INFINITY,
                light: *irradiance,
            },
        };
        (arrival.light != Vec3::ZERO).then_some(arrival)
    }

    /// Emitted power, for choosing among lights: 4π I for a point, the cone's solid angle
    /// (to the middle of the falloff) times I for a spot, and E π R² for a directional light
    /// over a scene of bounding radius `scene_radius`.
    pub fn power(&self, scene_radius: f64) -> f64 {
        match self {
            DeltaLight::Point { intensity, .. } => 4.0 * PI * super::luminance(*intensity) as f64,
            DeltaLight::Spot(spot) => {
                let half_angle = 0.5 * (spot.cutoff_angle + spot.beam_width) as f64;
                let mean = spot.texture.as_ref().map_or(1.0, |t| t.mean_luminance()) as f64;
                2.0 * PI * (1.0 - half_angle.cos()) * super::luminance(spot.intensity) as f64 * mean
            }
            // The image's power on the plane at z = 1.
            DeltaLight::Projector(projector) => {
                let area = 4.0 * (projector.half.x * projector.half.y) as f64;
                PI * (projector.scale * projector.irradiance.mean_luminance()) as f64 * area
            }
            DeltaLight::Directional { irradiance, .. } => {
                PI * scene_radius * scene_radius * super::luminance(*irradiance) as f64
            }
        }
    }
}
