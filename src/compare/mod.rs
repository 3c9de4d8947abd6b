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
    #[error("configuration `{what}`: {defect}")]
    Config {
        /// the configuration as given, or its name
        what: String,
        /// what is wrong
        defect: ConfigDefect,
    },
    /// A configuration file that is not TOML of the expected form.
    #[error("{path}: {source}")]
    ConfigToml {
        /// the TOML file
        path: String,
        /// the parser's error
        source: toml::de::Error,
    },
    /// A configuration file whose argument line has an unclosed quote.
    #[error("{path}: {source}")]
    ConfigQuote {
        /// the TOML file
        path: String,
        /// the line and its quote
        source: config::UnclosedQuote,
    },
    /// A bad `--seeds`.
    #[error("--seeds `{spec}`: {defect}")]
    Seeds {
        /// as given
        spec: String,
        /// what is wrong
        defect: SeedsDefect,
    },
    /// An input that cannot be run.
    #[error("input {path}: {defect}")]
    Input {
        /// the file or folder
        path: String,
        /// what is wrong
        defect: InputDefect,
    },
    /// A report without the expected numbers.
    #[error("report {path}: {defect}")]
    Report {
        /// the report
        path: String,
        /// what is missing
        defect: ReportDefect,
    },
    /// A snapshot file that cannot be checked.
    #[error("snapshot {path}: {defect}")]
    Snapshot {
        /// the snapshot file
        path: String,
        /// what is wrong
        defect: SnapshotDefect,
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

/// What is wrong with a configuration ([`CompareError::Config`]).
#[derive(Debug, thiserror::Error)]
pub enum ConfigDefect {
    /// Not of the form `NAME=ARGS`.
    #[error("a configuration is NAME=ARGS (e.g. `base=` or `kring=--strategy kring`)")]
    NotNameArgs,
    /// Its argument line has an unclosed quote.
    #[error(transparent)]
    Quote(#[from] config::UnclosedQuote),
    /// A name that cannot name files.
    #[error("the name `{name}` must be letters, digits, `-`, `_` or `.` (it names files)")]
    BadName {
        /// the name
        name: String,
    },
    /// An argument compare sets itself ([`config::OWN_ARGS`]).
    #[error("`{arg}` is set by compare for every run; leave it out (seeds: --seeds)")]
    OwnArg {
        /// the argument
        arg: String,
    },
    /// No configuration at all.
    #[error("no configuration: give `-c NAME=ARGS` or `--config FILE.toml`")]
    None,
    /// Two configurations share the name.
    #[error("two configurations have this name")]
    SameName,
}

/// What is wrong with `--seeds` ([`CompareError::Seeds`]).
#[derive(Debug, thiserror::Error)]
pub enum SeedsDefect {
    /// A part that is not a whole number.
    #[error("`{part}` is not a seed (a whole number ≥ 0)")]
    NotASeed {
        /// the part
        part: String,
    },
    /// A range whose start is after its end.
    #[error("the range {start}-{end} is empty (start after end)")]
    EmptyRange {
        /// first seed
        start: u64,
        /// last seed
        end: u64,
    },
    /// A range of more than 10000 seeds.
    #[error("the range {start}-{end} has more than 10000 seeds")]
    TooMany {
        /// first seed
        start: u64,
        /// last seed
        end: u64,
    },
}

/// What is wrong with an input ([`CompareError::Input`]).
#[derive(Debug, thiserror::Error)]
pub enum InputDefect {
    /// No input at all.
    #[error("no input: give mesh files or folders")]
    None,
    /// A folder without mesh files.
    #[error("the folder holds no mesh file (.obj, .off, .ply, .stl, .mesh)")]
    NoMeshFile,
    /// Neither a file nor a folder.
    #[error("no such file or folder")]
    Missing,
    /// Two inputs with one name (the file stem), which names their outputs.
    #[error("shares the name `{name}` with {} (outputs are named by it)", other.display())]
    SameName {
        /// the shared name
        name: String,
        /// the other input
        other: std::path::PathBuf,
    },
}

/// What a run's report lacks ([`CompareError::Report`]).
#[derive(Debug, thiserror::Error)]
pub enum ReportDefect {
    /// It is not JSON.
    #[error(transparent)]
    NotJson(serde_json::Error),
    /// A field it does not have (its keys from the top).
    #[error("no `{}`", .0.join("."))]
    Missing(&'static [&'static str]),
    /// A field of another type.
    #[error("`{}` is not a {kind:?}", path.join("."))]
    WrongType {
        /// the keys from the top
        path: &'static [&'static str],
        /// what it should be
        kind: measures::Kind,
    },
    /// `eval.output_quality` is not the quality statistics.
    #[error("eval.output_quality: {0}")]
    Quality(#[source] serde_json::Error),
}

/// What is wrong with a snapshot file ([`CompareError::Snapshot`]).
#[derive(Debug, thiserror::Error)]
pub enum SnapshotDefect {
    /// It cannot be read.
    #[error(transparent)]
    Unreadable(std::io::Error),
    /// It is not a snapshot's JSON.
    #[error(transparent)]
    NotJson(serde_json::Error),
    /// Another format.
    #[error("format `{found}`, this conemesh reads `{}`", snapshot::FORMAT)]
    Format {
        /// the format it names
        found: String,
    },
    /// A configuration it lists cannot run.
    #[error(transparent)]
    Config(Box<CompareError>),
    /// A time limit that is not a positive time.
    #[error("timeout_s {0} is not a positive time")]
    Timeout(f64),
    /// It lists no runs.
    #[error("it lists no runs")]
    NoRuns,
    /// A run names a configuration it does not list.
    #[error("run {run} names no listed configuration")]
    UnknownConfig {
        /// the run's label
        run: String,
    },
    /// A run names an input it does not list.
    #[error("run {run} names no listed input")]
    UnknownInput {
        /// the run's label
        run: String,
    },
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
