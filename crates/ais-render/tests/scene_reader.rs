//! The Mitsuba XML reader on hand-written scenes, including every error path.

mod common;

use ais_render::scene::{parse_scene, FovAxis, Property, ShapeGeometry};
use glam::{DMat4, DVec3};
use std::path::Path;

fn parse(text: &str) -> Result<ais_render::scene::SceneDescription, ais_render::InputError> {
    parse_scene(Path::new("/scenes/test.xml"), text, &[])
}

fn error(text: &str) -> String {
    let e = parse(text).expect_err("the scene should be refused");
    assert_eq!(
        e.file,
        Path::new("/scenes/test.xml"),
        "the error names the file"
    );
    e.to_string()
}

const FULL: &str = r#"<?xml version="1.0"?>
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <default name="res" value="320"/>
    <integrator type="direct"/>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <string name="fov_axis" value="y"/>
        <transform name="to_world">
            <lookat origin="0, 1, 5" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="240"/>
        </film>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
    </sensor>
    <bsdf type="diffuse" id="grey">
        <rgb name="reflectance" value="0.5, 0.5, 0.5"/>
    </bsdf>
    <shape type="obj">
        <string name="filename" value="meshes/bunny.obj"/>
        <boolean name="face_normals" value="true"/>
        <ref id="grey"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="1" y="2" z="3"/>
        <float name="radius" value="0.5"/>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="2"/>
            <rotate x="1" angle="90"/>
            <translate x="1" y="0" z="0"/>
        </transform>
        <boolean name="flip_normals" value="true"/>
        <bsdf type="roughconductor"/>
    </shape>
    <shape type="disk"/>
    <shape type="cube"/>
    <shape type="ply"><string name="filename" value="a.ply"/></shape>
    <shape type="glb"><string name="filename" value="b.glb"/></shape>
    <emitter type="envmap">
        <string name="filename" value="sky.exr"/>
        <float name="scale" value="2"/>
    </emitter>
</scene>"#;

#[test]
fn a_full_scene_is_read() {
    let scene = parse(FULL).unwrap();
    assert_eq!(scene.resolution, (320, 240));
    assert_eq!(scene.sample_count, 64);
    assert_eq!(scene.camera.fov_degrees, 45.0);
    assert_eq!(scene.camera.fov_axis, FovAxis::Y);
    let origin = scene.camera.to_world.transform_point3(DVec3::ZERO);
    assert!((origin - DVec3::new(0.0, 1.0, 5.0)).length() < 1e-12);
    let forward = scene.camera.to_world.transform_vector3(DVec3::Z);
    assert!((forward - DVec3::new(0.0, -1.0, -5.0).normalize()).length() < 1e-12);
    assert_eq!(scene.shapes.len(), 7);
    match &scene.shapes[0].geometry {
        ShapeGeometry::Mesh { path, .. } => assert_eq!(path, Path::new("/scenes/meshes/bunny.obj")),
        other => panic!("{other:?}"),
    }
    assert!(scene.shapes[0].face_normals);
    assert_eq!(scene.shapes[0].bsdf, Some(0));
    assert_eq!(scene.bsdfs[0].kind, "diffuse");
    assert_eq!(
        scene.bsdfs[0].properties["reflectance"].value,
        Property::Rgb([0.5, 0.5, 0.5])
    );
    assert_eq!(
        scene.shapes[1].geometry,
        ShapeGeometry::Sphere {
            center: DVec3::new(1.0, 2.0, 3.0),
            radius: 0.5
        }
    );
    assert_eq!(scene.shapes[1].emitter.as_ref().unwrap().kind, "area");
    // Transforms compose in order: scale, then rotate, then translate.
    let expected = DMat4::from_translation(DVec3::X)
        * DMat4::from_axis_angle(DVec3::X, 90f64.to_radians())
        * DMat4::from_scale(DVec3::splat(2.0));
    assert!(scene.shapes[2].to_world.abs_diff_eq(expected, 1e-12));
    assert!(scene.shapes[2].flip_normals);
    assert_eq!(
        scene.bsdfs[scene.shapes[2].bsdf.unwrap()].kind,
        "roughconductor"
    );
    assert_eq!(scene.emitters.len(), 1);
    assert_eq!(scene.emitters[0].kind, "envmap");
    assert_eq!(scene.integrator.as_ref().unwrap().kind, "direct");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

#[test]
fn command_line_parameters_override_defaults() {
    let scene = parse_scene(Path::new("t.xml"), FULL, &[("spp".into(), "8".into())]).unwrap();
    assert_eq!(scene.sample_count, 8);
}

#[test]
fn matrix_transform_is_row_major() {
    let scene = parse(
        r#"<scene version="3.0.0"><shape type="cube"><transform name="to_world">
        <matrix value="1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1"/></transform></shape></scene>"#,
    )
    .unwrap();
    let p = scene.shapes[0].to_world.transform_point3(DVec3::ZERO);
    assert_eq!(p, DVec3::new(5.0, 6.0, 7.0));
}

#[test]
fn ignored_properties_and_filters_are_warned_about() {
    let scene = parse(
        r#"<scene version="3.0.0">
        <sensor type="perspective"><float name="shutter" value="1"/>
          <film type="hdrfilm"><rfilter type="mitchell"/></film></sensor>
        <shape type="cube"><float name="weird" value="1"/></shape>
        </scene>"#,
    )
    .unwrap();
    let all = scene.warnings.join("\n");
    assert!(all.contains("test.xml:2: property \"shutter\""), "{all}");
    assert!(all.contains("\"mitchell\" replaced by a Gaussian"), "{all}");
    assert!(all.contains("test.xml:4: property \"weird\""), "{all}");
}

#[test]
fn reconstruction_filters_take_mitsubas_defaults() {
    use ais_render::film::ReconstructionFilter;
    let filter = |film: &str| {
        let text =
            format!(r#"<scene version="3.0.0"><sensor type="perspective">{film}</sensor></scene>"#);
        parse(&text).map(|scene| (scene.filter, scene.warnings))
    };
    // No film, or a film without a filter: Mitsuba's Gaussian of σ = ½.
    let gaussian = ReconstructionFilter::Gaussian { stddev: 0.5 };
    assert_eq!(filter("").unwrap().0, gaussian);
    assert_eq!(filter(r#"<film type="hdrfilm"/>"#).unwrap().0, gaussian);
    let read = |rfilter: &str| filter(&format!(r#"<film type="hdrfilm">{rfilter}</film>"#));
    assert_eq!(
        read(r#"<rfilter type="box"/>"#).unwrap().0,
        ReconstructionFilter::Box
    );
    assert_eq!(
        read(r#"<rfilter type="tent"/>"#).unwrap().0,
        ReconstructionFilter::Tent { radius: 1.0 }
    );
    let wide = read(r#"<rfilter type="gaussian"><float name="stddev" value="0.75"/></rfilter>"#);
    assert_eq!(
        wide.unwrap().0,
        ReconstructionFilter::Gaussian { stddev: 0.75 }
    );
    let (_, warnings) =
        read(r#"<rfilter type="box"><float name="width" value="2"/></rfilter>"#).unwrap();
    assert!(
        warnings.join("\n").contains("property \"width\""),
        "{warnings:?}"
    );
    // Mitsuba's Gaussian reaches 4σ: more than 16 pixels is refused.
    let too_wide = read(r#"<rfilter type="gaussian"><float name="stddev" value="5"/></rfilter>"#);
    assert!(too_wide.unwrap_err().to_string().contains("(0, 4]"));
    let bad = read(r#"<rfilter type="gaussian"><float name="stddev" value="0"/></rfilter>"#);
    let message = bad.unwrap_err().to_string();
    assert!(
        message.contains("test.xml:1") && message.contains("stddev"),
        "{message}"
    );
}

#[test]
fn spectra_become_colours_as_mitsubas_rgb_variants_make_them() {
    use ais_render::scene::ColourRole;
    let scene = parse(
        "<scene><emitter type=\"constant\"><spectrum name=\"radiance\" value=\"0.25\"/></emitter>
         <bsdf type=\"diffuse\" id=\"paint\"><spectrum name=\"reflectance\" value=\"0.25\"/></bsdf>
         <bsdf type=\"diffuse\" id=\"red\">
           <spectrum name=\"reflectance\" value=\"400:0.04, 500:0.058, 600:0.287, 700:0.642\"/></bsdf>
         </scene>",
    )
    .unwrap();
    let colour = |plugin: &ais_render::scene::Plugin, name, role| {
        plugin.colour(name, role).unwrap().unwrap().to_array()
    };
    // A flat emission spectrum is not white in sRGB: value × sRGB of the equal-energy white.
    let radiance = colour(&scene.emitters[0], "radiance", ColourRole::Emission);
    let expected = [1.204794f32, 0.948291, 0.908916].map(|c| 0.25 * c);
    for (r, e) in radiance.iter().zip(expected) {
        assert!((r - e).abs() < 1e-5, "{radiance:?}");
    }
    let paint = colour(&scene.bsdfs[0], "reflectance", ColourRole::Reflectance);
    assert_eq!(paint, [0.25; 3]);
    let red = colour(&scene.bsdfs[1], "reflectance", ColourRole::Reflectance);
    assert!(red[0] > 0.3 && red[1] < 0.2 && red[2] < 0.1, "{red:?}");
}

#[test]
fn every_error_names_file_line_and_problem() {
    let cases: &[(&str, &str)] = &[
        ("<scene><shape type=\"cube\"></scene>", "malformed XML"),
        ("<world/>", "root element must be <scene>"),
        ("<scene>\n<medium type=\"homogeneous\"/></scene>", "test.xml:2: <medium> is not supported"),
        ("<scene>\n<include filename=\"x.xml\"/></scene>", "test.xml:2: the included file /scenes/x.xml does not exist"),
        ("<scene><shape type=\"cube\">\n<include filename=\"x.xml\"/></shape></scene>", "test.xml:2: <include> is only supported at scene level"),
        ("<scene><emitter type=\"constant\">\n<spectrum name=\"radiance\" value=\"700:1, 400:2\"/></emitter></scene>", "test.xml:2: wavelengths must increase, but 400 follows 700"),
        ("<scene><emitter type=\"constant\">\n<spectrum name=\"radiance\" filename=\"d65.spd\"/></emitter></scene>", "test.xml:2: cannot read the spectrum file /scenes/d65.spd"),
        ("<scene>\n<banana/></scene>", "test.xml:2: unexpected element <banana> in <scene>"),
        ("<scene>\n<shape/></scene>", "test.xml:2: <shape> needs a \"type\" attribute"),
        ("<scene>\n<shape type=\"teapot\"/></scene>", "test.xml:2: shape type \"teapot\" is not supported"),
        ("<scene>\n<shape type=\"obj\"/></scene>", "needs a \"filename\" string"),
        ("<scene><shape type=\"sphere\">\n<float name=\"radius\" value=\"abc\"/></shape></scene>", "test.xml:2: \"abc\" is not a number"),
        ("<scene><shape type=\"sphere\">\n<float name=\"radius\" value=\"-1\"/></shape></scene>", "radius must be positive"),
        ("<scene>\n<shape type=\"cylinder\"><float name=\"radius\" value=\"0\"/></shape></scene>", "test.xml:2: cylinder radius must be positive"),
        ("<scene>\n<shape type=\"cylinder\"><point name=\"p0\" x=\"0\" y=\"0\" z=\"1\"/></shape></scene>", "test.xml:2: cylinder p0 and p1 must be finite and distinct"),
        ("<scene><shape type=\"sphere\">\n<string name=\"radius\" value=\"1\"/></shape></scene>", "test.xml:2: property \"radius\" of shape \"sphere\" must be a float, not a string"),
        ("<scene><shape type=\"cube\">\n<boolean name=\"flip_normals\" value=\"yes\"/></shape></scene>", "\"yes\" is not true or false"),
        ("<scene><sensor type=\"perspective\"><film type=\"hdrfilm\">\n<integer name=\"width\" value=\"1.5\"/></film></sensor></scene>", "test.xml:2: \"1.5\" is not an integer"),
        ("<scene><sensor type=\"perspective\"><film type=\"hdrfilm\">\n<integer name=\"width\" value=\"0\"/></film></sensor></scene>", "out of range"),
        ("<scene><sensor type=\"radiancemeter\"/></scene>", "sensor type \"radiancemeter\" is not supported"),
        ("<scene><sensor type=\"thinlens\"/></scene>", "a thinlens sensor needs \"aperture_radius\""),
        ("<scene><sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.1\"/><float name=\"focus_distance\" value=\"0\"/></sensor></scene>", "focus_distance must be positive"),
        ("<scene><sensor type=\"perspective\"><float name=\"fov\" value=\"200\"/></sensor></scene>", "fov must be in (0, 180)"),
        ("<scene><sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"z\"/></sensor></scene>", "unknown fov_axis"),
        ("<scene><sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><string name=\"focal_length\" value=\"35mm\"/></sensor></scene>", "give either \"fov\" or \"focal_length\", not both"),
        ("<scene><sensor type=\"perspective\"><string name=\"focal_length\" value=\"wide\"/></sensor></scene>", "focal_length \"wide\" must be a positive length in mm"),
        ("<scene><sensor type=\"perspective\"><film type=\"ldrfilm\"/></sensor></scene>", "film type \"ldrfilm\" is not supported"),
        ("<scene><sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sample_count\" value=\"0\"/></sampler></sensor></scene>", "sample_count must be at least 1"),
        ("<scene><sensor type=\"perspective\"/><sensor type=\"perspective\"/></scene>", "only one <sensor>"),
        ("<scene><shape type=\"cube\">\n<ref id=\"nothing\"/></shape></scene>", "test.xml:2: no <bsdf> or area <emitter> with id \"nothing\""),
        ("<scene>\n<emitter type=\"area\"/></scene>", "test.xml:2: an area emitter must be nested in a <shape>"),
        ("<scene><shape type=\"cube\">\n<emitter type=\"envmap\"/></shape></scene>", "can only carry an area emitter"),
        ("<scene><shape type=\"cube\"><float name=\"x\" value=\"$missing\"/></shape></scene>", "parameter $missing has no <default>"),
        ("<scene><shape type=\"cube\"><transform name=\"to_world\"><scale value=\"0\"/></transform></shape></scene>", "singular"),
        ("<scene><shape type=\"cube\"><transform name=\"to_world\"><rotate angle=\"30\" x=\"0\"/></transform></shape></scene>", "non-zero axis"),
        ("<scene><shape type=\"cube\"><transform name=\"to_world\"><matrix value=\"1 2 3\"/></transform></shape></scene>", "9 or 16 numbers"),
        ("<scene><shape type=\"cube\"><transform name=\"to_world\"><lookat origin=\"0,0,0\" target=\"0,0,0\"/></transform></shape></scene>", "target = origin"),
        ("<scene><shape type=\"cube\"><transform name=\"to_world\"><shear/></transform></shape></scene>", "unexpected element <shear> in <transform>"),
        ("<scene><shape type=\"cube\"><rgb name=\"c\" value=\"1 2\"/></shape></scene>", "<rgb> needs 1 or 3 numbers"),
        ("<scene><shape type=\"cube\"><point name=\"c\"/></shape></scene>", "<point> needs x, y, z or value"),
        ("<scene><shape type=\"cube\"><default name=\"a\" value=\"1\"/></shape></scene>", "<default> must be a direct child"),
        ("<scene><ref id=\"x\"/></scene>", "a <ref> at scene level"),
    ];
    for (text, expected) in cases {
        let message = error(text);
        assert!(
            message.contains(expected),
            "for {text}\n got: {message}\n want: {expected}"
        );
        assert!(
            message.starts_with("/scenes/test.xml:"),
            "no line in: {message}"
        );
    }
}

#[test]
fn a_truncated_file_says_so() {
    let e = parse(r#"<scene version="3.0.0"><shape type="sphere"><bsdf type="diff"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("is it truncated?"), "{e}");
}

/// Asserts that the scene `text` parses but cannot become a world, with an error that says
/// `expected`.
fn assert_world_refuses(text: &str, expected: &str) {
    let description = parse(text).expect("the file itself is well formed");
    let Err(e) = ais_render::world::World::from_description(description) else {
        panic!("{text} should be refused");
    };
    let message = e.to_string();
    assert!(
        message.contains(expected),
        "for {text}\n got: {message}\n want: {expected}"
    );
}

#[test]
fn emitter_errors_name_file_line_and_problem() {
    let cases: &[(&str, &str)] = &[
        ("<scene><emitter type=\"constant\"/>\n<emitter type=\"constant\"/></scene>", "test.xml:2: only one envmap or constant emitter"),
        ("<scene>\n<emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"0\"/></emitter></scene>", "test.xml:2: spot angles must be finite"),
        ("<scene>\n<emitter type=\"point\"><point name=\"position\" x=\"nan\" y=\"0\" z=\"0\"/></emitter></scene>", "test.xml:2: point emitter: position or direction is not finite"),
        ("<scene>\n<emitter type=\"directional\"><vector name=\"direction\" x=\"0\" y=\"0\" z=\"0\"/></emitter></scene>", "test.xml:2: directional light has no direction"),
        ("<scene>\n<emitter type=\"point\"><rgb name=\"intensity\" value=\"-1\"/></emitter></scene>", "test.xml:2: intensity must be finite and non-negative"),
        ("<scene>\n<emitter type=\"irradiancemeter\"/></scene>", "test.xml:2: emitter type \"irradiancemeter\" is not supported"),
        ("<scene><emitter type=\"spot\">\n<texture type=\"bitmap\" name=\"pattern\"/></emitter></scene>", "test.xml:2: a nested <texture> in a \"spot\" emitter is not supported"),
        ("<scene>\n<emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"95\"/><texture type=\"checkerboard\" name=\"texture\"/></emitter></scene>", "test.xml:2: a textured spot's cutoff_angle must be below 90 degrees"),
        ("<scene>\n<emitter type=\"projector\"><float name=\"scale\" value=\"-1\"/></emitter></scene>", "test.xml:2: projector scale must be finite and non-negative"),
        ("<scene><shape type=\"cube\"><emitter type=\"area\">\n<texture type=\"checkerboard\" name=\"glow\"/></emitter></shape></scene>", "test.xml:2: a nested <texture> in a \"area\" emitter is not supported (only an area light's radiance may be a texture)"),
    ];
    for (text, expected) in cases {
        assert_world_refuses(text, expected);
    }
}

#[test]
fn point_spot_and_directional_lights_take_mitsubas_defaults() {
    let text = r#"<scene><emitter type="point"/><emitter type="spot"/>
        <emitter type="directional"/><emitter type="constant"/></scene>"#;
    let world = ais_render::world::World::from_description(parse(text).unwrap()).unwrap();
    let lights = &world.lights.delta;
    assert_eq!(lights.len(), 3);
    let Some(arrival) = lights[0].arrival(DVec3::new(0.0, 2.0, 0.0).as_vec3()) else {
        panic!("a point light reaches every point");
    };
    assert!((arrival.light - glam::Vec3::splat(0.25)).length() < 1e-6);
    // The spot looks down +z with a 20° cutoff: on axis it sends all, at 30° nothing.
    let on_axis = lights[1].arrival(glam::Vec3::new(0.0, 0.0, 1.0)).unwrap();
    assert!((on_axis.light - glam::Vec3::ONE).length() < 1e-6);
    let tilt = 30f32.to_radians();
    assert!(lights[1]
        .arrival(glam::Vec3::new(tilt.sin(), 0.0, tilt.cos()))
        .is_none());
    // The directional light travels along +z.
    let sun = lights[2].arrival(glam::Vec3::ZERO).unwrap();
    assert!((sun.direction + glam::Vec3::Z).length() < 1e-6);
    assert_eq!(sun.distance, f32::INFINITY);
}

#[test]
fn any_mitsuba_integrator_renders_as_the_gather_with_a_warning() {
    let cases: &[(&str, &[&str], bool)] = &[
        (
            r#"<scene><integrator type="volpath"><integer name="max_depth" value="8"/></integrator></scene>"#,
            &[
                "integrator \"volpath\" rendered with ais's gather (MIS): direct light only",
                "\"max_depth\" of integrator \"volpath\" is ignored",
            ],
            false,
        ),
        (
            r#"<scene><integrator type="aov"><string name="aovs" value="nn:sh_normal"/>
                <integrator type="path"><boolean name="hide_emitters" value="true"/></integrator>
            </integrator></scene>"#,
            &[
                "integrator \"aov\" is unwrapped: its inner \"path\" renders",
                "integrator \"path\" rendered with ais's gather",
            ],
            true,
        ),
    ];
    for (text, expected, hidden) in cases {
        let world = ais_render::world::World::from_description(parse(text).unwrap()).unwrap();
        let mut warnings = Vec::new();
        let settings =
            ais_render::request::gather_settings(&world, &[], str::to_string, &mut warnings)
                .unwrap();
        assert_eq!(settings.hide_emitters, *hidden, "{text}");
        for want in *expected {
            assert!(
                warnings.iter().any(|w| w.contains(want)),
                "{want} missing from {warnings:?}"
            );
        }
    }
}

#[test]
fn gather_parameters_that_cannot_apply_are_warned_of() {
    use ais_render::request::{gather_settings, ParameterOverride};
    let text = "<scene><integrator type=\"gather\">\n<string name=\"ais\" value=\"off\"/>\n\
                <integer name=\"field_res\" value=\"8\"/>\n<integer name=\"rays\" value=\"16\"/>\n\
                </integrator></scene>";
    let world = ais_render::world::World::from_description(parse(text).unwrap()).unwrap();
    let warned = |overrides: &[(&'static str, &str)]| {
        let overrides: Vec<ParameterOverride> = overrides
            .iter()
            .map(|&(name, value)| ParameterOverride {
                name,
                value: value.to_string(),
            })
            .collect();
        let mut warnings = Vec::new();
        gather_settings(&world, &overrides, |n| format!("--{n}"), &mut warnings).unwrap();
        warnings
    };
    let scene_only = warned(&[]);
    assert_eq!(
        scene_only,
        ["/scenes/test.xml:3: \"field_res\" is ignored: it applies only to the visibility field \
          (map field: ais auto)"],
    );
    let flags = warned(&[
        ("field_race", "false"),
        ("acceptance", "sqrt"),
        ("sharing", "pass"),
        ("guide_fraction", "0.5"),
        ("map_res", "8"),
        ("placement", "random"),
    ]);
    for flag in [
        "--field_race",
        "--acceptance",
        "--sharing",
        "--guide_fraction",
        "--map_res",
    ] {
        assert!(
            flags
                .iter()
                .any(|w| w.starts_with(&format!("{flag} is ignored"))),
            "{flag} missing from {flags:?}"
        );
    }
    assert!(!flags.iter().any(|w| w.contains("placement")), "{flags:?}");
    // Under the field, its own parameters apply; a cost ratio needs roulette's 64 rays.
    let field = warned(&[
        ("ais", "auto"),
        ("field_race", "false"),
        ("cost_ratio", "1"),
    ]);
    assert_eq!(field.len(), 1, "{field:?}");
    assert!(field[0].starts_with("--cost_ratio is ignored: the field rolls only"));
    assert!(warned(&[("ais", "auto"), ("rays", "64"), ("cost_ratio", "1")]).is_empty());
    // MIS's share splits MIS's candidates only (the scene's own warning stays).
    assert_eq!(warned(&[("mis_share", "0.25")]), scene_only);
    let bsdf = warned(&[("strategy", "bsdf"), ("mis_share", "0.25")]);
    assert_eq!(bsdf.len(), 2, "{bsdf:?}");
    assert!(
        bsdf.iter()
            .any(|w| w.starts_with("--mis_share is ignored: it splits the candidates of MIS")),
        "{bsdf:?}"
    );
}

#[test]
fn mis_share_is_a_share_or_auto() {
    use ais_render::integrators::gather::GatherSettings;
    let mut settings = GatherSettings::default();
    settings.set("mis_share", "0.25").unwrap();
    assert_eq!(settings.mis_share, Some(0.25));
    assert!(settings.validate().is_ok());
    settings.set("mis_share", "auto").unwrap();
    assert_eq!(settings.mis_share, None);
    for refused in ["0", "0.99", "nan"] {
        settings.set("mis_share", refused).unwrap();
        let error = settings.validate().unwrap_err();
        assert!(
            error.contains("mis_share must lie in [0.05, 0.95]"),
            "{error}"
        );
    }
    assert!(settings.set("mis_share", "half").is_err());
}

#[test]
fn texture_errors_name_file_line_and_problem() {
    let shape = |bsdf: &str| {
        format!("<scene>{bsdf}<shape type=\"rectangle\"><ref id=\"b\"/></shape></scene>")
    };
    let cases: Vec<(String, &str)> = vec![
        (
            shape("<bsdf type=\"diffuse\" id=\"b\">\n<texture type=\"noise\" name=\"reflectance\"/></bsdf>"),
            "test.xml:2: texture type \"noise\" is not supported (checkerboard, bitmap, rawconstant, mesh_attribute)",
        ),
        (
            shape("<bsdf type=\"diffuse\" id=\"b\">\n<texture type=\"bitmap\" name=\"reflectance\"/></bsdf>"),
            "test.xml:2: bitmap needs a \"filename\"",
        ),
        (
            shape("<bsdf type=\"diffuse\" id=\"b\">\n<texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.png\"/><string name=\"wrap_mode\" value=\"spiral\"/></texture></bsdf>"),
            "test.xml:2: unknown wrap_mode \"spiral\"",
        ),
        (
            shape("<bsdf type=\"diffuse\" id=\"b\">\n<ref name=\"reflectance\" id=\"missing\"/></bsdf>"),
            "test.xml:2: no <texture> with id \"missing\"",
        ),
        (
            shape("<bsdf type=\"diffuse\" id=\"b\"><texture type=\"checkerboard\" name=\"reflectance\">\n<texture type=\"checkerboard\" name=\"color0\"/></texture></bsdf>"),
            "test.xml:2: a texture inside a texture (\"color0\") is not supported",
        ),
        (
            shape("<bsdf type=\"diffuse\" id=\"b\"><texture type=\"bitmap\" name=\"reflectance\">\n<string name=\"filename\" value=\"nowhere.png\"/></texture></bsdf>"),
            "nowhere.png",
        ),
    ];
    for (text, expected) in &cases {
        assert_world_refuses(text, expected);
    }
}

#[test]
fn textures_reach_their_parameters_and_warn_where_they_do_not() {
    let text = r#"<scene>
        <texture type="checkerboard" id="checks"><rgb name="color0" value="0.9"/></texture>
        <bsdf type="diffuse" id="d"><ref name="reflectance" id="checks"/></bsdf>
        <bsdf type="roughconductor" id="c">
            <texture type="checkerboard" name="eta"/>
            <texture type="checkerboard" name="alpha"/></bsdf>
        <bsdf type="roughplastic" id="p"><texture type="checkerboard" name="alpha"/></bsdf>
        <shape type="rectangle"><ref id="d"/></shape>
        <shape type="rectangle"><ref id="c"/></shape>
        <shape type="sphere"><transform name="to_world"><rotate x="1" angle="30"/></transform><ref id="d"/></shape>
        <shape type="rectangle"><ref id="p"/></shape>
    </scene>"#;
    let world = ais_render::world::World::from_description(parse(text).unwrap()).unwrap();
    let albedo = |shape: usize| match world.surfaces[shape].as_ref() {
        ais_render::bsdf::Surface::Material { textures, .. } => (textures.iter())
            .find(|t| t.parameter == ais_render::bsdf::TexturedParameter::Albedo)
            .map(|t| t.texture.clone()),
        other => panic!("{other:?}"),
    };
    let board = albedo(0).expect("the diffuse is textured");
    assert_eq!(
        board.eval(glam::Vec2::new(0.1, 0.1)),
        glam::Vec3::splat(0.9)
    );
    assert!(albedo(1).is_none());
    let ais_render::bsdf::Surface::Material { textures, .. } = world.surfaces[1].as_ref() else {
        panic!("{:?}", world.surfaces[1]);
    };
    let parameters: Vec<_> = textures.iter().map(|t| t.parameter).collect();
    use ais_render::bsdf::TexturedParameter::{ConductorEta, Roughness};
    assert_eq!(parameters, [ConductorEta, Roughness]);
    let warned = |want: &str| world.warnings.iter().any(|w| w.contains(want));
    assert!(
        warned("textures are not supported: alpha \"roughplastic\""),
        "{:?}",
        world.warnings
    );
    // A rotated sphere's texture coordinates follow its rotation, as Mitsuba's do.
    assert!(!warned("rotation"), "{:?}", world.warnings);
}

#[test]
fn include_reads_other_files_with_their_defaults_and_refuses_cycles() {
    let folder = std::env::temp_dir().join(format!("ais-include-{}", std::process::id()));
    std::fs::create_dir_all(folder.join("parts")).unwrap();
    let write = |name: &str, text: &str| std::fs::write(folder.join(name), text).unwrap();
    // parts/room.xml includes parts/preamble.xml by a name relative to the top file's folder,
    // as Mitsuba's scenes do, and uses the default that file sets.
    write(
        "parts/preamble.xml",
        r#"<scene version="3.0.0"><default name="size" value="2"/></scene>"#,
    );
    write(
        "parts/room.xml",
        r#"<scene version="3.0.0"><include filename="parts/preamble.xml"/>
        <shape type="sphere"><float name="radius" value="$size"/></shape></scene>"#,
    );
    write(
        "main.xml",
        "<scene version=\"3.0.0\">\n<include filename=\"parts/room.xml\"/>\n<shape type=\"cube\"/></scene>",
    );
    let scene = ais_render::scene::load_scene(&folder.join("main.xml"), &[]).unwrap();
    assert_eq!(scene.shapes.len(), 2);
    match scene.shapes[0].geometry {
        ShapeGeometry::Sphere { radius, .. } => assert_eq!(radius, 2.0),
        ref other => panic!("{other:?}"),
    }
    // Later messages about included elements point at the <include>.
    assert_eq!(scene.shapes[0].line, 2);
    write(
        "parts/a.xml",
        r#"<scene version="3.0.0"><include filename="b.xml"/></scene>"#,
    );
    write(
        "parts/b.xml",
        r#"<scene version="3.0.0"><include filename="a.xml"/></scene>"#,
    );
    write(
        "cycle.xml",
        r#"<scene version="3.0.0"><include filename="parts/a.xml"/></scene>"#,
    );
    let e = ais_render::scene::load_scene(&folder.join("cycle.xml"), &[]).unwrap_err();
    assert!(
        e.to_string()
            .contains("include one another more than 16 deep"),
        "{e}"
    );
    write(
        "parts/broken.xml",
        "<scene version=\"3.0.0\">\n<shape type=\"teapot\"/></scene>",
    );
    write(
        "uses_broken.xml",
        r#"<scene version="3.0.0"><include filename="parts/broken.xml"/></scene>"#,
    );
    let e = ais_render::scene::load_scene(&folder.join("uses_broken.xml"), &[]).unwrap_err();
    assert!(
        e.to_string()
            .contains("shape type \"teapot\" is not supported"),
        "{e}"
    );
    std::fs::remove_dir_all(&folder).unwrap();
}

#[test]
fn a_sensor_may_reference_a_scene_level_sampler_and_film() {
    let text = r#"<scene>
        <sampler type="independent" id="s"><integer name="sample_count" value="25"/></sampler>
        <film type="hdrfilm" id="f"><integer name="width" value="40"/><integer name="height" value="30"/></film>
        <sensor type="perspective"><ref id="s"/><ref id="f"/></sensor></scene>"#;
    let scene = parse(text).unwrap();
    assert_eq!(scene.sample_count, 25);
    assert_eq!(scene.resolution, (40, 30));
    let message =
        error("<scene><sensor type=\"perspective\">\n<ref id=\"nothing\"/></sensor></scene>");
    assert!(
        message.contains("test.xml:2: no <film> or <sampler> with id \"nothing\""),
        "{message}"
    );
}

#[test]
fn shapes_may_reference_an_area_emitter_declared_at_scene_level() {
    // Mitsuba's own Cornell box declares its lamp after the shapes that reference it.
    let scene = parse(
        "<scene>
         <bsdf type=\"diffuse\" id=\"white\"/>
         <shape type=\"rectangle\"><ref id=\"white\"/><ref id=\"lamp\"/></shape>
         <shape type=\"cube\"><ref id=\"white\"/></shape>
         <emitter type=\"area\" id=\"lamp\"><rgb name=\"radiance\" value=\"4\"/></emitter>
         </scene>",
    )
    .unwrap();
    let lamp = scene.shapes[0]
        .emitter
        .as_ref()
        .expect("the lamp is attached");
    assert_eq!(lamp.id.as_deref(), Some("lamp"));
    assert_eq!(scene.shapes[0].bsdf, Some(0));
    assert!(scene.shapes[1].emitter.is_none());
    assert!(
        scene.emitters.is_empty(),
        "an area emitter is not a scene-level light"
    );
    let twice = error(
        "<scene><emitter type=\"area\" id=\"lamp\"/>
         <shape type=\"cube\"><ref id=\"lamp\"/>\n<emitter type=\"area\"/></shape></scene>",
    );
    assert!(
        twice.contains("test.xml:3: a shape can have only one area emitter"),
        "{twice}"
    );
}

#[test]
fn a_spectrum_file_that_is_no_file_is_refused_before_it_is_read() {
    let folder = common::scratch("spectrum-device");
    let scene = folder.join("scene.xml");
    std::fs::create_dir_all(folder.join("folder.spd")).unwrap();
    let text = "<scene><emitter type=\"constant\">\n<spectrum name=\"radiance\" filename=\"folder.spd\"/></emitter></scene>";
    let error = parse_scene(&scene, text, &[]).expect_err("a folder is no spectrum");
    assert!(error.to_string().contains("not a regular file"), "{error}");
}

#[test]
fn masks_blends_and_null_are_read_and_checked() {
    let shape = |bsdf: &str| {
        format!("<scene version=\"3.0.0\">\n<shape type=\"rectangle\">\n{bsdf}\n</shape></scene>")
    };
    assert_world_refuses(
        &shape(
            r#"<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/></bsdf>"#,
        ),
        "test.xml:3: a \"blendbsdf\" holds two BSDFs, not 1",
    );
    assert_world_refuses(
        &shape(r#"<bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf>"#),
        "test.xml:3: a \"blendbsdf\" needs its \"weight\"",
    );
    assert_world_refuses(
        &shape(r#"<bsdf type="mask"><ref id="nowhere"/></bsdf>"#),
        "test.xml:3: no <bsdf> with id \"nowhere\"",
    );
    assert_world_refuses(
        &shape(
            r#"<bsdf type="bumpmap"><float name="scale" value="nan"/><texture type="checkerboard"/><bsdf type="diffuse"/></bsdf>"#,
        ),
        "test.xml:3: a bumpmap's scale must be finite, not NaN",
    );
    assert_world_refuses(
        &shape(
            r#"<bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance"><string name="name" value="vertex_color"/><float name="scale" value="inf"/></texture></bsdf>"#,
        ),
        "test.xml:3: a mesh_attribute's scale must be finite, not inf",
    );
    let text = shape(
        r#"<bsdf type="mask"><float name="opacity" value="1.5"/><float name="alpha" value="1"/>
           <bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>"#,
    );
    let world = ais_render::world::World::from_description(parse(&text).unwrap()).unwrap();
    let warned = |want: &str| world.warnings.iter().any(|w| w.contains(want));
    assert!(warned("test.xml:3: \"opacity\" = 1.5 is outside [0, 1]"));
    assert!(warned(
        "test.xml:3: property \"alpha\" of bsdf \"mask\" is ignored"
    ));
    match world.surfaces[0].as_ref() {
        ais_render::bsdf::Surface::Mask { inner, .. } => assert!(matches!(
            inner.as_ref(),
            ais_render::bsdf::Surface::Material { material, .. } if material.two_sided
        )),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_raw_constant_texture_is_its_value() {
    let text = r#"<scene version="3.0.0"><shape type="rectangle">
        <bsdf type="blendbsdf">
            <texture type="rawconstant" name="weight"><vector name="value" value="0.2, 0.4, 0.6"/></texture>
            <bsdf type="diffuse"/><bsdf type="diffuse"/>
        </bsdf></shape></scene>"#;
    let world = ais_render::world::World::from_description(parse(text).unwrap()).unwrap();
    let ais_render::bsdf::Surface::Blend { weight, .. } = world.surfaces[0].as_ref() else {
        panic!("{:?}", world.surfaces[0]);
    };
    let luminance = 0.2 * 0.212_671 + 0.4 * 0.715_160 + 0.6 * 0.072_169;
    let lookup = ais_render::texture::TextureLookup {
        uv: glam::Vec2::new(0.3, 0.7),
        attributes: None,
    };
    assert!((weight.at(&lookup) - luminance).abs() < 1e-6);
    assert_world_refuses(
        r#"<scene version="3.0.0"><shape type="rectangle"><bsdf type="mask">
           <texture type="rawconstant" name="opacity"><string name="value" value="x"/></texture>
           <bsdf type="diffuse"/></bsdf></shape></scene>"#,
        "test.xml:2: \"value\" of a rawconstant must be a float, vector or rgb, not a string",
    );
}

#[test]
fn a_missing_mesh_attribute_is_refused_with_those_there() {
    let folder = common::shipped_scenes().expect("the scenes' assets");
    let text = r#"<scene version="3.0.0">
        <shape type="ply"><string name="filename" value="../assets/attributes.ply"/>
            <bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance">
                <string name="name" value="vertex_colour"/></texture></bsdf></shape></scene>"#;
    let file = folder.join("crosscheck").join("attributes-test.xml");
    let description = parse_scene(&file, text, &[]).unwrap();
    let Err(e) = ais_render::world::World::from_description(description) else {
        panic!("a missing attribute must be refused");
    };
    let message = e.to_string();
    assert!(
        message.contains("attributes-test.xml:2: the shape has no mesh attribute \"vertex_colour\" (it has: vertex_color, face_weight)"),
        "{message}"
    );
}

#[test]
fn instances_place_their_group_under_their_transform() {
    let text = r#"<scene version="3.0.0">
        <shape type="shapegroup" id="g">
            <shape type="cube"><transform name="to_world"><translate x="1"/></transform></shape>
            <shape type="sphere"/>
        </shape>
        <shape type="instance"><ref id="g"/><transform name="to_world"><scale value="2"/></transform></shape>
        <shape type="instance"><ref id="g"/></shape></scene>"#;
    let scene = parse(text).unwrap();
    assert!(scene.shapes.is_empty(), "the group itself renders nothing");
    assert_eq!(scene.shape_groups.len(), 1);
    assert_eq!(scene.shape_groups[0].shapes.len(), 2);
    assert_eq!(scene.instances.len(), 2);
    assert_eq!(scene.instances[0].group, 0);
    let moved = scene.instances[0].to_world.transform_point3(DVec3::X);
    assert_eq!(moved, DVec3::new(2.0, 0.0, 0.0));
    let world = ais_render::world::World::from_description(scene).unwrap();
    assert_eq!(world.geometry.instance_count(), 2);
    assert_eq!(
        world.geometry.triangle_count(),
        12,
        "the cube is stored once"
    );
    assert_eq!(
        world.surfaces.len(),
        2,
        "one surface per shape of the group"
    );
    let singular = r#"<scene version="3.0.0">
        <shape type="shapegroup" id="g"><shape type="sphere"/></shape>
        <shape type="instance"><ref id="g"/><transform name="to_world"><scale x="0"/></transform></shape></scene>"#;
    let error = parse(singular).unwrap_err().to_string();
    assert!(
        error.contains(":3:") && error.contains("singular"),
        "{error}"
    );
}
