//! `conemesh patches` (in progress).

use std::process::ExitCode;

/// Arguments of `conemesh patches`.
#[derive(clap::Args, Debug)]
pub struct PatchesArgs {}

/// Run `conemesh patches`.
pub fn run(_args: PatchesArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`conemesh patches` is not available in this build yet")
}
