//! `conemesh eval` (in progress).

use std::process::ExitCode;

/// Arguments of `conemesh eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {}

/// Run `conemesh eval`.
pub fn run(_args: EvalArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`conemesh eval` is not available in this build yet")
}
