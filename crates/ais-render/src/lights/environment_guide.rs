//! Environment sampling multiplied by a fixed piecewise-constant weight over directions (an
//! affinity map's texels, or a visibility field cell's): the exact product
//! `p_env(ω) · A(ω) / Z`, sampled without rejection.
//!
//! Every cell of the environment's sampling distribution is assigned to the texel that
//! holds its centre, so each texel owns a set of whole cells and its share of the
//! environment's probability, `P_t`. With the weights `A_t` held fixed for a batch,
//! the product density picks texel `t` with probability `A_t P_t / Z` (`Z = Σ A_t P_t`),
//! then a cell of it in proportion to the environment's own cell probabilities (an alias
//! table per texel), then a point in the cell exactly as the environment does. Its density
//! is therefore `p_env(ω) · A_{t(ω)} / Z`, known in closed form: a light sample that
//! follows the map, for the price of a short inversion and an alias draw, and no rejected
//! candidate.

use super::ONE_BELOW;
use super::{Environment, EnvironmentMap, MapLocation, Toward};
use ais::field::octahedral;
use ais::mapping::LatLong;
use ais::sampling::{cumulative, guide_table, invert_guided};
use glam::Vec3;
use std::sync::{Arc, Mutex};

/// The texels a guide weighs: how world directions are binned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuideLayout {
    /// An affinity map's lat-long texels (guided gathers with shared maps).
    LatLong(LatLong),
    /// A visibility field cell's equal-area octahedral texels, `side × side`.
    Octahedral(u32),
}

impl GuideLayout {
    /// Number of texels.
    pub fn texel_count(self) -> usize {
        match self {
            GuideLayout::LatLong(layout) => layout.texel_count(),
            GuideLayout::Octahedral(side) => (side * side) as usize,
        }
    }

    /// The index of the texel holding `direction` (unit, world space).
    pub fn index(self, direction: Vec3) -> usize {
        match self {
            GuideLayout::LatLong(layout) => layout.index(layout.texel(direction)),
            GuideLayout::Octahedral(side) => octahedral::texel_of(direction.into(), side),
        }
    }
}

impl From<LatLong> for GuideLayout {
    fn from(layout: LatLong) -> Self {
        GuideLayout::LatLong(layout)
    }
}

/// What a texel of a partition holds, and how a direction is drawn in it.
#[derive(Debug)]
enum TexelContents {
    /// Whole cells of an environment map, each assigned to the texel of its centre.
    Cells {
        /// The texel of every environment cell.
        cell_texel: Vec<u32>,
        /// Environment cells grouped by texel: texel `t` owns `cells[start[t]..start[t + 1]]`.
        cells: Vec<u32>,
        start: Vec<u32>,
        /// Per texel, the cumulative probabilities of its cells within it: texel `t`'s are
        /// `within[start[t] + t..][..n_t + 1]` with `n_t` its cells (drawn by inversion,
        /// which keeps stratified numbers stratified).
        within: Vec<f64>,
        /// Per texel, the guide table of its cumulative probabilities (`n_t` entries from
        /// `start[t]`), so that an inversion looks at a bin or two.
        within_guides: Vec<u32>,
    },
    /// A constant environment's uniform directions over equal-area octahedral texels: a
    /// point uniform in the texel's square is uniform over its solid angle.
    Uniform {
        /// Texels per side.
        side: u32,
    },
}

/// The environment's cells grouped by the texels of one layout: built once per
/// environment and layout, shared by every thread ([`EnvironmentMap::partition`]).
#[derive(Debug)]
pub struct EnvironmentPartition {
    layout: GuideLayout,
    contents: TexelContents,
    /// `P_t`: the environment's probability of each texel.
    texel_mass: Vec<f64>,
}

impl EnvironmentPartition {
    /// Groups the cells of `environment` by the texels of `layout` (texel directions are
    /// world directions), each cell by the texel of its centre.
    pub fn new(environment: &EnvironmentMap, layout: GuideLayout) -> Self {
        let texels = layout.texel_count();
        let cell_texel: Vec<u32> = (0..environment.cell_count())
            .map(|cell| layout.index(environment.cell_centre(cell)) as u32)
            .collect();
        let mut start = vec![0u32; texels + 1];
        for &t in &cell_texel {
            start[t as usize + 1] += 1;
        }
        for t in 0..texels {
            start[t + 1] += start[t];
        }
        let mut fill = start.clone();
        let mut cells = vec![0u32; cell_texel.len()];
        for (cell, &t) in cell_texel.iter().enumerate() {
            cells[fill[t as usize] as usize] = cell as u32;
            fill[t as usize] += 1;
        }
        let mut within = Vec::with_capacity(cells.len() + texels);
        let mut texel_mass = vec![0.0; texels];
        for t in 0..texels {
            let range = start[t] as usize..start[t + 1] as usize;
            let probabilities: Vec<f64> = cells[range]
                .iter()
                .map(|&cell| environment.cell_probability(cell as usize))
                .collect();
            texel_mass[t] = probabilities.iter().sum();
            if texel_mass[t] > 0.0 {
                within.extend(cumulative(&probabilities, texel_mass[t]));
            } else {
                // Never drawn (no mass); any valid table will do.
                let n = probabilities.len().max(1) as f64;
                within.extend((0..=probabilities.len()).map(|k| k as f64 / n));
            }
        }
        let within_guides = (0..texels)
            .flat_map(|t| {
                let count = (start[t + 1] - start[t]) as usize;
                let first = start[t] as usize + t;
                guide_table(&within[first..first + count + 1])
            })
            .collect();
        EnvironmentPartition {
            layout,
            contents: TexelContents::Cells {
                cell_texel,
                cells,
                start,
                within,
                within_guides,
            },
            texel_mass,
        }
    }

    /// Uniform directions (a constant environment) over `side × side` equal-area octahedral
    /// texels, each of probability 1 / side².
    pub fn uniform(side: u32) -> Self {
        let layout = GuideLayout::Octahedral(side.clamp(1, 64));
        let texels = layout.texel_count();
        EnvironmentPartition {
            layout,
            contents: TexelContents::Uniform {
                side: side.clamp(1, 64),
            },
            texel_mass: vec![1.0 / texels as f64; texels],
        }
    }

    /// The layout the cells are grouped by.
    pub fn layout(&self) -> GuideLayout {
        self.layout
    }

    /// `P_t`: the environment's sampling probability of texel `index`.
    pub fn texel_mass(&self, index: usize) -> f64 {
        self.texel_mass[index]
    }

    /// Bytes held by its tables (about 20 per environment cell).
    pub fn memory_bytes(&self) -> usize {
        let cells = match &self.contents {
            TexelContents::Cells {
                cell_texel,
                cells,
                start,
                within,
                within_guides,
            } => {
                4 * (cell_texel.len() + cells.len() + start.len() + within_guides.len())
                    + 8 * within.len()
            }
            TexelContents::Uniform { .. } => 0,
        };
        std::mem::size_of_val(self) + cells + 8 * self.texel_mass.len()
    }

    /// A direction of texel `t` from `v` and `w` in [0, 1), in proportion to the
    /// environment's own density there.
    fn sample_in_texel(&self, environment: &Environment, t: usize, v: f32, w: f32) -> Toward {
        match (&self.contents, environment) {
            (TexelContents::Cells { .. }, Environment::Map(map)) => {
                let (cell, fx) = self.cell_in_texel(t, v).expect("cells");
                map.toward_in_cell(cell, [fx, w.min(ONE_BELOW)])
            }
            (TexelContents::Uniform { side }, _) => {
                let (row, column) = ((t as u32 / side) as f32, (t as u32 % side) as f32);
                let square = [
                    ((column + v) / *side as f32).min(ONE_BELOW),
                    ((row + w) / *side as f32).min(ONE_BELOW),
                ];
                let direction = Vec3::from(octahedral::direction_of(square)).normalize();
                Toward::from_environment(direction, None)
            }
            (TexelContents::Cells { .. }, _) => environment.sample_toward([v, w]),
        }
    }

    /// Whether its texels hold an environment map's cells (else they hold uniform
    /// directions).
    pub(super) fn holds_cells(&self) -> bool {
        matches!(self.contents, TexelContents::Cells { .. })
    }

    /// The environment cell of texel `t` that `v` ∈ [0, 1) draws, in proportion to the
    /// cells' probabilities, and where `v` fell within the cell's bin (`None`: the texels
    /// hold no cells, a constant environment's partition).
    #[inline]
    pub(super) fn cell_in_texel(&self, t: usize, v: f32) -> Option<(usize, f32)> {
        let TexelContents::Cells {
            cells,
            start,
            within,
            within_guides,
            ..
        } = &self.contents
        else {
            return None;
        };
        let first = start[t] as usize + t;
        let count = (start[t + 1] - start[t]) as usize;
        let guide = &within_guides[start[t] as usize..][..count];
        let (i, fx) = invert_guided(&within[first..first + count + 1], guide, v as f64);
        Some((cells[start[t] as usize + i] as usize, fx))
    }
}

/// The partitions built for an environment, one per layout, shared by all threads. Cloning
/// an environment starts an empty cache.
#[derive(Debug, Default)]
pub(crate) struct PartitionCache(Mutex<Vec<Arc<EnvironmentPartition>>>);

impl Clone for PartitionCache {
    fn clone(&self) -> Self {
        PartitionCache::default()
    }
}

impl PartitionCache {
    /// The partition of `environment` by `layout`, built on first use.
    pub(crate) fn get(
        &self,
        environment: &EnvironmentMap,
        layout: GuideLayout,
    ) -> Arc<EnvironmentPartition> {
        // A panic while building poisons nothing we rely on: the list stays valid.
        let mut built = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(partition) = built.iter().find(|p| p.layout == layout) {
            return partition.clone();
        }
        let partition = Arc::new(EnvironmentPartition::new(environment, layout));
        built.push(partition.clone());
        partition
    }
}

/// Which half of a guide's mixture a draw takes ([`EnvironmentGuide::pick`]).
#[derive(Clone, Copy, Debug)]
pub(super) enum Pick {
    /// The environment's own distribution, from this first number.
    Own(f32),
    /// The product: this texel, and where the number fell within its bin.
    Texel(usize, f32),
}

/// The product distribution of one batch: a shared [`EnvironmentPartition`] and the
/// affinities of the batch's map.
#[derive(Clone, Debug)]
pub struct EnvironmentGuide {
    partition: Arc<EnvironmentPartition>,
    /// Per batch: the affinity of each texel, the cumulative of `A_t P_t / Z`, and `Z`.
    affinity: Vec<f32>,
    cdf: Vec<f64>,
    /// The guide table of `cdf` ([`guide_table`]).
    cdf_guide: Vec<u32>,
    normaliser: f64,
    /// The product's share β of the defensive mixture `(1 − β) p_env + β p_env A / Z`.
    fraction: f64,
}

impl EnvironmentGuide {
    /// A guide over `partition`; the product starts as the environment's own distribution
    /// (all A = 1).
    pub fn new(partition: Arc<EnvironmentPartition>) -> Self {
        let texels = partition.layout.texel_count();
        let mut guide = EnvironmentGuide {
            partition,
            affinity: vec![1.0; texels],
            cdf: vec![0.0; texels + 1],
            cdf_guide: Vec::with_capacity(texels),
            normaliser: 1.0,
            fraction: 1.0,
        };
        guide.set_affinities(|_| 1.0);
        guide
    }

    /// Bytes held by this thread's part (the shared partition is counted once, in
    /// [`EnvironmentPartition::memory_bytes`]).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self)
            + 4 * (self.affinity.len() + self.cdf_guide.capacity())
            + 8 * self.cdf.len()
    }

    /// The layout the cells are grouped by.
    pub fn layout(&self) -> GuideLayout {
        self.partition.layout
    }

    /// Sets the affinity `A_t` of every texel (by index in the layout) for the next batch. The product has density
    /// only where `A_t > 0`: keep it positive wherever the integrand may be (non-positive or
    /// non-finite values count as 0; if no texel with environment mass is left, all count
    /// as 1).
    pub fn set_affinities(&mut self, affinity: impl Fn(usize) -> f32) {
        let mut running = 0.0;
        for t in 0..self.affinity.len() {
            let a = affinity(t);
            self.affinity[t] = if a.is_finite() && a > 0.0 { a } else { 0.0 };
            running += self.affinity[t] as f64 * self.partition.texel_mass[t];
            self.cdf[t + 1] = running;
        }
        if running <= 0.0 {
            self.affinity.fill(1.0);
            running = 0.0;
            for t in 0..self.affinity.len() {
                running += self.partition.texel_mass[t];
                self.cdf[t + 1] = running;
            }
        }
        self.normaliser = running;
        self.cdf.iter_mut().for_each(|c| *c /= running);
        *self.cdf.last_mut().expect("at least one texel") = 1.0;
        self.cdf_guide.clear();
        self.cdf_guide.extend(guide_table(&self.cdf));
    }

    /// How much more often the mixture draws texel `t` than the environment alone:
    /// `(1 − β) + β A_t / Z`.
    pub fn mixture_weight(&self, t: usize) -> f64 {
        (1.0 - self.fraction) + self.fraction * self.affinity[t] as f64 / self.normaliser
    }

    /// Sets the product's share β ∈ [0, 1] of the mixture with the environment's own
    /// distribution (1: the product alone). A map that wrongly calls a bright light blocked
    /// raises the variance by at most 1 / (1 − β).
    pub fn set_fraction(&mut self, fraction: f64) {
        self.fraction = fraction.clamp(0.0, 1.0);
    }

    /// A direction from the mixture for `u` ∈ [0, 1)², located on the map.
    pub fn sample(&self, environment: &Environment, u: [f32; 2]) -> Toward {
        match self.pick(u[0]) {
            Pick::Own(u0) => environment.sample_toward([u0, u[1]]),
            Pick::Texel(t, v) => self.partition.sample_in_texel(environment, t, v, u[1]),
        }
    }

    /// The first step of [`EnvironmentGuide::sample`], from its first number `u0`.
    #[inline]
    pub(super) fn pick(&self, u0: f32) -> Pick {
        let beta = self.fraction;
        let u0 = u0 as f64;
        if u0 >= beta {
            let rescaled = ((u0 - beta) / (1.0 - beta)).clamp(0.0, 1.0 - 1e-7);
            return Pick::Own(rescaled as f32);
        }
        let (t, v) = invert_guided(&self.cdf, &self.cdf_guide, u0 / beta);
        Pick::Texel(t, v)
    }

    /// The cells the texels hold ([`EnvironmentPartition::cell_in_texel`]).
    pub(super) fn partition(&self) -> &EnvironmentPartition {
        &self.partition
    }

    /// Its weights per place on an environment map, where its texels hold the map's cells
    /// (`None`: they split them).
    pub fn map_weights(&self) -> Option<MapWeights<'_>> {
        match &self.partition.contents {
            TexelContents::Cells { cell_texel, .. } => Some(MapWeights {
                guide: self,
                cell_texel,
            }),
            _ => None,
        }
    }

    /// The mixture's weight toward `direction` where its texels do not hold a map's cells
    /// (a constant environment's uniform texels): its density there is the environment's
    /// times this ([`EnvironmentGuide::pdf`], to the bit).
    pub fn weight_toward(&self, direction: Vec3) -> f64 {
        self.mixture_weight(self.partition.layout.index(direction))
    }

    /// The mixture's density at a direction (solid angle): the environment's own density
    /// there times the weight of the texel it lies in ([`MapWeights::at`] where the texels
    /// hold a map's cells, [`EnvironmentGuide::weight_toward`] otherwise).
    pub fn pdf(&self, environment: &Environment, toward: &mut Toward) -> f64 {
        match (self.map_weights(), environment) {
            (Some(weights), Environment::Map(map)) => {
                let location = toward.location(map);
                map.density_at(location) as f64 * weights.at(location)
            }
            _ => environment.pdf_toward(toward) * self.weight_toward(toward.direction),
        }
    }
}

/// What an environment guide whose texels hold whole cells multiplies the map's own
/// density by, place by place ([`EnvironmentGuide::map_weights`]).
#[derive(Clone, Copy, Debug)]
pub struct MapWeights<'g> {
    guide: &'g EnvironmentGuide,
    cell_texel: &'g [u32],
}

impl MapWeights<'_> {
    /// The mixture's weight at `location`: its density there is the map's times this
    /// ([`EnvironmentGuide::pdf`], to the bit).
    #[inline]
    pub fn at(&self, location: MapLocation) -> f64 {
        self.guide
            .mixture_weight(self.cell_texel[location.cell()] as usize)
    }
}
