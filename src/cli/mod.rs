//! One file per subcommand: `XArgs` (clap) and `run(XArgs) -> anyhow::Result<ExitCode>`.

pub mod bench;
pub mod check;
pub mod convert;
pub mod eval;
pub mod param;
pub mod patches;
pub mod remesh;
pub mod stages;

/// `--threads N`: the size of rayon's global pool (before any parallel work of the process).
pub fn set_threads(n: usize) -> anyhow::Result<()> {
    anyhow::ensure!(n >= 1, "--threads must be at least 1 (got {n})");
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| anyhow::anyhow!("cannot start {n} worker threads: {e}"))
}
