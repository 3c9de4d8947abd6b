//! `conemesh check` (in progress).

use std::process::ExitCode;

/// Arguments of `conemesh check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {}

/// Run `conemesh check`.
pub fn run(_args: CheckArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`conemesh check` is not available in this build yet")
}
