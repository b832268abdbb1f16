//! The BSDF's share of one-sample MIS, learned from the gathers' own candidates where the
//! field does not roll (below 64 candidates), and fixed where it does
//! ([`ROLLING_MIS_SHARE`]).
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
//! A pass sums these per field cell (a patch of surface a few pixels wide), with the cell's
//! gathers' mean estimate `Ē`, and the next pass uses the share with the least
//! `Σ_cells M̂_cell(c) / (Ē_cell² + 0.01)`: the image's relMSE, which weighs each pixel's
//! squared error by `1 / (r² + 0.01)`, with a cell's pixels alike. (Weighing by the squared
//! error in radiance instead, every gather alike, lets the bright pixels choose: in a
//! sunlit room the sun patch chose a share that raised relMSE by 12%. Weighing each
//! gather by its own estimate `E`, noisy as it is, chose a share that raised relMSE by a
//! quarter behind a roof edge: the repository's BENCHMARKS.md, section 5.6.) A pass's
//! share depends only on earlier passes, so every pass is unbiased; the sums are added in
//! tile order per cell and over the cells in their keys' order, so the choice does not
//! depend on the thread count.

use super::race::RELATIVE_FLOOR;
use super::strategy::MisParts;
use ais::field::CellKey;
use std::collections::HashMap;

/// The BSDF shares a render chooses among (the default,
/// [`MIS_BSDF_WEIGHT`](super::strategy::MIS_BSDF_WEIGHT), among them).
pub const MIS_SHARES: [f64; 4] = [0.125, 0.25, 0.5, 0.75];

/// MIS's BSDF share where the field rolls (64 candidates or more) and guides light
/// sampling, where no share is learned: light sampling, guided by a field taught from the
/// first passes, is the better of the two strategies there, and the BSDF's draws the
/// defensive part. Pinned at n = 128 and measured by `ais compare` (equal time, 3 s, a
/// field taught as a render's is), 0.25 against 0.5 gained 1.51× on the default scene,
/// 1.26× behind a roof edge, 1.24× in the foliage and 1.11× in the courtyard, tied in four
/// more scenes and lost 3% in the overcast room and 20% in the sunlit room (measured
/// before guides weighed the square root of a texel's visibility); 0.75 lost or tied
/// everywhere (the repository's BENCHMARKS.md, section 5.6). A share learned from the candidates' moments
/// lost in the rooms there, and one raced in the race passes chose by a field too young.
pub const ROLLING_MIS_SHARE: f64 = 0.25;

/// A share is chosen only from at least this many gathers with light, else the last share
/// stays.
pub const LEAST_GATHERS: u64 = 500;

/// The second moments of the gathers of a pass at every share of [`MIS_SHARES`], per
/// field cell.
#[derive(Clone, Debug, Default)]
pub struct ShareMoments {
    /// Per cell, its gathers' sums.
    cells: HashMap<CellKey, CellMoments>,
    /// The current gather's sums per share.
    gather: [f64; MIS_SHARES.len()],
    /// Gathers with a candidate that brought light.
    gathers: u64,
}

/// One cell's gathers' sums.
#[derive(Clone, Copy, Debug, Default)]
struct CellMoments {
    /// Per share, the sum of the gathers' moment estimates.
    sums: [f64; MIS_SHARES.len()],
    /// The sum of the gathers' estimates (luminance).
    estimates: f64,
    /// Its gathers.
    gathers: u64,
}

impl CellMoments {
    fn add(&mut self, other: &CellMoments) {
        for (sum, other) in self.sums.iter_mut().zip(&other.sums) {
            *sum += other;
        }
        self.estimates += other.estimates;
        self.gathers += other.gathers;
    }
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

    /// Ends a gather in cell `cell` whose estimate (luminance) is `estimate`: its sums
    /// join the cell's.
    pub fn end_gather(&mut self, cell: CellKey, estimate: f32) {
        let sums = std::mem::take(&mut self.gather);
        let brought = sums.iter().any(|&sum| sum != 0.0);
        self.gathers += u64::from(brought);
        self.cells.entry(cell).or_default().add(&CellMoments {
            sums,
            estimates: estimate as f64,
            gathers: 1,
        });
    }

    /// Adds another tile's sums (tiles in order, so that the sums do not depend on the
    /// thread count).
    pub fn merge(&mut self, other: &ShareMoments) {
        for (key, cell) in &other.cells {
            self.cells.entry(*key).or_default().add(cell);
        }
        self.gathers += other.gathers;
    }

    /// The share with the least relMSE-weighted second moment, or `None` from fewer than
    /// [`LEAST_GATHERS`] gathers with light.
    pub fn best(&self) -> Option<f64> {
        if self.gathers < LEAST_GATHERS {
            return None;
        }
        let mut cells: Vec<(&CellKey, &CellMoments)> = self.cells.iter().collect();
        cells.sort_unstable_by_key(|(key, _)| **key);
        let mut weighted = [0.0; MIS_SHARES.len()];
        for (_, cell) in cells {
            let mean = cell.estimates / cell.gathers.max(1) as f64;
            let weight = 1.0 / (mean * mean + RELATIVE_FLOOR);
            for (total, sum) in weighted.iter_mut().zip(&cell.sums) {
                *total += sum * weight;
            }
        }
        let least = (0..MIS_SHARES.len()).min_by(|&a, &b| weighted[a].total_cmp(&weighted[b]));
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
        let mean = sum / n as f64;
        moments.end_gather(CellKey::new([0.0; 3], [0.0, 0.0, 1.0], 0), mean as f32);
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
            let cell = |m: &ShareMoments| *m.cells.values().next().unwrap();
            let mean_squared = |k: usize| cell(&moments).sums[k] / 200_000.0;
            for (k, &share) in MIS_SHARES.iter().enumerate() {
                let direct = variance_at(share, light_weight, &mut rng).1;
                let own = cell(&direct).sums[k] / 200_000.0;
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

    #[test]
    fn cells_weigh_as_relmse_weighs_their_pixels() {
        // A bright cell's gathers vary least at share 0.75 and, in radiance, dominate; a
        // dark cell's vary least at 0.125. relMSE weighs the dark cell's pixels 5000 times
        // more: its share wins.
        let mut moments = ShareMoments::default();
        let bright = CellKey::new([0.0; 3], [0.0, 0.0, 1.0], 0);
        let dark = CellKey::new([5.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0);
        for _ in 0..LEAST_GATHERS {
            moments.gather = [200.0, 150.0, 100.0, 50.0];
            moments.end_gather(bright, 10.0);
            moments.gather = [0.01, 0.03, 0.06, 0.12];
            moments.end_gather(dark, 0.1);
        }
        assert_eq!(moments.best(), Some(0.125));
        let mut few = ShareMoments::default();
        few.merge(&moments);
        few.gathers = LEAST_GATHERS - 1;
        assert_eq!(few.best(), None, "too few gathers with light");
    }
}
