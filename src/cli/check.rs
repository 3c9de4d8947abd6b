//! `conemesh check [MESH] [--json] [--no-self-intersections]`: read a mesh (or take the
//! built-in default surface), run every certificate, print the report. Exit code 0 only when
//! the mesh is valid, 1 when it is not, 2 when it cannot be read.

use anyhow::Context;
use conemesh::check::{check_mesh, CheckOptions};
use conemesh::io::read_mesh;
use conemesh::mesh::generators;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `conemesh check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// Mesh file (.obj, .off, .ply, .stl, .mesh); the built-in default surface when absent.
    pub mesh: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Skip the self-intersection search.
    #[arg(long)]
    pub no_self_intersections: bool,
}

/// Run `conemesh check`.
pub fn run(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let (mesh, name, warnings) = match &args.mesh {
        Some(path) => {
            let loaded =
                read_mesh(path).with_context(|| format!("cannot check {}", path.display()))?;
            (loaded.mesh, path.display().to_string(), loaded.warnings)
        }
        None => (
            generators::default_surface(),
            "built-in default surface (torus R=1, r=0.35)".to_string(),
            Vec::new(),
        ),
    };
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    let opts = CheckOptions {
        self_intersections: !args.no_self_intersections,
    };
    let report = check_mesh(&mesh, &opts);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("mesh: {name}");
        println!("{report}");
    }
    let repairable = report.non_manifold_edges
        + report.non_manifold_vertices
        + report.inconsistently_oriented_edges
        + report.degenerate_faces;
    if repairable > 0 {
        eprintln!(
            "hint: `conemesh remesh --repair` orients the surface, cuts non-manifold edges and \
             vertices, and drops zero-area faces before remeshing (coordinates unchanged)"
        );
    }
    Ok(if report.valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
