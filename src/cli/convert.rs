//! `conemesh convert IN OUT`: read any supported format, write another (chosen by extension).
//! Attributes the input carries (uv, face properties, colours) are passed on to formats that
//! hold them. The output is written atomically: on any error no OUT file is left.

use conemesh::io::{read_mesh, write_mesh_with, WriteOptions};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `conemesh convert`.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// Input mesh (.obj, .off, .ply, .stl, .mesh).
    pub input: PathBuf,
    /// Output mesh; the format is chosen by its extension.
    pub output: PathBuf,
    /// Binary encoding for PLY and STL (STL binary stores f32 coordinates).
    #[arg(long)]
    pub binary: bool,
    /// Big-endian binary PLY (implies --binary).
    #[arg(long)]
    pub big_endian: bool,
}

/// Run `conemesh convert`.
pub fn run(args: ConvertArgs) -> anyhow::Result<ExitCode> {
    // The IoError's message already names the file, line and element (and its OS cause), so
    // it is printed as one line rather than as an anyhow chain that would repeat the cause.
    let loaded =
        read_mesh(&args.input).map_err(|e| anyhow::anyhow!("cannot read the input mesh: {e}"))?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let opts = WriteOptions {
        binary: args.binary || args.big_endian,
        big_endian: args.big_endian,
    };
    write_mesh_with(&args.output, &loaded.mesh, &loaded.attributes, &opts)
        .map_err(|e| anyhow::anyhow!("cannot write the output mesh: {e}"))?;
    println!(
        "{} -> {}: {} vertices, {} triangles ({} polygons triangulated, {} vertices welded)",
        args.input.display(),
        args.output.display(),
        loaded.mesh.n_vertices(),
        loaded.mesh.n_faces(),
        loaded.polygons_triangulated,
        loaded.welded_vertices
    );
    Ok(ExitCode::SUCCESS)
}
