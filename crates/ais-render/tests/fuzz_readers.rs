//! Fuzzing every reader of user input on the stable toolchain: scene XML (from a grammar of
//! Mitsuba's elements, with hostile values), OBJ (from a grammar of its lines), and PLY,
//! GLB, EXR and HDR (valid files mutated by byte flips, insertions, deletions and
//! truncation). Every input must give a value or an error, never a panic.
//!
//! `cargo test` runs a fixed, seeded set of cases per reader. A longer run, for as long as
//! `AIS_FUZZ_SECONDS` says, each reader in turn:
//!
//! ```sh
//! AIS_FUZZ_SECONDS=600 cargo test --release -p ais-render --test fuzz_readers -- --nocapture --test-threads 1
//! ```
//!
//! A panicking input is written to `target/tmp/fuzz-crash-<reader>-*` before the test
//! fails, to become a regression case.

mod common;
mod serialized_files;

use ais_render::image_io::{read_image, write_exr, RgbImage};
use ais_render::mesh::load_mesh;
use ais_render::scene::{parse_scene, MeshFormat};
use ais_render::world::World;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Cases per reader in `cargo test`.
const CASES: u32 = 160;

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Runs `check` on inputs from `strategy`: a fixed number of seeded cases, or for
/// `AIS_FUZZ_SECONDS` seconds. A panic saves the input and fails the test.
fn fuzz(reader: &str, strategy: impl Strategy<Value = Vec<u8>>, check: impl Fn(&[u8])) {
    let seconds: Option<u64> = std::env::var("AIS_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok());
    let config = Config {
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let deadline = seconds.map(|s| Instant::now() + Duration::from_secs(s));
    let mut cases = 0u64;
    while deadline.map_or(cases < CASES as u64, |d| Instant::now() < d) {
        let input = strategy.new_tree(&mut runner).unwrap().current();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(&input)));
        if outcome.is_err() {
            let saved = scratch(&format!("fuzz-crash-{reader}-{cases}"));
            std::fs::write(&saved, &input).unwrap();
            panic!(
                "{reader}: case {cases} panicked; input saved to {}",
                saved.display()
            );
        }
        cases += 1;
    }
    if seconds.is_some() {
        println!("{reader}: {cases} cases without a panic");
    }
}

/// Mutations of `seed`: byte flips, insertions of random bytes, deletions and a truncation.
fn mutated(seed: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
    let edit = (any::<u16>(), 0u8..4, any::<u8>(), 0usize..16);
    prop::collection::vec(edit, 0..8).prop_map(move |edits| {
        let mut bytes = seed.clone();
        for (at, kind, byte, length) in edits {
            let at = at as usize % (bytes.len() + 1);
            match kind {
                0 if at < bytes.len() => bytes[at] ^= byte.max(1),
                1 => bytes
                    .splice(at..at, std::iter::repeat_n(byte, length))
                    .for_each(drop),
                2 => {
                    let end = (at + length).min(bytes.len());
                    bytes.drain(at..end);
                }
                _ => bytes.truncate(at),
            }
        }
        bytes
    })
}

/// Values a careless or hostile scene might hold.
fn hostile_value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("0".to_string()),
        Just("-1".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("1e40".to_string()),
        Just("99999999999".to_string()),
        Just("".to_string()),
        Just("$undefined".to_string()),
        Just("0.5, 0.5".to_string()),
        Just("ggx".to_string()),
        Just("none".to_string()),
        (-1e6f64..1e6).prop_map(|v| v.to_string()),
    ]
}

/// One element of a Mitsuba scene, nested up to `depth` levels.
fn element(depth: u32) -> BoxedStrategy<String> {
    let property = (
        prop::sample::select(vec![
            "float", "integer", "boolean", "string", "rgb", "point",
        ]),
        prop::sample::select(vec![
            "radius",
            "alpha",
            "reflectance",
            "radiance",
            "width",
            "height",
            "fov",
            "rays",
            "filename",
            "scale",
            "value",
            "distribution",
            "material",
            "int_ior",
        ]),
        hostile_value(),
    )
        .prop_map(|(tag, name, value)| format!(r#"<{tag} name="{name}" value="{value}"/>"#));
    let transform = (hostile_value(), hostile_value()).prop_map(|(a, b)| {
        format!(
            r#"<transform name="to_world"><scale value="{a}"/><translate x="{b}"/></transform>"#
        )
    });
    let leaf = prop_oneof![property, transform, Just(r#"<ref id="a"/>"#.to_string())];
    if depth == 0 {
        return leaf.boxed();
    }
    let plugin = (
        prop::sample::select(vec![
            ("shape", "sphere"),
            ("shape", "rectangle"),
            ("shape", "cube"),
            ("shape", "obj"),
            ("bsdf", "twosided"),
            ("bsdf", "diffuse"),
            ("bsdf", "roughplastic"),
            ("bsdf", "roughconductor"),
            ("emitter", "area"),
            ("emitter", "constant"),
            ("emitter", "envmap"),
            ("sensor", "perspective"),
            ("film", "hdrfilm"),
            ("integrator", "gather"),
            ("texture", "checkerboard"),
        ]),
        prop::option::of(Just("a")),
        prop::collection::vec(element(depth - 1), 0..4),
    )
        .prop_map(|((tag, kind), id, children)| {
            let id = id.map_or(String::new(), |id| format!(r#" id="{id}""#));
            format!(r#"<{tag} type="{kind}"{id}>{}</{tag}>"#, children.concat())
        });
    prop_oneof![leaf, plugin].boxed()
}

/// Whole scenes from the grammar, some truncated.
fn scenes() -> impl Strategy<Value = Vec<u8>> {
    (
        prop::collection::vec(element(3), 0..6),
        any::<u16>(),
        any::<bool>(),
    )
        .prop_map(|(elements, cut, truncate)| {
            let text = format!(r#"<scene version="3.0.0">{}</scene>"#, elements.concat());
            let mut bytes = text.into_bytes();
            if truncate {
                bytes.truncate(cut as usize % (bytes.len() + 1));
            }
            bytes
        })
}

#[test]
fn the_scene_reader_survives_hostile_scenes() {
    let path = scratch("scene.xml");
    fuzz("xml", scenes(), |bytes| {
        let text = String::from_utf8_lossy(bytes);
        if let Ok(description) = parse_scene(&path, &text, &[]) {
            let _ = World::from_description(description);
        }
    });
}

/// OBJ files from a grammar of its lines, with hostile numbers and indices.
fn obj_files() -> impl Strategy<Value = Vec<u8>> {
    let number = prop_oneof![
        (-10.0f64..10.0).prop_map(|v| v.to_string()),
        Just("nan".to_string()),
        Just("1e20".to_string()),
        Just("x".to_string()),
    ];
    let index = prop_oneof![
        (-5i64..8).prop_map(|i| i.to_string()),
        Just("99999999999".into())
    ];
    let line = prop_oneof![
        (number.clone(), number.clone(), number.clone())
            .prop_map(|(x, y, z)| format!("v {x} {y} {z}")),
        (number.clone(), number.clone(), number).prop_map(|(x, y, z)| format!("vn {x} {y} {z}")),
        prop::collection::vec(index, 0..6).prop_map(|i| format!("f {}", i.join(" "))),
        Just("o thing".to_string()),
        Just("mtllib missing.mtl".to_string()),
        "[ -~]{0,12}",
    ];
    prop::collection::vec(line, 0..24).prop_map(|lines| lines.join("\n").into_bytes())
}

#[test]
fn the_obj_reader_survives_hostile_files() {
    let path = scratch("mesh.obj");
    fuzz("obj", obj_files(), |bytes| {
        std::fs::write(&path, bytes).unwrap();
        let _ = load_mesh(&path, MeshFormat::Obj);
    });
}

/// A binary PLY quad.
fn binary_ply() -> Vec<u8> {
    let mut bytes = common::PLY_HEADER
        .replace("{FORMAT}", "binary_little_endian")
        .into_bytes();
    for c in [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
    ] {
        bytes.extend(c.to_le_bytes());
    }
    bytes.push(4);
    for i in [0i32, 1, 2, 3] {
        bytes.extend(i.to_le_bytes());
    }
    bytes
}

#[test]
fn the_ply_reader_survives_mutated_files() {
    let path = scratch("mesh.ply");
    let ascii =
        common::PLY_HEADER.replace("{FORMAT}", "ascii") + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    let files = prop_oneof![mutated(ascii.into_bytes()), mutated(binary_ply())];
    fuzz("ply", files, |bytes| {
        std::fs::write(&path, bytes).unwrap();
        let _ = load_mesh(&path, MeshFormat::Ply);
    });
}

#[test]
fn the_glb_reader_survives_mutated_files() {
    let path = scratch("mesh.glb");
    fuzz("glb", mutated(common::glb(false)), |bytes| {
        std::fs::write(&path, bytes).unwrap();
        let _ = load_mesh(&path, MeshFormat::Glb);
    });
}

#[test]
fn the_serialized_reader_survives_mutated_files() {
    use serialized_files::{serialized, serialized_body};
    let path = scratch("mesh.serialized");
    let square = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 2.0, 0.0],
        [0.0, 2.0, 0.0],
    ];
    let body = serialized_body(&square, &[[0, 1, 2], [0, 2, 3]], None, false, 4);
    // Mutations of the decompressed stream reach the parser; of the file, the framing.
    let files = prop_oneof![
        mutated(body).prop_map(|body| serialized(&[body], 4)),
        mutated(serialized(
            &[serialized_body(&square, &[[0, 1, 2]], None, true, 3)],
            3
        )),
    ];
    fuzz("serialized", files, |bytes| {
        std::fs::write(&path, bytes).unwrap();
        let _ = load_mesh(&path, MeshFormat::Serialized { shape_index: 0 });
    });
}

/// A small image's bytes as written by `write` to `name`.
fn image_bytes(name: &str, write: impl Fn(&Path)) -> Vec<u8> {
    let path = scratch(name);
    write(&path);
    std::fs::read(path).unwrap()
}

#[test]
fn the_image_readers_survive_mutated_files() {
    let image = RgbImage {
        width: 4,
        height: 2,
        pixels: (0..8).map(|i| [i as f32, 0.5, 2.0]).collect(),
    };
    let exr = image_bytes("seed.exr", |p| write_exr(p, &image).unwrap());
    let hdr = image_bytes("seed.hdr", |p| {
        let pixels: Vec<_> = image.pixels.iter().map(|p| image::Rgb(*p)).collect();
        image::codecs::hdr::HdrEncoder::new(std::fs::File::create(p).unwrap())
            .encode(&pixels, 4, 2)
            .unwrap();
    });
    let (exr_path, hdr_path) = (scratch("image.exr"), scratch("image.hdr"));
    fuzz("exr", mutated(exr), |bytes| {
        std::fs::write(&exr_path, bytes).unwrap();
        let _ = read_image(&exr_path);
    });
    fuzz("hdr", mutated(hdr), |bytes| {
        std::fs::write(&hdr_path, bytes).unwrap();
        let _ = read_image(&hdr_path);
    });
}
