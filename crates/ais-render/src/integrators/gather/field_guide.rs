//! Light sampling guided by the visibility field (`map = field` with `map_use = proposal`
//! or `both`).
//!
//! Where a scene has two or more lights, a cell also chooses among them by what it saw:
//! each light's probability of being chosen is a defensive mixture of its share of the
//! power (as unguided light sampling chooses) and that share weighed by the visibility of
//! the rays the cell aimed at it. A light hidden from the cell is chosen less, one in view
//! more; the choice's probabilities are exact, so nothing is biased.
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
use ais::field::{CellIndex, FieldCell, LEAST_EVIDENCE};
use ais::sampling::AliasTable;
use std::collections::HashMap;
use std::sync::Arc;

/// A cell is guided only where fewer than this share of the environment's own draws would
/// be free (Σ P_t v_t, texels whose block no ray went to counting as blocked): where most
/// are free (open ground, a sculpture under the sky), guiding saves little variance, makes
/// its rays dearer (free rays cross the scene) and, where a bright light is partly hidden
/// within a texel, adds variance. Measured on the default scene: guided everywhere it had contrast,
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

/// What guides light sampling in one cell of the field.
#[derive(Default)]
pub struct CellGuide {
    /// The environment drawn through its product with the cell's texels (`None`: not
    /// worth it here).
    pub environment: Option<EnvironmentGuide>,
    /// The choice among the lights by what the cell sees of them (`None`: by power).
    pub lights: Option<AliasTable>,
}

/// A tile's guides, one per cell of the field it met.
pub struct FieldGuides {
    /// The environment's cells grouped by the field's texels (`None`: the scene has no
    /// environment, or light sampling is not in the proposal).
    partition: Option<Arc<EnvironmentPartition>>,
    /// Light sampling's probabilities of choosing each light by power (empty: the field
    /// does not choose among the lights).
    power_choice: Vec<f64>,
    by_cell: HashMap<CellIndex, CellGuide>,
    /// The guided share β of each mixture.
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
        let counted = super::field::counted_sources(world) > 0 && samples_lights;
        FieldGuides {
            partition,
            power_choice: if counted {
                world.lights.power_choice()
            } else {
                Vec::new()
            },
            by_cell: HashMap::new(),
            fraction: fraction as f64,
        }
    }

    /// The guide of the cell at `index`, built on first use.
    pub fn guide(&mut self, index: CellIndex, cell: &FieldCell) -> &CellGuide {
        let (partition, power, fraction) = (&self.partition, &self.power_choice, self.fraction);
        self.by_cell.entry(index).or_insert_with(|| CellGuide {
            environment: partition
                .as_ref()
                .and_then(|partition| build(partition, cell, fraction)),
            lights: light_choice(power, cell, fraction),
        })
    }

    /// Bytes held by the guides (the shared partition is counted by the environment).
    pub fn memory_bytes(&self) -> usize {
        let light_choice = |table: &AliasTable| table.len() * 12;
        self.by_cell
            .values()
            .map(|guide| {
                guide
                    .environment
                    .as_ref()
                    .map_or(0, EnvironmentGuide::memory_bytes)
                    + guide.lights.as_ref().map_or(0, light_choice)
            })
            .sum::<usize>()
            + self.by_cell.capacity() * std::mem::size_of::<(CellIndex, CellGuide)>()
    }
}

/// The choice among the lights in `cell`: each light's power share `power[l]` and, with
/// share `fraction`, that share weighed by the visibility of the rays the cell aimed at it
/// (a light it aimed no ray at counts as the cell's visibility). `None` where the field
/// counts no lights, the cell has too little evidence, or no light is much less visible
/// than the others (then the choice by power is as good).
fn light_choice(power: &[f64], cell: &FieldCell, fraction: f64) -> Option<AliasTable> {
    if power.is_empty() || cell.total().traced < LEAST_EVIDENCE {
        return None;
    }
    let visibility = cell.visibility();
    let seen: Vec<f64> = (0..power.len())
        .map(|light| cell.source_visibility(light).unwrap_or(visibility) as f64)
        .collect();
    let free: f64 = power.iter().zip(&seen).map(|(p, v)| p * v).sum();
    let contrast = power
        .iter()
        .zip(&seen)
        .any(|(&p, &v)| p > 0.0 && v < GUIDE_CONTRAST as f64 * free);
    if !(free > 0.0 && contrast) {
        return None;
    }
    let weights: Vec<f64> = power
        .iter()
        .zip(&seen)
        .map(|(p, v)| (1.0 - fraction) * p + fraction * p * v / free)
        .collect();
    Some(AliasTable::new(&weights))
}

/// A texel whose 2 × 2 block no ray of a cell went to (behind the surface, or where light
/// sampling never draws) weighs this share of the cell's visibility in its guide. Such
/// draws are mostly below the surface's horizon, wasted: at a tenth, 2.4 of 16 candidates
/// per gather were outside the BSDF's support in the sunlit room; at a hundredth, relMSE
/// fell 7–8% in the sunlit and overcast rooms and stayed within noise in the courtyard and
/// the interior (the repository's BENCHMARKS.md, section 5.6). Not zero: a direction that some point of
/// the cell sees but no ray tried keeps a chance beyond the defensive share.
pub const UNSEEN_TEXEL_SHARE: f32 = 0.01;

/// The guide of `cell`: each texel weighed by its learned visibility, pooled with its
/// neighbours' ([`FieldCell::pooled_visibility_at`]); texels whose block no ray of the
/// cell went to by [`UNSEEN_TEXEL_SHARE`] of the cell's. `None` where the cell has too
/// little evidence or too little contrast, or where most of the environment's draws are
/// free anyway.
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
        .map(|t| partition.texel_mass(t) * cell.pooled_visibility_at(t).unwrap_or(0.0) as f64)
        .sum();
    if free_draws >= MOST_FREE_DRAWS {
        return None;
    }
    let mut guide = EnvironmentGuide::new(partition.clone());
    guide.set_fraction(fraction);
    let unseen = UNSEEN_TEXEL_SHARE * visibility;
    guide.set_affinities(|texel| cell.pooled_visibility_at(texel).unwrap_or(unseen));
    Some(guide)
}
