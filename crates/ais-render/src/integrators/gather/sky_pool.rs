//! A pixel's environment-map lookups, pooled across its camera samples.
//!
//! A free candidate that meets an environment map needs its place on the map, the
//! radiance there (four texels blended) and the map's density. One by one these cost some
//! 29 ns; sixteen at a time in vector lanes, some 8 ns each. One gather's run rarely holds
//! sixteen free candidates meeting the map after its shadow rays, but a pixel's camera
//! samples together hold many. So while a pixel's samples are gathered
//! ([`super::gather_samples`]), the plain lanes work out everything of such a candidate
//! but the map's numbers, add a zero in its place, and leave the rest here; once the
//! pixel's gathers are done, the pool is looked up sixteen at a time and each candidate's
//! share is added to its sample's value.
//!
//! The value is the same sum, in another order: a sample's value differs from the one-by-one
//! form by rounding (a few units in the last place). Only AIS off's plain batches under an
//! unguided map pool, and only where nothing reads a candidate's value as it comes (a
//! gather's spread, a race's moments, a probe).

use super::plain_lanes::weighed;
use super::strategy::MisParts;
use crate::lights::{EnvironmentMap, MapLocation, MAP_LANES};
use glam::Vec3;

/// The lookups left by a pixel's gathers.
#[derive(Debug, Default)]
pub struct SkyPool {
    /// Whether the gathers now running may leave their lookups here.
    open: bool,
    /// The camera sample of the pixel being gathered.
    sample: u32,
    lookups: Vec<Left>,
}

/// What a free candidate that meets the map brings, but for the map's numbers.
#[derive(Clone, Copy, Debug)]
pub(super) struct SkyLookup {
    /// The candidate's direction.
    pub direction: Vec3,
    /// Where it falls on the map, if it was drawn from the map.
    pub location: Option<MapLocation>,
    /// The BSDF times the cosine toward it.
    pub scattering: Vec3,
    /// The BSDF's density of drawing it.
    pub bsdf_density: f64,
    /// The probability that light sampling chooses the environment.
    pub choice: f64,
    /// MIS's BSDF share.
    pub share: f64,
    /// Its weight in the sample's value: one over the gather's candidates.
    pub weight: f32,
}

/// A lookup left in the pool, and the camera sample (within the pixel) it belongs to.
#[derive(Clone, Copy, Debug)]
struct Left {
    sample: u32,
    lookup: SkyLookup,
}

impl SkyPool {
    /// Opens the pool for a pixel's gathers.
    pub(super) fn open(&mut self) {
        self.open = true;
        self.lookups.clear();
    }

    /// Whether gathers may leave their lookups here.
    pub(super) fn is_open(&self) -> bool {
        self.open
    }

    /// The pixel's camera sample `sample` is being gathered.
    pub(super) fn begin_sample(&mut self, sample: u32) {
        self.sample = sample;
    }

    /// Leaves `lookup` for the sample being gathered.
    pub(super) fn leave(&mut self, lookup: SkyLookup) {
        self.lookups.push(Left {
            sample: self.sample,
            lookup,
        });
    }

    /// Looks up what the pool's candidates bring from `map`, sixteen at a time, adds each
    /// to its sample's value in `values`, and closes the pool.
    pub(super) fn resolve(&mut self, map: &EnvironmentMap, values: &mut [[f32; 3]]) {
        self.open = false;
        for run in self.lookups.chunks(MAP_LANES) {
            // Lanes past the run hold a unit direction, looked up for nothing.
            let mut directions = [Vec3::Z; MAP_LANES];
            let mut known = [None; MAP_LANES];
            for (k, left) in run.iter().enumerate() {
                (directions[k], known[k]) = (left.lookup.direction, left.lookup.location);
            }
            let (locations, radiances) = map.look_up_lanes(&directions, &known);
            for (k, &Left { sample, lookup }) in run.iter().enumerate() {
                let parts = MisParts {
                    bsdf: lookup.bsdf_density,
                    light: lookup.choice * map.density_at(locations[k]) as f64,
                };
                let brought = weighed(lookup.scattering, radiances[k], parts.mixed(lookup.share));
                let value = &mut values[sample as usize];
                for (channel, add) in value.iter_mut().zip(brought.to_array()) {
                    *channel += add * lookup.weight;
                }
            }
        }
        self.lookups.clear();
    }
}
