//! Unbiasedness of every configuration on an occluded analytic scene: the mean of 10⁴
//! independent batches must lie within 4 standard errors of the exact integral.
//!
//! Configurations: aggressive and conservative × single- and (literal) multi-level ×
//! tol ∈ {∞, 1, 0.25} × n ∈ {8, 32, 128}, under three schedules:
//! - frozen-map epochs with random placement and the n+1 rule (exact);
//! - frozen-map epochs with Halton placement and the candidate budget (exact; the default);
//! - the talk's continuous updates with random placement and the n+1 rule (not exact in
//!   theory; measured within the bound on this grid).
//!
//! The talk's own placement, Halton with the n+1 rule, is biased even for a fixed map; that
//! is shown in `stopping_rule.rs`.

mod common;

use ais::analytic::{GatherTarget, Proposal, Scene};
use ais::{BatchConfig, Learning, LevelRule, MapConfig, Mode, Placement, Stopping};
use common::summarize;

const BATCHES: u32 = 10_000;

fn grid() -> Vec<(String, MapConfig, u32)> {
    let mut cells = Vec::new();
    for mode in [Mode::Aggressive, Mode::Conservative] {
        for levels in [LevelRule::Single, LevelRule::FinestBelowOne { count: 3 }] {
            for tol in [f32::INFINITY, 1.0, 0.25] {
                for n in [8, 32, 128] {
                    let label = format!("{mode:?} {levels:?} tol {tol} n {n}");
                    let config = MapConfig {
                        height: 8,
                        tol,
                        mode,
                        levels,
                    };
                    cells.push((label, config, n));
                }
            }
        }
    }
    cells
}

/// Runs the grid on two threads and returns (label, z) per cell.
fn measure_grid(
    learning: Learning,
    placement: Placement,
    stopping: Stopping,
) -> Vec<(String, f64)> {
    let scene = Scene::window(0.35);
    let cells = grid();
    let (first, second) = cells.split_at(cells.len() / 2);
    let run = |part: &[(String, MapConfig, u32)]| -> Vec<(String, f64)> {
        part.iter()
            .map(|(label, map, n)| {
                let config = BatchConfig {
                    affinity: Some(*map),
                    learning,
                    placement,
                    stopping,
                    ..BatchConfig::default()
                };
                let summary = summarize(
                    config,
                    &scene,
                    Proposal::CosineHemisphere,
                    *n,
                    BATCHES,
                    GatherTarget::Normal,
                );
                (label.clone(), summary.z(scene.exact()))
            })
            .collect()
    };
    let (mut a, b) = std::thread::scope(|scope| {
        let handle = scope.spawn(|| run(second));
        (run(first), handle.join().unwrap())
    });
    a.extend(b);
    for (label, z) in &a {
        println!("{label}: z = {z:+.2}");
    }
    a
}

fn assert_all_within(results: &[(String, f64)], bound: f64) {
    let failures: Vec<_> = results.iter().filter(|(_, z)| z.abs() >= bound).collect();
    assert!(
        failures.is_empty(),
        "biased beyond {bound} standard errors: {failures:?}"
    );
}

/// Frozen-map epochs (4) over the whole grid, within 4 standard errors.
fn assert_epochs_unbiased(placement: Placement, stopping: Stopping) {
    let results = measure_grid(Learning::Epochs { epochs: 4 }, placement, stopping);
    assert_all_within(&results, 4.0);
}

#[test]
fn epochs_with_random_placement_and_n_plus_one_are_unbiased() {
    assert_epochs_unbiased(Placement::Random, Stopping::DropLast);
}

#[test]
fn epochs_with_halton_placement_and_candidate_budget_are_unbiased() {
    assert_epochs_unbiased(Placement::Halton, Stopping::CandidateBudget);
}

#[test]
fn epochs_with_halton_placement_and_fixed_candidates_are_unbiased() {
    assert_epochs_unbiased(Placement::Halton, Stopping::FixedCandidates);
}

/// The talk's continuous updates are not exactly unbiased in theory (acceptance changes
/// inside the batch). With independent candidates this grid measured them within ±2.3
/// standard errors at 10⁴ batches (see BENCHMARKS.md for larger n and other scenes, where
/// the bias does show), so the test holds them to the same bound.
#[test]
fn continuous_updates_with_random_placement_show_no_bias_on_this_grid() {
    let results = measure_grid(Learning::Continuous, Placement::Random, Stopping::DropLast);
    assert_all_within(&results, 4.0);
}

/// The talk's own schedule (continuous updates, Halton placement, n+1 rule) with the literal
/// multi-level reading is biased; this states the measured bias. It is not offered as a
/// default (the default is exactly unbiased).
#[test]
fn the_talks_schedule_with_literal_multilevel_is_measurably_biased() {
    let scene = Scene::courtyard();
    let config = BatchConfig {
        affinity: Some(MapConfig {
            height: 8,
            tol: f32::INFINITY,
            mode: Mode::Aggressive,
            levels: LevelRule::FinestBelowOne { count: 3 },
        }),
        learning: Learning::Continuous,
        placement: Placement::Halton,
        stopping: Stopping::DropLast,
        ..BatchConfig::default()
    };
    let summary = summarize(
        config,
        &scene,
        Proposal::CosineHemisphere,
        128,
        BATCHES,
        GatherTarget::Normal,
    );
    let relative = summary.mean / scene.exact() - 1.0;
    println!(
        "courtyard n = 128: bias {:+.2}%, z = {:+.1}",
        relative * 100.0,
        summary.z(scene.exact())
    );
    // Measured: z = +21.4 with 10⁴ batches (BENCHMARKS.md).
    assert!(summary.z(scene.exact()) > 10.0);
    assert!(relative > 0.01);
}
