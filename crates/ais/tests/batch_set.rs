//! A batch set gives exactly what its batches give one by one, and its estimates are
//! unbiased.

use ais::{Batch, BatchConfig, BatchSet, Decision, MapConfig, MapStart, Mode, Round};

/// A host's hemisphere sample from a candidate's numbers (uniform, pdf 1/2π).
fn direction([u1, u2]: [f32; 2]) -> [f32; 3] {
    let (r, phi) = ((1.0 - u1 * u1).max(0.0).sqrt(), std::f32::consts::TAU * u2);
    [r * phi.cos(), r * phi.sin(), u1]
}

/// Half the sky is blocked (x < 0): a traced ray's value (cosine over π, over the pdf) and
/// its rating.
fn trace(direction: [f32; 3]) -> (f32, f32) {
    let visible = direction[0] > 0.0;
    let value = 2.0 * direction[2]; // (cos/π) / (1/2π)
    if visible {
        (value, 1.0)
    } else {
        (0.0, 0.0)
    }
}

/// A band of directions lies outside the support (a known zero, rejected unconditionally).
fn in_support(direction: [f32; 3]) -> bool {
    direction[1] > -0.5 || direction[1] < -0.9
}

/// One gather by hand with a single batch.
fn one_by_one(config: BatchConfig, n: u32, seed: u64) -> ais::Estimate<f32> {
    let mut batch: Batch<f32> = Batch::new(config).unwrap();
    batch.begin(n, seed, MapStart::Empty);
    while let Some(candidate) = batch.next_candidate() {
        let d = direction(candidate.u);
        if let Decision::Trace { .. } = batch.decide(d, in_support(d)) {
            let (value, rating) = trace(d);
            batch.record(value, rating);
        }
    }
    batch.finish()
}

/// All gathers together, in rounds.
fn in_rounds(config: BatchConfig, n: u32, seeds: &[u64]) -> Vec<ais::Estimate<f32>> {
    let mut set: BatchSet<f32> = BatchSet::new(config, seeds.len()).unwrap();
    set.begin(n, seeds);
    let mut round: Round<f32> = set.round_buffers();
    while set.next_candidates(&mut round) > 0 {
        for g in (0..seeds.len()).filter(|&g| round.active[g]) {
            round.directions[g] = direction(round.u[g]);
            round.in_support[g] = in_support(round.directions[g]);
        }
        set.decide(&mut round);
        for g in (0..seeds.len()).filter(|&g| round.trace[g]) {
            (round.contributions[g], round.ratings[g]) = trace(round.directions[g]);
        }
        set.record(&round);
    }
    set.finish()
}

fn configurations() -> [BatchConfig; 3] {
    let conservative = BatchConfig {
        affinity: Some(MapConfig {
            mode: Mode::Conservative,
            ..MapConfig::default()
        }),
        ..BatchConfig::default()
    };
    [BatchConfig::off(), BatchConfig::default(), conservative]
}

#[test]
fn a_batch_set_equals_its_batches_one_by_one() {
    let seeds: Vec<u64> = (0..37).map(|i| i * 7919 + 3).collect();
    for config in configurations() {
        let together = in_rounds(config, 24, &seeds);
        for (estimate, &seed) in together.iter().zip(&seeds) {
            assert_eq!(*estimate, one_by_one(config, 24, seed), "{config:?}");
        }
    }
}

#[test]
fn batch_set_estimates_are_unbiased() {
    // The exact value by a fine quadrature of the same integrand over the hemisphere.
    let steps = 2000;
    let mut exact = 0.0f64;
    for i in 0..steps {
        for j in 0..steps {
            let u = [
                (i as f32 + 0.5) / steps as f32,
                (j as f32 + 0.5) / steps as f32,
            ];
            let d = direction(u);
            if in_support(d) {
                exact += trace(d).0 as f64;
            }
        }
    }
    exact /= (steps * steps) as f64;
    let seeds: Vec<u64> = (0..4000).collect();
    for config in configurations() {
        let values: Vec<f64> = in_rounds(config, 16, &seeds)
            .iter()
            .map(|e| e.value as f64)
            .collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let variance =
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (values.len() - 1) as f64;
        let standard_error = (variance / values.len() as f64).sqrt();
        assert!(
            (mean - exact).abs() < 4.0 * standard_error,
            "{config:?}: {mean} vs exact {exact} (SE {standard_error})"
        );
    }
}
