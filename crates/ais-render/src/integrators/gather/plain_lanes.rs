//! A plain batch (AIS off's, or a guided one of `auto`'s) drawn by MIS, run lane by lane:
//! a run's directions, places on the map and sources in arrays of their own, without the
//! general runs' per-candidate record (a [`Toward`], over a hundred bytes copied between
//! stages) and their dispatch over kinds of draws. Any lights: area and delta lights, and
//! an environment (a map or a constant sky, drawn from its own density or its product with
//! a guide). The estimate of the general runs ([`super::batch_loop`]) to the bit.
//!
//! [`Toward`]: crate::lights::Toward

use super::batch_loop::{BatchRun, PlainSum};
use super::light::{ray_origins, shadow_ray};
use super::pixel_pool::{Brings, SkyLookup};
use super::shared_origin::SharedOrigin;
use super::strategy::{MisParts, MisPick, Strategy};
use crate::bsdf::{DiffuseHit, SpecularMass};
use crate::lights::{
    Aim, AreaDraws, Draw, Environment, EnvironmentDraws, EnvironmentGuide, EnvironmentMap,
    MapLocation, MapWeights, Receiver, Source, Toward, LANES,
};
use crate::render::RayCounts;
use glam::Vec3;
use std::f64::consts::PI;

/// How many candidates are drawn, traced and added up together (as many as the lights
/// find sources for at once, [`crate::lights::Lights::sources_along`]).
const RUN: usize = LANES;

/// What a lane-by-lane batch needs of its scene and gather point.
pub(super) struct PlainLanes<'a> {
    /// The environment, if any.
    sky: Option<Sky<'a>>,
    /// MIS's BSDF share.
    share: f64,
    /// The probability that light sampling chooses the environment.
    choice: f64,
    /// Whether there are lights besides the environment: without them, every candidate
    /// meets the environment, and no shaft bounds any ray.
    sources: bool,
    /// A single diffuse material, whose numbers are worked out here (other BSDFs are asked
    /// for theirs; every BSDF's draws are the run's, [`GatherPoint::draw_bsdf_run`]).
    ///
    /// [`GatherPoint::draw_bsdf_run`]: super::strategy::GatherPoint::draw_bsdf_run
    diffuse: Option<DiffuseHit>,
    /// Whether the shadow rays that no shaft bounds are left to the pixel's pool.
    defers: bool,
}

/// The environment, as the lanes look it up.
enum Sky<'a> {
    /// A map, drawn from its own density (no guide) or from a guide whose texels hold its
    /// cells (the guide's weights over the map's own density).
    Map {
        map: &'a EnvironmentMap,
        guide: Option<MapWeights<'a>>,
    },
    /// The same radiance from everywhere, drawn uniformly or from a guide's texels.
    Constant {
        radiance: Vec3,
        guide: Option<&'a EnvironmentGuide>,
    },
}

/// What the environment sends along a direction, and light sampling's density of it (the
/// choice of the environment left out).
struct SkyLight {
    radiance: Vec3,
    density: f64,
}

impl<'a> Sky<'a> {
    /// `environment`, as drawn for `receiver` (`None`: by a guide whose texels split a map's
    /// cells, which has no weight per cell).
    fn of(environment: &'a Environment, receiver: &Receiver<'a>) -> Option<Self> {
        let guide = receiver.environment_guide;
        Some(match environment {
            Environment::Map(map) => Sky::Map {
                map,
                guide: match guide {
                    Some(guide) => Some(guide.map_weights()?),
                    None => None,
                },
            },
            &Environment::Constant(radiance) => Sky::Constant { radiance, guide },
        })
    }

    /// What arrives along `direction` (at `location` on a map if drawn from it). The
    /// densities are the general lookups' to the bit: an unguided one is multiplied by 1.
    /// (Always inlined: called from both forms of the lanes, it was not, and scenes lit by
    /// a sky lost 3%.)
    #[inline(always)]
    fn toward(&self, direction: Vec3, location: Option<MapLocation>) -> SkyLight {
        match self {
            Sky::Map { map, guide } => {
                let location = location.unwrap_or_else(|| map.locate(direction));
                let guided = guide.map_or(1.0, |weights| weights.at(location));
                SkyLight {
                    radiance: map.radiance_at(location),
                    density: map.density_at(location) as f64 * guided,
                }
            }
            Sky::Constant { radiance, guide } => {
                let guided = guide.map_or(1.0, |guide| guide.weight_toward(direction));
                SkyLight {
                    radiance: *radiance,
                    density: 1.0 / (4.0 * PI) * guided,
                }
            }
        }
    }
}

/// The candidates of one run, lane by lane.
struct Lanes {
    /// Each candidate's direction.
    direction: [Vec3; RUN],
    /// Where a candidate drawn from the map falls on it (`None`: drawn otherwise, to be
    /// located if it meets the environment and its ray is free).
    location: [Option<MapLocation>; RUN],
    /// What it meets first among the emitters ([`Source::Unknown`] until found).
    source: [Source; RUN],
    /// Whether a direction was drawn and lies inside the BSDF's support.
    kept: [bool; RUN],
    /// Whether a direction was drawn.
    drawn: [bool; RUN],
    /// Whether its shadow ray was traced and is free.
    free: [bool; RUN],
    /// A BSDF-drawn candidate's specular lobe (a point mass), where one gave it.
    specular: [Option<SpecularMass>; RUN],
    /// Whether its shadow ray is left to the pixel's pool to trace (then `free` holds until
    /// the pool finds otherwise), whether the ray ends, and the point it ends at (where it
    /// ends). All three are set only for candidates whose ray is needed: a lane whose ray
    /// is not needed may hold an earlier run's. `deferred` is read only where `free` is
    /// set, the other two only where `deferred` is. (Two arrays, not one of
    /// `Option<Vec3>`: an option written a field at a time and copied whole waited for the
    /// writes.)
    deferred: [bool; RUN],
    bounded: [bool; RUN],
    target: [Vec3; RUN],
}

impl Default for Lanes {
    fn default() -> Self {
        Lanes {
            // Unit directions in lanes never drawn: the lights' tests over all the lanes
            // stay finite there.
            direction: [Vec3::Z; RUN],
            location: [None; RUN],
            source: [Source::Unknown; RUN],
            kept: [false; RUN],
            drawn: [false; RUN],
            free: [false; RUN],
            specular: [None; RUN],
            deferred: [false; RUN],
            bounded: [false; RUN],
            target: [Vec3::ZERO; RUN],
        }
    }
}

impl Lanes {
    /// The point candidate `k`'s shadow ray ends at, if it ends (set where it is deferred).
    #[inline]
    fn target_of(&self, k: usize) -> Option<Vec3> {
        self.bounded[k].then_some(self.target[k])
    }

    /// Candidate `k` drawn toward `toward`, which meets `source` first (kept only where
    /// the lanes keep sources, `SOURCES`).
    #[inline]
    fn put<const SOURCES: bool>(&mut self, k: usize, toward: &Toward, source: Source) {
        self.direction[k] = toward.direction;
        self.location[k] = toward.map_location();
        if SOURCES {
            self.source[k] = source;
        }
        self.specular[k] = toward.specular;
        self.drawn[k] = true;
    }
}

impl<'a> PlainLanes<'a> {
    /// The batch's lanes, where they apply: an unguided MIS proposal, and an environment
    /// that is a constant one, or a map drawn from its own density or from a guide whose
    /// texels hold its cells (or none), beside any other lights. Any BSDF: its own draws
    /// and densities are asked of it.
    pub(super) fn of(run: &BatchRun<'a>) -> Option<Self> {
        let at = run.at;
        let lights = at.lights;
        let unguided_mis = run.sampler.unguided() == Some(Strategy::Mis);
        if !unguided_mis || lights.is_empty() {
            return None;
        }
        // (Without an environment, its probability is not asked for: there is none.)
        let (sky, choice) = match &lights.environment {
            Some(environment) => (
                Some(Sky::of(environment, &at.receiver)?),
                lights.environment_choice(&at.receiver),
            ),
            None => (None, 0.0),
        };
        Some(PlainLanes {
            sky,
            diffuse: at.bsdf.diffuse(at.wo),
            share: at.mis_bsdf_share,
            choice,
            sources: !(lights.area.is_empty() && lights.delta.is_empty()),
            defers: run.pixel_pool.is_some() && lights.some_rays_unbounded(),
        })
    }

    /// Draws, traces and adds up the candidates of `numbers` (the batch's, from
    /// [`ais::Batch::begin_plain`]) into `total`.
    pub(super) fn run(
        &self,
        run: &BatchRun,
        numbers: &[[f32; 2]],
        counts: &mut RayCounts,
        total: &mut PlainSum,
    ) {
        // Compiled twice: lit by the environment alone, the lanes keep no sources (keeping
        // them cost scenes lit by a sky about 2% of a frame).
        // And twice again: where no ray is left to the pixel's pool (lights all bounded by
        // shafts), the lanes are compiled without the pool's steps.
        match (self.sources, self.defers) {
            (true, true) => self.run_lanes::<true, true>(run, numbers, counts, total),
            (true, false) => self.run_lanes::<true, false>(run, numbers, counts, total),
            (false, true) => self.run_lanes::<false, true>(run, numbers, counts, total),
            (false, false) => self.run_lanes::<false, false>(run, numbers, counts, total),
        }
    }

    /// [`PlainLanes::run`], with lights besides the environment (`SOURCES`) or none, and
    /// with the rays that no shaft bounds left to the pixel's pool (`DEFERS`) or not.
    #[inline(never)]
    fn run_lanes<const SOURCES: bool, const DEFERS: bool>(
        &self,
        run: &BatchRun,
        numbers: &[[f32; 2]],
        counts: &mut RayCounts,
        total: &mut PlainSum,
    ) {
        let mut origin = run.shared_origin();
        let mut lanes = Lanes::default();
        let origins = ray_origins(run.at);
        // Borrowed once for the batch: nothing else reaches the pool while it runs.
        let mut pool = run
            .pixel_pool
            .filter(|_| DEFERS)
            .map(|pool| pool.borrow_mut());
        for numbers in numbers.chunks(RUN) {
            let count = numbers.len();
            self.draw::<SOURCES>(run, numbers, &mut lanes);
            let kept = lanes.kept[..count].iter().filter(|&&kept| kept).count();
            total.count_run(count, kept);
            if SOURCES {
                meet(run, &mut lanes, count);
            }
            trace::<SOURCES, DEFERS>(run, &mut lanes, count, counts, &mut origin);
            // All the lookups after all the rays, so that they overlap. A candidate whose
            // ray was blocked or not needed adds its zero, as in the general runs (the
            // gather's spread counts it), and so does one left to the pixel's pool.
            for k in (0..count).filter(|&k| lanes.kept[k]) {
                total.add(
                    match (lanes.free[k], DEFERS && lanes.deferred[k], pool.as_mut()) {
                        (false, ..) => Vec3::ZERO,
                        (true, true, Some(pool)) => {
                            let ray = origins.aimed(lanes.direction[k], lanes.target_of(k));
                            let brings = self.brings::<SOURCES>(run, &lanes, k);
                            pool.leave(ray, brings, 1.0 / run.rays as f32);
                            Vec3::ZERO
                        }
                        (true, ..) => self.brought::<SOURCES>(run, &lanes, k),
                    },
                );
            }
        }
        run.pass_on(&origin);
    }

    /// Draws the candidates of `numbers` into `lanes`: the map's all together
    /// ([`EnvironmentDraws`]), then the area lights' ([`AreaDraws`]), then the
    /// BSDF's ([`GatherPoint::draw_bsdf_run`]), and which carry light to the viewer
    /// ([`GatherPoint::carries`]).
    ///
    /// [`GatherPoint::draw_bsdf_run`]: super::strategy::GatherPoint::draw_bsdf_run
    /// [`GatherPoint::carries`]: super::strategy::GatherPoint::carries
    #[inline(always)]
    fn draw<const SOURCES: bool>(&self, run: &BatchRun, numbers: &[[f32; 2]], lanes: &mut Lanes) {
        let at = run.at;
        let mut environment = EnvironmentDraws::default();
        let mut area_draws = AreaDraws::default();
        let mut bsdf_numbers = [[0.0; 2]; RUN];
        let mut bsdf_slots = [0; RUN];
        let mut bsdf_draws = 0;
        lanes.drawn = [false; RUN];
        // A BSDF-drawn direction's source is found later, with the run's others ([`meet`]).
        for (k, &u) in numbers.iter().enumerate() {
            let u = match MisPick::of(self.share, u) {
                MisPick::Bsdf(u) => {
                    (bsdf_numbers[bsdf_draws], bsdf_slots[bsdf_draws]) = (u, k);
                    bsdf_draws += 1;
                    continue;
                }
                MisPick::Light(u) => u,
            };
            match at.lights.begin_sample(&at.receiver, u) {
                Draw::Environment(u) => environment.push(k, u),
                Draw::Area(draw) => area_draws.push(k, draw),
                Draw::Made(Some(toward)) => lanes.put::<SOURCES>(k, &toward, toward.source()),
                Draw::Made(None) => {}
            }
        }
        let receiver = &at.receiver;
        environment.draw(at.lights, receiver, |k, toward| {
            lanes.put::<SOURCES>(k, &toward, Source::Environment);
        });
        area_draws.draw(at.lights, receiver, |k, toward| {
            lanes.put::<SOURCES>(k, &toward, toward.source());
        });
        at.draw_bsdf_run(&bsdf_numbers[..bsdf_draws], |i, toward| {
            if let Some(toward) = toward {
                lanes.put::<SOURCES>(bsdf_slots[i], &toward, Source::Unknown);
            }
        });
        for (k, kept) in lanes.kept[..numbers.len()].iter_mut().enumerate() {
            let in_support = self.in_support(run, lanes.direction[k]);
            *kept = lanes.drawn[k] && (lanes.specular[k].is_some() || in_support);
        }
    }

    /// What candidate `k` of `lanes`, whose ray is free, brings (f·L/p, as the general runs
    /// weigh it: along a specular lobe, its mass over the probability of picking it).
    #[inline]
    fn brought<const SOURCES: bool>(&self, run: &BatchRun, lanes: &Lanes, k: usize) -> Vec3 {
        let at = run.at;
        let direction = lanes.direction[k];
        let source = match SOURCES {
            true => &lanes.source[k],
            false => &Source::Environment,
        };
        let (radiance, light_density) = match (source, &self.sky) {
            (Source::Area(point), _) => (point.radiance, point.density),
            (Source::Environment, Some(sky)) => {
                let arriving = sky.toward(direction, lanes.location[k]);
                (arriving.radiance, self.choice * arriving.density)
            }
            (&Source::Delta(delta, arrival), _) => {
                // A point mass of light sampling, which the BSDF's density does not add to.
                let pdf = (1.0 - self.share) * at.lights.delta_choice(&at.receiver, delta);
                return weighed(self.bsdf_value(run, direction), arrival.light, pdf);
            }
            _ => unreachable!("a free ray meets a light or the environment"),
        };
        let (scattering, pdf) = match lanes.specular[k] {
            Some(mass) => (mass.weight, self.share * mass.probability as f64),
            None => {
                let (eval, bsdf) = self.bsdf_value_and_density(run, direction);
                let parts = MisParts {
                    bsdf,
                    light: light_density,
                };
                (eval, parts.mixed(self.share))
            }
        };
        weighed(scattering, radiance, pdf)
    }

    /// What candidate `k` of `lanes`, whose ray is left to the pixel's pool, brings if the
    /// ray is free: the numbers of a lookup on an unguided map, which the pool makes with
    /// others in lanes, or else its value ([`PlainLanes::brought`]).
    #[inline(always)]
    fn brings<const SOURCES: bool>(&self, run: &BatchRun, lanes: &Lanes, k: usize) -> Brings {
        let to_sky = !SOURCES || matches!(lanes.source[k], Source::Environment);
        let unguided_map = matches!(self.sky, Some(Sky::Map { guide: None, .. }));
        if !(to_sky && unguided_map && lanes.specular[k].is_none()) {
            return Brings::Value(self.brought::<SOURCES>(run, lanes, k));
        }
        let (scattering, bsdf_density) = self.bsdf_value_and_density(run, lanes.direction[k]);
        Brings::Sky(SkyLookup {
            location: lanes.location[k],
            scattering,
            bsdf_density,
            choice: self.choice,
            share: self.share,
        })
    }

    /// Whether light along `direction` reaches the viewer through the BSDF's continuous
    /// part: from the diffuse material's numbers where there is one, else asked of the BSDF.
    #[inline]
    fn in_support(&self, run: &BatchRun, direction: Vec3) -> bool {
        match &self.diffuse {
            Some(diffuse) => diffuse.in_support(direction),
            None => run.at.bsdf.in_support(run.at.wo, direction),
        }
    }

    /// The BSDF times the cosine toward `direction`, from the same numbers as
    /// [`PlainLanes::in_support`].
    #[inline]
    fn bsdf_value(&self, run: &BatchRun, direction: Vec3) -> Vec3 {
        match &self.diffuse {
            Some(diffuse) => diffuse.eval(direction),
            None => run.at.bsdf.eval(run.at.wo, direction),
        }
    }

    /// [`PlainLanes::bsdf_value`] and the density of the BSDF's draws toward `direction`.
    #[inline(always)]
    fn bsdf_value_and_density(&self, run: &BatchRun, direction: Vec3) -> (Vec3, f64) {
        match &self.diffuse {
            Some(diffuse) => diffuse.eval_and_pdf(direction),
            None => {
                let at = run.at;
                (
                    at.bsdf.eval(at.wo, direction),
                    at.bsdf.pdf(at.wo, direction),
                )
            }
        }
    }
}

/// f·L/p of a candidate whose surface scatters by `scattering` the `radiance` arriving,
/// drawn with probability (density) `pdf`: nothing at a zero density (possible only at a
/// light's rim in f32) or a zero radiance.
#[inline]
pub(super) fn weighed(scattering: Vec3, radiance: Vec3, pdf: f64) -> Vec3 {
    if pdf <= 0.0 || radiance == Vec3::ZERO {
        return Vec3::ZERO;
    }
    scattering * radiance / pdf as f32
}

/// Finds what the kept candidates of `lanes` (the first `count`) whose sources are not
/// known meet first among the emitters: the BSDF's draws.
#[inline(always)]
fn meet(run: &BatchRun, lanes: &mut Lanes, count: usize) {
    let wanted: [bool; RUN] = std::array::from_fn(|k| {
        k < count && lanes.kept[k] && matches!(lanes.source[k], Source::Unknown)
    });
    let receiver = &run.at.receiver;
    (run.world.lights).sources_along(receiver, &lanes.direction, &wanted, &mut lanes.source);
}

/// Traces the shadow rays of the kept candidates of `lanes` (the first `count`) that could
/// bring light, toward the point of the area light they meet or the environment, with what
/// the gather's earlier rays learned (`origin`), and notes which are free. Without area
/// lights besides the environment (`SOURCES`), every one meets it and no shaft bounds any.
/// With `DEFERS`, the rays that no shaft bounds are left to the pixel's pool instead, and
/// noted free until the pool finds otherwise.
fn trace<const SOURCES: bool, const DEFERS: bool>(
    run: &BatchRun,
    lanes: &mut Lanes,
    count: usize,
    counts: &mut RayCounts,
    origin: &mut SharedOrigin,
) {
    let (world, at) = (run.world, run.at);
    let lights = &world.lights;
    let shaft_light = |source: &Source| match SOURCES {
        true => lights.shaft_light_of(source),
        false => None,
    };
    if SOURCES {
        let aimed = (0..count).filter(|&k| lanes.kept[k]);
        origin.expect(aimed.map(|k| shaft_light(&lanes.source[k])));
    }
    for k in 0..count {
        let aim = match SOURCES {
            _ if !lanes.kept[k] => Aim::Nothing,
            true => lights.aim_at(&at.receiver, &lanes.source[k]),
            false => Aim::Unbounded,
        };
        let target = match aim {
            Aim::Nothing => {
                lanes.free[k] = false;
                continue;
            }
            Aim::Point(target) => {
                (lanes.bounded[k], lanes.target[k]) = (true, target);
                Some(target)
            }
            Aim::Unbounded => {
                lanes.bounded[k] = false;
                None
            }
        };
        counts.occlusion += 1;
        // A ray toward a light with a shaft stays with the gather, which may find it free
        // from the shaft (leaving those to the pool too lost time in a room lit through a
        // door gap).
        let light = shaft_light(&lanes.source[k]);
        if DEFERS {
            lanes.deferred[k] = light.is_none();
            if light.is_none() {
                lanes.free[k] = true;
                continue;
            }
        }
        let ray = shadow_ray(at, lanes.direction[k], target);
        lanes.free[k] = !origin.occluded_aiming(world, at, light, &ray);
    }
}

#[cfg(test)]
mod tests {
    use super::super::batch_loop::add_up_plain;
    use super::super::gather_sizes::CandidateSpread;
    use super::super::guiding::CandidateSampler;
    use super::super::settings::GatherSettings;
    use super::super::strategy::gather_point;
    use super::*;
    use crate::geometry::Ray;
    use crate::image_io::{write_exr, RgbImage};
    use crate::lights::{EnvironmentPartition, GuideLayout, Lights, RegionChoice, REGIONS};
    use crate::scene::load_scene;
    use crate::world::World;
    use ais::rng::Pcg32;
    use ais::sampling::AliasTable;
    use ais::{Batch, BatchConfig, MapStart};
    use std::sync::Arc;

    /// A diffuse floor with a smooth plastic box and a rough metal ball on it under
    /// `emitter`, in a scratch folder named after `name` (holding `sky.exr`: a map of 32 × 16
    /// texels with a small sun).
    fn scene_under(name: &str, emitter: &str) -> World {
        let dir = std::env::temp_dir().join(format!("ais-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut sky = RgbImage::new(32, 16);
        for (i, pixel) in sky.pixels.iter_mut().enumerate() {
            let v = 0.1 + (i / 32) as f32 / 16.0 + 0.02 * (i % 32) as f32;
            *pixel = [v, 0.9 * v, 0.7 * v];
        }
        sky.pixels[3 * 32 + 5] = [400.0; 3];
        write_exr(&dir.join("sky.exr"), &sky).unwrap();
        let xml = format!(
            r#"<scene version="3.0.0">{emitter}
            <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.6, 0.5, 0.4"/></bsdf>
            <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform><ref id="grey"/></shape>
            <shape type="cube"><transform name="to_world"><scale value="0.5"/><translate z="0.5"/></transform>
                <bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2, 0.4, 0.6"/></bsdf></shape>
            <shape type="sphere"><point name="center" x="-1" y="0.8" z="0.4"/><float name="radius" value="0.4"/>
                <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf></shape>
        </scene>"#
        );
        std::fs::write(dir.join("scene.xml"), xml).unwrap();
        let world = World::from_description(load_scene(&dir.join("scene.xml"), &[]).unwrap());
        // The world holds the sky in memory; the files are not needed once it is built.
        std::fs::remove_dir_all(&dir).unwrap();
        world.unwrap()
    }

    /// Two guides of `partition`'s texels: the product alone, and mixed half and half.
    fn guides(partition: Arc<EnvironmentPartition>) -> [Option<EnvironmentGuide>; 2] {
        let mut guides = [1.0, 0.5].map(|fraction| {
            let mut guide = EnvironmentGuide::new(partition.clone());
            guide.set_affinities(|t| 0.01 + ((t * 5) % 7) as f32);
            guide.set_fraction(fraction);
            guide
        });
        guides[1].set_affinities(|t| (t % 3) as f32);
        guides.map(Some)
    }

    /// A field cell's learned choice of `lights` (none chosen by power) and of the first
    /// area light's regions, if there is one.
    fn learned_choices(lights: &Lights) -> (AliasTable, Vec<Option<RegionChoice>>) {
        let choice_weights: Vec<f64> = (0..lights.source_count())
            .map(|l| 0.2 + (l % 3) as f64)
            .collect();
        let region_weights: [f64; REGIONS] = std::array::from_fn(|r| 0.5 + (r % 4) as f64);
        let mut region_choices = vec![None; lights.area.len()];
        if let Some(first) = region_choices.first_mut() {
            *first = RegionChoice::new(&region_weights);
        }
        (AliasTable::new(&choice_weights), region_choices)
    }

    /// Compares the lanes with the general runs at 400 gather points of `world` seen from
    /// above, lit and in shadow, for several MIS shares and batch sizes, unguided and with
    /// each of `guides`, the lights chosen by power and by a cell's learned choice (with
    /// the first area light's regions weighed, where there is one): their estimates,
    /// counts and spreads must be the same to the bit.
    fn compare_batches(world: &World, guides: &[Option<EnvironmentGuide>; 2]) {
        let (light_choice, region_choices) = learned_choices(&world.lights);
        let settings = GatherSettings::default();
        let sampler = CandidateSampler::plain(Strategy::Mis);
        let mut batch = Batch::<[f32; 3]>::new(BatchConfig::off()).unwrap();
        let mut rng = Pcg32::new(5, 0);
        let mut compared = 0;
        for trial in 0..400u64 {
            let target = Vec3::new(rng.next_f32() * 3.0 - 1.5, rng.next_f32() * 3.0 - 1.5, 0.0);
            let eye = Vec3::new(2.0, -3.0, 2.5);
            let ray = Ray::new(eye, (target - eye).normalize());
            let Some(hit) = world.geometry.intersect(&ray) else {
                continue;
            };
            let mut at = gather_point(world, &hit, (eye - hit.point).normalize());
            at.mis_bsdf_share = [0.5, 0.25, 0.8][trial as usize % 3];
            at.receiver.environment_guide =
                [None, guides[0].as_ref(), guides[1].as_ref()][(trial / 3) as usize % 3];
            if trial % 4 == 1 {
                at.receiver.light_choice = Some(&light_choice);
                at.receiver.region_choices = &region_choices;
            }
            let run = BatchRun {
                world,
                settings: &settings,
                rays: 7 + (trial % 20) as u32,
                at: &at,
                sampler: &sampler,
                seed: trial,
                start: MapStart::Empty,
                field: None,
                clock: None,
                blockers: &std::cell::Cell::default(),
                pixel_pool: None,
            };
            let lanes = PlainLanes::of(&run).expect("lights the lanes take");
            let numbers = batch.begin_plain(run.rays, run.seed).to_vec();
            let totals = [true, false].map(|in_lanes| {
                let mut spread = CandidateSpread::default();
                let mut counts = RayCounts::default();
                let mut total = PlainSum {
                    spread: Some(&mut spread),
                    ..PlainSum::default()
                };
                match in_lanes {
                    true => lanes.run(&run, &numbers, &mut counts, &mut total),
                    false => add_up_plain(&run, &numbers, &mut counts, &mut total),
                }
                let (sum, tally) = (total.sum, total.tally);
                format!("{sum:?} {tally:?} {counts:?} {spread:?}")
            });
            assert_eq!(totals[0], totals[1], "gather {trial}");
            compared += 1;
        }
        assert!(compared > 300, "{compared} gathers hit the scene");
    }

    /// A rotated map.
    const MAP: &str = r#"<emitter type="envmap"><string name="filename" value="sky.exr"/>
            <transform name="to_world"><rotate x="1" angle="90"/><rotate z="1" angle="30"/></transform></emitter>"#;

    /// A rectangle light facing the floor, a sphere light, and a small cube (a mesh) that
    /// emits.
    const AREA_LIGHTS: &str = r#"
        <shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="180"/>
            <translate x="0.6" y="0.3" z="2.2"/></transform>
            <emitter type="area"><rgb name="radiance" value="9, 8, 7"/></emitter></shape>
        <shape type="sphere"><point name="center" x="1.2" y="-1" z="1.1"/><float name="radius" value="0.2"/>
            <emitter type="area"><rgb name="radiance" value="20, 12, 6"/></emitter></shape>
        <shape type="cube"><transform name="to_world"><scale value="0.15"/><translate x="-0.9" y="-0.9" z="1.4"/></transform>
            <emitter type="area"><rgb name="radiance" value="5, 9, 14"/></emitter></shape>"#;

    /// Under a rotated map, drawn from its own density and from a guide whose texels hold
    /// its cells.
    #[test]
    fn the_lanes_are_the_general_batch_to_the_bit_under_a_map() {
        let world = scene_under("plain-lanes-map", MAP);
        let Some(Environment::Map(map)) = &world.lights.environment else {
            unreachable!("the scene has a map")
        };
        compare_batches(&world, &guides(map.partition(GuideLayout::Octahedral(8))));
    }

    /// A pixel's gathers with their shadow rays and map lookups pooled ([`gather_samples`],
    /// 100 samples: two pools) bring what they bring one by one ([`gather`]), up to the
    /// rounding of sums made in another order; without the pool they would bring much less.
    ///
    /// [`gather_samples`]: super::super::gather_samples
    /// [`gather`]: super::super::gather
    #[test]
    fn a_pixels_pooled_rays_and_map_lookups_bring_what_its_gathers_bring_one_by_one() {
        let world = scene_under("pixel-pool-map", &format!("{MAP}{AREA_LIGHTS}"));
        pooled_gathers_bring_what_they_bring_one_by_one(&world);
    }

    /// With no map: only the pool's rays.
    #[test]
    fn a_pixels_pooled_rays_under_a_constant_sky_bring_what_its_gathers_bring_one_by_one() {
        let constant =
            r#"<emitter type="constant"><rgb name="radiance" value="3, 3.5, 4"/></emitter>"#;
        let world = scene_under("pixel-pool-constant", &format!("{constant}{AREA_LIGHTS}"));
        pooled_gathers_bring_what_they_bring_one_by_one(&world);
    }

    /// A pixel's 100 gathers (two pools) in `world` bring, with the pool, what they bring
    /// one by one without it, and the pool takes a real share of it.
    fn pooled_gathers_bring_what_they_bring_one_by_one(world: &World) {
        use super::super::settings::Preset;
        use super::super::{gather, gather_samples, GatherLearning, GatherTile};
        use crate::render::{PixelRect, Tile};
        let settings = GatherSettings::preset(Preset::Off);
        let tile = Tile {
            rect: PixelRect::whole(8, 8),
            image: (8, 8),
            seed: 1,
            learns: false,
        };
        let learning = GatherLearning::new(world, &settings);
        let begin = || {
            let counts = &mut RayCounts::default();
            GatherTile::begin(world, &settings, &tile, &learning, counts, ())
        };
        let eye = Vec3::new(2.0, -3.0, 2.5);
        let mut aim = Pcg32::new(3, 0);
        let rays: Vec<Ray> = (0..100)
            .map(|_| {
                let target = Vec3::new(aim.next_f32() * 3.0 - 1.5, aim.next_f32() * 3.0 - 1.5, 0.0);
                Ray::new(eye, (target - eye).normalize())
            })
            .collect();
        let counts = &mut RayCounts::default();
        let (mut one_by_one, mut rng) = (begin(), Pcg32::new(9, 0));
        let single: Vec<[f32; 3]> = (rays.iter())
            .map(|ray| gather(world, &settings, ray, &mut rng, &mut one_by_one, counts).to_array())
            .collect();
        let mut pooled = Vec::new();
        gather_samples(
            world,
            &settings,
            &rays,
            &mut Pcg32::new(9, 0),
            &mut begin(),
            counts,
            &mut pooled,
        );
        // The same gathers with the pool open and never resolved: what they leave out.
        let (mut unresolved, mut rng) = (begin(), Pcg32::new(9, 0));
        unresolved.pixel_pool.get_mut().open();
        let left_out: Vec<[f32; 3]> = (rays.iter())
            .map(|ray| gather(world, &settings, ray, &mut rng, &mut unresolved, counts).to_array())
            .collect();
        let total = |values: &[[f32; 3]]| values.iter().flatten().map(|&c| c as f64).sum::<f64>();
        assert!(
            total(&left_out) < 0.8 * total(&single),
            "the pool takes a share: {} of {}",
            total(&left_out),
            total(&single)
        );
        for (sample, (a, b)) in pooled.iter().zip(&single).enumerate() {
            for (a, b) in a.iter().zip(b) {
                assert!(
                    (a - b).abs() <= 1e-5 * b.abs() + 1e-7,
                    "sample {sample}: {a} vs {b}"
                );
            }
        }
    }

    /// Under a constant sky, drawn uniformly and from a guide's uniform texels.
    #[test]
    fn the_lanes_are_the_general_batch_to_the_bit_under_a_constant_sky() {
        let emitter =
            r#"<emitter type="constant"><rgb name="radiance" value="0.8, 0.9, 1"/></emitter>"#;
        let world = scene_under("plain-lanes-constant", emitter);
        compare_batches(&world, &guides(Arc::new(EnvironmentPartition::uniform(8))));
    }

    /// Under a map and area lights of three kinds, which shadow one another.
    #[test]
    fn the_lanes_are_the_general_batch_to_the_bit_under_a_map_and_area_lights() {
        let world = scene_under("plain-lanes-map-and-area", &format!("{MAP}{AREA_LIGHTS}"));
        let Some(Environment::Map(map)) = &world.lights.environment else {
            unreachable!("the scene has a map")
        };
        assert_eq!(world.lights.area.len(), 3);
        compare_batches(&world, &guides(map.partition(GuideLayout::Octahedral(8))));
    }

    /// Under a constant sky, area lights and delta lights (a point light, a spot light and a
    /// directional light).
    #[test]
    fn the_lanes_are_the_general_batch_to_the_bit_under_delta_lights_too() {
        let emitters = r#"<emitter type="constant"><rgb name="radiance" value="0.1, 0.1, 0.2"/></emitter>
            <emitter type="point"><point name="position" x="-1" y="1" z="1.5"/><rgb name="intensity" value="3, 2, 1"/></emitter>
            <emitter type="spot"><transform name="to_world"><lookat origin="1, -1, 3" target="0, 0, 0" up="0, 0, 1"/></transform>
                <rgb name="intensity" value="6, 7, 9"/><float name="cutoff_angle" value="25"/></emitter>
            <emitter type="directional"><vector name="direction" x="0.4" y="0.3" z="-1"/><rgb name="irradiance" value="0.6, 0.5, 0.4"/></emitter>"#;
        let world = scene_under("plain-lanes-delta", &format!("{emitters}{AREA_LIGHTS}"));
        assert_eq!(world.lights.delta.len(), 3);
        compare_batches(&world, &guides(Arc::new(EnvironmentPartition::uniform(8))));
    }

    /// Lit by area lights alone: a direction from the BSDF that meets none brings nothing.
    #[test]
    fn the_lanes_are_the_general_batch_to_the_bit_under_area_lights_alone() {
        let world = scene_under("plain-lanes-area", AREA_LIGHTS);
        assert!(world.lights.environment.is_none());
        compare_batches(&world, &[None, None]);
    }
}
