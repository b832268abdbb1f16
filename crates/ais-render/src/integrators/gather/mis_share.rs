//! The BSDF's share of one-sample MIS, learned from the gathers' own candidates.
//!
//! MIS draws a candidate from the BSDF with probability `c` and from the lights otherwise,
//! and weighs it by the mixture's density `q_c = c p_B + (1 − c) p_L`. Which `c` is best
//! depends on the scene: under an open sky light sampling finds the sun that the BSDF
//! misses; where the field guides light sampling through a window it finds the light that
//! the BSDF's draws at the walls miss; on a glossy surface the BSDF does better. A gather's
//! variance is `(M(c) − μ²) / n`, with `M(c) = ∫ f² / q_c` its second moment and `μ` its
//! mean, which does not depend on `c`. Candidates drawn with share `c₀` estimate `M(c)`
//! for every `c` at once, without bias: `M̂(c) = mean(f² / (q_c · q_{c₀}))` over them, or
//! `(f / q_{c₀})² · q_{c₀} / q_c` per candidate, where `f / q_{c₀}` is the candidate's value
//! and both densities are known. The ratio `q_{c₀} / q_c` is at most `max(c₀ / c,
//! (1 − c₀) / (1 − c))`, so the estimates are no heavier-tailed than the gathers
//! themselves.
//!
//! A pass sums these over its gathers and the next pass uses the share with the least sum:
//! the least summed variance of the gathers' estimates, the image's squared error in
//! radiance. (relMSE weighs dark pixels more; weighing each gather by `1 / (E² + 0.01)`
//! with `E` its own estimate, noisy as it is, chose a share that raised relMSE by a quarter
//! behind a roof edge: the repository's BENCHMARKS.md, section 5.6.) A pass's share depends
//! only on earlier passes, so every pass is unbiased, and the sums are added in tile order,
//! so the choice does not depend on the thread count.

use super::strategy::MisParts;

/// The BSDF shares a render chooses among (the default,
/// [`MIS_BSDF_WEIGHT`](super::strategy::MIS_BSDF_WEIGHT), among them).
pub const MIS_SHARES: [f64; 4] = [0.125, 0.25, 0.5, 0.75];

/// A share is chosen only from at least this many gathers with light, else the last share
/// stays.
pub const LEAST_GATHERS: u64 = 500;

/// The second moments of the gathers of a pass at every share of [`MIS_SHARES`].
#[derive(Clone, Debug, Default)]
pub struct ShareMoments {
    /// Per share, the sum over the pass's gathers of their weighted moment estimates.
    sums: [f64; MIS_SHARES.len()],
    /// The current gather's sums per share.
    gather: [f64; MIS_SHARES.len()],
    /// Gathers with a candidate that brought light.
    gathers: u64,
}

impl ShareMoments {
    /// Adds a candidate of value `value` (luminance of `f / q`, nonzero) drawn with share
    /// `used`, where MIS's two densities are `parts`.
    #[inline]
    pub fn add(&mut self, value: f32, parts: MisParts, used: f64) {
        let drawn = parts.mixed(used);
        let square = (value as f64) * (value as f64);
        for (sum, &share) in self.gather.iter_mut().zip(&MIS_SHARES) {
            let density = parts.mixed(share);
            if density > 0.0 {
                *sum += square * drawn / density;
            }
        }
    }

    /// Ends a gather: its sums join the pass's.
    pub fn end_gather(&mut self) {
        if self.gather.iter().all(|&sum| sum == 0.0) {
            return;
        }
        for (sum, gather) in self.sums.iter_mut().zip(&mut self.gather) {
            *sum += *gather;
            *gather = 0.0;
        }
        self.gathers += 1;
    }

    /// Adds another tile's sums (tiles in order, so that the sums do not depend on the
    /// thread count).
    pub fn merge(&mut self, other: &ShareMoments) {
        for (sum, other) in self.sums.iter_mut().zip(&other.sums) {
            *sum += other;
        }
        self.gathers += other.gathers;
    }

    /// The share with the least second moment, or `None` from fewer than
    /// [`LEAST_GATHERS`] gathers.
    pub fn best(&self) -> Option<f64> {
        if self.gathers < LEAST_GATHERS {
            return None;
        }
        let least = (0..MIS_SHARES.len()).min_by(|&a, &b| self.sums[a].total_cmp(&self.sums[b]));
        least.map(|k| MIS_SHARES[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::rng::Pcg32;

    /// A one-dimensional gather on [0, 1]: the BSDF draws uniformly, the light draws with
    /// density 2x, and the integrand is `light_weight · 2x + (1 − light_weight)`.
    fn variance_at(share: f64, light_weight: f64, rng: &mut Pcg32) -> (f64, ShareMoments) {
        let mut moments = ShareMoments::default();
        let (mut sum, mut square) = (0.0, 0.0);
        let n = 200_000;
        for _ in 0..n {
            let (u, v) = (rng.next_f64(), rng.next_f64());
            let x = if u < share { v } else { v.sqrt() };
            let parts = MisParts {
                bsdf: 1.0,
                light: 2.0 * x,
            };
            let f = light_weight * 2.0 * x + (1.0 - light_weight);
            let value = f / parts.mixed(share);
            sum += value;
            square += value * value;
            moments.add(value as f32, parts, share);
        }
        moments.end_gather();
        let mean = sum / n as f64;
        (square / n as f64 - mean * mean, moments)
    }

    #[test]
    fn the_moments_of_every_share_come_from_one_share_s_draws() {
        let mut rng = Pcg32::new(7, 1);
        for light_weight in [0.05, 0.95] {
            let (_, moments) = variance_at(0.5, light_weight, &mut rng);
            // Each share's own variance, measured by drawing with it.
            let variances: Vec<f64> = MIS_SHARES
                .iter()
                .map(|&share| variance_at(share, light_weight, &mut rng).0)
                .collect();
            let best = (0..MIS_SHARES.len())
                .min_by(|&a, &b| variances[a].total_cmp(&variances[b]))
                .map(|k| MIS_SHARES[k]);
            // One gather of n candidates: the sums estimate n × M(c).
            let mean_squared = |k: usize| moments.sums[k] / 200_000.0;
            for (k, &share) in MIS_SHARES.iter().enumerate() {
                let direct = variance_at(share, light_weight, &mut rng).1;
                let own = direct.sums[k] / 200_000.0;
                assert!(
                    (mean_squared(k) / own - 1.0).abs() < 0.02,
                    "share {share}: {} from share 0.5's draws, {own} from its own",
                    mean_squared(k),
                );
            }
            let mut enough = moments.clone();
            enough.gathers = LEAST_GATHERS;
            assert_eq!(enough.best(), best, "light weight {light_weight}");
        }
    }
}
