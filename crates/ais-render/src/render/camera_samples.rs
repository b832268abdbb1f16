//! Where in its pixel, and where on the lens, each camera sample falls: one Owen-scrambled
//! Sobol sequence per pixel (Burley's hash-based scrambling), indexed by the sample's rank
//! over the whole render.
//!
//! Two things follow. Any prefix of a pixel's samples is stratified over the pixel (and the
//! lens), so an edge or a texture inside a pixel converges faster than with independent
//! positions, however the render splits its samples into passes. And the positions do not
//! depend on what the integrator draws: two gather configurations with one seed see the
//! same camera rays, so comparing them measures the gathers, not the camera's luck.

use ais::rng::mix64;

/// Samples per sequence (`sobol_burley`'s limit); later samples continue in a sequence of
/// their own seed.
const SEQUENCE_LENGTH: u32 = 1 << 16;

/// One pixel's camera samples.
#[derive(Clone, Copy, Debug)]
pub struct CameraSamples {
    seed: u64,
}

impl CameraSamples {
    /// The samples of the pixel whose own seed is `pixel_seed` (the same in every pass).
    pub fn new(pixel_seed: u64) -> Self {
        CameraSamples {
            seed: mix64(pixel_seed ^ 0xC0FF_EE00_CA3E_7A55),
        }
    }

    /// The offset within the pixel of its sample of rank `index`, in [0, 1)².
    pub fn position(&self, index: u32) -> [f32; 2] {
        let [x, y, _, _] = self.dimensions(index);
        [x, y]
    }

    /// The point on the unit square of the lens of its sample of rank `index`.
    pub fn lens(&self, index: u32) -> [f32; 2] {
        let [_, _, x, y] = self.dimensions(index);
        [x, y]
    }

    /// Dimensions 0 to 3 of the sample of rank `index`, computed together (in vector lanes:
    /// the same numbers as one dimension at a time, for the cost of about one).
    fn dimensions(&self, index: u32) -> [f32; 4] {
        let sequence = (index / SEQUENCE_LENGTH) as u64;
        let seed = mix64(self.seed ^ sequence.wrapping_mul(0x9E37_79B9_7F4A_7C15)) as u32;
        sobol_burley::sample_4d(index % SEQUENCE_LENGTH, 0, seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first 2^k positions of a pixel put one sample in each of 2^k equal columns and
    /// in each of 2^k equal rows (a (0, 2)-sequence, scrambled).
    #[test]
    fn every_power_of_two_prefix_is_stratified_in_rows_and_columns() {
        for pixel in 0..20u64 {
            let samples = CameraSamples::new(mix64(pixel));
            for k in 0..8u32 {
                let count = 1u32 << k;
                let mut columns = vec![0u32; count as usize];
                let mut rows = vec![0u32; count as usize];
                for index in 0..count {
                    let [x, y] = samples.position(index);
                    columns[(x * count as f32) as usize] += 1;
                    rows[(y * count as f32) as usize] += 1;
                }
                assert!(columns.iter().chain(&rows).all(|&c| c == 1), "{pixel} {k}");
            }
        }
    }

    /// Pixels' sequences are independent: across many pixels, the first position of each
    /// is uniform (a chi-square over 16 cells, far below its 0.1% bound).
    #[test]
    fn pixels_scramble_their_sequences_independently() {
        let mut cells = [0u32; 16];
        let pixels = 16_000u64;
        for pixel in 0..pixels {
            let [x, y] = CameraSamples::new(mix64(pixel)).position(0);
            cells[(x * 4.0) as usize * 4 + (y * 4.0) as usize] += 1;
        }
        let expected = pixels as f64 / 16.0;
        let chi2: f64 = cells
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        assert!(chi2 < 37.7, "chi-square {chi2} over 15 degrees of freedom");
    }

    /// Past the sequence's length, samples go on in another sequence, still in [0, 1).
    #[test]
    fn samples_past_the_sequence_length_stay_in_the_unit_square() {
        let samples = CameraSamples::new(7);
        let first = samples.position(3);
        let later = samples.position(SEQUENCE_LENGTH + 3);
        assert_ne!(first, later);
        assert!(later.iter().all(|v| (0.0..1.0).contains(v)));
    }
}
