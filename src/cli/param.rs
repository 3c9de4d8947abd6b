//! `conemesh param` (in progress).

use std::process::ExitCode;

/// Arguments of `conemesh param`.
#[derive(clap::Args, Debug)]
pub struct ParamArgs {}

/// Run `conemesh param`.
pub fn run(_args: ParamArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`conemesh param` is not available in this build yet")
}
