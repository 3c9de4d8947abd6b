//! A patch as its own mesh, with local ids (input of the parameterization, Sec. 3.3).

use super::PatchError;
use crate::ids::{FaceId, VertexId};
use crate::mesh::TriMesh;
use std::collections::HashMap;

/// A patch copied out of its mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchMesh {
    /// The patch faces with local vertex ids (first-use order over the sorted faces) and
    /// copied positions; face `i` is `face_to_global[i]`, same orientation.
    pub mesh: TriMesh,
    /// Local vertex id → global vertex id.
    pub to_global: Vec<VertexId>,
    /// Local face id → global face id (sorted).
    pub face_to_global: Vec<FaceId>,
    /// The boundary loop in local ids, ordered, with the surface on its left.
    pub boundary: Vec<VertexId>,
}

impl PatchMesh {
    /// Global → local vertex map.
    pub fn to_local(&self) -> HashMap<VertexId, VertexId> {
        self.to_global
            .iter()
            .enumerate()
            .map(|(i, &g)| (g, VertexId::new(i)))
            .collect()
    }
}

/// Copy `faces` of `mesh` into a [`PatchMesh`], after certifying that they form a disk
/// (`invariants::certify_disk`).
pub fn extract_patch(mesh: &TriMesh, faces: &[FaceId]) -> Result<PatchMesh, PatchError> {
    let boundary = crate::invariants::certify_disk(mesh, faces)?;
    let mut face_to_global = faces.to_vec();
    face_to_global.sort_unstable();
    let mut local: HashMap<VertexId, VertexId> = HashMap::new();
    let mut to_global = Vec::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(face_to_global.len());
    for &f in &face_to_global {
        let t = mesh.face(f);
        let mut lt = [VertexId(0); 3];
        for (k, v) in t.iter().enumerate() {
            lt[k] = *local.entry(*v).or_insert_with(|| {
                to_global.push(*v);
                positions.push(*mesh.position(*v));
                VertexId::new(to_global.len() - 1)
            });
        }
        triangles.push(lt);
    }
    let boundary = boundary
        .iter()
        .filter_map(|v| local.get(v).copied())
        .collect();
    Ok(PatchMesh {
        mesh: TriMesh {
            positions,
            triangles,
        },
        to_global,
        face_to_global,
        boundary,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    #[test]
    fn extracted_patch_keeps_geometry_orientation_and_boundary() {
        let m = generators::torus(2.0, 0.5, 12, 8);
        let faces = vec![FaceId(0), FaceId(1), FaceId(2), FaceId(3)];
        let pm = extract_patch(&m, &faces).expect("strip of a torus is a disk");
        assert_eq!(pm.face_to_global, faces);
        for (i, &g) in pm.face_to_global.iter().enumerate() {
            let lt = pm.mesh.triangles[i];
            let gt = m.face(g);
            for k in 0..3 {
                assert_eq!(pm.to_global[lt[k].idx()], gt[k]);
                assert_eq!(pm.mesh.positions[lt[k].idx()], m.positions[gt[k].idx()]);
            }
        }
        let lb = crate::invariants::certify_disk(&pm.mesh, &pm.mesh.faces().collect::<Vec<_>>())
            .expect("local copy is a disk");
        // Same loop up to rotation.
        let n = lb.len();
        let s = pm
            .boundary
            .iter()
            .position(|&v| v == lb[0])
            .expect("same vertices");
        assert!((0..n).all(|k| pm.boundary[(s + k) % n] == lb[k]));
        let all: Vec<FaceId> = m.faces().collect();
        assert!(matches!(
            extract_patch(&m, &all),
            Err(PatchError::Invariant(
                crate::invariants::InvariantError::NotADisk(_)
            ))
        ));
    }
}
