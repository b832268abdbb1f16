//! A piecewise-constant density over the texels of a lat-long map: the way to fold a fixed
//! affinity map into a proposal instead of rejecting candidates against it.
//!
//! A texel is chosen with probability proportional to its weight, then a direction uniformly
//! in solid angle inside it (φ uniform over the column, cos θ uniform over the row), so the
//! density is `P(texel) / Ω(texel)` in solid angle. A host mixes it with its own proposal
//! (`q = (1 − α) p + α g`, weight `f / q`): exactly unbiased wherever `p` covers the
//! integrand, whatever the weights are. Texels are classified with the same stored row
//! boundaries that sampling interpolates, and a sample is checked against that
//! classification, so a drawn direction always has the density of the texel it came from.

use crate::mapping::{LatLong, Texel};
use glam::Vec3;
use std::f32::consts::TAU;

/// A piecewise-constant distribution of directions over a lat-long layout's texels.
#[derive(Clone, Debug)]
pub struct TexelDistribution {
    layout: LatLong,
    /// cos θ at the row boundaries: `height + 1` values from 1 (+z) down to −1.
    row_cosines: Vec<f32>,
    /// Cumulative texel probabilities, `texel_count + 1` values from 0 to 1.
    cdf: Vec<f32>,
    /// Density in solid angle of every texel (its probability over its solid angle).
    density: Vec<f32>,
}

impl TexelDistribution {
    /// The uniform distribution over the sphere on `layout`.
    pub fn new(layout: LatLong) -> Self {
        let h = layout.height();
        let row_cosines = (0..=h)
            .map(|row| match row {
                0 => 1.0,
                r if r == h => -1.0,
                r => (std::f32::consts::PI * r as f32 / h as f32).cos(),
            })
            .collect();
        let mut distribution = TexelDistribution {
            layout,
            row_cosines,
            cdf: vec![0.0; layout.texel_count() + 1],
            density: vec![0.0; layout.texel_count()],
        };
        distribution.set_weights(|texel| layout.texel_solid_angle(texel.row));
        distribution
    }

    /// Bytes held by its tables.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self)
            + 4 * (self.row_cosines.len() + self.cdf.len() + self.density.len())
    }

    /// The layout.
    pub fn layout(&self) -> LatLong {
        self.layout
    }

    /// Solid angle of the texels of `row`, from the stored boundaries.
    fn solid_angle(&self, row: u32) -> f32 {
        let r = row as usize;
        (self.row_cosines[r] - self.row_cosines[r + 1]) * TAU / self.layout.width() as f32
    }

    /// Makes texel probabilities proportional to `weight(texel)` (negative, NaN and infinite
    /// weights count as 0). Returns false, and leaves the distribution uniform in solid angle,
    /// when no weight is positive.
    pub fn set_weights(&mut self, mut weight: impl FnMut(Texel) -> f32) -> bool {
        if self.fill(&mut weight) {
            return true;
        }
        let layout = self.layout;
        // Solid angles are positive: this fill succeeds.
        self.fill(&mut |texel| layout.texel_solid_angle(texel.row));
        false
    }

    /// Builds the cumulative distribution and densities; false if no weight is positive.
    fn fill(&mut self, weight: &mut dyn FnMut(Texel) -> f32) -> bool {
        let count = self.layout.texel_count();
        let mut running = 0.0f64;
        self.cdf[0] = 0.0;
        for index in 0..count {
            let w = weight(self.layout.texel_of_index(index));
            if w.is_finite() && w > 0.0 {
                running += w as f64;
            }
            self.cdf[index + 1] = running as f32;
        }
        if running <= 0.0 {
            return false;
        }
        let scale = (1.0 / running) as f32;
        for c in &mut self.cdf[1..] {
            *c *= scale;
        }
        self.cdf[count] = 1.0;
        for index in 0..count {
            let row = index as u32 / self.layout.width();
            self.density[index] = (self.cdf[index + 1] - self.cdf[index]) / self.solid_angle(row);
        }
        true
    }

    /// Probability of drawing `texel`.
    pub fn texel_probability(&self, texel: Texel) -> f32 {
        let index = self.layout.index(texel);
        self.cdf[index + 1] - self.cdf[index]
    }

    /// A direction drawn from `u` ∈ [0, 1)²: `u[0]` picks the texel by inversion of the
    /// cumulative distribution and, rescaled, the azimuth inside it; `u[1]` picks cos θ.
    /// Inversion keeps stratified `u` stratified.
    pub fn sample(&self, u: [f32; 2]) -> Vec3 {
        let count = self.layout.texel_count();
        // The first texel whose upper cumulative bound exceeds u[0].
        let mut index = self.cdf[1..].partition_point(|&c| c <= u[0]).min(count - 1);
        while index > 0 && self.cdf[index + 1] <= self.cdf[index] {
            index -= 1; // only after rounding at u ≈ 1: step back to a texel that has mass
        }
        let probability = self.cdf[index + 1] - self.cdf[index];
        let within = ((u[0] - self.cdf[index]) / probability).clamp(0.0, 1.0);
        let texel = self.layout.texel_of_index(index);
        let direction = self.direction_in(texel, within, u[1].clamp(0.0, 1.0));
        // Rounding can put a point drawn on a texel's edge into its neighbour (measure
        // zero, but that neighbour may have no mass): then take the texel's centre.
        if self.texel_of(direction) == texel {
            direction
        } else {
            self.direction_in(texel, 0.5, 0.5)
        }
    }

    /// The direction at fractions (`s`, `t`) of a texel's azimuth and cos θ ranges.
    fn direction_in(&self, texel: Texel, s: f32, t: f32) -> Vec3 {
        let phi = TAU * (texel.column as f32 + s) / self.layout.width() as f32;
        let (top, bottom) = (
            self.row_cosines[texel.row as usize],
            self.row_cosines[texel.row as usize + 1],
        );
        let cos_theta = top + t * (bottom - top);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = phi.sin_cos();
        Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
    }

    /// The texel holding a unit `direction`: row `r` holds cos θ ∈ (c\[r+1\], c\[r\]] (the last
    /// row also −1) for the stored boundary cosines c, column `c` holds φ ∈ [c, c+1)·2π/width.
    pub fn texel_of(&self, direction: Vec3) -> Texel {
        let h = self.layout.height();
        let z = direction.z.clamp(-1.0, 1.0);
        let mut row = ((z.acos() / std::f32::consts::PI * h as f32) as u32).min(h - 1);
        // acos rounds; the stored boundaries decide.
        while row > 0 && z > self.row_cosines[row as usize] {
            row -= 1;
        }
        while row + 1 < h && z <= self.row_cosines[row as usize + 1] {
            row += 1;
        }
        let mut phi = direction.y.atan2(direction.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let width = self.layout.width();
        let column = ((phi / TAU * width as f32) as u32).min(width - 1);
        Texel { row, column }
    }

    /// The `u` that [`TexelDistribution::sample`] maps to a unit `direction` in a texel with
    /// mass: the inverse of sampling, for hosts that stratify or reuse sample values.
    pub fn invert(&self, direction: Vec3) -> [f32; 2] {
        let texel = self.texel_of(direction);
        let index = self.layout.index(texel);
        let mut phi = direction.y.atan2(direction.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let s = (phi / TAU * self.layout.width() as f32 - texel.column as f32).clamp(0.0, 1.0);
        let (top, bottom) = (
            self.row_cosines[texel.row as usize],
            self.row_cosines[texel.row as usize + 1],
        );
        let t = ((top - direction.z.clamp(-1.0, 1.0)) / (top - bottom)).clamp(0.0, 1.0);
        let probability = self.cdf[index + 1] - self.cdf[index];
        [self.cdf[index] + s * probability, t]
    }

    /// Density of [`TexelDistribution::sample`] at a unit `direction`, in solid angle.
    pub fn pdf(&self, direction: Vec3) -> f32 {
        self.density[self.layout.index(self.texel_of(direction))]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invert_undoes_sample() {
        let mut distribution = TexelDistribution::new(LatLong::new(4));
        distribution.set_weights(|texel| 1.0 + texel.column as f32 + 3.0 * texel.row as f32);
        for (i, j) in (1..20).flat_map(|i| (1..20).map(move |j| (i, j))) {
            let u = [i as f32 / 20.0, j as f32 / 20.0];
            let back = distribution.invert(distribution.sample(u));
            assert!(
                (back[0] - u[0]).abs() < 1e-4 && (back[1] - u[1]).abs() < 1e-4,
                "{u:?} -> {back:?}"
            );
        }
    }

    #[test]
    fn uniform_weights_give_the_uniform_sphere_density() {
        let d = TexelDistribution::new(LatLong::new(4));
        for direction in [Vec3::X, Vec3::Z, -Vec3::Z, Vec3::new(0.6, -0.8, 0.0)] {
            let expected = 1.0 / (4.0 * std::f32::consts::PI);
            assert!((d.pdf(direction) - expected).abs() < 1e-4 * expected);
        }
    }

    #[test]
    fn all_zero_weights_fall_back_to_uniform() {
        let mut d = TexelDistribution::new(LatLong::new(2));
        assert!(!d.set_weights(|_| 0.0));
        assert!(!d.set_weights(|_| f32::NAN));
        assert!(d.pdf(Vec3::Y) > 0.0);
    }

    #[test]
    fn samples_stay_in_their_texel_and_skip_empty_ones() {
        let layout = LatLong::new(4);
        let mut d = TexelDistribution::new(layout);
        // Only two texels have mass.
        assert!(d.set_weights(|t| match (t.row, t.column) {
            (1, 3) => 1.0,
            (3, 7) => 3.0,
            _ => 0.0,
        }));
        let mut rng = crate::rng::Pcg32::new(5, 5);
        for _ in 0..2000 {
            let u = [rng.next_f32(), rng.next_f32()];
            let direction = d.sample(u);
            let texel = d.texel_of(direction);
            assert!(d.texel_probability(texel) > 0.0, "{texel:?} from {u:?}");
            assert!(d.pdf(direction) > 0.0);
        }
        // Extreme u still lands in a texel with mass.
        for u in [[0.0, 0.0], [0.999_999_9, 0.999_999_9], [0.25, 1.0]] {
            assert!(d.pdf(d.sample(u)) > 0.0);
        }
    }
}
