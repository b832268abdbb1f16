//! A candidate direction toward the lights, and what it is known to meet there.
//!
//! The gather weighs a candidate by the density of drawing what the candidate sees first:
//! the point of an area light, the environment, or a delta light. A direction drawn by light
//! sampling knows its source already (the point drawn on an area light, the environment's
//! cell, the delta light); a direction drawn from the BSDF finds it once, by a query of the
//! emitters along it, and keeps it for the density and the radiance. Locating a direction on
//! a lat-long map costs an atan2, an acos and a rotation, so that too is done at most once.

use super::delta::DeltaArrival;
use super::environment::{EnvironmentMap, MapLocation};
use crate::bsdf::SpecularMass;
use glam::Vec3;

/// What a candidate direction meets first among the emitters.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Source {
    /// Not known yet: found by [`super::Lights`] when first needed.
    Unknown,
    /// The environment: nothing that emits lies along the direction before it.
    Environment,
    /// A point of an area light.
    Area(AreaPoint),
    /// A point, spot or directional light (its index among the scene's delta lights).
    Delta(usize, DeltaArrival),
    /// Nothing emits along the direction.
    Dark,
}

/// The point of an area light that a candidate direction meets.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AreaPoint {
    /// The light (its index among the scene's area lights).
    pub light: usize,
    /// Where it is (world space).
    pub target: Vec3,
    /// Radiance it sends toward the receiver (zero from its back side).
    pub radiance: Vec3,
    /// Light sampling's density of drawing this point, in solid angle at the receiver,
    /// including the choice of the light (and the weighing of its regions).
    pub density: f64,
    /// The region of the light's sample square it was drawn from ([`super::region_of`]),
    /// where known: always for a point drawn by light sampling, for one found along a
    /// direction where the receiver weighs the light's regions.
    pub region: Option<u8>,
}

/// A unit world-space direction, with what it meets and its place on the environment map
/// once known.
#[derive(Clone, Copy, Debug)]
pub struct Toward {
    /// The direction (unit, world space).
    pub direction: Vec3,
    /// Where it falls on the environment map, once located.
    on_map: Option<MapLocation>,
    /// What it meets first among the emitters, once known.
    pub(super) source: Source,
    /// When a smooth surface's specular lobe gave it: the lobe's mass and the probability
    /// of picking it (a point mass of BSDF sampling).
    pub specular: Option<SpecularMass>,
}

impl Toward {
    /// A direction whose source is not known yet (drawn from a BSDF, say).
    #[inline]
    pub fn new(direction: Vec3) -> Self {
        Toward {
            direction,
            on_map: None,
            source: Source::Unknown,
            specular: None,
        }
    }

    /// The direction of a specular lobe picked by a BSDF sample.
    #[inline]
    pub fn specular(direction: Vec3, mass: SpecularMass) -> Self {
        Toward {
            specular: Some(mass),
            ..Toward::new(direction)
        }
    }

    /// A direction drawn from the environment, with its place on the map when it has one.
    #[inline]
    pub(super) fn from_environment(direction: Vec3, location: Option<MapLocation>) -> Self {
        Toward {
            direction,
            on_map: location,
            source: Source::Environment,
            specular: None,
        }
    }

    /// A direction drawn toward a point of an area light.
    #[inline]
    pub(super) fn area(direction: Vec3, point: AreaPoint) -> Self {
        Toward {
            direction,
            on_map: None,
            source: Source::Area(point),
            specular: None,
        }
    }

    /// The direction toward delta light `index`, which sends `arrival`.
    #[inline]
    pub(super) fn delta(index: usize, arrival: DeltaArrival) -> Self {
        Toward {
            direction: arrival.direction,
            on_map: None,
            source: Source::Delta(index, arrival),
            specular: None,
        }
    }

    /// Whether it was drawn toward a point, spot or directional light: its probability is
    /// then a point mass, which no density (BSDF, guide) adds to.
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(self.source, Source::Delta(..))
    }

    /// Whether its probability is a point mass: drawn toward a delta light, or along a
    /// specular lobe. No density (BSDF, light, guide) adds to it.
    #[inline]
    pub fn is_point_mass(&self) -> bool {
        self.is_delta() || self.specular.is_some()
    }

    /// What it meets first among the emitters, as far as known.
    #[inline]
    pub(crate) fn source(&self) -> Source {
        self.source
    }

    /// Its place on the environment map, if located.
    pub(crate) fn map_location(&self) -> Option<MapLocation> {
        self.on_map
    }

    /// Its place on `map` (a scene has one environment), located on first use.
    #[inline]
    pub(super) fn location(&mut self, map: &EnvironmentMap) -> MapLocation {
        *self
            .on_map
            .get_or_insert_with(|| map.locate(self.direction))
    }
}
