//! A learned directional visibility field over the whole image: for a region of space and a
//! range of normals (a *cell*), how often the rays traced from there toward each direction
//! were free.
//!
//! The state is split as Open PGL splits its Field and SamplingDistribution:
//! - [`VisibilityField`] is the learned state. It is read-only while a pass renders, so every
//!   acceptance probability derived from it is fixed before the candidate is drawn, Russian
//!   roulette with weight 1/a stays exactly unbiased, and the image does not depend on the
//!   number of threads.
//! - [`FieldObservations`] is per-thread scratch: the rays a tile traced, counted per cell
//!   and texel. Between passes the host merges every tile's observations into the field.
//!   Counts are integers, so the merged counts are the same in whatever order tiles finish;
//!   what sources brought are float sums, the same for a fixed merging order (by tile).
//!
//! Cells are keyed by position on a hashed grid whose spacing the host chooses per lookup,
//! as a power of two (so that it can follow the pixel footprint: a cell covers a few pixels
//! wherever it is), and by the dominant axis of the normal. Each cell holds an equal-area
//! octahedral map of `side × side` texels ([`octahedral`]), whose visibilities are also
//! kept pooled with their neighbours' for proposals ([`pooling`]). A lookup is one hash
//! probe per gather and one texel index per candidate: O(1) whatever the scene.
//!
//! A cell may also count rays by *source*: whatever the host says a ray aimed at (one of
//! its emitters, say), so that it can learn which sources a cell sees
//! ([`VisibilityField::with_sources`], [`FieldCell::source_visibility`]), and what the rays
//! that reached each source brought, as the host's estimate weighs them
//! ([`CellRecorder::record_brought`], [`FieldCell::source_brought`]): which sources light
//! the cell, not only which it sees.

pub mod octahedral;
pub mod pooling;

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::ops::Range;

/// What a texel of a cell has seen: rays traced and, of those, rays that were free.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TexelCounts {
    /// Traced rays that reached the light (or the sky).
    pub free: u32,
    /// Traced rays.
    pub traced: u32,
}

impl TexelCounts {
    fn add(&mut self, other: TexelCounts) {
        self.free = self.free.saturating_add(other.free);
        self.traced = self.traced.saturating_add(other.traced);
    }
}

/// The key of a cell: grid level (log2 of its spacing), integer coordinates at that level,
/// and the dominant axis of the normal (0..6: ±x, ±y, ±z).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CellKey {
    level: i8,
    face: u8,
    coordinates: [i32; 3],
}

impl CellKey {
    /// The cell holding `position` (normal `normal`) on the grid of spacing `2^level`.
    /// Coordinates beyond ±2³¹ cells clamp; a non-finite position lands in one cell.
    pub fn new(position: [f32; 3], normal: [f32; 3], level: i8) -> Self {
        let scale = (-(level as f32)).exp2();
        let coordinates = position.map(|p| {
            let c = (p * scale).floor();
            if c.is_finite() {
                c.clamp(i32::MIN as f32, i32::MAX as f32) as i32
            } else {
                0
            }
        });
        CellKey {
            level,
            face: dominant_face(normal),
            coordinates,
        }
    }

    /// The grid level whose spacing is the power of two nearest to `spacing` (world units).
    pub fn level_for(spacing: f32) -> i8 {
        if spacing.is_finite() && spacing > 0.0 {
            spacing.log2().round().clamp(-60.0, 60.0) as i8
        } else {
            0
        }
    }
}

/// 0..6 for the normal's dominant axis and its sign.
fn dominant_face(normal: [f32; 3]) -> u8 {
    let [x, y, z] = normal;
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let (axis, value) = if ax >= ay && ax >= az {
        (0, x)
    } else if ay >= az {
        (1, y)
    } else {
        (2, z)
    };
    axis * 2 + u8::from(value < 0.0)
}

/// A fast multiplicative hasher for cell keys (the keys are not adversarial: they come from
/// the host's own hit points).
#[derive(Default)]
pub struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }

    fn write_u8(&mut self, value: u8) {
        self.write_u64(value as u64);
    }

    fn write_i8(&mut self, value: i8) {
        self.write_u64(value as u8 as u64);
    }

    fn write_i32(&mut self, value: i32) {
        self.write_u64(value as u32 as u64);
    }

    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0.rotate_left(5) ^ value).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type KeyMap<V> = HashMap<CellKey, V, BuildHasherDefault<KeyHasher>>;

/// Where a cell's counts lie in a [`VisibilityField`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CellIndex(u32);

/// The learned field: every cell seen so far and its texels' counts.
#[derive(Clone, Debug)]
pub struct VisibilityField {
    side: u32,
    /// Sources counted per cell, after its texels.
    sources: u32,
    /// Pseudo-observations added to every cell (of a free ray) and texel (at its cell's
    /// visibility).
    prior: f32,
    /// Cell → index of its first texel in `counts`.
    cells: KeyMap<u32>,
    /// Per cell, its texels' counts, then its sources'.
    counts: Vec<TexelCounts>,
    /// Per cell, what the rays that reached each source brought (summed in the order the
    /// host merges its observations, so the same at any thread count).
    brought: Vec<f64>,
    /// Per cell, the sum of its texels' counts.
    totals: Vec<TexelCounts>,
    /// Per cell, the normals its hosts recorded (once per gather; summed in the order the
    /// host merges its observations).
    normals: Vec<NormalSum>,
    /// Per cell, its texels' visibilities pooled with their blocks' ([`pooling`]).
    pooled: Vec<f32>,
    /// Per cell, the lowest visibility of its texels.
    darkest: Vec<f32>,
    /// The cost ratio of the last [`VisibilityField::plan`] (None after a merge).
    planned: Option<f32>,
    /// Per cell, the share of its candidates roulette skips at the planned cost ratio.
    expected_rejection: Vec<f32>,
    /// Per cell where roulette pays at the planned cost ratio, its texels' acceptances at
    /// it, worked out once per pass instead of once per candidate (empty elsewhere).
    acceptances: Vec<f32>,
    /// Per cell, where its texels' acceptances start in `acceptances` (`u32::MAX`: not
    /// worked out).
    acceptances_at: Vec<u32>,
}

/// Texels per side of a cell's map by default: 64 texels of 0.2 sr each, for a host that
/// uses the field for roulette, which reads each texel's own counts (finer texels learn
/// more slowly, so roulette skips less). A host that guides its proposal with the pooled
/// visibilities can afford finer maps: the renderer of this repository uses 16.
pub const DEFAULT_SIDE: u32 = 8;

impl Default for VisibilityField {
    fn default() -> Self {
        VisibilityField::new(DEFAULT_SIDE)
    }
}

impl VisibilityField {
    /// An empty field whose cells hold `side × side` texels (`side` in 1..=64).
    pub fn new(side: u32) -> Self {
        VisibilityField {
            side: side.clamp(1, 64),
            sources: 0,
            prior: PRIOR_FREE,
            cells: KeyMap::default(),
            counts: Vec::new(),
            brought: Vec::new(),
            totals: Vec::new(),
            normals: Vec::new(),
            pooled: Vec::new(),
            darkest: Vec::new(),
            planned: None,
            expected_rejection: Vec::new(),
            acceptances: Vec::new(),
            acceptances_at: Vec::new(),
        }
    }

    /// This field with `prior` pseudo-observations per texel and cell instead of
    /// [`PRIOR_FREE`] (negative or non-finite values count as 0).
    pub fn with_prior(self, prior: f32) -> Self {
        VisibilityField {
            prior: if prior.is_finite() {
                prior.max(0.0)
            } else {
                0.0
            },
            ..self
        }
    }

    /// This field with `sources` counts per cell, besides its texels, of the rays the host
    /// says aimed at each source (at most [`MOST_SOURCES`]).
    pub fn with_sources(self, sources: u32) -> Self {
        VisibilityField {
            sources: sources.min(MOST_SOURCES),
            ..self
        }
    }

    /// Texels per side of a cell's map.
    pub fn side(&self) -> u32 {
        self.side
    }

    /// Sources counted per cell.
    pub fn sources(&self) -> u32 {
        self.sources
    }

    /// Counts held per cell: its texels, then its sources.
    fn stride(&self) -> usize {
        (self.side * self.side + self.sources) as usize
    }

    /// Number of cells learned.
    pub fn cell_count(&self) -> usize {
        self.totals.len()
    }

    /// Rays learned from, over all cells.
    pub fn traced(&self) -> u64 {
        self.totals.iter().map(|total| total.traced as u64).sum()
    }

    /// Bytes held by the field.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.cells.capacity() * (std::mem::size_of::<(CellKey, u32)>() + 1)
            + (self.counts.capacity() + self.totals.capacity()) * std::mem::size_of::<TexelCounts>()
            + (self.pooled.capacity()
                + self.darkest.capacity()
                + self.expected_rejection.capacity()
                + self.acceptances.capacity()
                + self.acceptances_at.capacity())
                * std::mem::size_of::<f32>()
            + self.brought.capacity() * std::mem::size_of::<f64>()
            + self.normals.capacity() * std::mem::size_of::<NormalSum>()
    }

    /// Works out, for every cell, the share of its candidates that roulette at `cost_ratio`
    /// would skip ([`FieldCell::expected_rejection`]), so that gathers can tell at once
    /// whether roulette pays there, and in the cells where it pays, every texel's
    /// acceptance. Call it once a pass's observations are merged, with the cost ratio of
    /// the next pass; without it both are worked out per lookup.
    pub fn plan(&mut self, cost_ratio: f32) {
        if self.planned == Some(cost_ratio) {
            return;
        }
        let (texels, stride) = ((self.side * self.side) as usize, self.stride());
        self.expected_rejection = (0..self.totals.len())
            .map(|cell| {
                let counts = &self.counts[cell * stride..cell * stride + texels];
                expected_rejection(counts, self.totals[cell], self.prior, cost_ratio)
            })
            .collect();
        self.planned = Some(cost_ratio);
        self.plan_acceptances(cost_ratio);
    }

    /// Works out the texels' acceptances at `cost_ratio` of the cells where roulette pays
    /// at it (the planned ratio), as [`FieldCell::acceptance`] would per candidate.
    fn plan_acceptances(&mut self, cost_ratio: f32) {
        self.acceptances_at.clear();
        let mut acceptances = Vec::new();
        let mut starts = vec![u32::MAX; self.totals.len()];
        for (index, start) in starts.iter_mut().enumerate() {
            let cell = self.cell_at(CellIndex((index * self.stride()) as u32));
            if cell.worth_rolling(cost_ratio) {
                let visibility = cell.visibility();
                *start = acceptances.len() as u32;
                acceptances.extend(
                    cell.counts.iter().map(|&counts| {
                        texel_acceptance(counts, visibility, self.prior, cost_ratio)
                    }),
                );
            }
        }
        self.acceptances = acceptances;
        self.acceptances_at = starts;
    }

    /// After [`VisibilityField::plan`]: the share of the rays recorded so far whose cells
    /// roulette pays in at the planned ratio ([`FieldCell::worth_rolling`]), or `None`
    /// while less than half of them lie in cells with [`LEAST_EVIDENCE`] (too early to
    /// tell). A host may stop learning where the share is small: the field would stand
    /// aside nearly everywhere.
    pub fn rolling_share(&self) -> Option<f32> {
        let cost_ratio = self.planned?;
        let (mut all, mut known, mut rolling) = (0u64, 0u64, 0u64);
        for (index, total) in self.totals.iter().enumerate() {
            let rays = u64::from(total.traced);
            all += rays;
            if total.traced >= LEAST_EVIDENCE {
                known += rays;
                let cell = self.cell_at(CellIndex((index * self.stride()) as u32));
                if cell.worth_rolling(cost_ratio) {
                    rolling += rays;
                }
            }
        }
        (all > 0 && 2 * known >= all).then(|| rolling as f32 / all as f32)
    }

    /// The cell `key`, if any ray was ever recorded there.
    #[inline]
    pub fn cell(&self, key: &CellKey) -> Option<FieldCell<'_>> {
        self.find(key).map(|index| self.cell_at(index))
    }

    /// Where the cell `key` is, if any ray was ever recorded there: one hash probe, whose
    /// answer a host may keep for the next gathers in the same cell while the field is
    /// unchanged (a pass).
    #[inline]
    pub fn find(&self, key: &CellKey) -> Option<CellIndex> {
        self.cells.get(key).map(|&first| CellIndex(first))
    }

    /// The cell at `index` (from [`VisibilityField::find`] on this field since its last
    /// merge).
    #[inline]
    pub fn cell_at(&self, CellIndex(first): CellIndex) -> FieldCell<'_> {
        let (texels, first) = ((self.side * self.side) as usize, first as usize);
        let index = first / self.stride();
        let sources = self.sources as usize;
        FieldCell {
            counts: &self.counts[first..first + texels],
            pooled: &self.pooled[index * texels..(index + 1) * texels],
            sources: &self.counts[first + texels..first + self.stride()],
            brought: &self.brought[index * sources..(index + 1) * sources],
            total: self.totals[index],
            normal: self.normals[index],
            darkest: self.darkest[index],
            planned: self
                .planned
                .map(|ratio| (ratio, self.expected_rejection[index])),
            acceptances: self.planned_acceptances(index),
            side: self.side,
            prior: self.prior,
        }
    }

    /// Cell `index`'s texels' acceptances at the planned cost ratio, if worked out.
    fn planned_acceptances(&self, index: usize) -> &[f32] {
        let texels = (self.side * self.side) as usize;
        match self.acceptances_at.get(index) {
            Some(&first) if first != u32::MAX && self.planned.is_some() => {
                &self.acceptances[first as usize..first as usize + texels]
            }
            _ => &[],
        }
    }

    /// Adds what a tile observed (observations made with another `side` or number of
    /// sources are refused).
    pub fn merge(&mut self, observations: &FieldObservations) {
        self.merge_all([observations]);
    }

    /// Adds what several tiles observed (a pass's), then works out each cell they touched
    /// once: the same field as merging them one by one (in any order for the counts; in
    /// the same order for what sources brought), for less work (a
    /// cell that several tiles saw is pooled once, not once per tile).
    pub fn merge_all<'o>(&mut self, all: impl IntoIterator<Item = &'o FieldObservations>) {
        let mut touched = Vec::new();
        for observations in all {
            assert_eq!(
                (observations.side, observations.sources),
                (self.side, self.sources),
                "observations of another map size"
            );
            for (key, seen) in &observations.cells {
                touched.push(self.add(*key, seen));
            }
        }
        if !touched.is_empty() {
            self.planned = None;
            self.acceptances.clear();
            self.acceptances_at.clear();
        }
        touched.sort_unstable();
        touched.dedup();
        for index in touched {
            self.pool(index);
        }
    }

    /// Adds `seen` to the counts of cell `key` (made if new); returns its index.
    fn add(&mut self, key: CellKey, seen: &CellSeen) -> usize {
        let (texels, stride) = ((self.side * self.side) as usize, self.stride());
        let next = self.counts.len() as u32;
        let first = *self.cells.entry(key).or_insert_with(|| next) as usize;
        if first == next as usize {
            self.counts.resize(first + stride, TexelCounts::default());
            self.brought
                .resize(self.brought.len() + self.sources as usize, 0.0);
            self.totals.push(TexelCounts::default());
            self.normals.push(NormalSum::default());
            self.pooled.resize(self.pooled.len() + texels, 1.0);
            self.darkest.push(1.0);
        }
        let index = first / stride;
        for (slot, &count) in seen.counts.iter().enumerate() {
            self.counts[first + slot].add(count);
            if slot < texels {
                self.totals[index].add(count);
            }
        }
        let brought = &mut self.brought[index * self.sources as usize..];
        for (sum, &value) in brought.iter_mut().zip(seen.brought.iter()) {
            *sum += value;
        }
        self.normals[index].add(seen.normal);
        index
    }

    /// Works out cell `index`'s darkest texel and pooled visibilities from its counts.
    fn pool(&mut self, index: usize) {
        let (texels, stride) = ((self.side * self.side) as usize, self.stride());
        let counts = &self.counts[index * stride..index * stride + texels];
        let cell = visibility(self.totals[index], self.prior);
        self.darkest[index] = counts
            .iter()
            .map(|&c| texel_visibility(c, cell, self.prior))
            .fold(1.0, f32::min);
        self.pooled[index * texels..(index + 1) * texels].copy_from_slice(
            &pooling::pooled_visibilities(counts, self.side, cell, self.prior),
        );
    }
}

/// The normals recorded in a cell: their sum and their number.
#[derive(Clone, Copy, Debug, Default)]
struct NormalSum {
    sum: [f64; 3],
    count: f64,
}

/// A cell's normals agree where their mean is at least this long (1: all the same). Below
/// it (a cell across a fold or a sharp curve) the cell reports no normal.
pub const AGREEING_NORMALS: f64 = 0.9;

impl NormalSum {
    /// Adds `other`'s normals.
    fn add(&mut self, other: NormalSum) {
        for (sum, value) in self.sum.iter_mut().zip(other.sum) {
            *sum += value;
        }
        self.count += other.count;
    }

    /// Adds one normal (unit; a non-finite one is ignored).
    fn record(&mut self, normal: [f32; 3]) {
        if normal.iter().all(|c| c.is_finite()) {
            self.add(NormalSum {
                sum: normal.map(f64::from),
                count: 1.0,
            });
        }
    }

    /// The direction of the mean normal, where the normals agree ([`AGREEING_NORMALS`]).
    fn mean_direction(&self) -> Option<[f32; 3]> {
        let [x, y, z] = self.sum;
        let length = (x * x + y * y + z * z).sqrt();
        (self.count > 0.0 && length >= AGREEING_NORMALS * self.count)
            .then(|| self.sum.map(|c| (c / length) as f32))
    }
}

/// The most sources a field counts per cell.
pub const MOST_SOURCES: u32 = 64;

/// Pseudo-observations added to every cell (of a free ray) and to every texel (at its
/// cell's visibility): a texel seen a few times stays like its cell, and only its own
/// evidence pulls it down.
pub const PRIOR_FREE: f32 = 2.0;

/// The lowest acceptance the field gives: a free ray in a texel the field calls blocked
/// weighs at most 1 / this.
pub const LOWEST_ACCEPTANCE: f32 = 0.1;

/// A cell with fewer traced rays than this is not trusted yet: its gathers trace every
/// candidate.
pub const LEAST_EVIDENCE: u32 = 32;

/// A gather rolls only where roulette is expected to skip at least this share of its
/// candidates. Below it, the work of rolling every candidate (its texel, its acceptance,
/// the timed and recording gathers) costs about what the skipped rays save, since a blocked
/// ray skips its lookups anyway: measured, skipping a third of the candidates at n = 16
/// saved no time. 0.45 was chosen on four scenes and held on three others (the
/// repository's BENCHMARKS.md, section 5.6); a rule from measured costs should replace it.
pub const WORTH_REJECTING: f32 = 0.45;

/// The share of a cell's candidates that roulette at `cost_ratio` skips, estimated from
/// where its traced rays went: Σ over texels of (rays there / rays) · (1 − acceptance).
pub fn expected_rejection(
    counts: &[TexelCounts],
    total: TexelCounts,
    prior: f32,
    cost_ratio: f32,
) -> f32 {
    if total.traced == 0 {
        return 0.0;
    }
    let cell = visibility(total, prior);
    let skipped: f32 = counts
        .iter()
        .filter(|c| c.traced > 0)
        .map(|&c| c.traced as f32 * (1.0 - texel_acceptance(c, cell, prior, cost_ratio)))
        .sum();
    skipped / total.traced as f32
}

/// The visibility of counts with `prior` free pseudo-observations (1 with no evidence).
#[inline]
pub fn visibility(counts: TexelCounts, prior: f32) -> f32 {
    let traced = counts.traced as f32 + prior;
    if traced > 0.0 {
        (counts.free as f32 + prior) / traced
    } else {
        1.0
    }
}

/// A texel's visibility given its cell's: `prior` pseudo-observations at the cell's
/// visibility are added to its own. A texel seen a few times is taken to be like its cell
/// (and roulette, which rolls only texels darker than their cell, leaves it alone); only
/// its own evidence makes it darker. (Pseudo-observations of a *free* ray, as the cell
/// itself has, kept a texel that is always blocked but seen only tens of times about as
/// visible as a dark cell, so roulette left it alone.)
#[inline]
pub fn texel_visibility(counts: TexelCounts, cell: f32, prior: f32) -> f32 {
    let traced = counts.traced as f32 + prior;
    if traced > 0.0 {
        (counts.free as f32 + prior * cell) / traced
    } else {
        cell
    }
}

/// The cost-optimal acceptance of a candidate toward a texel of visibility `texel` in a cell
/// of visibility `cell`, when a candidate costs `cost_ratio` times what tracing it adds:
///
///   a = min(1, √((1 + ρ) · v_texel / v_cell)),  floored at [`LOWEST_ACCEPTANCE`].
///
/// It minimises variance × cost over a gather whose candidates carry alike (the derivation
/// is in the repository's docs/technique.md). Tracing every candidate whose texel is at
/// least `v_cell / (1 + ρ)` visible, it rolls only where rays are dear next to the rest of a
/// candidate's work and the texel is much darker than the cell.
#[inline]
pub fn acceptance(texel: f32, cell: f32, cost_ratio: f32) -> f32 {
    ((1.0 + cost_ratio) * texel / cell)
        .sqrt()
        .clamp(LOWEST_ACCEPTANCE, 1.0)
}

/// The [`acceptance`] of a texel of `counts` in a cell of visibility `cell`.
#[inline]
fn texel_acceptance(counts: TexelCounts, cell: f32, prior: f32, cost_ratio: f32) -> f32 {
    acceptance(texel_visibility(counts, cell, prior), cell, cost_ratio)
}

/// One cell of the field, for the lookups of one gather.
#[derive(Clone, Copy, Debug)]
pub struct FieldCell<'a> {
    counts: &'a [TexelCounts],
    /// Its texels' visibilities, pooled with their blocks' ([`pooling`]).
    pooled: &'a [f32],
    /// The counts of the rays aimed at each source.
    sources: &'a [TexelCounts],
    /// What the rays that reached each source brought.
    brought: &'a [f64],
    total: TexelCounts,
    /// The normals recorded in it.
    normal: NormalSum,
    /// The lowest visibility of its texels.
    darkest: f32,
    /// The planned cost ratio and this cell's expected rejection at it.
    planned: Option<(f32, f32)>,
    /// Its texels' acceptances at the planned cost ratio, where roulette pays at it (else
    /// empty).
    acceptances: &'a [f32],
    side: u32,
    prior: f32,
}

impl FieldCell<'_> {
    /// The counts of the texel toward `direction` (world space, unit).
    #[inline]
    pub fn texel(&self, direction: [f32; 3]) -> TexelCounts {
        self.counts[octahedral::texel_of(direction, self.side)]
    }

    /// Texels per side of the cell's map.
    pub fn side(&self) -> u32 {
        self.side
    }

    /// The visibility of texel `index` (row-major, as [`octahedral::texel_of`] numbers
    /// them) pooled with its blocks' ([`pooling`]), or `None` where no ray of the cell went
    /// into its 2 × 2 block. Pooling lends a texel seen a few times its neighbours'
    /// evidence; since the same rays count at every level, the estimate is overconfident
    /// where rays are few. A proposal that keeps a defensive share can use it (a wrong
    /// estimate costs a bounded factor in variance); roulette, whose mistakes cost 1 / a,
    /// reads each texel's own evidence ([`FieldCell::acceptance`]).
    pub fn pooled_visibility_at(&self, index: usize) -> Option<f32> {
        let estimate = *self.pooled.get(index)?;
        pooling::block_seen(self.counts, self.side, index).then_some(estimate)
    }

    /// The visibility of the rays aimed at `source`, with the field's prior (centred on the
    /// cell's visibility, as a texel's), or `None` where the field does not count it or no
    /// such ray was recorded.
    pub fn source_visibility(&self, source: usize) -> Option<f32> {
        self.sources_visibility(source..source + 1)
    }

    /// The visibility of the rays aimed at any of `sources` (the parts of one light, say),
    /// as [`FieldCell::source_visibility`] gives it for one.
    pub fn sources_visibility(&self, sources: Range<usize>) -> Option<f32> {
        let counts = self.sources_counts(sources);
        (counts.traced > 0).then(|| texel_visibility(counts, self.visibility(), self.prior))
    }

    /// The counts of the rays aimed at `source` (zero where the field does not count it).
    pub fn source_counts(&self, source: usize) -> TexelCounts {
        self.sources_counts(source..source + 1)
    }

    /// The counts of the rays aimed at any of `sources` (those the field counts).
    pub fn sources_counts(&self, sources: Range<usize>) -> TexelCounts {
        let mut total = TexelCounts::default();
        for counts in self.sources.get(sources).unwrap_or_default() {
            total.add(*counts);
        }
        total
    }

    /// The sum of what the rays that reached `source` brought, as the host recorded it
    /// ([`CellRecorder::record_brought`]; 0 where the field does not count it). Over a
    /// cell's sources these sums share one denominator (the cell's gathers), so their
    /// ratios estimate the sources' shares of the light the cell receives.
    pub fn source_brought(&self, source: usize) -> f64 {
        self.sources_brought(source..source + 1)
    }

    /// What the rays that reached any of `sources` brought (summed in the sources' order).
    pub fn sources_brought(&self, sources: Range<usize>) -> f64 {
        self.brought.get(sources).unwrap_or_default().iter().sum()
    }

    /// The mean of the normals recorded in the cell ([`CellRecorder::record_normal`]), as a
    /// unit vector, if they agree: `None` where none was recorded or their mean is shorter
    /// than [`AGREEING_NORMALS`] (the cell spans a fold or a sharp curve).
    pub fn normal(&self) -> Option<[f32; 3]> {
        self.normal.mean_direction()
    }

    /// The lowest visibility of the cell's texels.
    pub fn darkest(&self) -> f32 {
        self.darkest
    }

    /// The sum over the cell's texels.
    pub fn total(&self) -> TexelCounts {
        self.total
    }

    /// The cell's visibility, with the field's prior.
    pub fn visibility(&self) -> f32 {
        visibility(self.total, self.prior)
    }

    /// Whether roulette can pay here at this cost ratio: the cell has [`LEAST_EVIDENCE`]
    /// rays, and roulette would skip at least [`WORTH_REJECTING`] of its candidates.
    /// Elsewhere a gather should trace every candidate and do no map work.
    pub fn worth_rolling(&self, cost_ratio: f32) -> bool {
        self.total.traced >= LEAST_EVIDENCE
            && (1.0 + cost_ratio) * self.darkest < self.visibility()
            && self.expected_rejection(cost_ratio) >= WORTH_REJECTING
    }

    /// The share of this cell's candidates that roulette at `cost_ratio` skips (see
    /// [`expected_rejection`]); read from the field's plan when it was made for this ratio.
    pub fn expected_rejection(&self, cost_ratio: f32) -> f32 {
        match self.planned {
            Some((ratio, share)) if ratio == cost_ratio => share,
            _ => expected_rejection(self.counts, self.total, self.prior, cost_ratio),
        }
    }

    /// [`acceptance`] toward `direction`: read from the field's plan where it was made at
    /// this cost ratio and roulette pays here, else worked out (the same number).
    #[inline]
    pub fn acceptance(&self, direction: [f32; 3], cost_ratio: f32) -> f32 {
        // Once per candidate: this is the hot path of a rolling gather.
        let texel = octahedral::texel_of(direction, self.side);
        match (self.planned, self.acceptances.get(texel)) {
            (Some((ratio, _)), Some(&planned)) if ratio == cost_ratio => planned,
            _ => texel_acceptance(
                self.counts[texel],
                self.visibility(),
                self.prior,
                cost_ratio,
            ),
        }
    }
}

/// Per-thread scratch: the rays one tile traced in a pass, counted per cell and texel.
#[derive(Clone, Debug)]
pub struct FieldObservations {
    side: u32,
    sources: u32,
    cells: KeyMap<CellSeen>,
}

/// What a tile saw in one cell: its texels' and sources' counts, and what the rays that
/// reached each source brought.
#[derive(Clone, Debug)]
struct CellSeen {
    counts: Box<[TexelCounts]>,
    brought: Box<[f64]>,
    normal: NormalSum,
}

impl FieldObservations {
    /// Empty observations for cells of `side × side` texels (as [`VisibilityField::new`]).
    pub fn new(side: u32) -> Self {
        FieldObservations {
            side: side.clamp(1, 64),
            sources: 0,
            cells: KeyMap::default(),
        }
    }

    /// These observations with `sources` counts per cell (as
    /// [`VisibilityField::with_sources`]).
    pub fn with_sources(self, sources: u32) -> Self {
        FieldObservations {
            sources: sources.min(MOST_SOURCES),
            ..self
        }
    }

    /// Records one traced ray from cell `key` toward `direction`: free or blocked.
    #[inline]
    pub fn record(&mut self, key: CellKey, direction: [f32; 3], free: bool) {
        self.cell_mut(key).record(direction, free);
    }

    /// The counts of cell `key`, to record a gather's rays with one hash probe.
    pub fn cell_mut(&mut self, key: CellKey) -> CellRecorder<'_> {
        let slots = (self.side * self.side + self.sources) as usize;
        let sources = self.sources as usize;
        let seen = self.cells.entry(key).or_insert_with(|| CellSeen {
            counts: vec![TexelCounts::default(); slots].into_boxed_slice(),
            brought: vec![0.0; sources].into_boxed_slice(),
            normal: NormalSum::default(),
        });
        CellRecorder {
            counts: &mut seen.counts,
            brought: &mut seen.brought,
            normal: &mut seen.normal,
            side: self.side,
        }
    }

    /// Forgets everything recorded (keeping the allocation).
    pub fn clear(&mut self) {
        self.cells.clear();
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        let slots = (self.side * self.side + self.sources) as usize;
        std::mem::size_of::<Self>()
            + self.cells.capacity() * std::mem::size_of::<(CellKey, CellSeen)>()
            + self.cells.len()
                * (slots * std::mem::size_of::<TexelCounts>()
                    + self.sources as usize * std::mem::size_of::<f64>())
    }
}

/// One cell's counts in [`FieldObservations`], for the rays of one gather.
pub struct CellRecorder<'a> {
    counts: &'a mut [TexelCounts],
    brought: &'a mut [f64],
    normal: &'a mut NormalSum,
    side: u32,
}

impl CellRecorder<'_> {
    /// Records the normal (unit) of one gather in the cell: the cell's mean normal
    /// ([`FieldCell::normal`]) lets a host weigh the cell's directions by their cosine.
    #[inline]
    pub fn record_normal(&mut self, normal: [f32; 3]) {
        self.normal.record(normal);
    }

    /// Records one traced ray toward `direction`: free or blocked.
    #[inline]
    pub fn record(&mut self, direction: [f32; 3], free: bool) {
        count(
            &mut self.counts[octahedral::texel_of(direction, self.side)],
            free,
        );
    }

    /// Records that a traced ray aimed at `source` was free or blocked (a source the
    /// observations do not count is ignored).
    #[inline]
    pub fn record_source(&mut self, source: usize, free: bool) {
        let texels = (self.side * self.side) as usize;
        if let Some(counts) = self.counts[texels..].get_mut(source) {
            count(counts, free);
        }
    }

    /// Adds what a ray that reached `source` brought, weighed as the host's estimate weighs
    /// it (its value over its density, times any roulette weight), so that the sums over
    /// all of a cell's candidates estimate each source's part of its light (a source the
    /// observations do not count is ignored).
    #[inline]
    pub fn record_brought(&mut self, source: usize, value: f64) {
        if let Some(sum) = self.brought.get_mut(source) {
            *sum += value;
        }
    }
}

/// One more traced ray in `counts`, free or not.
#[inline]
fn count(counts: &mut TexelCounts, free: bool) {
    counts.traced = counts.traced.saturating_add(1);
    counts.free = counts.free.saturating_add(u32::from(free));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell's normal is the mean of those its gathers recorded, merged from every tile
    /// in any split; normals that disagree (a fold) give none.
    #[test]
    fn a_cell_knows_the_mean_normal_of_its_gathers() {
        let flat = CellKey::new([0.5; 3], [0.0, 1.0, 0.0], 0);
        let fold = CellKey::new([4.5; 3], [0.0, 1.0, 0.0], 0);
        let tilted = [0.6f32, 0.8, 0.0];
        let mut field = VisibilityField::new(4);
        for tile in 0..2 {
            let mut observations = FieldObservations::new(4);
            for gather in 0..3 {
                let mut cell = observations.cell_mut(flat);
                cell.record([0.0, 1.0, 0.0], true);
                cell.record_normal(if (tile + gather) % 2 == 0 {
                    [0.0, 1.0, 0.0]
                } else {
                    tilted
                });
                let mut cell = observations.cell_mut(fold);
                cell.record([0.0, 1.0, 0.0], true);
                cell.record_normal(if gather == 0 {
                    [1.0, 0.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                });
            }
            field.merge(&observations);
        }
        // Three of each normal: the mean (0.3, 0.9, 0) normalised.
        let normal = field
            .cell(&flat)
            .and_then(|cell| cell.normal())
            .expect("agreeing");
        let length = (0.3f32 * 0.3 + 0.9 * 0.9).sqrt();
        for (got, want) in normal.iter().zip([0.3 / length, 0.9 / length, 0.0]) {
            assert!((got - want).abs() < 1e-6, "{normal:?}");
        }
        // Two of six at right angles: the mean is 0.75 long.
        assert_eq!(field.cell(&fold).and_then(|cell| cell.normal()), None);
    }

    #[test]
    fn merged_observations_are_found_by_cell_and_direction() {
        let mut field = VisibilityField::new(4);
        let key = CellKey::new([0.3, 0.1, -2.0], [0.0, 1.0, 0.0], -3);
        let other = CellKey::new([0.3, 0.1, -2.0], [0.0, -1.0, 0.0], -3);
        assert_ne!(key, other, "opposite normals are different cells");
        let mut a = FieldObservations::new(4);
        let mut b = FieldObservations::new(4);
        for k in 0..10 {
            a.record(key, [0.0, 1.0, 0.0], k < 7);
            b.record(key, [0.0, 0.0, -1.0], false);
        }
        b.record(other, [1.0, 0.0, 0.0], true);
        field.merge(&a);
        field.merge(&b);
        let cell = field.cell(&key).expect("learned");
        assert_eq!(
            cell.texel([0.0, 1.0, 0.0]),
            TexelCounts {
                free: 7,
                traced: 10
            }
        );
        assert_eq!(
            cell.texel([0.0, 0.0, -1.0]),
            TexelCounts {
                free: 0,
                traced: 10
            }
        );
        assert_eq!(
            cell.total(),
            TexelCounts {
                free: 7,
                traced: 20
            }
        );
        assert_eq!(field.cell(&other).unwrap().total().traced, 1);
        assert!(field
            .cell(&CellKey::new([5.0, 0.0, 0.0], [0.0, 1.0, 0.0], -3))
            .is_none());
        assert_eq!(field.cell_count(), 2);
    }

    #[test]
    fn a_cell_pools_its_texels_with_their_blocks() {
        let mut field = VisibilityField::new(4);
        let key = CellKey::new([0.0; 3], [0.0, 0.0, 1.0], 0);
        let mut observed = FieldObservations::new(4);
        // Many blocked rays straight up, one free ray just beside them (same 2 × 2 block),
        // and many free rays sideways: a bright cell with a dark block.
        let up = [0.0, 0.0, 1.0];
        let beside = octahedral::direction_of([0.8, 0.6]);
        let (t_up, t_beside) = (octahedral::texel_of(up, 4), octahedral::texel_of(beside, 4));
        assert_ne!(t_up, t_beside);
        assert_eq!(
            (t_up / 4 / 2, t_up % 4 / 2),
            (t_beside / 4 / 2, t_beside % 4 / 2)
        );
        for _ in 0..100 {
            observed.record(key, up, false);
        }
        observed.record(key, beside, true);
        for _ in 0..300 {
            observed.record(key, [-1.0, 0.0, 0.0], true);
        }
        field.merge(&observed);
        let cell = field.cell(&key).unwrap();
        let beside_alone = texel_visibility(cell.texel(beside), cell.visibility(), PRIOR_FREE);
        let pooled = cell.pooled_visibility_at(t_beside).expect("seen");
        assert!(
            pooled < 0.5 * beside_alone,
            "{pooled} against {beside_alone}"
        );
        // No ray went into the top-left block (texels 0, 1, 4 and 5): the cell knows
        // nothing there.
        assert_eq!(cell.pooled_visibility_at(5), None);
    }

    #[test]
    fn merging_in_any_order_gives_the_same_field() {
        let keys: Vec<CellKey> = (0..50)
            .map(|i| CellKey::new([i as f32 * 0.37, 0.0, 1.0], [1.0, 0.0, 0.0], 0))
            .collect();
        let tiles: Vec<FieldObservations> = (0..5)
            .map(|t| {
                let mut o = FieldObservations::new(8);
                for (i, &key) in keys.iter().enumerate() {
                    o.record(key, [0.6, 0.8, 0.0], (i + t) % 3 == 0);
                }
                o
            })
            .collect();
        let mut forward = VisibilityField::new(8);
        tiles.iter().for_each(|o| forward.merge(o));
        let mut backward = VisibilityField::new(8);
        tiles.iter().rev().for_each(|o| backward.merge(o));
        let mut together = VisibilityField::new(8);
        together.merge_all(&tiles);
        let texel = octahedral::texel_of([0.6, 0.8, 0.0], 8);
        for key in &keys {
            let (f, b) = (forward.cell(key).unwrap(), backward.cell(key).unwrap());
            assert_eq!(f.total(), b.total());
            assert_eq!(f.texel([0.6, 0.8, 0.0]), b.texel([0.6, 0.8, 0.0]));
            let t = together.cell(key).unwrap();
            assert_eq!(t.total(), f.total());
            assert_eq!(t.darkest(), f.darkest());
            assert!(t.darkest() < 1.0, "pooled and worked out");
            assert_eq!(t.pooled_visibility_at(texel), f.pooled_visibility_at(texel));
            assert_eq!(t.pooled_visibility_at(texel), b.pooled_visibility_at(texel));
        }
    }

    #[test]
    fn acceptance_trusts_evidence_and_weighs_the_cost_of_a_ray() {
        let seen = |free, traced| visibility(TexelCounts { free, traced }, PRIOR_FREE);
        assert_eq!(seen(0, 0), 1.0);
        assert!(seen(0, 3) > 0.39, "three blocked rays are not proof");
        // A texel a quarter as visible as its cell, with candidates that cost as much as
        // their rays (ρ = 1): √(2 · 1/4).
        assert!((acceptance(0.1, 0.4, 1.0) - 0.5f32.sqrt()).abs() < 1e-6);
        // Cheap rays next to the rest of a candidate's work: trace everything.
        assert_eq!(acceptance(0.1, 0.4, 3.0), 1.0);
        assert_eq!(acceptance(0.0, 0.4, 0.0), LOWEST_ACCEPTANCE);
        assert_eq!(acceptance(0.5, 0.5, 0.0), 1.0);
    }

    #[test]
    fn a_texel_is_like_its_cell_until_its_own_evidence_says_otherwise() {
        let cell = 0.2;
        let unseen = TexelCounts::default();
        assert_eq!(texel_visibility(unseen, cell, PRIOR_FREE), cell);
        // Unseen, it is traced whatever the cost ratio.
        assert_eq!(
            acceptance(texel_visibility(unseen, cell, 2.0), cell, 0.0),
            1.0
        );
        let blocked = |traced| texel_visibility(TexelCounts { free: 0, traced }, cell, 2.0);
        assert!(blocked(3) > 0.07, "three blocked rays are not proof");
        assert!(blocked(300) < 0.002);
    }

    #[test]
    fn a_cell_stands_aside_unless_roulette_can_pay() {
        let mut field = VisibilityField::new(4);
        let key = CellKey::new([0.0; 3], [0.0, 1.0, 0.0], 0);
        let mut observed = FieldObservations::new(4);
        // 30 rays free toward +y; 100 blocked toward −x.
        for k in 0..100 {
            if k < 30 {
                observed.record(key, [0.0, 1.0, 0.0], true);
            }
            observed.record(key, [-1.0, 0.0, 0.0], false);
        }
        field.merge(&observed);
        let cell = field.cell(&key).unwrap();
        assert!(cell.worth_rolling(1.0), "a dark texel in a bright cell");
        // The texel: 0 free of 100, plus 2 pseudo-observations at the cell's visibility
        // (30 + 2) / (130 + 2); acceptance √(2 · texel / cell).
        let cell_visibility = 32.0f32 / 132.0;
        let texel = (2.0 * cell_visibility) / 102.0;
        let expected = (2.0 * texel / cell_visibility).sqrt();
        assert!((cell.acceptance([-1.0, 0.0, 0.0], 1.0) - expected).abs() < 1e-6);
        assert_eq!(cell.acceptance([0.0, 1.0, 0.0], 1.0), 1.0);
        assert!(!cell.worth_rolling(40.0), "rays too cheap to skip");
    }

    #[test]
    fn a_cell_rolls_only_where_roulette_skips_enough() {
        let key = CellKey::new([0.0; 3], [0.0, 1.0, 0.0], 0);
        let field_with = |blocked_share: u32| {
            let mut observed = FieldObservations::new(4);
            for k in 0..1000 {
                let blocked = k % 100 < blocked_share;
                let direction = if blocked {
                    [-1.0, 0.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                };
                observed.record(key, direction, !blocked);
            }
            let mut field = VisibilityField::new(4);
            field.merge(&observed);
            field
        };
        // 1% of the rays go to a blocked texel: roulette would skip about 1% of candidates.
        let rare = field_with(1);
        let cell = rare.cell(&key).unwrap();
        assert!(cell.expected_rejection(1.0) < 0.02);
        assert!(
            !cell.worth_rolling(1.0),
            "too little to skip for the map work"
        );
        // 60%: at ρ = 1 a blocked texel (0 free of 600, plus 2 pseudo-observations at the
        // cell's visibility v) is accepted with √(2 · (2v / 602) / v) ≈ 0.0815, floored.
        let mut field = field_with(60);
        let unplanned = field.cell(&key).unwrap().expected_rejection(1.0);
        let a = (2.0f32 * 2.0 / 602.0).sqrt().max(LOWEST_ACCEPTANCE);
        assert!((unplanned - 0.6 * (1.0 - a)).abs() < 1e-5);
        assert!(field.cell(&key).unwrap().worth_rolling(1.0));
        // A plan gives the same share without a pass over the texels.
        field.plan(1.0);
        let cell = field.cell(&key).unwrap();
        assert_eq!(cell.planned, Some((1.0, unplanned)));
        assert_eq!(cell.expected_rejection(1.0), unplanned);
        assert!(
            cell.expected_rejection(4.0) < unplanned,
            "another ratio is worked out"
        );
        // A merge makes the plan stale.
        let mut more = FieldObservations::new(4);
        more.record(key, [0.0, 1.0, 0.0], true);
        field.merge(&more);
        assert_eq!(field.cell(&key).unwrap().planned, None);
        assert!(field.cell(&key).unwrap().acceptances.is_empty());
    }

    #[test]
    fn planned_acceptances_are_the_acceptances_worked_out() {
        let key = CellKey::new([0.0; 3], [0.0, 1.0, 0.0], 0);
        let mut observed = FieldObservations::new(8);
        let mut rng = crate::rng::Pcg32::new(3, 9);
        // Blocked below the horizon's band, free above, with some noise: many distinct
        // texel counts.
        for _ in 0..5000 {
            let d = crate::sampling::uniform_sphere([rng.next_f32(), rng.next_f32()]);
            let free = d.y > 0.5 || rng.next_f32() < 0.01;
            observed.record(key, d.into(), free);
        }
        let mut field = VisibilityField::new(8);
        field.merge(&observed);
        let directions: Vec<[f32; 3]> = (0..2000)
            .map(|_| crate::sampling::uniform_sphere([rng.next_f32(), rng.next_f32()]).into())
            .collect();
        let unplanned = field.cell(&key).unwrap();
        let worked_out: Vec<f32> = directions
            .iter()
            .map(|&d| unplanned.acceptance(d, 1.0))
            .collect();
        field.plan(1.0);
        let cell = field.cell(&key).unwrap();
        assert!(cell.worth_rolling(1.0));
        assert_eq!(cell.acceptances.len(), 64, "planned where roulette pays");
        for (&d, expected) in directions.iter().zip(worked_out) {
            assert_eq!(cell.acceptance(d, 1.0), expected, "toward {d:?}");
        }
        // Another cost ratio is worked out, not read from the plan.
        let direct = texel_acceptance(cell.texel([0.0, -1.0, 0.0]), cell.visibility(), 2.0, 4.0);
        assert_eq!(cell.acceptance([0.0, -1.0, 0.0], 4.0), direct);
    }

    #[test]
    fn the_rolling_share_says_when_learning_can_stop() {
        let mut field = VisibilityField::new(4);
        assert_eq!(field.rolling_share(), None, "nothing planned");
        let dark = CellKey::new([0.0; 3], [0.0, 1.0, 0.0], 0);
        let open = CellKey::new([9.0; 3], [0.0, 1.0, 0.0], 0);
        let mut observed = FieldObservations::new(4);
        for k in 0..10 {
            // Too few rays in the dark cell to judge it.
            observed.record(dark, [-1.0, 0.0, 0.0], false);
            observed.record(dark, [0.0, 1.0, 0.0], k % 2 == 0);
        }
        for _ in 0..10 {
            observed.record(open, [0.0, 1.0, 0.0], true);
        }
        field.merge(&observed);
        field.plan(1.0);
        assert_eq!(field.rolling_share(), None, "too early to tell");
        let mut more = FieldObservations::new(4);
        for k in 0..200 {
            more.record(dark, [-1.0, 0.0, 0.0], false);
            more.record(dark, [-1.0, 0.0, 0.0], false);
            more.record(dark, [0.0, 1.0, 0.0], k % 2 == 0);
            more.record(open, [0.0, 1.0, 0.0], true);
        }
        field.merge(&more);
        field.plan(1.0);
        // The dark cell (620 of 830 rays) rolls; the open one does not.
        let share = field.rolling_share().unwrap();
        assert!((share - 620.0 / 830.0).abs() < 1e-6, "{share}");
    }

    #[test]
    fn grid_levels_follow_the_spacing() {
        assert_eq!(CellKey::level_for(1.0), 0);
        assert_eq!(CellKey::level_for(0.1), -3);
        assert_eq!(CellKey::level_for(3.0), 2);
        assert_eq!(CellKey::level_for(f32::NAN), 0);
        let a = CellKey::new([0.10, 0.0, 0.0], [0.0, 0.0, 1.0], -3);
        let b = CellKey::new([0.12, 0.0, 0.0], [0.0, 0.0, 1.0], -3);
        let c = CellKey::new([0.13, 0.0, 0.0], [0.0, 0.0, 1.0], -3);
        assert_eq!(a, b);
        assert_ne!(b, c);
        let far = CellKey::new([f32::INFINITY, f32::NAN, 1e30], [0.0, 0.0, 1.0], -3);
        assert_eq!(far.coordinates, [0, 0, i32::MAX]);
    }

    #[test]
    fn sources_are_counted_apart_from_the_texels() {
        let mut field = VisibilityField::new(4).with_sources(3);
        let key = CellKey::new([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], 0);
        let other = CellKey::new([9.0, 2.0, 3.0], [0.0, 0.0, 1.0], 0);
        let mut observations = FieldObservations::new(4).with_sources(3);
        let mut cell = observations.cell_mut(key);
        for k in 0..40 {
            cell.record([0.0, 0.0, 1.0], k % 4 == 0);
            cell.record_source(k % 2, k % 4 == 0);
        }
        cell.record_source(7, true);
        observations.record(other, [1.0, 0.0, 0.0], true);
        field.merge(&observations);
        let cell = field.cell(&key).unwrap();
        assert_eq!(
            cell.total(),
            TexelCounts {
                free: 10,
                traced: 40
            }
        );
        assert_eq!(
            cell.source_counts(0),
            TexelCounts {
                free: 10,
                traced: 20
            }
        );
        assert_eq!(
            cell.source_counts(1),
            TexelCounts {
                free: 0,
                traced: 20
            }
        );
        assert_eq!(cell.source_visibility(2), None, "no ray aimed at it");
        assert_eq!(cell.source_visibility(7), None, "not counted");
        let (seen, blocked) = (
            cell.source_visibility(0).unwrap(),
            cell.source_visibility(1).unwrap(),
        );
        assert!(seen > 0.4 && blocked < 0.05, "{seen} {blocked}");
        assert_eq!(field.cell(&other).unwrap().total().traced, 1);
        assert_eq!(field.cell(&other).unwrap().source_counts(0).traced, 0);
    }

    #[test]
    fn what_sources_brought_is_summed_per_cell_across_merges() {
        let mut field = VisibilityField::new(4).with_sources(2);
        let key = CellKey::new([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], 0);
        let other = CellKey::new([9.0, 2.0, 3.0], [0.0, 0.0, 1.0], 0);
        let mut first = FieldObservations::new(4).with_sources(2);
        let mut cell = first.cell_mut(key);
        cell.record_brought(0, 0.25);
        cell.record_brought(1, 2.0);
        cell.record_brought(1, 1.0);
        cell.record_brought(5, 100.0); // not counted: ignored
        first.cell_mut(other).record_brought(0, 7.0);
        let mut second = FieldObservations::new(4).with_sources(2);
        second.cell_mut(key).record_brought(0, 0.5);
        field.merge_all([&first, &second]);
        let cell = field.cell(&key).unwrap();
        assert_eq!(cell.source_brought(0), 0.75);
        assert_eq!(cell.source_brought(1), 3.0);
        assert_eq!(cell.source_brought(5), 0.0);
        assert_eq!(field.cell(&other).unwrap().source_brought(0), 7.0);
        assert_eq!(field.cell(&other).unwrap().source_brought(1), 0.0);
        // A range of sources (a light's regions) sums them; beyond the counted, nothing.
        assert_eq!(cell.sources_brought(0..2), 3.75);
        assert_eq!(cell.sources_brought(1..9), 0.0);
    }

    #[test]
    fn a_range_of_sources_counts_the_rays_aimed_at_any_of_them() {
        let key = CellKey::new([0.0; 3], [0.0, 0.0, 1.0], 0);
        let mut observations = FieldObservations::new(4).with_sources(3);
        let mut cell = observations.cell_mut(key);
        for ray in 0..40 {
            cell.record([0.0, 0.0, 1.0], ray % 2 == 0);
            // Source 0 always free, 1 never, 2 unused.
            cell.record_source(ray % 2, ray % 2 == 0);
        }
        let mut field = VisibilityField::new(4).with_sources(3).with_prior(0.0);
        field.merge(&observations);
        let cell = field.cell(&key).unwrap();
        let both = cell.sources_counts(0..2);
        assert_eq!((both.free, both.traced), (20, 40));
        assert_eq!(cell.sources_visibility(0..2), Some(0.5));
        assert_eq!(cell.sources_visibility(0..1), Some(1.0));
        assert_eq!(cell.sources_visibility(2..3), None);
        assert_eq!(cell.source_counts(1).free, 0);
    }
}
