//! The talk's affinity-map figure: one gather point's map after 0, 32 and 128 traced rays.

use ais::{Batch, BatchConfig, Learning, Stopping};
use ais_render::integrators::gather::guiding::CandidateSampler;
use ais_render::integrators::gather::{
    gather_point, run_batch, BatchProbe, BatchRun, GatherSettings, Lessons, Preset,
};
use ais_render::render::RayCounts;
use ais_render::world::World;

/// Traced-ray counts at which the map is shown.
pub const SNAPSHOTS: [u64; 3] = [0, 32, 128];

/// A map's level-0 affinities, row-major, rows from θ = 0 (the map's +z pole).
#[derive(Clone, Debug)]
pub struct MapSnapshot {
    /// Traced rays so far.
    pub traced: u64,
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Affinity of each texel.
    pub affinities: Vec<f32>,
}

/// The aggressive map, learning continuously as in the talk, at the first hit of the camera
/// ray through the centre of pixel (`x`, `y`), snapshotted after [`SNAPSHOTS`] traced rays.
/// `None` when the ray hits nothing or the scene has no lights.
pub fn snapshots(
    world: &World,
    settings: &GatherSettings,
    (x, y): (u32, u32),
    seed: u64,
) -> Option<Vec<MapSnapshot>> {
    let (width, height) = world.resolution;
    let ray = world.camera.ray(
        (x as f32 + 0.5) / width as f32,
        (y as f32 + 0.5) / height as f32,
    );
    let hit = world.geometry.intersect(&ray)?;
    if world.lights.is_empty() {
        return None;
    }
    let at = gather_point(world, &hit, -ray.direction);
    let settings = GatherSettings {
        rays: *SNAPSHOTS.last().expect("snapshots") as u32,
        ..settings.with_preset(Preset::Aggressive)
    };
    let config = BatchConfig {
        learning: Learning::Continuous,
        stopping: Stopping::DropLast,
        ..settings.batch_config()
    };
    let mut batch = Batch::new(config).ok()?;
    let mut snapshots = Snapshots::default();
    // The empty map, before any ray.
    batch.begin(settings.rays, seed, ais::MapStart::Empty);
    snapshots.taken.push(snapshot(&batch));
    let run = BatchRun {
        world,
        settings: &settings,
        at: &at,
        sampler: &CandidateSampler::plain(settings.strategy),
        seed,
        rays: settings.rays,
        start: ais::MapStart::Empty,
        field: None,
        clock: None,
        blockers: &std::cell::Cell::default(),
        pixel_pool: None,
    };
    run_batch(
        &run,
        &mut batch,
        &mut RayCounts::default(),
        &mut snapshots,
        Lessons::default(),
    );
    Some(snapshots.taken)
}

/// A map's level-0 affinities now.
fn snapshot(batch: &Batch<[f32; 3]>) -> MapSnapshot {
    let map = batch.map().expect("an aggressive batch has a map");
    let layout = map.level_layout(0);
    MapSnapshot {
        traced: batch.batch_stats().traced,
        width: layout.width(),
        height: layout.height(),
        affinities: (0..layout.texel_count())
            .map(|i| map.texel_affinity(0, layout.texel_of_index(i)))
            .collect(),
    }
}

/// Takes a snapshot whenever the batch has traced one of [`SNAPSHOTS`] rays.
#[derive(Default)]
struct Snapshots {
    taken: Vec<MapSnapshot>,
}

impl BatchProbe for Snapshots {
    fn recorded(&mut self, batch: &Batch<[f32; 3]>, _: [f32; 3], _: f32) {
        let traced = batch.batch_stats().traced;
        if SNAPSHOTS[1..].contains(&traced) && self.taken.iter().all(|s| s.traced != traced) {
            self.taken.push(snapshot(batch));
        }
    }
}

/// An SVG of one snapshot: a `cell`-pixel square per texel, grey from black (affinity at
/// its floor) to white (1).
pub fn snapshot_svg(snapshot: &MapSnapshot, cell: u32) -> String {
    let (w, h) = (snapshot.width * cell, snapshot.height * cell);
    let mut svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" class="affinity-map">"#
    );
    for (i, a) in snapshot.affinities.iter().enumerate() {
        let (column, row) = (i as u32 % snapshot.width, i as u32 / snapshot.width);
        let grey = (a.clamp(0.0, 1.0) * 255.0).round() as u8;
        svg.push_str(&format!(
            r##"<rect x="{}" y="{}" width="{cell}" height="{cell}" fill="rgb({grey},{grey},{grey})" stroke="#888" stroke-width="0.5"><title>affinity {a:.3}</title></rect>"##,
            column * cell,
            row * cell
        ));
    }
    svg.push_str("</svg>");
    svg
}
