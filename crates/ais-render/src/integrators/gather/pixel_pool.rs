//! What a pixel's gathers leave to be done together: their shadow rays, sorted by
//! direction, and their environment-map lookups, made in vector lanes.
//!
//! While a pixel's camera samples are gathered ([`super::gather_samples`]), the plain
//! lanes work out everything of a candidate but its shadow ray (and, for one that meets an
//! unguided environment map, the map's numbers), add a zero in its place, and leave the
//! rest here. Once the pixel's gathers are done, the pool
//! - traces the rays in order of direction. A pixel's rays start from nearby points, so
//!   rays of neighbouring directions mostly meet the same surfaces: the blocker that
//!   stopped one ([`RecentBlockers`]) is tried first for the next, and usually stops it
//!   too. A gather's own rays, spread over a hemisphere, rarely share a blocker. Where
//!   the pool last found most of its rays free (an open sky), the sort would cost more
//!   than it saves, and the rays are traced in the order left;
//! - adds what each free candidate brings to its sample's value, the map's lookups sixteen
//!   at a time: one by one these cost some 29 ns, in lanes some 8 ns each.
//!
//! A sample's value is the same sum, in another order: it differs from the one-by-one form
//! by rounding (a few units in the last place). Only AIS off's plain batches pool, and
//! only where nothing reads a candidate's value as it comes (a gather's spread, a race's
//! moments, a probe). Rays toward a rectangle or a sphere light stay with their gather,
//! whose shafts (`SharedOrigin`) may find them free without tracing.

use super::plain_lanes::weighed;
use super::strategy::MisParts;
use crate::geometry::{Geometry, Ray, RecentBlockers};
use crate::lights::{EnvironmentMap, MapLocation, MAP_LANES};
use glam::Vec3;

/// The candidates left by a pixel's gathers.
#[derive(Debug, Default)]
pub struct PixelPool {
    /// Whether the gathers now running may leave their candidates here.
    open: bool,
    /// The camera sample of the pixel being gathered.
    sample: u32,
    /// The candidates left, in the order left.
    left: Vec<Left>,
    /// The candidates' order of direction, kept to spare an allocation per pixel.
    order: Vec<u32>,
    /// Each candidate's cell of direction, found once for both passes of the sort.
    cells: Vec<u16>,
    /// The share of the rays found blocked when the pool was last resolved (`None`: not
    /// yet resolved).
    blocked_share: Option<f32>,
}

/// The share of blocked rays from which on the pool sorts its rays by direction. The sort
/// pays through the blocked rays (the blocker of one stops the next), and costs every ray
/// its place in the sort: measured with AIS off, it lost 3–9% where 13% of the rays were
/// blocked (an open sky) and gained 9–11% where 60% were (a courtyard).
const SORTS_ABOVE_BLOCKED: f32 = 0.25;

/// What a candidate whose ray is left in the pool brings if the ray is free.
#[derive(Clone, Copy, Debug)]
pub(super) enum Brings {
    /// This value, weighed in its sample's.
    Value(Vec3),
    /// What the map sends along the candidate's direction ([`SkyLookup`]).
    Sky(SkyLookup),
}

/// What a candidate that meets the map brings, but for the map's numbers (its direction
/// is its shadow ray's).
#[derive(Clone, Copy, Debug)]
pub(super) struct SkyLookup {
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
}

/// A candidate left in the pool.
#[derive(Clone, Copy, Debug)]
struct Left {
    /// The camera sample (within the pixel) it belongs to.
    sample: u32,
    /// Its weight in the sample's value: one over the gather's candidates.
    weight: f32,
    /// Its shadow ray.
    ray: Ray,
    /// Whether the ray was found blocked.
    blocked: bool,
    brings: Brings,
}

impl PixelPool {
    /// Opens the pool for a pixel's gathers.
    pub(super) fn open(&mut self) {
        self.open = true;
        self.left.clear();
    }

    /// Whether gathers may leave their candidates here.
    pub(super) fn is_open(&self) -> bool {
        self.open
    }

    /// The pixel's camera sample `sample` is being gathered.
    pub(super) fn begin_sample(&mut self, sample: u32) {
        self.sample = sample;
    }

    /// Leaves a candidate of the sample being gathered, with weight `weight` in its value:
    /// what it `brings` if its shadow `ray` is free.
    pub(super) fn leave(&mut self, ray: Ray, brings: Brings, weight: f32) {
        self.left.push(Left {
            sample: self.sample,
            weight,
            ray,
            blocked: false,
            brings,
        });
    }

    /// Traces the pool's rays through `geometry`, adds what each free candidate brings to
    /// its sample's value in `values` (the map's lookups from `map`, sixteen at a time),
    /// and closes the pool.
    pub(super) fn resolve(
        &mut self,
        geometry: &Geometry,
        map: Option<&EnvironmentMap>,
        values: &mut [[f32; 3]],
    ) {
        self.open = false;
        if self.left.is_empty() {
            return;
        }
        self.trace(geometry);
        let mut run = [0; MAP_LANES];
        let mut in_run = 0;
        for (i, left) in self
            .left
            .iter()
            .enumerate()
            .filter(|(_, left)| !left.blocked)
        {
            match (left.brings, map) {
                (Brings::Value(value), _) => {
                    add(&mut values[left.sample as usize], value, left.weight)
                }
                (Brings::Sky(_), Some(map)) => {
                    run[in_run] = i;
                    in_run += 1;
                    if in_run == MAP_LANES {
                        look_up(map, &self.left, &run, values);
                        in_run = 0;
                    }
                }
                (Brings::Sky(_), None) => unreachable!("only a map's candidates wait for it"),
            }
        }
        if let (Some(map), 1..) = (map, in_run) {
            look_up(map, &self.left, &run[..in_run], values);
        }
        self.left.clear();
    }

    /// Traces the rays, each tried first against what blocked the rays just before it, and
    /// notes which are blocked: in order of direction where the pool last found at least
    /// [`SORTS_ABOVE_BLOCKED`] of its rays blocked (or has not been resolved yet), else in
    /// the order left.
    fn trace(&mut self, geometry: &Geometry) {
        let mut blockers = RecentBlockers::default();
        let mut blocked = 0;
        let mut trace_one = |left: &mut Left| {
            left.blocked = geometry.occluded_after(&left.ray, &mut blockers);
            blocked += left.blocked as usize;
        };
        if self.sorts() {
            self.sort_by_direction();
            self.order
                .iter()
                .for_each(|&i| trace_one(&mut self.left[i as usize]));
        } else {
            self.left.iter_mut().for_each(trace_one);
        }
        self.blocked_share = Some(blocked as f32 / self.left.len() as f32);
    }

    /// Whether the rays are traced in order of direction ([`PixelPool::trace`]).
    fn sorts(&self) -> bool {
        self.blocked_share
            .is_none_or(|share| share >= SORTS_ABOVE_BLOCKED)
    }

    /// Puts the indices of the candidates in `order`, by direction: a counting sort over
    /// cells of the directions' octants.
    fn sort_by_direction(&mut self) {
        self.cells.clear();
        (self.cells).extend(
            self.left
                .iter()
                .map(|l| direction_cell(l.ray.direction) as u16),
        );
        let mut starts = [0u32; DIRECTION_CELLS + 1];
        for &cell in &self.cells {
            starts[cell as usize + 1] += 1;
        }
        for cell in 0..DIRECTION_CELLS {
            starts[cell + 1] += starts[cell];
        }
        self.order.clear();
        self.order.resize(self.left.len(), 0);
        for (i, &cell) in self.cells.iter().enumerate() {
            let start = &mut starts[cell as usize];
            self.order[*start as usize] = i as u32;
            *start += 1;
        }
    }
}

/// Adds `brought`, weighed by `weight`, to a sample's `value`.
fn add(value: &mut [f32; 3], brought: Vec3, weight: f32) {
    for (channel, add) in value.iter_mut().zip(brought.to_array()) {
        *channel += add * weight;
    }
}

/// Looks up what the candidates `run` of `left` (at most sixteen, each meeting `map`)
/// bring, all at once, and adds each to its sample's value in `values`.
#[inline(always)]
fn look_up(map: &EnvironmentMap, left: &[Left], run: &[usize], values: &mut [[f32; 3]]) {
    let lookup = |i: usize| match left[i].brings {
        Brings::Sky(lookup) => (left[i].ray.direction, lookup),
        Brings::Value(_) => unreachable!("a run holds the map's candidates"),
    };
    // Lanes past the run hold a unit direction, looked up for nothing.
    let mut directions = [Vec3::Z; MAP_LANES];
    let mut known = [None; MAP_LANES];
    for (k, &i) in run.iter().enumerate() {
        let (direction, lookup) = lookup(i);
        (directions[k], known[k]) = (direction, lookup.location);
    }
    let (locations, radiances) = map.look_up_lanes(&directions, &known);
    for (k, &i) in run.iter().enumerate() {
        let (_, lookup) = lookup(i);
        let parts = MisParts {
            bsdf: lookup.bsdf_density,
            light: lookup.choice * map.density_at(locations[k]) as f64,
        };
        let brought = weighed(lookup.scattering, radiances[k], parts.mixed(lookup.share));
        add(
            &mut values[left[i].sample as usize],
            brought,
            left[i].weight,
        );
    }
}

/// How many cells of direction the rays are sorted into: 64 per octant.
const DIRECTION_CELLS: usize = 8 * 64;

/// The cell of `direction` (a unit vector): its octant, then an 8 × 8 grid over the
/// octant's face of the octahedron |x| + |y| + |z| = 1.
fn direction_cell(direction: Vec3) -> usize {
    let negative = direction.cmplt(Vec3::ZERO).bitmask() as usize;
    let on_face = direction.abs() / direction.abs().element_sum();
    let cell = |v: f32| ((v * 8.0) as usize).min(7);
    negative << 6 | cell(on_face.x) << 3 | cell(on_face.y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ShapeGeometry, ShapeInput, Sphere};
    use ais::rng::Pcg32;

    #[test]
    fn the_rays_are_traced_by_direction_cell_each_once_and_in_order_within_a_cell() {
        let mut rng = Pcg32::new(4, 2);
        let mut pool = PixelPool::default();
        pool.open();
        for _ in 0..700 {
            let mut coordinate = || 2.0 * rng.next_f32() - 1.0;
            let direction = Vec3::new(coordinate(), coordinate(), coordinate()).normalize();
            // Axis-aligned directions sit on the cells' edges.
            let direction = if pool.left.len() % 50 == 0 {
                -Vec3::Y
            } else {
                direction
            };
            let ray = Ray::new(Vec3::ZERO, direction);
            pool.leave(ray, Brings::Value(Vec3::ONE), 1.0);
        }
        pool.sort_by_direction();
        let mut seen = vec![false; pool.left.len()];
        let cells: Vec<usize> = (pool.order.iter())
            .map(|&i| {
                assert!(!std::mem::replace(&mut seen[i as usize], true), "{i} twice");
                direction_cell(pool.left[i as usize].ray.direction)
            })
            .collect();
        assert!(seen.iter().all(|&seen| seen), "every ray is traced");
        for (pair, order) in cells.windows(2).zip(pool.order.windows(2)) {
            assert!(pair[0] < pair[1] || (pair[0] == pair[1] && order[0] < order[1]));
        }
        let distinct = cells.iter().collect::<std::collections::HashSet<_>>().len();
        assert!(
            distinct > 200,
            "directions spread over the cells: {distinct}"
        );
    }

    /// A pool sorts its rays until it finds most of them free, and again once it finds
    /// many blocked; either way every free ray's value is added, and no blocked one's.
    #[test]
    fn a_pool_sorts_its_rays_where_many_were_blocked() {
        let sphere = Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        };
        let geometry = Geometry::build(vec![ShapeInput {
            geometry: ShapeGeometry::Sphere(sphere),
            flip_normals: false,
            rotation: None,
        }]);
        let mut pool = PixelPool::default();
        let resolve = |pool: &mut PixelPool, values: &mut [[f32; 3]], toward: Vec3, rays| {
            pool.open();
            for k in 0..rays {
                let wobble = Vec3::new(k as f32 * 1e-3, 0.0, 0.0);
                let ray = Ray::new(Vec3::ZERO, (toward + wobble).normalize());
                pool.leave(ray, Brings::Value(Vec3::ONE), 0.5);
            }
            pool.resolve(&geometry, None, values);
        };
        let mut values = [[0.0; 3]; 1];
        assert!(pool.sorts(), "a new pool sorts");
        resolve(&mut pool, &mut values, -Vec3::Z, 40);
        assert!(!pool.sorts(), "all its rays were free");
        assert_eq!(values[0], [20.0; 3]);
        resolve(&mut pool, &mut values, Vec3::Z, 40);
        assert!(pool.sorts(), "all its rays were blocked");
        assert_eq!(values[0], [20.0; 3]);
        resolve(&mut pool, &mut values, -Vec3::Z, 10);
        assert_eq!(values[0], [25.0; 3]);
    }

    #[test]
    fn a_direction_cell_holds_only_directions_of_its_octant() {
        let cell_of = |x: f32, y: f32, z: f32| direction_cell(Vec3::new(x, y, z).normalize());
        assert_eq!(cell_of(1.0, 0.0, 0.0), 7 << 3);
        assert_eq!(cell_of(0.0, 0.0, 1.0), 0);
        assert_eq!(cell_of(-1.0, -1.0, -1.0) >> 6, 7);
        assert!((0..DIRECTION_CELLS).contains(&cell_of(-0.0, -1.0, 0.0)));
    }
}
