//! Chi-square goodness-of-fit tests, in the manner of Mitsuba 3's chi2 tests: samples are
//! binned on a lat-long grid and compared with the probability each bin should receive.

use ais::analytic::Proposal;
use ais::chi2::chi_square_p_value;
use ais::mapping::{LatLong, SphericalCoordinates, Texel};
use ais::rng::Pcg32;
use ais::{AffinityMap, Batch, BatchConfig, Decision, Learning, MapStart, Placement};
use glam::DVec3;
use std::f64::consts::PI;

const ROWS: u32 = 16;
const SIGNIFICANCE: f64 = 0.01;

/// Probability of the lat-long bin (row, column) of a `ROWS`-row grid under `proposal`.
fn bin_probability(proposal: Proposal, row: u32, columns: u32) -> f64 {
    let theta0 = row as f64 * PI / ROWS as f64;
    let theta1 = (row + 1) as f64 * PI / ROWS as f64;
    let azimuth_share = 1.0 / columns as f64;
    match proposal {
        Proposal::UniformSphere => (theta0.cos() - theta1.cos()) / 2.0 * azimuth_share,
        Proposal::CosineHemisphere => {
            let clip = |t: f64| t.min(PI / 2.0);
            (clip(theta1).sin().powi(2) - clip(theta0).sin().powi(2)) * azimuth_share
        }
    }
}

fn bin_of(direction: DVec3, layout: LatLong) -> usize {
    layout.index(layout.texel_at(SphericalCoordinates::of(direction.as_vec3())))
}

fn proposal_p_value(proposal: Proposal, samples: u32) -> f64 {
    let layout = LatLong::new(ROWS);
    let mut observed = vec![0.0; layout.texel_count()];
    let mut rng = Pcg32::new(77, 1);
    for _ in 0..samples {
        let (direction, pdf) = proposal.sample([rng.next_f32(), rng.next_f32()]);
        assert!((pdf - proposal.pdf(direction)).abs() < 1e-9 * pdf.max(1.0));
        observed[bin_of(direction, layout)] += 1.0;
    }
    let expected: Vec<f64> = (0..layout.texel_count())
        .map(|i| {
            let row = layout.texel_of_index(i).row;
            samples as f64 * bin_probability(proposal, row, layout.width())
        })
        .collect();
    chi_square_p_value(&observed, &expected)
}

#[test]
fn uniform_sphere_proposal_fits() {
    let p = proposal_p_value(Proposal::UniformSphere, 200_000);
    assert!(p > SIGNIFICANCE, "p = {p}");
}

#[test]
fn cosine_hemisphere_proposal_fits() {
    let p = proposal_p_value(Proposal::CosineHemisphere, 200_000);
    assert!(p > SIGNIFICANCE, "p = {p}");
}

#[test]
fn chi_square_rejects_a_wrong_distribution() {
    // The uniform proposal's samples tested against the cosine expectation must fail.
    let layout = LatLong::new(ROWS);
    let mut observed = vec![0.0; layout.texel_count()];
    let mut rng = Pcg32::new(5, 5);
    let samples = 50_000;
    let mut kept = 0;
    for _ in 0..samples {
        let (direction, _) = Proposal::UniformSphere.sample([rng.next_f32(), rng.next_f32()]);
        if direction.z > 0.0 {
            observed[bin_of(direction, layout)] += 1.0;
            kept += 1;
        }
    }
    let expected: Vec<f64> = (0..layout.texel_count())
        .map(|i| {
            let row = layout.texel_of_index(i).row;
            kept as f64 * bin_probability(Proposal::CosineHemisphere, row, layout.width())
        })
        .collect();
    assert!(chi_square_p_value(&observed, &expected) < 1e-6);
}

/// Traced directions under a fixed map follow p(w) · a(w) / q: the acceptance step is a
/// sampler too. Checked for Halton and random placement.
#[test]
fn accepted_directions_follow_proposal_times_affinity() {
    let map_rows = 8;
    let mut config = BatchConfig {
        learning: Learning::Off,
        ..BatchConfig::default()
    };
    let map_config = ais::MapConfig {
        height: map_rows,
        tol: f32::INFINITY,
        ..ais::MapConfig::default()
    };
    config.affinity = Some(map_config);
    // A map with a random affinity per texel, learned once, then fixed.
    let mut map = AffinityMap::new(map_config).unwrap();
    let layout = map.level_layout(0);
    let mut rng = Pcg32::new(9, 9);
    for index in 0..layout.texel_count() {
        let direction = layout.center_direction(layout.texel_of_index(index));
        let lookup = map.lookup(direction);
        map.record(&lookup, rng.next_f32(), 1.0 + 3.0 * rng.next_f32());
    }
    for placement in [Placement::Halton, Placement::Random] {
        config.placement = placement;
        let mut batch: Batch<f64> = Batch::new(config).unwrap();
        batch.map_mut().unwrap().copy_from(&map);
        let bins = LatLong::new(ROWS);
        let mut observed = vec![0.0; bins.texel_count()];
        let mut traced = 0u32;
        for seed in 0..4_000u64 {
            batch.begin(32, seed, MapStart::Current);
            while let Some(candidate) = batch.next_candidate() {
                let (direction, _) = Proposal::UniformSphere.sample(candidate.u);
                if let Decision::Trace { .. } = batch.decide(direction.as_vec3(), true) {
                    observed[bin_of(direction, bins)] += 1.0;
                    traced += 1;
                    batch.record(0.0, 1.0);
                }
            }
            batch.finish();
        }
        // Expected: proposal probability of the bin times the affinity of its map texel.
        let weights: Vec<f64> = (0..bins.texel_count())
            .map(|i| {
                let bin = bins.texel_of_index(i);
                let texel = Texel {
                    row: bin.row * map_rows / ROWS,
                    column: bin.column * map_rows / ROWS,
                };
                bin_probability(Proposal::UniformSphere, bin.row, bins.width())
                    * map.texel_affinity(0, texel) as f64
            })
            .collect();
        let total: f64 = weights.iter().sum();
        let expected: Vec<f64> = weights.iter().map(|w| w / total * traced as f64).collect();
        let p = chi_square_p_value(&observed, &expected);
        assert!(p > SIGNIFICANCE, "{placement:?}: p = {p}");
    }
}

/// Samples of a texel distribution with uneven weights (some zero), binned on a grid that is
/// not the texels' (uniform in cos θ, offset in φ), against the integral of its own density.
#[test]
fn texel_distribution_fits_its_density() {
    use ais::TexelDistribution;
    let mut distribution = TexelDistribution::new(LatLong::new(4));
    let mut weights = Pcg32::new(9, 9);
    assert!(distribution.set_weights(|_| {
        let w = weights.next_f32();
        if w < 0.3 {
            0.0
        } else {
            w * w
        }
    }));
    let (columns, rows) = (20usize, 10usize);
    let bin = |direction: glam::Vec3| {
        let cos_row = (((1.0 - direction.z) / 2.0 * rows as f32) as usize).min(rows - 1);
        let phi = (direction.y.atan2(direction.x) as f64 + 0.3).rem_euclid(2.0 * PI);
        let column = ((phi / (2.0 * PI) * columns as f64) as usize).min(columns - 1);
        cos_row * columns + column
    };
    let samples = 300_000u32;
    let mut observed = vec![0.0; columns * rows];
    let mut rng = Pcg32::new(4, 2);
    for _ in 0..samples {
        let direction = distribution.sample([rng.next_f32(), rng.next_f32()]);
        assert!((direction.length() - 1.0).abs() < 1e-5);
        assert!(
            distribution.pdf(direction) > 0.0,
            "sampled where the density is 0"
        );
        observed[bin(direction)] += 1.0;
    }
    // Midpoint rule on 48 × 48 sub-cells per bin (each of equal solid angle).
    let sub = 48;
    let mut expected = vec![0.0; columns * rows];
    for (index, e) in expected.iter_mut().enumerate() {
        let (cos_row, column) = (index / columns, index % columns);
        let mut sum = 0.0f64;
        for i in 0..sub {
            for j in 0..sub {
                let z = 1.0 - 2.0 * (cos_row as f64 + (i as f64 + 0.5) / sub as f64) / rows as f64;
                let phi = 2.0 * PI * (column as f64 + (j as f64 + 0.5) / sub as f64)
                    / columns as f64
                    - 0.3;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let d = glam::Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32);
                sum += distribution.pdf(d) as f64;
            }
        }
        let bin_solid_angle = 4.0 * PI / (columns * rows) as f64;
        *e = samples as f64 * sum / (sub * sub) as f64 * bin_solid_angle;
    }
    let total: f64 = expected.iter().sum();
    assert!(
        (total / samples as f64 - 1.0).abs() < 2e-3,
        "density integrates to {}",
        total / samples as f64
    );
    let p = chi_square_p_value(&observed, &expected);
    assert!(p > SIGNIFICANCE, "p = {p}");
}
