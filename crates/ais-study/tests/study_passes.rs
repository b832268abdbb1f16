//! A study's run learns, races and chooses its gather sizes exactly as `ais render` does:
//! its first passes are the render's own.

#[path = "../../ais-render/tests/common/mod.rs"]
mod common;

use ais_render::integrators::gather::field::LEARNING_PASSES;
use ais_render::integrators::gather::{GatherLearning, GatherSettings, Preset};
use ais_render::integrators::Integrator;
use ais_render::render::{render_learning, RenderSettings};
use ais_study::compare::{Configuration, SampleRange};

/// `ais auto` at 16 candidates: no roulette, so nothing it decides depends on timing.
fn auto_settings() -> GatherSettings {
    GatherSettings {
        rays: 16,
        ..GatherSettings::preset(Preset::Auto)
    }
}

#[test]
fn a_runs_first_passes_are_those_of_a_render() {
    let world = common::shipped_scene_at("sphere_lights.xml", (32, 24));
    let auto = Configuration::new("auto", "auto", auto_settings());
    assert_eq!(auto.leading_passes(&world), LEARNING_PASSES.to_vec());
    let off = Configuration::new("off", "off", GatherSettings::preset(Preset::Off));
    assert_eq!(off.leading_passes(&world), Vec::<u32>::new());
    let oracle = Configuration::oracle("oracle", "oracle", auto_settings());
    assert_eq!(oracle.leading_passes(&world), Vec::<u32>::new());
}

#[test]
fn a_run_races_and_sizes_its_gathers_as_a_render_does() {
    // The race reads the samples of the render's second and third passes (1 and 2 per
    // pixel): a study that rendered passes of one sample would race on two samples per
    // pixel, and choose other gather sizes, than the renderer it measures.
    let world = common::shipped_scene_at("sphere_lights.xml", (48, 32));
    let configuration = Configuration::new("auto", "auto", auto_settings());
    let mut studied = GatherLearning::new(&world, &auto_settings());
    let mut first = 0;
    for count in configuration.leading_passes(&world) {
        let samples = SampleRange { first, count };
        configuration.render_pass(&world, samples, 7, &mut studied);
        first += count;
    }
    let mut rendered = GatherLearning::new(&world, &auto_settings());
    let settings = RenderSettings {
        samples_per_pixel: first,
        seed: 7,
        first_sample: 0,
        progress: false,
        crop: None,
    };
    render_learning(
        &world,
        &Integrator::Gather(auto_settings()),
        &settings,
        &mut rendered,
    );
    let race = rendered.race_result().expect("the render raced");
    assert_eq!(studied.race_result(), Some(race));
    assert_eq!(studied.gather_sizes(), rendered.gather_sizes());
}
