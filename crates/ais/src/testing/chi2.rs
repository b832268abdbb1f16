//! Pearson's chi-square goodness-of-fit statistic and its p-value, pooling sparse cells as
//! Mitsuba 3's chi2 tests do.

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
/// expected count is below 5 (as Mitsuba's chi2 tests do). Returns the p-value; 0 when a
/// sample fell in a cell whose expected count is zero.
pub fn chi_square_p_value(observed: &[f64], expected: &[f64]) -> f64 {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut statistic, mut dof) = (0.0, 0.0);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for index in order {
        if expected[index] == 0.0 {
            if observed[index] > 0.0 {
                // A sample where the density is zero: the fit is certainly wrong.
                return 0.0;
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_tail_matches_tables() {
        // Critical values at 5%: 3.841 (1 dof), 18.307 (10 dof), 124.342 (100 dof).
        assert!((chi_square_tail(3.841, 1.0) - 0.05).abs() < 1e-3);
        assert!((chi_square_tail(18.307, 10.0) - 0.05).abs() < 1e-3);
        assert!((chi_square_tail(124.342, 100.0) - 0.05).abs() < 1e-3);
    }

    #[test]
    fn pooling_and_a_perfect_fit() {
        let expected = [100.0, 100.0, 2.0, 2.0, 2.0];
        let observed = [100.0, 100.0, 2.0, 2.0, 2.0];
        assert!(chi_square_p_value(&observed, &expected) > 0.99);
        let skewed = [150.0, 50.0, 2.0, 2.0, 2.0];
        assert!(chi_square_p_value(&skewed, &expected) < 1e-6);
    }
}
