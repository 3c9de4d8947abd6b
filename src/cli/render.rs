//! `conemesh render`: a picture of a mesh (front, side and iso views, coloured by q, smallest
//! angle, patch or distance, with a colour bar). Parses, calls [`conemesh::render`], writes
//! the PNG.

use anyhow::Context;
use conemesh::io::sol::SolError;
use conemesh::render::{ColorBy, RenderOptions, Sources, VertexMetric, Wireframe};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `--wireframe`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireArg {
    /// When the visible triangles are large enough on screen (20 pixels each on average).
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

/// Arguments of `conemesh render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// The mesh to draw (OBJ, OFF, PLY, STL, Medit .mesh).
    pub mesh: PathBuf,
    /// The picture (PNG).
    #[arg(short, long, value_name = "OUT.png")]
    pub output: PathBuf,
    /// What the faces are coloured by: `q` (2√3·a/(p·h) in the metric) or `min-angle` (the
    /// smallest angle in the metric), both with the faces whose smallest angle is below 20°
    /// in magenta (the paper's Fig. 6); `patch` (the patch that made each face, neighbouring
    /// patches in different colours, Fig. 3; needs `--patches`, or a PLY face property
    /// `patch` as `conemesh patches` writes); `distance` (to `--reference`, in % of its
    /// bounding-box diagonal); `none`.
    #[arg(long, default_value = "q", value_parser = ColorBy::parse)]
    pub color: ColorBy,
    /// The metric of `q` and `min-angle` (Medit .sol): one tensor per vertex of MESH (as
    /// `remesh --write-metric` writes), or per vertex of `--reference` (as a user metric of
    /// the run). Default: the curvature metric (Sec. 4.1) of `--reference`, or of MESH
    /// without one, as `conemesh eval`.
    #[arg(long, value_name = "M.sol")]
    pub metric: Option<PathBuf>,
    /// The reference (input) surface: the curvature metric is measured on it, and
    /// `--color distance` measures the distance to it.
    #[arg(long, value_name = "INPUT_MESH")]
    pub reference: Option<PathBuf>,
    /// The patch of each face of MESH, as `remesh --write-patches` writes it (one line per
    /// face: the patch id, or `-` for none).
    #[arg(long, value_name = "P")]
    pub patches: Option<PathBuf>,
    /// Picture width in pixels (the three views side by side).
    #[arg(long, default_value_t = RenderOptions::default().width)]
    pub width: u32,
    /// Picture height in pixels (views and colour bar).
    #[arg(long, default_value_t = RenderOptions::default().height)]
    pub height: u32,
    /// The faces' edges.
    #[arg(long, value_enum, default_value_t = WireArg::Auto)]
    pub wireframe: WireArg,
}

/// Run `conemesh render`.
pub fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    let t0 = std::time::Instant::now();
    check_args(&args)?;
    let loaded = conemesh::io::read_mesh(&args.mesh)
        .with_context(|| format!("reading {}", args.mesh.display()))?;
    let mesh = loaded.mesh;
    let reference = match &args.reference {
        Some(p) => Some(
            conemesh::io::read_mesh(p)
                .with_context(|| format!("reading reference {}", p.display()))?
                .mesh,
        ),
        None => None,
    };
    let metric = match &args.metric {
        Some(p) => Some(read_metric(
            p,
            &args.mesh,
            mesh.n_vertices(),
            reference.as_ref(),
        )?),
        None => None,
    };
    let patches = match (&args.patches, args.color) {
        (Some(p), _) => Some(
            conemesh::io::patches::read_face_patches(p)
                .with_context(|| format!("reading patches {}", p.display()))?,
        ),
        (None, ColorBy::Patch) => Some(file_patches(&loaded.attributes).ok_or_else(|| {
            anyhow::anyhow!(
                "--color patch needs --patches P (written by `conemesh remesh --write-patches P`); {} has no face property `patch`",
                args.mesh.display()
            )
        })?),
        (None, _) => None,
    };
    let sources = Sources {
        metric: (metric.as_ref()).map(|(m, on_mesh)| VertexMetric::new(m, *on_mesh)),
        reference: reference.as_ref(),
        patches: patches.as_deref(),
        ..Default::default()
    };
    if let (Some(p), Some(ids)) = (&args.patches, &patches) {
        anyhow::ensure!(
            ids.len() == mesh.n_faces(),
            "--patches {}: {} patch ids (one per face), but {} has {} faces",
            p.display(),
            ids.len(),
            args.mesh.display(),
            mesh.n_faces()
        );
    }
    let what = || match &args.metric {
        Some(m) => format!(
            "drawing {} in the metric of {}",
            args.mesh.display(),
            m.display()
        ),
        None => format!("drawing {}", args.mesh.display()),
    };
    let colors = conemesh::render::face_colors(&mesh, args.color, &sources).with_context(what)?;
    let opts = RenderOptions {
        width: args.width,
        height: args.height,
        wireframe: match args.wireframe {
            WireArg::Auto => Wireframe::Auto,
            WireArg::On => Wireframe::On,
            WireArg::Off => Wireframe::Off,
        },
        ..Default::default()
    };
    let (img, layout) = conemesh::render::render(&mesh, &colors, &opts).with_context(what)?;
    let png = img.png().with_context(what)?;
    let mut outputs = conemesh::io::Outputs::new();
    outputs
        .bytes(&args.output, &png)
        .with_context(|| format!("writing {}", args.output.display()))?;
    super::commit(outputs)?;
    println!(
        "wrote {} ({}×{}, {} faces coloured by {}, wireframe {}), {:.2} s",
        args.output.display(),
        img.width,
        img.height,
        mesh.n_faces(),
        args.color.name(),
        if layout.wireframe { "on" } else { "off" },
        t0.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}

/// Everything that can be refused before reading a mesh: the size, the output path (a
/// `.png`, not a folder, in a folder that exists, none of the inputs) and what the
/// colouring needs.
fn check_args(args: &RenderArgs) -> anyhow::Result<()> {
    conemesh::render::check_size(args.width, args.height)
        .map_err(|e| anyhow::anyhow!("--width {} --height {}: {e}", args.width, args.height))?;
    super::check_file_output("-o", &args.output)?;
    let png = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    anyhow::ensure!(
        png,
        "-o {}: pictures are written as PNG; give a .png file",
        args.output.display()
    );
    for (flag, p) in [
        Some(("MESH", &args.mesh)),
        args.metric.as_ref().map(|p| ("--metric", p)),
        args.reference.as_ref().map(|p| ("--reference", p)),
        args.patches.as_ref().map(|p| ("--patches", p)),
    ]
    .into_iter()
    .flatten()
    {
        if super::same_path(&args.output, p) {
            anyhow::bail!("-o {} is the same path as {flag}", args.output.display());
        }
    }
    if args.color == ColorBy::Distance && args.reference.is_none() {
        anyhow::bail!("--color distance needs --reference INPUT_MESH (the surface to measure the distance to)");
    }
    Ok(())
}

/// The `.sol` of `--metric`, and whether it is per vertex of MESH (`true`) or of the
/// reference: a file whose count matches MESH is MESH's.
fn read_metric(
    p: &Path,
    mesh_path: &Path,
    n_mesh: usize,
    reference: Option<&conemesh::TriMesh>,
) -> anyhow::Result<(Vec<nalgebra::Matrix3<f64>>, bool)> {
    match conemesh::io::sol::read_sol(p, n_mesh) {
        Ok(m) => Ok((m, true)),
        Err(SolError::CountMismatch { found, .. })
            if reference.is_some_and(|r| r.n_vertices() == found) =>
        {
            let n = reference.map_or(0, |r| r.n_vertices());
            let m = conemesh::io::sol::read_sol(p, n)
                .with_context(|| format!("reading metric {}", p.display()))?;
            Ok((m, false))
        }
        Err(e) => Err(anyhow::Error::new(e).context(format!(
            "reading metric {} (one tensor per vertex of {}{})",
            p.display(),
            mesh_path.display(),
            if reference.is_some() {
                ", or of --reference"
            } else {
                ""
            }
        ))),
    }
}

/// The face property `patch` of the mesh file (a PLY from `conemesh patches`), negative ids
/// meaning none.
fn file_patches(attrs: &conemesh::io::MeshAttributes) -> Option<Vec<Option<conemesh::PatchId>>> {
    let (_, ids) = attrs.face_ints.iter().find(|(n, _)| n == "patch")?;
    Some(
        ids.iter()
            .map(|&i| u32::try_from(i).ok().map(conemesh::PatchId))
            .collect(),
    )
}
