//! The shipped scenes in `scenes/` load without warnings and render.

mod common;

use ais_render::integrators::gather::GatherSettings;
use ais_render::integrators::Integrator;
use ais_render::render::{render, RenderSettings};
use ais_render::scene::load_scene;
use ais_render::world::World;

#[test]
fn shipped_scenes_load_and_render() {
    let folder = match common::shipped_scenes() {
        Ok(folder) => folder,
        Err(why) => return common::skip("the shipped-scenes test", &why),
    };
    for name in ["open", "occluded", "interior", "sunlit_room"] {
        let path = folder.join(format!("{name}.xml"));
        let overrides = [
            ("res_x".to_string(), "32".to_string()),
            ("res_y".to_string(), "18".to_string()),
        ];
        let description = load_scene(&path, &overrides).unwrap();
        assert!(
            description.warnings.is_empty(),
            "{name}: {:?}",
            description.warnings
        );
        assert_eq!(description.integrator.as_ref().unwrap().kind, "gather");
        let world = World::from_description(description).unwrap();
        assert!(world.warnings.is_empty(), "{name}: {:?}", world.warnings);
        assert!(world.lights.environment.is_some(), "{name} has a sky");
        let output = render(
            &world,
            &Integrator::Gather(GatherSettings::default()),
            &RenderSettings {
                samples_per_pixel: 1,
                seed: 0,
                first_sample: 0,
                progress: false,
                crop: None,
            },
        );
        let mean: f64 = output.image.pixels.iter().map(|p| p[1] as f64).sum::<f64>()
            / output.image.pixels.len() as f64;
        assert!(mean.is_finite() && mean > 0.0, "{name}: mean {mean}");
    }
}
