//! Environment sampling multiplied by a fixed affinity map: the exact product
//! `p_env(ω) · A(ω) / Z`, sampled without rejection.
//!
//! Every cell of the environment's sampling distribution is assigned to the map texel that
//! holds its centre, so each map texel owns a set of whole cells and its share of the
//! environment's probability, `P_t`. With the map's affinities `A_t` held fixed for a batch,
//! the product density picks texel `t` with probability `A_t P_t / Z` (`Z = Σ A_t P_t`),
//! then a cell of it in proportion to the environment's own cell probabilities, then a point
//! in the cell exactly as the environment does. Its density is therefore
//! `p_env(ω) · A_{t(ω)} / Z`, known in closed form: a light sample that follows the map, for
//! the price of two short inversions and no rejected candidate. Inversion all the way down
//! keeps stratified `u` stratified.

use super::{EnvironmentMap, Toward};
use ais::mapping::{LatLong, Texel};
use std::sync::{Arc, Mutex};

/// The environment's cells grouped by the texels of one map layout: built once per
/// environment and layout, shared by every thread ([`EnvironmentMap::partition`]).
#[derive(Debug)]
pub struct EnvironmentPartition {
    layout: LatLong,
    /// The map texel of every environment cell.
    cell_texel: Vec<u32>,
    /// Environment cells grouped by texel: texel `t` owns `cells[start[t]..start[t + 1]]`.
    cells: Vec<u32>,
    start: Vec<u32>,
    /// For each entry of `cells`, the cumulative probability of the texel's cells up to and
    /// including it, divided by the texel's total (so the last of each texel is 1).
    within: Vec<f64>,
    /// `P_t`: the environment's probability of each texel.
    texel_mass: Vec<f64>,
}

impl EnvironmentPartition {
    /// Groups the cells of `environment` by the texels of `layout` (map directions are world
    /// directions), each cell by the texel of its centre.
    pub fn new(environment: &EnvironmentMap, layout: LatLong) -> Self {
        let texels = layout.texel_count();
        let cell_texel: Vec<u32> = (0..environment.cell_count())
            .map(|cell| layout.index(layout.texel(environment.cell_centre(cell))) as u32)
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
        let mut within = vec![0.0; cells.len()];
        let mut texel_mass = vec![0.0; texels];
        for t in 0..texels {
            let range = start[t] as usize..start[t + 1] as usize;
            let mut running = 0.0;
            for i in range.clone() {
                running += environment.cell_probability(cells[i] as usize);
                within[i] = running;
            }
            texel_mass[t] = running;
            if running > 0.0 {
                within[range].iter_mut().for_each(|c| *c /= running);
            }
        }
        EnvironmentPartition {
            layout,
            cell_texel,
            cells,
            start,
            within,
            texel_mass,
        }
    }

    /// The map layout the cells are grouped by.
    pub fn layout(&self) -> LatLong {
        self.layout
    }

    /// Bytes held by its tables (about 16 per environment cell).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self)
            + 4 * (self.cell_texel.len() + self.cells.len() + self.start.len())
            + 8 * (self.within.len() + self.texel_mass.len())
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
        layout: LatLong,
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

/// The product distribution of one batch: a shared [`EnvironmentPartition`] and the
/// affinities of the batch's map.
#[derive(Clone, Debug)]
pub struct EnvironmentGuide {
    partition: Arc<EnvironmentPartition>,
    /// Per batch: the affinity of each texel, the cumulative of `A_t P_t / Z`, and `Z`.
    affinity: Vec<f32>,
    cdf: Vec<f64>,
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
            normaliser: 1.0,
            fraction: 1.0,
        };
        guide.set_affinities(|_| 1.0);
        guide
    }

    /// Bytes held by this thread's part (the shared partition is counted once, in
    /// [`EnvironmentPartition::memory_bytes`]).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self) + 4 * self.affinity.len() + 8 * self.cdf.len()
    }

    /// The map layout the cells are grouped by.
    pub fn layout(&self) -> LatLong {
        self.partition.layout
    }

    /// Sets the affinity `A_t` of every texel for the next batch. The product has density
    /// only where `A_t > 0`: keep it positive wherever the integrand may be (non-positive or
    /// non-finite values count as 0; if no texel with environment mass is left, all count
    /// as 1).
    pub fn set_affinities(&mut self, affinity: impl Fn(Texel) -> f32) {
        let mut running = 0.0;
        for t in 0..self.affinity.len() {
            let a = affinity(self.partition.layout.texel_of_index(t));
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
    }

    /// Sets the product's share β ∈ [0, 1] of the mixture with the environment's own
    /// distribution (1: the product alone). A map that wrongly calls a bright light blocked
    /// raises the variance by at most 1 / (1 − β).
    pub fn set_fraction(&mut self, fraction: f64) {
        self.fraction = fraction.clamp(0.0, 1.0);
    }

    /// A direction from the mixture for `u` ∈ [0, 1)², located on the map.
    pub fn sample(&self, environment: &EnvironmentMap, u: [f32; 2]) -> Toward {
        let beta = self.fraction;
        let u0 = u[0] as f64;
        if u0 >= beta {
            let rescaled = ((u0 - beta) / (1.0 - beta)).clamp(0.0, 1.0 - 1e-7);
            return environment.sample([rescaled as f32, u[1]]);
        }
        let u0 = u0 / beta;
        let texels = self.affinity.len();
        let mut t = self.cdf[1..].partition_point(|&c| c <= u0).min(texels - 1);
        while t > 0 && self.cdf[t + 1] <= self.cdf[t] {
            t -= 1; // rounding at u ≈ 1: back to a texel with mass
        }
        let share = self.cdf[t + 1] - self.cdf[t];
        let v = ((u0 - self.cdf[t]) / share).clamp(0.0, 1.0);
        let partition = &*self.partition;
        let range = partition.start[t] as usize..partition.start[t + 1] as usize;
        let within = &partition.within[range.clone()];
        let mut i = within.partition_point(|&c| c <= v).min(within.len() - 1);
        while i > 0 && within[i] <= within[i - 1] {
            i -= 1;
        }
        let below = if i == 0 { 0.0 } else { within[i - 1] };
        let fx = ((v - below) / (within[i] - below)).clamp(0.0, 1.0 - 1e-7) as f32;
        let cell = partition.cells[range.start + i] as usize;
        environment.toward_in_cell(cell, [fx, u[1].min(1.0 - 1e-7)])
    }

    /// The mixture's density at a direction (solid angle).
    pub fn pdf(&self, environment: &EnvironmentMap, toward: &mut Toward) -> f64 {
        let (density, cell) = environment.pdf_and_cell(toward);
        let product =
            self.affinity[self.partition.cell_texel[cell] as usize] as f64 / self.normaliser;
        density as f64 * ((1.0 - self.fraction) + self.fraction * product)
    }
}
