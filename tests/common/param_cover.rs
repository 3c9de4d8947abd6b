//! Shared loop of `examples/param_cover.rs` and `tests/param_cover.rs` (issue 7, "Done
//! when"): cover a mesh with the default cone patches (seed 1, unit-diagonal mesh), extract
//! every patch, parameterize it with the default symmetric Dirichlet parameterizer
//! (Sec. 3.3) and certify the map exactly with `certify_bijective`.

#![allow(dead_code)]

use conemesh::invariants::certify_bijective;
use conemesh::metric::Normalization;
use conemesh::param::{DistortionReport, Parameterizer, SymmetricDirichlet};
use conemesh::patches::{cover, extract_patch, ConePatches, CoverOptions};
use conemesh::TriMesh;
use rand::SeedableRng;
use serde::Serialize;
use std::time::Instant;

/// The shared-mesh catalogue (`tests/common/mod.rs`), here too for the examples that include
/// this file.
#[path = "mod.rs"]
pub mod catalogue;

/// The shared test meshes directory.
#[allow(unused_imports)]
pub use catalogue::DIR as MESHES;

/// One patch of a covering run, parameterized.
#[derive(Clone, Debug, Serialize)]
pub struct PatchRow {
    /// Patch index in creation order.
    pub patch: usize,
    /// Number of faces.
    pub faces: usize,
    /// 3D area (unit-diagonal mesh).
    pub area: f64,
    /// Wall time of `SymmetricDirichlet::parameterize`, ms.
    pub ms: f64,
    /// The distortion report (absent when a stage failed).
    pub report: Option<DistortionReport>,
    /// `None` when certified; otherwise the precise failure (extract / param / certificate).
    pub error: Option<String>,
}

/// All patches of one mesh.
#[derive(Clone, Debug, Serialize)]
pub struct MeshRun {
    /// File name.
    pub mesh: String,
    /// Faces of the mesh (after dropping unreferenced vertices).
    pub faces: usize,
    /// Covering time, ms.
    pub cover_ms: f64,
    /// Every patch of the covering run.
    pub patches: Vec<PatchRow>,
}

/// Summary of a [`MeshRun`].
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub patches: usize,
    pub certified: usize,
    /// Mean of `mean_conformal` over certified patches, weighted by patch 3D area.
    pub mean_conformal_area_weighted: f64,
    /// Worst `max_conformal` over certified patches.
    pub worst_max_conformal: f64,
    pub fallbacks: usize,
    pub budget_hits: usize,
    pub total_param_ms: f64,
    pub largest_patch_faces: usize,
    pub largest_patch_ms: f64,
}

impl MeshRun {
    pub fn summary(&self) -> Summary {
        let ok: Vec<(&PatchRow, &DistortionReport)> = self
            .patches
            .iter()
            .filter(|p| p.error.is_none())
            .filter_map(|p| p.report.as_ref().map(|r| (p, r)))
            .collect();
        let area: f64 = ok.iter().map(|(p, _)| p.area).sum();
        let weighted: f64 = ok.iter().map(|(p, r)| p.area * r.mean_conformal).sum();
        let largest = self.patches.iter().max_by_key(|p| p.faces);
        Summary {
            patches: self.patches.len(),
            certified: ok.len(),
            mean_conformal_area_weighted: if area > 0.0 {
                weighted / area
            } else {
                f64::NAN
            },
            worst_max_conformal: ok.iter().map(|(_, r)| r.max_conformal).fold(0.0, f64::max),
            fallbacks: ok.iter().filter(|(_, r)| r.fell_back).count(),
            budget_hits: ok.iter().filter(|(_, r)| r.hit_budget).count(),
            total_param_ms: self.patches.iter().map(|p| p.ms).sum(),
            largest_patch_faces: largest.map_or(0, |p| p.faces),
            largest_patch_ms: largest.map_or(0.0, |p| p.ms),
        }
    }
}

/// Read the shared mesh `name` ("bunny.off"), drop unreferenced vertices, normalize to unit
/// bounding-box diagonal.
pub fn load(name: &str) -> TriMesh {
    let m = catalogue::load_referenced(name);
    Normalization::of(&m).apply(&m)
}

/// Parameterize and certify one patch (given by its faces) of `mesh`.
pub fn param_patch(mesh: &TriMesh, patch: usize, faces: &[conemesh::FaceId]) -> PatchRow {
    let mut row = PatchRow {
        patch,
        faces: faces.len(),
        area: 0.0,
        ms: 0.0,
        report: None,
        error: None,
    };
    let pm = match extract_patch(mesh, faces) {
        Ok(pm) => pm,
        Err(e) => {
            row.error = Some(format!("extract_patch: {e}"));
            return row;
        }
    };
    row.area = pm.mesh.area();
    let t0 = Instant::now();
    let res = SymmetricDirichlet::default().parameterize(&pm.mesh, &pm.boundary);
    row.ms = t0.elapsed().as_secs_f64() * 1e3;
    match res {
        Err(e) => row.error = Some(format!("parameterize: {e}")),
        Ok(p) => {
            if let Err(e) = certify_bijective(&p.uv, &pm.mesh.triangles, &pm.boundary) {
                row.error = Some(format!("certify_bijective: {e}"));
            }
            row.report = Some(p.report);
        }
    }
    row
}

/// Cover `name` (cone patches, seed 1) and parameterize every patch. Also returns the mesh
/// and the patches' faces (for re-timing).
pub fn run_mesh(name: &str) -> Result<(MeshRun, TriMesh, Vec<Vec<conemesh::FaceId>>), String> {
    let mesh = load(name);
    let mut rng = conemesh::Rng::seed_from_u64(1);
    let t0 = Instant::now();
    let run = cover(
        &mesh,
        &ConePatches::default(),
        &CoverOptions::default(),
        &mut rng,
    )
    .map_err(|e| format!("{name}: cover: {e}"))?;
    let cover_ms = t0.elapsed().as_secs_f64() * 1e3;
    if !run.complete {
        return Err(format!("{name}: covering run incomplete"));
    }
    let faces: Vec<Vec<conemesh::FaceId>> = run.patches.into_iter().map(|p| p.faces).collect();
    let patches = faces
        .iter()
        .enumerate()
        .map(|(i, f)| param_patch(&mesh, i, f))
        .collect();
    Ok((
        MeshRun {
            mesh: name.to_string(),
            faces: mesh.n_faces(),
            cover_ms,
            patches,
        },
        mesh,
        faces,
    ))
}
