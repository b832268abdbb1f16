//! Hostile and absurd input: each case ends in a clear error naming what is wrong (or, where
//! the input is legal, a finished render), never a panic, an abort or a hang.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("hostile-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn ais(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ais"))
        .args(args)
        .output()
        .expect("ais runs")
}

/// Runs `ais args` and checks that it fails with a message containing `expected`.
fn refused(args: &[&str], expected: &str) {
    let output = ais(args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(
        stderr.contains(expected),
        "{args:?}: expected {expected:?} in {stderr}"
    );
}

/// A scene with a constant sky, a camera and `body`.
fn scene(dir: &Path, body: &str) -> String {
    let text = format!(
        r#"<scene version="3.0.0"><sensor type="perspective"><transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film></sensor><emitter type="constant"><rgb name="radiance" value="1"/></emitter>{body}</scene>"#
    );
    let path = dir.join("scene.xml");
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn huge_coordinates_are_refused_before_the_bvh() {
    let dir = scratch("huge");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    let rectangle = scene(
        &dir,
        r#"<shape type="rectangle"><transform name="to_world"><scale value="1e20"/></transform></shape>"#,
    );
    refused(&["render", &rectangle, "-o", out], "beyond ±1e12");
    let sphere = scene(
        &dir,
        r#"<shape type="sphere"><float name="radius" value="1e20"/></shape>"#,
    );
    refused(&["render", &sphere, "-o", out], "beyond ±1e12");
    std::fs::write(
        dir.join("far.obj"),
        "v 0 0 0\nv 1e20 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let obj = scene(
        &dir,
        r#"<shape type="obj"><string name="filename" value="far.obj"/></shape>"#,
    );
    refused(&["render", &obj, "-o", out], "beyond ±1e12");
}

#[test]
fn absurd_sizes_are_refused_before_work_starts() {
    let dir = scratch("sizes");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    refused(
        &[
            "render",
            "--map-res",
            "46341",
            "--ais",
            "aggressive",
            "-o",
            out,
        ],
        "map_res must lie in",
    );
    refused(&["render", "--rays", "4294967295", "-o", out], "rays");
    refused(&["render", "--threads", "10000", "-o", out], "per core");
    refused(&["render", "--resolution", "65536x65536", "-o", out], "GiB");
    let rays = scene(
        &dir,
        r#"<integrator type="gather"><integer name="rays" value="99999999999"/></integrator><shape type="sphere"/>"#,
    );
    refused(&["render", &rays, "-o", out], "scene.xml:1:");
}

#[test]
fn deep_nesting_and_endless_files_are_refused() {
    let dir = scratch("deep");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    let depth = 10_000;
    let nested = format!(
        r#"<shape type="sphere">{}<bsdf type="diffuse"/>{}</shape>"#,
        r#"<bsdf type="twosided">"#.repeat(depth),
        "</bsdf>".repeat(depth)
    );
    refused(
        &["render", &scene(&dir, &nested), "-o", out],
        "nested more than",
    );
    if Path::new("/dev/zero").exists() {
        let endless = scene(
            &dir,
            r#"<shape type="obj"><string name="filename" value="/dev/zero"/></shape>"#,
        );
        refused(&["render", &endless, "-o", out], "not a regular file");
        refused(&["render", "/dev/zero", "-o", out], "not a regular file");
    }
}

#[test]
fn smooth_microfacets_render_and_bad_roughness_warns() {
    let dir = scratch("alpha");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    for (alpha, warns) in [("1e-4", false), ("0", false), ("nan", true), ("-0.3", true)] {
        for bsdf in ["roughplastic", "roughconductor"] {
            let body = format!(
                r#"<shape type="sphere"><bsdf type="{bsdf}"><string name="distribution" value="ggx"/><float name="alpha" value="{alpha}"/></bsdf></shape>"#
            );
            let output = ais(&["render", &scene(&dir, &body), "-o", out, "--quiet"]);
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert!(output.status.success(), "{bsdf} alpha {alpha}: {stderr}");
            assert_eq!(
                stderr.contains("alpha"),
                warns,
                "{bsdf} alpha {alpha}: {stderr}"
            );
        }
    }
}

#[test]
fn outputs_are_checked_first_and_written_as_a_unit() {
    let dir = scratch("outputs");
    let out = dir.join("a.exr");
    let out = out.to_str().unwrap();
    fn with<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        let small = ["render", "--resolution", "16x9", "--spp", "1", "--quiet"];
        [&small[..], extra].concat()
    }
    refused(
        &with(&["-o", out, "--aov-traced", out]),
        "would overwrite the image",
    );
    refused(
        &with(&["-o", out, "--aov-traced", "x.txt"]),
        "must be an .exr",
    );
    let missing = dir.join("no/such/folder/a.exr");
    refused(&with(&["-o", missing.to_str().unwrap()]), "does not exist");
    let folder = dir.join("folder.exr");
    std::fs::create_dir_all(&folder).unwrap();
    refused(&with(&["-o", folder.to_str().unwrap()]), "is a folder");
    // The same render writes the same bytes, at any thread count.
    let bytes = |threads: &str| {
        let output = ais(&with(&["-o", out, "--threads", threads]));
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        std::fs::read(out).unwrap()
    };
    assert_eq!(bytes("1"), bytes("2"), "EXR bytes differ between runs");
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

#[test]
fn bsdf_references_resolve_and_bad_ones_are_errors() {
    let dir = scratch("references");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    let green = scene(
        &dir,
        r#"<bsdf type="diffuse" id="green"><rgb name="reflectance" value="0,0.5,0"/></bsdf><shape type="sphere"><bsdf type="twosided"><ref id="green"/></bsdf></shape>"#,
    );
    let output = ais(&["render", &green, "-o", out, "--quiet", "--strict"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let missing = scene(
        &dir,
        r#"<shape type="sphere"><bsdf type="twosided"><ref id="nosuch"/></bsdf></shape>"#,
    );
    refused(
        &["render", &missing, "-o", out],
        r#"no <bsdf> with id "nosuch""#,
    );
    let cycle = scene(
        &dir,
        r#"<bsdf type="twosided" id="loop"><ref id="loop"/></bsdf><shape type="sphere"><ref id="loop"/></shape>"#,
    );
    refused(&["render", &cycle, "-o", out], "a cycle of references");
    let twice = scene(
        &dir,
        r#"<shape type="sphere" id="x"/><shape type="sphere" id="x"/>"#,
    );
    refused(&["render", &twice, "-o", out], r#"id "x" is already used"#);
}

#[test]
fn every_unread_input_is_named_and_strict_refuses_it() {
    let dir = scratch("unread");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    let text = r#"<scene version="3.0.0"><default name="a" value="1"/><default name="a" value="2"/>
<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><string name="component_format" value="float16"/></film>
<sampler type="independent"><integer name="sample_cont" value="8"/></sampler></sensor>
<emitter type="constant" foo="bar"><float name="scael" value="2"/></emitter>
<shape type="sphere"><bsdf type="diffuse"><rgb name="reflectanse" value="0.3"/></bsdf></shape>
<shape type="sphere"><point name="center" x="3" y="0" z="0"/><bsdf type="roughplastic"><float name="alpah" value="0.3"/><texture type="checkerboard" name="alpha"/></bsdf></shape></scene>"#;
    let path = dir.join("scene.xml");
    std::fs::write(&path, text).unwrap();
    let path = path.to_str().unwrap();
    let output = ais(&["render", path, "-D", "nosuch=3", "-o", out, "--quiet"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    for expected in [
        r#"scene.xml:1: a second <default> of "a" is ignored"#,
        r#"scene.xml:3: component_format "float16""#,
        r#"scene.xml:4: property "sample_cont" of sampler"#,
        r#"scene.xml:5: attribute "foo" of <emitter>"#,
        r#"scene.xml:5: property "scael" of emitter"#,
        r#"scene.xml:6: property "reflectanse" of bsdf"#,
        "scene.xml:7: textures are not supported: alpha",
        r#"scene.xml:7: property "alpah" of bsdf"#,
        "-D nosuch=3 is not used",
    ] {
        assert!(
            stderr.contains(expected),
            "{expected:?} missing from {stderr}"
        );
    }
    refused(
        &["render", path, "-o", out, "--strict"],
        "--strict makes them errors",
    );
    // Mitsuba's default radiance of a constant emitter is 1.
    let bare = scene(&dir, r#"<shape type="sphere"/>"#);
    let text = std::fs::read_to_string(&bare).unwrap();
    std::fs::write(
        &bare,
        text.replace(r#"<rgb name="radiance" value="1"/>"#, ""),
    )
    .unwrap();
    let output = ais(&["render", &bare, "-o", out, "--quiet", "--strict"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn concurrent_renders_to_one_output_leave_one_render_s_files() {
    let dir = scratch("concurrent");
    let render = |seed: &str, out: &Path| {
        Command::new(env!("CARGO_BIN_EXE_ais"))
            .args(["render", "--resolution", "24x14", "--spp", "1", "--quiet"])
            .args(["--seed", seed, "-o"])
            .arg(out)
            .spawn()
            .expect("ais runs")
    };
    for (seed, name) in [("1", "one.exr"), ("2", "two.exr")] {
        assert!(render(seed, &dir.join(name)).wait().unwrap().success());
    }
    let shared = dir.join("shared.exr");
    for _ in 0..6 {
        let (mut a, mut b) = (render("1", &shared), render("2", &shared));
        assert!(a.wait().unwrap().success() && b.wait().unwrap().success());
        let same = |x: &str, y: &str| {
            std::fs::read(dir.join(x)).unwrap() == std::fs::read(dir.join(y)).unwrap()
        };
        assert_eq!(
            same("shared.exr", "one.exr"),
            same("shared.png", "one.png"),
            "the EXR and the PNG come from different renders"
        );
    }
}

#[test]
fn compare_with_one_seed_or_a_black_scene_still_reports() {
    let dir = scratch("compare");
    let black = scene(&dir, r#"<shape type="sphere"/>"#);
    let text = std::fs::read_to_string(&black).unwrap();
    let without_light = text.replace(
        r#"<emitter type="constant"><rgb name="radiance" value="1"/></emitter>"#,
        "",
    );
    std::fs::write(&black, without_light).unwrap();
    let report = dir.join("report");
    let report = report.to_str().unwrap();
    let tiny = [
        "--time-budget",
        "0.05",
        "--reference-spp",
        "4",
        "--quiet",
        "-o",
        report,
    ];
    for (scene, seeds) in [(black.as_str(), "2"), (black.as_str(), "1")] {
        let output = ais(&[&["compare", scene, "--seeds", seeds][..], &tiny[..]].concat());
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(!stdout.contains("NaN"), "{stdout}");
    }
    let sky = dir.join("sky.hdr");
    let hdr = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets/sky.hdr");
    if hdr.exists() {
        std::fs::copy(&hdr, &sky).unwrap();
        let scaled = scene(&dir, r#"<shape type="sphere"/>"#);
        let text = std::fs::read_to_string(&scaled).unwrap().replace(
            r#"<emitter type="constant"><rgb name="radiance" value="1"/></emitter>"#,
            r#"<emitter type="envmap"><string name="filename" value="sky.hdr"/><float name="scale" value="1e37"/></emitter>"#,
        );
        std::fs::write(&scaled, text).unwrap();
        let out = dir.join("out.exr");
        refused(
            &["render", &scaled, "-o", out.to_str().unwrap()],
            "makes texels exceed",
        );
    }
}

#[test]
fn gather_settings_and_property_values_are_checked() {
    let dir = scratch("settings");
    let out = dir.join("out.exr");
    let out = out.to_str().unwrap();
    let typo = scene(
        &dir,
        r#"<integrator type="gather"><integer name="rayz" value="8"/></integrator><shape type="sphere"/>"#,
    );
    refused(
        &["render", &typo, "-o", out],
        r#"unknown gather parameter "rayz""#,
    );
    refused(
        &[
            "render",
            "--ais",
            "shared",
            "--sharing",
            "pass:0",
            "-o",
            out,
        ],
        "S in 1..=16",
    );
    let ior = scene(
        &dir,
        r#"<shape type="sphere"><bsdf type="roughplastic"><float name="int_ior" value="-1.5"/></bsdf></shape>"#,
    );
    let output = ais(&["render", &ior, "-o", out, "--quiet"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(
        stderr.contains(r#""int_ior" = -1.5 must be positive"#),
        "{stderr}"
    );
    assert!(!stderr.contains("Float("), "{stderr}");
}
