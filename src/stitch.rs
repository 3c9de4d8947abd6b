//! Replacing a remeshed patch inside the working mesh (Algorithm 1, step e).
//!
//! The working mesh of Algorithm 1 is a [`WorkingMesh`]: the triangle mesh being rebuilt,
//! for every vertex its location on the reference surface, and for every face whether it is
//! processed. [`stitch`] swaps a patch's faces for the remeshed triangles. It touches only
//! the arrays (no global topology rebuild inside); vertices that no face references any more
//! stay in the arrays until [`WorkingMesh::compact`] at the end, so ids of untouched
//! elements are stable while the loop runs.

use crate::boundary::CurvePoint;
use crate::ids::{FaceId, FaceMap, VertexId, VertexMap};
use crate::mesh::{SurfaceLocation, TriMesh};
use nalgebra::Point3;
use thiserror::Error;

/// Errors of patch replacement.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum StitchError {
    /// A face id out of range or listed twice.
    #[error("patch face {0} is out of range or repeated")]
    BadFace(FaceId),
    /// A replacement triangle refers to a vertex that does not exist.
    #[error("replacement triangle {triangle} refers to missing vertex {vertex:?}")]
    BadVertex {
        /// index in the replacement list
        triangle: usize,
        /// the vertex reference
        vertex: PatchVertex,
    },
}

/// The state of Algorithm 1: the mesh being remeshed, where each of its vertices lies on the
/// reference surface, and which faces are processed.
#[derive(Clone, Debug)]
pub struct WorkingMesh {
    /// The current mesh (unit-diagonal space).
    pub mesh: TriMesh,
    /// `locations[v]`: where vertex `v` lies on the reference mesh.
    pub locations: VertexMap<SurfaceLocation>,
    /// `processed[f]`: face `f` was produced by (or lies inside) an already remeshed patch.
    pub processed: FaceMap<bool>,
    /// `curve[v]`: where vertex `v` lies on the input's boundary curves, for boundary
    /// vertices ([`crate::boundary`]); `None` inside.
    pub curve: VertexMap<Option<CurvePoint>>,
}

/// A vertex of a replacement triangle: an existing working-mesh vertex (patch boundary) or
/// the index of a new vertex in [`Replacement::new_positions`].
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum PatchVertex {
    /// A vertex already in the working mesh.
    Existing(VertexId),
    /// A new vertex.
    New(u32),
}

/// The remeshed patch, ready to be stitched.
#[derive(Clone, Debug, Default)]
pub struct Replacement {
    /// Positions of the new vertices.
    pub new_positions: Vec<Point3<f64>>,
    /// Their locations on the reference surface (parallel to `new_positions`).
    pub new_locations: Vec<SurfaceLocation>,
    /// Their points on the input's boundary curves (parallel to `new_positions`; missing
    /// entries are `None`: a vertex inside the surface).
    pub new_curve: Vec<Option<CurvePoint>>,
    /// The triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[PatchVertex; 3]>,
}

/// The location a vertex has before one is known (a referenced vertex always has one).
const UNLOCATED: SurfaceLocation = SurfaceLocation {
    face: FaceId(0),
    bary: [1.0, 0.0, 0.0],
};

impl WorkingMesh {
    /// Start Algorithm 1 on `reference`: every vertex located at itself, nothing processed.
    pub fn from_reference(reference: &TriMesh) -> WorkingMesh {
        let mut locations = VertexMap::filled(reference.n_vertices(), UNLOCATED);
        // Each vertex is located as a corner of its last incident face.
        for (f, t) in reference.triangles.iter().enumerate() {
            for (k, &v) in t.iter().enumerate() {
                let mut bary = [0.0; 3];
                bary[k] = 1.0;
                locations[v] = SurfaceLocation {
                    face: FaceId::new(f),
                    bary,
                };
            }
        }
        WorkingMesh {
            mesh: reference.clone(),
            locations,
            processed: FaceMap::filled(reference.n_faces(), false),
            curve: VertexMap::filled(reference.n_vertices(), None),
        }
    }

    /// Number of unprocessed faces.
    pub fn unprocessed(&self) -> usize {
        self.processed.iter().filter(|p| !**p).count()
    }

    /// Drop vertices no face references; returns the old → new vertex map.
    pub fn compact(&mut self) -> Vec<Option<VertexId>> {
        let (mesh, map) = self.mesh.without_unreferenced_vertices();
        self.mesh = mesh;
        self.locations.compact(&map, UNLOCATED);
        self.curve.compact(&map, None);
        map
    }
}

/// Replace the faces `patch_faces` of the working mesh by `replacement`, marking the new
/// faces processed. Faces outside the patch keep their relative order (their ids shift
/// down past removed faces); new faces are appended. Returns the ids of the new faces.
pub fn stitch(
    work: &mut WorkingMesh,
    patch_faces: &[FaceId],
    replacement: &Replacement,
) -> Result<Vec<FaceId>, StitchError> {
    let mut new = stitch_all(work, &[(patch_faces, replacement)])?;
    Ok(new.pop().unwrap_or_default())
}

/// [`stitch`] for several patches with disjoint face sets at once (a batch of Algorithm 1,
/// ids of the same working mesh): the faces of all patches are dropped, the replacements
/// appended in order, their new vertices numbered in order. The arrays come out exactly as
/// from stitching the patches one after another (with their face ids followed), in one pass
/// over the faces instead of one per patch. Returns each patch's new faces. On an error the
/// working mesh is untouched.
pub fn stitch_all(
    work: &mut WorkingMesh,
    patches: &[(&[FaceId], &Replacement)],
) -> Result<Vec<Vec<FaceId>>, StitchError> {
    let nf = work.mesh.n_faces();
    let mut remove = vec![false; nf];
    let mut base = work.mesh.n_vertices() as u32;
    let mut new_tris = Vec::with_capacity(patches.len());
    for (patch_faces, replacement) in patches {
        for &f in *patch_faces {
            if f.idx() >= nf || remove[f.idx()] {
                return Err(StitchError::BadFace(f));
            }
            remove[f.idx()] = true;
        }
        let n_old = work.mesh.n_vertices();
        let nv_new = replacement.new_positions.len() as u32;
        let mut tris = Vec::with_capacity(replacement.triangles.len());
        for (i, t) in replacement.triangles.iter().enumerate() {
            let mut out = [VertexId(0); 3];
            for (k, pv) in t.iter().enumerate() {
                out[k] = match *pv {
                    PatchVertex::Existing(v) if v.idx() < n_old => v,
                    PatchVertex::New(j) if j < nv_new => VertexId(base + j),
                    other => {
                        return Err(StitchError::BadVertex {
                            triangle: i,
                            vertex: other,
                        })
                    }
                };
            }
            tris.push(out);
        }
        base += nv_new;
        new_tris.push(tris);
    }
    let removed = remove.iter().filter(|r| **r).count();
    let added: usize = new_tris.iter().map(Vec::len).sum();
    let mut triangles = Vec::with_capacity(nf - removed + added);
    let mut processed = Vec::with_capacity(triangles.capacity());
    for (f, gone) in remove.iter().enumerate() {
        if !gone {
            triangles.push(work.mesh.triangles[f]);
            processed.push(work.processed[FaceId::new(f)]);
        }
    }
    let mut new_faces = Vec::with_capacity(patches.len());
    for tris in &new_tris {
        let first = triangles.len();
        triangles.extend_from_slice(tris);
        new_faces.push((first..triangles.len()).map(FaceId::new).collect());
    }
    processed.resize(triangles.len(), true);
    work.mesh.triangles = triangles;
    work.processed = FaceMap::from_vec(processed);
    for (_, replacement) in patches {
        work.mesh
            .positions
            .extend_from_slice(&replacement.new_positions);
        work.locations
            .extend(replacement.new_locations.iter().copied());
        let n = work.mesh.n_vertices();
        work.curve.resize(n - replacement.new_positions.len(), None);
        for i in 0..replacement.new_positions.len() {
            work.curve
                .push(replacement.new_curve.get(i).copied().flatten());
        }
    }
    Ok(new_faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{generators, Topology};

    #[test]
    fn stitch_replaces_fan_by_split_fan_and_keeps_manifold() {
        // Replace the centre fan of a disk by the same fan around a new, moved centre vertex.
        let d = generators::disk(1.0, 2, 6);
        let mut w = WorkingMesh::from_reference(&d);
        let topo = Topology::build(&d);
        let fan: Vec<FaceId> = topo.vertex_faces(VertexId(0)).to_vec();
        let ring: Vec<VertexId> = (1..=6).map(VertexId).collect();
        let repl = Replacement {
            new_positions: vec![Point3::new(0.01, 0.0, 0.0)],
            new_locations: vec![w.locations[VertexId(0)]],
            new_curve: Vec::new(),
            triangles: (0..6)
                .map(|i| {
                    [
                        PatchVertex::New(0),
                        PatchVertex::Existing(ring[i]),
                        PatchVertex::Existing(ring[(i + 1) % 6]),
                    ]
                })
                .collect(),
        };
        let before_unprocessed = w.unprocessed();
        let new_faces = stitch(&mut w, &fan, &repl).expect("valid replacement");
        assert_eq!(new_faces.len(), 6);
        assert_eq!(w.unprocessed(), before_unprocessed - 6);
        assert!(new_faces.iter().all(|&f| w.processed[f]));
        let t = Topology::build(&w.mesh);
        assert!(t.is_oriented_manifold());
        assert_eq!(t.components()[0].euler, 1);
        assert_eq!(t.boundary_loops().len(), 1);
        // Old centre is now unreferenced and disappears on compaction.
        let map = w.compact();
        assert_eq!(map[0], None);
        assert_eq!(w.mesh.n_vertices(), d.n_vertices());
        assert_eq!(w.locations.len(), w.mesh.n_vertices());
    }

    #[test]
    fn stitch_rejects_bad_references() {
        let d = generators::disk(1.0, 1, 6);
        let mut w = WorkingMesh::from_reference(&d);
        let bad = Replacement {
            triangles: vec![[
                PatchVertex::New(0),
                PatchVertex::Existing(VertexId(1)),
                PatchVertex::Existing(VertexId(2)),
            ]],
            ..Default::default()
        };
        assert!(matches!(
            stitch(&mut w, &[FaceId(0)], &bad),
            Err(StitchError::BadVertex {
                triangle: 0,
                vertex: PatchVertex::New(0)
            })
        ));
        assert_eq!(
            stitch(&mut w, &[FaceId(0), FaceId(0)], &Replacement::default()),
            Err(StitchError::BadFace(FaceId(0)))
        );
        assert_eq!(w.mesh, d, "a refused stitch leaves the mesh untouched");
    }
}
