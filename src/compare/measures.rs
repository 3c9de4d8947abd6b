//! What a comparison measures of one run, read from its `conemesh remesh --report` file: the
//! Table-1 row in the metric (Sec. 4.1), the distance to the input, flips, certificate
//! retries, faces, and the machine's time and peak memory.

use super::stats::Better;
use super::{CompareError, ReportDefect};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One measure: its key (in `compare.json` and the snapshot), its column heading, which way
/// is better, how many decimals a table shows and whether it is a property of the result
/// (the same bytes give the same value) rather than of the machine.
#[derive(Clone, Copy, Debug)]
pub struct Measure {
    /// key in the JSON files
    pub key: &'static str,
    /// column heading
    pub label: &'static str,
    /// which way wins
    pub better: Better,
    /// decimals shown
    pub digits: usize,
    /// a property of the output (false: of the machine, left out of snapshots)
    pub deterministic: bool,
    /// where the report holds it
    path: &'static [&'static str],
    /// how the report's value is turned into the measure
    kind: Kind,
}

/// How a report's value becomes a measure.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// a number as it is
    Number,
    /// a fraction shown in %
    Percent,
    /// the length of a list
    Count,
}

const fn m(
    key: &'static str,
    label: &'static str,
    better: Better,
    digits: usize,
    deterministic: bool,
    path: &'static [&'static str],
    kind: Kind,
) -> Measure {
    Measure {
        key,
        label,
        better,
        digits,
        deterministic,
        path,
        kind,
    }
}

use Better::{Higher, Lower};
use Kind::{Count, Number, Percent};

/// Every measure, in table order: the Table-1 row (q and the angles in the metric, of the
/// output against the run's target, from `eval`), the Hausdorff distance in % of the input's
/// bounding-box diagonal, flipped faces, patch attempts that failed a certificate and were
/// retried smaller, output faces, and the run's own time and peak resident memory.
pub const MEASURES: [Measure; 12] = [
    m(
        "q_min",
        "q_min",
        Higher,
        3,
        true,
        &["eval", "output_quality", "q_min"],
        Number,
    ),
    m(
        "q_max",
        "q_max",
        Higher,
        3,
        true,
        &["eval", "output_quality", "q_max"],
        Number,
    ),
    m(
        "q_avg",
        "q_avg",
        Higher,
        3,
        true,
        &["eval", "output_quality", "q_avg"],
        Number,
    ),
    m(
        "theta_min",
        "θ_min°",
        Higher,
        2,
        true,
        &["eval", "output_quality", "theta_min"],
        Number,
    ),
    m(
        "theta_max",
        "θ_max°",
        Lower,
        2,
        true,
        &["eval", "output_quality", "theta_max"],
        Number,
    ),
    m(
        "theta_avg",
        "θ_avg°",
        Higher,
        2,
        true,
        &["eval", "output_quality", "theta_avg"],
        Number,
    ),
    m(
        "hausdorff_pct",
        "Hausdorff %",
        Lower,
        3,
        true,
        &["eval", "distance", "hausdorff_rel"],
        Percent,
    ),
    m("flips", "flips", Lower, 1, true, &["eval", "flips"], Count),
    m(
        "cert_retries",
        "cert. retries",
        Lower,
        1,
        true,
        &["run", "fallbacks", "failures"],
        Count,
    ),
    m(
        "faces_out",
        "faces",
        Lower,
        0,
        true,
        &["run", "faces_out"],
        Number,
    ),
    m("seconds", "time s", Lower, 2, false, &["seconds"], Number),
    m(
        "peak_mib",
        "peak MiB",
        Lower,
        0,
        false,
        &["peak_rss_mib"],
        Number,
    ),
];

/// The measure of key `key`.
pub fn measure(key: &str) -> Option<&'static Measure> {
    MEASURES.iter().find(|m| m.key == key)
}

/// What one successful run gave, from its report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// every measure of [`MEASURES`] by key
    pub measures: BTreeMap<String, f64>,
    /// the resolved options of the run (`run.options` without the debug folder, which names
    /// the output's folder; `run.stages`; `run.improvers`)
    pub options: serde_json::Value,
    /// the histograms of the output's quality (q, angles, smallest angles)
    pub quality: crate::quality::QualityStats,
}

impl RunResult {
    /// Read a `conemesh remesh --report` document; `path` names it in errors.
    pub fn from_report(json: &serde_json::Value, path: &str) -> Result<RunResult, CompareError> {
        let bad = |defect: ReportDefect| CompareError::Report {
            path: path.to_string(),
            defect,
        };
        let mut measures = BTreeMap::new();
        for m in &MEASURES {
            let v = m
                .path
                .iter()
                .try_fold(json, |v, k| v.get(k))
                .ok_or_else(|| bad(ReportDefect::Missing(m.path)))?;
            let x = match m.kind {
                Kind::Number => v.as_f64(),
                Kind::Percent => v.as_f64().map(|x| 100.0 * x),
                Kind::Count => v.as_array().map(|a| a.len() as f64),
            }
            .ok_or_else(|| {
                bad(ReportDefect::WrongType {
                    path: m.path,
                    kind: m.kind,
                })
            })?;
            measures.insert(m.key.to_string(), x);
        }
        let run = json
            .get("run")
            .ok_or_else(|| bad(ReportDefect::Missing(&["run"])))?;
        let mut opts = run
            .get("options")
            .cloned()
            .ok_or_else(|| bad(ReportDefect::Missing(&["run", "options"])))?;
        if let Some(o) = opts.as_object_mut() {
            o.remove("debug_dir");
        }
        let options = serde_json::json!({
            "options": opts,
            "stages": run.get("stages"),
            "improvers": run.get("improvers"),
        });
        let quality = json
            .pointer("/eval/output_quality")
            .cloned()
            .ok_or_else(|| bad(ReportDefect::Missing(&["eval", "output_quality"])))
            .and_then(|q| serde_json::from_value(q).map_err(|e| bad(ReportDefect::Quality(e))))?;
        Ok(RunResult {
            measures,
            options,
            quality,
        })
    }
}
