//! Frozen-map epochs: how a batch's `n` traced rays are split into epochs.
//!
//! With continuous updates the map changes inside the batch, so the n+1 stopping rule is not
//! exactly unbiased (a visible direction accepted at low affinity both adds a large value and
//! shortens the batch). Splitting the batch into epochs, each run with its own `n_e + 1` rule
//! under a map frozen for the epoch and updated only at its end, makes every epoch exactly
//! unbiased given the past; combining them with the fixed weights `n_e / n` keeps the total
//! exactly unbiased.

/// Most epochs a batch may be split into.
pub const MAX_EPOCHS: usize = 8;

/// The traced-ray counts of a batch's epochs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EpochPlan {
    sizes: [u32; MAX_EPOCHS],
    count: usize,
}

impl EpochPlan {
    /// One epoch of `n` rays (the continuous-update schedule and the fixed-map schedule).
    pub fn single(n: u32) -> Self {
        let mut sizes = [0; MAX_EPOCHS];
        sizes[0] = n;
        EpochPlan { sizes, count: 1 }
    }

    /// Up to `epochs` epochs whose sizes double, e.g. `n/8, n/8, n/4, n/2` for 4 epochs: each
    /// later epoch takes half of what is left, the first takes the rest. Epochs that would be
    /// empty (small `n`) are left out.
    pub fn doubling(n: u32, epochs: u32) -> Self {
        let epochs = (epochs as usize).clamp(1, MAX_EPOCHS);
        let mut reversed = [0u32; MAX_EPOCHS];
        let mut count = 0;
        let mut remaining = n;
        while remaining > 0 && count < epochs {
            let size = if count + 1 == epochs {
                remaining
            } else {
                remaining.div_ceil(2)
            };
            reversed[count] = size;
            remaining -= size;
            count += 1;
        }
        let mut sizes = [0; MAX_EPOCHS];
        for i in 0..count {
            sizes[i] = reversed[count - 1 - i];
        }
        EpochPlan { sizes, count }
    }

    /// The epoch sizes, in order.
    pub fn sizes(&self) -> &[u32] {
        &self.sizes[..self.count]
    }

    /// The total number of rays (n).
    #[cfg(test)]
    pub fn total(&self) -> u32 {
        self.sizes().iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doubling_plans() {
        assert_eq!(EpochPlan::doubling(128, 4).sizes(), &[16, 16, 32, 64]);
        assert_eq!(EpochPlan::doubling(8, 4).sizes(), &[1, 1, 2, 4]);
        assert_eq!(EpochPlan::doubling(3, 4).sizes(), &[1, 2]);
        assert_eq!(EpochPlan::doubling(1, 4).sizes(), &[1]);
        assert_eq!(EpochPlan::doubling(100, 1).sizes(), &[100]);
        for n in 1..300 {
            for e in 1..6 {
                let plan = EpochPlan::doubling(n, e);
                assert_eq!(plan.total(), n);
                assert!(plan.sizes().iter().all(|&s| s > 0));
            }
        }
    }
}
