//! The gather integrator: a white furnace, a plane under a sphere light against the
//! analytic answer, unbiasedness of every strategy × AIS mode against a reference, and AIS
//! lowering the variance at equal traced rays in an occluded interior.

mod common;

use ais_render::integrators::gather::field::field_rolls;
use ais_render::integrators::gather::{
    Acceptance, GatherSettings, MapUse, Preset, RayBudget, Sharing, Strategy,
};
use ais_render::integrators::Integrator;
use ais_render::render::{render, RenderSettings};
use ais_render::scene::load_scene;
use ais_render::world::World;
use common::{agreement, camera, occluded_scene, PixelStatistics};

const STRATEGIES: [Strategy; 4] = [
    Strategy::Uniform,
    Strategy::Bsdf,
    Strategy::Light,
    Strategy::Mis,
];
const MODES: [Preset; 7] = Preset::ALL;

/// Statistics of the gather with `gather` settings.
fn pixel_statistics(
    world: &World,
    gather: GatherSettings,
    spp: u32,
    renders: u64,
) -> PixelStatistics {
    common::pixel_statistics(world, &Integrator::Gather(gather), spp, renders)
}

/// [`common::reference_statistics`] of a gather.
fn reference_statistics(
    world: &World,
    gather: GatherSettings,
    spp: u32,
    renders: u64,
) -> PixelStatistics {
    common::reference_statistics(world, &Integrator::Gather(gather), spp, renders)
}

/// The traced budget (the talk's reading: about `rays` traced per gather), which the
/// equal-traced-ray comparisons here were written for; tests of the (default) candidate
/// budget set it themselves.
fn settings(strategy: Strategy, ais: Preset, rays: u32) -> GatherSettings {
    GatherSettings {
        strategy,
        rays,
        budget: RayBudget::Traced,
        // The field's measured cost ratio depends on timing: pinned, so tests never flake.
        cost_ratio: Some(1.0),
        ..GatherSettings::preset(ais)
    }
}

#[test]
fn white_furnace() {
    let world = common::furnace();
    for strategy in STRATEGIES {
        for mode in MODES {
            let statistics = pixel_statistics(&world, settings(strategy, mode, 16), 2, 8);
            let (average, error) = statistics.image_mean();
            assert!(
                (average - 0.8).abs() <= 4.0 * error + 1e-4,
                "{strategy:?} {mode:?}: {average} ± {error}"
            );
        }
    }
}

#[test]
fn smooth_white_surfaces_reflect_a_furnace_exactly() {
    // A perfect mirror reflects the constant environment; a white smooth plastic does too,
    // its mirror lobe carrying F and its base 1 − F (the base's inner reflections lose
    // nothing). Only BSDF samples see the mirror lobe: light samples bring nothing there.
    for bsdf in [
        r#"<bsdf type="conductor"/>"#,
        r#"<bsdf type="plastic"><rgb name="diffuse_reflectance" value="1"/></bsdf>"#,
    ] {
        let xml = format!(
            r#"<scene version="3.0.0">{}
            <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
            <shape type="sphere"><float name="radius" value="1"/>{bsdf}</shape></scene>"#,
            common::camera("0, -5, 0", "0, 0, 0", 8.0, 8)
        );
        let world = common::scene_world("smooth-furnace", &xml, &[]);
        for strategy in [Strategy::Bsdf, Strategy::Mis] {
            for mode in MODES {
                let statistics = pixel_statistics(&world, settings(strategy, mode, 16), 2, 8);
                let (average, error) = statistics.image_mean();
                assert!(
                    (average - 1.0).abs() <= 4.0 * error + 2e-3,
                    "{bsdf} {strategy:?} {mode:?}: {average} ± {error}"
                );
            }
        }
    }
}

#[test]
fn plane_under_a_sphere_light_matches_the_analytic_irradiance() {
    let (world, exact) = common::plane_under_a_sphere_light();
    for strategy in STRATEGIES {
        for mode in MODES {
            let statistics = pixel_statistics(&world, settings(strategy, mode, 16), 16, 24);
            let (mean, se) = (statistics.mean[0], statistics.se[0]);
            let z = (mean - exact) / se.max(1e-9);
            assert!(
                z.abs() < 4.0,
                "{strategy:?} {mode:?}: {mean} ± {se} (z {z:.1})"
            );
        }
    }
}

#[test]
fn light_samples_reach_a_sphere_light_right_up_to_its_rim() {
    // Far from the origin, shadow rays start well off the surface; one sent along the sampled
    // direction to the sampled distance stops past the sphere's surface and loses the light
    // (all of it, here; some of it near the rim anywhere). Light sampling of a sphere seen whole has almost no variance, so a small
    // loss is many standard errors.
    let (world, exact) = common::distant_plane_under_a_sphere_light();
    for mode in [Preset::Off, Preset::Aggressive] {
        let statistics = pixel_statistics(&world, settings(Strategy::Light, mode, 16), 16, 8);
        let (mean, se) = (statistics.mean[0], statistics.se[0]);
        let z = (mean - exact) / se.max(1e-4 * exact);
        assert!(
            z.abs() < 4.0,
            "{mode:?}: {mean} ± {se} against {exact} (z {z:.1})"
        );
    }
}

#[test]
fn point_spot_and_directional_lights_match_the_analytic_radiance() {
    let (world, exact, sky_only) = common::plane_under_delta_lights();
    for strategy in STRATEGIES {
        // Only light sampling reaches a delta light (as in Mitsuba's direct integrator).
        let expected = match strategy {
            Strategy::Light | Strategy::Mis => exact,
            Strategy::Uniform | Strategy::Bsdf => sky_only,
        };
        for mode in MODES {
            let statistics = pixel_statistics(&world, settings(strategy, mode, 16), 16, 24);
            let (mean, se) = (statistics.mean[0], statistics.se[0]);
            // BSDF sampling of a constant sky is exact: no noise, only f32 rounding.
            let z = (mean - expected) / se.max(1e-6 * expected);
            assert!(
                z.abs() < 4.0,
                "{strategy:?} {mode:?}: {mean} ± {se} against {expected} (z {z:.1})"
            );
        }
    }
}

/// Asserts that `gather` agrees with the converged reference of the occluded scene pixel by
/// pixel: no |z| above the bound of `common::agreement` and a mean z² below 2.
fn assert_agrees_with_the_reference(
    world: &World,
    reference: &PixelStatistics,
    gather: GatherSettings,
    renders: u64,
    what: &str,
) {
    if let Err(message) = agreement(&pixel_statistics(world, gather, 8, renders), reference) {
        panic!("{what}: {message}");
    }
}

#[test]
fn every_strategy_and_ais_mode_is_unbiased_against_a_reference() {
    let world = occluded_scene();
    // Standard errors come from the spread over renders: with few renders their own noise
    // inflates z, so both sides use enough of them.
    let reference = reference_statistics(&world, settings(Strategy::Mis, Preset::Off, 32), 64, 32);
    for strategy in STRATEGIES {
        for mode in MODES {
            assert_agrees_with_the_reference(
                &world,
                &reference,
                settings(strategy, mode, 16),
                48,
                &format!("{strategy:?} {mode:?}"),
            );
        }
    }
}

#[test]
fn every_acceptance_rule_is_unbiased_against_a_reference() {
    let world = occluded_scene();
    let reference = reference_statistics(&world, settings(Strategy::Mis, Preset::Off, 32), 64, 8);
    let rules = [
        Acceptance::SqrtAffinity,
        Acceptance::ValueThreshold,
        Acceptance::ValueEfficient,
    ];
    for (mode, acceptance) in [
        Preset::Aggressive,
        Preset::Conservative,
        Preset::Shared,
        Preset::Warm,
    ]
    .into_iter()
    .flat_map(|m| rules.map(|r| (m, r)))
    {
        let gather = GatherSettings {
            acceptance,
            ..settings(Strategy::Mis, mode, 16)
        };
        assert_agrees_with_the_reference(
            &world,
            &reference,
            gather,
            12,
            &format!("{mode:?} + {acceptance:?}"),
        );
    }
}

/// A 4 × 4 room with walls of height 2 under a constant sky: closed by a ceiling with a
/// window of half-width `half_width` from `bottom` to `top` in the wall at y = 2, or open to
/// the sky without a ceiling (a courtyard). Everything is two-sided diffuse.
fn room(half_width: f64, bottom: f64, top: f64, ceiling: bool, target: &str) -> World {
    let (w, b, t) = (half_width, bottom, top);
    let vertices = [
        (-2.0, -2.0, 0.0),
        (2.0, -2.0, 0.0),
        (2.0, 2.0, 0.0),
        (-2.0, 2.0, 0.0),
        (-2.0, -2.0, 2.0),
        (2.0, -2.0, 2.0),
        (2.0, 2.0, 2.0),
        (-2.0, 2.0, 2.0),
        (-w, 2.0, b),
        (w, 2.0, b),
        (w, 2.0, t),
        (-w, 2.0, t),
    ];
    let quads = [
        [1, 2, 3, 4], // floor
        [1, 2, 6, 5], // wall y = −2
        [2, 3, 7, 6], // wall x = 2
        [4, 1, 5, 8], // wall x = −2
        // wall y = 2 around the window
        [4, 3, 10, 9],
        [3, 7, 11, 10],
        [7, 8, 12, 11],
        [8, 4, 9, 12],
    ];
    let mut obj = String::new();
    for (x, y, z) in vertices {
        obj += &format!("v {x} {y} {z}\n");
    }
    if ceiling {
        obj += "f 5 6 7\nf 5 7 8\n";
    }
    for [a, b, c, d] in quads {
        obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
    }
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
        <shape type="obj"><string name="filename" value="room.obj"/>
            <bsdf type="twosided"><bsdf type="diffuse"/></bsdf></shape></scene>"#,
        camera(
            if ceiling {
                "0.1, 1.5, 1.8"
            } else {
                "0.1, 0.5, 1.0"
            },
            target,
            0.01,
            1
        )
    );
    common::scene_world("interior", &xml, &[("room.obj", &obj)])
}

/// Floor points of the rooms, seen through a camera with a tiny field of view so that the
/// variance measured is the gather's alone (not the pixel footprint's).
const PROBES: [&str; 3] = ["0, -1, 0", "1, 0.5, 0", "-1.2, 1.2, 0"];

/// (Var · traced) without AIS over that with aggressive AIS, summed over the probes, for
/// one room, strategy, placement and n.
fn variance_gain(
    room_of: impl Fn(&str) -> World,
    strategy: Strategy,
    placement: ais::Placement,
    rays: u32,
    renders: u64,
) -> f64 {
    let (mut off, mut on) = (0.0, 0.0);
    for target in PROBES {
        let world = room_of(target);
        let with = |ais| GatherSettings {
            placement,
            ..settings(strategy, ais, rays)
        };
        let off_run = pixel_statistics(&world, with(Preset::Off), 1, renders);
        let (off_se, off_traced) = (off_run.se, off_run.traced);
        let ais_run = pixel_statistics(&world, with(Preset::Aggressive), 1, renders);
        let (ais_se, ais_traced) = (ais_run.se, ais_run.traced);
        off += off_se[0] * off_se[0] * off_traced;
        on += ais_se[0] * ais_se[0] * ais_traced;
    }
    off / on
}

/// The big-window interior: a 3.6 × 1.6 opening in one wall of a closed room.
fn big_window(target: &str) -> World {
    room(1.8, 0.3, 1.9, true, target)
}

#[test]
fn ais_lowers_variance_at_equal_traced_rays_in_an_occluded_interior() {
    // With independent candidates AIS gains in the big-window interior; measured 1.38× at
    // n = 256 with 400 renders per probe. (With Halton placement it loses here: see
    // BENCHMARKS.md and `measure_ais_gain_in_rooms`.)
    let gain = variance_gain(big_window, Strategy::Bsdf, ais::Placement::Random, 256, 400);
    println!("big window, random placement, n = 256: gain {gain:.2}×");
    assert!(gain > 1.2, "gain {gain:.2}");
}

/// Var · traced of one probe pixel rendered with `spp` gathers per render (so that shared
/// maps have earlier gathers at the same point to learn from), over `renders` renders.
fn variance_times_rays(world: &World, gather: GatherSettings, spp: u32, renders: u64) -> f64 {
    let statistics = pixel_statistics(world, gather, spp, renders);
    statistics.se[0] * statistics.se[0] * statistics.traced
}

#[test]
fn shared_maps_beat_per_batch_ais_and_no_ais_at_equal_traced_rays() {
    // The big-window interior at n = 128, MIS proposal, independent (random) candidates,
    // an 8-row map, 8 gathers per pixel: each gather after the first starts from the
    // earlier ones' map. Measured (2400 renders per probe): shared 0.76 and per-batch 0.92
    // of AIS off's Var · traced (150 renders had given 0.67 and 0.95: a ratio of variances
    // needs thousands of renders). With Halton placement shared maps lose (0.6-0.8×) unless
    // acceptance is value-efficient: see `measure_shared_maps_in_rooms` and BENCHMARKS.md.
    let (mut off, mut per_batch, mut shared) = (0.0, 0.0, 0.0);
    for target in PROBES {
        let world = big_window(target);
        let with = |ais| GatherSettings {
            placement: ais::Placement::Random,
            map_height: 8,
            ..settings(Strategy::Mis, ais, 128)
        };
        off += variance_times_rays(&world, with(Preset::Off), 8, 2400);
        per_batch += variance_times_rays(&world, with(Preset::Aggressive), 8, 2400);
        shared += variance_times_rays(&world, with(Preset::Shared), 8, 2400);
    }
    println!(
        "Var · traced relative to AIS off: per-batch {:.2}, shared {:.2}",
        per_batch / off,
        shared / off
    );
    assert!(shared < 0.85 * off, "shared {shared:.3e} vs off {off:.3e}");
    assert!(
        shared < 0.9 * per_batch,
        "shared {shared:.3e} vs per-batch {per_batch:.3e}"
    );
}

#[test]
fn every_mode_is_unbiased_with_a_fixed_candidate_budget() {
    let world = occluded_scene();
    let reference = reference_statistics(&world, settings(Strategy::Mis, Preset::Off, 32), 64, 8);
    // The 6 × 6 image is one tile: a learning pass with 2-pixel blocks gives every pixel
    // learned neighbours all around.
    let pass = Sharing::LearningPass { stride: 2 };
    for strategy in [Strategy::Uniform, Strategy::Mis] {
        for (mode, sharing) in [
            (Preset::Off, Sharing::TileOrder),
            (Preset::Aggressive, Sharing::TileOrder),
            (Preset::Shared, Sharing::TileOrder),
            (Preset::Warm, Sharing::TileOrder),
            (Preset::Shared, pass),
            (Preset::Warm, pass),
            (Preset::Guided, pass),
            (Preset::Auto, Sharing::TileOrder),
        ] {
            let gather = GatherSettings {
                budget: RayBudget::Candidates,
                sharing,
                ..settings(strategy, mode, 16)
            };
            assert_agrees_with_the_reference(
                &world,
                &reference,
                gather,
                // Roulette without extra candidates gives rare large weights: the standard
                // error needs more renders to be trustworthy (12 renders: a 7.9σ pixel).
                64,
                &format!("{strategy:?} {mode:?} {sharing:?}, fixed candidates"),
            );
        }
    }
}

/// A shipped scene at 12 × 8 pixels.
fn small_shipped_scene(name: &str) -> World {
    common::shipped_scene_at(name, (12, 8))
}

#[test]
fn the_field_is_unbiased_in_rooms_lit_through_windows() {
    // The field learned in each render's first passes rolls the later ones' candidates,
    // guides their environment draws, or both, through a window: every pixel agrees with
    // AIS off. The interior's sky is an environment map; the overcast room's a constant.
    // Among several lights, it guides the choice of a light by what each brought.
    let cases = [
        ("interior.xml", Strategy::Mis, MapUse::Roulette, true),
        ("interior.xml", Strategy::Mis, MapUse::Proposal, true),
        ("interior.xml", Strategy::Light, MapUse::Proposal, true),
        ("interior.xml", Strategy::Mis, MapUse::Both, true),
        ("overcast_room.xml", Strategy::Mis, MapUse::Both, true),
        // Four sphere lights among pillars: cells choose among the lights by what they see
        // (the field learns there only where it rolls: 64 candidates or more). Roulette
        // pays almost nowhere there, so the field would stand aside after its first pass:
        // kept (`field_race` false) to test its choice.
        ("sphere_lights.xml", Strategy::Light, MapUse::Both, false),
        // A sky with a sun and a lamp under a roof: the cells under it choose the lamp by
        // what it brought them, far above its share of the power.
        ("occluded.xml", Strategy::Mis, MapUse::Proposal, false),
        // A rectangle light seen through a door gap: the cells draw the parts of the light
        // they see, weighing the regions of its sample square by what each brought.
        ("door_gap.xml", Strategy::Mis, MapUse::Proposal, false),
    ];
    for (scene, strategy, map_use, field_race) in cases {
        // At 12 × 8 pixels the default cells (16 footprints) would span the image, and
        // their 256 texels see too few rays for roulette to skip any: smaller cells and
        // maps, so that every use of the field is exercised.
        let gather = GatherSettings {
            budget: RayBudget::Candidates,
            map_use,
            field_race,
            field_res: 8,
            field_cell: 4.0,
            ..settings(strategy, Preset::Auto, 64)
        };
        assert_field_agrees_with_ais_off(scene, gather);
    }
    // The default field (pooled 16 × 16 maps) guiding a room at 16 candidates, as `auto`
    // renders it by default.
    let gather = GatherSettings {
        budget: RayBudget::Candidates,
        ..settings(Strategy::Mis, Preset::Auto, 16)
    };
    assert_field_agrees_with_ais_off("interior.xml", gather);
    // In a courtyard at 32 × 20 pixels the first pass has gathers enough to choose MIS's
    // BSDF share, which the later passes then use.
    let world = common::shipped_scene_at("courtyard.xml", (32, 20));
    let learned = render(
        &world,
        &Integrator::Gather(gather),
        &small_render_settings(),
    );
    assert!(
        learned.stats.mis_share.is_some(),
        "the MIS share is learned"
    );
    assert_agrees_with_ais_off(&world, "courtyard.xml", gather);
}

#[test]
fn gathers_with_the_sizes_the_race_chose_are_unbiased() {
    // Two rooms at 48 × 32 pixels, whose gathers vary much more in some blocks than in
    // others: after the race passes (4 samples) the other 28 gather with fewer candidates
    // where they vary little, chosen per block. The interior is lit by a sky the field guides toward; the door gap by a
    // rectangle light alone, whose regions the field weighs.
    // Emitters seen directly are hidden, so that every pixel is gathered light. The
    // image's mean agrees with AIS off's within 4 standard errors (an estimate 5% off in
    // the sized gathers fails), and its pixels' z² average below 2. (Single pixels' |z| is
    // not checked: with these rooms' heavy tails a few pixels reach 5 in 1536, sized or
    // not.)
    for scene in ["interior.xml", "door_gap.xml"] {
        let world = common::shipped_scene_at(scene, (48, 32));
        let gather = GatherSettings {
            budget: RayBudget::Candidates,
            hide_emitters: true,
            ..settings(Strategy::Mis, Preset::Auto, 16)
        };
        assert_sized_gathers_agree_with_ais_off(&world, scene, gather);
    }
}

/// Checks that `gather` on `world` chooses fewer candidates than it asks for, and that
/// its image's mean agrees with AIS off's and its pixels on average (32 spp, 48 renders).
fn assert_sized_gathers_agree_with_ais_off(world: &World, scene: &str, gather: GatherSettings) {
    let spp = 32;
    let sized = render(
        world,
        &Integrator::Gather(gather),
        &RenderSettings {
            samples_per_pixel: spp,
            ..small_render_settings()
        },
    );
    let mean_size = sized.stats.gather_sizes.expect("gather sizes chosen");
    assert!(mean_size < gather.rays as f64, "{scene}: {mean_size}");
    let off = GatherSettings {
        hide_emitters: true,
        ..settings(Strategy::Mis, Preset::Off, 64)
    };
    let reference = reference_statistics(world, off, 32, 32);
    let statistics = pixel_statistics(world, gather, spp, 48);
    let ((mean, error), (expected, expected_error)) =
        (statistics.image_mean(), reference.image_mean());
    let z = (mean - expected) / error.hypot(expected_error);
    assert!(
        z.abs() < 4.0,
        "{scene}: image mean {mean} against {expected}: z = {z:.2}"
    );
    let mean_square = (statistics.mean.iter().zip(&statistics.se))
        .zip(reference.mean.iter().zip(&reference.se))
        .map(|((m, s), (r, rs))| (m - r).powi(2) / (s * s + rs * rs).max(1e-18))
        .sum::<f64>()
        / statistics.mean.len() as f64;
    assert!(mean_square < 2.0, "{scene}: mean z² {mean_square:.2}");
}

/// The settings of the renders that test the field: 8 spp, seed 1.
fn small_render_settings() -> RenderSettings {
    RenderSettings {
        samples_per_pixel: 8,
        seed: 1,
        first_sample: 0,
        progress: false,
        crop: None,
    }
}

/// Renders the shipped `scene` at 12 × 8 pixels with `gather` (a field preset), checks
/// that the field guided and rolled as its `map_use` says, and that every pixel agrees
/// with AIS off.
fn assert_field_agrees_with_ais_off(scene: &str, gather: GatherSettings) {
    let world = small_shipped_scene(scene);
    let output = render(
        &world,
        &Integrator::Gather(gather),
        &small_render_settings(),
    );
    let map_use = gather.map_use;
    let guided = output.stats.field_guided > 0;
    assert_eq!(guided, map_use.guides(), "{scene} {map_use:?}: guided");
    let rolled = output.stats.ais.rejected_roulette > 0;
    assert_eq!(rolled, field_rolls(&gather), "{scene} {map_use:?}: rolled");
    assert_agrees_with_ais_off(&world, scene, gather);
}

/// Checks that every pixel of `world` rendered with `gather` agrees with AIS off.
fn assert_agrees_with_ais_off(world: &World, scene: &str, gather: GatherSettings) {
    let off = settings(Strategy::Mis, Preset::Off, 64);
    let reference = reference_statistics(world, off, 32, 32);
    let statistics = pixel_statistics(world, gather, 8, 96);
    if let Err(message) = agreement(&statistics, &reference) {
        panic!(
            "{scene} {:?} {:?}: {message}",
            gather.strategy, gather.map_use
        );
    }
}

#[test]
fn with_a_fixed_candidate_budget_shared_maps_cost_least_for_their_variance() {
    // scenes/interior.xml (a room lit by a sky with a sun through a window) at 40 × 22,
    // n = 128 candidates, MIS, Halton placement, 2 gathers per pixel, 32 renders. Cost of a
    // gather = candidates + 2 × traced rays (there a traced candidate costs about 3× a
    // rejected one, BENCHMARKS.md §7); the figure of merit is Σ over pixels of
    // Var / (mean² + 0.01) · cost, the study's relMSE. Measured relative to AIS off:
    // per-batch 0.73, shared 0.55, warm 0.55 (at 80 × 45, 1 gather per pixel: 0.75, 0.55,
    // 0.56). Without the 0.01 (dark pixels weighing as much as lit ones) every AIS mode
    // loses 2-3×: a rare lit candidate weighted 1/affinity dominates a dark pixel.
    let folder = common::shipped_scenes().expect("the shipped scenes' assets");
    let overrides = [
        ("res_x".to_string(), "40".to_string()),
        ("res_y".to_string(), "22".to_string()),
    ];
    let world =
        World::from_description(load_scene(&folder.join("interior.xml"), &overrides).unwrap())
            .unwrap();
    let with = |ais| GatherSettings {
        budget: RayBudget::Candidates,
        ..settings(Strategy::Mis, ais, 128)
    };
    let (spp, renders) = (2, 32);
    let off_mean = pixel_statistics(&world, with(Preset::Off), spp, renders).mean;
    let cost = |gather: GatherSettings| {
        let PixelStatistics { se, traced, .. } = pixel_statistics(&world, gather, spp, renders);
        let relative: f64 = se
            .iter()
            .zip(&off_mean)
            .map(|(s, m)| s * s / (m * m + 1e-2))
            .sum();
        relative * (gather.rays as f64 + 2.0 * traced)
    };
    let off = cost(with(Preset::Off));
    let per_batch = cost(with(Preset::Aggressive)) / off;
    let shared = cost(with(Preset::Shared)) / off;
    let warm = cost(with(Preset::Warm)) / off;
    println!(
        "Var · cost relative to AIS off: per-batch {per_batch:.2}, shared {shared:.2}, warm {warm:.2}"
    );
    assert!(
        shared < 0.85 * per_batch,
        "shared {shared:.2} vs per-batch {per_batch:.2}"
    );
    assert!(
        warm < 0.85 * per_batch,
        "warm {warm:.2} vs per-batch {per_batch:.2}"
    );
    assert!(shared < 0.7, "shared {shared:.2} vs off");
}

/// A measurement, not a check: AIS's variance gain in three rooms for both placements.
/// Run with `cargo test --release -p ais-render --test gather measure -- --ignored --nocapture`;
/// its output is recorded in BENCHMARKS.md.
#[test]
#[ignore = "a measurement for BENCHMARKS.md, run on demand"]
fn measure_ais_gain_in_rooms() {
    let courtyard = |target: &str| room(0.6, 0.8, 1.6, false, target);
    let small_window = |target: &str| room(0.6, 0.8, 1.6, true, target);
    println!("| room | placement | strategy | n = 64 | n = 128 | n = 256 |");
    println!("|---|---|---|---|---|---|");
    for placement in [ais::Placement::Random, ais::Placement::Halton] {
        for strategy in [Strategy::Bsdf, Strategy::Uniform] {
            for (name, room_of) in [
                (
                    "courtyard (walls, no ceiling)",
                    &courtyard as &dyn Fn(&str) -> World,
                ),
                ("small window 1.2 × 0.8", &small_window),
                ("big window 3.6 × 1.6", &big_window),
            ] {
                let gains: Vec<String> = [64u32, 128, 256]
                    .iter()
                    .map(|&n| {
                        format!(
                            "{:.2}×",
                            variance_gain(room_of, strategy, placement, n, 400)
                        )
                    })
                    .collect();
                println!(
                    "| {name} | {placement:?} | {} | {} |",
                    strategy.name(),
                    gains.join(" | ")
                );
            }
        }
    }
}

/// A measurement, not a check: Var · traced relative to AIS off (same placement) for
/// per-batch and shared maps, with and without value-aware acceptance, in the big-window
/// interior at n = 128 with 8 gathers per pixel. Run with
/// `cargo test --release -p ais-render --test gather measure_shared -- --ignored --nocapture`.
#[test]
#[ignore = "a measurement for BENCHMARKS.md, run on demand"]
fn measure_shared_maps_in_rooms() {
    let small_window = |target: &str| room(0.6, 0.8, 1.6, true, target);
    println!("| room | placement | map height | aggressive | aggressive+efficient | shared | shared+value | shared+efficient |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, room_of) in [
        ("big window", &big_window as &dyn Fn(&str) -> World),
        ("small window", &small_window),
    ] {
        for placement in [ais::Placement::Halton, ais::Placement::Random] {
            for map_height in [4, 8, 16] {
                let measure = |ais, acceptance| {
                    PROBES
                        .iter()
                        .map(|target| {
                            let gather = GatherSettings {
                                placement,
                                map_height,
                                acceptance,
                                ..settings(Strategy::Mis, ais, 128)
                            };
                            variance_times_rays(&room_of(target), gather, 8, 150)
                        })
                        .sum::<f64>()
                };
                let off = measure(Preset::Off, Acceptance::Affinity);
                let cells: Vec<String> = [
                    (Preset::Aggressive, Acceptance::Affinity),
                    (Preset::Aggressive, Acceptance::ValueEfficient),
                    (Preset::Shared, Acceptance::Affinity),
                    (Preset::Shared, Acceptance::ValueThreshold),
                    (Preset::Shared, Acceptance::ValueEfficient),
                ]
                .iter()
                .map(|&(ais, acceptance)| format!("{:.2}×", off / measure(ais, acceptance)))
                .collect();
                println!(
                    "| {name} | {placement:?} | {map_height} | {} |",
                    cells.join(" | ")
                );
            }
        }
    }
}

#[test]
fn a_given_mis_share_is_kept_and_unbiased() {
    // `auto` at 16 candidates would learn its own share; a given one is kept, and AIS off
    // takes it too.
    let world = small_shipped_scene("sphere_lights.xml");
    for preset in [Preset::Auto, Preset::Off] {
        let gather = GatherSettings {
            mis_share: Some(0.75),
            ..settings(Strategy::Mis, preset, 16)
        };
        let output = render(
            &world,
            &Integrator::Gather(gather),
            &small_render_settings(),
        );
        assert_eq!(output.stats.mis_share, Some(0.75), "{preset:?}");
        assert_agrees_with_ais_off(&world, "sphere_lights.xml", gather);
    }
}
