//! Walker's alias method: a discrete distribution sampled in O(1) from one uniform number,
//! with one table lookup and one comparison whatever the number of bins.
//!
//! Every bin `i` of `n` holds a threshold `t_i` and an alias `a_i`. A uniform `u` picks bin
//! `i = ⌊u n⌋`; the fraction `f = u n − i` keeps `i` when `f < t_i` and gives `a_i`
//! otherwise. The tables are built (Vose's method, in f64) so that bin `j` is returned with
//! probability exactly `w_j / Σ w` up to the f32 rounding of the thresholds, and a bin of
//! zero weight is never returned. The fraction, rescaled to [0, 1), is handed back so that
//! the caller can place a point inside the bin without another random number.

/// One bin of an alias table.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AliasBin {
    /// The bin keeps itself when the fraction is below this.
    threshold: f32,
    /// The bin given otherwise.
    alias: u32,
}

/// A discrete distribution over `0..len()` sampled in O(1).
#[derive(Clone, Debug)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
    /// Each bin's probability.
    probabilities: Vec<f32>,
    /// The sum of the input weights.
    total: f64,
}

impl AliasTable {
    /// A table proportional to `weights`. Negative and non-finite weights count as zero; an
    /// all-zero (or empty) input gives the uniform distribution, so that sampling stays
    /// defined.
    pub fn new(weights: &[f64]) -> Self {
        let (clean, total, sum) = super::distribution::sampling_weights(weights);
        let probabilities: Vec<f32> = clean.iter().map(|&w| (w / sum) as f32).collect();
        AliasTable {
            bins: build_bins(&clean, sum),
            probabilities,
            total: total.max(0.0),
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Whether there are no bins (never: at least one bin exists).
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// The sum of the input weights (zero if they were all zero).
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Probability of bin `i`.
    #[inline]
    pub fn probability(&self, i: usize) -> f32 {
        self.probabilities[i]
    }

    /// A bin drawn from `u` ∈ [0, 1), and a number in [0, 1) left over from `u`, uniform and
    /// independent of the bin when `u` is uniform. It carries about 24 − log2(len) bits.
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        draw(&self.bins, u)
    }
}

/// The bin of `bins` (a table built by [`build_bins`]) drawn from `u`, and what is left of
/// `u`: [`AliasTable::sample`].
#[inline]
pub(crate) fn draw(bins: &[AliasBin], u: f32) -> (usize, f32) {
    let n = bins.len();
    let scaled = u.clamp(0.0, 1.0) * n as f32;
    let i = (scaled as usize).min(n - 1);
    let fraction = (scaled - i as f32).clamp(0.0, 1.0);
    let bin = bins[i];
    if fraction < bin.threshold {
        (i, (fraction / bin.threshold).min(ONE_BELOW))
    } else {
        let rest = 1.0 - bin.threshold;
        let left = if rest > 0.0 {
            (fraction - bin.threshold) / rest
        } else {
            0.0
        };
        (bin.alias as usize, left.clamp(0.0, ONE_BELOW))
    }
}

/// The largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// Vose's construction: bins scaled to mean 1, each under-full bin topped up by an
/// over-full one.
pub(crate) fn build_bins(weights: &[f64], sum: f64) -> Vec<AliasBin> {
    let n = weights.len();
    let mut scaled: Vec<f64> = weights.iter().map(|&w| w * n as f64 / sum).collect();
    let mut bins: Vec<AliasBin> = (0..n)
        .map(|i| AliasBin {
            threshold: 1.0,
            alias: i as u32,
        })
        .collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        bins[s] = AliasBin {
            threshold: scaled[s] as f32,
            alias: l as u32,
        };
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left is full up to rounding. A left-over bin of zero weight (possible only
    // through rounding) must still never be returned: send it to a bin that has weight.
    let heaviest = (0..n)
        .max_by(|&a, &b| weights[a].total_cmp(&weights[b]))
        .unwrap_or(0);
    for i in small.into_iter().chain(large) {
        bins[i] = if weights[i] > 0.0 {
            AliasBin {
                threshold: 1.0,
                alias: i as u32,
            }
        } else {
            AliasBin {
                threshold: 0.0,
                alias: heaviest as u32,
            }
        };
    }
    bins
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact probability with which the table returns each bin, from its thresholds.
    fn realised(table: &AliasTable) -> Vec<f64> {
        let n = table.len();
        let mut p = vec![0.0; n];
        for (i, bin) in table.bins.iter().enumerate() {
            p[i] += bin.threshold as f64 / n as f64;
            p[bin.alias as usize] += (1.0 - bin.threshold as f64) / n as f64;
        }
        p
    }

    #[test]
    fn the_table_returns_each_bin_with_its_weight() {
        let mut rng = crate::rng::Pcg32::new(3, 9);
        for size in [1usize, 2, 3, 7, 64, 1000] {
            // Uneven weights with runs of zeros, as a sky with a sun has.
            let weights: Vec<f64> = (0..size)
                .map(|i| match i % 5 {
                    0 => 0.0,
                    1 => 1e4 * rng.next_f32() as f64,
                    _ => rng.next_f32() as f64,
                })
                .collect();
            let table = AliasTable::new(&weights);
            let sum: f64 = weights.iter().sum();
            for (i, p) in realised(&table).into_iter().enumerate() {
                let expected = if sum > 0.0 {
                    weights[i] / sum
                } else {
                    1.0 / size as f64
                };
                assert!(
                    (p - expected).abs() < 1e-6,
                    "bin {i} of {size}: {p} vs {expected}"
                );
                assert!((table.probability(i) as f64 - expected).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn a_bin_of_zero_weight_is_never_drawn() {
        let table = AliasTable::new(&[0.0, 3.0, 0.0, 1.0, 0.0]);
        for k in 0..10_000 {
            let (bin, left) = table.sample(k as f32 / 10_000.0);
            assert!(bin == 1 || bin == 3, "drew {bin}");
            assert!((0.0..1.0).contains(&left));
        }
    }

    #[test]
    fn degenerate_inputs_give_a_uniform_table() {
        let table = AliasTable::new(&[0.0, f64::NAN, -1.0]);
        assert_eq!(table.total(), 0.0);
        for i in 0..3 {
            assert!((table.probability(i) - 1.0 / 3.0).abs() < 1e-7);
        }
        assert_eq!(AliasTable::new(&[]).len(), 1);
        assert_eq!(table.sample(1.0).0, 2);
    }
}
