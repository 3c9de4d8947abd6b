//! Comparisons of configurations (ours): every (configuration, input, seed) remeshed in its
//! own process, the Table-1 row and the other measures as mean ± sd over the seeds, and each
//! configuration against the first, paired over (input, seed), with a bootstrap interval and
//! an exact sign test; a snapshot to check later that the same inputs and options still give
//! the same bytes. `conemesh compare` is the front end.
//!
//! - [`config`]: configurations (`NAME=ARGS`, TOML), seeds, inputs.
//! - [`process`]: one child process with a time limit.
//! - [`grid`]: running the grid, one process per cell, `jobs` at once.
//! - [`measures`]: what a run's report gives.
//! - [`stats`]: mean ± sd, the paired bootstrap interval, the sign test.
//! - [`snapshot`]: `snapshot.json` and its drift.
//! - [`page`]: `compare.md`, `compare.json`, `index.html` and the plots.

pub mod config;
pub mod grid;
pub mod measures;
pub mod page;
pub mod process;
pub mod snapshot;
pub mod stats;

pub use config::{Config, Input};
pub use grid::{Grid, Job, PictureError, RunRecord, Status};
pub use snapshot::{Drift, Snapshot};

use measures::MEASURES;
use serde::Serialize;
use std::collections::BTreeMap;

/// What a comparison can refuse.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A configuration (`NAME=ARGS`) that cannot run.
    #[error("configuration `{what}`: {detail}")]
    Config {
        /// the configuration as given, or its name
        what: String,
        /// what is wrong
        detail: String,
    },
    /// A configuration file that does not parse.
    #[error("{path}: {detail}")]
    ConfigFile {
        /// the TOML file
        path: String,
        /// the parser's message
        detail: String,
    },
    /// A bad `--seeds`.
    #[error("--seeds `{spec}`: {detail}")]
    Seeds {
        /// as given
        spec: String,
        /// what is wrong
        detail: String,
    },
    /// An input that cannot be run.
    #[error("input {path}: {detail}")]
    Input {
        /// the file or folder
        path: String,
        /// what is wrong
        detail: String,
    },
    /// A report without the expected numbers.
    #[error("report {path}: {detail}")]
    Report {
        /// the report
        path: String,
        /// what is missing
        detail: String,
    },
    /// A snapshot file that cannot be checked.
    #[error("snapshot {path}: {detail}")]
    Snapshot {
        /// the snapshot file
        path: String,
        /// what is wrong
        detail: String,
    },
    /// Operating-system error on a path.
    #[error("{path}: {source}")]
    Os {
        /// the file or folder
        path: String,
        /// the OS error
        source: std::io::Error,
    },
    /// A plot could not be drawn.
    #[error(transparent)]
    Plot(#[from] crate::report::ReportError),
}

/// The bootstrap stream of configuration `config` (its index in the grid, the first being 0)
/// against the first on measure `measure` (its index in [`measures::MEASURES`]): one fixed
/// stream per pair, so the same pairs give the same interval in every run and in the Python
/// front end's table.
pub fn paired_seed(config: usize, measure: usize) -> u64 {
    stats::BOOTSTRAP_SEED + (config * MEASURES.len() + measure) as u64
}

/// Mean and sample standard deviation over the seeds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MeanSd {
    /// mean
    pub mean: f64,
    /// sample standard deviation (0 for one run)
    pub sd: f64,
}

/// One (input, configuration) over its seeds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SummaryRow {
    /// input name
    pub mesh: String,
    /// configuration name
    pub config: String,
    /// runs (seeds)
    pub runs: usize,
    /// runs that ended `ok` (the statistics are over these)
    pub ok: usize,
    /// every measure over the ok runs, by key
    pub measures: BTreeMap<String, MeanSd>,
}

/// One configuration against the first on one measure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PairedRow {
    /// the measure's key
    pub measure: String,
    /// the configuration
    pub config: String,
    /// the configuration it is compared with (the first)
    pub against: String,
    /// the statistics over the (input, seed) pairs where both ran
    #[serde(flatten)]
    pub stats: stats::Paired,
}

/// A finished comparison: every run, the per-input summaries and the paired statistics.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// who ran it
    pub conemesh: snapshot::Build,
    /// the configurations, the first the baseline
    pub configs: Vec<Config>,
    /// the inputs
    pub inputs: Vec<Input>,
    /// the seeds
    pub seeds: Vec<u64>,
    /// every run, in grid order (input, configuration, seed)
    pub runs: Vec<RunRecord>,
    /// per input and configuration, in grid order
    pub summary: Vec<SummaryRow>,
    /// per measure and configuration after the first
    pub paired: Vec<PairedRow>,
}

impl Comparison {
    /// The statistics of a grid's records.
    pub fn of(grid: &Grid, runs: Vec<RunRecord>) -> Comparison {
        let value = |r: &RunRecord, key: &str| -> Option<f64> {
            r.result
                .as_ref()
                .and_then(|res| res.measures.get(key).copied())
        };
        let mut summary = Vec::new();
        for input in &grid.inputs {
            for c in &grid.configs {
                let mine: Vec<&RunRecord> = runs
                    .iter()
                    .filter(|r| r.mesh == input.name && r.config == c.name)
                    .collect();
                let ok: Vec<&&RunRecord> = mine.iter().filter(|r| r.status == Status::Ok).collect();
                let measures = MEASURES
                    .iter()
                    .filter_map(|m| {
                        let xs: Vec<f64> = ok.iter().filter_map(|r| value(r, m.key)).collect();
                        (!xs.is_empty()).then(|| {
                            let (mean, sd) = stats::mean_sd(&xs);
                            (m.key.to_string(), MeanSd { mean, sd })
                        })
                    })
                    .collect();
                summary.push(SummaryRow {
                    mesh: input.name.clone(),
                    config: c.name.clone(),
                    runs: mine.len(),
                    ok: ok.len(),
                    measures,
                });
            }
        }
        let mut paired = Vec::new();
        if let Some(base) = grid.configs.first() {
            for (mi, m) in MEASURES.iter().enumerate() {
                for (ci, c) in grid.configs.iter().enumerate().skip(1) {
                    let pairs: Vec<(f64, f64)> = runs
                        .iter()
                        .filter(|r| r.config == c.name)
                        .filter_map(|r| {
                            let b = runs.iter().find(|b| {
                                b.config == base.name && b.mesh == r.mesh && b.seed == r.seed
                            })?;
                            Some((value(b, m.key)?, value(r, m.key)?))
                        })
                        .collect();
                    let seed = paired_seed(ci, mi);
                    paired.push(PairedRow {
                        measure: m.key.to_string(),
                        config: c.name.clone(),
                        against: base.name.clone(),
                        stats: stats::paired(&pairs, m.better, seed),
                    });
                }
            }
        }
        Comparison {
            conemesh: snapshot::Build::current(),
            configs: grid.configs.clone(),
            inputs: grid.inputs.clone(),
            seeds: grid.seeds.clone(),
            runs,
            summary,
            paired,
        }
    }
}
