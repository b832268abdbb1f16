//! The multi-ray gather integrator: direct light at the first hit, gathered with `n` rays
//! through the AIS batch driver from a proposal strategy.

use crate::ais_timer::AisTimer;
use crate::bsdf::ShadingFrame;
use crate::geometry::Hit;
use crate::geometry::{spawn_ray, Ray};
use crate::guiding::{Guidance, Guide, Proposal};
use crate::integrator::{RayCounts, SampleContext};
use crate::lights::luminance;
use crate::proposal::{GatherPoint, Strategy};
use crate::shared_maps::{blend_neighbours, RADIUS_PIXELS};
use crate::world::World;
use ais::rng::Pcg32;
use ais::{rating, Batch, BatchConfig, Decision, MapConfig, MapStart, Mode, Stopping};
use glam::Vec3;

/// AIS setting of the gather.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AisMode {
    /// No affinity map: every in-support candidate is traced.
    Off,
    /// The talk's aggressive map.
    Aggressive,
    /// The talk's conservative map (shadow-edge resets).
    Conservative,
    /// Shared maps: each batch starts from a fixed map blended from the batches at
    /// neighbouring gather points before it (see [`crate::shared_maps`]).
    Shared,
    /// Shared maps as a warm start: each batch starts from the blended map of
    /// [`AisMode::Shared`], then keeps learning from its own rays in frozen-map epochs
    /// (exactly unbiased: the map changes only between epochs).
    Warm,
    /// Guided gathers: the shared mode's fixed map folded into the proposal (a mixture with
    /// a piecewise-constant density over its texels) rather than used for roulette: nothing
    /// is rejected (see [`crate::guiding`]).
    Guided,
    /// Not a technique but a bound for studies: the same proposal restricted to the
    /// directions that bring light, found by tracing every candidate for free
    /// (see [`crate::oracle`]).
    Oracle,
}

impl AisMode {
    /// Parses a command-line or XML name.
    pub fn parse(name: &str) -> Option<AisMode> {
        match name {
            "off" => Some(AisMode::Off),
            "aggressive" => Some(AisMode::Aggressive),
            "conservative" => Some(AisMode::Conservative),
            "oracle" => Some(AisMode::Oracle),
            "shared" => Some(AisMode::Shared),
            "guided" => Some(AisMode::Guided),
            "warm" => Some(AisMode::Warm),
            _ => None,
        }
    }
}

/// Settings of the multi-ray gather integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherSettings {
    /// The proposal sampler.
    pub strategy: Strategy,
    /// AIS off, aggressive or conservative.
    pub ais: AisMode,
    /// Rays per gather (n).
    pub rays: u32,
    /// The map's tol (a_min = 1 / (tol h²)).
    pub tol: f32,
    /// The map's height in texels.
    pub map_height: u32,
    /// Halton (the talk's) or independent random candidates.
    pub placement: ais::Placement,
    /// How a candidate's acceptance probability follows from the map.
    pub acceptance: Acceptance,
    /// Guided gathers: the guide's share α of the proposal mixture `(1 − α) p + α g`.
    pub guide_fraction: f32,
    /// What `rays` counts: traced rays (AIS draws extra candidates to trace about `rays`)
    /// or candidates (AIS traces fewer and the gather gets cheaper).
    pub budget: RayBudget,
    /// Where shared, warm and guided gathers find their neighbours' maps.
    pub sharing: Sharing,
}

/// Where the modes that share maps ([`GatherSettings::shares_maps`]) take the maps of
/// neighbouring gather points from. Both keep the image independent of threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sharing {
    /// The gathers before it in its tile, in the tile's fixed pixel order (see
    /// [`crate::shared_maps`]): free, but one-sided, and a tile's first gathers have none.
    TileOrder,
    /// A learning pass: AIS-off gathers at the centres of `stride × stride` pixel blocks
    /// over the tile and one block around it, run before the tile (see
    /// [`crate::learning_pass`]): neighbours on every side, for extra gathers.
    LearningPass {
        /// Block edge in pixels (1 to [`crate::render::TILE_SIZE`]).
        stride: u32,
    },
}

/// The learning pass's default block edge, in pixels.
pub const LEARNING_STRIDE: u32 = 4;

impl Sharing {
    /// Parses "tile", "pass" (blocks of [`LEARNING_STRIDE`]) or "pass:S" (blocks of S
    /// pixels).
    pub fn parse(name: &str) -> Option<Sharing> {
        match name.split_once(':') {
            None if name == "tile" => Some(Sharing::TileOrder),
            None if name == "pass" => Some(Sharing::LearningPass {
                stride: LEARNING_STRIDE,
            }),
            Some(("pass", stride)) => stride
                .parse()
                .ok()
                .filter(|s| (1..=crate::render::TILE_SIZE as u32).contains(s))
                .map(|stride| Sharing::LearningPass { stride }),
            _ => None,
        }
    }
}

/// What a gather's `rays` counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayBudget {
    /// About `rays` traced rays per gather: every epoch draws ⌈n_e / acceptance rate⌉
    /// candidates ([`ais::Stopping::CandidateBudget`]). The talk's reading: AIS buys more
    /// candidates with the same rays.
    Traced,
    /// Exactly `rays` candidates per gather, of which AIS traces only the accepted
    /// ([`ais::Stopping::FixedCandidates`]): AIS makes each gather cheaper.
    Candidates,
}

impl RayBudget {
    /// Parses "traced" or "candidates".
    pub fn parse(name: &str) -> Option<RayBudget> {
        match name {
            "traced" => Some(RayBudget::Traced),
            "candidates" => Some(RayBudget::Candidates),
            _ => None,
        }
    }
}

/// How a candidate's acceptance probability follows from the map's affinity `q` and, for
/// the value-aware rules, the candidate's unoccluded contribution `v` (luminance of
/// f·L/p with nothing in the way, known before tracing) and the mean `v̄` of the batch's
/// earlier candidates. Every rule is exactly unbiased (the traced ray weighs 1/acceptance).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Acceptance {
    /// The talk's: `q`.
    Affinity,
    /// `√q`: efficiency-optimised roulette when the candidate's value is not known (and so
    /// costs nothing to decide). A rejected candidate still costs a proposal sample, so
    /// rejecting in proportion to `q` draws too many of them; `√q` balances the two costs.
    SqrtAffinity,
    /// `1` when `v > 2 v̄` (never skip a bright candidate), else `q`.
    ValueThreshold,
    /// Efficiency-optimised Russian roulette: `clamp(√q · v / v̄, 10⁻³, 1)`, the
    /// variance-per-cost optimum for a candidate worth `v` with probability `q`.
    ValueEfficient,
}

/// [`Acceptance::ValueThreshold`] traces every candidate brighter than this many times the
/// mean unoccluded contribution of the batch's earlier candidates.
pub const VALUE_THRESHOLD: f32 = 2.0;

impl Acceptance {
    /// Parses a rule's name: "affinity" (or "", as after a mode name without a suffix),
    /// "sqrt", "value" or "efficient".
    pub fn parse(name: &str) -> Option<Acceptance> {
        match name {
            "" | "affinity" => Some(Acceptance::Affinity),
            "value" => Some(Acceptance::ValueThreshold),
            "efficient" => Some(Acceptance::ValueEfficient),
            "sqrt" => Some(Acceptance::SqrtAffinity),
            _ => None,
        }
    }

    /// Whether the rule needs the candidate's unoccluded value (and so its density, the
    /// BSDF and the lights) before deciding.
    pub fn needs_value(self) -> bool {
        matches!(
            self,
            Acceptance::ValueThreshold | Acceptance::ValueEfficient
        )
    }

    /// The acceptance probability for affinity `q`, value `v` and earlier mean `mean`
    /// (`v` and `mean` matter only to the rules that [`Acceptance::needs_value`]).
    fn probability(self, q: f32, v: f32, mean: Option<f32>) -> f32 {
        match (self, mean) {
            (Acceptance::Affinity, _) => q,
            (Acceptance::SqrtAffinity, _) => q.sqrt(),
            // The first candidate has no mean to compare with: trace it.
            (_, None) => 1.0,
            (Acceptance::ValueThreshold, Some(mean)) => {
                if v > VALUE_THRESHOLD * mean {
                    1.0
                } else {
                    q
                }
            }
            (Acceptance::ValueEfficient, Some(mean)) => {
                if mean > 0.0 {
                    (q.sqrt() * v / mean).clamp(1e-3, 1.0)
                } else {
                    1.0
                }
            }
        }
    }
}

impl Default for GatherSettings {
    fn default() -> Self {
        let map = MapConfig::default();
        GatherSettings {
            strategy: Strategy::Mis,
            // Measured: per-batch AIS with Halton placement loses to AIS off in every room
            // and scene tried so far (BENCHMARKS.md), so the renderer starts with it off.
            ais: AisMode::Off,
            rays: 16,
            tol: map.tol,
            map_height: map.height,
            placement: ais::Placement::Halton,
            acceptance: Acceptance::Affinity,
            guide_fraction: crate::guiding::GUIDE_FRACTION,
            // Measured (BENCHMARKS.md §7): with AIS off, exactly n candidates in one Halton
            // set beat the traced budget's 4 separately scrambled epochs by 1.27-1.57× at
            // equal time on every scene, and shared maps gain only with this budget.
            budget: RayBudget::Candidates,
            sharing: Sharing::TileOrder,
        }
    }
}

impl GatherSettings {
    /// Whether each gather starts from maps learned at neighbouring gather points (shared,
    /// warm and guided).
    pub fn shares_maps(&self) -> bool {
        matches!(self.ais, AisMode::Shared | AisMode::Warm | AisMode::Guided)
    }

    /// The batch configuration. Every mode uses the candidate-budget stopping rule, which is
    /// exactly unbiased with Halton placement even when candidates fall outside the support.
    pub fn batch_config(&self) -> BatchConfig {
        let base = BatchConfig {
            stopping: match self.budget {
                RayBudget::Traced => Stopping::CandidateBudget,
                RayBudget::Candidates => Stopping::FixedCandidates,
            },
            placement: self.placement,
            ..BatchConfig::default()
        };
        match self.ais {
            AisMode::Off | AisMode::Oracle => BatchConfig {
                affinity: None,
                learning: ais::Learning::Off,
                ..base
            },
            AisMode::Shared | AisMode::Guided | AisMode::Warm => BatchConfig {
                affinity: Some(MapConfig {
                    height: self.map_height,
                    tol: self.tol,
                    ..MapConfig::default()
                }),
                // Shared and guided hold the blended map fixed (exactly unbiased); warm
                // keeps learning from it in frozen-map epochs.
                learning: if self.ais == AisMode::Warm {
                    ais::Learning::Epochs { epochs: 4 }
                } else {
                    ais::Learning::Off
                },
                ..base
            },
            AisMode::Aggressive | AisMode::Conservative => BatchConfig {
                affinity: Some(MapConfig {
                    height: self.map_height,
                    tol: self.tol,
                    mode: if self.ais == AisMode::Aggressive {
                        Mode::Aggressive
                    } else {
                        Mode::Conservative
                    },
                    ..MapConfig::default()
                }),
                ..base
            },
        }
    }
}

/// The ray leaving the gather point toward `direction`, what it would bring if nothing
/// blocked it, and how far it must be free (infinite toward the environment).
fn leaving(world: &World, at: &GatherPoint, direction: Vec3) -> (Ray, Vec3, f32) {
    let ray = spawn_ray(at.point, at.frame.geometric, direction);
    let (unoccluded, distance) = world.lights.unoccluded(&ray);
    (ray, unoccluded, distance)
}

/// What the `leaving` ray actually brings: its unoccluded radiance, or zero if blocked. Only
/// rays that could bring light are traced (and counted).
fn trace_leaving(
    world: &World,
    (mut ray, unoccluded, distance): (Ray, Vec3, f32),
    counts: &mut RayCounts,
) -> Vec3 {
    // A ray whose unoccluded radiance is zero brings zero whatever blocks it.
    if unoccluded == Vec3::ZERO {
        return Vec3::ZERO;
    }
    // The emitter's own surface is in the BVH: stop just short of it.
    ray.t_max = distance * (1.0 - 1e-4);
    counts.occlusion += 1;
    if world.geometry.occluded(&ray) {
        Vec3::ZERO
    } else {
        unoccluded
    }
}

/// Radiance arriving at the gather point from `direction`: (actual, unoccluded).
pub(crate) fn light_along(
    world: &World,
    at: &GatherPoint,
    direction: Vec3,
    counts: &mut RayCounts,
) -> (Vec3, Vec3) {
    let ray = leaving(world, at, direction);
    let unoccluded = ray.1;
    (trace_leaving(world, ray, counts), unoccluded)
}

/// The gather point where `hit` is seen from direction `wo` (pointing away from it).
pub fn gather_point<'a>(world: &'a World, hit: &Hit, wo: Vec3) -> GatherPoint<'a> {
    let material = &world.materials[hit.shape as usize];
    GatherPoint {
        point: hit.point,
        frame: ShadingFrame::new(material, hit.shading_normal, hit.geometric_normal, wo),
        wo,
        material,
        lights: &world.lights,
        environment_guide: None,
    }
}

/// The gather: emitted radiance at the first hit plus `n` rays of direct light through the
/// AIS batch driver.
pub fn gather(
    world: &World,
    settings: &GatherSettings,
    ray: &Ray,
    rng: &mut Pcg32,
    context: &mut SampleContext,
) -> Vec3 {
    context.counts.closest_hit += 1;
    let Some(hit) = world.geometry.intersect(ray) else {
        return world.lights.background(ray.direction);
    };
    let emitted = world
        .lights
        .emitted(hit.shape, hit.geometric_normal, ray.direction);
    if world.lights.is_empty() {
        return emitted;
    }
    let mut at = gather_point(world, &hit, -ray.direction);
    if settings.ais == AisMode::Oracle {
        return emitted
            + crate::oracle::gather_with_oracle(world, settings, &at, rng, &mut context.counts);
    }
    let SampleContext {
        counts,
        batch,
        ais_timer,
        shared,
        learned,
        guide,
    } = context;
    let sharing = settings.shares_maps();
    let batch = batch.get_or_insert_with(|| {
        let mut batch = Batch::new(settings.batch_config()).expect("valid gather configuration");
        batch.observe_rays(sharing);
        batch
    });
    let seed = ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64;
    let mut proposal = Proposal::plain(settings.strategy);
    let start = if sharing {
        let footprint = hit.t * world.camera.pixel_angle(world.resolution.0);
        let map = batch.map_mut().expect("shared mode has a map");
        let (point, normal) = (hit.point, at.frame.normal);
        let tile_order = (shared.neighbours(), RADIUS_PIXELS * footprint);
        let neighbours = match settings.sharing {
            Sharing::TileOrder => blend_neighbours(map, &[tile_order], point, normal),
            // The pass gives neighbours on all sides; the tile's earlier gathers add theirs.
            Sharing::LearningPass { stride } => blend_neighbours(
                map,
                &[
                    tile_order,
                    (learned.neighbours(), stride as f32 * footprint),
                ],
                point,
                normal,
            ),
        };
        if settings.ais == AisMode::Guided && neighbours > 0 {
            let guide = guide.get_or_insert_with(|| Guide::new(settings.map_height));
            match guide.prepare(map, settings.strategy, &at, settings.guide_fraction) {
                Guidance::Unguided => {}
                Guidance::Environment(environment) => at.environment_guide = Some(environment),
                Guidance::Mixture(distribution) => {
                    proposal =
                        Proposal::guided(settings.strategy, distribution, settings.guide_fraction)
                }
            }
        }
        MapStart::Current
    } else {
        MapStart::Empty
    };
    let value = run_batch(
        world,
        settings,
        &at,
        (batch, &proposal),
        (seed, start),
        counts,
        ais_timer,
        &mut |_| {},
    );
    if sharing {
        let observations = batch.observations().expect("shared mode observes its rays");
        shared.remember(hit.point, at.frame.normal, observations);
    }
    emitted + value
}

/// One batch of `settings.rays` rays at `at` through `batch` (configured for `settings`,
/// or a variant of it) with candidates from `proposal`, begun with scrambling seed and map start `(seed, start)`; `observe`
/// sees the batch after every traced candidate.
#[allow(clippy::too_many_arguments)]
pub fn run_batch(
    world: &World,
    settings: &GatherSettings,
    at: &GatherPoint,
    (batch, proposal): (&mut Batch<[f32; 3]>, &Proposal),
    (seed, start): (u64, MapStart),
    counts: &mut RayCounts,
    timer: &mut AisTimer,
    observe: &mut dyn FnMut(&Batch<[f32; 3]>),
) -> Vec3 {
    let (frame, wo, material) = (&at.frame, at.wo, at.material);
    timer.start_gather();
    batch.begin(settings.rays, seed, start);
    // Value-aware acceptance: the running mean of earlier candidates' contributions.
    let (mut value_sum, mut value_count) = (0.0f32, 0u32);
    while let Some(candidate) = batch.next_candidate() {
        let Some(direction) = proposal.sample_direction(at, candidate.u) else {
            timer.decided(frame.normal, false);
            batch.decide(frame.normal, false);
            continue;
        };
        let in_support = material.in_support(frame, wo, direction);
        timer.decided(direction, in_support);
        // Value-aware rules need the density and the unoccluded radiance before deciding;
        // the others ask for them only for traced candidates.
        let mut known = None;
        let decision = if settings.acceptance.needs_value() && in_support {
            // What the candidate would bring if nothing blocked it is known before tracing.
            let density = proposal.pdf(at, direction);
            let ray = leaving(world, at, direction);
            let value = if density > 0.0 {
                luminance(material.eval(frame, wo, direction) * ray.1) / density as f32
            } else {
                0.0
            };
            known = Some((density, ray));
            let mean = (value_count > 0).then(|| value_sum / value_count as f32);
            value_sum += value;
            value_count += 1;
            batch.decide_with(direction, in_support, |affinity| {
                settings.acceptance.probability(affinity, value, mean)
            })
        } else if settings.ais == AisMode::Guided {
            // The map is already in the proposal: trace every candidate.
            batch.decide_with(direction, in_support, |_| 1.0)
        } else {
            batch.decide_with(direction, in_support, |affinity| {
                settings.acceptance.probability(affinity, 0.0, None)
            })
        };
        if let Decision::Trace { .. } = decision {
            let (pdf, ray) = known
                .unwrap_or_else(|| (proposal.pdf(at, direction), leaving(world, at, direction)));
            let unoccluded = ray.1;
            // A zero density, possible only at a light's rim in f32, brings nothing.
            let (value, rating) = if pdf > 0.0 {
                let actual = trace_leaving(world, ray, counts);
                let value = material.eval(frame, wo, direction) * actual / pdf as f32;
                (value, rating(luminance(actual), luminance(unoccluded)))
            } else {
                (Vec3::ZERO, rating(0.0, 0.0))
            };
            timer.recorded(value.to_array(), rating);
            batch.record(value.to_array(), rating);
            observe(batch);
        }
    }
    let estimate = batch.finish();
    timer.end_gather(batch.config(), settings.rays, seed);
    Vec3::from(estimate.value)
}
