//! A plain batch (AIS off's, or a guided one of `auto`'s) where the environment is the only
//! light (a map or a constant sky, drawn from its own density or its product with a guide)
//! and MIS draws the candidates: the estimate of the general runs ([`super::batch_loop`]) to
//! the bit, without their per-candidate bookkeeping (a candidate's [`Toward`], the dispatch
//! over kinds of draws and lights, the search for an emitter along a BSDF-drawn
//! direction). In scenes lit by a sky that bookkeeping was about a tenth of the frame.
//!
//! [`Toward`]: crate::lights::Toward

use super::batch_loop::{BatchRun, PlainSum};
use super::strategy::{MisParts, MisPick, Strategy};
use crate::bsdf::{diffuse_direction, ShadingFrame, SpecularMass};
use crate::geometry::{spawn_ray, RecentBlockers};
use crate::lights::{
    Draw, Environment, EnvironmentDraws, EnvironmentGuide, EnvironmentMap, MapLocation, MapWeights,
    Receiver,
};
use crate::render::RayCounts;
use glam::Vec3;
use std::f64::consts::PI;

/// How many candidates are drawn, traced and added up together.
const RUN: usize = 16;

/// What an environment-only batch needs of its scene and gather point.
pub(super) struct EnvironmentOnly<'a> {
    /// The only light.
    sky: Sky<'a>,
    /// MIS's BSDF share.
    share: f64,
    /// The probability that light sampling chooses the environment.
    choice: f64,
    /// A single diffuse material's frame, whose draws are made here (other BSDFs are asked
    /// for theirs).
    diffuse: Option<ShadingFrame>,
}

/// The environment, as the shortcut looks it up.
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
    #[inline]
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
    /// Where a candidate drawn from the map falls on it (`None`: drawn from the BSDF, to be
    /// located if its ray is free).
    location: [Option<MapLocation>; RUN],
    /// Whether a direction was drawn and lies inside the BSDF's support.
    kept: [bool; RUN],
    /// Whether its shadow ray is free.
    free: [bool; RUN],
    /// A BSDF-drawn candidate's specular lobe (a point mass), where one gave it.
    specular: [Option<SpecularMass>; RUN],
}

impl<'a> EnvironmentOnly<'a> {
    /// The batch's shortcut, where it applies: an unguided MIS proposal, and an environment
    /// as the only light (chosen by power): a constant one, or a map drawn from its own
    /// density or from a guide whose texels hold its cells. Any BSDF: its own draws and
    /// densities are asked of it.
    pub(super) fn of(run: &BatchRun<'a>) -> Option<Self> {
        let at = run.at;
        let lights = at.lights;
        let only_the_environment =
            lights.area.is_empty() && lights.delta.is_empty() && at.receiver.light_choice.is_none();
        if run.sampler.unguided() != Some(Strategy::Mis) || !only_the_environment {
            return None;
        }
        Some(EnvironmentOnly {
            sky: Sky::of(lights.environment.as_ref()?, &at.receiver)?,
            diffuse: at.bsdf.diffuse_frame().copied(),
            share: at.mis_bsdf_share,
            choice: lights.environment_choice(&at.receiver),
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
        let mut blockers = RecentBlockers::default();
        let mut lanes = Lanes {
            direction: [Vec3::ZERO; RUN],
            location: [None; RUN],
            kept: [false; RUN],
            free: [false; RUN],
            specular: [None; RUN],
        };
        for numbers in numbers.chunks(RUN) {
            let count = numbers.len();
            self.draw(run, numbers, &mut lanes);
            let kept = lanes.kept[..count].iter().filter(|&&kept| kept).count();
            total.count_run(count, kept);
            for k in 0..count {
                lanes.free[k] = lanes.kept[k] && {
                    counts.occlusion += 1;
                    let at = run.at;
                    let ray = spawn_ray(at.receiver.point, at.frame.geometric, lanes.direction[k]);
                    !run.world.geometry.occluded_after(&ray, &mut blockers)
                };
            }
            // All the lookups after all the rays, so that they overlap. A blocked candidate
            // adds its zero, as in the general runs (the gather's spread counts it).
            for k in (0..count).filter(|&k| lanes.kept[k]) {
                total.add(if lanes.free[k] {
                    self.brought(run, &lanes, k)
                } else {
                    Vec3::ZERO
                });
            }
        }
    }

    /// Draws the candidates of `numbers` into `lanes`: the map's all together
    /// ([`EnvironmentDraws`]), then the BSDF's ([`GatherPoint::draw_bsdf_run`]), and which
    /// carry light to the viewer ([`GatherPoint::carries`]).
    ///
    /// [`GatherPoint::draw_bsdf_run`]: super::strategy::GatherPoint::draw_bsdf_run
    /// [`GatherPoint::carries`]: super::strategy::GatherPoint::carries
    fn draw(&self, run: &BatchRun, numbers: &[[f32; 2]], lanes: &mut Lanes) {
        let at = run.at;
        let mut environment = EnvironmentDraws::default();
        let mut bsdf_numbers = [[0.0; 2]; RUN];
        let mut bsdf_slots = [0; RUN];
        let mut bsdf_draws = 0;
        let mut drawn = [false; RUN];
        for (k, &u) in numbers.iter().enumerate() {
            lanes.location[k] = None;
            lanes.specular[k] = None;
            let u = match MisPick::of(self.share, u) {
                MisPick::Bsdf(u) => {
                    if let Some(frame) = &self.diffuse {
                        (lanes.direction[k], drawn[k]) = (diffuse_direction(frame, u), true);
                    } else {
                        (bsdf_numbers[bsdf_draws], bsdf_slots[bsdf_draws]) = (u, k);
                        bsdf_draws += 1;
                    }
                    continue;
                }
                MisPick::Light(u) => u,
            };
            match at.lights.begin_sample(&at.receiver, u) {
                Draw::Environment(u) => environment.push(k, u),
                Draw::Made(toward) => {
                    if let Some(toward) = toward {
                        (lanes.direction[k], lanes.location[k]) =
                            (toward.direction, toward.map_location());
                        drawn[k] = true;
                    }
                }
                Draw::Rectangle(_) => unreachable!("no area light lights this scene"),
            }
        }
        environment.draw(at.lights, &at.receiver, |k, toward| {
            (lanes.direction[k], lanes.location[k]) = (toward.direction, toward.map_location());
            drawn[k] = true;
        });
        at.draw_bsdf_run(&bsdf_numbers[..bsdf_draws], |i, toward| {
            let k = bsdf_slots[i];
            if let Some(toward) = toward {
                (lanes.direction[k], lanes.specular[k]) = (toward.direction, toward.specular);
                drawn[k] = true;
            }
        });
        for (k, &drawn) in drawn[..numbers.len()].iter().enumerate() {
            lanes.kept[k] = drawn
                && (lanes.specular[k].is_some() || at.bsdf.in_support(at.wo, lanes.direction[k]));
        }
    }

    /// What candidate `k` of `lanes`, whose ray is free, brings (f·L/p, as the general runs
    /// weigh it: along a specular lobe, its mass over the probability of picking it).
    #[inline]
    fn brought(&self, run: &BatchRun, lanes: &Lanes, k: usize) -> Vec3 {
        let at = run.at;
        let direction = lanes.direction[k];
        let arriving = self.sky.toward(direction, lanes.location[k]);
        let (scattering, pdf) = match lanes.specular[k] {
            Some(mass) => (mass.weight, self.share * mass.probability as f64),
            None => {
                let parts = MisParts {
                    bsdf: at.bsdf.pdf(at.wo, direction),
                    light: self.choice * arriving.density,
                };
                (at.bsdf.eval(at.wo, direction), parts.mixed(self.share))
            }
        };
        if pdf <= 0.0 || arriving.radiance == Vec3::ZERO {
            return Vec3::ZERO;
        }
        scattering * arriving.radiance / pdf as f32
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
    use crate::lights::{EnvironmentPartition, GuideLayout};
    use crate::scene::load_scene;
    use crate::world::World;
    use ais::rng::Pcg32;
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
        World::from_description(load_scene(&dir.join("scene.xml"), &[]).unwrap()).unwrap()
    }

    /// Two guides of `partition`'s texels: the product alone, and mixed half and half.
    fn guides(partition: Arc<EnvironmentPartition>) -> [EnvironmentGuide; 2] {
        let mut guides = [1.0, 0.5].map(|fraction| {
            let mut guide = EnvironmentGuide::new(partition.clone());
            guide.set_affinities(|t| 0.01 + ((t * 5) % 7) as f32);
            guide.set_fraction(fraction);
            guide
        });
        guides[1].set_affinities(|t| (t % 3) as f32);
        guides
    }

    /// Compares the shortcut with the general runs at 400 gather points of `world` seen
    /// from above, lit and in shadow, for several MIS shares and batch sizes, unguided and
    /// with each of `guides`: their estimates, counts and spreads must be the same to the
    /// bit.
    fn compare_batches(world: &World, guides: &[EnvironmentGuide; 2]) {
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
                [None, Some(&guides[0]), Some(&guides[1])][(trial / 3) as usize % 3];
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
            };
            let shortcut = EnvironmentOnly::of(&run).expect("an environment-only scene");
            let numbers = batch.begin_plain(run.rays, run.seed).to_vec();
            let totals = [true, false].map(|short| {
                let mut spread = CandidateSpread::default();
                let mut counts = RayCounts::default();
                let mut total = PlainSum {
                    spread: Some(&mut spread),
                    ..PlainSum::default()
                };
                match short {
                    true => shortcut.run(&run, &numbers, &mut counts, &mut total),
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

    /// Under a rotated map, drawn from its own density and from a guide whose texels hold
    /// its cells.
    #[test]
    fn the_shortcut_is_the_general_batch_to_the_bit_under_a_map() {
        let emitter = r#"<emitter type="envmap"><string name="filename" value="sky.exr"/>
            <transform name="to_world"><rotate x="1" angle="90"/><rotate z="1" angle="30"/></transform></emitter>"#;
        let world = scene_under("environment-only-map", emitter);
        let Some(Environment::Map(map)) = &world.lights.environment else {
            unreachable!("the scene has a map")
        };
        compare_batches(&world, &guides(map.partition(GuideLayout::Octahedral(8))));
    }

    /// Under a constant sky, drawn uniformly and from a guide's uniform texels.
    #[test]
    fn the_shortcut_is_the_general_batch_to_the_bit_under_a_constant_sky() {
        let emitter =
            r#"<emitter type="constant"><rgb name="radiance" value="0.8, 0.9, 1"/></emitter>"#;
        let world = scene_under("environment-only-constant", emitter);
        compare_batches(&world, &guides(Arc::new(EnvironmentPartition::uniform(8))));
    }
}
