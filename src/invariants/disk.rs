//! `certify_disk`: a set of faces is a topological disk (Sec. 3.2, the patch invariant).
//!
//! Checked in this order, each failure naming its element: faces distinct; every edge has at
//! most two patch faces, traversed in opposite directions (edge-manifold, oriented); every
//! vertex's patch faces form one fan (vertex-manifold, no pinch); the faces are connected
//! through edges; exactly one boundary loop; Euler characteristic V − E + F = 1. A connected,
//! oriented, manifold surface with one boundary loop and χ = 1 is a disk (χ = 2 − 2g − b).

use super::{DiskDefect, InvariantError, Offenders};
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::{TriMesh, UnionFind};
use std::collections::HashMap;

fn not_disk(defect: DiskDefect) -> InvariantError {
    InvariantError::NotADisk(defect)
}

/// Certify that `faces` of `mesh` form a topological disk and return its boundary loop:
/// an ordered vertex cycle following the patch faces' half-edge direction (the patch lies to
/// its left), starting at its smallest vertex id.
///
/// Errors are [`InvariantError::NotADisk`] whose [`DiskDefect`] names the offending face,
/// edge, vertex or count.
pub fn certify_disk(mesh: &TriMesh, faces: &[FaceId]) -> Result<Vec<VertexId>, InvariantError> {
    let sorted = distinct_faces(mesh, faces)?;
    let (edges, keys) = manifold_edges(mesh, &sorted)?;
    let verts = single_fans(mesh, &sorted, &edges)?;
    connected(&sorted, &edges, &keys)?;
    let boundary = one_boundary_loop(&sorted, &edges, &keys)?;
    let chi = verts.len() as i64 - keys.len() as i64 + sorted.len() as i64;
    if chi != 1 {
        return Err(not_disk(DiskDefect::euler(
            verts.len(),
            keys.len(),
            sorted.len(),
        )));
    }
    Ok(boundary)
}

/// The patch's directed edges grouped by undirected edge: (from, to, index in the sorted
/// faces).
type PatchEdges = HashMap<EdgeKey, Vec<(VertexId, VertexId, usize)>>;

/// The faces sorted, each listed once and existing.
fn distinct_faces(mesh: &TriMesh, faces: &[FaceId]) -> Result<Vec<FaceId>, InvariantError> {
    if faces.is_empty() {
        return Err(not_disk(DiskDefect::NoFaces));
    }
    let mut sorted = faces.to_vec();
    sorted.sort_unstable();
    for w in sorted.windows(2) {
        if w[0] == w[1] {
            return Err(not_disk(DiskDefect::RepeatedFace(w[0])));
        }
    }
    if let Some(f) = sorted.iter().find(|f| f.idx() >= mesh.n_faces()) {
        return Err(not_disk(DiskDefect::FaceOutOfRange {
            face: *f,
            faces: mesh.n_faces(),
        }));
    }
    Ok(sorted)
}

/// The patch's edges (and their keys, sorted), each with at most two faces traversing it in
/// opposite directions (edge-manifold, oriented).
fn manifold_edges(
    mesh: &TriMesh,
    sorted: &[FaceId],
) -> Result<(PatchEdges, Vec<EdgeKey>), InvariantError> {
    // Directed edges of the patch, grouped by undirected edge: (from, to, local face index).
    let mut edges: PatchEdges = HashMap::new();
    for (k, &f) in sorted.iter().enumerate() {
        let t = mesh.face(f);
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            edges.entry(EdgeKey::new(a, b)).or_default().push((a, b, k));
        }
    }
    let mut keys: Vec<EdgeKey> = edges.keys().copied().collect();
    keys.sort_unstable();
    for key in &keys {
        let hs = &edges[key];
        if hs.len() > 2 {
            return Err(not_disk(DiskDefect::NonManifoldEdge {
                edge: *key,
                faces: hs.len(),
            }));
        }
        if hs.len() == 2 && hs[0].0 == hs[1].0 {
            return Err(not_disk(DiskDefect::InconsistentEdge {
                edge: *key,
                faces: Some((sorted[hs[0].2], sorted[hs[1].2])),
            }));
        }
    }
    Ok((edges, keys))
}

/// The patch's vertices, sorted, each one's patch faces forming one fan.
fn single_fans(
    mesh: &TriMesh,
    sorted: &[FaceId],
    edges: &PatchEdges,
) -> Result<Vec<VertexId>, InvariantError> {
    // Vertex-manifold: the patch faces around each vertex form one fan, i.e. are connected
    // through patch edges at that vertex.
    let mut vertex_faces: HashMap<VertexId, Vec<usize>> = HashMap::new();
    for (k, &f) in sorted.iter().enumerate() {
        for v in mesh.face(f) {
            vertex_faces.entry(v).or_default().push(k);
        }
    }
    let mut verts: Vec<VertexId> = vertex_faces.keys().copied().collect();
    verts.sort_unstable();
    for &v in &verts {
        let fs = &vertex_faces[&v];
        if fs.len() <= 1 {
            continue;
        }
        let mut sets = UnionFind::new(fs.len());
        for (a, &k) in fs.iter().enumerate() {
            let t = mesh.face(sorted[k]);
            for w in t {
                if w == v {
                    continue;
                }
                for &(_, _, k2) in &edges[&EdgeKey::new(v, w)] {
                    if k2 != k {
                        // `fs` is increasing (faces pushed in order): a hub vertex of a
                        // 100k-face fan costs d log d, not d².
                        if let Ok(b) = fs.binary_search(&k2) {
                            sets.union(a, b);
                        }
                    }
                }
            }
        }
        let fans = sets.count();
        if fans > 1 {
            return Err(not_disk(DiskDefect::Pinch {
                vertex: v,
                fans: Some(fans),
            }));
        }
    }
    Ok(verts)
}

/// The patch faces are connected through edges.
fn connected(
    sorted: &[FaceId],
    edges: &PatchEdges,
    keys: &[EdgeKey],
) -> Result<(), InvariantError> {
    // Connected through edges.
    let mut sets = UnionFind::new(sorted.len());
    for key in keys {
        let hs = &edges[key];
        if hs.len() == 2 {
            sets.union(hs[0].2, hs[1].2);
        }
    }
    if let Some(k) = (0..sorted.len()).find(|&k| sets.find(k) != 0) {
        return Err(not_disk(DiskDefect::Disconnected {
            components: sets.count(),
            faces: Some((sorted[0], sorted[k])),
        }));
    }
    Ok(())
}

/// The one boundary loop, from the smallest vertex id, following the boundary half-edges
/// (one outgoing per vertex: the patch is vertex-manifold).
fn one_boundary_loop(
    sorted: &[FaceId],
    edges: &PatchEdges,
    keys: &[EdgeKey],
) -> Result<Vec<VertexId>, InvariantError> {
    // Boundary loops: boundary half-edges, one outgoing per vertex (vertex-manifold).
    let mut next: HashMap<VertexId, VertexId> = HashMap::new();
    for key in keys {
        let hs = &edges[key];
        if hs.len() == 1 {
            next.insert(hs[0].0, hs[0].1);
        }
    }
    if next.is_empty() {
        return Err(not_disk(DiskDefect::Closed {
            faces: sorted.len(),
        }));
    }
    let mut starts: Vec<VertexId> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut seen: HashMap<VertexId, usize> = HashMap::new();
    let mut loops: Vec<Vec<VertexId>> = Vec::new();
    for &s in &starts {
        if seen.contains_key(&s) {
            continue;
        }
        let mut lp = vec![s];
        seen.insert(s, loops.len());
        let mut v = s;
        loop {
            let Some(&w) = next.get(&v) else {
                return Err(not_disk(DiskDefect::OpenBoundary(v)));
            };
            if w == s {
                break;
            }
            if seen.contains_key(&w) {
                return Err(not_disk(DiskDefect::BoundaryRevisits(w)));
            }
            seen.insert(w, loops.len());
            lp.push(w);
            v = w;
        }
        loops.push(lp);
    }
    if loops.len() != 1 {
        return Err(not_disk(DiskDefect::BoundaryLoops {
            loops: loops.len(),
            starts: Offenders(loops.iter().map(|l| l[0]).collect()),
        }));
    }
    Ok(loops.pop().unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use nalgebra::Point3;

    fn defect(e: InvariantError) -> DiskDefect {
        match e {
            InvariantError::NotADisk(d) => d,
            other => panic!("unexpected error {other}"),
        }
    }

    fn all(m: &TriMesh) -> Vec<FaceId> {
        m.faces().collect()
    }

    #[test]
    fn generated_disks_are_certified_with_ccw_boundary() {
        let d = generators::disk(1.0, 3, 6);
        let lp = certify_disk(&d, &all(&d)).expect("disk");
        assert_eq!(lp.len(), 18);
        let mut a = 0.0;
        for k in 0..lp.len() {
            let p = d.positions[lp[k].idx()];
            let q = d.positions[lp[(k + 1) % lp.len()].idx()];
            a += p.x * q.y - q.x * p.y;
        }
        assert!(a > 0.0, "patch must lie to the left of its boundary");
        let c = generators::cone_piece(0.5, 2.0, 0.5, 2.0, 6, 4);
        assert!(certify_disk(&c, &all(&c)).is_ok());
    }

    #[test]
    fn rejects_annulus_closed_surface_and_disjoint_triangles() {
        let cyl = generators::cylinder(1.0, 1.0, 8, 2);
        let r = defect(certify_disk(&cyl, &all(&cyl)).unwrap_err());
        assert!(
            matches!(r, DiskDefect::BoundaryLoops { loops: 2, .. }),
            "{r}"
        );
        let s = generators::icosphere(1.0, 0);
        let r = defect(certify_disk(&s, &all(&s)).unwrap_err());
        assert_eq!(r, DiskDefect::Closed { faces: 20 });
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(5.0, 0.0, 0.0),
            Point3::new(6.0, 0.0, 0.0),
            Point3::new(5.0, 1.0, 0.0),
        ];
        let m = TriMesh::from_indices(p, &[[0, 1, 2], [3, 4, 5]]).unwrap();
        let r = defect(certify_disk(&m, &all(&m)).unwrap_err());
        assert_eq!(
            r,
            DiskDefect::Disconnected {
                components: 2,
                faces: Some((FaceId(0), FaceId(1)))
            }
        );
    }

    #[test]
    fn rejects_bowtie_naming_the_pinch_vertex() {
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(-1.0, 0.0, 0.0),
            Point3::new(-1.0, -1.0, 0.0),
        ];
        // Two triangles meeting only at v0.
        let m = TriMesh::from_indices(p, &[[1, 2, 0], [3, 4, 0]]).unwrap();
        let r = defect(certify_disk(&m, &all(&m)).unwrap_err());
        assert_eq!(
            r,
            DiskDefect::Pinch {
                vertex: VertexId(0),
                fans: Some(2)
            }
        );
        assert_eq!(
            r.to_string(),
            "vertex v0 is a pinch: its faces form 2 separate fans"
        );
    }

    #[test]
    fn rejects_nonmanifold_edge_flip_and_duplicates() {
        let p = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.5, 1.0, 0.0),
            Point3::new(0.5, -1.0, 0.0),
            Point3::new(0.5, 0.0, 1.0),
        ];
        let m = TriMesh::from_indices(p.clone(), &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap();
        let v01 = EdgeKey::new(VertexId(0), VertexId(1));
        let r = defect(certify_disk(&m, &all(&m)).unwrap_err());
        assert_eq!(
            r,
            DiskDefect::NonManifoldEdge {
                edge: v01,
                faces: 3
            }
        );
        let m = TriMesh::from_indices(p, &[[0, 1, 2], [0, 1, 3]]).unwrap();
        let r = defect(certify_disk(&m, &all(&m)).unwrap_err());
        assert_eq!(
            r,
            DiskDefect::InconsistentEdge {
                edge: v01,
                faces: Some((FaceId(0), FaceId(1)))
            }
        );
        let r = defect(certify_disk(&m, &[FaceId(0), FaceId(0)]).unwrap_err());
        assert_eq!(r, DiskDefect::RepeatedFace(FaceId(0)));
    }

    #[test]
    fn rejects_torus_with_a_hole_by_euler_characteristic() {
        let t = generators::torus(2.0, 0.5, 8, 6);
        let faces: Vec<FaceId> = t.faces().skip(1).collect();
        let r = defect(certify_disk(&t, &faces).unwrap_err());
        assert!(
            matches!(r, DiskDefect::EulerCharacteristic { chi: -1, .. }),
            "{r}"
        );
    }
}
