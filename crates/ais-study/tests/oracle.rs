//! The oracle gather is exactly unbiased: a white furnace, a plane under a sphere light
//! against the analytic answer, and the occluded scene against the gather's converged
//! reference, for every strategy.

#[path = "../../ais-render/tests/common/mod.rs"]
mod common;

use ais_render::integrators::gather::{GatherSettings, Preset, Strategy};
use ais_render::integrators::Integrator;
use ais_study::oracle::Oracle;
use common::{agreement, pixel_statistics, reference_statistics};

const STRATEGIES: [Strategy; 4] = [
    Strategy::Uniform,
    Strategy::Bsdf,
    Strategy::Light,
    Strategy::Mis,
];

fn oracle(strategy: Strategy) -> Oracle {
    Oracle(GatherSettings {
        strategy,
        rays: 16,
        ..GatherSettings::preset(Preset::Off)
    })
}

#[test]
fn the_oracle_passes_the_white_furnace() {
    let world = common::furnace();
    for strategy in STRATEGIES {
        let (average, error) = pixel_statistics(&world, &oracle(strategy), 2, 8).image_mean();
        assert!(
            (average - 0.8).abs() <= 4.0 * error + 1e-4,
            "{strategy:?}: {average} ± {error}"
        );
    }
}

#[test]
fn the_oracle_matches_the_analytic_irradiance_under_a_sphere_light() {
    let (world, exact) = common::plane_under_a_sphere_light();
    for strategy in STRATEGIES {
        let statistics = pixel_statistics(&world, &oracle(strategy), 16, 24);
        let z = (statistics.mean[0] - exact) / statistics.se[0].max(1e-9);
        assert!(z.abs() < 4.0, "{strategy:?}: z {z:.1}");
    }
}

#[test]
fn the_oracle_agrees_with_the_reference_in_an_occluded_scene() {
    let world = common::occluded_scene();
    let reference_settings = GatherSettings {
        rays: 32,
        ..GatherSettings::preset(Preset::Off)
    };
    let reference = reference_statistics(&world, &Integrator::Gather(reference_settings), 64, 8);
    for strategy in STRATEGIES {
        let statistics = pixel_statistics(&world, &oracle(strategy), 8, 48);
        if let Err(message) = agreement(&statistics, &reference) {
            panic!("{strategy:?}: {message}");
        }
    }
}
