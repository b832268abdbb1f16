//! The measured study behind the library's defaults (tables in BENCHMARKS.md).
//!
//! For every analytic scene, map rule and batch size it runs many independent batches and
//! reports, against the exact integral:
//! - the variance gain at equal traced rays, (Var · traced) of the baseline over that of the
//!   configuration (traced rays matter because the candidate-budget rule traces `n` only on
//!   average);
//! - the bias in standard errors, z = (mean − exact) / SE (bold when |z| ≥ 4).
//!
//! Run: `cargo run --release -p ais --example study -- [--batches N] [--section NAME]...`.
//! Sections: `rules` (the full grid), `heights`, `placement`, `stopping`, `proposals`.

use ais::analytic::{AnalyticGather, GatherTarget, Moments, Proposal, Scene};
use ais::{
    Batch, BatchConfig, Learning, LevelRule, MapConfig, MapStart, Mode, Placement, Stopping,
};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Mean, variance and mean traced rays of many batches.
#[derive(Clone, Copy, Debug, Default)]
struct Cell {
    mean: f64,
    variance: f64,
    standard_error: f64,
    traced: f64,
    candidates: f64,
}

/// One configuration of the study: a batch configuration and what the gather may skip.
#[derive(Clone, Debug)]
struct Setup {
    label: String,
    config: BatchConfig,
    target: GatherTarget,
}

impl Setup {
    fn new(label: &str, config: BatchConfig) -> Self {
        Setup {
            label: label.to_string(),
            config,
            target: GatherTarget::Normal,
        }
    }

    fn oracle(label: &str, config: BatchConfig) -> Self {
        Setup {
            target: GatherTarget::Oracle,
            ..Setup::new(label, config)
        }
    }
}

fn measure(setup: &Setup, scene: &Scene, proposal: Proposal, n: u32, batches: u32) -> Cell {
    let mut batch: Batch<f64> = Batch::new(setup.config).expect("valid study configuration");
    let mut moments = Moments::default();
    for seed in 0..batches {
        let job = AnalyticGather {
            scene,
            proposal,
            n,
            target: setup.target,
        };
        let estimate = job.run(&mut batch, seed as u64, MapStart::Empty);
        moments.add(estimate.value);
    }
    let count = batches as f64;
    let stats = batch.stats();
    Cell {
        mean: moments.mean(),
        variance: moments.variance(),
        standard_error: moments.standard_error(),
        traced: stats.traced as f64 / count,
        candidates: stats.candidates as f64 / count,
    }
}

/// Runs `jobs` jobs on all cores, keeping their order.
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

/// One table of the study: every (scene, proposal, setup, n) cell.
struct Table<'a> {
    title: &'a str,
    scenes: &'a [Scene],
    proposals: &'a [Proposal],
    setups: &'a [Setup],
    ns: &'a [u32],
    /// The setup every cell is compared with.
    baseline: usize,
    /// Whether to add a candidates-per-traced-ray column.
    show_candidates: bool,
}

/// Measures every cell of `table` and prints one table per scene and proposal, each cell
/// relative to the baseline setup.
fn study(table: Table, batches: u32) {
    let Table {
        title,
        scenes,
        proposals,
        setups,
        ns,
        baseline,
        show_candidates,
    } = table;
    let per_scene = proposals.len() * setups.len() * ns.len();
    let cells = run_parallel(scenes.len() * per_scene, |job| {
        let (s, rest) = (job / per_scene, job % per_scene);
        let (p, rest) = (
            rest / (setups.len() * ns.len()),
            rest % (setups.len() * ns.len()),
        );
        let (c, n) = (rest / ns.len(), rest % ns.len());
        measure(&setups[c], &scenes[s], proposals[p], ns[n], batches)
    });
    let at = |s: usize, p: usize, c: usize, n: usize| {
        cells[((s * proposals.len() + p) * setups.len() + c) * ns.len() + n]
    };
    for (s, scene) in scenes.iter().enumerate() {
        for (p, proposal) in proposals.iter().enumerate() {
            println!(
                "\n#### {title}: scene `{}` ({:.0}% of the cosine-weighted hemisphere visible), {} proposal, {batches} batches per cell\n",
                scene.name(),
                scene.visible_cosine_fraction() * 100.0,
                proposal.name()
            );
            let mut header = String::from("| configuration |");
            let mut rule = String::from("|---|");
            for n in ns {
                header += &format!(" n = {n} |");
                rule += "---|";
                if show_candidates {
                    header += &format!(" candidates / traced, n = {n} |");
                    rule += "---|";
                }
            }
            println!("{header}\n{rule}");
            for (c, setup) in setups.iter().enumerate() {
                let mut line = format!("| {} |", setup.label);
                for n in 0..ns.len() {
                    let cell = at(s, p, c, n);
                    let base = at(s, p, baseline, n);
                    let z = (cell.mean - scene.exact()) / cell.standard_error;
                    let gain = (base.variance * base.traced) / (cell.variance * cell.traced);
                    let bold = if z.abs() >= 4.0 { "**" } else { "" };
                    line += &format!(" {gain:.2}× ({bold}z {z:+.1}{bold}) |");
                    if show_candidates {
                        line += &format!(" {:.2} |", cell.candidates / cell.traced);
                    }
                }
                println!("{line}");
            }
        }
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

fn all_scenes() -> Vec<Scene> {
    vec![
        Scene::open(),
        Scene::courtyard(),
        Scene::window(0.35),
        Scene::window(0.10),
    ]
}

fn random_off() -> BatchConfig {
    BatchConfig {
        placement: Placement::Random,
        ..BatchConfig::talk_off()
    }
}

fn budget_off() -> BatchConfig {
    BatchConfig {
        stopping: Stopping::CandidateBudget,
        ..BatchConfig::talk_off()
    }
}

/// The reference rows every table starts with.
fn reference_setups() -> Vec<Setup> {
    vec![
        Setup::new("off, random", random_off()),
        Setup::new("off, Halton", BatchConfig::talk_off()),
        Setup::oracle("oracle, random, n+1", random_off()),
        Setup::oracle("oracle, Halton, budget", budget_off()),
    ]
}

/// The three schedules: the talk's, and our two exactly unbiased ones.
const SCHEDULES: [(&str, Learning, Placement, Stopping); 3] = [
    (
        "talk: continuous, Halton, n+1",
        Learning::Continuous,
        Placement::Halton,
        Stopping::DropLast,
    ),
    (
        "epochs, random, n+1",
        Learning::Epochs { epochs: 4 },
        Placement::Random,
        Stopping::DropLast,
    ),
    (
        "epochs, Halton, budget",
        Learning::Epochs { epochs: 4 },
        Placement::Halton,
        Stopping::CandidateBudget,
    ),
];

fn level_label(levels: LevelRule) -> &'static str {
    match levels {
        LevelRule::Single => "single",
        LevelRule::FinestBelowOne { .. } => "literal×3",
        LevelRule::FinestWithSamples { .. } => "samples≥4×3",
    }
}

fn tol_label(tol: f32) -> String {
    if tol.is_infinite() {
        "∞".into()
    } else {
        format!("{tol}")
    }
}

/// The full grid: schedule × mode × level rule × tol, per scene and n.
fn rules_section(batches: u32) {
    let mut setups = reference_setups();
    for (schedule, learning, placement, stopping) in SCHEDULES {
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
                    let label = format!(
                        "{schedule} · {} {} tol {}",
                        if mode == Mode::Aggressive {
                            "aggressive"
                        } else {
                            "conservative"
                        },
                        level_label(levels),
                        tol_label(tol)
                    );
                    let config = BatchConfig {
                        affinity: Some(map_config(8, tol, mode, levels)),
                        learning,
                        placement,
                        stopping,
                        ..BatchConfig::default()
                    };
                    setups.push(Setup::new(&label, config));
                }
            }
        }
    }
    study(
        Table {
            title: "Rules (height 8); variance gain at equal traced rays vs off with random placement (z of bias)",
            scenes: &all_scenes(),
            proposals: &[Proposal::CosineHemisphere],
            setups: &setups,
            ns: &[8, 32, 128, 256],
            baseline: 0,
            show_candidates: false,
        },
        batches,
    );
}

/// Map height sweep for the default schedule.
fn heights_section(batches: u32) {
    let mut setups = vec![Setup::new("off, Halton", BatchConfig::talk_off())];
    for mode in [Mode::Conservative, Mode::Aggressive] {
        for height in [2u32, 4, 8, 16, 32] {
            let label = format!(
                "{} h {height}",
                if mode == Mode::Aggressive {
                    "aggressive"
                } else {
                    "conservative"
                }
            );
            let config = BatchConfig {
                affinity: Some(map_config(height, 1.0, mode, LevelRule::Single)),
                ..BatchConfig::default()
            };
            setups.push(Setup::new(&label, config));
        }
    }
    study(
        Table {
            title: "Map height (epochs, Halton, budget, single level, tol 1); variance gain at equal traced rays vs off with Halton placement (z of bias)",
            scenes: &all_scenes(),
            proposals: &[Proposal::CosineHemisphere],
            setups: &setups,
            ns: &[32, 256],
            baseline: 0,
            show_candidates: false,
        },
        batches,
    );
}

/// Halton versus simple random placement (the talk's figure), with AIS off and on.
fn placement_section(batches: u32) {
    let default = BatchConfig::default();
    let setups = vec![
        Setup::new("off, random", random_off()),
        Setup::new("off, Halton", BatchConfig::talk_off()),
        Setup::new(
            "default AIS, random, n+1",
            BatchConfig {
                placement: Placement::Random,
                stopping: Stopping::DropLast,
                ..default
            },
        ),
        Setup::new(
            "default AIS, Halton, n+1",
            BatchConfig {
                stopping: Stopping::DropLast,
                ..default
            },
        ),
        Setup::new(
            "default AIS, Halton, budget",
            BatchConfig {
                stopping: Stopping::CandidateBudget,
                ..default
            },
        ),
    ];
    study(
        Table {
            title: "Placement; variance gain at equal traced rays vs off with random placement (z of bias)",
            scenes: &all_scenes(),
            proposals: &[Proposal::CosineHemisphere],
            setups: &setups,
            ns: &[8, 32, 128],
            baseline: 0,
            show_candidates: false,
        },
        batches,
    );
}

/// The n+1 rule against stopping at the n-th acceptance, and placement's effect on bias.
fn stopping_section(batches: u32) {
    let map = Some(map_config(
        8,
        f32::INFINITY,
        Mode::Aggressive,
        LevelRule::Single,
    ));
    let rules = [
        ("random, n+1", Placement::Random, Stopping::DropLast),
        ("random, stop at n", Placement::Random, Stopping::AtN),
        ("Halton, n+1", Placement::Halton, Stopping::DropLast),
        (
            "Halton, budget",
            Placement::Halton,
            Stopping::CandidateBudget,
        ),
    ];
    let mut setups = Vec::new();
    for (prefix, affinity, learning) in [
        ("oracle", None, Learning::Off),
        ("epochs", map, Learning::Epochs { epochs: 4 }),
    ] {
        for (rule, placement, stopping) in rules {
            let label = format!("{prefix}, {rule}");
            let config = BatchConfig {
                affinity,
                learning,
                stopping,
                placement,
                ..BatchConfig::default()
            };
            setups.push(match affinity {
                None => Setup::oracle(&label, config),
                Some(_) => Setup::new(&label, config),
            });
        }
    }
    study(
        Table {
            title: "Stopping rule and placement (maps: aggressive, single level, h 8, tol ∞); variance gain vs the first row (z of bias)",
            scenes: &[Scene::window(0.35), Scene::window(0.10)],
            proposals: &[Proposal::CosineHemisphere],
            setups: &setups,
            ns: &[1, 8, 32],
            baseline: 0,
            show_candidates: false,
        },
        batches,
    );
}

/// The uniform-sphere proposal (half of its candidates are unconditional rejections).
fn proposals_section(batches: u32) {
    let setups = vec![
        Setup::new("off, Halton, n+1", BatchConfig::talk_off()),
        Setup::new("off, Halton, budget", budget_off()),
        Setup::oracle("oracle, Halton, budget", budget_off()),
        Setup::new("default AIS", BatchConfig::default()),
    ];
    study(
        Table {
            title: "Proposals; variance gain at equal traced rays vs the first row (z of bias)",
            scenes: &all_scenes(),
            proposals: &[Proposal::UniformSphere, Proposal::CosineHemisphere],
            setups: &setups,
            ns: &[32, 256],
            baseline: 0,
            show_candidates: true,
        },
        batches,
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
