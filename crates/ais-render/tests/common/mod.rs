//! Helpers shared by the renderer's integration tests.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A scratch folder for one test, removed with all it holds when dropped (test runs must
/// not fill the temporary folder: an npm package alone is 33 MB).
pub struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh scratch folder for one test; keep it bound while its files are used.
pub fn scratch(name: &str) -> Scratch {
    // In the build's own temporary folder, so that even a panicking test leaves nothing
    // outside the target folder.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("ais-render-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    Scratch(dir)
}

/// An npm package unpacked in a scratch folder (removed when dropped).
pub struct NpmPackage {
    scratch: Scratch,
}

impl NpmPackage {
    /// The package's folder.
    pub fn folder(&self) -> PathBuf {
        self.scratch.join("package")
    }
}

/// Prints why a test is skipped, where the test harness does not swallow it.
pub fn skip(test: &str, reason: &str) {
    let _ = writeln!(std::io::stderr(), "SKIPPED {test}: {reason}");
}

/// Fetches an npm package tarball (`name@version`) with `npm pack` and unpacks it; returns
/// the unpacked package, or `None` (after printing why) when npm cannot provide it.
pub fn npm_package(test: &str, spec: &str) -> Option<NpmPackage> {
    let dir = scratch(&format!("npm-{}", spec.replace(['/', '@'], "_")));
    let pack = Command::new("npm")
        .args(["pack", spec, "--silent", "--pack-destination"])
        .arg(&*dir)
        .output();
    let tarball = match pack {
        Err(e) => {
            skip(test, &format!("npm could not be run ({e})"));
            return None;
        }
        Ok(out) if !out.status.success() => {
            skip(
                test,
                &format!(
                    "`npm pack {spec}` failed: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            );
            return None;
        }
        Ok(out) => String::from_utf8_lossy(&out.stdout)
            .trim()
            .lines()
            .last()
            .unwrap_or("")
            .to_string(),
    };
    let untar = Command::new("tar")
        .args(["xzf", &tarball])
        .current_dir(&*dir)
        .status()
        .expect("tar runs");
    assert!(untar.success(), "the npm tarball {tarball} must unpack");
    Some(NpmPackage { scratch: dir })
}

/// The repository's `scenes/` folder, with its generated assets made (by
/// `scenes/make_assets.py`) if they are missing; `Err` says why they could not be.
pub fn shipped_scenes() -> Result<PathBuf, String> {
    let folder = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let assets = [
        "sky.hdr",
        "blob.obj",
        "leaves.obj",
        "ball.obj",
        "tiles.png",
        "bumps.png",
        "attributes.ply",
        "quad.obj",
        "shapes.serialized",
    ];
    if assets
        .iter()
        .any(|name| !folder.join("assets").join(name).exists())
    {
        let made = Command::new("python3")
            .arg(folder.join("make_assets.py"))
            .status();
        match made {
            Ok(status) if status.success() => {}
            Ok(status) => panic!("scenes/make_assets.py failed: {status}"),
            Err(e) => return Err(format!("python3 could not be run ({e})")),
        }
    }
    Ok(folder)
}

/// A shipped scene (`scenes/NAME`) at `size` pixels.
pub fn shipped_scene_at(name: &str, size: (u32, u32)) -> World {
    let scenes = shipped_scenes().expect("the shipped scenes' assets");
    let mut world = World::from_description(load_scene(&scenes.join(name), &[]).unwrap()).unwrap();
    world.set_resolution(size);
    world
}

use ais_render::render::{render, RenderSettings, SampleIntegrator};
use ais_render::scene::load_scene;
use ais_render::world::World;

/// A world from a scene text `xml` and side files `(name, text)`, written to a scratch
/// folder `name`.
pub fn scene_world(name: &str, xml: &str, files: &[(&str, &str)]) -> World {
    let dir = scratch(name);
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    World::from_description(load_scene(&path, &[]).unwrap()).unwrap()
}

/// A perspective sensor at `origin` looking at `target` (z up), square film of `size`,
/// box-filtered so that the statistical tests' pixels are independent samples.
pub fn camera(origin: &str, target: &str, fov: f64, size: u32) -> String {
    format!(
        r#"<sensor type="perspective"><float name="fov" value="{fov}"/>
        <transform name="to_world"><lookat origin="{origin}" target="{target}" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="{size}"/><integer name="height" value="{size}"/><rfilter type="box"/></film></sensor>"#
    )
}

/// A white furnace: a diffuse sphere of albedo 0.8 in a constant environment of radiance 1
/// reflects 0.8 wherever it is seen; the camera sees only the sphere.
pub fn furnace() -> World {
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
        <shape type="sphere"><float name="radius" value="1"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf></shape></scene>"#,
        camera("0, -5, 0", "0, 0, 0", 8.0, 8)
    );
    scene_world("furnace", &xml, &[])
}

/// Radiance L = 10, radius r = 0.5, centre 2 above a diffuse floor of albedo 0.5, seen from
/// one pixel: directly below, the outgoing radiance is ρ L (r/d)² = 0.5 · 10 · 0.0625.
pub fn plane_under_a_sphere_light() -> (World, f64) {
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="0" y="0" z="2"/><float name="radius" value="0.5"/>
            <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape></scene>"#,
        camera("3, 0, 1", "0, 0, 0", 0.01, 1)
    );
    (scene_world("sphere-light", &xml, &[]), 0.3125)
}

/// [`plane_under_a_sphere_light`] moved 300 units from the origin, where a ray's offset
/// from its surface is 300 times larger; the exact radiance toward the camera.
pub fn distant_plane_under_a_sphere_light() -> (World, f64) {
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <shape type="rectangle"><transform name="to_world"><scale value="10"/><translate x="300"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="300" y="0" z="2"/><float name="radius" value="0.5"/>
            <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape></scene>"#,
        camera("303, 0, 1", "300, 0, 0", 0.01, 1)
    );
    (scene_world("distant-sphere-light", &xml, &[]), 0.3125)
}

/// A diffuse plane (reflectance 0.5) under a point light straight above (intensity 4 at
/// height 2), a directional light at 60° from the normal (irradiance 2), a spot light aimed
/// away from the plane and a constant sky of 0.2; the exact radiance toward the camera, and
/// the part of it that BSDF sampling can find (the sky's).
pub fn plane_under_delta_lights() -> (World, f64, f64) {
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
        <emitter type="point"><point name="position" x="0" y="0" z="2"/><rgb name="intensity" value="4"/></emitter>
        <emitter type="directional"><vector name="direction" x="-0.8660254" y="0" z="-0.5"/>
            <rgb name="irradiance" value="2"/></emitter>
        <emitter type="spot"><transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 4" up="0, 1, 0"/></transform>
            <rgb name="intensity" value="50"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape></scene>"#,
        camera("3, 0, 1", "0, 0, 0", 0.01, 1)
    );
    let sky = 0.5 * 0.2;
    // Irradiance: I / h² from the point light, E cos 60° from the directional light.
    let (intensity, height, irradiance) = (4.0, 2.0, 2.0);
    let (point, directional) = (intensity / (height * height), irradiance * 0.5);
    let delta = 0.5 / std::f64::consts::PI * (point + directional);
    (scene_world("delta-lights", &xml, &[]), sky + delta, sky)
}

/// A floor with a box on it under a sphere light, a rectangle light and a constant sky.
pub fn occluded_scene() -> World {
    let xml = format!(
        r#"<scene version="3.0.0">{}
        <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform></shape>
        <shape type="cube"><transform name="to_world"><scale x="0.4" y="0.4" z="0.6"/><translate x="0.2" z="0.6"/></transform></shape>
        <shape type="sphere"><point name="center" x="-1" y="0.5" z="1.5"/><float name="radius" value="0.3"/>
            <emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="180"/><translate x="1" y="-0.5" z="1.6"/></transform>
            <emitter type="area"><rgb name="radiance" value="6"/></emitter></shape></scene>"#,
        camera("0, -3, 3", "0, 0, 0.2", 45.0, 6)
    );
    scene_world("occluded", &xml, &[])
}

/// Per-pixel statistics of the red channel over independent renders.
pub struct PixelStatistics {
    /// Mean per pixel.
    pub mean: Vec<f64>,
    /// Standard error of the mean per pixel.
    pub se: Vec<f64>,
    /// Mean work per camera sample (for the gather: traced rays).
    pub traced: f64,
}

impl PixelStatistics {
    /// The image mean and its standard error.
    pub fn image_mean(&self) -> (f64, f64) {
        let n = self.mean.len() as f64;
        let average = self.mean.iter().sum::<f64>() / n;
        let error = self.se.iter().map(|s| s * s).sum::<f64>().sqrt() / n;
        (average, error)
    }
}

/// The first seed of the renders [`pixel_statistics`] makes.
const FIRST_SEED: u64 = 1000;

/// The first seed of the renders [`reference_statistics`] makes: far from [`FIRST_SEED`],
/// so that a reference shares no camera sequence with what it is compared to.
const FIRST_REFERENCE_SEED: u64 = 1_000_000;

/// Per-pixel mean and standard error over `renders` independent renders of `spp` samples.
pub fn pixel_statistics<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    spp: u32,
    renders: u64,
) -> PixelStatistics {
    statistics_from(world, integrator, spp, FIRST_SEED..FIRST_SEED + renders)
}

/// [`pixel_statistics`] of a reference: renders of seeds of their own. (A pixel's camera
/// samples are one stratified sequence per seed; a reference of 64 samples sharing its
/// first 8 with a tested render of 8 errs against it, not independently of it, and z
/// computed as for independent estimates comes out too large.)
pub fn reference_statistics<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    spp: u32,
    renders: u64,
) -> PixelStatistics {
    let seeds = FIRST_REFERENCE_SEED..FIRST_REFERENCE_SEED + renders;
    statistics_from(world, integrator, spp, seeds)
}

/// Per-pixel mean and standard error over the renders of `seeds`.
fn statistics_from<I: SampleIntegrator>(
    world: &World,
    integrator: &I,
    spp: u32,
    seeds: std::ops::Range<u64>,
) -> PixelStatistics {
    let count = world.resolution.0 as usize * world.resolution.1 as usize;
    let (mut sum, mut sum_sq, mut traced) = (vec![0.0; count], vec![0.0; count], 0.0);
    let renders = seeds.end - seeds.start;
    for seed in seeds {
        let settings = RenderSettings {
            samples_per_pixel: spp,
            seed,
            first_sample: 0,
            progress: false,
            crop: None,
        };
        let output = render(world, integrator, &settings);
        for (i, p) in output.image.pixels.iter().enumerate() {
            let v = p[0] as f64;
            sum[i] += v;
            sum_sq[i] += v * v;
        }
        traced += output
            .work_per_sample
            .iter()
            .map(|&t| t as f64)
            .sum::<f64>()
            / count as f64;
    }
    let r = renders as f64;
    let mean: Vec<f64> = sum.iter().map(|s| s / r).collect();
    let se = sum_sq
        .iter()
        .zip(&mean)
        .map(|(s2, m)| ((s2 / r - m * m).max(0.0) * r / (r - 1.0) / r).sqrt())
        .collect();
    PixelStatistics {
        mean,
        se,
        traced: traced / r,
    }
}

/// A pixel's standard error is taken as at least this share of the reference image's
/// mean. A pixel a thousand times darker than the image is lit by rare events: a few of
/// the renders light it, its spread is itself noise, and its z says nothing (with
/// stratified camera samples such pixels reached |z| = 7 unbiased).
const LEAST_ERROR_SHARE: f64 = 1e-3;

/// The largest |z| of one pixel that [`agreement`] accepts. Per-pixel standard errors from
/// tens of renders of a heavy-tailed estimator are themselves noisy: the field's light
/// proposal in the interior reached |z| = 5.5 at 96 renders and 2.5 at 384, unbiased. A
/// biased estimator fails the mean z² first.
const WORST_Z: f64 = 6.0;

/// Whether `statistics` agrees with the converged `reference` pixel by pixel: no |z| above
/// [`WORST_Z`] and a mean z² below 2 (an error message otherwise).
pub fn agreement(statistics: &PixelStatistics, reference: &PixelStatistics) -> Result<(), String> {
    let floor = LEAST_ERROR_SHARE * reference.image_mean().0.abs();
    let z: Vec<f64> = statistics
        .mean
        .iter()
        .zip(&statistics.se)
        .zip(reference.mean.iter().zip(&reference.se))
        .map(|((m, s), (r, rs))| (m - r) / (s * s + rs * rs).sqrt().max(floor).max(1e-9))
        .collect();
    let worst = z.iter().fold(0.0f64, |w, z| w.max(z.abs()));
    let mean_square = z.iter().map(|z| z * z).sum::<f64>() / z.len() as f64;
    if worst < WORST_Z && mean_square < 2.0 {
        Ok(())
    } else {
        Err(format!("worst |z| {worst:.2}, mean z² {mean_square:.2}"))
    }
}

/// The header of a PLY quad (4 vertices, 1 face); `{FORMAT}` names the encoding.
pub const PLY_HEADER: &str = "ply\nformat {FORMAT} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

/// A minimal GLB: one triangle, optionally declaring Draco compression.
pub fn glb(draco: bool) -> Vec<u8> {
    let mut bin = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bin.extend(c.to_le_bytes());
        }
    }
    let extensions = if draco {
        r#""extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],"#
    } else {
        ""
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},{extensions}"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"translation":[0,0,2]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"buffers":[{{"byteLength":36}}],"bufferViews":[{{"buffer":0,"byteLength":36}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}]}}"#
    );
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}
