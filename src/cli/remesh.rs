//! `conemesh remesh` (in progress).

use std::process::ExitCode;

/// Arguments of `conemesh remesh`.
#[derive(clap::Args, Debug)]
pub struct RemeshArgs {}

/// Run `conemesh remesh`.
pub fn run(_args: RemeshArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`conemesh remesh` is not available in this build yet")
}
