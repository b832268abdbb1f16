//! Chi-square goodness-of-fit tests of the library's samplers with the shared harness
//! ([`ais::testing::ChiSquareTest`]): the analytic proposals, the batch's acceptance (itself a
//! sampler of p · a) and the texel distribution. The harness's negative control is in its own
//! unit tests; one more here rejects a proposal checked against another's density.

use ais::analytic::Proposal;
use ais::rng::Pcg32;
use ais::testing::{ChiSquareTest, Drawn};
use ais::{AffinityMap, Batch, BatchConfig, Decision, Learning, MapStart, Placement};
use ais::{MapConfig, TexelDistribution};

const SIGNIFICANCE: f64 = 0.01;

fn proposal_fit(proposal: Proposal, against: Proposal) -> ais::testing::ChiSquareOutcome {
    let test = ChiSquareTest {
        rows: 16,
        samples: 200_000,
        seed: 77,
        ..ChiSquareTest::default()
    };
    test.run(
        |u| {
            let (direction, pdf) = proposal.sample(u);
            Some(Drawn::with_pdf(direction.as_vec3(), pdf))
        },
        |d| against.pdf(d.as_dvec3()),
    )
}

#[test]
fn uniform_sphere_proposal_fits() {
    let outcome = proposal_fit(Proposal::UniformSphere, Proposal::UniformSphere);
    assert!(
        outcome.fits(SIGNIFICANCE),
        "{:?}",
        outcome.problem(SIGNIFICANCE)
    );
}

#[test]
fn cosine_hemisphere_proposal_fits() {
    let outcome = proposal_fit(Proposal::CosineHemisphere, Proposal::CosineHemisphere);
    assert!(
        outcome.fits(SIGNIFICANCE),
        "{:?}",
        outcome.problem(SIGNIFICANCE)
    );
}

#[test]
fn chi_square_rejects_a_wrong_distribution() {
    // The cosine proposal's samples tested against the uniform density must fail.
    let outcome = proposal_fit(Proposal::CosineHemisphere, Proposal::UniformSphere);
    assert!(!outcome.fits(SIGNIFICANCE), "{outcome:?}");
    assert!(outcome.p_value < 1e-6, "{outcome:?}");
}

/// A map of `rows` rows with a random affinity per texel, learned once.
fn random_map(rows: u32) -> AffinityMap {
    let mut map = AffinityMap::new(MapConfig {
        height: rows,
        tol: f32::INFINITY,
        ..MapConfig::default()
    })
    .unwrap();
    let layout = map.level_layout(0);
    let mut rng = Pcg32::new(9, 9);
    for index in 0..layout.texel_count() {
        let direction = layout.center_direction(layout.texel_of_index(index));
        let lookup = map.lookup(direction);
        map.record(&lookup, rng.next_f32(), 1.0 + 3.0 * rng.next_f32());
    }
    map
}

/// Traced directions under a fixed map follow p(w) · a(w) per candidate: the acceptance step
/// is a sampler too. Checked for Halton and random placement.
#[test]
fn accepted_directions_follow_proposal_times_affinity() {
    let map = random_map(8);
    for placement in [Placement::Halton, Placement::Random] {
        let config = BatchConfig {
            affinity: Some(*map.config()),
            learning: Learning::Off,
            placement,
            ..BatchConfig::default()
        };
        let mut batch: Batch<f64> = Batch::new(config).unwrap();
        batch.map_mut().unwrap().copy_from(&map);
        let mut draws = Vec::new();
        for seed in 0..4_000u64 {
            batch.begin(32, seed, MapStart::Current);
            while let Some(candidate) = batch.next_candidate() {
                let (direction, _) = Proposal::UniformSphere.sample(candidate.u);
                let direction = direction.as_vec3();
                let traced = matches!(batch.decide(direction, true), Decision::Trace { .. });
                draws.push(traced.then(|| Drawn::direction(direction)));
                if traced {
                    batch.record(0.0, 1.0);
                }
            }
            batch.finish();
        }
        let test = ChiSquareTest {
            rows: 16,
            ..ChiSquareTest::default()
        };
        let outcome = test.run_draws(draws.into_iter(), &|d| {
            Proposal::UniformSphere.pdf(d.as_dvec3()) * map.lookup(d).affinity as f64
        });
        assert!(
            outcome.fits(SIGNIFICANCE),
            "{placement:?}: {:?}",
            outcome.problem(SIGNIFICANCE)
        );
    }
}

/// Samples of a texel distribution with uneven weights (some zero), binned on a grid that is
/// not the texels' (21 rows against 4), against its own density.
#[test]
fn texel_distribution_fits_its_density() {
    let mut distribution = TexelDistribution::new(ais::mapping::LatLong::new(4));
    let mut weights = Pcg32::new(9, 9);
    assert!(distribution.set_weights(|_| {
        let w = weights.next_f32();
        if w < 0.3 {
            0.0
        } else {
            w * w
        }
    }));
    let test = ChiSquareTest {
        rows: 21,
        subdivision: 64,
        samples: 300_000,
        seed: 4,
    };
    let outcome = test.run(
        |u| {
            let direction = distribution.sample(u);
            Some(Drawn::with_pdf(
                direction,
                distribution.pdf(direction) as f64,
            ))
        },
        |d| distribution.pdf(d) as f64,
    );
    assert!(
        outcome.fits(SIGNIFICANCE),
        "{:?}",
        outcome.problem(SIGNIFICANCE)
    );
}
