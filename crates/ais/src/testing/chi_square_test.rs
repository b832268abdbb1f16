//! The chi-square harness for samplers of directions: draws samples, bins them on a lat-long
//! grid, integrates the claimed density over every bin, and compares the two with Pearson's
//! test (see [`super::chi2`]).

use super::chi2::chi_square_p_value;
use crate::mapping::LatLong;
use crate::rng::Pcg32;
use glam::Vec3;
use std::f32::consts::PI;

/// One draw of a sampler: a unit direction and, if the sampler reports one, its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drawn {
    /// The direction.
    pub direction: Vec3,
    /// The density the sampler reports for it (checked against the pdf), if any.
    pub pdf: Option<f64>,
}

impl Drawn {
    /// A direction with the density its sampler reports.
    pub fn with_pdf(direction: impl Into<[f32; 3]>, pdf: f64) -> Self {
        Drawn {
            direction: Vec3::from(direction.into()),
            pdf: Some(pdf),
        }
    }

    /// A direction whose sampler reports no density.
    pub fn direction(direction: impl Into<[f32; 3]>) -> Self {
        Drawn {
            direction: Vec3::from(direction.into()),
            pdf: None,
        }
    }
}

/// A chi-square test of a sampler of directions against its density, in solid angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquareTest {
    /// Rows of the lat-long grid of bins (columns: twice as many).
    pub rows: u32,
    /// Each bin's density integral uses `subdivision²` equal-area cells (midpoint rule).
    pub subdivision: u32,
    /// Draws.
    pub samples: u32,
    /// Seed of the uniform numbers handed to the sampler.
    pub seed: u64,
}

impl Default for ChiSquareTest {
    fn default() -> Self {
        ChiSquareTest {
            rows: 24,
            subdivision: 32,
            samples: 100_000,
            seed: 11,
        }
    }
}

/// What a [`ChiSquareTest`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquareOutcome {
    /// Pearson's p-value (0 when a sample fell where the density is zero).
    pub p_value: f64,
    /// Attempts that produced a sample.
    pub drawn: u32,
    /// Attempts in all.
    pub attempts: u32,
    /// The density's integral over the sphere; it must equal the share of attempts that
    /// produced a sample.
    pub integral: f64,
    /// Samples whose reported density differs from the pdf by more than 0.1%.
    pub mismatched_densities: u32,
}

impl ChiSquareOutcome {
    /// Whether the sampler fits its density at `significance`: the p-value is above it, the
    /// density integrates to the share of attempts that drew (within 0.02), and at most one
    /// sample in a thousand reports another density (rounding at bin edges).
    pub fn fits(&self, significance: f64) -> bool {
        self.problem(significance).is_none()
    }

    /// Why the sampler does not fit at `significance`, if it does not.
    pub fn problem(&self, significance: f64) -> Option<String> {
        self.consistency_problem().or_else(|| {
            (self.p_value <= significance)
                .then(|| format!("p = {:.3e} ≤ {significance}", self.p_value))
        })
    }

    /// Why the reported densities or the density's integral disagree with the draws, if they
    /// do (the checks besides the p-value).
    pub fn consistency_problem(&self) -> Option<String> {
        let produced = self.drawn as f64 / self.attempts.max(1) as f64;
        if self.mismatched_densities as u64 * 1000 > self.drawn as u64 {
            Some(format!(
                "{} of {} samples report a density that differs from the pdf",
                self.mismatched_densities, self.drawn
            ))
        } else if (self.integral - produced).abs() >= 0.02 {
            Some(format!(
                "the density integrates to {:.4}, but {produced:.4} of the attempts drew",
                self.integral
            ))
        } else {
            None
        }
    }
}

impl ChiSquareTest {
    /// Tests `sample`, which maps uniform numbers in [0, 1)² to a direction (or `None` for no
    /// sample), against `pdf`.
    pub fn run(
        &self,
        mut sample: impl FnMut([f32; 2]) -> Option<Drawn>,
        pdf: impl Fn(Vec3) -> f64,
    ) -> ChiSquareOutcome {
        let mut rng = Pcg32::new(self.seed, 11);
        let draws = (0..self.samples).map(|_| sample([rng.next_f32(), rng.next_f32()]));
        self.run_draws(draws, &pdf)
    }

    /// Tests draws made elsewhere (one item per attempt, `None` where an attempt drew
    /// nothing) against `pdf`.
    pub fn run_draws(
        &self,
        draws: impl Iterator<Item = Option<Drawn>>,
        pdf: &impl Fn(Vec3) -> f64,
    ) -> ChiSquareOutcome {
        let layout = LatLong::new(self.rows);
        let mut observed = vec![0.0; layout.texel_count()];
        let (mut attempts, mut drawn, mut mismatched) = (0u32, 0u32, 0u32);
        for draw in draws {
            attempts += 1;
            let Some(draw) = draw else { continue };
            let reference = pdf(draw.direction);
            if let Some(reported) = draw.pdf {
                if (reported - reference).abs() > 1e-3 * reference.max(1e-3) {
                    mismatched += 1;
                }
            }
            observed[layout.index(layout.texel(draw.direction))] += 1.0;
            drawn += 1;
        }
        let probabilities = self.bin_probabilities(layout, pdf);
        let integral = probabilities.iter().sum();
        let expected: Vec<f64> = probabilities.iter().map(|p| p * attempts as f64).collect();
        ChiSquareOutcome {
            p_value: chi_square_p_value(&observed, &expected),
            drawn,
            attempts,
            integral,
            mismatched_densities: mismatched,
        }
    }

    /// The integral of `pdf` over every bin of `layout`.
    fn bin_probabilities(&self, layout: LatLong, pdf: &impl Fn(Vec3) -> f64) -> Vec<f64> {
        let sub = self.subdivision.max(1);
        (0..layout.texel_count())
            .map(|index| {
                let texel = layout.texel_of_index(index);
                let (z0, z1) = (
                    (PI * texel.row as f32 / self.rows as f32).cos(),
                    (PI * (texel.row + 1) as f32 / self.rows as f32).cos(),
                );
                let (phi0, phi1) = (
                    2.0 * PI * texel.column as f32 / layout.width() as f32,
                    2.0 * PI * (texel.column + 1) as f32 / layout.width() as f32,
                );
                let cell = ((z0 - z1) * (phi1 - phi0)) as f64 / (sub * sub) as f64;
                let mut integral = 0.0;
                for i in 0..sub {
                    let z = z0 + (z1 - z0) * (i as f32 + 0.5) / sub as f32;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for j in 0..sub {
                        let phi = phi0 + (phi1 - phi0) * (j as f32 + 0.5) / sub as f32;
                        integral += pdf(Vec3::new(r * phi.cos(), r * phi.sin(), z)) * cell;
                    }
                }
                integral
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::warp::{cosine_hemisphere, cosine_hemisphere_pdf, uniform_sphere};

    fn cosine(u: [f32; 2]) -> Option<Drawn> {
        let direction = cosine_hemisphere(u);
        Some(Drawn::with_pdf(
            direction,
            cosine_hemisphere_pdf(direction) as f64,
        ))
    }

    #[test]
    fn a_correct_sampler_fits() {
        let test = ChiSquareTest::default();
        let outcome = test.run(cosine, |d| cosine_hemisphere_pdf(d) as f64);
        assert!(outcome.fits(0.01), "{:?}", outcome.problem(0.01));
    }

    #[test]
    fn the_harness_rejects_a_wrong_density() {
        // The negative control: uniform directions tested against the cosine density.
        let test = ChiSquareTest::default();
        let outcome = test.run(
            |u| Some(Drawn::direction(uniform_sphere(u))),
            |d| cosine_hemisphere_pdf(d) as f64,
        );
        assert!(outcome.p_value < 1e-6, "{outcome:?}");
        // And a reported density that disagrees with the pdf is caught as such.
        let lying = test.run(
            |u| cosine(u).map(|d| Drawn::with_pdf(d.direction, 2.0 * d.pdf.unwrap())),
            |d| cosine_hemisphere_pdf(d) as f64,
        );
        assert!(lying.problem(0.01).is_some_and(|p| p.contains("report")));
    }
}
