//! The whole job from the library, as `conemesh remesh` does it: read a mesh, repair it when
//! asked, remesh it (Algorithm 1, certified), score it (Sec. 4.1), and write the mesh and the
//! report as one transaction. [`conemesh::job`] does every step; this file parses and prints.
//!
//! `cargo run --release --example library -- [MESH [OUT.obj]] [--repair]` (a generated torus
//! and `library-out.obj`, its report `library-out.json`, by default). Choose other stages by
//! registry name, e.g.
//! `Stages::from_registry(("kring", Params::default()), ("sd", ..), ("lct", ..), false)`.

use conemesh::job::{Job, JobInput, OutputFiles, Source};
use conemesh::pipeline::{RemeshOptions, Remesher};
use conemesh::quality::EvalReport;
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let repair = args.iter().any(|a| a == "--repair");
    let mut paths = args.iter().filter(|a| *a != "--repair").map(PathBuf::from);
    let (mesh, source) = match paths.next() {
        Some(p) => {
            let loaded = conemesh::io::read_mesh(&p)?;
            let short_name = p.file_stem().map(|s| s.to_string_lossy().into_owned());
            let source = Source::File {
                name: p.display().to_string(),
                short_name: short_name.unwrap_or_else(|| "mesh".into()),
                polygons_triangulated: loaded.polygons_triangulated,
            };
            (loaded.mesh, source)
        }
        None => (
            conemesh::mesh::generators::torus(1.0, 0.35, 40, 16),
            Source::Arrays,
        ),
    };
    let out = paths.next().unwrap_or_else(|| "library-out.obj".into());

    // Options of Algorithm 1 with their documented defaults; change any field.
    let options = RemeshOptions {
        seed: 7,
        ..RemeshOptions::default()
    };
    let mut job = Job::new(Remesher::new(options));
    if repair {
        job = job.with_repair(Default::default());
    }
    let outcome = job.run(JobInput::new(mesh, None), |_| {})?;

    if let Some(log) = &outcome.repair {
        println!("repair: {}", log.summary());
    }
    for w in &outcome.remeshed.warnings {
        eprintln!("warning: {w}");
    }
    println!("{}", EvalReport::table_header());
    println!("{}", outcome.eval.table_row(source.short_name()));
    let r = &outcome.remeshed.unit.report;
    println!(
        "{} patches, {} certified disks, {} bijective maps, {} planar remeshes",
        r.patches, r.certificate.disk, r.certificate.bijective, r.certificate.planar
    );
    // The mesh and the report (the run's, the repair's and the yardstick's), written together
    // or not at all.
    let report = out.with_extension("json");
    let files = OutputFiles {
        mesh: Some(out.clone()),
        report: Some(report.clone()),
        ..Default::default()
    };
    let mut outputs = conemesh::io::Outputs::new();
    outcome.stage_files(&mut outputs, &files, &source)?;
    conemesh::io::paths::commit(outputs)?;
    println!("wrote {} and {}", out.display(), report.display());
    Ok(())
}
