//! The measured study behind the library's defaults (tables in BENCHMARKS.md).
//!
//! For every analytic scene, map rule and batch size it runs many independent batches and
//! reports, against the exact integral:
//! - the bias in standard errors, z = (mean − exact) / SE;
//! - the variance gain at equal traced rays, Var(AIS off) / Var(configuration).
//!
//! Run: `cargo run --release -p ais --example study -- [--batches N] [--section NAME]`.
//! Sections: `rules` (the full grid), `heights`, `placement`, `stopping`, `proposals`.

use ais::analytic::{gather, GatherTarget, Proposal, Scene};
use ais::{
    Batch, BatchConfig, Learning, LevelRule, MapConfig, MapStart, Mode, Placement, Stopping,
};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Mean, variance and mean traced rays and candidates of many batches.
#[derive(Clone, Copy, Debug, Default)]
struct Cell {
    mean: f64,
    variance: f64,
    standard_error: f64,
    traced: f64,
    candidates: f64,
}

fn measure(
    config: BatchConfig,
    scene: &Scene,
    proposal: Proposal,
    n: u32,
    batches: u32,
    target: GatherTarget,
) -> Cell {
    let mut batch: Batch<f64> = Batch::new(config).expect("valid study configuration");
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    for seed in 0..batches {
        let value = gather(
            &mut batch,
            scene,
            proposal,
            n,
            seed as u64,
            MapStart::Empty,
            target,
        )
        .value;
        sum += value;
        sum_sq += value * value;
    }
    let count = batches as f64;
    let mean = sum / count;
    let variance = (sum_sq / count - mean * mean) * count / (count - 1.0);
    let stats = batch.stats();
    Cell {
        mean,
        variance,
        standard_error: (variance / count).sqrt(),
        traced: stats.traced as f64 / count,
        candidates: stats.candidates as f64 / count,
    }
}

/// Runs `jobs` on two threads (the machine has two cores), keeping their order.
fn run_parallel<T: Send, F: Fn(usize) -> T + Sync>(jobs: usize, work: F) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let mut results: Vec<(usize, T)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let job = next.fetch_add(1, Ordering::Relaxed);
                        if job >= jobs {
                            break mine;
                        }
                        mine.push((job, work(job)));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("study worker panicked"))
            .collect()
    });
    results.sort_by_key(|(job, _)| *job);
    results.into_iter().map(|(_, r)| r).collect()
}

/// Row-major index arithmetic over a K-dimensional grid of study cells.
#[derive(Clone, Copy)]
struct Grid<const K: usize>([usize; K]);

impl<const K: usize> Grid<K> {
    fn len(&self) -> usize {
        self.0.iter().product()
    }
    fn split(&self, mut job: usize) -> [usize; K] {
        let mut index = [0; K];
        for k in (0..K).rev() {
            index[k] = job % self.0[k];
            job /= self.0[k];
        }
        index
    }
    fn join(&self, index: [usize; K]) -> usize {
        index.iter().zip(self.0).fold(0, |acc, (&i, d)| acc * d + i)
    }
}

#[derive(Clone, Copy)]
struct Row {
    label: &'static str,
    config: BatchConfig,
    target: GatherTarget,
}

fn level_label(levels: LevelRule) -> &'static str {
    match levels {
        LevelRule::Single => "single",
        LevelRule::FinestBelowOne { .. } => "literal×3",
        LevelRule::FinestWithSamples { .. } => "samples≥4×3",
    }
}

fn map_config(height: u32, tol: f32, mode: Mode, levels: LevelRule) -> MapConfig {
    MapConfig {
        height,
        tol,
        mode,
        levels,
    }
}

fn tol_label(tol: f32) -> String {
    if tol.is_infinite() {
        "∞".into()
    } else {
        format!("{tol}")
    }
}

fn print_table(title: &str, rows: &[(String, Vec<String>)], columns: &[String]) {
    println!("\n{title}\n");
    println!("| configuration | {} |", columns.join(" | "));
    println!(
        "|---|{}|",
        columns.iter().map(|_| "---").collect::<Vec<_>>().join("|")
    );
    for (label, cells) in rows {
        println!("| {label} | {} |", cells.join(" | "));
    }
}

fn format_cell(cell: &Cell, baseline: &Cell, exact: f64) -> String {
    let z = (cell.mean - exact) / cell.standard_error;
    let gain = baseline.variance / cell.variance;
    let flag = if z.abs() >= 4.0 { "**" } else { "" };
    format!("{gain:.2}× ({flag}z {z:+.1}{flag})")
}

fn scenes() -> Vec<Scene> {
    vec![
        Scene::open(),
        Scene::courtyard(),
        Scene::window(0.35),
        Scene::window(0.10),
    ]
}

/// The full grid: mode × level rule × tol × learning, per scene and n.
fn rules_section(batches: u32) {
    let ns = [8u32, 32, 128, 256];
    let mut rows = vec![
        Row {
            label: "off",
            config: BatchConfig::off(),
            target: GatherTarget::Normal,
        },
        Row {
            label: "oracle",
            config: BatchConfig::off(),
            target: GatherTarget::Oracle,
        },
    ];
    let mut labels = vec!["off".to_string(), "oracle".to_string()];
    for learning in [Learning::Continuous, Learning::Epochs { epochs: 4 }] {
        for mode in [Mode::Aggressive, Mode::Conservative] {
            for levels in [
                LevelRule::Single,
                LevelRule::FinestBelowOne { count: 3 },
                LevelRule::FinestWithSamples {
                    count: 3,
                    min_samples: 4,
                },
            ] {
                for tol in [f32::INFINITY, 1.0, 0.25] {
                    rows.push(Row {
                        label: "",
                        config: BatchConfig {
                            affinity: Some(map_config(8, tol, mode, levels)),
                            learning,
                            ..BatchConfig::default()
                        },
                        target: GatherTarget::Normal,
                    });
                    labels.push(format!(
                        "{} {} {} tol {}",
                        if learning == Learning::Continuous {
                            "continuous"
                        } else {
                            "epochs"
                        },
                        if mode == Mode::Aggressive {
                            "aggressive"
                        } else {
                            "conservative"
                        },
                        level_label(levels),
                        tol_label(tol)
                    ));
                }
            }
        }
    }
    let scenes = scenes();
    let grid = Grid([scenes.len(), ns.len(), rows.len()]);
    let cells = run_parallel(grid.len(), |job| {
        let [s, n, r] = grid.split(job);
        measure(
            rows[r].config,
            &scenes[s],
            Proposal::CosineHemisphere,
            ns[n],
            batches,
            rows[r].target,
        )
    });
    let cell = |s: usize, n: usize, r: usize| cells[grid.join([s, n, r])];
    let columns: Vec<String> = ns.iter().map(|n| format!("n = {n}")).collect();
    for (s, scene) in scenes.iter().enumerate() {
        let table: Vec<(String, Vec<String>)> = (0..rows.len())
            .map(|r| {
                let cells = (0..ns.len())
                    .map(|n| format_cell(&cell(s, n, r), &cell(s, n, 0), scene.exact()))
                    .collect();
                (labels[r].clone(), cells)
            })
            .collect();
        print_table(
            &format!(
                "#### Scene `{}` ({:.0}% of the cosine proposal visible), cosine proposal, height 8, {batches} batches per cell: variance gain vs off (z of bias)",
                scene.name(),
                scene.visible_cosine_fraction() * 100.0
            ),
            &table,
            &columns,
        );
    }
}

/// Map height sweep for the single-level rule with epochs and continuous learning.
fn heights_section(batches: u32) {
    let heights = [2u32, 4, 8, 16, 32];
    let ns = [32u32, 256];
    let scenes = scenes();
    let configs: Vec<(String, Learning, Mode, f32)> = vec![
        (
            "epochs conservative tol 1".into(),
            Learning::Epochs { epochs: 4 },
            Mode::Conservative,
            1.0,
        ),
        (
            "epochs aggressive tol 1".into(),
            Learning::Epochs { epochs: 4 },
            Mode::Aggressive,
            1.0,
        ),
        (
            "continuous conservative tol 1".into(),
            Learning::Continuous,
            Mode::Conservative,
            1.0,
        ),
    ];
    let grid = Grid([scenes.len(), configs.len(), heights.len(), ns.len()]);
    let cells = run_parallel(grid.len(), |job| {
        let [s, c, h, n] = grid.split(job);
        let (_, learning, mode, tol) = configs[c].clone();
        let config = BatchConfig {
            affinity: Some(map_config(heights[h], tol, mode, LevelRule::Single)),
            learning,
            ..BatchConfig::default()
        };
        measure(
            config,
            &scenes[s],
            Proposal::CosineHemisphere,
            ns[n],
            batches,
            GatherTarget::Normal,
        )
    });
    let baselines = run_parallel(scenes.len() * ns.len(), |job| {
        measure(
            BatchConfig::off(),
            &scenes[job / ns.len()],
            Proposal::CosineHemisphere,
            ns[job % ns.len()],
            batches,
            GatherTarget::Normal,
        )
    });
    let columns: Vec<String> = heights
        .iter()
        .flat_map(|h| ns.iter().map(move |n| format!("h {h}, n {n}")))
        .collect();
    let mut table = Vec::new();
    for (s, scene) in scenes.iter().enumerate() {
        for (c, config) in configs.iter().enumerate() {
            let mut row = Vec::new();
            for h in 0..heights.len() {
                for n in 0..ns.len() {
                    row.push(format_cell(
                        &cells[grid.join([s, c, h, n])],
                        &baselines[s * ns.len() + n],
                        scene.exact(),
                    ));
                }
            }
            table.push((format!("{} · {}", scene.name(), config.0), row));
        }
    }
    print_table(
        &format!("#### Map height (single level), cosine proposal, {batches} batches per cell: variance gain vs off (z of bias)"),
        &table,
        &columns,
    );
}

/// Halton versus simple random placement, with AIS off and with the default configuration.
fn placement_section(batches: u32) {
    let ns = [8u32, 32, 128];
    let scenes = scenes();
    let configs = [
        (
            "off, random",
            BatchConfig {
                placement: Placement::Random,
                ..BatchConfig::off()
            },
        ),
        ("off, Halton", BatchConfig::off()),
        (
            "default AIS, random",
            BatchConfig {
                placement: Placement::Random,
                ..BatchConfig::default()
            },
        ),
        ("default AIS, Halton", BatchConfig::default()),
    ];
    let grid = Grid([scenes.len(), configs.len(), ns.len()]);
    let cells = run_parallel(grid.len(), |job| {
        let [s, c, n] = grid.split(job);
        measure(
            configs[c].1,
            &scenes[s],
            Proposal::CosineHemisphere,
            ns[n],
            batches,
            GatherTarget::Normal,
        )
    });
    let columns: Vec<String> = ns.iter().map(|n| format!("n = {n}")).collect();
    let mut table = Vec::new();
    for (s, scene) in scenes.iter().enumerate() {
        // Baseline: AIS off with random placement.
        for (c, config) in configs.iter().enumerate() {
            let row = (0..ns.len())
                .map(|n| {
                    let at = |c: usize| cells[grid.join([s, c, n])];
                    format_cell(&at(c), &at(0), scene.exact())
                })
                .collect();
            table.push((format!("{} · {}", scene.name(), config.0), row));
        }
    }
    print_table(
        &format!("#### Placement, cosine proposal, {batches} batches per cell: variance gain vs AIS off with random placement (z of bias)"),
        &table,
        &columns,
    );
}

/// The n+1 rule against stopping at the n-th acceptance.
fn stopping_section(batches: u32) {
    let ns = [1u32, 4, 8, 32];
    let scenes = scenes();
    let configs = [
        (
            "continuous, drop last (n+1)",
            Learning::Continuous,
            Stopping::DropLast,
        ),
        ("continuous, stop at n", Learning::Continuous, Stopping::AtN),
        (
            "epochs, drop last (n+1)",
            Learning::Epochs { epochs: 4 },
            Stopping::DropLast,
        ),
        (
            "epochs, stop at n",
            Learning::Epochs { epochs: 4 },
            Stopping::AtN,
        ),
    ];
    let grid = Grid([scenes.len(), configs.len(), ns.len()]);
    let cells = run_parallel(grid.len(), |job| {
        let [s, c, n] = grid.split(job);
        let config = BatchConfig {
            affinity: Some(map_config(
                8,
                f32::INFINITY,
                Mode::Aggressive,
                LevelRule::Single,
            )),
            learning: configs[c].1,
            stopping: configs[c].2,
            ..BatchConfig::default()
        };
        measure(
            config,
            &scenes[s],
            Proposal::CosineHemisphere,
            ns[n],
            batches,
            GatherTarget::Normal,
        )
    });
    let columns: Vec<String> = ns.iter().map(|n| format!("n = {n}")).collect();
    let mut table = Vec::new();
    for (s, scene) in scenes.iter().enumerate() {
        for (c, config) in configs.iter().enumerate() {
            let row = (0..ns.len())
                .map(|n| {
                    let cell = cells[grid.join([s, c, n])];
                    let z = (cell.mean - scene.exact()) / cell.standard_error;
                    let relative = (cell.mean - scene.exact()) / scene.exact() * 100.0;
                    format!("{relative:+.2}% (z {z:+.1})")
                })
                .collect();
            table.push((format!("{} · {}", scene.name(), config.0), row));
        }
    }
    print_table(
        &format!("#### Stopping rule, aggressive single level h 8 tol ∞, {batches} batches per cell: relative bias (z)"),
        &table,
        &columns,
    );
}

/// The uniform-sphere proposal (half its candidates are unconditional rejections).
fn proposals_section(batches: u32) {
    let ns = [32u32, 256];
    let scenes = scenes();
    let configs = [
        ("off", BatchConfig::off(), GatherTarget::Normal),
        ("oracle", BatchConfig::off(), GatherTarget::Oracle),
        ("default AIS", BatchConfig::default(), GatherTarget::Normal),
    ];
    let proposals = [Proposal::UniformSphere, Proposal::CosineHemisphere];
    let grid = Grid([scenes.len(), proposals.len(), configs.len(), ns.len()]);
    let cells = run_parallel(grid.len(), |job| {
        let [s, p, c, n] = grid.split(job);
        measure(
            configs[c].1,
            &scenes[s],
            proposals[p],
            ns[n],
            batches,
            configs[c].2,
        )
    });
    let columns: Vec<String> = ns
        .iter()
        .flat_map(|n| [format!("n = {n}"), format!("candidates/traced, n = {n}")])
        .collect();
    let mut table = Vec::new();
    for (s, scene) in scenes.iter().enumerate() {
        for (p, proposal) in proposals.iter().enumerate() {
            for (c, config) in configs.iter().enumerate() {
                let mut row = Vec::new();
                for n in 0..ns.len() {
                    let at = |c: usize| cells[grid.join([s, p, c, n])];
                    row.push(format_cell(&at(c), &at(0), scene.exact()));
                    row.push(format!("{:.2}", at(c).candidates / at(c).traced));
                }
                table.push((
                    format!("{} · {} · {}", scene.name(), proposal.name(), config.0),
                    row,
                ));
            }
        }
    }
    print_table(
        &format!("#### Proposals, {batches} batches per cell: variance gain vs off with the same proposal (z of bias)"),
        &table,
        &columns,
    );
}

fn main() {
    let mut batches = 10_000u32;
    let mut sections: Vec<String> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--batches" => {
                batches = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .filter(|&b| b >= 2)
                    .unwrap_or_else(|| {
                        eprintln!("--batches needs an integer of at least 2");
                        std::process::exit(2)
                    })
            }
            "--section" => sections.push(args.next().unwrap_or_default()),
            other => {
                eprintln!("unknown argument {other:?}; use --batches N and --section rules|heights|placement|stopping|proposals");
                std::process::exit(2);
            }
        }
    }
    if sections.is_empty() {
        sections = ["rules", "heights", "placement", "stopping", "proposals"]
            .map(String::from)
            .to_vec();
    }
    for section in &sections {
        let started = std::time::Instant::now();
        match section.as_str() {
            "rules" => rules_section(batches),
            "heights" => heights_section(batches),
            "placement" => placement_section(batches),
            "stopping" => stopping_section(batches),
            "proposals" => proposals_section(batches),
            other => {
                eprintln!("unknown section {other:?}");
                std::process::exit(2);
            }
        }
        eprintln!(
            "section {section}: {:.1} s",
            started.elapsed().as_secs_f64()
        );
    }
}
