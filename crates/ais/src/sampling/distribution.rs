//! Piecewise-constant distributions in 1-D and 2-D (Pharr-Humphreys), with sampling, density
//! and inversion. The 2-D one drives environment-map importance sampling.

/// A piecewise-constant density on [0, 1) with `n` equal bins.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// Bin weights (non-negative).
    weights: Vec<f64>,
    /// Cumulative distribution at bin edges, `n + 1` values from 0 to 1.
    cdf: Vec<f64>,
    /// Sum of the weights divided by n (the mean of the function).
    integral: f64,
    /// Guide table (the cutpoint method): entry `k` is the first bin whose upper edge
    /// exceeds `k / n`, so sampling starts its search there and takes O(1) steps on
    /// average instead of a binary search (the same bin, hence the same samples).
    guide: Vec<u32>,
}

/// Weights made usable for sampling: negative and non-finite ones count as zero, an empty
/// input is one bin, and all-zero weights become uniform. Returns them, the sum of the
/// original (cleaned) weights, and the sum of the returned ones.
pub(crate) fn sampling_weights(weights: &[f64]) -> (Vec<f64>, f64, f64) {
    let mut clean: Vec<f64> = weights
        .iter()
        .map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
        .collect();
    if clean.is_empty() {
        clean.push(0.0);
    }
    let total: f64 = clean.iter().sum();
    if total <= 0.0 {
        clean.iter_mut().for_each(|w| *w = 1.0);
    }
    let sum = clean.iter().sum();
    (clean, total, sum)
}

impl Distribution1D {
    /// A distribution proportional to `weights`. An all-zero (or empty) input gives a uniform
    /// distribution, so that sampling stays defined.
    pub fn new(weights: &[f64]) -> Self {
        let n = weights.len().max(1);
        let (clean, total, sum) = sampling_weights(weights);
        let integral = total / n as f64;
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut running = 0.0;
        for &w in &clean {
            running += w;
            cdf.push(running / sum);
        }
        *cdf.last_mut().expect("n >= 1") = 1.0;
        let mut guide = Vec::with_capacity(n);
        let mut bin = 0;
        for k in 0..n {
            let u = k as f64 / n as f64;
            while bin < n - 1 && cdf[bin + 1] <= u {
                bin += 1;
            }
            guide.push(bin as u32);
        }
        Distribution1D {
            weights: clean,
            cdf,
            integral,
            guide,
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Whether there are no bins (never: at least one bin exists).
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// The mean of the input weights.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Probability of bin `i`.
    pub fn bin_probability(&self, i: usize) -> f64 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// Samples a bin and a continuous position in [0, 1): returns (x, density at x, bin).
    pub fn sample(&self, u: f64) -> (f64, f64, usize) {
        let n = self.len();
        // The bin whose edges bracket u: the first whose upper edge exceeds u, searched
        // from the guide table's entry for u.
        let mut bin = self.guide[((u * n as f64) as usize).min(n - 1)] as usize;
        while bin < n - 1 && self.cdf[bin + 1] <= u {
            bin += 1;
        }
        let probability = self.bin_probability(bin);
        let within = if probability > 0.0 {
            (u - self.cdf[bin]) / probability
        } else {
            0.5
        };
        let x = ((bin as f64 + within.clamp(0.0, 1.0)) / n as f64).min(1.0 - f64::EPSILON);
        (x, probability * n as f64, bin)
    }

    /// Density at x ∈ [0, 1).
    pub fn pdf(&self, x: f64) -> f64 {
        let n = self.len();
        let bin = ((x * n as f64) as usize).min(n - 1);
        self.bin_probability(bin) * n as f64
    }

    /// The `u` that [`Distribution1D::sample`] maps to `x` (for bins of non-zero probability).
    pub fn invert(&self, x: f64) -> f64 {
        let n = self.len();
        let scaled = x * n as f64;
        let bin = (scaled as usize).min(n - 1);
        self.cdf[bin] + (scaled - bin as f64) * self.bin_probability(bin)
    }
}

/// A piecewise-constant density on [0, 1)² over a `width × height` grid: a marginal over
/// rows and a conditional per row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    conditionals: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// A distribution proportional to `weights` (row-major, `height` rows of `width`).
    pub fn new(weights: &[f64], width: usize, height: usize) -> Self {
        assert_eq!(weights.len(), width * height, "weights must fill the grid");
        let conditionals: Vec<Distribution1D> = weights
            .chunks_exact(width)
            .map(Distribution1D::new)
            .collect();
        let marginal = Distribution1D::new(
            &conditionals
                .iter()
                .map(|c| c.integral())
                .collect::<Vec<_>>(),
        );
        Distribution2D {
            conditionals,
            marginal,
        }
    }

    /// Samples (x, y) ∈ [0, 1)² and its density.
    pub fn sample(&self, u: [f64; 2]) -> ([f64; 2], f64) {
        let (y, pdf_y, row) = self.marginal.sample(u[1]);
        let (x, pdf_x, _) = self.conditionals[row].sample(u[0]);
        ([x, y], pdf_x * pdf_y)
    }

    /// Probability of the cell in `column` of `row`.
    pub fn cell_probability(&self, column: usize, row: usize) -> f64 {
        self.marginal.bin_probability(row) * self.conditionals[row].bin_probability(column)
    }

    /// Density at (x, y).
    pub fn pdf(&self, p: [f64; 2]) -> f64 {
        let rows = self.conditionals.len();
        let row = ((p[1] * rows as f64) as usize).min(rows - 1);
        self.marginal.pdf(p[1]) * self.conditionals[row].pdf(p[0])
    }

    /// The `u` that [`Distribution2D::sample`] maps to `p`.
    pub fn invert(&self, p: [f64; 2]) -> [f64; 2] {
        let rows = self.conditionals.len();
        let row = ((p[1] * rows as f64) as usize).min(rows - 1);
        [
            self.conditionals[row].invert(p[0]),
            self.marginal.invert(p[1]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimensional_sampling_follows_the_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert!((d.bin_probability(0) - 0.25).abs() < 1e-12);
        assert_eq!(d.bin_probability(1), 0.0);
        let (x, pdf, bin) = d.sample(0.5);
        assert_eq!(bin, 2);
        assert!((pdf - 2.25).abs() < 1e-12);
        assert!((d.invert(x) - 0.5).abs() < 1e-12);
        assert!((d.pdf(x) - pdf).abs() < 1e-12);
        let (x, _, bin) = d.sample(0.1);
        assert_eq!(bin, 0);
        assert!((x - 0.4 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn the_guide_table_finds_the_bin_a_binary_search_finds() {
        let mut rng = crate::rng::Pcg32::new(8, 8);
        for size in [1usize, 2, 3, 7, 64, 257] {
            // Uneven weights with runs of zeros, as a sky with a sun has.
            let weights: Vec<f64> = (0..size)
                .map(|i| match i % 5 {
                    0 | 1 => 0.0,
                    2 => 1e4 * rng.next_f64(),
                    _ => rng.next_f64(),
                })
                .collect();
            let d = Distribution1D::new(&weights);
            for _ in 0..2000 {
                let u = rng.next_f64();
                let searched = d
                    .cdf
                    .partition_point(|&c| c <= u)
                    .saturating_sub(1)
                    .min(size - 1);
                assert_eq!(d.sample(u).2, searched, "size {size}, u {u}");
            }
            assert_eq!(d.sample(0.0).2, d.cdf.partition_point(|&c| c <= 0.0) - 1);
        }
    }

    #[test]
    fn zero_weights_fall_back_to_uniform() {
        let d = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(d.pdf(0.3), 1.0);
        assert_eq!(d.integral(), 0.0);
    }

    #[test]
    fn two_dimensional_sample_pdf_and_invert_agree() {
        let weights: Vec<f64> = (0..12).map(|i| (i % 5) as f64 + 0.5).collect();
        let d = Distribution2D::new(&weights, 4, 3);
        let mut rng = crate::rng::Pcg32::new(3, 3);
        let mut integral = 0.0;
        for _ in 0..1000 {
            let u = [rng.next_f64(), rng.next_f64()];
            let (p, pdf) = d.sample(u);
            assert!((d.pdf(p) - pdf).abs() < 1e-9 * pdf);
            let back = d.invert(p);
            assert!((back[0] - u[0]).abs() < 1e-9 && (back[1] - u[1]).abs() < 1e-9);
            integral += 1.0 / pdf;
        }
        // E[1/pdf] = area of the support = 1.
        assert!((integral / 1000.0 - 1.0).abs() < 0.1);
    }
}
