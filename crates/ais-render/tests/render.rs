//! End-to-end rendering: scene files with meshes, thread-count independence, and a real
//! model from npm (the Stanford bunny).

use ais_render::default_scene::default_world;
use ais_render::film::{Film, ReconstructionFilter};
use ais_render::image_io::RgbImage;
use ais_render::integrators::gather::mis_share::ROLLING_MIS_SHARE;
use ais_render::integrators::gather::{self, GatherStats};
use ais_render::integrators::gather::{Acceptance, GatherSettings, MapUse, Preset, Sharing};
use ais_render::integrators::{AmbientOcclusion, Integrator};
use ais_render::render::{render, PixelRect, RenderOutput, RenderSettings};
use ais_render::scene::load_scene;
use ais_render::world::World;
use std::path::{Path, PathBuf};

mod common;
use common::{npm_package, scratch};

fn settings(spp: u32) -> RenderSettings {
    RenderSettings {
        samples_per_pixel: spp,
        seed: 5,
        first_sample: 0,
        progress: false,
        crop: None,
    }
}

fn render_with(world: &World, integrator: Integrator, spp: u32) -> RenderOutput<GatherStats> {
    render(world, &integrator, &settings(spp))
}

/// Renders `integrator` on `world` with 2 spp on a pool of `threads` threads.
fn on_threads(world: &World, threads: usize, integrator: Integrator) -> RenderOutput<GatherStats> {
    on_threads_at(world, threads, integrator, 2)
}

/// [`on_threads`] with `spp` samples per pixel.
fn on_threads_at(
    world: &World,
    threads: usize,
    integrator: Integrator,
    spp: u32,
) -> RenderOutput<GatherStats> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| render_with(world, integrator, spp))
}

fn bits(image: &ais_render::image_io::RgbImage) -> Vec<u32> {
    image.pixels.iter().flatten().map(|c| c.to_bits()).collect()
}

/// Renders `settings` at 1 and 2 threads, checks that image and counts agree, and returns
/// the first render.
fn thread_independent(world: &World, settings: GatherSettings) -> RenderOutput<GatherStats> {
    let one = on_threads(world, 1, Integrator::Gather(settings));
    let two = on_threads(world, 2, Integrator::Gather(settings));
    assert_eq!(bits(&one.image), bits(&two.image), "{settings:?}");
    assert_eq!(one.stats.ais, two.stats.ais, "{settings:?}");
    // The threads' summed time on tiles: some, and no more than the pool could give.
    for (output, threads) in [(&one, 1.0), (&two, 2.0)] {
        let (busy, time) = (output.busy.as_secs_f64(), output.time.as_secs_f64());
        assert!(
            busy > 0.0 && busy <= threads * time,
            "{busy} s busy in {time} s"
        );
    }
    one
}

#[test]
fn images_are_bit_identical_at_one_and_two_threads() {
    let world = default_world(48, 27);
    let per_batch = thread_independent(&world, GatherSettings::preset(Preset::Aggressive));
    // Shared maps (with value-aware acceptance) learn across gathers in a fixed order.
    let shared = thread_independent(
        &world,
        GatherSettings {
            acceptance: Acceptance::ValueEfficient,
            ..GatherSettings::preset(Preset::Shared)
        },
    );
    assert!(shared.stats.ais.rejected_roulette > 0, "shared maps reject");
    // Warm starts from the same maps, then per-batch learning, with √affinity acceptance.
    let warm = GatherSettings {
        acceptance: Acceptance::SqrtAffinity,
        ..GatherSettings::preset(Preset::Warm)
    };
    thread_independent(&world, warm);
    // Guided gathers build their proposal from the same neighbourhood maps.
    let guided = thread_independent(&world, GatherSettings::preset(Preset::Guided));
    assert_ne!(
        bits(&guided.image),
        bits(&per_batch.image),
        "the guide changes the proposal"
    );
}

/// Renders `crops` of `world` with `integrator` and pastes them into a whole image.
fn pasted_crops(world: &World, integrator: &Integrator, crops: &[[usize; 4]]) -> Vec<u32> {
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    let mut pasted = vec![[f32::NAN; 3]; width * height];
    for &crop in crops {
        let rect = PixelRect::check_crop(crop, (width, height)).unwrap();
        let part = render(
            world,
            integrator,
            &RenderSettings {
                crop: Some(rect),
                ..settings(2)
            },
        );
        assert_eq!((part.image.width, part.image.height), (crop[2], crop[3]));
        for (i, (x, y)) in rect.pixels().enumerate() {
            pasted[y * width + x] = part.image.pixels[i];
        }
    }
    pasted.iter().flatten().map(|c| c.to_bits()).collect()
}

#[test]
fn a_wide_filter_keeps_crops_and_threads_exact() {
    // Mitsuba's default Gaussian spreads each sample over the pixels within 2 of it: a
    // crop renders the pixels around it too, and tiles' splats add up in a fixed order.
    let mut world = default_world(48, 27);
    world.filter = ReconstructionFilter::MITSUBA_DEFAULT;
    let uneven = [[0, 0, 17, 27], [17, 0, 31, 10], [17, 10, 31, 17]];
    for gather in [Preset::Off, Preset::Conservative].map(GatherSettings::preset) {
        let integrator = Integrator::Gather(gather);
        let whole = thread_independent(&world, gather);
        assert_eq!(
            pasted_crops(&world, &integrator, &uneven),
            bits(&whole.image),
            "{gather:?}"
        );
        // The filter changes the image: it is not the box's.
        let mut boxed = default_world(48, 27);
        boxed.filter = ReconstructionFilter::Box;
        assert_ne!(
            bits(&on_threads(&boxed, 1, integrator).image),
            bits(&whole.image)
        );
    }
    thread_independent(&world, GatherSettings::preset(Preset::Shared));
}

/// Renders of `passes` one-sample passes that continue one another, combined by adding
/// their films, and by averaging their images.
fn progressive_normals(world: &World, passes: u32) -> (RgbImage, RgbImage) {
    let mut film = Film::new(world.resolution.0 as usize, world.resolution.1 as usize);
    let mut averaged = vec![[0.0f64; 3]; film.image().pixels.len()];
    for first_sample in 0..passes {
        let pass = RenderSettings {
            first_sample,
            ..settings(1)
        };
        let output = render(world, &Integrator::Normals, &pass);
        film.add_film(&output.film);
        for (sum, pixel) in averaged.iter_mut().zip(&output.image.pixels) {
            for c in 0..3 {
                sum[c] += pixel[c] as f64 / passes as f64;
            }
        }
    }
    let added = film.image();
    let averaged = RgbImage {
        pixels: averaged.iter().map(|sum| sum.map(|v| v as f32)).collect(),
        ..added
    };
    (added, averaged)
}

#[test]
fn passes_whose_films_are_added_equal_one_render_of_their_samples() {
    // The normals depend on the camera samples alone, and those on their rank: one render
    // of 8 samples and 8 one-sample passes see the same rays.
    let mut world = default_world(48, 27);
    world.filter = ReconstructionFilter::MITSUBA_DEFAULT;
    let whole = render(&world, &Integrator::Normals, &settings(8)).image;
    let (added, averaged) = progressive_normals(&world, 8);
    let largest_difference = |image: &RgbImage| {
        image
            .pixels
            .iter()
            .flatten()
            .zip(whole.pixels.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max)
    };
    assert!(
        largest_difference(&added) < 1e-5,
        "{}",
        largest_difference(&added)
    );
    // Averaging the passes' images is another estimator: a pixel is a ratio of weighted
    // sums, and at the sculpture's edges the mean of one-sample ratios is not the ratio.
    assert!(largest_difference(&averaged) > 1e-2);
}

#[test]
fn crops_pasted_together_equal_the_whole_render() {
    let world = default_world(48, 27);
    // Pixels that are rendered independently agree for any split...
    let uneven = [[0, 0, 17, 27], [17, 0, 31, 10], [17, 10, 31, 17]];
    // ...and tiles that share state (neighbouring gathers' maps) for splits on the tile grid.
    let on_the_grid = [[0, 0, 16, 27], [16, 0, 32, 16], [16, 16, 32, 11]];
    let shared_pass = GatherSettings {
        sharing: Sharing::LearningPass { stride: 4 },
        ..GatherSettings::preset(Preset::Shared)
    };
    let cases = [
        (GatherSettings::preset(Preset::Off), &uneven),
        (GatherSettings::preset(Preset::Conservative), &uneven),
        (GatherSettings::preset(Preset::Shared), &on_the_grid),
        (shared_pass, &on_the_grid),
    ];
    for (gather, crops) in cases {
        let integrator = Integrator::Gather(gather);
        let whole = render(&world, &integrator, &settings(2));
        assert_eq!(
            pasted_crops(&world, &integrator, crops),
            bits(&whole.image),
            "{gather:?}"
        );
    }
}

/// scenes/interior.xml (a room lit through a window by a sky with a sun) at `width × height`.
fn interior(width: u32, height: u32) -> World {
    common::shipped_scene_at("interior.xml", (width, height))
}

#[test]
fn a_progressive_study_stops_observing_once_the_field_has_learned() {
    // Passes of 1 spp that go on from one another, as `ais compare` renders: the field
    // learns from the first samples, as many as a render of its own learns from, and the
    // passes after them record nothing.
    use ais_render::integrators::gather::field::LEARNING_SAMPLES;
    use ais_render::render::render_learning;
    let world = interior(24, 16);
    // Kept throughout (no race to lose): a field that stands aside stops learning anyway.
    let auto = GatherSettings {
        rays: 16,
        field_race: false,
        ..GatherSettings::preset(Preset::Auto)
    };
    let integrator = Integrator::Gather(auto);
    let mut learned = gather::GatherLearning::new(&world, &auto);
    let mut traced = Vec::new();
    for first_sample in 0..LEARNING_SAMPLES + 3 {
        let settings = RenderSettings {
            samples_per_pixel: 1,
            seed: 5,
            first_sample,
            progress: false,
            crop: None,
        };
        render_learning(&world, &integrator, &settings, &mut learned);
        traced.push(learned.field.traced());
    }
    let learning = LEARNING_SAMPLES as usize;
    assert!(
        traced[..learning].windows(2).all(|pair| pair[1] > pair[0]),
        "every learning pass adds rays: {traced:?}"
    );
    assert!(
        traced[learning - 1..]
            .iter()
            .all(|&t| t == traced[learning - 1]),
        "no pass after them does: {traced:?}"
    );
}

#[test]
fn the_learned_field_is_thread_independent_and_used() {
    // Two passes of 1 spp: the field learned in the first is fixed for the second, and
    // merged from integer counts, so the image cannot depend on the threads. A room lit
    // through a window, with many rays per gather: where roulette pays.
    let world = interior(48, 27);
    // The measured cost ratio depends on timing; pinned, the image is reproducible. A low
    // ratio (rays dear next to the rest of a candidate's work) makes roulette pay in some
    // cells. With `map_use = both` the field also guides light sampling.
    for map_use in [MapUse::Roulette, MapUse::Both] {
        let auto = Integrator::Gather(GatherSettings {
            cost_ratio: Some(0.05),
            rays: 128,
            map_use,
            ..GatherSettings::preset(Preset::Auto)
        });
        let one = on_threads(&world, 1, auto);
        let two = on_threads(&world, 2, auto);
        assert_eq!(bits(&one.image), bits(&two.image), "{map_use:?}");
        assert_eq!(one.stats.ais, two.stats.ais);
        assert_eq!(one.stats.field_gathers, two.stats.field_gathers);
        let [rolled, aside] = one.stats.field_gathers;
        assert!(
            rolled > 0 && aside > 0,
            "{rolled} gathers used the field, {aside} did not"
        );
        assert!(one.stats.ais.rejected_roulette > 0, "the field rejects");
        assert!(one.stats.field_memory > 0);
        assert_eq!(one.stats.field_guided > 0, map_use == MapUse::Both);
        // Where the field rolls and guides, MIS gives the BSDF a quarter of the candidates.
        let share = (map_use == MapUse::Both).then_some(ROLLING_MIS_SHARE);
        assert_eq!(one.stats.mis_share, share, "{map_use:?}");
    }
}

#[test]
fn the_default_gather_guides_without_timing_and_is_reproducible() {
    // The default (auto, 16 candidates, the cost ratio measured) neither rolls nor times
    // anything: its image is the same at any thread count and in every run.
    let world = interior(48, 27);
    let auto = Integrator::Gather(GatherSettings::default());
    let one = on_threads(&world, 1, auto);
    let two = on_threads(&world, 2, auto);
    let again = on_threads(&world, 2, auto);
    assert_eq!(bits(&one.image), bits(&two.image));
    assert_eq!(bits(&two.image), bits(&again.image));
    assert!(
        one.stats.field_guided > 0,
        "the field guides light sampling"
    );
    assert_eq!(one.stats.mis_share, two.stats.mis_share);
    assert_eq!(
        one.stats.ais.rejected_roulette, 0,
        "nothing is rolled at n = 16"
    );
}

#[test]
fn the_light_choice_learned_from_what_lights_brought_is_thread_independent() {
    // A sky with a sun and a lamp under a roof: cells choose among the two by what their
    // rays brought, sums of floats that add in tile order between passes, so the image is
    // the same at any thread count.
    let world = common::shipped_scene_at("occluded.xml", (40, 24));
    let auto = Integrator::Gather(GatherSettings::default());
    let one = on_threads_at(&world, 1, auto, 8);
    let two = on_threads_at(&world, 2, auto, 8);
    assert!(one.stats.field_guided > 0, "the field guides");
    assert_eq!(bits(&one.image), bits(&two.image));
}

#[test]
fn the_learned_mis_share_is_thread_independent() {
    // A courtyard, where most gathers see the sky: the first pass has gathers enough to
    // choose MIS's BSDF share, summed in tile order.
    let world = common::shipped_scene_at("courtyard.xml", (40, 24));
    let auto = Integrator::Gather(GatherSettings::default());
    let one = on_threads(&world, 1, auto);
    let two = on_threads(&world, 2, auto);
    assert!(one.stats.mis_share.is_some(), "the MIS share is learned");
    assert_eq!(one.stats.mis_share, two.stats.mis_share);
    assert_eq!(bits(&one.image), bits(&two.image));
}

#[test]
fn the_race_of_the_field_against_ais_off_is_reproducible() {
    // 24 spp: passes of 1, 1, 2, 4 and 16 samples; the second and third race the field
    // against AIS off on a checkerboard of pixels, and the rest follow the verdict, with
    // the candidates per gather the race chose. The race reads sample values only: same
    // image at any thread count.
    let world = interior(48, 27);
    let auto = Integrator::Gather(GatherSettings::default());
    let one = on_threads_at(&world, 1, auto, 24);
    let two = on_threads_at(&world, 2, auto, 24);
    assert_eq!(bits(&one.image), bits(&two.image));
    let race = one.stats.field_race.expect("the default gather raced");
    assert_eq!(Some(race), two.stats.field_race);
    assert!(race.field > 0.0 && race.off > 0.0, "{race:?}");
    // The race also chose the candidates per gather for the last pass.
    assert!(one.stats.gather_sizes.is_some(), "gather sizes chosen");
    assert_eq!(one.stats.gather_sizes, two.stats.gather_sizes);
}

#[test]
fn with_a_pinned_cost_ratio_the_rolling_field_does_not_race() {
    // A rolling field's race is timed (race.rs's tests); with the cost ratio pinned the
    // image must not depend on timings, so there is no race, and the field rolls.
    let world = interior(48, 27);
    let pinned = GatherSettings {
        rays: 128,
        cost_ratio: Some(0.05),
        ..GatherSettings::default()
    };
    let one = on_threads_at(&world, 1, Integrator::Gather(pinned), 8);
    let two = on_threads_at(&world, 2, Integrator::Gather(pinned), 8);
    assert_eq!(one.stats.field_race, None);
    assert!(one.stats.ais.rejected_roulette > 0, "the field rolled");
    assert_eq!(bits(&one.image), bits(&two.image));
}

#[test]
fn candidates_per_block_are_chosen_alike_at_any_thread_count_without_a_field() {
    // A room lit by a disk light through a door gap: the field has no use at 16
    // candidates (one light, drawn by area: no regions to weigh), yet the race passes
    // measure the pixels and the rest gathers as AIS off with the candidates per block
    // they chose, from sample values only.
    let scenes = common::shipped_scenes().expect("the shipped scenes");
    let door_gap = std::fs::read_to_string(scenes.join("door_gap.xml")).unwrap();
    let with_a_disk = door_gap.replace(r#"<shape type="rectangle">"#, r#"<shape type="disk">"#);
    assert_ne!(with_a_disk, door_gap, "the light is a disk");
    let mut world = common::scene_world("door_gap_disk", &with_a_disk, &[]);
    world.set_resolution((48, 32));
    let auto = Integrator::Gather(GatherSettings::default());
    let one = on_threads_at(&world, 1, auto, 24);
    let two = on_threads_at(&world, 2, auto, 24);
    assert!(one.stats.gather_sizes.is_some(), "gather sizes chosen");
    assert_eq!(one.stats.gather_sizes, two.stats.gather_sizes);
    assert_eq!(one.stats.field_race, None, "nothing raced");
    assert_eq!(bits(&one.image), bits(&two.image));
}

/// A learning whose race passes saw every pixel's two samples at 1 ± `spread(x, y)`.
fn raced(world: &World, spread: impl Fn(usize, usize) -> f32) -> gather::GatherLearning {
    use ais_render::integrators::gather::race::TileMoments;
    use ais_render::render::Learning;
    let mut learning = gather::GatherLearning::new(world, &GatherSettings::default());
    let (width, height) = (world.resolution.0 as usize, world.resolution.1 as usize);
    let rect = PixelRect::whole(width, height);
    for pass in 0..3 {
        let mut moments = TileMoments::new(rect, false);
        for (x, y) in rect.pixels() {
            moments.begin_pixel(x, y);
            moments.sampled([1.0 - spread(x, y); 3]);
            moments.sampled([1.0 + spread(x, y); 3]);
        }
        learning.merge(Some(gather::FieldPass {
            observations: ais::field::FieldObservations::new(learning.field.side()),
            cost: Default::default(),
            guided: [1, 1],
            moments: (pass > 0).then_some(moments),
            shares: None,
        }));
        learning.end_pass(ais_render::render::PassEnd {
            done: 2 * (pass + 1),
            left: Some(8),
        });
    }
    learning
}

#[test]
fn a_field_that_loses_its_race_stands_aside_for_the_rest() {
    use ais_render::integrators::gather::race::races_off;
    use ais_render::render::Learning;
    let world = interior(16, 8);
    // The field's pixels are quieter: it guides the rest, and learning goes on.
    let wins = raced(&world, |x, y| if races_off(x, y) { 0.5 } else { 0.2 });
    assert!(wins.race_result().unwrap().field_pays());
    assert!(!wins.stands_aside() && wins.keeps_learning());
    // AIS off's pixels are quieter: the rest gathers as AIS off, and learning stops.
    let loses = raced(&world, |x, y| if races_off(x, y) { 0.2 } else { 0.5 });
    assert!(loses.stands_aside() && !loses.keeps_learning());
}

#[test]
fn field_passes_learn_from_eight_samples_then_render_the_rest() {
    assert_eq!(gather::field_passes(0, 4), vec![1, 1, 2]);
    assert_eq!(gather::field_passes(0, 64), vec![1, 1, 2, 4, 56]);
    assert_eq!(gather::field_passes(0, 8), vec![1, 1, 2, 4]);
    assert_eq!(gather::field_passes(0, 5), vec![1, 1, 2, 1]);
    assert_eq!(gather::field_passes(0, 1), vec![1]);
    assert_eq!(gather::field_passes(0, 0), Vec::<u32>::new());
    // A render that goes on from earlier ones ends its passes where a whole render would.
    assert_eq!(gather::field_passes(2, 2), vec![2]);
    assert_eq!(gather::field_passes(3, 1), vec![1]);
    assert_eq!(gather::field_passes(2, 10), vec![2, 4, 4]);
    assert_eq!(gather::field_passes(8, 4), vec![4]);
}

#[test]
fn maps_from_a_learning_pass_are_thread_independent() {
    // A tile's learning gathers at its edges are also computed by its neighbour tiles, on
    // another thread, and must agree.
    let world = default_world(48, 27);
    let with = |preset, stride| GatherSettings {
        sharing: Sharing::LearningPass { stride },
        ..GatherSettings::preset(preset)
    };
    let from_a_pass = thread_independent(&world, with(Preset::Shared, 4));
    assert!(
        from_a_pass.stats.ais.rejected_roulette > 0,
        "learned maps reject"
    );
    let tile_order = on_threads(
        &world,
        1,
        Integrator::Gather(GatherSettings::preset(Preset::Shared)),
    );
    assert_ne!(
        bits(&from_a_pass.image),
        bits(&tile_order.image),
        "a learning pass is another source of maps"
    );
    thread_independent(&world, with(Preset::Warm, 8));
}

#[test]
fn ambient_occlusion_is_thread_independent() {
    let world = default_world(48, 27);
    let ao = Integrator::AmbientOcclusion(AmbientOcclusion {
        rays: 4,
        distance: 1.0,
    });
    let one = on_threads(&world, 1, ao);
    let two = on_threads(&world, 2, ao);
    assert_eq!(bits(&one.image), bits(&two.image));
    assert_eq!(one.rays, two.rays);
    // The image is not trivially uniform: the sculpture occludes.
    let min = one.image.pixels.iter().map(|p| p[0]).fold(1.0, f32::min);
    assert!(min < 0.5, "some pixels must be occluded, min {min}");
}

/// A scene file with a mesh in front of the camera.
fn write_scene(dir: &Path, shape: &str) -> PathBuf {
    let scene = dir.join("scene.xml");
    std::fs::write(
        &scene,
        format!(
            r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 6" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/></film>
        <sampler type="independent"><integer name="sample_count" value="1"/></sampler>
    </sensor>
    {shape}
</scene>"#
        ),
    )
    .unwrap();
    scene
}

#[test]
fn an_xml_scene_with_an_obj_mesh_renders() {
    let dir = scratch("obj");
    std::fs::write(
        dir.join("quad.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let scene = write_scene(
        &dir,
        r#"<shape type="obj"><string name="filename" value="quad.obj"/></shape>"#,
    );
    let world = World::from_description(load_scene(&scene, &[]).unwrap()).unwrap();
    assert_eq!(world.geometry.triangle_count(), 2);
    let output = render_with(&world, Integrator::Normals, 1);
    // Centre pixel: the quad's normal +z maps to (0.5, 0.5, 1); a corner misses (black).
    let centre = output.image.pixels[16 * 32 + 16];
    assert!(
        (centre[2] - 1.0).abs() < 1e-3 && (centre[0] - 0.5).abs() < 1e-3,
        "{centre:?}"
    );
    assert_eq!(output.image.pixels[0], [0.0; 3]);
}

#[test]
fn path_elements_add_folders_to_search_for_files() {
    let dir = scratch("path-element");
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(
        dir.join("meshes/quad.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let shape = r#"<path value="meshes"/>
    <shape type="obj"><string name="filename" value="quad.obj"/></shape>"#;
    let scene = write_scene(&dir, shape);
    let world = World::from_description(load_scene(&scene, &[]).unwrap()).unwrap();
    assert_eq!(world.geometry.triangle_count(), 2);
    // Without the <path>, the file is looked for beside the scene, and the error says so.
    let scene = write_scene(
        &dir,
        r#"<shape type="obj"><string name="filename" value="quad.obj"/></shape>"#,
    );
    let Err(error) = World::from_description(load_scene(&scene, &[]).unwrap()) else {
        panic!("the mesh is not beside the scene");
    };
    assert!(error.to_string().contains("quad.obj"), "{error}");
}

#[test]
fn a_missing_mesh_is_an_error_naming_the_file() {
    let dir = scratch("missing");
    let scene = write_scene(
        &dir,
        r#"<shape type="ply"><string name="filename" value="nowhere.ply"/></shape>"#,
    );
    let e = World::from_description(load_scene(&scene, &[]).unwrap())
        .err()
        .unwrap();
    assert!(
        e.to_string().contains("nowhere.ply") && e.to_string().contains("not found"),
        "{e}"
    );
}

/// Parses the bunny package's `exports.positions=[[x,y,z],…]` and `exports.cells=[[a,b,c],…]`.
fn bunny_obj(index_js: &str) -> Option<String> {
    let numbers = |name: &str| -> Option<Vec<f64>> {
        let start = index_js.find(&format!("exports.{name}="))? + name.len() + 9;
        let rest = &index_js[start..];
        let end = rest.find("\nexports").unwrap_or(rest.len());
        rest[..end]
            .split(|c: char| c == '[' || c == ']' || c == ',' || c.is_whitespace() || c == ';')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().ok())
            .collect()
    };
    let positions = numbers("positions")?;
    let cells = numbers("cells")?;
    let mut obj = String::new();
    for p in positions.chunks_exact(3) {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for c in cells.chunks_exact(3) {
        obj += &format!("f {} {} {}\n", c[0] + 1.0, c[1] + 1.0, c[2] + 1.0);
    }
    Some(obj)
}

#[test]
fn the_stanford_bunny_from_npm_loads_and_renders() {
    let Some(package) = npm_package("the npm bunny test", "bunny@1.0.1") else {
        return;
    };
    let folder = package.folder();
    let dir = folder.parent().unwrap().to_path_buf();
    let index = std::fs::read_to_string(folder.join("index.js")).unwrap();
    let obj = bunny_obj(&index).expect("the bunny package has positions and cells");
    std::fs::write(dir.join("bunny.obj"), obj).unwrap();
    let scene = write_scene(
        &dir,
        r#"<shape type="obj"><string name="filename" value="bunny.obj"/>
           <transform name="to_world"><translate y="-5"/><scale value="0.25"/></transform></shape>"#,
    );
    let world = World::from_description(load_scene(&scene, &[]).unwrap()).unwrap();
    // The npm bunny is the 1,839-vertex, 3,674-triangle low-resolution Stanford bunny.
    assert_eq!(world.geometry.triangle_count(), 3674);
    let output = render_with(&world, Integrator::Normals, 1);
    let covered = output
        .image
        .pixels
        .iter()
        .filter(|p| p.iter().any(|&c| c > 0.0))
        .count();
    assert!(
        covered > 100 && covered < 32 * 32,
        "bunny covers {covered} of 1024 pixels"
    );
}

#[test]
fn the_exported_default_scene_renders_as_the_built_in_one() {
    let dir = scratch("export-default");
    let file = ais_render::default_scene::export::write_mitsuba_scene(&dir).unwrap();
    let mut exported = World::from_description(load_scene(&file, &[]).unwrap()).unwrap();
    exported.set_resolution((48, 27));
    let built_in = default_world(48, 27);
    assert_eq!(exported.sample_count, built_in.sample_count);
    assert_eq!(
        exported.geometry.triangle_count(),
        built_in.geometry.triangle_count()
    );
    // AIS off: the field's cells would follow the rounding of positions through the files.
    let integrator = Integrator::Gather(GatherSettings::preset(Preset::Off));
    let (a, b) = (
        render_with(&exported, integrator, 2).image,
        render_with(&built_in, integrator, 2).image,
    );
    // The same scene, up to f32 rounding of positions and normals through the files.
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        for c in 0..3 {
            let tolerance = 1e-4 * q[c].abs().max(1.0);
            assert!(
                (p[c] - q[c]).abs() <= tolerance,
                "pixel {i}: {p:?} vs {q:?}"
            );
        }
    }
}
