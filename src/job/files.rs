//! The files a job writes: the mesh and the files beside it (`--report`, `--write-metric`,
//! `--write-input-metric`, `--write-patches`, `--plots`), checked before any work and staged
//! into one [`Outputs`] transaction after it.

use crate::io::paths::{check_file_output, check_plots_folder, same_path, OutputPathError};
use crate::io::sol::SolError;
use crate::io::{IoError, Outputs};
use crate::pipeline::Remeshed;
use crate::quality::EvalReport;
use crate::render::RenderError;
use crate::report::ReportError;
use std::path::{Path, PathBuf};

/// The files of a job; `None`: not written.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct OutputFiles {
    /// The output mesh (`-o`); the format follows the extension.
    pub mesh: Option<PathBuf>,
    /// The report as JSON (`--report`).
    pub report: Option<PathBuf>,
    /// The metric at the output vertices, Medit .sol (`--write-metric`).
    pub metric: Option<PathBuf>,
    /// The patch of each output face (`--write-patches`).
    pub patches: Option<PathBuf>,
    /// The run's metric at the input vertices over L_tar², Medit .sol
    /// (`--write-input-metric`).
    pub input_metric: Option<PathBuf>,
    /// A folder of quality histograms and the picture `mesh.png` (`--plots`).
    pub plots: Option<PathBuf>,
}

/// A file of the job that could not be staged.
#[derive(Debug, thiserror::Error)]
pub enum FilesError {
    /// A metric that cannot be written as .sol.
    #[error(transparent)]
    Sol(#[from] SolError),
    /// The report that cannot be encoded.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A file that cannot be staged.
    #[error("writing {}", path.display())]
    Write {
        /// the destination
        path: PathBuf,
        /// why
        #[source]
        source: Box<IoError>,
    },
    /// The plots folder that cannot be staged.
    #[error("writing plots into {}", dir.display())]
    PlotsFolder {
        /// the destination folder
        dir: PathBuf,
        /// why
        #[source]
        source: Box<IoError>,
    },
    /// A histogram that cannot be drawn or written.
    #[error("writing plots into {}", dir.display())]
    Plot {
        /// the destination folder
        dir: PathBuf,
        /// why
        #[source]
        source: ReportError,
    },
    /// The picture of the output that cannot be drawn.
    #[error("drawing {}", path.display())]
    Draw {
        /// the picture's destination
        path: PathBuf,
        /// why
        #[source]
        source: RenderError,
    },
    /// The picture of the output that cannot be written.
    #[error("writing {}", path.display())]
    Picture {
        /// the picture's destination
        path: PathBuf,
        /// why
        #[source]
        source: std::io::Error,
    },
}

impl OutputFiles {
    /// Every output path, checked before any work (issue 20): each file's folder exists, no
    /// file output is a directory, `--plots` is not a regular file and its folder exists, and
    /// no two outputs (nor an output and one of `inputs`, named by their flag) are the same
    /// path.
    pub fn check(&self, inputs: &[(&'static str, &Path)]) -> Result<(), OutputPathError> {
        let files = self.named_files();
        for (flag, p) in &files {
            check_file_output(flag, p)?;
        }
        if let Some(d) = &self.plots {
            check_plots_folder("--plots", d)?;
            if let Some((flag, _)) = files.iter().find(|(_, p)| same_path(p, d)) {
                return Err(OutputPathError::SamePath {
                    flag: "--plots",
                    path: d.clone(),
                    other: flag,
                });
            }
        }
        for (i, (flag, p)) in files.iter().enumerate() {
            for (other, q) in files[..i].iter().chain(inputs) {
                if same_path(p, q) {
                    return Err(OutputPathError::SamePath {
                        flag,
                        path: p.to_path_buf(),
                        other,
                    });
                }
            }
        }
        Ok(())
    }

    /// The file outputs (not `--plots`) with their flags, in the order they are checked.
    fn named_files(&self) -> Vec<(&'static str, &Path)> {
        [
            ("-o", &self.mesh),
            ("--report", &self.report),
            ("--write-metric", &self.metric),
            ("--write-patches", &self.patches),
            ("--write-input-metric", &self.input_metric),
        ]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect()
    }
}

/// Stage `bytes` for `path`.
fn stage_bytes(outputs: &mut Outputs, path: &Path, bytes: &[u8]) -> Result<(), FilesError> {
    outputs
        .bytes(path, bytes)
        .map_err(|source| FilesError::Write {
            path: path.to_path_buf(),
            source: Box::new(source),
        })
}

/// The files beside the mesh, staged into `outputs`: the metrics, the patches, `report` as
/// `--report`'s document, and the plots (named `short_name`).
pub(super) fn stage_side_files(
    outputs: &mut Outputs,
    files: &OutputFiles,
    out: &Remeshed,
    eval: &EvalReport,
    report: &serde_json::Value,
    short_name: &str,
) -> Result<(), FilesError> {
    if let Some(p) = &files.metric {
        let bytes = crate::io::sol::sol_bytes(p, &out.output_metric(), false)?;
        stage_bytes(outputs, p, &bytes)?;
    }
    if let Some(p) = &files.input_metric {
        let bytes = crate::io::sol::sol_bytes(p, &out.input_metric_unit_target(), false)?;
        stage_bytes(outputs, p, &bytes)?;
    }
    if let Some(p) = &files.patches {
        let bytes = crate::io::patches::face_patches_bytes(&out.unit.face_patch);
        stage_bytes(outputs, p, &bytes)?;
    }
    if let Some(p) = &files.report {
        stage_bytes(outputs, p, serde_json::to_string_pretty(report)?.as_bytes())?;
    }
    if let Some(dir) = &files.plots {
        stage_plots(outputs, dir, out, eval, short_name)?;
    }
    Ok(())
}

/// `--plots`: the quality histograms of input and output, the picture of the output coloured
/// by q in the run's metric, and with an improver the smallest angles before and after it.
fn stage_plots(
    outputs: &mut Outputs,
    dir: &Path,
    out: &Remeshed,
    eval: &EvalReport,
    short_name: &str,
) -> Result<(), FilesError> {
    let plot_error = |source| FilesError::Plot {
        dir: dir.to_path_buf(),
        source,
    };
    let staged = outputs.dir(dir).map_err(|source| FilesError::PlotsFolder {
        dir: dir.to_path_buf(),
        source: Box::new(source),
    })?;
    crate::report::write_quality_plots(
        &staged,
        short_name,
        &[
            ("input", &eval.input_quality),
            ("output", &eval.output_quality),
        ],
    )
    .map_err(plot_error)?;
    let colors = crate::render::quality_face_colors(
        &out.mesh,
        &out.output_metric(),
        crate::render::ColorBy::Q,
    );
    let picture = dir.join("mesh.png");
    let draw_error = |source| FilesError::Draw {
        path: picture.clone(),
        source,
    };
    let (img, _) =
        crate::render::render(&out.mesh, &colors, &Default::default()).map_err(draw_error)?;
    let bytes = img.png().map_err(draw_error)?;
    std::fs::write(staged.join("mesh.png"), bytes).map_err(|source| FilesError::Picture {
        path: picture.clone(),
        source,
    })?;
    if let Some(i) = &out.unit.report.improvement {
        crate::report::write_improvement_plot(
            &staged,
            short_name,
            &i.before.hist_min_angles,
            &i.after.hist_min_angles,
            (i.before.theta_min, i.after.theta_min),
        )
        .map_err(plot_error)?;
    }
    Ok(())
}
