//! The multi-ray gather integrator: direct light at the first hit, gathered with `n` rays
//! through the AIS batch driver from a proposal strategy.
//!
//! - [`settings`]: the parameter table (from the scene's XML, overridden by flags);
//! - [`strategy`]: the proposal samplers (uniform, BSDF, light, MIS);
//! - [`acceptance`]: roulette's acceptance rules;
//! - [`batch_loop`]: one batch through the library's driver;
//! - [`learning_pass`]: maps learned around a tile before it renders (with the tile's
//!   recent gathers of [`ais::shared`], the sources of shared maps);
//! - [`guiding`]: a fixed map folded into the proposal;
//! - [`field`]: acceptance from the visibility field learned between passes (`ais auto`);
//! - [`field_guide`]: light sampling guided by that field;
//! - [`race`]: the field raced against AIS off on the image, to stand aside where it
//!   does not pay.

pub mod acceptance;
pub mod batch_loop;
pub mod field;
pub mod field_guide;
pub mod gather_sizes;
pub mod guiding;
pub mod learning_pass;
mod light;
pub mod mis_share;
pub mod pixel_pool;
mod plain_lanes;
pub mod race;
pub mod settings;
mod shared_origin;
pub mod strategy;

pub use acceptance::Acceptance;
pub use batch_loop::{run_batch, BatchProbe, BatchRun, Lessons};
pub use field::{field_has_use, field_passes, CostSample, FieldPass, GatherLearning};
pub use light::arriving_light;
pub use settings::{GatherSettings, MapSource, MapUse, Preset, RayBudget, Sharing, Update};
pub use strategy::{gather_point, GatherPoint, Strategy};

use crate::geometry::{Hit, Ray, RecentBlockers};
use crate::lights::Environment;
use crate::render::{RayCounts, Tile, TileState, TileStats};
use crate::world::World;
use ais::field::{CellIndex, CellKey, FieldObservations, VisibilityField};
use ais::rng::Pcg32;
use ais::shared::{blend_neighbours, NeighbourSource, RecentGathers};
use ais::{AffinityMap, Batch, MapStart};
use field_guide::FieldGuides;
use gather_sizes::{CandidateSpread, GatherSizes};
use glam::Vec3;
use guiding::{CandidateSampler, Guidance, Guide};
use learning_pass::LearningPass;
use mis_share::ShareMoments;
use pixel_pool::PixelPool;
use race::{RaceResult, TileMoments};
use std::cell::{Cell, RefCell};
use std::sync::Arc;

/// The radius of a gather's neighbourhood among the tile's recent gathers, in pixel
/// footprints at the gather point.
pub const RADIUS_PIXELS: f32 = 3.0;

/// What a render's gathers report: the batches' counters and the AIS memory a thread held.
#[derive(Clone, Copy, Debug, Default)]
pub struct GatherStats {
    /// Counts of the AIS batches.
    pub ais: ais::Stats,
    /// The most AIS state (maps, shared maps, guides) any one tile held, in bytes: what a
    /// thread needs on top of the scene.
    pub memory_per_thread: usize,
    /// The visibility field at the end of the render, in bytes (`map = field`).
    pub field_memory: usize,
    /// Gathers that used the field for roulette, and gathers where it stood aside.
    pub field_gathers: [u64; 2],
    /// Gathers whose light sampling the field guided.
    pub field_guided: u64,
    /// The cost ratio ρ (a candidate's work besides tracing, over tracing's) the field's
    /// acceptance used in the last pass.
    pub field_cost_ratio: f32,
    /// The race of the field against AIS off, where one was run (see [`race`]).
    pub field_race: Option<RaceResult>,
    /// Whether the field stood aside for the last pass (it gathered as AIS off).
    pub field_stood_aside: bool,
    /// The BSDF's share of MIS in the last pass, where `map = field` chose it: learned by
    /// its first passes below 64 candidates, [`mis_share::ROLLING_MIS_SHARE`] from 64 on
    /// (`None`: the default, [`strategy::MIS_BSDF_WEIGHT`]).
    pub mis_share: Option<f64>,
    /// The mean candidates per gather over the image's blocks, where the race chose them
    /// per block ([`gather_sizes`]; `None`: the settings' `rays` everywhere).
    pub gather_sizes: Option<f64>,
}

impl TileStats for GatherStats {
    fn merge(&mut self, other: GatherStats) {
        self.ais.merge(&other.ais);
        self.memory_per_thread = self.memory_per_thread.max(other.memory_per_thread);
        self.field_memory = self.field_memory.max(other.field_memory);
        for (mine, theirs) in self.field_gathers.iter_mut().zip(other.field_gathers) {
            *mine += theirs;
        }
        self.field_guided += other.field_guided;
        self.field_cost_ratio = self.field_cost_ratio.max(other.field_cost_ratio);
        self.field_race = self.field_race.or(other.field_race);
        self.field_stood_aside |= other.field_stood_aside;
        // Passes merge in order: the last pass's share stays.
        self.mis_share = other.mis_share.or(self.mis_share);
        self.gather_sizes = other.gather_sizes.or(self.gather_sizes);
    }
}

/// A tile's gather state: the reusable batch, the maps shared between its gathers, and a
/// probe watching the batches (`()` in the renderer).
#[derive(Default)]
pub struct GatherTile<P: BatchProbe = ()> {
    /// The batch driver (allocated on first use).
    pub(super) batch: Option<Batch<[f32; 3]>>,
    /// What blocked the shadow rays of the tile's last gather, passed on to the next.
    pub(super) blockers: Cell<RecentBlockers>,
    /// What the pixel's gathers leave to be done together: shadow rays and map lookups
    /// ([`PixelPool`]).
    pub(super) pixel_pool: RefCell<PixelPool>,
    /// The tile's recent gathers, for shared maps in tile order.
    recent: RecentGathers,
    /// The learning pass around this tile, for shared maps from a learning pass.
    learned: LearningPass,
    /// The guide distributions of `map_use = proposal` (allocated on first use).
    guide: Option<Guide>,
    /// The visibility field learned in earlier passes (`map = field`).
    pub(super) field: Arc<VisibilityField>,
    /// The rays this tile traced in this pass, for the field (`map = field`).
    pub(super) observations: Option<FieldObservations>,
    /// Gathers that used the field, and gathers where it stood aside.
    pub(super) field_gathers: [u64; 2],
    /// Gathers whose light sampling the field guided.
    pub(super) field_guided: u64,
    /// The environment guides of the field's cells this tile met (`map = field` guiding
    /// light sampling).
    pub(super) field_guides: Option<FieldGuides>,
    /// The last cell looked up in the field, and where it is: neighbouring pixels often
    /// share a cell.
    pub(super) last_cell: Option<(CellKey, Option<CellIndex>)>,
    /// The cost ratio the field's acceptance uses in this pass.
    pub(super) cost_ratio: f32,
    /// This pass's timings of sampled gathers, for the next pass's cost ratio.
    pub(super) cost: CostSample,
    /// Gathers run by this tile (to sample the timed ones).
    pub(super) gathers: u64,
    /// The pixel moments of a race pass (see [`race`]), raced or only measured for the
    /// candidates per block.
    pub(super) race: Option<TileMoments>,
    /// Whether this pass races the field against AIS off.
    races: bool,
    /// Whether the current pixel gathers as AIS off in a race pass.
    pub(super) racing_off: bool,
    /// Gathers that raced as AIS off in this pass.
    pub(super) raced_off: u64,
    /// Whether the race found that the field does not pay: every gather runs as AIS off.
    stands_aside: bool,
    /// The race's result, once run.
    race_result: Option<RaceResult>,
    /// What watches the batches.
    pub probe: P,
    /// The pass's second moments per MIS share, while the field learns with MIS.
    shares: Option<ShareMoments>,
    /// The BSDF's share of MIS in this pass, where the field learns it (`None`: the default).
    mis_share: Option<f64>,
    /// The settings' candidates per gather.
    settings_rays: u32,
    /// The candidates per gather per block, where the race chose them.
    sizes: Option<Arc<GatherSizes>>,
    /// The current pixel's candidates per gather.
    pub(super) rays: u32,
    /// The current gather's candidates as its estimate weighs them, in a race pass.
    pub(super) spread: Option<CandidateSpread>,
}

impl<P: BatchProbe> GatherTile<P> {
    /// The state for `tile`, watched by `probe`: runs the tile's learning pass if the
    /// settings share maps from one (its rays are counted in `counts`).
    pub fn begin(
        world: &World,
        settings: &GatherSettings,
        tile: &Tile,
        learning: &GatherLearning,
        counts: &mut RayCounts,
        probe: P,
    ) -> Self {
        let field = settings.map == MapSource::Field;
        // Where the field rolls, the race is timed: not with a pinned cost ratio, whose
        // images are reproducible.
        let rolls = field::field_rolls(settings);
        // Where the field rolls (64 candidates or more), a share that lowers the variance
        // per candidate also changes what roulette skips and what a candidate costs: there
        // a learned share lost in the rooms, and MIS takes `ROLLING_MIS_SHARE`.
        let has_use = field && field::field_has_use(world, settings);
        let mis = has_use && settings.strategy == Strategy::Mis;
        // A share given in the settings is kept.
        let learns_share = mis && !rolls && settings.mis_share.is_none();
        // Only where the field also guides light sampling, as the share was measured.
        let guided = field::field_can_guide(world, settings);
        let fixed_share = (mis && rolls && guided).then_some(mis_share::ROLLING_MIS_SHARE);
        let race_pass = tile.learns && race::RACE_PASSES.contains(&learning.passes_ended());
        let races = race_pass && field::races(world, settings);
        // The race passes measure the pixels for the candidates per block, raced or not.
        let measures = races || (race_pass && field::chooses_sizes(settings));
        let mut state = GatherTile {
            batch: None,
            blockers: Cell::default(),
            pixel_pool: RefCell::default(),
            recent: RecentGathers::default(),
            learned: LearningPass::default(),
            guide: None,
            field: learning.field.clone(),
            // What the last pass of a render observes would never be used.
            observations: (field && tile.learns).then(|| {
                FieldObservations::new(learning.field.side()).with_sources(learning.field.sources())
            }),
            field_gathers: [0; 2],
            field_guided: 0,
            field_guides: (field && settings.map_use.guides()).then(|| {
                let samples_lights = matches!(settings.strategy, Strategy::Light | Strategy::Mis);
                FieldGuides::new(
                    world,
                    learning.field.side(),
                    samples_lights,
                    settings.guide_share(),
                )
            }),
            last_cell: None,
            cost_ratio: learning.cost_ratio(),
            cost: CostSample::default(),
            gathers: 0,
            race: measures.then(|| TileMoments::new(tile.rect, races && rolls)),
            races,
            racing_off: false,
            raced_off: 0,
            stands_aside: learning.stands_aside(),
            race_result: learning.race_result(),
            probe,
            shares: (learns_share && tile.learns).then(ShareMoments::default),
            mis_share: settings.mis_share.map(f64::from).or_else(|| {
                learning
                    .mis_share()
                    .filter(|_| learns_share)
                    .or(fixed_share)
            }),
            settings_rays: settings.rays,
            sizes: learning.gather_sizes().cloned(),
            rays: settings.rays,
            spread: measures.then(CandidateSpread::default),
        };
        if let (true, Sharing::LearningPass { stride }) = (settings.shares_maps(), settings.sharing)
        {
            state
                .learned
                .learn(world, settings, stride as usize, tile, counts);
        }
        state
    }

    /// Bytes of AIS state held: the batch's map and observations, the shared maps of the
    /// tile's recent gathers or of its learning pass, and the guides.
    pub fn memory_bytes(&self) -> usize {
        self.batch.as_ref().map_or(0, Batch::memory_bytes)
            + self.recent.memory_bytes()
            + self.learned.memory_bytes()
            + self.guide.as_ref().map_or(0, Guide::memory_bytes)
            + self
                .observations
                .as_ref()
                .map_or(0, FieldObservations::memory_bytes)
            + self
                .field_guides
                .as_ref()
                .map_or(0, FieldGuides::memory_bytes)
    }

    /// The batches' counters so far.
    pub fn ais_stats(&self) -> ais::Stats {
        self.batch.as_ref().map(|b| *b.stats()).unwrap_or_default()
    }
}

impl<P: BatchProbe> TileState for GatherTile<P> {
    type Stats = GatherStats;

    /// Traced gather rays.
    fn work(&self) -> u64 {
        self.batch.as_ref().map_or(0, |b| b.stats().traced)
    }

    type Observed = Option<FieldPass>;

    fn take_observed(&mut self) -> Option<FieldPass> {
        let observations = self.observations.take()?;
        let gathers = self.field_gathers.iter().sum::<u64>();
        Some(FieldPass {
            observations,
            cost: std::mem::take(&mut self.cost),
            // Gathers racing as AIS off could not be guided.
            guided: [self.field_guided, gathers - self.raced_off],
            moments: self.race.take().map(|mut moments| {
                moments.end_pixel();
                moments
            }),
            shares: self.shares.take(),
        })
    }

    fn begin_pixel(&mut self, x: usize, y: usize) {
        self.rays = self
            .sizes
            .as_ref()
            .map_or(self.settings_rays, |sizes| sizes.at(x, y));
        self.racing_off = match self.race.as_mut() {
            Some(race) => {
                race.begin_pixel(x, y);
                self.races && race::races_off(x, y)
            }
            None => false,
        };
    }

    fn sampled(&mut self, value: [f32; 3]) {
        if let Some(race) = self.race.as_mut() {
            race.sampled(value);
        }
    }

    fn finish(self) -> GatherStats {
        GatherStats {
            ais: self.ais_stats(),
            memory_per_thread: self.memory_bytes(),
            field_memory: if self.field.cell_count() > 0 {
                self.field.memory_bytes()
            } else {
                0
            },
            field_gathers: self.field_gathers,
            field_guided: self.field_guided,
            field_cost_ratio: self.cost_ratio,
            field_race: self.race_result,
            field_stood_aside: self.stands_aside,
            mis_share: self.mis_share,
            gather_sizes: self.sizes.as_ref().map(|sizes| sizes.mean()),
        }
    }
}

/// Where a gather's neighbours' maps come from.
struct Neighbourhood<'a> {
    /// The tile's recent gathers.
    recent: &'a RecentGathers,
    /// The tile's learning pass.
    learned: &'a LearningPass,
    /// Which of the two to use.
    sharing: Sharing,
    /// The pixel footprint at the gather point, in world units.
    footprint: f32,
}

impl Neighbourhood<'_> {
    /// Sets `map` to the blend of the neighbours near `point` (shading normal `normal`);
    /// returns how many contributed.
    fn blend_into(&self, map: &mut AffinityMap, point: Vec3, normal: Vec3) -> usize {
        let recent = NeighbourSource {
            neighbours: self.recent.neighbours(),
            radius: RADIUS_PIXELS * self.footprint,
        };
        match self.sharing {
            Sharing::TileOrder => blend_neighbours(map, &[recent], point, normal),
            // The pass gives neighbours on all sides; the tile's earlier gathers add theirs.
            Sharing::LearningPass { stride } => {
                let learned = NeighbourSource {
                    neighbours: self.learned.neighbours(),
                    radius: stride as f32 * self.footprint,
                };
                blend_neighbours(map, &[recent, learned], point, normal)
            }
        }
    }
}

/// The candidate sampler of a gather at `at` whose fixed map is folded into the proposal:
/// light sampling through the environment's product with the map, or a mixture.
fn guided_sampler<'g>(
    guide: &'g mut Guide,
    map: &AffinityMap,
    settings: &GatherSettings,
    at: &mut GatherPoint<'g>,
) -> CandidateSampler<'g> {
    match guide.prepare(map, settings.strategy, at, settings.guide_share()) {
        Guidance::Unguided => CandidateSampler::plain(settings.strategy),
        Guidance::Environment(environment) => {
            at.receiver.environment_guide = Some(environment);
            CandidateSampler::plain(settings.strategy)
        }
        Guidance::Mixture(distribution) => {
            CandidateSampler::guided(settings.strategy, distribution, settings.guide_share())
        }
    }
}

/// The tile's batch driver, made on first use for `settings` (observing its rays when the
/// gathers share maps).
pub(super) fn batch_for<'b>(
    slot: &'b mut Option<Batch<[f32; 3]>>,
    settings: &GatherSettings,
) -> &'b mut Batch<[f32; 3]> {
    slot.get_or_insert_with(|| {
        let mut batch = Batch::new(settings.batch_config()).expect("valid gather configuration");
        batch.observe_rays(settings.shares_maps());
        batch
    })
}

/// The gather: emitted radiance at the first hit of `ray` plus `n` rays of direct light
/// through the AIS batch driver.
pub fn gather<P: BatchProbe>(
    world: &World,
    settings: &GatherSettings,
    ray: &Ray,
    rng: &mut Pcg32,
    state: &mut GatherTile<P>,
    counts: &mut RayCounts,
) -> Vec3 {
    let field = field::field_has_use(world, settings) && !state.stands_aside;
    let started =
        (field && field::times_next_gather(state, settings)).then(std::time::Instant::now);
    counts.closest_hit += 1;
    // The hit read where it was returned, not moved out of its option: a move copied it
    // whole before its fields were all written, and the copy waited for the writes.
    let found = world.geometry.intersect(ray);
    let Some(hit) = &found else {
        if settings.hide_emitters {
            return Vec3::ZERO;
        }
        return world.lights.background(ray.direction);
    };
    let emitted = if settings.hide_emitters {
        Vec3::ZERO
    } else {
        world
            .lights
            .emitted(hit.shape, hit.geometric_normal, ray.direction, hit.uv)
    };
    if world.lights.is_empty() {
        return emitted;
    }
    let mis_bsdf_share = state.mis_share.unwrap_or(strategy::MIS_BSDF_WEIGHT);
    let footprint = world.camera.footprint(hit.t, world.resolution.0);
    let seed = ((rng.next_u32() as u64) << 32) | rng.next_u32() as u64;
    if field {
        let mut at = gather_point(world, hit, -ray.direction);
        at.mis_bsdf_share = mis_bsdf_share;
        let mut site = field::FieldSite::new(hit, at, footprint, settings.field_cell, seed);
        site.started = started;
        return emitted + field::field_gather(world, settings, site, state, counts);
    }
    let site = MapSite {
        hit,
        wo: -ray.direction,
        mis_bsdf_share,
        footprint,
        seed,
    };
    emitted + map_gather(world, settings, &site, state, counts)
}

/// The values of a pixel's camera `rays` (its samples, in order), pushed onto `values`:
/// [`gather`] of each, with the shadow rays and environment-map lookups of AIS off's plain
/// batches pooled across them and made together ([`PixelPool`]).
pub fn gather_samples<P: BatchProbe>(
    world: &World,
    settings: &GatherSettings,
    rays: &[Ray],
    rng: &mut Pcg32,
    state: &mut GatherTile<P>,
    counts: &mut RayCounts,
    values: &mut Vec<[f32; 3]>,
) {
    let map = match &world.lights.environment {
        Some(Environment::Map(map)) => Some(&**map),
        _ => None,
    };
    // A pool per group of samples, so that it stays small whatever the samples per pixel.
    for rays in rays.chunks(POOLED_SAMPLES) {
        let first = values.len();
        state.pixel_pool.get_mut().open();
        for (sample, ray) in rays.iter().enumerate() {
            state.pixel_pool.get_mut().begin_sample(sample as u32);
            values.push(gather(world, settings, ray, rng, state, counts).to_array());
        }
        let pool = state.pixel_pool.get_mut();
        pool.resolve(&world.geometry, map, &mut values[first..]);
    }
}

/// How many of a pixel's samples share a pool: about a thousand candidates at 16 per
/// gather (some 120 KiB), enough to sort by direction and to fill the lookups' lanes.
const POOLED_SAMPLES: usize = 64;

/// Whether a gather of `state`'s may leave its shadow rays and map lookups in the pixel's pool:
/// while the pool is open, unless something reads the gather's candidates one by one (their
/// spread, a race's moments, or a probe).
fn pools<P: BatchProbe>(state: &GatherTile<P>) -> bool {
    state.pixel_pool.borrow().is_open()
        && state.spread.is_none()
        && state.race.is_none()
        && !P::WATCHES
}

/// Hands the variance of the gather just run, from its candidates' `spread`, to the pixel
/// moments of a race pass (`race`), where both are kept.
pub(super) fn note_gather_variance(
    race: &mut Option<TileMoments>,
    spread: &mut Option<CandidateSpread>,
) {
    if let (Some(race), Some(spread)) = (race.as_mut(), spread.as_mut()) {
        race.gathered(spread.take_variance());
    }
}

/// Where a gather with the batch's own map (or none) happens. (The gather point is made
/// where it is used, from the hit, `wo` and the share: some thousand bytes, it was copied
/// into the gather's call, and the copy waited for the writes of its fields.)
struct MapSite<'a> {
    /// The first hit.
    hit: &'a Hit,
    /// The direction toward the viewer.
    wo: Vec3,
    /// The BSDF's share of the MIS mixture.
    mis_bsdf_share: f64,
    /// The pixel footprint there.
    footprint: f32,
    /// The batch's scrambling seed.
    seed: u64,
}

/// A gather whose batch starts from an empty map, from its neighbours' maps (shared maps),
/// or has none (AIS off).
fn map_gather<P: BatchProbe>(
    world: &World,
    settings: &GatherSettings,
    site: &MapSite,
    state: &mut GatherTile<P>,
    counts: &mut RayCounts,
) -> Vec3 {
    let mut at = gather_point(world, site.hit, site.wo);
    at.mis_bsdf_share = site.mis_bsdf_share;
    let sharing = settings.shares_maps();
    let pools = pools(state);
    let batch = batch_for(&mut state.batch, settings);
    let mut sampler = CandidateSampler::plain(settings.strategy);
    let start = if sharing {
        let map = batch.map_mut().expect("shared maps have a map");
        let neighbourhood = Neighbourhood {
            recent: &state.recent,
            learned: &state.learned,
            sharing: settings.sharing,
            footprint: site.footprint,
        };
        let found = neighbourhood.blend_into(map, site.hit.point, at.frame.normal);
        if settings.map_use.guides() && found > 0 {
            let guide = state
                .guide
                .get_or_insert_with(|| Guide::new(settings.map_height));
            sampler = guided_sampler(guide, map, settings, &mut at);
        }
        MapStart::Current
    } else {
        MapStart::Empty
    };
    let run = BatchRun {
        world,
        settings,
        at: &at,
        sampler: &sampler,
        seed: site.seed,
        rays: state.rays,
        start,
        field: None,
        clock: None,
        blockers: &state.blockers,
        pixel_pool: pools.then_some(&state.pixel_pool),
    };
    let lessons = Lessons {
        spread: state.spread.as_mut(),
        ..Lessons::default()
    };
    let value = run_batch(&run, batch, counts, &mut state.probe, lessons);
    note_gather_variance(&mut state.race, &mut state.spread);
    if sharing {
        let observations = batch
            .observations()
            .expect("shared maps observe their rays");
        state
            .recent
            .remember(site.hit.point, at.frame.normal, observations);
    }
    value
}
