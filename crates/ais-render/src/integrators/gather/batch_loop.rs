//! One batch of a gather: candidates from the proposal, decided by the library's batch
//! driver, traced and recorded. The host loop of the `ais` library, written for this
//! renderer.

use super::gather_sizes::CandidateSpread;
use super::guiding::CandidateSampler;
use super::light::{free_radiance, radiance_if_free, trace_aimed, Leaving, ShadowRay};
use super::mis_share::ShareMoments;
use super::pixel_pool::PixelPool;
use super::plain_lanes::PlainLanes;
use super::settings::GatherSettings;
use super::shared_origin::SharedOrigin;
use super::strategy::{CandidateDraw, GatherPoint, MisParts};
use crate::geometry::RecentBlockers;
use crate::lights::{luminance, AreaDraws, EnvironmentDraws, Toward};
use crate::render::RayCounts;
use crate::world::World;
use ais::field::{CellRecorder, FieldCell};
use ais::{rating, Batch, BatchConfig, Decision, MapStart, PlainTally, Value};
use glam::Vec3;
use std::cell::{Cell, RefCell};
use std::time::{Duration, Instant};

/// Watches the calls a batch makes into the library, for studies (timing them, taking
/// snapshots of the map). The renderer itself uses `()`, which watches nothing and costs
/// nothing.
pub trait BatchProbe {
    /// Whether it watches anything: a probe that does sees every candidate decided, traced
    /// and recorded one at a time; without one, candidates may be decided ahead and traced
    /// together.
    const WATCHES: bool = true;
    /// A batch begins.
    fn started(&mut self) {}
    /// A candidate toward `direction` was decided (`in_support`: inside the BSDF's support).
    fn decided(&mut self, _direction: Vec3, _in_support: bool) {}
    /// The last decided candidate was traced and recorded `value` and `rating` in `batch`.
    fn recorded(&mut self, _batch: &Batch<[f32; 3]>, _value: [f32; 3], _rating: f32) {}
    /// The batch (configured as `config`, begun with `rays` and `seed`) finished.
    fn finished(&mut self, _config: &BatchConfig, _rays: u32, _seed: u64) {}
}

impl BatchProbe for () {
    const WATCHES: bool = false;
}

/// What one batch runs on.
pub struct BatchRun<'a> {
    /// The scene.
    pub world: &'a World,
    /// The gather's settings (acceptance, how the map is used).
    pub settings: &'a GatherSettings,
    /// Its candidates (the settings' `rays`, or fewer where [`GatherSizes`] says so).
    ///
    /// [`GatherSizes`]: super::gather_sizes::GatherSizes
    pub rays: u32,
    /// Where the gather happens.
    pub at: &'a GatherPoint<'a>,
    /// Where candidates come from.
    pub sampler: &'a CandidateSampler<'a>,
    /// The batch's scrambling seed.
    pub seed: u64,
    /// Whether the batch keeps the map it holds or starts from an empty one.
    pub start: MapStart,
    /// The learned field's cell, when it gives the acceptance (`map = field`).
    pub field: Option<FieldUse<'a>>,
    /// When given, the time spent on accepted candidates is added to it.
    pub clock: Option<&'a Cell<Duration>>,
    /// What blocked the shadow rays of the tile's gather before this one, which it passed
    /// on ([`RecentBlockers::passed_on`]); this batch passes on its own.
    pub blockers: &'a Cell<RecentBlockers>,
    /// Where a plain batch leaves its shadow rays and environment-map lookups for the
    /// pixel's gathers to make together ([`PixelPool`]); `None`: it makes them itself.
    pub pixel_pool: Option<&'a RefCell<PixelPool>>,
}

impl BatchRun<'_> {
    /// The batch's shadow rays, starting from the blockers passed on to it.
    pub(super) fn shared_origin(&self) -> SharedOrigin {
        SharedOrigin::after(self.blockers.get())
    }

    /// Passes on what `origin`, the batch's shadow rays, met to the tile's next gather.
    pub(super) fn pass_on(&self, origin: &SharedOrigin) {
        self.blockers.set(origin.blockers.passed_on());
    }
}

/// The field's cell for one gather, and the cost ratio its acceptance uses.
#[derive(Clone, Copy, Debug)]
pub struct FieldUse<'a> {
    /// The gather's cell.
    pub cell: FieldCell<'a>,
    /// ρ: what every candidate costs over what an accepted one adds.
    pub cost_ratio: f32,
}

/// What a batch's traced rays teach later passes: the field's cell, the moments that
/// choose MIS's BSDF share, and the spread of the candidates that tells the gather's
/// variance (all `None`: nothing is recorded).
#[derive(Default)]
pub struct Lessons<'l, 'c> {
    /// The gather's cell in the pass's field observations.
    pub cell: Option<&'l mut CellRecorder<'c>>,
    /// The pass's second moments per MIS share (the host ends each gather in them).
    pub shares: Option<&'l mut ShareMoments>,
    /// The gather's candidates as its estimate weighs them.
    pub spread: Option<&'l mut CandidateSpread>,
}

/// The running mean of earlier candidates' unoccluded values (value-aware acceptance).
#[derive(Default)]
struct RunningMean {
    sum: f32,
    count: u32,
}

impl RunningMean {
    /// The mean so far (None before the first value), then adds `value`.
    fn mean_then_add(&mut self, value: f32) -> Option<f32> {
        let mean = (self.count > 0).then(|| self.sum / self.count as f32);
        self.sum += value;
        self.count += 1;
        mean
    }
}

/// Runs one batch of `run.rays` rays through `batch` (configured for those
/// settings, or a variant of them) and returns its estimate of the reflected direct light.
/// Every traced ray that could bring light is recorded in `lessons`.
pub fn run_batch<P: BatchProbe>(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    counts: &mut RayCounts,
    probe: &mut P,
    mut lessons: Lessons,
) -> Vec3 {
    probe.started();
    // Without a map or observations, nothing reads what a traced ray saw but its value and
    // (for a recorder) whether it was free: a blocked ray can skip the lookups its value
    // would need.
    let value_only = batch.map().is_none() && batch.observations().is_none();
    // Candidates can be traced together when no decision waits on an earlier outcome or
    // value, and nothing watches or times them one by one.
    let values_unneeded = run.field.is_some() || !run.settings.acceptance.needs_value();
    let unwatched = !P::WATCHES && run.clock.is_none();
    let ahead = value_only && values_unneeded && unwatched && batch.decides_ahead();
    // AIS off with nothing to learn from single rays: no decision to ask the driver for.
    let plain = ahead
        && batch.is_plain()
        && run.field.is_none()
        && lessons.cell.is_none()
        && lessons.shares.is_none();
    let estimate = if plain {
        // A plain batch begins with its own numbers ([`Batch::begin_plain`]): `begin`'s
        // scramble of an epoch would be thrown away.
        run_plain(run, batch, counts, lessons.spread.as_deref_mut())
    } else {
        batch.begin(run.rays, run.seed, run.start);
        if ahead {
            run_ahead(run, batch, counts, &mut lessons);
        } else {
            run_one_by_one(run, batch, counts, probe, &mut lessons);
        }
        batch.finish()
    };
    if let Some(spread) = lessons.spread {
        spread.end_gather(estimate.candidates);
    }
    probe.finished(batch.config(), run.rays, run.seed);
    Vec3::from(estimate.value)
}

/// Candidates drawn and decided before their shadow rays are traced together, so that the
/// lookups of one (the environment's tables, the BSDF) overlap those of the next instead of
/// waiting behind a traversal.
const AHEAD: usize = 16;

/// The batch in runs of [`AHEAD`] candidates: draw and decide them, trace their rays, then
/// look up what the free ones bring and record them in the order decided (the same
/// estimate, to the bit, as [`run_one_by_one`]).
fn run_ahead(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    counts: &mut RayCounts,
    lessons: &mut Lessons,
) {
    let mut drawn = [None; AHEAD];
    let mut weights = [1.0; AHEAD];
    let mut arriving = [ShadowRay::Unneeded; AHEAD];
    let mut origin = run.shared_origin();
    loop {
        let count = draw_ahead(run, batch, &mut drawn, &mut weights);
        if count == 0 {
            run.pass_on(&origin);
            return;
        }
        let shadow_rays = ShadowRays {
            counts,
            origin: &mut origin,
        };
        trace_run(run, &mut drawn[..count], &mut arriving, shadow_rays);
        let traced = drawn[..count].iter_mut().flatten().zip(&arriving);
        for ((toward, &arriving), &weight) in traced.zip(&weights) {
            let traced = value_of(run, toward, arriving);
            record(run, batch, lessons, toward, &traced, weight);
        }
    }
}

/// Where a gather's shadow rays are counted, and what they learn from one another.
struct ShadowRays<'a> {
    counts: &'a mut RayCounts,
    origin: &'a mut SharedOrigin,
}

/// Finds what the drawn candidates of a run meet among the lights, together (`drawn`; empty
/// slots are passed over), traces their shadow rays, then looks up what the free ones bring
/// into `arriving` (from its start, in the order of the filled slots): all the lookups
/// after all the rays, so that they overlap.
fn trace_run(
    run: &BatchRun,
    drawn: &mut [Option<Toward>],
    arriving: &mut [ShadowRay; AHEAD],
    rays: ShadowRays,
) {
    run.world.lights.resolve_run(&run.at.receiver, drawn);
    rays.origin.expect_run(run.world, drawn);
    let mut blocked = [None; AHEAD];
    for (toward, blocked) in drawn.iter_mut().flatten().zip(&mut blocked) {
        *blocked = trace_aimed(run.world, run.at, toward, rays.counts, rays.origin);
    }
    let looked_up = drawn.iter_mut().flatten().zip(&blocked);
    for ((toward, blocked), arriving) in looked_up.zip(arriving) {
        *arriving = radiance_if_free(run.world, run.at, toward, *blocked);
    }
}

/// AIS off's batch ([`Batch::is_plain`]): its numbers taken at once, its candidates drawn,
/// traced and added up in runs of [`AHEAD`] as [`run_ahead`] does, but with no call into
/// the driver per candidate. The same estimate and counts, to the bit. Each candidate's
/// value goes to `spread` where given.
/// A batch that MIS draws from an unguided proposal runs lane by lane ([`PlainLanes`]),
/// whatever its lights: the same estimate, without the general candidate's bookkeeping.
fn run_plain(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    counts: &mut RayCounts,
    spread: Option<&mut CandidateSpread>,
) -> ais::Estimate<[f32; 3]> {
    let mut total = PlainSum {
        spread,
        ..PlainSum::default()
    };
    let numbers = batch.begin_plain(run.rays, run.seed);
    match PlainLanes::of(run) {
        Some(lanes) => lanes.run(run, numbers, counts, &mut total),
        None => add_up_plain(run, numbers, counts, &mut total),
    }
    batch.finish_plain(total.sum, total.tally)
}

/// The general runs of [`run_plain`]: `numbers`' candidates drawn, traced and added up
/// into `total` (for proposals that fold in a map, strategies other than MIS, and guides
/// whose texels split a map's cells, which the lanes do not take).
pub(super) fn add_up_plain(
    run: &BatchRun,
    numbers: &[[f32; 2]],
    counts: &mut RayCounts,
    total: &mut PlainSum,
) {
    let mut drawn = [None; AHEAD];
    let mut arriving = [ShadowRay::Unneeded; AHEAD];
    let mut origin = run.shared_origin();
    for numbers in numbers.chunks(AHEAD) {
        let drawn = &mut drawn[..numbers.len()];
        draw_into(run, numbers, drawn);
        let kept = keep_in_support(run.at, drawn);
        total.count_run(numbers.len(), kept);
        let shadow_rays = ShadowRays {
            counts,
            origin: &mut origin,
        };
        trace_run(run, drawn, &mut arriving, shadow_rays);
        for (toward, &arriving) in drawn.iter_mut().flatten().zip(&arriving) {
            total.add(plain_value_of(run, toward, arriving));
        }
    }
    run.pass_on(&origin);
}

/// What a plain batch adds up: its traced candidates' values, how many it traced, and
/// each value for the gather's spread where one is kept.
#[derive(Default)]
pub(super) struct PlainSum<'s> {
    /// The sum of the values.
    pub sum: [f32; 3],
    /// The candidates traced and not.
    pub tally: PlainTally,
    /// The gather's spread, given every value.
    pub spread: Option<&'s mut CandidateSpread>,
}

impl PlainSum<'_> {
    /// A run of `candidates` of which `kept` lie inside the support (and are traced).
    pub fn count_run(&mut self, candidates: usize, kept: usize) {
        self.tally.outside_support += (candidates - kept) as u32;
        self.tally.traced += kept as u32;
    }

    /// A traced candidate's value (zero if its ray was blocked).
    #[inline]
    pub fn add(&mut self, value: Vec3) {
        self.sum = Value::add(self.sum, value.to_array());
        if let Some(spread) = self.spread.as_deref_mut() {
            spread.add(luminance(value) as f64);
        }
    }
}

/// Empties the slots of `drawn` whose candidates lie outside the support (not carried by
/// the BSDF), leaving the others where they are (a candidate is over a hundred bytes);
/// returns how many are left.
fn keep_in_support(at: &GatherPoint, drawn: &mut [Option<Toward>]) -> usize {
    let mut kept = 0;
    for slot in drawn {
        if slot.as_ref().is_some_and(|toward| at.carries(toward)) {
            kept += 1;
        } else {
            *slot = None;
        }
    }
    kept
}

/// Draws the candidates of `numbers` into `slots` (as many), in order: `None` where no
/// direction could be drawn. The environment map's draws are made all together, step by
/// step, so that one draw's table lookups overlap the next's; the area lights' after them,
/// light by light (a rectangle's over the run's lanes at once), and the BSDF's last (a
/// diffuse material's in lanes too).
fn draw_into(run: &BatchRun, numbers: &[[f32; 2]], slots: &mut [Option<Toward>]) {
    let mut environment = EnvironmentDraws::default();
    let mut area_draws = AreaDraws::default();
    let mut bsdf_numbers = [[0.0; 2]; AHEAD];
    let mut bsdf_slots = [0; AHEAD];
    let mut bsdf_draws = 0;
    for (k, (&u, slot)) in numbers.iter().zip(slots.iter_mut()).enumerate() {
        *slot = match run.sampler.begin_direction(run.at, u) {
            CandidateDraw::Made(toward) => toward,
            CandidateDraw::Environment(u) => {
                environment.push(k, u);
                None
            }
            CandidateDraw::Area(draw) => {
                area_draws.push(k, draw);
                None
            }
            CandidateDraw::Bsdf(u) => {
                (bsdf_numbers[bsdf_draws], bsdf_slots[bsdf_draws]) = (u, k);
                bsdf_draws += 1;
                None
            }
        };
    }
    environment.draw(run.at.lights, &run.at.receiver, |k, toward| {
        slots[k] = Some(toward)
    });
    area_draws.draw(run.at.lights, &run.at.receiver, |k, toward| {
        slots[k] = Some(toward)
    });
    run.at
        .draw_bsdf_run(&bsdf_numbers[..bsdf_draws], |k, toward| {
            slots[bsdf_slots[k]] = toward
        });
}

/// Draws and decides candidates until [`AHEAD`] are to be traced or the batch is complete;
/// returns how many were put in `drawn` (from its start, in the order decided), with their
/// weights (1 / acceptance) in `weights`. The candidates the batch places next are drawn one
/// after another before any is decided, so that one draw's table lookups overlap the next's.
fn draw_ahead(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    drawn: &mut [Option<Toward>; AHEAD],
    weights: &mut [f32; AHEAD],
) -> usize {
    let at = run.at;
    // No value-aware rule runs here: the running mean stays unused.
    let mut values = RunningMean::default();
    let mut points = [[0.0; 3]; AHEAD];
    let mut count = 0;
    while count < AHEAD {
        let placed = batch.upcoming(&mut points[..AHEAD - count]);
        if placed == 0 {
            break;
        }
        // Drawn into their slots (moved only to close the gap a rejected one leaves).
        let numbers: [[f32; 2]; AHEAD] = std::array::from_fn(|k| [points[k][0], points[k][1]]);
        draw_into(run, &numbers[..placed], &mut drawn[count..count + placed]);
        let mut kept = count;
        for k in count..count + placed {
            let taken = batch.next_candidate();
            debug_assert!(taken.is_some(), "the batch took back a candidate it placed");
            let Some(toward) = &mut drawn[k] else {
                batch.decide(at.frame.normal, false);
                continue;
            };
            let in_support = at.carries(toward);
            let (decision, _) = decide(run, batch, &mut values, toward, in_support);
            if let Decision::Trace { weight } = decision {
                weights[kept] = weight;
                // (A candidate is over a hundred bytes: most stay where they were drawn.)
                if kept != k {
                    drawn.swap(kept, k);
                }
                kept += 1;
            }
        }
        count = kept;
    }
    count
}

/// The batch one candidate at a time: drawn, decided, traced and recorded.
fn run_one_by_one<P: BatchProbe>(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    counts: &mut RayCounts,
    probe: &mut P,
    lessons: &mut Lessons,
) {
    let at = run.at;
    let value_only = batch.map().is_none() && batch.observations().is_none();
    let mut values = RunningMean::default();
    let mut origin = run.shared_origin();
    while let Some(candidate) = batch.next_candidate() {
        let Some(mut toward) = run.sampler.sample_direction(at, candidate.u) else {
            probe.decided(at.frame.normal, false);
            batch.decide(at.frame.normal, false);
            continue;
        };
        let in_support = at.carries(&toward);
        probe.decided(toward.direction, in_support);
        let (decision, known) = decide(run, batch, &mut values, &mut toward, in_support);
        if let Decision::Trace { weight } = decision {
            let started = run.clock.map(|_| Instant::now());
            let traced = if value_only && known.is_none() {
                traced_value(run, toward, counts, &mut origin)
            } else {
                trace(run, toward, known, counts, &mut origin.blockers)
            };
            record(run, batch, lessons, &mut toward, &traced, weight);
            if let (Some(clock), Some(started)) = (run.clock, started) {
                clock.set(clock.get() + started.elapsed());
            }
            probe.recorded(batch, traced.value.to_array(), traced.rating);
        }
    }
    run.pass_on(&origin);
}

/// Records a traced candidate toward `toward` (weighed `weight` = 1 / acceptance) in the
/// batch, and what it teaches in `lessons`: whether its ray was free (in its direction's
/// texel, and for the light it aimed at), what it brought from that light, its value at
/// every MIS share, and its weighted value for the gather's spread.
fn record(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    lessons: &mut Lessons,
    toward: &mut Toward,
    traced: &Traced,
    weight: f32,
) {
    let value = luminance(traced.value);
    // What the candidate adds to the gather's estimate.
    let weighted = value as f64 * weight as f64;
    if let (Some(recorder), Some(free)) = (lessons.cell.as_deref_mut(), traced.free) {
        recorder.record(toward.direction.into(), free);
        if let Some(source) = traced.source {
            recorder.record_source(source, free);
            recorder.record_brought(source, weighted);
        }
    }
    if let (Some(shares), Some(parts), true) =
        (lessons.shares.as_deref_mut(), traced.parts, value > 0.0)
    {
        shares.add(value, parts, run.at.mis_bsdf_share);
    }
    if let Some(spread) = lessons.spread.as_deref_mut() {
        spread.add(weighted);
    }
    batch.record(traced.value.to_array(), traced.rating);
}

/// What is known of a candidate before it is traced.
struct Known {
    /// The proposal's density.
    density: f64,
    /// Its leaving ray.
    leaving: Leaving,
}

/// Asks the batch whether to trace the candidate toward `direction`. Value-aware rules need
/// the density and the unoccluded radiance before deciding; they are returned so that a
/// traced candidate does not compute them twice.
fn decide(
    run: &BatchRun,
    batch: &mut Batch<[f32; 3]>,
    values: &mut RunningMean,
    toward: &mut Toward,
    in_support: bool,
) -> (Decision, Option<Known>) {
    let acceptance = run.settings.acceptance;
    let direction = toward.direction;
    if toward.specular.is_some() {
        // A specular lobe is one direction whatever the map learned of its neighbours: it
        // is always traced.
        return (batch.decide_with(direction, in_support, |_| 1.0), None);
    }
    if let Some(field) = &run.field {
        // Visibility alone: computing each candidate's value before deciding (to always
        // trace the bright ones) cost more time than it saved, measured on the rooms.
        let decision = batch.decide_with(direction, in_support, |_| {
            field.cell.acceptance(direction.into(), field.cost_ratio)
        });
        return (decision, None);
    }
    if acceptance.needs_value() && in_support {
        let (value, known) = unoccluded_value(run, toward);
        let mean = values.mean_then_add(value);
        let decision = batch.decide_with(direction, in_support, |affinity| {
            acceptance.probability(affinity, value, mean)
        });
        return (decision, Some(known));
    }
    let decision = if run.settings.map_use.guides() {
        // The map is already in the proposal: trace every candidate.
        batch.decide_with(direction, in_support, |_| 1.0)
    } else {
        batch.decide_with(direction, in_support, |affinity| {
            acceptance.probability(affinity, 0.0, None)
        })
    };
    (decision, None)
}

/// The candidate's unoccluded value (luminance of f·L/p with nothing in the way), and what
/// tracing it will need.
fn unoccluded_value(run: &BatchRun, toward: &mut Toward) -> (f32, Known) {
    let at = run.at;
    let density = run.sampler.pdf(at, toward);
    let leaving = Leaving::new(run.world, at, toward);
    let value = if density > 0.0 {
        luminance(at.scattering(toward) * leaving.unoccluded) / density as f32
    } else {
        0.0
    };
    (value, Known { density, leaving })
}

/// What a traced candidate brought and saw, for the batch and the field.
struct Traced {
    /// Its contribution f·L/p.
    value: Vec3,
    /// Actual over unoccluded radiance, in [0, 1] (0 where nothing reads it).
    rating: f32,
    /// Whether its ray toward light was free (None: no such ray was traced, or it brought
    /// nothing).
    free: Option<bool>,
    /// The light it aimed at, indexed as light sampling chooses them (None: none).
    source: Option<usize>,
    /// MIS's two densities at it, where it brought light and the plain MIS proposal drew it
    /// from a density (for [`ShareMoments`]).
    parts: Option<MisParts>,
}

/// Traces an accepted candidate whose value alone is wanted (with whether its ray was
/// free, for a recorder): the density, the BSDF and the environment's radiance are looked
/// up only if its shadow ray is free. The same value as [`trace`] gives; the rating is 0,
/// as nothing reads it (the batch has no map to learn). `origin` holds what the gather's
/// earlier rays learned ([`SharedOrigin`]).
fn traced_value(
    run: &BatchRun,
    mut toward: Toward,
    counts: &mut RayCounts,
    origin: &mut SharedOrigin,
) -> Traced {
    let shadow_ray = free_radiance(run.world, run.at, &mut toward, counts, origin);
    value_of(run, &mut toward, shadow_ray)
}

/// What an accepted candidate brings, once its shadow ray is known ([`traced_value`]).
fn value_of(run: &BatchRun, toward: &mut Toward, shadow_ray: ShadowRay) -> Traced {
    let source = run.world.lights.source_of(&run.at.receiver, toward);
    let (value, parts, free) = match shadow_ray {
        ShadowRay::Unneeded => (Vec3::ZERO, None, None),
        ShadowRay::Blocked => (Vec3::ZERO, None, Some(false)),
        ShadowRay::Free(radiance) => match brought(run, toward, radiance) {
            Some((value, parts)) => (value, parts, Some(true)),
            None => (Vec3::ZERO, None, None),
        },
    };
    Traced {
        value,
        rating: 0.0,
        free,
        source,
        parts,
    }
}

/// [`value_of`]'s value alone, for AIS off's batches, which record nothing else.
#[inline]
fn plain_value_of(run: &BatchRun, toward: &mut Toward, shadow_ray: ShadowRay) -> Vec3 {
    match shadow_ray {
        ShadowRay::Free(radiance) => brought(run, toward, radiance).map_or(Vec3::ZERO, |b| b.0),
        ShadowRay::Unneeded | ShadowRay::Blocked => Vec3::ZERO,
    }
}

/// What a candidate whose ray was free brings with `radiance`: f·L/p, and MIS's two
/// densities where the plain MIS proposal drew it (`None`: nothing, at a zero density,
/// possible only at a light's rim in f32, or a zero radiance).
#[inline]
fn brought(
    run: &BatchRun,
    toward: &mut Toward,
    radiance: Vec3,
) -> Option<(Vec3, Option<MisParts>)> {
    let at = run.at;
    // MIS's density from its two parts, kept for the share's moments.
    let parts = run.sampler.mis_parts(at, toward);
    let pdf = match parts {
        Some(parts) => parts.mixed(at.mis_bsdf_share),
        None => run.sampler.pdf(at, toward),
    };
    if pdf <= 0.0 || radiance == Vec3::ZERO {
        return None;
    }
    Some((at.scattering(toward) * radiance / pdf as f32, parts))
}

/// Traces an accepted candidate: its contribution f·L/p and what it saw (`blockers`: the
/// gather's recent blockers, tried first).
fn trace(
    run: &BatchRun,
    mut toward: Toward,
    known: Option<Known>,
    counts: &mut RayCounts,
    blockers: &mut RecentBlockers,
) -> Traced {
    let at = run.at;
    let Known {
        density: pdf,
        leaving,
    } = known.unwrap_or_else(|| Known {
        density: run.sampler.pdf(at, &mut toward),
        leaving: Leaving::new(run.world, at, &mut toward),
    });
    // A zero density, possible only at a light's rim in f32, brings nothing.
    if pdf <= 0.0 {
        return Traced {
            value: Vec3::ZERO,
            rating: rating(0.0, 0.0),
            free: None,
            source: None,
            parts: None,
        };
    }
    let actual = leaving.trace(run.world, counts, blockers);
    let rating = rating(luminance(actual), luminance(leaving.unoccluded));
    Traced {
        value: at.scattering(&toward) * actual / pdf as f32,
        rating,
        // A ray was traced toward light only if it could bring some.
        free: (leaving.unoccluded != Vec3::ZERO).then_some(rating > 0.0),
        source: run.world.lights.source_of(&at.receiver, &toward),
        parts: None,
    }
}
