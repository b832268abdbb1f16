//! A light's sample square cut into regions, and draws that weigh the regions.
//!
//! A sphere's and a rectangle's light sampling turn a point `u` of the unit square into a
//! direction toward the light, one to one. The square's 4 × 4 regions are then 16 parts of
//! the light as seen from the receiver, each drawn with probability 1/16. A receiver that
//! knows which parts bring it light (a field cell that learned it: through a door gap, only
//! a strip of a ceiling lamp is seen) can draw `u` from a piecewise-constant density over
//! the regions instead of uniformly, and the light's draw stays the same map from `u`: the
//! density of a direction is then the light's own times `16 · P(region)`, exact wherever
//! the region is known. A direction drawn by light sampling knows its region; one drawn
//! from the BSDF finds it through the light's inverse map
//! (`AreaLight::sample_square_of`).
//!
//! The draw takes a column from `u₀` and a row within the column from `u₁`, each by
//! inverting a cumulative table and rescaling the number within its interval, so draws
//! that were stratified in `u` stay stratified.

use super::ONE_BELOW;

/// Regions along each side of the sample square.
pub const REGION_SIDE: usize = 4;

/// Regions of a sample square.
pub const REGIONS: usize = REGION_SIDE * REGION_SIDE;

/// The region of the sample square holding `u` (row-major: `row · 4 + column`, the column
/// from `u₀`).
#[inline]
pub fn region_of(u: [f32; 2]) -> usize {
    let cell = |x: f32| ((x * REGION_SIDE as f32) as usize).min(REGION_SIDE - 1);
    cell(u[1]) * REGION_SIDE + cell(u[0])
}

/// A piecewise-constant density over the regions of a sample square.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionChoice {
    /// Cumulative probabilities of the columns (the last is 1).
    columns: [f32; REGION_SIDE],
    /// For each column, cumulative probabilities of its rows (the last is 1).
    rows: [[f32; REGION_SIDE]; REGION_SIDE],
    /// Each region's probability times [`REGIONS`]: the factor on the light's own density.
    factors: [f32; REGIONS],
}

impl RegionChoice {
    /// The density whose regions' probabilities are proportional to `weights` (indexed as
    /// [`region_of`]); `None` unless every weight is finite and positive.
    pub fn new(weights: &[f64; REGIONS]) -> Option<Self> {
        if !weights.iter().all(|w| w.is_finite() && *w > 0.0) {
            return None;
        }
        let total: f64 = weights.iter().sum();
        let weight = |row: usize, column: usize| weights[row * REGION_SIDE + column];
        let column_mass: [f64; REGION_SIDE] =
            std::array::from_fn(|column| (0..REGION_SIDE).map(|row| weight(row, column)).sum());
        Some(RegionChoice {
            columns: cumulative(column_mass),
            rows: std::array::from_fn(|column| {
                cumulative(std::array::from_fn(|row| weight(row, column)))
            }),
            factors: std::array::from_fn(|region| {
                (weights[region] / total * REGIONS as f64) as f32
            }),
        })
    }

    /// The point of the square drawn for `u` (uniform in `u` gives this density), and its
    /// region.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> ([f32; 2], usize) {
        let (column, x) = invert(&self.columns, u[0]);
        let (row, y) = invert(&self.rows[column], u[1]);
        let side = REGION_SIDE as f32;
        let at = |cell: usize, within: f32| ((cell as f32 + within) / side).min(ONE_BELOW);
        ([at(column, x), at(row, y)], row * REGION_SIDE + column)
    }

    /// The density's factor on the light's own in `region`: `16 · P(region)`.
    #[inline]
    pub fn factor(&self, region: usize) -> f64 {
        self.factors[region] as f64
    }

    /// Bytes it holds.
    pub const fn memory_bytes() -> usize {
        std::mem::size_of::<Self>()
    }
}

/// Cumulative sums of `masses`, normalised so that the last is exactly 1.
fn cumulative(masses: [f64; REGION_SIDE]) -> [f32; REGION_SIDE] {
    let total: f64 = masses.iter().sum();
    let mut sum = 0.0;
    let mut table = masses.map(|mass| {
        sum += mass;
        (sum / total) as f32
    });
    table[REGION_SIDE - 1] = 1.0;
    table
}

/// The interval of `table` (cumulative, last 1) holding `u`, and `u` rescaled within it.
#[inline]
fn invert(table: &[f32; REGION_SIDE], u: f32) -> (usize, f32) {
    let index = table[..REGION_SIDE - 1].iter().filter(|&&c| c <= u).count();
    let low = if index == 0 { 0.0 } else { table[index - 1] };
    let width = table[index] - low;
    let within = if width > 0.0 {
        ((u - low) / width).clamp(0.0, ONE_BELOW)
    } else {
        0.5
    };
    (index, within)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ais::rng::Pcg32;

    fn uneven() -> [f64; REGIONS] {
        std::array::from_fn(|k| 0.02 + (k % 5) as f64 * (1 + k / 7) as f64)
    }

    #[test]
    fn draws_fall_in_their_regions_as_often_as_the_weights_say() {
        let weights = uneven();
        let choice = RegionChoice::new(&weights).unwrap();
        let total: f64 = weights.iter().sum();
        let mut rng = Pcg32::new(3, 7);
        let draws = 200_000;
        let mut seen = [0u32; REGIONS];
        for _ in 0..draws {
            let (point, region) = choice.sample([rng.next_f32(), rng.next_f32()]);
            assert_eq!(region_of(point), region, "{point:?}");
            assert!(point.iter().all(|c| (0.0..1.0).contains(c)));
            seen[region] += 1;
        }
        for (region, &count) in seen.iter().enumerate() {
            let expected = weights[region] / total * draws as f64;
            let z = (count as f64 - expected) / expected.sqrt();
            assert!(
                z.abs() < 5.0,
                "region {region}: {count} against {expected:.0}"
            );
            let factor = choice.factor(region);
            assert!((factor - weights[region] / total * REGIONS as f64).abs() < 1e-5);
        }
    }

    #[test]
    fn draws_are_uniform_within_a_region() {
        // The square's points drawn in one region fill its four quarters alike.
        let choice = RegionChoice::new(&uneven()).unwrap();
        let mut rng = Pcg32::new(5, 1);
        let mut quarters = [0u32; 4];
        for _ in 0..100_000 {
            let (point, region) = choice.sample([rng.next_f32(), rng.next_f32()]);
            if region == 13 {
                let inner = |c: f32| ((c * 8.0) as usize) % 2;
                quarters[inner(point[1]) * 2 + inner(point[0])] += 1;
            }
        }
        let mean = quarters.iter().sum::<u32>() as f64 / 4.0;
        for count in quarters {
            assert!(
                (count as f64 - mean).abs() < 5.0 * mean.sqrt(),
                "{quarters:?}"
            );
        }
    }

    #[test]
    fn equal_weights_leave_the_square_as_it_was() {
        let choice = RegionChoice::new(&[1.0; REGIONS]).unwrap();
        for u in [[0.0, 0.0], [0.3, 0.71], [0.999, 0.5], [0.25, 0.75]] {
            let (point, _) = choice.sample(u);
            assert!((point[0] - u[0]).abs() < 1e-6 && (point[1] - u[1]).abs() < 1e-6);
        }
        assert!(RegionChoice::new(&[0.0; REGIONS]).is_none());
        assert!(RegionChoice::new(&[f64::NAN; REGIONS]).is_none());
    }
}
