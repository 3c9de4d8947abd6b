//! The whole job of `conemesh remesh` and of the Python package's `remesh`: the input
//! repaired when asked ([`JobInput::prepare`]), Algorithm 1 from file units
//! ([`Remesher`]), the yardstick ([`quality::evaluate`](crate::quality::evaluate)), the
//! report, and the files beside the mesh as one transaction ([`Outcome::stage_files`]).
//! The front ends parse and print only; [`args::RemeshArgs`] is the one argument vocabulary
//! both parse.
//!
//! ```no_run
//! use conemesh::job::{Job, JobInput, OutputFiles, Source};
//! use conemesh::pipeline::{RemeshOptions, Remesher};
//! let loaded = conemesh::io::read_mesh(std::path::Path::new("bunny.off"))?;
//! let job = Job::new(Remesher::new(RemeshOptions::default())).with_repair(Default::default());
//! let outcome = job.run(JobInput::new(loaded.mesh, None), |_| {})?;
//! println!("{}", outcome.eval.table_row("bunny"));
//! let files = OutputFiles {
//!     mesh: Some("bunny-remeshed.obj".into()),
//!     report: Some("bunny.json".into()),
//!     ..Default::default()
//! };
//! let mut outputs = conemesh::io::Outputs::new();
//! outcome.stage_files(&mut outputs, &files, &Source::Arrays)?;
//! conemesh::io::paths::commit(outputs)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod args;
mod files;
mod progress;

pub use args::{ArgsError, RemeshArgs};
pub use files::{FilesError, OutputFiles};
pub use progress::ProgressBar;

use crate::io::{Outputs, RepeatedIndexFace};
use crate::mesh::TriMesh;
use crate::pipeline::{PipelineError, Progress, Remeshed, Remesher};
use crate::quality::{EvalError, EvalOptions, EvalReport};
use crate::repair::{RepairError, RepairLog, RepairOptions};
use nalgebra::Matrix3;
use std::path::Path;
use std::time::Instant;

/// The input of a job, as read.
pub struct JobInput {
    /// The mesh, in file units.
    pub mesh: TriMesh,
    /// A user metric: one symmetric tensor per vertex of `mesh`, in file units.
    pub metric: Option<Vec<Matrix3<f64>>>,
    /// The file faces the reader left out for using a vertex twice (listed in the repair
    /// log).
    pub repeated_index_faces: Vec<RepeatedIndexFace>,
    /// When the job began: the report's `seconds` run from here to the end of Algorithm 1
    /// (the command line starts the clock before it reads the file).
    pub started: Instant,
}

/// The input a run remeshes: the mesh (repaired when asked), the user's tensors (carried to
/// the repaired vertices), and the repair's log.
pub struct Prepared {
    /// The mesh, in file units.
    pub mesh: TriMesh,
    /// One tensor per vertex of `mesh`.
    pub metric: Option<Vec<Matrix3<f64>>>,
    /// What the repair changed; `None` without one.
    pub repair: Option<RepairLog>,
    /// When the job began.
    pub started: Instant,
}

/// A job: Algorithm 1 with its options and stages, after a repair of the input when asked.
pub struct Job {
    /// Algorithm 1 from file units.
    pub remesher: Remesher,
    /// Repair the input first (`--repair`); `None`: the input must be an oriented manifold.
    pub repair: Option<RepairOptions>,
}

/// What a job made.
pub struct Outcome {
    /// The mesh that was remeshed (the repaired input with a repair), in file units.
    pub input: TriMesh,
    /// What the repair changed; `None` without one.
    pub repair: Option<RepairLog>,
    /// The output and everything Algorithm 1 recorded.
    pub remeshed: Remeshed,
    /// The yardstick: `conemesh eval` of the output against the input at the run's target.
    pub eval: EvalReport,
    /// Seconds from [`JobInput::started`] to the end of Algorithm 1.
    pub seconds: f64,
}

/// Where the input came from, as the report names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// A mesh file.
    File {
        /// The input as printed (its path, or "built-in torus").
        name: String,
        /// The first column of the Table-1 row and the plots' title (the file's stem).
        short_name: String,
        /// Polygons the reader cut into triangles.
        polygons_triangulated: usize,
    },
    /// Arrays from a program (the Python package): no names, and the report carries the
    /// Table-1 line (`table_header`, `table_row` named `remesh`) a terminal would print.
    Arrays,
}

impl Source {
    /// The Table-1 row's first column and the plots' title.
    pub fn short_name(&self) -> &str {
        match self {
            Source::File { short_name, .. } => short_name,
            Source::Arrays => "remesh",
        }
    }
}

/// A job that failed, by step.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The repair of the input.
    #[error(transparent)]
    Repair(#[from] RepairError),
    /// Algorithm 1.
    #[error(transparent)]
    Remesh(#[from] PipelineError),
    /// The yardstick.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

impl JobInput {
    /// A mesh and an optional user metric (one tensor per vertex, file units); the clock
    /// starts now.
    pub fn new(mesh: TriMesh, metric: Option<Vec<Matrix3<f64>>>) -> JobInput {
        JobInput {
            mesh,
            metric,
            repeated_index_faces: Vec::new(),
            started: Instant::now(),
        }
    }

    /// The input repaired with `repair` (the log lists the faces the reader left out), the
    /// user's tensors carried to the repaired vertices; with `None`, the input as read.
    pub fn prepare(self, repair: Option<&RepairOptions>) -> Result<Prepared, RepairError> {
        let Some(options) = repair else {
            return Ok(Prepared {
                mesh: self.mesh,
                metric: self.metric,
                repair: None,
                started: self.started,
            });
        };
        let mut r = crate::repair::repair(&self.mesh, options)?;
        r.log.repeated_index_faces = self.repeated_index_faces;
        Ok(Prepared {
            metric: self.metric.map(|m| r.vertex_values(&m)),
            mesh: r.mesh,
            repair: Some(r.log),
            started: self.started,
        })
    }
}

impl Job {
    /// A job without a repair.
    pub fn new(remesher: Remesher) -> Job {
        Job {
            remesher,
            repair: None,
        }
    }

    /// The same, repairing the input first.
    pub fn with_repair(self, options: RepairOptions) -> Job {
        Job {
            repair: Some(options),
            ..self
        }
    }

    /// The whole job: [`JobInput::prepare`] with the job's repair, then [`Job::remesh`].
    pub fn run(
        &self,
        input: JobInput,
        on_progress: impl FnMut(Progress),
    ) -> Result<Outcome, JobError> {
        let prepared = input.prepare(self.repair.as_ref())?;
        self.remesh(prepared, on_progress)
    }

    /// Algorithm 1 on a prepared input, reporting progress after every patch, then the
    /// yardstick at the run's target (self-intersections left to the pipeline's exact
    /// certificate).
    pub fn remesh(
        &self,
        input: Prepared,
        on_progress: impl FnMut(Progress),
    ) -> Result<Outcome, JobError> {
        let remeshed = self
            .remesher
            .run_with(&input.mesh, input.metric.as_deref(), on_progress)?;
        let seconds = input.started.elapsed().as_secs_f64();
        let eval_options = EvalOptions {
            target: self.remesher.options.target,
            self_intersections: false,
            ..EvalOptions::default()
        };
        let eval = crate::quality::evaluate(
            &remeshed.input,
            &remeshed.mesh,
            remeshed.input_metric.as_deref(),
            &eval_options,
        )?;
        Ok(Outcome {
            input: input.mesh,
            repair: input.repair,
            remeshed,
            eval,
            seconds,
        })
    }
}

impl Outcome {
    /// The `--report` document: where the input came from and the output went, the time and
    /// peak memory, the repair log, the run's own report and the yardstick's.
    pub fn report(&self, source: &Source, output: Option<&Path>) -> serde_json::Value {
        let mut doc = serde_json::json!({
            // A path the OS accepts need not be UTF-8: the report holds it lossily.
            "output": output.map(|p| p.to_string_lossy()),
            "seconds": self.seconds,
            "peak_rss_mib": peak_rss_mib(),
            "repair": self.repair,
            "run": self.remeshed.unit.report,
            "eval": self.eval,
        });
        let extra = match source {
            Source::File {
                name,
                polygons_triangulated,
                ..
            } => serde_json::json!({
                "input": name,
                "polygons_triangulated": polygons_triangulated,
            }),
            Source::Arrays => serde_json::json!({
                "input": null,
                "table_header": EvalReport::table_header(),
                "table_row": self.eval.table_row(source.short_name()),
            }),
        };
        if let (Some(doc), serde_json::Value::Object(extra)) = (doc.as_object_mut(), extra) {
            doc.extend(extra);
        }
        doc
    }

    /// Stage the job's files into `outputs` for the one commit: the mesh first, then the
    /// report (built after the mesh is staged, so its peak memory counts the writing), the
    /// metrics, the patches and the plots. Returns the report.
    pub fn stage_files(
        &self,
        outputs: &mut Outputs,
        files: &OutputFiles,
        source: &Source,
    ) -> Result<serde_json::Value, FilesError> {
        if let Some(p) = &files.mesh {
            let (read, write) = (Default::default(), Default::default());
            outputs
                .mesh(p, &self.remeshed.mesh, &read, &write)
                .map_err(|source| FilesError::Write {
                    path: p.clone(),
                    source: Box::new(source),
                })?;
        }
        let report = self.report(source, files.mesh.as_deref());
        files::stage_side_files(
            outputs,
            files,
            &self.remeshed,
            &self.eval,
            &report,
            source.short_name(),
        )?;
        Ok(report)
    }
}

/// This process's peak resident memory in MiB (`VmHWM` of `/proc/self/status`, in kB; `None`
/// where there is no such file, i.e. off Linux).
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::paths::OutputPathError;
    use clap::Parser;
    use std::path::PathBuf;

    type R = Result<(), Box<dyn std::error::Error>>;

    /// `conemesh remesh FLAGS` as the front ends parse it.
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: RemeshArgs,
    }

    fn args(flags: &[&str]) -> Result<RemeshArgs, clap::Error> {
        let argv = std::iter::once("remesh").chain(flags.iter().copied());
        Ok(Cli::try_parse_from(argv)?.args)
    }

    /// A small torus with every third face reversed: an oriented manifold only after a repair.
    fn shuffled_torus() -> TriMesh {
        let mut m = crate::mesh::generators::torus(1.0, 0.4, 16, 8);
        for (f, t) in m.triangles.iter_mut().enumerate() {
            if f % 3 == 2 {
                t.swap(0, 1);
            }
        }
        m
    }

    #[test]
    fn a_repair_job_orients_the_input_scores_the_output_and_reports_both() -> R {
        let job = args(&["--repair", "-q", "--improvers", "none"])?.job(false)?;
        let outcome = job.run(JobInput::new(shuffled_torus(), None), |_| {})?;
        let log = outcome.repair.as_ref().ok_or("a repair log")?;
        assert!(!log.flipped_faces.is_empty());
        let topo = crate::Topology::build(&outcome.input);
        crate::invariants::certify_oriented(&outcome.input, &topo)?;
        assert_eq!(outcome.eval.output.faces, outcome.remeshed.mesh.n_faces());
        assert_eq!(outcome.eval.input.faces, outcome.input.n_faces());

        let file = Source::File {
            name: "t.off".into(),
            short_name: "t".into(),
            polygons_triangulated: 3,
        };
        let doc = outcome.report(&file, Some(Path::new("out.obj")));
        assert_eq!(doc["input"], "t.off");
        assert_eq!(doc["output"], "out.obj");
        assert_eq!(doc["polygons_triangulated"], 3);
        let flipped = doc["repair"]["flipped_faces"].as_array().map(Vec::len);
        assert_eq!(flipped, Some(log.flipped_faces.len()));
        assert!(doc.get("table_row").is_none());
        let arrays = outcome.report(&Source::Arrays, None);
        assert!(arrays["input"].is_null() && arrays["output"].is_null());
        assert!(arrays.get("polygons_triangulated").is_none());
        assert_eq!(arrays["table_row"], outcome.eval.table_row("remesh"));
        Ok(())
    }

    #[test]
    fn without_a_repair_the_shuffled_input_is_refused_by_algorithm_1() -> R {
        let job = args(&["-q"])?.job(false)?;
        let refused = job.run(JobInput::new(shuffled_torus(), None), |_| {});
        assert!(matches!(refused, Err(JobError::Remesh(_))));
        Ok(())
    }

    #[test]
    fn output_paths_that_meet_are_refused_naming_both_flags() -> R {
        let dir = tempfile::tempdir()?;
        let report = dir.path().join("r.json");
        let files = OutputFiles {
            report: Some(report.clone()),
            metric: Some(report.clone()),
            ..Default::default()
        };
        let e = files.check(&[]).err().ok_or("refused")?;
        assert!(matches!(
            e,
            OutputPathError::SamePath {
                flag: "--write-metric",
                other: "--report",
                ..
            }
        ));
        let files = OutputFiles {
            report: Some(report.clone()),
            ..Default::default()
        };
        let e = files
            .check(&[("the input", &report)])
            .err()
            .ok_or("refused")?;
        assert!(matches!(
            e,
            OutputPathError::SamePath {
                flag: "--report",
                other: "the input",
                ..
            }
        ));
        let files = OutputFiles {
            report: Some(report.clone()),
            plots: Some(report),
            ..Default::default()
        };
        let e = files.check(&[]).err().ok_or("refused")?;
        assert!(matches!(
            e,
            OutputPathError::SamePath {
                flag: "--plots",
                other: "--report",
                ..
            }
        ));
        let missing = OutputFiles {
            mesh: Some(PathBuf::from("/no/such/folder/out.obj")),
            ..Default::default()
        };
        let e = missing.check(&[]).err().ok_or("refused")?;
        assert!(matches!(e, OutputPathError::NoFolder { flag: "-o", .. }));
        Ok(())
    }

    #[test]
    fn improver_options_must_fit_the_improvers_that_run() -> R {
        let e = args(&["--improvers", "surface", "--improver-opt", "eq5.q=0.7"])?
            .job(false)
            .err()
            .ok_or("refused")?;
        assert_eq!(
            e,
            ArgsError::ImproverNotRun {
                item: "eq5.q=0.7".into(),
                name: "eq5".into(),
                running: vec!["surface".into()],
            }
        );
        let e = args(&["--improver-opt", "eq5q=1"])?
            .job(false)
            .err()
            .ok_or("refused")?;
        assert_eq!(
            e,
            ArgsError::ImproverOptForm {
                item: "eq5q=1".into()
            }
        );
        Ok(())
    }
}
