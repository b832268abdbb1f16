//! Light sampling guided by the visibility field (`map = field` with `map_use = proposal`
//! or `both`).
//!
//! In a cell whose texels the field knows, the environment is drawn from a defensive
//! mixture of its own distribution and its exact product with the cell's texel
//! visibilities ([`EnvironmentGuide`] on the field's octahedral texels): the sky that the
//! cell sees through a window gets the samples that the walls around it would have
//! blocked. Nothing is rejected for it; every candidate weighs f / q with q the mixture's
//! density, so the estimate stays exactly unbiased whatever the field says, and a field
//! that wrongly calls a bright direction blocked costs at most 1 / (1 − β) in variance.
//!
//! The field is fixed during a pass, so the guide of a cell depends on nothing but the
//! field: every tile that meets the cell builds the same one (the image does not depend on
//! the thread count). A tile keeps the guides of the cells it met.

use crate::lights::{Environment, EnvironmentGuide, EnvironmentPartition, GuideLayout};
use crate::world::World;
use ais::field::{CellIndex, FieldCell, LEAST_EVIDENCE, LOWEST_ACCEPTANCE};
use std::collections::HashMap;
use std::sync::Arc;

/// A cell is guided only where fewer than this share of the environment's own draws would
/// be free (Σ P_t v_t, texels no ray went to counting as blocked): where most are free
/// (open ground, a sculpture under the sky), guiding saves little variance, makes its rays
/// dearer (free rays cross the scene) and, where a bright light is partly hidden within a
/// texel, adds variance. Measured on the default scene: guided everywhere it had contrast,
/// auto took 34% more time for 11% more relMSE.
pub const MOST_FREE_DRAWS: f64 = 0.5;

/// The product's default share β of the environment's draws in a guided cell: a field that
/// wrongly calls a bright direction blocked costs at most 4× in variance there. (0.75 gained
/// more than 0.5 in the rooms and the courtyard, 1.45× against 1.36× and 2.6× against 2.1×,
/// and lost 3% more behind a roof edge: the repository's BENCHMARKS.md, section 5.6.)
pub const FIELD_GUIDE_FRACTION: f32 = 0.75;

/// A cell is guided only where its darkest texel is below this share of the cell's
/// visibility: elsewhere the product is close to the environment's own distribution.
/// (Besides, see [`MOST_FREE_DRAWS`].)
/// (A rule from the expected variance gain, Σ P_t v_t / m_t against Σ P_t v_t, was tried:
/// it guided about as many cells and lost 10% of the gain in the sunlit room.)
pub const GUIDE_CONTRAST: f32 = 0.5;

/// A tile's environment guides, one per cell of the field it met (none where the cell is
/// not worth guiding).
pub struct FieldGuides {
    /// The environment's cells grouped by the field's texels (`None`: the scene has no
    /// environment, or light sampling is not in the proposal).
    partition: Option<Arc<EnvironmentPartition>>,
    by_cell: HashMap<CellIndex, Option<EnvironmentGuide>>,
    /// The product's share β of the mixture.
    fraction: f64,
}

impl FieldGuides {
    /// Guides for a field of `side × side` texels per cell, with the product's share
    /// `fraction` (guides exist only if `samples_lights` and the scene has an environment:
    /// a map, or a constant one).
    pub fn new(world: &World, side: u32, samples_lights: bool, fraction: f32) -> Self {
        let partition = match (&world.lights.environment, samples_lights) {
            (Some(Environment::Map(map)), true) => {
                Some(map.partition(GuideLayout::Octahedral(side)))
            }
            (Some(Environment::Constant(_)), true) => {
                Some(Arc::new(EnvironmentPartition::uniform(side)))
            }
            _ => None,
        };
        FieldGuides {
            partition,
            by_cell: HashMap::new(),
            fraction: fraction as f64,
        }
    }

    /// The guide of the cell at `index`, built on first use (`None`: unguided there).
    pub fn guide(&mut self, index: CellIndex, cell: &FieldCell) -> Option<&EnvironmentGuide> {
        let partition = self.partition.as_ref()?;
        let fraction = self.fraction;
        self.by_cell
            .entry(index)
            .or_insert_with(|| build(partition, cell, fraction))
            .as_ref()
    }

    /// Bytes held by the guides (the shared partition is counted by the environment).
    pub fn memory_bytes(&self) -> usize {
        self.by_cell
            .values()
            .flatten()
            .map(EnvironmentGuide::memory_bytes)
            .sum::<usize>()
            + self.by_cell.capacity() * std::mem::size_of::<(CellIndex, Option<EnvironmentGuide>)>()
    }
}

/// The guide of `cell`: each texel weighed by its learned visibility; texels no ray of the
/// cell went to (behind the surface, or where light sampling never draws) by a tenth of
/// the cell's. `None` where the cell has too little evidence or too little contrast, or
/// where most of the environment's draws are free anyway.
fn build(
    partition: &Arc<EnvironmentPartition>,
    cell: &FieldCell,
    fraction: f64,
) -> Option<EnvironmentGuide> {
    let visibility = cell.visibility();
    if cell.total().traced < LEAST_EVIDENCE || cell.darkest() >= GUIDE_CONTRAST * visibility {
        return None;
    }
    let texels = (cell.side() * cell.side()) as usize;
    let free_draws: f64 = (0..texels)
        .map(|t| partition.texel_mass(t) * cell.texel_visibility_at(t).unwrap_or(0.0) as f64)
        .sum();
    if free_draws >= MOST_FREE_DRAWS {
        return None;
    }
    let mut guide = EnvironmentGuide::new(partition.clone());
    guide.set_fraction(fraction);
    let unseen = LOWEST_ACCEPTANCE * visibility;
    guide.set_affinities(|texel| cell.texel_visibility_at(texel).unwrap_or(unseen));
    Some(guide)
}
