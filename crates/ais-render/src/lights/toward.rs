//! A direction toward the lights that remembers where it falls on the environment map.
//!
//! A traced candidate asks the environment for its density and then for its radiance; a
//! light-sampled one was drawn from a cell that is already known. Locating a direction on a
//! lat-long map costs an atan2, an acos and a rotation, so a [`Toward`] does it at most once
//! and carries the result to every later lookup. A direction drawn toward a point, spot or
//! directional light carries that light too: its probability is a point mass, not a density.

use super::delta::DeltaArrival;
use super::environment::{EnvironmentMap, MapLocation};
use glam::Vec3;

/// A unit world-space direction, and its place on the scene's environment map once known.
#[derive(Clone, Copy, Debug)]
pub struct Toward {
    /// The direction (unit, world space).
    pub direction: Vec3,
    /// Where it falls on the environment map, once located.
    on_map: Option<MapLocation>,
    /// The delta light it was drawn toward (its index among the scene's delta lights).
    delta: Option<(usize, DeltaArrival)>,
}

impl Toward {
    /// A direction not yet located.
    #[inline]
    pub fn new(direction: Vec3) -> Self {
        Toward {
            direction,
            on_map: None,
            delta: None,
        }
    }

    /// A direction whose place on the map is known (it was drawn there).
    #[inline]
    pub(super) fn located(direction: Vec3, location: MapLocation) -> Self {
        Toward {
            direction,
            on_map: Some(location),
            delta: None,
        }
    }

    /// The direction toward delta light `index`, which sends `arrival`.
    #[inline]
    pub(super) fn delta(index: usize, arrival: DeltaArrival) -> Self {
        Toward {
            direction: arrival.direction,
            on_map: None,
            delta: Some((index, arrival)),
        }
    }

    /// Whether it was drawn toward a point, spot or directional light: its probability is
    /// then a point mass, which no density (BSDF, guide) adds to.
    #[inline]
    pub fn is_delta(&self) -> bool {
        self.delta.is_some()
    }

    /// The delta light it was drawn toward, and what that light sends.
    #[inline]
    pub(super) fn delta_light(&self) -> Option<(usize, DeltaArrival)> {
        self.delta
    }

    /// Its place on `map` (a scene has one environment), located on first use.
    #[inline]
    pub(super) fn location(&mut self, map: &EnvironmentMap) -> MapLocation {
        *self
            .on_map
            .get_or_insert_with(|| map.locate(self.direction))
    }
}
