//! Light sampling guided by the visibility field (`map = field` with `map_use = proposal`
//! or `both`).
//!
//! Where a scene has two or more lights, a cell also chooses among them by what their rays
//! brought it: each light's probability of being chosen is a defensive mixture of its share
//! of the power (as unguided light sampling chooses) and its learned share of the cell's
//! light. A light hidden from the cell, or far from it, is chosen less, a close one in view
//! more; the choice's probabilities are exact, so nothing is biased.
//!
//! Within a sphere or a rectangle light, a cell weighs the 16 regions of the light's sample
//! square ([`RegionChoice`]: 16 parts of the light as the cell sees it) by the same rule:
//! through a door gap, the strip of a ceiling lamp that the cell sees gets the draws that
//! the door would have blocked.
//!
//! In a cell whose texels the field knows, the environment is drawn from a defensive
//! mixture of its own distribution (in front of the surface, where the cell knows its
//! normal) and its exact product with the square roots of the cell's texel
//! visibilities ([`EnvironmentGuide`] on the field's octahedral texels), each times the
//! cosine between the cell's mean normal and the texel: the sky that the cell sees through
//! a window gets the samples that the walls around it would have blocked, and more of them
//! where it shines on the surface more steeply. Nothing is rejected for it; every candidate
//! weighs f / q with q the mixture's density, so the estimate stays exactly unbiased
//! whatever the field says, and a field that wrongly calls a bright direction blocked costs
//! at most 1 / (1 − β) in variance.
//!
//! The field is fixed during a pass, so the guide of a cell depends on nothing but the
//! field: every tile that meets the cell builds the same one (the image does not depend on
//! the thread count). A tile keeps the guides of the cells it met.

use crate::lights::{
    Environment, EnvironmentGuide, EnvironmentPartition, GuideLayout, RegionChoice, REGIONS,
};
use crate::world::World;
use ais::field::{octahedral, CellIndex, FieldCell, LEAST_EVIDENCE};
use ais::sampling::AliasTable;
use glam::Vec3;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

/// A cell whose normals disagree (so that its guide cannot follow the cosine) is guided
/// only where fewer than this share of the environment's own draws would be free (Σ P_t
/// v_t, texels whose block no ray went to counting as blocked): where most are free, a
/// guide of visibilities alone saves little variance and makes its rays dearer (free rays
/// cross the scene). Measured on the default scene before guides followed the cosine:
/// guided everywhere it had contrast, auto took 34% more time for 11% more relMSE. With the
/// cosine, guiding every cell that knows its normal gained at equal time in every sky-lit
/// scene but the foliage (the repository's BENCHMARKS.md, section 5.6).
pub const MOST_FREE_DRAWS: f64 = 0.5;

/// The product's default share β of the environment's draws in a guided cell: a field that
/// wrongly calls a bright direction blocked costs at most 4× in variance there. (0.75 gained
/// more than 0.5 in the rooms and the courtyard, 1.45× against 1.36× and 2.6× against 2.1×,
/// and lost 3% more behind a roof edge: the repository's BENCHMARKS.md, section 5.6.)
pub const FIELD_GUIDE_FRACTION: f32 = 0.75;

/// A cell whose normals disagree is guided only where its darkest texel is below this
/// share of the cell's visibility: elsewhere the product is close to the environment's own
/// distribution (besides, see [`MOST_FREE_DRAWS`]). (A rule from the expected variance
/// gain, Σ P_t v_t / m_t against Σ P_t v_t, was tried: it guided about as many cells and
/// lost 10% of the gain in the sunlit room.)
pub const GUIDE_CONTRAST: f32 = 0.5;

/// The least cosine weight of a texel in a cell's guide (a texel across the horizon gets
/// part of its light more steeply than at its centre). (0.1 gained more than 0.3 in the
/// courtyard, 8% against 5% in relMSE at n = 16.)
pub const LEAST_TEXEL_COSINE: f32 = 0.1;

/// A texel whose centre lies less than this cosine below a cell's horizon may still hold
/// directions above it (a texel of a 16 × 16 map spans about 11°).
pub const HORIZON_SLACK: f32 = 0.2;

/// What guides light sampling in one cell of the field.
#[derive(Default)]
pub struct CellGuide {
    /// The environment drawn through its product with the cell's texels (`None`: not
    /// worth it here).
    pub environment: Option<EnvironmentGuide>,
    /// The choice among the lights by what the cell sees of them (`None`: by power).
    pub lights: Option<AliasTable>,
    /// For each area light, the weighing of its sample square's regions by what they
    /// brought the cell (`None`, or an empty list: drawn uniformly).
    pub regions: Vec<Option<RegionChoice>>,
}

impl CellGuide {
    /// Whether it changes light sampling at all.
    pub fn guides(&self) -> bool {
        self.environment.is_some()
            || self.lights.is_some()
            || self.regions.iter().any(Option::is_some)
    }
}

/// A tile's guides, one per cell of the field it met.
pub struct FieldGuides {
    /// The environment's cells grouped by the field's texels (`None`: the scene has no
    /// environment, or light sampling is not in the proposal).
    partition: Option<Arc<EnvironmentPartition>>,
    /// Light sampling's probabilities of choosing each light by power (empty: the field
    /// counts no light's rays).
    power_choice: Vec<f64>,
    /// The field's sources of each light (as light sampling orders them; empty where the
    /// field counts no light's rays).
    sources: Vec<Range<usize>>,
    /// How many of the lights are area lights (the first ones).
    area_lights: usize,
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
        let lights = &world.lights;
        let counted = super::field::counted_sources(world) > 0 && samples_lights;
        let (power_choice, sources) = if counted {
            let sources = (0..lights.source_count()).map(|l| lights.sources_of_light(l));
            (lights.power_choice(), sources.collect())
        } else {
            (Vec::new(), Vec::new())
        };
        FieldGuides {
            partition,
            power_choice,
            sources,
            area_lights: lights.area.len(),
            by_cell: HashMap::new(),
            fraction: fraction as f64,
        }
    }

    /// The guide of the cell at `index`, built on first use.
    pub fn guide(&mut self, index: CellIndex, cell: &FieldCell) -> &CellGuide {
        let (partition, fraction) = (&self.partition, self.fraction);
        let (power, sources) = (&self.power_choice, &self.sources);
        let area_sources = &sources[..self.area_lights.min(sources.len())];
        self.by_cell.entry(index).or_insert_with(|| CellGuide {
            environment: partition
                .as_ref()
                .and_then(|partition| build(partition, cell, fraction)),
            lights: light_choice(power, sources, cell, fraction),
            regions: region_choices(area_sources, cell, fraction),
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
                    + guide.regions.capacity() * std::mem::size_of::<Option<RegionChoice>>()
            })
            .sum::<usize>()
            + self.by_cell.capacity() * std::mem::size_of::<(CellIndex, CellGuide)>()
    }
}

/// The choice among the lights in `cell`: each light's power share `power[l]` and, with
/// share `fraction`, a share learned from what the cell's rays brought from each light,
/// `B_l / √v_l` normalised (`B_l` the light's part of the cell's light, `v_l` the
/// visibility of the rays aimed at it, over the light's field sources `sources[l]`). That is
/// the variance-optimal choice where a light's own sampling brings `B_l / v_l` through a
/// free ray and nothing through a blocked one (docs/technique.md, "Choosing among lights"):
/// a close light under a roof gets the draws a hidden sun would waste, though by power it is
/// a hundredth of the sky. `None` where there is one light or none to choose, the cell has
/// too little evidence, or no ray brought light.
fn light_choice(
    power: &[f64],
    sources: &[Range<usize>],
    cell: &FieldCell,
    fraction: f64,
) -> Option<AliasTable> {
    if power.len() < 2 || cell.total().traced < LEAST_EVIDENCE {
        return None;
    }
    let learned = learned_shares(sources.iter().cloned(), cell, cell.visibility())?;
    let weights: Vec<f64> = power
        .iter()
        .zip(&learned)
        .map(|(p, b)| (1.0 - fraction) * p + fraction * b)
        .collect();
    Some(AliasTable::new(&weights))
}

/// The shares `B_s / √v_s`, normalised, of the groups of sources `groups` in `cell`
/// (`B_s` what the rays that reached the group brought, `v_s` their visibility, `seen`
/// where no ray went); `None` where nothing was brought.
fn learned_shares(
    groups: impl Iterator<Item = Range<usize>>,
    cell: &FieldCell,
    seen: f32,
) -> Option<Vec<f64>> {
    let learned: Vec<f64> = groups
        .map(|group| {
            let visibility = cell.sources_visibility(group.clone()).unwrap_or(seen) as f64;
            cell.sources_brought(group) / visibility.max(LEAST_SOURCE_VISIBILITY).sqrt()
        })
        .collect();
    let total: f64 = learned.iter().sum();
    (total > 0.0 && total.is_finite()).then(|| learned.iter().map(|b| b / total).collect())
}

/// For each area light whose rays the cell counts by region (`sources[l]`, one source per
/// region), the weighing of the regions: `1 − fraction` spread evenly and `fraction` by
/// their learned shares `B_k / √v_k`, the choice among lights' rule, which is
/// variance-optimal here too, as a region is drawn by the light's own sampling restricted
/// to it. `None` for a light with fewer than [`LEAST_EVIDENCE`] rays aimed at it, whose
/// rays brought nothing, or of which the cell sees [`MOST_FREE_DRAWS`] or more: where most
/// of a light is in view, weighing its regions by 16 noisy sums added more variance than
/// it took (the default scene's relMSE rose 7%, the open scene's 3%; gated, they are as
/// before and the door gap keeps its gain: the repository's BENCHMARKS.md, section 5.6).
/// An empty list where no light has one.
fn region_choices(
    sources: &[Range<usize>],
    cell: &FieldCell,
    fraction: f64,
) -> Vec<Option<RegionChoice>> {
    let choices: Vec<Option<RegionChoice>> = sources
        .iter()
        .map(|light| {
            if light.len() != REGIONS || cell.sources_counts(light.clone()).traced < LEAST_EVIDENCE
            {
                return None;
            }
            let seen = cell.sources_visibility(light.clone())?;
            if seen as f64 >= MOST_FREE_DRAWS {
                return None;
            }
            let regions = light.clone().map(|source| source..source + 1);
            let learned = learned_shares(regions, cell, seen)?;
            let weights: [f64; REGIONS] =
                std::array::from_fn(|k| (1.0 - fraction) / REGIONS as f64 + fraction * learned[k]);
            RegionChoice::new(&weights)
        })
        .collect();
    if choices.iter().any(Option::is_some) {
        choices
    } else {
        Vec::new()
    }
}

/// The visibility below which a light's is not trusted to raise its choice further (a
/// light seen by one ray in a hundred, whose few free rays brought much, is not chosen
/// more than ten times its share of the light).
pub const LEAST_SOURCE_VISIBILITY: f64 = 0.01;

/// A texel whose 2 × 2 block no ray of a cell went to (behind the surface, or where light
/// sampling never draws) weighs this share of the cell's visibility in its guide. Such
/// draws are mostly below the surface's horizon, wasted: at a tenth, 2.4 of 16 candidates
/// per gather were outside the BSDF's support in the sunlit room; at a hundredth, relMSE
/// fell 7–8% in the sunlit and overcast rooms and stayed within noise in the courtyard and
/// the interior (the repository's BENCHMARKS.md, section 5.6). Not zero: a direction that some point of
/// the cell sees but no ray tried keeps a chance beyond the defensive share.
pub const UNSEEN_TEXEL_SHARE: f32 = 0.01;

/// The guide of `cell`: each texel weighed by the square root of its learned visibility,
/// pooled with its neighbours' ([`FieldCell::pooled_visibility_at`]); texels whose block no
/// ray of the cell went to by [`UNSEEN_TEXEL_SHARE`] of the cell's visibility. `None` where
/// the cell has too little evidence or too little contrast, or where most of the
/// environment's draws are free anyway.
fn build(
    partition: &Arc<EnvironmentPartition>,
    cell: &FieldCell,
    fraction: f64,
) -> Option<EnvironmentGuide> {
    if cell.total().traced < LEAST_EVIDENCE {
        return None;
    }
    // The cosine alone makes a guide worth drawing from: it follows the integrand's cosine
    // wherever the sky lies. Without it, only the visibility's contrast can.
    if cell.normal().is_none() && !contrast_worth_guiding(partition, cell) {
        return None;
    }
    let cosines = texel_cosines(cell);
    let (product, defensive) = (
        product_weights(cell, &cosines),
        defensive_weights(cell, &cosines),
    );
    // The mixture `(1 − β) p_env H_t + β p_env A_t / Z_A`, renormalised, is itself a
    // product of the environment with per-texel weights: drawn as one. Draws that H_t takes
    // away from behind the surface go to both parts in proportion, and the defensive part
    // keeps at least (1 − β) of the environment's density wherever H_t = 1.
    let product_mass: f64 = (0..product.len())
        .map(|t| partition.texel_mass(t) * product[t])
        .sum();
    let mut guide = EnvironmentGuide::new(partition.clone());
    guide.set_fraction(1.0);
    guide.set_affinities(|texel| {
        ((1.0 - fraction) * defensive[texel]
            + fraction * product[texel] / product_mass.max(f64::MIN_POSITIVE)) as f32
    });
    Some(guide)
}

/// `A_t`, the product's weight of each texel of `cell`: the square root of its learned
/// visibility, pooled with its neighbours' (texels whose block no ray of the cell went to:
/// a hundredth of the cell's visibility, [`UNSEEN_TEXEL_SHARE`]), times the cosine to the
/// cell's normal where it knows one (at least [`LEAST_TEXEL_COSINE`]; behind the surface,
/// its absolute value where rays went, as through a surface that transmits). `cosines` are
/// [`texel_cosines`]'.
///
/// Why the square root: the guide serves every gather of the cell, and a texel's
/// visibility `v` is the share of them (and of its directions) that see through it. Their
/// mean second moment, Σ f² v / q over the texels, is least for `q ∝ f √v`; `q ∝ f v`
/// starves the texels that some of the cell's points see fully (a window's edge, beside a
/// wall), whose candidates then weigh too much there.
fn product_weights(cell: &FieldCell, cosines: &[Option<f32>]) -> Vec<f64> {
    let unseen = UNSEEN_TEXEL_SHARE * cell.visibility();
    (cosines.iter().enumerate())
        .map(|(texel, &cosine)| {
            let weight = match (cell.pooled_visibility_at(texel), cosine) {
                (Some(visibility), Some(c)) => visibility.sqrt() * c.abs().max(LEAST_TEXEL_COSINE),
                (None, Some(c)) => unseen * c.max(LEAST_TEXEL_COSINE),
                (visibility, None) => visibility.map_or(unseen, f32::sqrt),
            };
            weight as f64
        })
        .collect()
}

/// `H_t`, the defensive share's weight of each texel of `cell`: 1 wherever light may come
/// from, [`UNSEEN_TEXEL_SHARE`] behind a surface that only reflects (below the cell's
/// horizon by more than [`HORIZON_SLACK`], where no ray of the cell went). `cosines` are
/// [`texel_cosines`]'.
fn defensive_weights(cell: &FieldCell, cosines: &[Option<f32>]) -> Vec<f64> {
    (cosines.iter().enumerate())
        .map(|(texel, &cosine)| match cosine {
            Some(c) if c < -HORIZON_SLACK && cell.pooled_visibility_at(texel).is_none() => {
                UNSEEN_TEXEL_SHARE as f64
            }
            _ => 1.0,
        })
        .collect()
}

/// Whether a cell's visibilities alone make a guide worth it: its darkest texel is below
/// [`GUIDE_CONTRAST`] of its visibility, and fewer than [`MOST_FREE_DRAWS`] of the
/// environment's own draws would be free.
fn contrast_worth_guiding(partition: &EnvironmentPartition, cell: &FieldCell) -> bool {
    let texels = (cell.side() * cell.side()) as usize;
    let free_draws: f64 = (0..texels)
        .map(|t| partition.texel_mass(t) * cell.pooled_visibility_at(t).unwrap_or(0.0) as f64)
        .sum();
    cell.darkest() < GUIDE_CONTRAST * cell.visibility() && free_draws < MOST_FREE_DRAWS
}

/// The cosine between the cell's mean normal and each texel's centre, in texel order
/// (`None` where the cell's normals disagree: [`FieldCell::normal`]).
fn texel_cosines(cell: &FieldCell) -> Vec<Option<f32>> {
    let side = cell.side();
    let normal = cell.normal().map(Vec3::from);
    (0..side * side)
        .map(|texel| {
            let (row, column) = ((texel / side) as f32, (texel % side) as f32);
            let centre =
                octahedral::direction_of([(column + 0.5) / side as f32, (row + 0.5) / side as f32]);
            Some(normal?.dot(Vec3::from(centre).normalize()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::field::{CellKey, FieldObservations, VisibilityField};

    /// A field of one cell whose rays aimed at a sky (source 0) were mostly blocked and
    /// brought little, and at a lamp (source 1) were free and brought much.
    fn cell_under_a_roof(brought: bool) -> (VisibilityField, CellKey) {
        let key = CellKey::new([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0);
        let mut observations = FieldObservations::new(4).with_sources(2);
        let mut cell = observations.cell_mut(key);
        for ray in 0..64 {
            let (source, free) = if ray < 40 {
                (0, ray % 10 == 0)
            } else {
                (1, true)
            };
            cell.record([0.0, 0.0, 1.0], free);
            cell.record_source(source, free);
            if brought && free {
                cell.record_brought(source, if source == 0 { 0.05 } else { 0.125 });
            }
        }
        let mut field = VisibilityField::new(4).with_sources(2);
        field.merge(&observations);
        (field, key)
    }

    #[test]
    fn a_cell_chooses_the_lights_that_brought_its_light() {
        let (field, key) = cell_under_a_roof(true);
        let cell = field.cell(&key).unwrap();
        let power = [0.99, 0.01];
        let choice = light_choice(&power, &[0..1, 1..2], &cell, 0.75).expect("learned");
        // The sky brought 0.2 through a tenth of its rays, the lamp 3 through all of
        // them: the learned shares are 0.2 / √0.1 against 3 / √1 (up to the prior).
        let lamp = choice.probability(1) as f64;
        let sky = choice.probability(0) as f64;
        assert!(lamp > 0.6, "the lamp's share {lamp}");
        // The defensive share keeps every light at least a quarter of its power share.
        assert!(sky >= 0.25 * 0.99 - 1e-6, "the sky's share {sky}");
        assert!((sky + lamp - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_cell_whose_rays_brought_nothing_chooses_by_power() {
        let (field, key) = cell_under_a_roof(false);
        let cell = field.cell(&key).unwrap();
        assert!(light_choice(&[0.99, 0.01], &[0..1, 1..2], &cell, 0.75).is_none());
    }

    /// A texel that a quarter of the cell's rays found free gets half the weight of one
    /// they all found free (the square root of its visibility, the share that minimises
    /// the cell's second moment), not a quarter.
    #[test]
    fn a_texel_weighs_the_square_root_of_its_visibility() {
        let key = CellKey::new([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0);
        let mut observations = FieldObservations::new(4);
        let mut cell = observations.cell_mut(key);
        for ray in 0..400 {
            cell.record([0.0, 0.0, 1.0], ray % 4 == 0);
            cell.record([0.0, 0.0, -1.0], true);
        }
        let mut field = VisibilityField::new(4);
        field.merge(&observations);
        let cell = field.cell(&key).unwrap();
        let side = cell.side();
        let (up, down) = (
            octahedral::texel_of([0.0, 0.0, 1.0], side),
            octahedral::texel_of([0.0, 0.0, -1.0], side),
        );
        let (v_up, v_down) = (
            cell.pooled_visibility_at(up).expect("seen"),
            cell.pooled_visibility_at(down).expect("seen"),
        );
        assert!(v_up < 0.5 * v_down, "visibilities {v_up} and {v_down}");
        // Without a normal, the weights are the visibilities' square roots alone.
        let weights = product_weights(&cell, &vec![None; (side * side) as usize]);
        let ratio = weights[up] / weights[down];
        let expected = (v_up as f64 / v_down as f64).sqrt();
        assert!(
            (ratio - expected).abs() < 1e-6,
            "{ratio} against {expected}"
        );
    }
}
