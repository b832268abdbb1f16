//! Running sample moments of batch estimates: mean, variance and standard error.

/// Accumulates estimates and reports their mean, sample variance and standard error.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    count: u64,
    sum: f64,
    sum_of_squares: f64,
}

impl Moments {
    /// Adds one estimate.
    pub fn add(&mut self, value: f64) {
        self.count += 1;
        self.sum += value;
        self.sum_of_squares += value * value;
    }

    /// Number of estimates added.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The sample mean (0 when empty).
    pub fn mean(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum / self.count as f64
        }
    }

    /// The unbiased sample variance (0 with fewer than two estimates).
    pub fn variance(&self) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        let n = self.count as f64;
        let mean = self.sum / n;
        ((self.sum_of_squares / n - mean * mean) * n / (n - 1.0)).max(0.0)
    }

    /// The standard error of the mean.
    pub fn standard_error(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            (self.variance() / self.count as f64).sqrt()
        }
    }

    /// The bias of the mean against `exact`, in standard errors.
    pub fn z(&self, exact: f64) -> f64 {
        (self.mean() - exact) / self.standard_error()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moments_of_a_known_sample() {
        let mut m = Moments::default();
        for x in [1.0, 2.0, 3.0, 4.0] {
            m.add(x);
        }
        assert_eq!(m.count(), 4);
        assert_eq!(m.mean(), 2.5);
        assert!((m.variance() - 5.0 / 3.0).abs() < 1e-12);
        assert!((m.standard_error() - (5.0f64 / 12.0).sqrt()).abs() < 1e-12);
    }
}
