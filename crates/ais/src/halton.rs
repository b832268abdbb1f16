//! The 3-D Halton sequence (bases 2, 3, 5) with per-batch random-digit scrambling.
//!
//! Candidate `k` of a batch uses point `k`: its first two coordinates drive the host's
//! proposal sampler and the third decides Russian-roulette acceptance. Because a batch uses
//! an unknown number of candidates and only a random subset of them is traced, a
//! low-discrepancy sequence (rather than a fixed-size stratified pattern) keeps the placement
//! even at every prefix.
//!
//! Scrambling applies, at every digit position, an independent random permutation of the
//! digits `0..base` (including the infinitely many leading zeros of the fraction's tail, which
//! become a fixed offset). A digit permutation maps each elementary interval of the sequence
//! onto another of the same size, so the stratification of every prefix is preserved, while
//! batches with different seeds are decorrelated.

use crate::rng::Pcg32;

/// Number of base-3 digits needed to represent any `u32` index.
const DIGITS_BASE3: usize = 21;
/// Number of base-5 digits needed to represent any `u32` index.
const DIGITS_BASE5: usize = 14;
/// Powers `BASE^-j` kept per base: `j` up to the most digits of any base.
const POWERS: usize = DIGITS_BASE3 + 1;

/// Largest `f32` below 1: scrambled values are clamped to it so that they stay in [0, 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Digit permutations for one base: one permutation per digit position, and the
/// precomputed contribution of the permuted zero digits beyond each position.
#[derive(Clone, Debug)]
struct DigitScramble<const BASE: usize, const DIGITS: usize> {
    permutations: [[u8; BASE]; DIGITS],
    /// `tail[j]` = sum over positions `k >= j` of `permutation[k][0] * BASE^-(k+1)`.
    tail: [f64; DIGITS],
    /// `BASE^-j` for `j` in `0..POWERS` (`DIGITS < POWERS`), worked out once (a scramble per epoch reads them).
    inverse_powers: [f64; POWERS],
}

impl<const BASE: usize, const DIGITS: usize> DigitScramble<BASE, DIGITS> {
    fn identity() -> Self {
        let mut identity = [0u8; BASE];
        for (digit, slot) in identity.iter_mut().enumerate() {
            *slot = digit as u8;
        }
        let inverse_base = 1.0 / BASE as f64;
        DigitScramble {
            permutations: [identity; DIGITS],
            tail: [0.0; DIGITS],
            inverse_powers: std::array::from_fn(|j| inverse_base.powi(j as i32)),
        }
    }

    /// Draws the permutations of the first `used` digit positions, and for the positions
    /// beyond (where every index of the epoch has the digit 0) only what they add: the
    /// permuted zeros, a uniform offset below `BASE^-used` (the limit of drawing each of them).
    /// Positions from `used` on keep whatever they held: no index below the epoch's count
    /// reads them.
    fn randomize(&mut self, rng: &mut Pcg32, used: usize) {
        let used = used.min(DIGITS);
        for permutation in self.permutations[..used].iter_mut() {
            // Fisher-Yates shuffle of the digits, from the identity.
            *permutation = std::array::from_fn(|digit| digit as u8);
            for i in (1..BASE).rev() {
                let j = rng.below(i as u32 + 1) as usize;
                permutation.swap(i, j);
            }
        }
        let mut sum = rng.next_f64() * self.inverse_powers[used];
        if used < DIGITS {
            self.tail[used] = sum;
        }
        for position in (0..used).rev() {
            sum += self.permutations[position][0] as f64 * self.inverse_powers[position + 1];
            self.tail[position] = sum;
        }
    }

    /// How many digit positions the indices `0..count` use.
    fn digits_for(count: u32) -> usize {
        let mut digits = 0;
        let mut reach = 1u64;
        while reach < count as u64 {
            reach *= BASE as u64;
            digits += 1;
        }
        digits
    }

    #[inline]
    fn radical_inverse(&self, mut index: u32) -> f64 {
        let inverse_base = 1.0 / BASE as f64;
        let mut scale = inverse_base;
        let mut value = 0.0;
        let mut position = 0;
        while index > 0 {
            let digit = (index % BASE as u32) as usize;
            index /= BASE as u32;
            value += self.permutations[position][digit] as f64 * scale;
            scale *= inverse_base;
            position += 1;
        }
        if position < DIGITS {
            value + self.tail[position]
        } else {
            value
        }
    }
}

/// A 3-D Halton sequence (bases 2, 3, 5), scrambled per batch.
#[derive(Clone, Debug)]
pub struct ScrambledHalton {
    /// Base 2: a random permutation of {0, 1} at every bit position is an XOR mask.
    base2_mask: u32,
    base3: DigitScramble<3, DIGITS_BASE3>,
    base5: DigitScramble<5, DIGITS_BASE5>,
}

impl Default for ScrambledHalton {
    fn default() -> Self {
        Self::unscrambled()
    }
}

impl ScrambledHalton {
    /// The plain Halton sequence (identity permutations).
    pub fn unscrambled() -> Self {
        ScrambledHalton {
            base2_mask: 0,
            base3: DigitScramble::identity(),
            base5: DigitScramble::identity(),
        }
    }

    /// A sequence scrambled with permutations drawn from `seed`.
    #[cfg(test)]
    pub fn scrambled(seed: u64) -> Self {
        let mut sequence = Self::unscrambled();
        sequence.rescramble(seed, u32::MAX);
        sequence
    }

    /// Draws fresh digit permutations from `seed` for the points `0..count`, in place (no
    /// allocation). Only the digit positions those indices reach get a full permutation,
    /// which is what makes a scramble cheap for a small batch; points beyond `count` keep
    /// their stratification but are not independently scrambled.
    pub fn rescramble(&mut self, seed: u64, count: u32) {
        let mut rng = self.rescramble_2d(seed, count);
        self.base5.randomize(
            &mut rng,
            DigitScramble::<5, DIGITS_BASE5>::digits_for(count),
        );
    }

    /// [`ScrambledHalton::rescramble`] for the first two coordinates alone
    /// ([`ScrambledHalton::point_2d`]; the same ones, drawn first), leaving the third's
    /// permutations as they were. Returns the generator, to draw the third's from.
    pub fn rescramble_2d(&mut self, seed: u64, count: u32) -> Pcg32 {
        let mut rng = Pcg32::new(seed, 0x4841_4c54_4f4e); // stream "HALTON"
        self.base2_mask = rng.next_u32();
        self.base3.randomize(
            &mut rng,
            DigitScramble::<3, DIGITS_BASE3>::digits_for(count),
        );
        rng
    }

    /// The `index`-th point, each coordinate in [0, 1).
    #[inline]
    pub fn point(&self, index: u32) -> [f32; 3] {
        let [u1, u2] = self.point_2d(index);
        let u3 = (self.base5.radical_inverse(index) as f32).min(ONE_MINUS_EPSILON);
        [u1, u2, u3]
    }

    /// The first two coordinates of the `index`-th point ([`ScrambledHalton::point`]'s),
    /// for a host that needs no third.
    #[inline]
    pub fn point_2d(&self, index: u32) -> [f32; 2] {
        let u1 = (index.reverse_bits() ^ self.base2_mask) as f64 * (1.0 / 4_294_967_296.0);
        let u2 = self.base3.radical_inverse(index);
        [u1, u2].map(|x| (x as f32).min(ONE_MINUS_EPSILON))
    }

    /// The digit permutation applied at `position` in `base` (2, 3 or 5), for inspection.
    ///
    /// Returns `None` for another base or a position beyond the stored digits.
    #[cfg(test)]
    pub fn digit_permutation(&self, base: u32, position: usize) -> Option<Vec<u8>> {
        match base {
            2 if position < 32 => {
                let flip = ((self.base2_mask.reverse_bits() >> position) & 1) as u8;
                Some(vec![flip, 1 - flip])
            }
            3 => self.base3.permutations.get(position).map(|p| p.to_vec()),
            5 => self.base5.permutations.get(position).map(|p| p.to_vec()),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f64) -> bool {
        (a as f64 - b).abs() < 1e-6
    }

    #[test]
    fn unscrambled_radical_inverses_match_known_values() {
        let h = ScrambledHalton::unscrambled();
        let expected: [(u32, [f64; 3]); 7] = [
            (0, [0.0, 0.0, 0.0]),
            (1, [0.5, 1.0 / 3.0, 0.2]),
            (2, [0.25, 2.0 / 3.0, 0.4]),
            (3, [0.75, 1.0 / 9.0, 0.6]),
            (4, [0.125, 4.0 / 9.0, 0.8]),
            (5, [0.625, 7.0 / 9.0, 0.04]),
            (6, [0.375, 2.0 / 9.0, 0.24]),
        ];
        for (index, want) in expected {
            let got = h.point(index);
            for d in 0..3 {
                assert!(
                    close(got[d], want[d]),
                    "index {index} dim {d}: {} vs {}",
                    got[d],
                    want[d]
                );
            }
        }
        // A longer index: 1234 in base 5 is 14414, reversed 0.41441 (base 5).
        let want5 = 4.0 / 5.0 + 1.0 / 25.0 + 4.0 / 125.0 + 4.0 / 625.0 + 1.0 / 3125.0;
        assert!(close(h.point(1234)[2], want5));
    }

    #[test]
    fn scrambling_uses_bijections_of_the_digits() {
        for seed in 0..20 {
            let h = ScrambledHalton::scrambled(seed);
            for (base, positions) in [(2u32, 32usize), (3, DIGITS_BASE3), (5, DIGITS_BASE5)] {
                for position in 0..positions {
                    let mut digits = h.digit_permutation(base, position).unwrap();
                    digits.sort_unstable();
                    let identity: Vec<u8> = (0..base as u8).collect();
                    assert_eq!(
                        digits, identity,
                        "seed {seed} base {base} position {position}"
                    );
                }
            }
        }
    }

    #[test]
    fn scrambling_preserves_stratification_of_every_prefix_block() {
        // The first b^k points of a (scrambled) radical inverse fall one per interval of width b^-k.
        let h = ScrambledHalton::scrambled(99);
        for (dim, base, k) in [(0usize, 2u32, 10u32), (1, 3, 6), (2, 5, 4)] {
            let count = base.pow(k);
            let mut hit = vec![false; count as usize];
            for index in 0..count {
                let cell = (h.point(index)[dim] as f64 * count as f64) as usize;
                assert!(!hit[cell], "dim {dim}: two points in cell {cell}");
                hit[cell] = true;
            }
        }
    }

    #[test]
    fn different_seeds_give_different_points() {
        let a = ScrambledHalton::scrambled(1);
        let b = ScrambledHalton::scrambled(2);
        let differing = (0..64).filter(|&i| a.point(i) != b.point(i)).count();
        assert!(differing > 60);
    }

    #[test]
    fn scrambled_points_are_uniform_in_each_dimension() {
        // Mean over seeds of the first point is 1/2 in every dimension if scrambling is uniform.
        let n = 20_000;
        let mut sum = [0.0f64; 3];
        for seed in 0..n {
            let p = ScrambledHalton::scrambled(seed).point(0);
            for d in 0..3 {
                assert!((0.0..1.0).contains(&p[d]));
                sum[d] += p[d] as f64;
            }
        }
        for s in sum {
            assert!((s / n as f64 - 0.5).abs() < 0.01, "mean {}", s / n as f64);
        }
    }

    #[test]
    fn a_scramble_for_a_few_points_is_stratified_and_uniform() {
        // Scrambling only the digits that 16 points reach: every point is still uniform over
        // seeds (tested on a fine grid, which the random tail offset must fill), and the
        // prefix blocks stay stratified.
        let n = 30_000;
        let mut histogram = vec![[0u32; 3]; 64];
        for seed in 0..n {
            let mut h = ScrambledHalton::unscrambled();
            h.rescramble(seed, 16);
            let points: Vec<[f32; 3]> = (0..16).map(|i| h.point(i)).collect();
            for (dim, base) in [(1usize, 3usize), (2, 5)] {
                let mut hit = vec![false; base];
                for p in &points[..base] {
                    let cell = (p[dim] * base as f32) as usize;
                    assert!(
                        !hit[cell],
                        "seed {seed}, dim {dim}: two points in cell {cell}"
                    );
                    hit[cell] = true;
                }
            }
            for d in 0..3 {
                histogram[(points[15][d] * 64.0) as usize][d] += 1;
            }
        }
        for counts in histogram {
            for count in counts {
                let expected = n as f64 / 64.0;
                assert!(
                    (count as f64 - expected).abs() < 5.0 * expected.sqrt(),
                    "{count}"
                );
            }
        }
    }
}
