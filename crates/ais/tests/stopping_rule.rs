//! Why the n+1 rule exists, and where it is not enough.
//!
//! 1. Stopping at the n-th accepted candidate is biased toward high-affinity directions (the
//!    talk's "families until n boys"); drawing until n+1 are accepted and dropping the last
//!    is not, for independent candidates.
//! 2. With Halton placement the candidates are not independent and the n+1 rule is biased
//!    low, even for a fixed acceptance probability; the candidate-budget rule is not.

mod common;

use ais::analytic::{GatherTarget, Proposal, Scene};
use ais::{
    AffinityMap, Batch, BatchConfig, Learning, MapConfig, MapStart, Mode, Placement, Stopping,
};
use common::{summarize, summarize_with, Summary};

const BATCHES: u32 = 20_000;

/// A fixed map whose affinity varies with direction: texels above 45° elevation keep 1,
/// the others are learned down to 1/4.
fn fixed_batch(stopping: Stopping, candidate_cap: u32) -> Batch<f64> {
    let map_config = MapConfig {
        height: 8,
        tol: f32::INFINITY,
        mode: Mode::Aggressive,
        ..MapConfig::default()
    };
    let config = BatchConfig {
        affinity: Some(map_config),
        learning: Learning::Off,
        placement: Placement::Random,
        stopping,
        candidate_cap,
    };
    let mut map = AffinityMap::new(map_config).unwrap();
    let layout = map.level_layout(0);
    for index in 0..layout.texel_count() {
        let direction = layout.center_direction(layout.texel_of_index(index));
        if direction.z < std::f32::consts::FRAC_1_SQRT_2 {
            for _ in 0..2 {
                let lookup = map.lookup(direction);
                map.record(&lookup, 0.0, lookup.affinity);
            }
        }
    }
    let mut batch = Batch::new(config).unwrap();
    batch.map_mut().unwrap().copy_from(&map);
    batch
}

/// Batches of `n` rays on the open scene with a prepared (fixed-map) batch.
fn run_on_open_scene(batch: &mut Batch<f64>, n: u32) -> (Summary, f64) {
    let scene = Scene::open();
    let summary = summarize_with(
        batch,
        &scene,
        Proposal::CosineHemisphere,
        n,
        BATCHES,
        GatherTarget::Normal,
        MapStart::Current,
    );
    (summary, scene.exact())
}

#[test]
fn stopping_at_n_is_biased_and_n_plus_one_is_not() {
    for n in [1, 4] {
        let (at_n, exact) = run_on_open_scene(&mut fixed_batch(Stopping::AtN, 64), n);
        let (n_plus_one, _) = run_on_open_scene(&mut fixed_batch(Stopping::DropLast, 64), n);
        let relative = at_n.mean / exact - 1.0;
        println!(
            "n = {n}: stop at n {:+.2}% (z {:+.1}); n+1 {:+.2}% (z {:+.1})",
            relative * 100.0,
            at_n.z(exact),
            (n_plus_one.mean / exact - 1.0) * 100.0,
            n_plus_one.z(exact)
        );
        assert!(
            at_n.z(exact) > 6.0,
            "n = {n}: stopping at n should be biased high"
        );
        assert!(relative > 0.03, "n = {n}: measured bias {relative}");
        assert!(n_plus_one.z(exact).abs() < 4.0, "n = {n}: n+1 rule biased");
    }
}

#[test]
fn halton_placement_biases_the_n_plus_one_rule_but_not_the_candidate_budget() {
    // The oracle rejects occluded candidates for free: a fixed acceptance probability.
    let scene = Scene::window(0.10);
    for n in [1, 8] {
        let oracle = |config| {
            summarize(
                config,
                &scene,
                Proposal::CosineHemisphere,
                n,
                BATCHES,
                GatherTarget::Oracle,
            )
        };
        let halton_n_plus_one = oracle(BatchConfig::talk_off());
        let halton_budget = oracle(BatchConfig {
            stopping: Stopping::CandidateBudget,
            ..BatchConfig::talk_off()
        });
        let random_n_plus_one = oracle(BatchConfig {
            placement: Placement::Random,
            ..BatchConfig::talk_off()
        });
        let exact = scene.exact();
        println!(
            "n = {n}: Halton n+1 {:+.2}% (z {:+.1}), Halton budget z {:+.1}, random n+1 z {:+.1}",
            (halton_n_plus_one.mean / exact - 1.0) * 100.0,
            halton_n_plus_one.z(exact),
            halton_budget.z(exact),
            random_n_plus_one.z(exact)
        );
        assert!(halton_n_plus_one.z(exact) < -4.0);
        assert!(halton_n_plus_one.mean / exact - 1.0 < -0.02);
        assert!(halton_budget.z(exact).abs() < 4.0);
        assert!(random_n_plus_one.z(exact).abs() < 4.0);
    }
}

#[test]
fn candidate_cap_ends_the_batch_and_stays_unbiased_for_a_fixed_map() {
    // A map of affinity 1/4 below 45° and a cap of 2 candidates per ray: a fifth of the
    // batches end at the cap, and the mixture of n+1 estimates and plain averages over the
    // capped candidates must still be unbiased.
    let mut batch = fixed_batch(Stopping::DropLast, 2);
    let (summary, exact) = run_on_open_scene(&mut batch, 8);
    let cap_share = batch.stats().cap_hits as f64 / BATCHES as f64;
    println!(
        "cap hit in {:.0}% of batches, z {:+.2}",
        cap_share * 100.0,
        summary.z(exact)
    );
    assert!(cap_share > 0.15);
    assert!(summary.z(exact).abs() < 4.0);
    assert!(batch.stats().candidates <= 16 * BATCHES as u64);
}
