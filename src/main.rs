//! The `conemesh` command line: parses arguments, calls the library, prints. No geometry
//! here. Each subcommand lives in its own file under `src/cli/`.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod cli;

/// Anisotropic surface remeshing by locally isometric embedding, with certified invariants.
#[derive(Parser, Debug)]
#[command(name = "conemesh", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per process: boxing the large argument structs would buy nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand, Debug)]
enum Command {
    /// Benchmark `remesh` on a folder of meshes (the shared meshes): quality, Hausdorff
    /// distance, time and peak memory per mesh, as a Markdown table; with `--suite analytic`,
    /// conemesh and MMG side by side on generated surfaces with user-style metrics.
    Bench(cli::bench::BenchArgs),
    /// Check a mesh: topology, manifoldness, degenerate faces, self-intersections.
    Check(cli::check::CheckArgs),
    /// Compare named configurations of `remesh` over inputs × seeds, one process per run:
    /// Table-1 rows as mean ± sd, paired statistics against the first configuration, plots,
    /// a static HTML page and a snapshot; `--check snapshot.json` reruns a snapshot.
    Compare(cli::compare::CompareArgs),
    /// Convert a mesh between formats (by file extension).
    Convert(cli::convert::ConvertArgs),
    /// Score a remeshed surface against its input (Table-1 quality, fidelity, validity).
    #[command(allow_negative_numbers = true)]
    Eval(cli::eval::EvalArgs),
    /// Cover a mesh with patches (no remeshing) and report them.
    Patches(cli::patches::PatchesArgs),
    /// Parameterize a disk-topology mesh bijectively into the plane.
    Param(cli::param::ParamArgs),
    /// Remesh a surface anisotropically (Algorithm 1).
    #[command(allow_negative_numbers = true)]
    Remesh(cli::remesh::RemeshArgs),
    /// Draw a mesh as a PNG: front, side and iso views, faces coloured by q, smallest angle,
    /// patch or distance to a reference, with a colour bar.
    Render(cli::render::RenderArgs),
    /// List the registered patch strategies, parameterizers and planar remeshers.
    Stages(cli::stages::StagesArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Bench(a) => cli::bench::run(a),
        Command::Check(a) => cli::check::run(a),
        Command::Compare(a) => cli::compare::run(a),
        Command::Convert(a) => cli::convert::run(a),
        Command::Eval(a) => cli::eval::run(a),
        Command::Patches(a) => cli::patches::run(a),
        Command::Param(a) => cli::param::run(a),
        Command::Remesh(a) => cli::remesh::run(a),
        Command::Render(a) => cli::render::run(a),
        Command::Stages(a) => cli::stages::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
