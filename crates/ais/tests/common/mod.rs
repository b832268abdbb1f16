//! Helpers shared by the statistical tests: batch statistics and the chi-square test.
#![allow(dead_code)]

use ais::analytic::{gather, GatherTarget, Moments, Proposal, Scene};
use ais::{Batch, BatchConfig, MapStart};

/// The sample mean, variance and mean traced rays of many independent batches.
#[derive(Clone, Copy, Debug)]
pub struct Summary {
    pub mean: f64,
    pub variance: f64,
    pub standard_error: f64,
    pub traced: f64,
}

impl Summary {
    /// Bias in standard errors against `exact`.
    pub fn z(&self, exact: f64) -> f64 {
        (self.mean - exact) / self.standard_error
    }

    /// Variance times mean traced rays: what equal-traced-ray comparisons divide.
    pub fn cost_variance(&self) -> f64 {
        self.variance * self.traced
    }
}

/// Runs `batches` batches with seeds `seed_base..seed_base + batches`.
pub fn summarize(
    config: BatchConfig,
    scene: &Scene,
    proposal: Proposal,
    n: u32,
    batches: u32,
    target: GatherTarget,
) -> Summary {
    let mut batch: Batch<f64> = Batch::new(config).expect("valid configuration");
    summarize_with(
        &mut batch,
        scene,
        proposal,
        n,
        batches,
        target,
        MapStart::Empty,
    )
}

/// [`summarize`] with a prepared batch (e.g. holding a fixed map) and map start.
pub fn summarize_with(
    batch: &mut Batch<f64>,
    scene: &Scene,
    proposal: Proposal,
    n: u32,
    batches: u32,
    target: GatherTarget,
    start: MapStart,
) -> Summary {
    let traced_before = batch.stats().traced;
    let mut moments = Moments::default();
    for seed in 0..batches {
        moments.add(
            gather(
                batch,
                scene,
                proposal,
                n,
                1_000_003 * seed as u64 + 17,
                start,
                target,
            )
            .value,
        );
    }
    Summary {
        mean: moments.mean(),
        variance: moments.variance(),
        standard_error: moments.standard_error(),
        traced: (batch.stats().traced - traced_before) as f64 / batches as f64,
    }
}

/// Upper tail probability of the chi-square distribution with `dof` degrees of freedom.
pub fn chi_square_tail(statistic: f64, dof: f64) -> f64 {
    1.0 - regularized_lower_gamma(dof / 2.0, statistic / 2.0)
}

/// P(a, x), by its series for x < a + 1 and by a continued fraction otherwise.
fn regularized_lower_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let log_prefactor = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut k) = (1.0 / a, 1.0 / a, a);
        while term.abs() > sum.abs() * 1e-15 {
            k += 1.0;
            term *= x / k;
            sum += term;
        }
        sum * log_prefactor.exp()
    } else {
        // Lentz's method for the continued fraction of Q(a, x).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        1.0 - log_prefactor.exp() * h
    }
}

/// ln Γ(x) by the Lanczos approximation (g = 7, 9 terms).
fn ln_gamma(x: f64) -> f64 {
    const COEFFICIENTS: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let t = x + 7.5;
    let series = COEFFICIENTS[1..]
        .iter()
        .enumerate()
        .fold(COEFFICIENTS[0], |acc, (i, c)| {
            acc + c / (x + i as f64 + 1.0)
        });
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + series.ln()
}

/// Pearson's chi-square test of observed against expected counts, pooling cells whose
/// expected count is below 5 (as Mitsuba's chi2 tests do). Returns the p-value.
pub fn chi_square_p_value(observed: &[f64], expected: &[f64]) -> f64 {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut statistic, mut dof) = (0.0, 0.0);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for index in order {
        if expected[index] == 0.0 {
            assert!(
                observed[index] == 0.0,
                "sample in a cell of zero density: {index}"
            );
            continue;
        }
        if expected[index] < 5.0 {
            pooled_observed += observed[index];
            pooled_expected += expected[index];
            if pooled_expected >= 5.0 {
                statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
                dof += 1.0;
                pooled_observed = 0.0;
                pooled_expected = 0.0;
            }
            continue;
        }
        statistic += (observed[index] - expected[index]).powi(2) / expected[index];
        dof += 1.0;
    }
    if pooled_expected > 0.0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        dof += 1.0;
    }
    chi_square_tail(statistic, dof - 1.0)
}
