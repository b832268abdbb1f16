//! The cost of AIS per candidate: map lookup, and the full decide + record step of a batch,
//! with the host's work reduced to reading precomputed directions.
//!
//! Run: `cargo bench -p ais --bench decide_record`

use ais::rng::Pcg32;
use ais::{
    AffinityMap, Batch, BatchConfig, Decision, Learning, LevelRule, MapConfig, MapStart, Mode,
    Placement, Stopping,
};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec3;
use std::hint::black_box;

fn directions(count: usize) -> Vec<Vec3> {
    let mut rng = Pcg32::new(1, 2);
    (0..count)
        .map(|_| {
            let z = rng.next_f32();
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

fn map_configs() -> Vec<(&'static str, MapConfig)> {
    let base = MapConfig::default();
    vec![
        ("single h4", base),
        ("single h16", MapConfig { height: 16, ..base }),
        (
            "literal×3 h16",
            MapConfig {
                height: 16,
                levels: LevelRule::FinestBelowOne { count: 3 },
                ..base
            },
        ),
    ]
}

fn lookup(c: &mut Criterion) {
    let dirs = directions(4096);
    let mut group = c.benchmark_group("lookup");
    group.throughput(Throughput::Elements(dirs.len() as u64));
    for (name, config) in map_configs() {
        let map = AffinityMap::new(config).unwrap();
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut sum = 0.0;
                for &d in &dirs {
                    sum += map.lookup(black_box(d)).affinity;
                }
                sum
            })
        });
    }
    group.finish();
}

/// One batch of n = 256 whose host reads directions from a table; half of the rays are
/// "occluded" (rating 0) by a fixed rule so that the map learns and rejects.
fn run_batch(batch: &mut Batch<f32>, dirs: &[Vec3], seed: u64) -> f32 {
    batch.begin(256, seed, MapStart::Empty);
    let mut k = 0;
    while let Some(candidate) = batch.next_candidate() {
        let d = dirs[(k + candidate.index as usize) % dirs.len()];
        k += 1;
        if let Decision::Trace { .. } = batch.decide(d, true) {
            let visible = d.x > 0.3;
            batch.record(
                if visible { 1.0 } else { 0.0 },
                if visible { 1.0 } else { 0.0 },
            );
        }
    }
    batch.finish().value
}

fn decide_record(c: &mut Criterion) {
    let dirs = directions(4096);
    let mut group = c.benchmark_group("decide+record per candidate");
    let mut configs: Vec<(String, BatchConfig)> = vec![("off".into(), BatchConfig::talk_off())];
    for (name, map) in map_configs() {
        configs.push((
            format!("default schedule, {name}"),
            BatchConfig {
                affinity: Some(map),
                ..BatchConfig::default()
            },
        ));
    }
    configs.push((
        "talk: continuous, Halton, n+1, aggressive h4".into(),
        BatchConfig {
            affinity: Some(MapConfig {
                mode: Mode::Aggressive,
                ..MapConfig::default()
            }),
            learning: Learning::Continuous,
            stopping: Stopping::DropLast,
            ..BatchConfig::default()
        },
    ));
    configs.push((
        "default, random placement".into(),
        BatchConfig {
            placement: Placement::Random,
            ..BatchConfig::default()
        },
    ));
    for (name, config) in configs {
        let mut batch: Batch<f32> = Batch::new(config).unwrap();
        // Measure candidates per batch once, to report time per candidate.
        run_batch(&mut batch, &dirs, 0);
        let per_batch = batch.batch_stats().candidates + batch.batch_stats().dropped;
        group.throughput(Throughput::Elements(per_batch));
        group.bench_with_input(BenchmarkId::from_parameter(&name), &name, |b, _| {
            let mut seed = 0;
            b.iter(|| {
                seed += 1;
                run_batch(&mut batch, &dirs, seed)
            })
        });
    }
    group.finish();
}

fn begin(c: &mut Criterion) {
    let mut batch: Batch<f32> = Batch::new(BatchConfig::default()).unwrap();
    c.bench_function("begin (clear map, rescramble)", |b| {
        let mut seed = 0;
        b.iter(|| {
            seed += 1;
            batch.begin(256, black_box(seed), MapStart::Empty);
        })
    });
}

criterion_group!(benches, lookup, decide_record, begin);
criterion_main!(benches);
