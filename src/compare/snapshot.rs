//! `snapshot.json`: what a comparison ran and what it gave, so that `conemesh compare
//! --check` can rerun it later and name every byte or measure that differs. It records the
//! conemesh version and commit, each input's SHA-256, the configurations and seeds, and per
//! run its status, its resolved options (from the report), its output's SHA-256 and its
//! measures that are properties of the output (not the time nor the memory).

use super::config::{Config, Input};
use super::grid::{Grid, Job, RunRecord, Status};
use super::measures::MEASURES;
use super::{CompareError, SnapshotDefect};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The `format` of the snapshots this version writes and reads.
pub const FORMAT: &str = "conemesh-compare-snapshot/1";

/// The git commit conemesh was built from (`build.rs`), or "unknown" (a build outside a git
/// checkout, e.g. from a tarball).
pub const GIT_COMMIT: &str = match option_env!("CONEMESH_GIT_COMMIT") {
    Some(c) => c,
    None => "unknown",
};

/// The conemesh that wrote a snapshot.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Build {
    /// the crate version
    pub version: String,
    /// the git commit, or "unknown"
    pub commit: String,
}

impl Build {
    /// This build.
    pub fn current() -> Build {
        Build {
            version: env!("CARGO_PKG_VERSION").to_string(),
            commit: GIT_COMMIT.to_string(),
        }
    }
}

/// One input of a snapshot.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SnapshotInput {
    /// the name in the runs (file stem)
    pub name: String,
    /// the file (absolute)
    pub path: PathBuf,
    /// SHA-256 of its bytes
    pub sha256: String,
}

/// One run of a snapshot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SnapshotRun {
    /// configuration name
    pub config: String,
    /// input name
    pub mesh: String,
    /// seed
    pub seed: u64,
    /// how it ended
    pub status: Status,
    /// SHA-256 of the output mesh (ok runs)
    pub output_sha256: Option<String>,
    /// the resolved options from the report (ok runs)
    pub options: Option<serde_json::Value>,
    /// the deterministic measures by key (ok runs)
    pub measures: BTreeMap<String, f64>,
}

impl SnapshotRun {
    /// `kring/bunny/seed 2`.
    pub fn label(&self) -> String {
        format!("{}/{}/seed {}", self.config, self.mesh, self.seed)
    }
}

/// A whole snapshot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Snapshot {
    /// [`FORMAT`]
    pub format: String,
    /// who wrote it
    pub conemesh: Build,
    /// each run's time limit, seconds
    pub timeout_s: f64,
    /// the inputs
    pub inputs: Vec<SnapshotInput>,
    /// the configurations, the first the baseline
    pub configs: Vec<Config>,
    /// the seeds
    pub seeds: Vec<u64>,
    /// every run, in the grid's order
    pub runs: Vec<SnapshotRun>,
}

/// One difference between a snapshot and its rerun.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Drift {
    /// the run (`config/mesh/seed N`), or the input
    pub what: String,
    /// what differs (`output_sha256`, `measures.q_avg`, `options.options.sweeps`)
    pub field: String,
    /// the snapshot's value
    pub was: String,
    /// the rerun's value
    pub now: String,
}

impl std::fmt::Display for Drift {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {}: snapshot {}, now {}",
            self.what, self.field, self.was, self.now
        )
    }
}

impl Snapshot {
    /// The snapshot of a grid's records (`inputs_sha256` in the order of `grid.inputs`).
    pub fn of(grid: &Grid, inputs_sha256: &[String], records: &[RunRecord]) -> Snapshot {
        Snapshot {
            format: FORMAT.to_string(),
            conemesh: Build::current(),
            timeout_s: grid.timeout.as_secs_f64(),
            inputs: grid
                .inputs
                .iter()
                .zip(inputs_sha256)
                .map(|(i, h)| SnapshotInput {
                    name: i.name.clone(),
                    path: i.path.clone(),
                    sha256: h.clone(),
                })
                .collect(),
            configs: grid.configs.clone(),
            seeds: grid.seeds.clone(),
            runs: records.iter().map(run_of).collect(),
        }
    }

    /// Read and check a snapshot file: JSON of this format whose runs name its own
    /// configurations and inputs.
    pub fn read(path: &Path) -> Result<Snapshot, CompareError> {
        let bad = |defect: SnapshotDefect| CompareError::Snapshot {
            path: path.display().to_string(),
            defect,
        };
        let config = |e: CompareError| bad(SnapshotDefect::Config(Box::new(e)));
        let text = std::fs::read_to_string(path).map_err(|e| bad(SnapshotDefect::Unreadable(e)))?;
        let s: Snapshot =
            serde_json::from_str(&text).map_err(|e| bad(SnapshotDefect::NotJson(e)))?;
        if s.format != FORMAT {
            return Err(bad(SnapshotDefect::Format {
                found: s.format.clone(),
            }));
        }
        super::config::check_configs(&s.configs).map_err(config)?;
        for c in &s.configs {
            Config::new(&c.name, c.args.clone()).map_err(config)?;
        }
        if !(s.timeout_s > 0.0 && s.timeout_s.is_finite()) {
            return Err(bad(SnapshotDefect::Timeout(s.timeout_s)));
        }
        if s.runs.is_empty() {
            return Err(bad(SnapshotDefect::NoRuns));
        }
        for r in &s.runs {
            if !s.configs.iter().any(|c| c.name == r.config) {
                return Err(bad(SnapshotDefect::UnknownConfig { run: r.label() }));
            }
            if !s.inputs.iter().any(|i| i.name == r.mesh) {
                return Err(bad(SnapshotDefect::UnknownInput { run: r.label() }));
            }
        }
        Ok(s)
    }

    /// The grid that reruns this snapshot, and its cells in the snapshot's order.
    pub fn grid(&self, exe: PathBuf, jobs: usize) -> (Grid, Vec<Job>) {
        let grid = Grid {
            exe,
            configs: self.configs.clone(),
            inputs: self
                .inputs
                .iter()
                .map(|i| Input {
                    path: i.path.clone(),
                    name: i.name.clone(),
                })
                .collect(),
            seeds: self.seeds.clone(),
            timeout: std::time::Duration::from_secs_f64(self.timeout_s),
            jobs,
            pictures: false,
        };
        let cells = self
            .runs
            .iter()
            .map(|r| Job {
                config: self
                    .configs
                    .iter()
                    .position(|c| c.name == r.config)
                    .unwrap_or(0),
                input: self
                    .inputs
                    .iter()
                    .position(|i| i.name == r.mesh)
                    .unwrap_or(0),
                seed: r.seed,
            })
            .collect();
        (grid, cells)
    }

    /// Every difference of `now` (the rerun, with the same runs in the same order) from this
    /// snapshot: the inputs' bytes, and per run the status, the output's bytes, every
    /// measure and every resolved option.
    pub fn drift(&self, now: &Snapshot) -> Vec<Drift> {
        let mut out = Vec::new();
        for (a, b) in self.inputs.iter().zip(&now.inputs) {
            if a.sha256 != b.sha256 {
                out.push(Drift {
                    what: format!("input {}", a.path.display()),
                    field: "sha256".into(),
                    was: a.sha256.clone(),
                    now: b.sha256.clone(),
                });
            }
        }
        for (a, b) in self.runs.iter().zip(&now.runs) {
            let mut d = |field: String, was: String, now: String| {
                out.push(Drift {
                    what: a.label(),
                    field,
                    was,
                    now,
                })
            };
            if a.status != b.status {
                d("status".into(), a.status.to_string(), b.status.to_string());
            }
            if a.output_sha256 != b.output_sha256 {
                d(
                    "output_sha256".into(),
                    a.output_sha256.clone().unwrap_or_else(|| "none".into()),
                    b.output_sha256.clone().unwrap_or_else(|| "none".into()),
                );
            }
            let keys: std::collections::BTreeSet<&String> =
                a.measures.keys().chain(b.measures.keys()).collect();
            for k in keys {
                let (x, y) = (a.measures.get(k), b.measures.get(k));
                if !same_number(x, y) {
                    d(format!("measures.{k}"), number(x), number(y));
                }
            }
            let (mut fa, mut fb) = (BTreeMap::new(), BTreeMap::new());
            flatten("options", a.options.as_ref(), &mut fa);
            flatten("options", b.options.as_ref(), &mut fb);
            let keys: std::collections::BTreeSet<&String> = fa.keys().chain(fb.keys()).collect();
            for k in keys {
                let (x, y) = (fa.get(k), fb.get(k));
                if x != y {
                    let show = |v: Option<&String>| v.cloned().unwrap_or_else(|| "absent".into());
                    d(k.clone(), show(x), show(y));
                }
            }
        }
        out
    }
}

fn run_of(r: &RunRecord) -> SnapshotRun {
    let measures = r
        .result
        .as_ref()
        .map(|res| {
            MEASURES
                .iter()
                .filter(|m| m.deterministic)
                .filter_map(|m| {
                    let v = *res.measures.get(m.key)?;
                    v.is_finite().then(|| (m.key.to_string(), v))
                })
                .collect()
        })
        .unwrap_or_default();
    SnapshotRun {
        config: r.config.clone(),
        mesh: r.mesh.clone(),
        seed: r.seed,
        status: r.status,
        output_sha256: r.output_sha256.clone(),
        options: r.result.as_ref().map(|res| res.options.clone()),
        measures,
    }
}

/// Equal up to the last bits a JSON round trip may change (the output's bytes are compared
/// exactly by their hash).
fn same_number(a: Option<&f64>, b: Option<&f64>) -> bool {
    match (a, b) {
        (Some(x), Some(y)) => x == y || (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(1e-300),
        (None, None) => true,
        _ => false,
    }
}

fn number(v: Option<&f64>) -> String {
    v.map_or("absent".into(), |x| format!("{x}"))
}

/// `{"a": {"b": 1}}` → `prefix.a.b = 1`, lists by index.
fn flatten(prefix: &str, v: Option<&serde_json::Value>, out: &mut BTreeMap<String, String>) {
    match v {
        None => {}
        Some(serde_json::Value::Object(m)) => {
            for (k, x) in m {
                flatten(&format!("{prefix}.{k}"), Some(x), out);
            }
        }
        Some(serde_json::Value::Array(a)) => {
            for (i, x) in a.iter().enumerate() {
                flatten(&format!("{prefix}.{i}"), Some(x), out);
            }
        }
        Some(x) => {
            out.insert(prefix.to_string(), x.to_string());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(sha: &str, q: f64, sweeps: u64) -> SnapshotRun {
        SnapshotRun {
            config: "cone".into(),
            mesh: "torus".into(),
            seed: 1,
            status: Status::Ok,
            output_sha256: Some(sha.into()),
            options: Some(serde_json::json!({"options": {"sweeps": sweeps}})),
            measures: [("q_avg".to_string(), q)].into_iter().collect(),
        }
    }

    fn snap(r: SnapshotRun) -> Snapshot {
        Snapshot {
            format: FORMAT.into(),
            conemesh: Build::current(),
            timeout_s: 10.0,
            inputs: vec![SnapshotInput {
                name: "torus".into(),
                path: "/t.off".into(),
                sha256: "ab".into(),
            }],
            configs: vec![Config::new("cone", vec![]).expect("config")],
            seeds: vec![1],
            runs: vec![r],
        }
    }

    #[test]
    fn drift_names_the_run_and_every_field_that_differs() {
        let a = snap(run("00", 0.9, 3));
        assert!(a.drift(&a.clone()).is_empty());
        let b = snap(run("11", 0.8, 2));
        let d: Vec<String> = a.drift(&b).iter().map(|d| d.field.clone()).collect();
        assert_eq!(
            d,
            ["output_sha256", "measures.q_avg", "options.options.sweeps"]
        );
        assert!(a.drift(&b)[2]
            .to_string()
            .starts_with("cone/torus/seed 1: options.options.sweeps: snapshot 3, now 2"));
    }

    #[test]
    fn a_snapshot_round_trips_and_bad_files_are_refused() -> Result<(), Box<dyn std::error::Error>>
    {
        let dir = tempfile::tempdir()?;
        let p = dir.path().join("snapshot.json");
        let a = snap(run("00", 0.877_963_397_645_883_3, 3));
        std::fs::write(&p, serde_json::to_string_pretty(&a)?)?;
        let back = Snapshot::read(&p)?;
        assert!(a.drift(&back).is_empty());
        std::fs::write(&p, "{\"format\": 1}")?;
        let e = Snapshot::read(&p).unwrap_err().to_string();
        assert!(e.contains("snapshot.json"), "{e}");
        let mut other = a.clone();
        other.runs[0].config = "nope".into();
        std::fs::write(&p, serde_json::to_string(&other)?)?;
        let e = Snapshot::read(&p).unwrap_err().to_string();
        assert!(e.contains("names no listed configuration"), "{e}");
        Ok(())
    }
}
