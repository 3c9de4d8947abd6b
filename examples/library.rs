//! The whole job from the library, as `conemesh remesh` does it: read a mesh, remesh it
//! (Algorithm 1, certified), score it, write it.
//!
//! `cargo run --release --example library -- [MESH] [OUT.obj]` (a generated torus and
//! `library-out.obj` by default). Choose other stages by registry name, e.g.
//! `Stages::from_registry(("kring", Params::default()), ("sd", ..), ("lct", ..), false)`.

use conemesh::pipeline::{RemeshOptions, Remesher};
use conemesh::quality::{evaluate, EvalOptions, EvalReport};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mesh = match args.next() {
        Some(p) => conemesh::io::read_mesh(std::path::Path::new(&p))?.mesh,
        None => conemesh::mesh::generators::torus(1.0, 0.35, 40, 16),
    };
    let out_path = PathBuf::from(args.next().unwrap_or_else(|| "library-out.obj".into()));

    // Options of Algorithm 1 with their documented defaults; change any field.
    let options = RemeshOptions {
        seed: 7,
        ..RemeshOptions::default()
    };
    let out = Remesher::new(options).run(&mesh)?;
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }

    // The yardstick (Sec. 4.1), independent of the remesher.
    let eval = evaluate(&out.input, &out.mesh, None, &EvalOptions::default())?;
    println!("{}", EvalReport::table_header());
    println!("{}", eval.table_row("library"));
    let r = &out.unit.report;
    println!(
        "{} patches, {} certified disks, {} bijective maps, {} planar remeshes",
        r.patches, r.certificate.disk, r.certificate.bijective, r.certificate.planar
    );
    conemesh::io::write_mesh(&out_path, &out.mesh)?;
    println!("wrote {}", out_path.display());
    Ok(())
}
