//! The gather with the visibility field (`map = field`, preset `auto`): acceptance from the
//! field learned in earlier passes, standing aside where roulette cannot pay, and what a
//! pass gives back: its rays, and what a candidate and a traced ray cost in this render.

use super::batch_loop::{run_batch, BatchProbe, BatchRun, FieldUse, Lessons};
use super::field_guide::CellGuide;
use super::gather_sizes::{least_error, GatherSizes};
use super::guiding::CandidateSampler;
use super::mis_share::ShareMoments;
use super::race::{Race, RaceResult, TileMoments, RACE_MARGIN, RACE_PASSES};
use super::strategy::{GatherPoint, Strategy};
use super::{batch_for, note_gather_variance, GatherSettings, GatherTile, MapSource};
use crate::geometry::Hit;
use crate::render::{Learning, PassEnd, RayCounts};
use crate::texture::luminance;
use crate::world::World;
use ais::field::{
    CellIndex, CellKey, CellRecorder, FieldCell, FieldObservations, VisibilityField, MOST_SOURCES,
};
use ais::{MapStart, Stats};
use glam::Vec3;
use std::cell::Cell;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// One gather in this many is timed to measure the cost ratio.
pub const TIMED_ONE_IN: u64 = 16;

/// The cost ratio used before anything was measured (and when nothing could be).
pub const UNMEASURED_COST_RATIO: f32 = 1.0;

/// Samples per pixel of the passes in which a render with `map = field` learns
/// ([`field_passes`]).
pub const LEARNING_PASSES: [u32; 4] = [1, 1, 2, 4];

/// Samples per pixel a field learns from: those of its [`LEARNING_PASSES`]. Renders that go
/// on from earlier ones (a study's progressive passes) stop observing after as many.
pub const LEARNING_SAMPLES: u32 =
    LEARNING_PASSES[0] + LEARNING_PASSES[1] + LEARNING_PASSES[2] + LEARNING_PASSES[3];

/// Samples per pixel of the passes of a render with `map = field` that takes `spp` samples
/// from sample `first_sample` on: the field learns in passes of 1, 1, 2 and 4 samples
/// ([`LEARNING_PASSES`]) and the rest is one pass, so it learns early and is used for most
/// samples. (Each pass ends with a barrier where a core may wait for the last tile: more
/// passes cost more. Learning from 8 samples per pixel instead of 4 lowered relMSE by
/// 4–21% at equal spp in five scenes.) The passes end where a whole render's would, so a
/// render that goes on from earlier ones (a study's) learns and races in the same passes.
pub fn field_passes(first_sample: u32, spp: u32) -> Vec<u32> {
    if spp == 0 {
        return Vec::new();
    }
    let end = first_sample.saturating_add(spp);
    let learning_ends = LEARNING_PASSES.iter().scan(0, |ended, &samples| {
        *ended += samples;
        Some(*ended)
    });
    let mut passes = Vec::new();
    let mut start = first_sample;
    for cut in learning_ends
        .filter(|&cut| cut > first_sample && cut < end)
        .chain([end])
    {
        passes.push(cut - start);
        start = cut;
    }
    passes
}

/// The field's roulette runs only in gathers of at least this many candidates. Measured
/// on ten scenes (the repository's BENCHMARKS.md, section 5.6): with 16 candidates it never
/// gained at equal time and lost up to 23% (a room lit through a door gap), with 128 it
/// gains in closed rooms. Skipping a few rays of a small gather saves little next to what
/// the gather costs anyway (its camera ray, its shading point, its share of the passes),
/// while every skip adds variance.
pub const LEAST_ROLLING_RAYS: u32 = 64;

/// Whether gathers with these settings use the field's roulette: `map_use` roulette or
/// both, and at least [`LEAST_ROLLING_RAYS`] candidates. Only then is the cost ratio
/// measured (and timing can change an image).
pub fn field_rolls(settings: &GatherSettings) -> bool {
    settings.map_use.rolls() && settings.rays >= LEAST_ROLLING_RAYS
}

/// The sources the field counts per cell ([`crate::lights::Lights::field_sources`]), to
/// choose among the lights and, within a sphere or a rectangle light, among the regions of
/// its sample square by what each brought: all of them where there is a choice to make
/// (two or more lights, or a light with regions), else none; none either beyond
/// [`MOST_SOURCES`], where a cell could learn only some of them and the others would keep
/// no more than the choice's defensive share.
pub fn counted_sources(world: &World) -> usize {
    let lights = &world.lights;
    let sources = lights.field_sources();
    let choice = lights.source_count() >= 2 || sources > lights.source_count();
    if choice && sources <= MOST_SOURCES as usize {
        sources
    } else {
        0
    }
}

/// Whether the field can change anything in `world` with these settings (`map = field`):
/// its roulette runs ([`field_rolls`]), or it can guide light sampling: toward an
/// environment, in the choice among two or more lights, or among a sphere's or a
/// rectangle's regions. Elsewhere (one disk, cylinder, mesh or delta light, and fewer than
/// [`LEAST_ROLLING_RAYS`] candidates) the gather renders as AIS off, nothing
/// recorded or timed: in one pass, or, where [`chooses_sizes`], in passes whose race
/// passes measure the pixels.
pub fn field_has_use(world: &World, settings: &GatherSettings) -> bool {
    settings.map == MapSource::Field && (field_rolls(settings) || field_can_guide(world, settings))
}

/// Whether the field can guide light sampling in `world` with these settings: light
/// sampling is in the proposal, `map_use` guides, and there is an environment to draw, a
/// choice among two or more lights, or a light with regions ([`counted_sources`]).
pub fn field_can_guide(world: &World, settings: &GatherSettings) -> bool {
    let guidable = world.lights.environment.is_some() || counted_sources(world) > 0;
    settings.map_use.guides()
        && guidable
        && matches!(settings.strategy, Strategy::Light | Strategy::Mis)
}

/// Whether gathers with these settings measure their pixels in the race passes to choose
/// the candidates per gather per block (`map = field` with `field_sizes`): where the field
/// has a use and where it has none (area lights only), since gathers' variance can be
/// spread unevenly over any image. Such renders run in passes ([`field_passes`]).
pub fn chooses_sizes(settings: &GatherSettings) -> bool {
    settings.map == MapSource::Field && settings.field_sizes
}

/// Whether gathers with these settings race the field against AIS off on the image (see
/// [`super::race`]): where the field has a use and may stand aside, and not where it
/// rolls with a pinned cost ratio (the race would be timed; such images are
/// reproducible).
pub fn races(world: &World, settings: &GatherSettings) -> bool {
    field_has_use(world, settings)
        && settings.field_race
        && !(field_rolls(settings) && settings.cost_ratio.is_some())
}

/// Learning stops once fewer than this share of the rays fall in cells where roulette pays.
pub const LEAST_ROLLING_SHARE: f32 = 0.05;

/// A cell with this many rays in the field learns from one gather in
/// [`WELL_KNOWN_RECORD_ONE_IN`] only: recording costs time, and it knows enough.
pub const WELL_KNOWN: u32 = 512;

/// See [`WELL_KNOWN`].
pub const WELL_KNOWN_RECORD_ONE_IN: u64 = 4;

/// Timings of sampled gathers: whole pixel samples from the camera ray on (what a gather
/// costs besides its candidates is shared among them), and the part spent on accepted
/// candidates (density, unoccluded radiance, the occlusion ray, the BSDF, recording).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CostSample {
    /// Time in the timed gathers, from their camera rays on.
    pub gathers: Duration,
    /// Of which, time on accepted candidates.
    pub traced: Duration,
    /// Candidates drawn in the timed gathers.
    pub candidates: u64,
    /// Of which, accepted.
    pub accepted: u64,
}

impl CostSample {
    /// A timed gather started at `started`, its batch's counts `before` and `after` it, and
    /// `traced`, its time on accepted candidates.
    fn since(started: Instant, before: &Stats, after: &Stats, traced: Duration) -> Self {
        CostSample {
            gathers: started.elapsed(),
            traced,
            candidates: after.candidates - before.candidates,
            accepted: after.traced - before.traced,
        }
    }

    fn add(&mut self, other: CostSample) {
        self.gathers += other.gathers;
        self.traced += other.traced;
        self.candidates += other.candidates;
        self.accepted += other.accepted;
    }

    /// ρ = (what every candidate costs) / (what an accepted one adds), rounded to a power of
    /// √2 in [1/16, 16] so that timing noise rarely moves it; `None` without timings.
    pub fn ratio(&self) -> Option<f32> {
        if self.candidates == 0 || self.accepted == 0 || self.traced.is_zero() {
            return None;
        }
        let per_candidate =
            self.gathers.saturating_sub(self.traced).as_secs_f64() / self.candidates as f64;
        let per_traced = self.traced.as_secs_f64() / self.accepted as f64;
        let ratio = per_candidate / per_traced;
        let steps = (2.0 * ratio.log2()).round().clamp(-8.0, 8.0);
        Some(2f64.powf(steps / 2.0) as f32)
    }
}

/// What a tile gives back after a pass: its rays, and its timings.
#[derive(Clone, Debug)]
pub struct FieldPass {
    /// The rays traced, counted per cell and texel.
    pub observations: FieldObservations,
    /// Timings of its sampled gathers.
    pub cost: CostSample,
    /// Its gathers whose light sampling the field guided, and all its gathers the field
    /// could guide.
    pub guided: [u64; 2],
    /// Its pixels' sample moments, in a race pass.
    pub moments: Option<TileMoments>,
    /// Its gathers' second moments per MIS share.
    pub shares: Option<ShareMoments>,
}

/// Where the field does not roll, it stands aside for the rest of the render (AIS off)
/// once a pass guided fewer than this share of the gathers it could guide: under an open
/// sky the field guides few cells, and its learning passes (recording, barriers) and
/// lookups would cost 6–14% for nothing.
pub const LEAST_GUIDED_SHARE: f64 = 0.05;

/// What the gather learns between passes: the visibility field and the measured costs.
#[derive(Clone, Debug)]
pub struct GatherLearning {
    /// The field, shared read-only by the tiles of a pass.
    pub field: Arc<VisibilityField>,
    /// The timings of every pass so far.
    pub cost: CostSample,
    /// The tiles' observations of the pass being merged, added to the field together when
    /// it ends.
    pending: Vec<FieldObservations>,
    /// The settings' `cost_ratio`, if pinned.
    pinned_cost_ratio: Option<f32>,
    /// Whether the gathers roll ([`field_rolls`]).
    rolls: bool,
    /// Whether the field can guide light sampling ([`field_can_guide`]).
    guides: bool,
    /// Guided and all gathers of the pass being merged.
    guided: [u64; 2],
    /// The share of guided gathers in the last pass that read a field (`None` before).
    guided_share: Option<f64>,
    /// Passes ended.
    passes: u32,
    /// The field against AIS off on the image.
    race: Race,
    /// The race's result, once its passes ended.
    race_result: Option<RaceResult>,
    /// Gathers the field guided in the race passes so far.
    race_guided: u64,
    /// Whether the field may stand aside (`field_race`).
    may_stand_aside: bool,
    /// The pass's second moments per MIS share, merged from its tiles.
    shares: ShareMoments,
    /// The BSDF's share of MIS for the next pass, once learned.
    mis_share: Option<f64>,
    /// The settings' candidates per gather.
    rays: u32,
    /// Whether the race passes choose candidates per block ([`chooses_sizes`]).
    chooses_sizes: bool,
    /// Whether those passes race the field against AIS off ([`races`]).
    races: bool,
    /// The candidates per gather per block, once the race chose them.
    sizes: Option<Arc<GatherSizes>>,
    /// The samples per pixel the whole render is expected to take, where its passes do not
    /// know (a progressive study's, whose budget is in time).
    horizon: Option<u32>,
}

impl GatherLearning {
    /// An empty field for these settings (`field_res`, `field_prior`), counting the rays
    /// aimed at each of `world`'s lights where light sampling may choose among them.
    pub fn new(world: &World, settings: &GatherSettings) -> Self {
        let field = VisibilityField::new(settings.field_res)
            .with_prior(settings.field_prior)
            .with_sources(counted_sources(world) as u32);
        GatherLearning {
            field: Arc::new(field),
            cost: CostSample::default(),
            pending: Vec::new(),
            pinned_cost_ratio: settings.cost_ratio,
            rolls: field_rolls(settings),
            guides: field_can_guide(world, settings),
            guided: [0; 2],
            guided_share: None,
            passes: 0,
            race: Race::new(world.resolution.0 as usize, world.resolution.1 as usize),
            race_result: None,
            race_guided: 0,
            may_stand_aside: settings.field_race,
            shares: ShareMoments::default(),
            mis_share: None,
            rays: settings.rays,
            chooses_sizes: chooses_sizes(settings),
            races: races(world, settings),
            sizes: None,
            horizon: None,
        }
    }

    /// Where a render's passes go on in later renders, the samples per pixel all of them are
    /// expected to take (`None`: not known), for the choice of candidates per block: how
    /// long the render is decides how much what the camera sees weighs
    /// ([`super::gather_sizes`]).
    pub fn expect_samples(&mut self, total: Option<u32>) {
        self.horizon = total;
    }

    /// The candidates per gather per block of the image, once the race chose them (`None`:
    /// the settings' `rays` everywhere).
    pub fn gather_sizes(&self) -> Option<&Arc<GatherSizes>> {
        self.sizes.as_ref()
    }

    /// The BSDF's share of MIS for the next pass: learned from the last pass whose gathers
    /// were enough to tell ([`ShareMoments::best`]); `None` before (the default,
    /// [`MIS_BSDF_WEIGHT`](super::strategy::MIS_BSDF_WEIGHT)).
    pub fn mis_share(&self) -> Option<f64> {
        self.mis_share
    }

    /// Passes ended so far (the index of the pass about to run).
    pub fn passes_ended(&self) -> u32 {
        self.passes
    }

    /// The race's result, once its passes ended.
    pub fn race_result(&self) -> Option<RaceResult> {
        self.race_result
    }

    /// Whether the field has no use in the rest of the render, which then gathers as AIS
    /// off (never with `field_race` false): it lost its race; or, before its verdict, it
    /// finds little to roll and little to guide (its learning's `little_use`).
    pub fn stands_aside(&self) -> bool {
        if !self.may_stand_aside {
            return false;
        }
        let lost_race = self.race_result.is_some_and(|race| !race.field_pays());
        let before_verdict = !self.rolls || self.race_result.is_none();
        lost_race || (before_verdict && self.little_use())
    }

    /// Whether the field found little use so far: roulette (where it rolls) pays for fewer
    /// than [`LEAST_ROLLING_SHARE`] of the rays, and its last pass guided fewer than
    /// [`LEAST_GUIDED_SHARE`] of the gathers it could guide (a rolling field is not judged
    /// by its guiding until a pass has read it). A field that guides is raced, even where
    /// it rolls little: its choice among lights gained 1.7–2.0× at 128 candidates behind a
    /// roof edge, where roulette pays almost nowhere.
    fn little_use(&self) -> bool {
        let rolls_little = !self.rolls
            || self
                .field
                .rolling_share()
                .is_some_and(|share| share < LEAST_ROLLING_SHARE);
        let guides_little = !self.guides
            || self
                .guided_share
                .is_some_and(|share| share < LEAST_GUIDED_SHARE);
        rolls_little && guides_little
    }

    /// The cost ratio the next pass uses: the settings' `cost_ratio` if given, else the one
    /// measured so far.
    pub fn cost_ratio(&self) -> f32 {
        self.pinned_cost_ratio
            .or_else(|| self.cost.ratio())
            .unwrap_or(UNMEASURED_COST_RATIO)
    }

    /// Each race arm's predicted error at the render's end with its own gather sizes, at its
    /// own pace (where sizes are chosen): the field's worth where it will gather with fewer
    /// candidates. Untimed, the field's pace is AIS off's over [`RACE_MARGIN`].
    fn arms_sized(&self, race: &RaceResult, samples: PassEnd) -> Option<[f64; 2]> {
        if !self.chooses_sizes {
            return None;
        }
        let samples = self.with_horizon(samples);
        let field_pace = match race.seconds_per_sample {
            Some([field, off]) => off / field,
            None => 1.0 / RACE_MARGIN,
        };
        let field = least_error(
            &self.race.relative_blocks(Some(false)),
            self.rays,
            samples,
            field_pace,
        )?;
        let off = least_error(
            &self.race.relative_blocks(Some(true)),
            self.rays,
            samples,
            1.0,
        )?;
        Some([field, off])
    }

    /// `samples` with what is left of the render taken from its horizon, where unknown.
    fn with_horizon(&self, samples: PassEnd) -> PassEnd {
        let horizon = self.horizon.map(|total| total.saturating_sub(samples.done));
        PassEnd {
            left: samples.left.or(horizon),
            ..samples
        }
    }

    /// Chooses the candidates per gather per block (where `field_sizes` allows) from the
    /// pixels of the arm that won the race, or of all pixels where nothing raced.
    fn choose_sizes(&mut self, samples: PassEnd) {
        if !self.chooses_sizes {
            return;
        }
        let arm = self.race_result.map(|race| !race.field_pays());
        let blocks = self.race.blocks(arm);
        let samples = self.with_horizon(samples);
        let columns = GatherSizes::columns_for(self.race.width());
        self.sizes = GatherSizes::choose(&blocks, columns, self.rays, samples).map(Arc::new);
    }
}

impl Learning for GatherLearning {
    type Observed = Option<FieldPass>;

    fn merge(&mut self, observed: Option<FieldPass>) {
        if let Some(pass) = observed {
            self.pending.push(pass.observations);
            self.cost.add(pass.cost);
            self.guided[0] += pass.guided[0];
            self.guided[1] += pass.guided[1];
            if let Some(moments) = &pass.moments {
                self.race.merge(moments);
            }
            if let Some(shares) = &pass.shares {
                self.shares.merge(shares);
            }
        }
    }

    /// Plans the next pass's roulette at its cost ratio: which cells it pays in.
    fn end_pass(&mut self, samples: PassEnd) {
        let cost_ratio = self.cost_ratio();
        // The pass's tiles have dropped their handles: no copy is made.
        let field = Arc::make_mut(&mut self.field);
        field.merge_all(&std::mem::take(&mut self.pending));
        field.plan(cost_ratio);
        if let Some(share) = std::mem::take(&mut self.shares).best() {
            self.mis_share = Some(share);
        }
        // The first pass reads an empty field: it guides nothing and says nothing.
        if self.passes > 0 && self.guided[1] > 0 {
            self.guided_share = Some(self.guided[0] as f64 / self.guided[1] as f64);
        }
        if RACE_PASSES.contains(&self.passes) {
            self.race_guided += self.guided[0];
        }
        self.guided = [0; 2];
        if self.passes == *RACE_PASSES.end() {
            let guided = self.race_guided > 0;
            self.race_result = (self.races.then(|| self.race.result()).flatten())
                .map(|race| RaceResult { guided, ..race });
            let sized = self
                .race_result
                .and_then(|race| self.arms_sized(&race, samples));
            if let Some(race) = self.race_result.as_mut() {
                race.sized = sized;
            }
            self.choose_sizes(samples);
            self.race = Race::default(); // its image-sized sums are no longer needed
        }
        self.passes += 1;
    }

    /// As a render of its own does, the field learns from its first [`LEARNING_SAMPLES`]
    /// samples per pixel: observing every later pass of a progressive study cost it time
    /// (recording its rays, rebuilding its field) that a render of its own does not spend.
    fn wants_observations(&self, samples_before: u32) -> bool {
        samples_before < LEARNING_SAMPLES
    }

    /// Learning goes on unless the field stands aside ([`GatherLearning::stands_aside`]:
    /// counts and sample values, not timings, so those images do not depend on the
    /// machine) or its roulette, with enough evidence, stands aside for nearly every ray
    /// (the talk's auto-disable): then the rest of the render is one pass.
    fn keeps_learning(&self) -> bool {
        // The candidates per block are chosen from the race passes, run as passes of
        // their own even where the field has stood aside or has no use.
        if self.chooses_sizes && self.passes <= *RACE_PASSES.end() {
            return true;
        }
        if self.stands_aside() {
            return false;
        }
        // After the race (or without one), as little use as it takes to stand aside stops
        // the learning but keeps the field.
        !self.little_use()
    }
}

/// Whether the tile's next field gather is one of the timed ones (one in
/// [`TIMED_ONE_IN`], while learning with a measured cost ratio for roulette; not a pixel
/// racing as AIS off, which does not roll).
pub(super) fn times_next_gather<P: BatchProbe>(
    state: &GatherTile<P>,
    settings: &GatherSettings,
) -> bool {
    state.observations.is_some()
        && settings.cost_ratio.is_none()
        && field_rolls(settings)
        && !state.racing_off
        && (state.gathers + 1).is_multiple_of(TIMED_ONE_IN)
}

/// Where a `map = field` gather happens.
pub(super) struct FieldSite<'a> {
    /// Its cell of the field.
    key: CellKey,
    /// The gather point.
    at: GatherPoint<'a>,
    /// The batch's scrambling seed.
    seed: u64,
    /// When a timed gather's pixel sample began (its camera ray and shading point count
    /// in what every candidate costs: they are paid once per n candidates).
    pub started: Option<Instant>,
}

impl<'a> FieldSite<'a> {
    /// The gather at `hit` (point `at`, pixel footprint `footprint`), seeded with `seed`,
    /// in a cell `cell_pixels` footprints wide.
    pub fn new(
        hit: &Hit,
        at: GatherPoint<'a>,
        footprint: f32,
        cell_pixels: f32,
        seed: u64,
    ) -> Self {
        FieldSite {
            key: CellKey::new(
                hit.point.into(),
                hit.geometric_normal.into(),
                CellKey::level_for(cell_pixels * footprint),
            ),
            at,
            seed,
            started: None,
        }
    }
}

/// The cell `key` of `field` and where it is, remembering it in `last_cell`: neighbouring
/// pixels often share a cell, and the field does not change within a pass.
fn find_cell<'f>(
    field: &'f VisibilityField,
    last_cell: &mut Option<(CellKey, Option<CellIndex>)>,
    key: CellKey,
) -> Option<(CellIndex, FieldCell<'f>)> {
    let index = match *last_cell {
        Some((last, index)) if last == key => index,
        _ => {
            let index = field.find(&key);
            *last_cell = Some((key, index));
            index
        }
    };
    index.map(|index| (index, field.cell_at(index)))
}

/// A gather with the learned field: roulette where the field's cell says it pays at this
/// render's cost ratio (`map_use` roulette or both), light sampling guided by the cell
/// where it is worth it (`map_use` proposal or both), every candidate traced and no map
/// work elsewhere. Its traced rays are recorded for the next pass's field; one gather in
/// [`TIMED_ONE_IN`] is timed for the next pass's cost ratio.
pub(super) fn field_gather<P: BatchProbe>(
    world: &World,
    settings: &GatherSettings,
    site: FieldSite,
    state: &mut GatherTile<P>,
    counts: &mut RayCounts,
) -> Vec3 {
    let GatherTile {
        batch,
        field,
        observations,
        field_gathers,
        field_guided,
        field_guides,
        last_cell,
        cost_ratio,
        cost,
        gathers,
        probe,
        racing_off,
        raced_off,
        shares,
        rays,
        spread,
        race,
        blockers,
        ..
    } = state;
    // A pixel racing as AIS off records its rays but is not guided (see `race`).
    let racing_off = *racing_off;
    *raced_off += u64::from(racing_off);
    let cost_ratio = *cost_ratio;
    let known = find_cell(field, last_cell, site.key);
    let record = records(known.map(|(_, cell)| cell), *gathers);
    let rolls = field_rolls(settings);
    let rolling = known
        .map(|(_, cell)| cell)
        .filter(|cell| rolls && !racing_off && cell.worth_rolling(cost_ratio));
    let mut at: GatherPoint<'_> = site.at;
    let guides = field_guides.as_mut().filter(|_| !racing_off);
    if let (Some(guides), Some((index, cell))) = (guides, known) {
        *field_guided += u64::from(follow_guide(&mut at, guides.guide(index, &cell)));
    }
    field_gathers[usize::from(rolling.is_none())] += 1;
    *gathers += 1;
    let clock = Cell::new(Duration::ZERO);
    let timed = site.started.is_some();
    let sampler = CandidateSampler::plain(settings.strategy);
    let run = BatchRun {
        world,
        settings,
        at: &at,
        sampler: &sampler,
        seed: site.seed,
        rays: *rays,
        start: MapStart::Empty,
        field: rolling.map(|cell| FieldUse { cell, cost_ratio }),
        clock: timed.then_some(&clock),
        blockers,
        pixel_pool: None,
    };
    let batch = batch_for(batch, settings);
    let before = *batch.stats();
    let mut recorder = observations
        .as_mut()
        .filter(|_| record)
        .map(|observations| cell_recorder(observations, site.key, &at));
    let lessons = Lessons {
        cell: recorder.as_mut(),
        shares: shares.as_mut(),
        spread: spread.as_mut(),
    };
    let value = run_batch(&run, batch, counts, probe, lessons);
    if let Some(shares) = shares.as_mut() {
        shares.end_gather(site.key, luminance(value));
    }
    note_gather_variance(race, spread);
    if let Some(started) = site.started {
        cost.add(CostSample::since(
            started,
            &before,
            batch.stats(),
            clock.get(),
        ));
    }
    value
}

/// Whether a gather in `cell` (`None`: a cell the field does not hold) records its rays,
/// the tile's `gathers`-th: always where the cell is little known, else one gather in
/// [`WELL_KNOWN_RECORD_ONE_IN`].
fn records(cell: Option<FieldCell>, gathers: u64) -> bool {
    cell.is_none_or(|cell| cell.total().traced < WELL_KNOWN)
        || gathers.is_multiple_of(WELL_KNOWN_RECORD_ONE_IN)
}

/// Points `at`'s light sampling at its cell's guide; returns whether the guide changes
/// anything there.
fn follow_guide<'g>(at: &mut GatherPoint<'g>, guide: &'g CellGuide) -> bool {
    at.receiver.environment_guide = guide.environment.as_ref();
    at.receiver.light_choice = guide.lights.as_ref();
    at.receiver.region_choices = &guide.regions;
    guide.guides()
}

/// The recorder of the pass's observations in cell `key`, told the normal of the gather at
/// `at`.
fn cell_recorder<'o>(
    observations: &'o mut FieldObservations,
    key: CellKey,
    at: &GatherPoint,
) -> CellRecorder<'o> {
    let mut recorder = observations.cell_mut(key);
    recorder.record_normal(at.frame.normal.into());
    recorder
}
