//! Lights that send all their light to a point from one direction: Mitsuba's `point`, `spot`
//! and `directional` emitters.
//!
//! Only light sampling can find them: a direction drawn from a BSDF or from another light
//! meets a point or a parallel beam with probability zero. In the gather's mixture they are
//! point masses. A candidate drawn toward one is weighed by the probability of choosing it,
//! not by a density, and brings the light's intensity over the squared distance (or the
//! directional light's irradiance), times the BSDF and cosine, if nothing is in the way.
//! This is what Mitsuba's `direct` integrator does with its emitter samples. BSDF sampling
//! alone (`strategy = bsdf` or `uniform`) sees none of their light, in both renderers.

use glam::{Mat3, Vec3};
use std::f64::consts::PI;

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
    /// The fraction of the axis intensity sent along `direction` (world, from the light).
    fn falloff(&self, direction: Vec3) -> f32 {
        let local = (self.to_local * direction).normalize_or_zero();
        let angle = local.z.clamp(-1.0, 1.0).acos();
        if angle >= self.cutoff_angle {
            0.0
        } else if angle <= self.beam_width {
            1.0
        } else {
            (self.cutoff_angle - angle) / (self.cutoff_angle - self.beam_width)
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
                2.0 * PI * (1.0 - half_angle.cos()) * super::luminance(spot.intensity) as f64
            }
            DeltaLight::Directional { irradiance, .. } => {
                PI * scene_radius * scene_radius * super::luminance(*irradiance) as f64
            }
        }
    }
}
