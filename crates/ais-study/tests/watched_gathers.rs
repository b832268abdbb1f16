//! A gather watched one candidate at a time (as `--time-ais` watches it) gives the image of
//! the unwatched gather, to the bit: AIS off's candidates taken at once from the driver and
//! traced in runs, and auto's decided ahead, add up to what the candidate-by-candidate
//! calls give.

#[path = "../../ais-render/tests/common/mod.rs"]
mod common;

use ais_render::integrators::gather::{GatherSettings, Preset};
use ais_render::integrators::Integrator;
use ais_render::render::{render, RenderSettings};
use ais_study::timing::TimedGather;

fn settings(preset: Preset) -> GatherSettings {
    GatherSettings {
        rays: 16,
        ..GatherSettings::preset(preset)
    }
}

#[test]
fn watched_and_unwatched_gathers_give_the_same_image() {
    let render_settings = RenderSettings {
        samples_per_pixel: 8,
        seed: 5,
        first_sample: 0,
        progress: false,
        crop: None,
    };
    // A rectangle light, sphere lights, and an environment map with a sun.
    for scene in ["door_gap.xml", "sphere_lights.xml", "sunlit_room.xml"] {
        let world = common::shipped_scene_at(scene, (24, 16));
        for preset in [Preset::Off, Preset::Auto] {
            let gather = settings(preset);
            let unwatched = render(&world, &Integrator::Gather(gather), &render_settings);
            let watched = render(&world, &TimedGather(gather), &render_settings);
            let bits = |pixels: &[[f32; 3]]| -> Vec<u32> {
                pixels.iter().flatten().map(|x| x.to_bits()).collect()
            };
            assert_eq!(
                bits(&unwatched.image.pixels),
                bits(&watched.image.pixels),
                "{scene}, {preset:?}"
            );
        }
    }
}
