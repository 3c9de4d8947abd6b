//! `conemesh param MESH -o OUT.obj [--flat]`: parameterize a disk-topology mesh bijectively
//! into the plane (Sec. 3.3), print the exact certificate and the distortion, and write the
//! mesh with `vt` texture coordinates (or, with `--flat`, the planar mesh itself).

use conemesh::invariants::certify_bijective;
use conemesh::io::{read_mesh, write_mesh_with, MeshAttributes, WriteOptions};
use conemesh::param::{disk_boundary, Parameterizer, SymmetricDirichlet, Tutte};
use conemesh::TriMesh;
use nalgebra::Point3;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Which parameterizer to run.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Symmetric Dirichlet, projected Newton with free boundary (the default).
    Sd,
    /// Tutte's embedding on a circle (mean-value weights), scaled to the 3D area.
    Tutte,
}

/// Arguments of `conemesh param`.
#[derive(clap::Args, Debug)]
pub struct ParamArgs {
    /// Input mesh (.obj, .off, .ply, .stl, .mesh); must be a topological disk.
    pub input: PathBuf,
    /// Output mesh (.obj keeps the uv as `vt`; .ply as `u v`).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write the planar mesh (positions `(u, v, 0)`) instead of the 3D mesh with `vt`.
    #[arg(long)]
    pub flat: bool,
    /// Parameterizer.
    #[arg(long, value_enum, default_value_t = Method::Sd)]
    pub method: Method,
}

/// Run `conemesh param`.
pub fn run(args: ParamArgs) -> anyhow::Result<ExitCode> {
    let loaded =
        read_mesh(&args.input).map_err(|e| anyhow::anyhow!("cannot read the input mesh: {e}"))?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let (mesh, _) = loaded.mesh.without_unreferenced_vertices();
    let dropped = loaded.mesh.n_vertices() - mesh.n_vertices();
    if dropped > 0 {
        eprintln!("warning: dropped {dropped} unreferenced vertices");
    }
    let boundary =
        disk_boundary(&mesh).map_err(|e| anyhow::anyhow!("{}: {e}", args.input.display()))?;
    let param: Box<dyn Parameterizer> = match args.method {
        Method::Sd => Box::new(SymmetricDirichlet::default()),
        Method::Tutte => Box::new(Tutte::default()),
    };
    let t0 = Instant::now();
    let p = param
        .parameterize(&mesh, &boundary)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.input.display()))?;
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    // Re-check independently of the parameterizer (it certified already).
    certify_bijective(&p.uv, &mesh.triangles, &boundary)
        .map_err(|e| anyhow::anyhow!("certificate failed: {e}"))?;
    println!(
        "{}: {} vertices, {} triangles, boundary loop of {} vertices; {} in {ms:.1} ms",
        args.input.display(),
        mesh.n_vertices(),
        mesh.n_faces(),
        boundary.len(),
        param.name()
    );
    println!(
        "certificate: bijective (exact): all {} triangles positively oriented, boundary polygon \
         simple and counter-clockwise",
        mesh.n_faces()
    );
    let r = &p.report;
    println!(
        "distortion: symmetric Dirichlet {:.6} (4 = isometry), conformal max {:.4} mean {:.4}, \
         max |log area ratio| {:.4}; {} iterations{}{}",
        r.symmetric_dirichlet,
        r.max_conformal,
        r.mean_conformal,
        r.max_area_distortion,
        r.iterations,
        if r.hit_budget {
            ", iteration budget hit"
        } else {
            ""
        },
        if r.fell_back {
            ", fell back to the last certified iterate"
        } else {
            ""
        }
    );
    let (out_mesh, attrs) = if args.flat {
        let flat = TriMesh {
            positions: p.uv.iter().map(|q| Point3::new(q.x, q.y, 0.0)).collect(),
            triangles: mesh.triangles.clone(),
        };
        (flat, MeshAttributes::default())
    } else {
        let attrs = MeshAttributes {
            uv: Some(p.uv.clone()),
            ..Default::default()
        };
        (mesh, attrs)
    };
    write_mesh_with(&args.output, &out_mesh, &attrs, &WriteOptions::default())
        .map_err(|e| anyhow::anyhow!("cannot write the output mesh: {e}"))?;
    println!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}
