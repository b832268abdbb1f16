//! Guided gathers: the fixed map of a shared-map gather folded into the proposal instead of
//! used for Russian roulette.
//!
//! `map_use = proposal` blends the same neighbourhood map as `map = neighbours`
//! ([`ais::shared`]) and holds it fixed, but rather than drawing candidates from the
//! strategy's density `p` and skipping those the map thinks blocked, it changes what is drawn,
//! so every in-support candidate is traced and weighs `f / q`: nothing is paid for rejected
//! candidates and stratified placement stays stratified.
//! - Strategies that sample lights, in a scene with an environment map, draw the environment
//!   from a defensive mixture with its exact product with the map
//!   ([`crate::lights::EnvironmentGuide`]); the BSDF half of MIS is unchanged.
//! - Other strategies draw from `q = (1 − α) p + α g`, where `g` is piecewise constant over
//!   the map's texels with probabilities ∝ affinity × `p` at the texel's centre × solid
//!   angle (an approximation of the product `p · affinity`).
//!
//! Both keep a share of the unguided density everywhere, so the estimate is exactly
//! unbiased whatever the map says, and a wrong map costs at most `1 / (1 − α)` in variance.

use super::strategy::{CandidateDraw, GatherPoint, MisParts, Strategy};
use crate::lights::{Environment, EnvironmentGuide, Toward};
use ais::mapping::LatLong;
use ais::{AffinityMap, TexelDistribution};

/// The default share α of the guide in the mixture `q = (1 − α) p + α g`.
pub const GUIDE_FRACTION: f32 = 0.5;

/// The least affinity a guide gives any texel, so that no direction loses all density.
pub const GUIDE_FLOOR: f32 = 1e-3;

/// What a gather draws candidates from: the strategy alone, or mixed with a guide.
#[derive(Clone, Copy)]
pub struct CandidateSampler<'a> {
    strategy: Strategy,
    guide: Option<&'a TexelDistribution>,
    /// The guide's share α.
    fraction: f32,
}

impl<'a> CandidateSampler<'a> {
    /// The strategy alone.
    pub fn plain(strategy: Strategy) -> Self {
        CandidateSampler {
            strategy,
            guide: None,
            fraction: 0.0,
        }
    }

    /// The mixture of `strategy` (share 1 − `fraction`) and `guide` (share `fraction`, in
    /// [0, 1); clamped so that the strategy always keeps a share and the estimate stays
    /// unbiased).
    pub fn guided(strategy: Strategy, guide: &'a TexelDistribution, fraction: f32) -> Self {
        CandidateSampler {
            strategy,
            guide: Some(guide),
            fraction: fraction.clamp(0.0, 0.99),
        }
    }

    /// The strategy, when nothing is mixed with it.
    pub fn unguided(&self) -> Option<Strategy> {
        self.guide.is_none().then_some(self.strategy)
    }

    /// A candidate direction from `u` ∈ [0, 1)² (`None`: the strategy gave none).
    #[inline]
    pub fn sample_direction(&self, at: &GatherPoint, u: [f32; 2]) -> Option<Toward> {
        at.finish(self.begin_direction(at, u))
    }

    /// [`CandidateSampler::sample_direction`], except that a draw from an environment map,
    /// a rectangle light or the BSDF is left to be made together with other candidates' of
    /// its kind ([`CandidateDraw`]).
    #[inline]
    pub fn begin_direction(&self, at: &GatherPoint, u: [f32; 2]) -> CandidateDraw {
        let Some(guide) = self.guide else {
            return self.strategy.begin_direction(at, u);
        };
        let alpha = self.fraction;
        if u[0] < alpha {
            CandidateDraw::Made(Some(Toward::new(guide.sample([u[0] / alpha, u[1]]))))
        } else {
            let rescaled = ((u[0] - alpha) / (1.0 - alpha)).min(1.0 - 1e-7);
            self.strategy.begin_direction(at, [rescaled, u[1]])
        }
    }

    /// MIS's two densities at `toward` when this is the plain MIS proposal and a density
    /// drew it ([`Strategy::mis_parts`]); `None` for a guided mixture.
    #[inline]
    pub fn mis_parts(&self, at: &GatherPoint, toward: &mut Toward) -> Option<MisParts> {
        match self.guide {
            None => self.strategy.mis_parts(at, toward),
            Some(_) => None,
        }
    }

    /// The proposal's density at a direction, in solid angle.
    #[inline]
    pub fn pdf(&self, at: &GatherPoint, toward: &mut Toward) -> f64 {
        let p = self.strategy.pdf(at, toward);
        match self.guide {
            None => p,
            // A point mass of the strategy: the guide's density does not add to it.
            Some(_) if toward.is_point_mass() => (1.0 - self.fraction as f64) * p,
            Some(guide) => {
                let alpha = self.fraction as f64;
                (1.0 - alpha) * p + alpha * guide.pdf(toward.direction) as f64
            }
        }
    }
}

/// How a guided batch draws its candidates.
pub enum Guidance<'g> {
    /// From the strategy alone (no neighbour, or no texel with weight).
    Unguided,
    /// Light sampling draws the environment map from its product with the map.
    Environment(&'g EnvironmentGuide),
    /// From the mixture of the strategy and this texel distribution.
    Mixture(&'g TexelDistribution),
}

/// A thread's reusable guides.
#[derive(Clone, Debug)]
pub struct Guide {
    distribution: TexelDistribution,
    environment: Option<EnvironmentGuide>,
}

impl Guide {
    /// Guides on a map layout of `height` rows.
    pub fn new(height: u32) -> Self {
        Guide {
            distribution: TexelDistribution::new(LatLong::new(height)),
            environment: None,
        }
    }

    /// Bytes held by its distributions.
    pub fn memory_bytes(&self) -> usize {
        self.distribution.memory_bytes()
            + self
                .environment
                .as_ref()
                .map_or(0, EnvironmentGuide::memory_bytes)
    }

    /// How the batch at `at` follows `map` (level 0): strategies that sample lights in a
    /// scene with an environment map draw it from its exact product with the map
    /// ([`EnvironmentGuide`]); the others mix in a texel distribution whose weights are
    /// affinity × the strategy's density at the texel's centre × solid angle (zero where the
    /// centre is outside the BSDF's support).
    pub fn prepare(
        &mut self,
        map: &AffinityMap,
        strategy: Strategy,
        at: &GatherPoint,
        fraction: f32,
    ) -> Guidance<'_> {
        let layout = map.level_layout(0);
        let samples_lights = matches!(strategy, Strategy::Light | Strategy::Mis);
        if let (true, Some(Environment::Map(environment))) =
            (samples_lights, &at.lights.environment)
        {
            if self.environment.as_ref().map(EnvironmentGuide::layout) != Some(layout.into()) {
                self.environment = Some(EnvironmentGuide::new(environment.partition(layout)));
            }
            let guide = self.environment.as_mut().expect("just built");
            guide.set_fraction(fraction as f64);
            // No ray of the neighbours went where the BSDF has no support, so the map knows
            // nothing there: give such texels the floor. Never 0, so the product keeps
            // density wherever light sampling alone had it (exactly unbiased).
            let floor = map.min_affinity(0).max(GUIDE_FLOOR);
            guide.set_affinities(|index| {
                let texel = layout.texel_of_index(index);
                let centre = layout.center_direction(texel);
                if at.bsdf.in_support(at.wo, centre) {
                    map.texel_affinity(0, texel).max(floor)
                } else {
                    floor
                }
            });
            return Guidance::Environment(guide);
        }
        if self.distribution.layout() != layout {
            self.distribution = TexelDistribution::new(layout);
        }
        let built = self.distribution.set_weights(|texel| {
            let centre = layout.center_direction(texel);
            if !at.bsdf.in_support(at.wo, centre) {
                return 0.0;
            }
            let density = strategy.pdf(at, &mut Toward::new(centre)) as f32;
            map.texel_affinity(0, texel) * density * layout.texel_solid_angle(texel.row)
        });
        if built {
            Guidance::Mixture(&self.distribution)
        } else {
            Guidance::Unguided
        }
    }
}
