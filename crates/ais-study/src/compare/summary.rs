//! The study's summary numbers per configuration: what the tables show, as data (for the
//! Markdown and HTML tables and for the Python package's dicts).

use super::metrics::PixelWeight;
use super::report::ReportContext;
use super::{mean_and_error, Run, StudyResults};

/// A relMSE over runs: mean and standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// The mean over seeds.
    pub mean: f64,
    /// Its standard error (NaN with one seed).
    pub error: f64,
}

/// A configuration's equal-time runs, averaged over seeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EqualTime {
    /// Samples per pixel reached in the budget.
    pub spp: f64,
    /// Milliseconds per sample per pixel.
    pub ms_per_spp: f64,
    /// Gather candidates per pixel (spp × n).
    pub nominal_rays_per_pixel: f64,
    /// Occlusion rays traced per pixel.
    pub traced_rays_per_pixel: f64,
    /// Candidates rejected by roulette per pixel.
    pub rejected_per_pixel: f64,
    /// AIS memory per thread, KiB.
    pub ais_kib_per_thread: f64,
    /// relMSE less the reference's noise, scaled to the budget (relMSE × time / budget).
    pub rel_mse: Measured,
    /// The baseline's relMSE over this one (above 1 is better).
    pub ratio: f64,
    /// The MSE with every pixel weighted alike, less the reference's noise and scaled to
    /// the budget as relMSE is.
    pub mse: Measured,
    /// The baseline's MSE over this one.
    pub mse_ratio: f64,
    /// The relative error with every pixel alike (ε = 10⁻⁴), corrected and scaled as
    /// relMSE is.
    pub relative_alike: Measured,
    /// The baseline's relative error alike over this one.
    pub relative_alike_ratio: f64,
}

/// A configuration's equal-ray runs, averaged over seeds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EqualRays {
    /// Samples per pixel reached.
    pub spp: f64,
    /// Render time, seconds.
    pub seconds: f64,
    /// relMSE scaled to the ray budget (relMSE × rays / budget).
    pub rel_mse: Measured,
    /// The baseline's relMSE over this one.
    pub ratio: f64,
    /// The MSE with every pixel weighted alike, scaled to the ray budget.
    pub mse: Measured,
    /// The baseline's MSE over this one.
    pub mse_ratio: f64,
    /// The relative error with every pixel alike (ε = 10⁻⁴), scaled to the ray budget.
    pub relative_alike: Measured,
    /// The baseline's relative error alike over this one.
    pub relative_alike_ratio: f64,
    /// (baseline − relMSE) / (baseline − oracle's relMSE); NaN without an oracle.
    pub oracle_share: f64,
}

/// One configuration's row of the summary.
#[derive(Clone, Debug, PartialEq)]
pub struct SummaryRow {
    /// The configuration's short name.
    pub name: String,
    /// What it is.
    pub label: String,
    /// Whether it is the oracle.
    pub oracle: bool,
    /// Equal-time results (None for the oracle, which is not timed).
    pub equal_time: Option<EqualTime>,
    /// Equal-ray results.
    pub equal_rays: EqualRays,
}

/// Mean and standard error over runs of an error (relMSE, or one with every pixel alike:
/// `weight`) scaled to the budget: error × cost / budget. A run stops after the pass that
/// crosses its budget, so it overshoots by up to one pass; the error of an unbiased
/// estimator falls as 1 / cost, so scaling removes the overshoot (it matters when a budget
/// holds only a few passes).
fn scaled_error(
    runs: &[Run],
    weight: PixelWeight,
    cost: impl Fn(&Run) -> f64,
    budget: f64,
) -> Measured {
    if runs.is_empty() {
        return Measured {
            mean: f64::NAN,
            error: f64::NAN,
        };
    }
    let scaled: Vec<f64> = runs
        .iter()
        .map(|r| r.error(weight) * cost(r) / budget)
        .collect();
    let (mean, error) = mean_and_error(&scaled);
    Measured { mean, error }
}

/// The errors of a set of runs: relMSE, the MSE, and the relative error alike.
struct Errors {
    rel_mse: Measured,
    mse: Measured,
    relative_alike: Measured,
}

impl Errors {
    /// The runs' errors scaled to the budget by `cost`.
    fn of(runs: &[Run], cost: impl Fn(&Run) -> f64, budget: f64) -> Self {
        Errors {
            rel_mse: scaled_error(runs, PixelWeight::Relative, &cost, budget),
            mse: scaled_error(runs, PixelWeight::Alike, &cost, budget),
            relative_alike: scaled_error(runs, PixelWeight::RelativeAlike, &cost, budget),
        }
    }

    /// `baseline`'s relMSE, MSE and relative error alike over these.
    fn ratios(&self, baseline: &Errors) -> [f64; 3] {
        [
            baseline.rel_mse.mean / self.rel_mse.mean,
            baseline.mse.mean / self.mse.mean,
            baseline.relative_alike.mean / self.relative_alike.mean,
        ]
    }
}

fn average(runs: &[Run], value: impl Fn(&Run) -> f64) -> f64 {
    runs.iter().map(value).sum::<f64>() / runs.len().max(1) as f64
}

fn equal_time(runs: &[Run], context: &ReportContext, baseline: &Errors) -> Option<EqualTime> {
    if runs.is_empty() {
        return None;
    }
    let pixels = (context.resolution.0 * context.resolution.1) as f64;
    let spp = average(runs, |r| r.spp as f64);
    let errors = Errors::of(runs, |r| r.seconds, context.time_budget);
    let [ratio, mse_ratio, relative_alike_ratio] = errors.ratios(baseline);
    Some(EqualTime {
        spp,
        ms_per_spp: 1e3 * average(runs, |r| r.seconds) / spp,
        nominal_rays_per_pixel: spp * context.rays as f64,
        traced_rays_per_pixel: average(runs, |r| r.rays.occlusion as f64) / pixels,
        rejected_per_pixel: average(runs, |r| r.stats.rejected_roulette as f64) / pixels,
        ais_kib_per_thread: average(runs, |r| r.ais_memory_per_thread as f64) / 1024.0,
        rel_mse: errors.rel_mse,
        ratio,
        mse: errors.mse,
        mse_ratio,
        relative_alike: errors.relative_alike,
        relative_alike_ratio,
    })
}

/// The summary of a study, one row per configuration in the order run (the first is the
/// baseline of the ratios).
pub fn summary(results: &StudyResults, context: &ReportContext) -> Vec<SummaryRow> {
    let rays_budget = results.ray_budget as f64;
    let by_rays = |runs: &[Run]| Errors::of(runs, |r| r.rays.total() as f64, rays_budget);
    let by_time = |runs: &[Run]| Errors::of(runs, |r| r.seconds, context.time_budget);
    let first = results.results.first();
    let no_runs: &[Run] = &[];
    let time_baseline = by_time(first.map_or(no_runs, |r| &r.equal_time));
    let rays_baseline = by_rays(first.map_or(no_runs, |r| &r.equal_rays));
    let oracle = results
        .results
        .iter()
        .find(|r| r.configuration.is_oracle())
        .map_or(f64::NAN, |r| by_rays(&r.equal_rays).rel_mse.mean);
    results
        .results
        .iter()
        .map(|result| {
            let errors = by_rays(&result.equal_rays);
            let [ratio, mse_ratio, relative_alike_ratio] = errors.ratios(&rays_baseline);
            let baseline = rays_baseline.rel_mse.mean;
            SummaryRow {
                name: result.configuration.name.clone(),
                label: result.configuration.label.clone(),
                oracle: result.configuration.is_oracle(),
                equal_time: equal_time(&result.equal_time, context, &time_baseline),
                equal_rays: EqualRays {
                    spp: average(&result.equal_rays, |r| r.spp as f64),
                    seconds: average(&result.equal_rays, |r| r.seconds),
                    ratio,
                    oracle_share: (baseline - errors.rel_mse.mean) / (baseline - oracle),
                    rel_mse: errors.rel_mse,
                    mse: errors.mse,
                    mse_ratio,
                    relative_alike: errors.relative_alike,
                    relative_alike_ratio,
                },
            }
        })
        .collect()
}
