//! A direction toward the lights that remembers where it falls on the environment map.
//!
//! A traced candidate asks the environment for its density and then for its radiance; a
//! light-sampled one was drawn from a cell that is already known. Locating a direction on a
//! lat-long map costs an atan2, an acos and a rotation, so a [`Toward`] does it at most once
//! and carries the result to every later lookup.

use super::environment::{EnvironmentMap, MapLocation};
use glam::Vec3;

/// A unit world-space direction, and its place on the scene's environment map once known.
#[derive(Clone, Copy, Debug)]
pub struct Toward {
    /// The direction (unit, world space).
    pub direction: Vec3,
    /// Where it falls on the environment map, once located.
    on_map: Option<MapLocation>,
}

impl Toward {
    /// A direction not yet located.
    #[inline]
    pub fn new(direction: Vec3) -> Self {
        Toward {
            direction,
            on_map: None,
        }
    }

    /// A direction whose place on the map is known (it was drawn there).
    #[inline]
    pub(super) fn located(direction: Vec3, location: MapLocation) -> Self {
        Toward {
            direction,
            on_map: Some(location),
        }
    }

    /// Its place on `map` (a scene has one environment), located on first use.
    #[inline]
    pub(super) fn location(&mut self, map: &EnvironmentMap) -> MapLocation {
        *self
            .on_map
            .get_or_insert_with(|| map.locate(self.direction))
    }
}
