//! The cost of drawing a cell from a [`CdfGrid`] (two guided inversions), on a sky-like
//! grid: whether a draw is slow for its own work or for waiting on its chain of dependent
//! loads. Three loops over the same numbers:
//! - `chained`: each draw's numbers depend on the previous draw's cell, so no two draws
//!   overlap (a renderer's draws, separated by a candidate's other work, come close to it);
//! - `independent`: draws one after another, free to overlap in the core;
//! - `staged`: the rows of a run of 16 draws, then their cells, as a wavefront would.
//!
//! Run: `cargo bench -p ais --bench cdf_grid`

use ais::rng::Pcg32;
use ais::sampling::CdfGrid;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

/// A 256 × 127 grid weighted like a sky with a sun: a smooth gradient over the upper
/// rows, little below the horizon, and a bright disc of a few cells.
fn sky() -> CdfGrid {
    let (columns, rows) = (256usize, 127usize);
    let weights: Vec<f64> = (0..rows * columns)
        .map(|cell| {
            let (row, column) = ((cell / columns) as f64, (cell % columns) as f64);
            let sky = if row < 64.0 { 1.0 + row / 32.0 } else { 0.05 };
            let sun = ((row - 40.0).powi(2) + (column - 100.0).powi(2) < 4.0) as u8 as f64;
            (sky + 5e4 * sun) * (std::f64::consts::PI * (row + 0.5) / rows as f64).sin()
        })
        .collect();
    CdfGrid::new(&weights, columns)
}

fn numbers(count: usize) -> Vec<[f32; 2]> {
    let mut rng = Pcg32::new(7, 3);
    (0..count)
        .map(|_| [rng.next_f32(), rng.next_f32()])
        .collect()
}

fn draws(c: &mut Criterion) {
    let grid = sky();
    let us = numbers(4096);
    let mut group = c.benchmark_group("cdf_grid draw");
    group.throughput(Throughput::Elements(us.len() as u64));
    group.bench_function("chained", |b| {
        b.iter(|| {
            let mut previous = 0usize;
            for u in &us {
                // A zero that the core cannot know before the previous draw is done.
                let shift = (previous & (1 << 40)) as f32;
                previous = grid.sample([u[0] + shift, u[1] + shift]).0;
            }
            previous
        })
    });
    group.bench_function("independent", |b| {
        b.iter(|| {
            let mut sum = 0usize;
            for u in &us {
                sum = sum.wrapping_add(grid.sample(black_box(*u)).0);
            }
            sum
        })
    });
    group.bench_function("staged by 16", |b| {
        b.iter(|| {
            let mut sum = 0usize;
            for run in us.chunks_exact(16) {
                let rows: [(usize, f32); 16] =
                    std::array::from_fn(|k| grid.sample_row(black_box(run[k][1])));
                for (k, &(row, _)) in rows.iter().enumerate() {
                    sum = sum.wrapping_add(grid.sample_column(row, run[k][0]).0);
                }
            }
            sum
        })
    });
    group.finish();
}

criterion_group!(benches, draws);
criterion_main!(benches);
