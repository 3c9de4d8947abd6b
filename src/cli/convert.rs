//! `conemesh convert` (in progress).

use std::process::ExitCode;

/// Arguments of `conemesh convert`.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {}

/// Run `conemesh convert`.
pub fn run(_args: ConvertArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`conemesh convert` is not available in this build yet")
}
