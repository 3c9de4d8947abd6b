//! One file per subcommand: `XArgs` (clap) and `run(XArgs) -> anyhow::Result<ExitCode>`.

pub mod bench;
pub mod check;
pub mod compare;
pub mod convert;
pub mod eval;
pub mod param;
pub mod patches;
pub mod remesh;
pub mod render;
pub mod stages;

pub use conemesh::io::paths::{check_file_output, check_plots_folder, commit, same_path};
