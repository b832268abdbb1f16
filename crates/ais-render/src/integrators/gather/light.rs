//! Light arriving at a gather point along a candidate direction: what it would bring with
//! nothing in the way, and what the occlusion ray lets through.

use super::shared_origin::SharedOrigin;
use super::strategy::GatherPoint;
use crate::geometry::{Ray, RayOrigins, RecentBlockers};
use crate::lights::{Aim, Toward};
use crate::render::RayCounts;
use crate::world::World;
use glam::Vec3;

/// The ray leaving a gather point toward a candidate direction, before it is traced.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Leaving {
    /// The ray, offset from the surface, ending just short of the light's point (unbounded
    /// toward the environment or a directional light).
    ray: Ray,
    /// The radiance it would bring if nothing blocked it.
    pub unoccluded: Vec3,
}

impl Leaving {
    /// The ray leaving `at` toward a direction.
    #[inline]
    pub fn new(world: &World, at: &GatherPoint, toward: &mut Toward) -> Self {
        let (unoccluded, target) = world.lights.unoccluded(&at.receiver, toward);
        let ray = shadow_ray(at, toward.direction, target);
        Leaving { ray, unoccluded }
    }

    /// What the ray actually brings: its unoccluded radiance, or zero if blocked, tried
    /// first near what blocked the gather's earlier rays (`blockers`). Only rays that could
    /// bring light are traced (and counted).
    pub fn trace(
        self,
        world: &World,
        counts: &mut RayCounts,
        blockers: &mut RecentBlockers,
    ) -> Vec3 {
        // A ray whose unoccluded radiance is zero brings zero whatever blocks it.
        if self.unoccluded == Vec3::ZERO {
            return Vec3::ZERO;
        }
        let ray = self.ray;
        counts.occlusion += 1;
        if world.geometry.occluded_after(&ray, blockers) {
            Vec3::ZERO
        } else {
            self.unoccluded
        }
    }
}

/// The origins of the shadow rays leaving `at`.
#[inline]
pub(super) fn ray_origins(at: &GatherPoint) -> RayOrigins {
    RayOrigins::new(at.receiver.point, at.frame.geometric)
}

/// The shadow ray leaving `at` along `direction`, free up to `target` if given
/// ([`RayOrigins::aimed`]).
pub(super) fn shadow_ray(at: &GatherPoint, direction: Vec3, target: Option<Vec3>) -> Ray {
    ray_origins(at).aimed(direction, target)
}

/// What a candidate's shadow ray found ([`free_radiance`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowRay {
    /// No ray was traced: the candidate surely brings nothing.
    Unneeded,
    /// Something blocks it.
    Blocked,
    /// It is free, and brings this radiance (zero toward a black part of the environment).
    Free(Vec3),
}

/// The radiance a candidate brings if its shadow ray is free. The ray is traced before the
/// radiance is looked up (for the environment, a texture lookup), which a blocked ray does
/// not need; so a ray toward a black part of the environment is traced (and counted),
/// where [`Leaving`] would know not to. `origin` as in [`trace_aimed`].
pub fn free_radiance(
    world: &World,
    at: &GatherPoint,
    toward: &mut Toward,
    counts: &mut RayCounts,
    origin: &mut SharedOrigin,
) -> ShadowRay {
    let blocked = trace_aimed(world, at, toward, counts, origin);
    radiance_if_free(world, at, toward, blocked)
}

/// Whether the shadow ray of `toward` is blocked (`None`: no ray was needed, the candidate
/// surely brings nothing), answered with what the gather's earlier rays learned
/// (`origin`). The first half of [`free_radiance`], for gathers that trace several
/// candidates' rays before looking up what the free ones bring.
#[inline]
pub fn trace_aimed(
    world: &World,
    at: &GatherPoint,
    toward: &mut Toward,
    counts: &mut RayCounts,
    origin: &mut SharedOrigin,
) -> Option<bool> {
    let target = match world.lights.aim(&at.receiver, toward) {
        Aim::Nothing => return None,
        Aim::Point(target) => Some(target),
        Aim::Unbounded => None,
    };
    counts.occlusion += 1;
    let ray = shadow_ray(at, toward.direction, target);
    Some(origin.occluded(world, at, toward, &ray))
}

/// The second half of [`free_radiance`]: what `toward` (aimed by [`trace_aimed`]) brings,
/// given whether its ray was blocked.
#[inline]
pub fn radiance_if_free(
    world: &World,
    at: &GatherPoint,
    toward: &mut Toward,
    blocked: Option<bool>,
) -> ShadowRay {
    match blocked {
        None => ShadowRay::Unneeded,
        Some(true) => ShadowRay::Blocked,
        Some(false) => ShadowRay::Free(world.lights.radiance_toward(&at.receiver, toward)),
    }
}

/// Light arriving at the gather point from a candidate direction, occluders included:
/// radiance, or for a delta light its intensity over the squared distance (or irradiance).
pub fn arriving_light(
    world: &World,
    at: &GatherPoint,
    toward: &mut Toward,
    counts: &mut RayCounts,
) -> Vec3 {
    Leaving::new(world, at, toward).trace(world, counts, &mut RecentBlockers::default())
}
