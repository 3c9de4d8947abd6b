//! Writing the offending patch (and its lifted candidate) when a certificate fails, so that
//! a failure can be reproduced and looked at.

use super::options::RemeshOptions;
use crate::ids::{FaceId, PatchId};
use crate::invariants::candidate_arrays;
use crate::mesh::TriMesh;
use crate::stitch::{Replacement, WorkingMesh};
use std::path::PathBuf;

/// Write a candidate replacement (the lifted remesh of a patch) as OBJ into the debug
/// directory, next to the patch it would replace.
pub(crate) fn write_candidate(
    options: &RemeshOptions,
    patch: PatchId,
    work: &WorkingMesh,
    r: &Replacement,
) -> Option<PathBuf> {
    let dir = options.debug_dir.as_ref()?;
    let (positions, triangles) = candidate_arrays(work, r);
    let (sub, _) = TriMesh {
        positions,
        triangles,
    }
    .without_unreferenced_vertices();
    let path = dir.join(format!("conemesh-failed-{patch}-candidate.obj"));
    crate::io::write_mesh(&path, &sub).ok()?;
    Some(path)
}

/// Write the offending patch (faces of `mesh`) as OBJ into the debug directory.
pub(crate) fn write_debug(
    options: &RemeshOptions,
    patch: PatchId,
    what: &str,
    mesh: &TriMesh,
    faces: &[FaceId],
) -> Option<PathBuf> {
    let dir = options.debug_dir.as_ref()?;
    let sub = TriMesh {
        positions: mesh.positions.clone(),
        triangles: faces.iter().map(|f| mesh.triangles[f.idx()]).collect(),
    };
    let (sub, _) = sub.without_unreferenced_vertices();
    let path = dir.join(format!("conemesh-failed-{patch}-{what}.obj"));
    crate::io::write_mesh(&path, &sub).ok()?;
    Some(path)
}
