//! Certificates of a candidate change to the working mesh, before it is made: the lifted
//! faces of a remeshed patch, an edge flip or a vertex move. None of the new faces may be
//! degenerate (exact), flipped against the reference, or intersect the faces around it
//! (exact), and no new edge may already exist outside the patch.

use super::{EdgeFaces, FacePair, FlipTest, InvariantError, Offenders};
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::{bbox_of, Topology, TriMesh};
use crate::predicates::collinear3d;
use crate::stitch::{PatchVertex, Replacement, WorkingMesh};
use nalgebra::Point3;
use std::collections::{HashMap, HashSet};

/// Exact: the corners of `p` are collinear (the triangle is degenerate).
pub fn is_degenerate_triangle(p: &[Point3<f64>; 3]) -> bool {
    collinear3d(&p[0], &p[1], &p[2])
}

/// The new faces of a candidate replacement: none degenerate (exact), none flipped against
/// the reference surface (normal more than 90° from the normal of the reference face closest
/// to the face's centroid).
pub fn certify_replacement(
    flip_test: &FlipTest,
    work: &WorkingMesh,
    topo: &Topology,
    patch_faces: &[FaceId],
    r: &Replacement,
) -> Result<(), InvariantError> {
    // A new edge between two existing (patch boundary) vertices must not already be an edge
    // of the working mesh outside the patch: a disk patch can touch itself from outside (two
    // boundary vertices joined by an outside edge), and a planar chord between them would
    // give that edge four faces after stitching.
    let in_patch: HashSet<FaceId> = patch_faces.iter().copied().collect();
    let mut duplicated = Vec::new();
    for t in &r.triangles {
        for k in 0..3 {
            if let (PatchVertex::Existing(a), PatchVertex::Existing(b)) = (t[k], t[(k + 1) % 3]) {
                let has_edge = |f: &&FaceId| work.mesh.triangles[f.idx()].contains(&b);
                let faces_a = topo.vertex_faces(a);
                // An edge of the patch itself (its boundary edges) is fine.
                let patch_edge = faces_a
                    .iter()
                    .filter(has_edge)
                    .any(|f| in_patch.contains(f));
                let outside = faces_a
                    .iter()
                    .filter(has_edge)
                    .any(|f| !in_patch.contains(f));
                if outside && !patch_edge {
                    duplicated.push(EdgeFaces(EdgeKey::new(a, b), 4));
                }
            }
        }
    }
    if !duplicated.is_empty() {
        duplicated.sort_by_key(|e| e.0);
        duplicated.dedup();
        return Err(InvariantError::NonManifoldEdges(Offenders(duplicated)));
    }
    let pos = |v: &PatchVertex| match *v {
        PatchVertex::Existing(g) => work.mesh.positions[g.idx()],
        PatchVertex::New(i) => r.new_positions[i as usize],
    };
    let mut degenerate = Vec::new();
    let mut flipped = Vec::new();
    for (i, t) in r.triangles.iter().enumerate() {
        let p = [pos(&t[0]), pos(&t[1]), pos(&t[2])];
        // Index in the stitched mesh is unknown yet: report the replacement index as a face id
        // of the candidate.
        let f = FaceId::new(i);
        if is_degenerate_triangle(&p) {
            degenerate.push(f);
            continue;
        }
        if flip_test.is_flipped_anywhere(&p) {
            flipped.push(f);
        }
    }
    if !degenerate.is_empty() {
        return Err(InvariantError::DegenerateFaces(Offenders(degenerate)));
    }
    if !flipped.is_empty() {
        return Err(InvariantError::FlippedFaces(Offenders(flipped)));
    }
    Ok(())
}

/// Exact local self-intersection test of a candidate: the new faces against each other and
/// against the working-mesh faces (outside the patch) whose bounding boxes meet the new faces'
/// bounding box. Pairs of two old faces are not the candidate's doing and are ignored. Face ids
/// in the error: `f0..` are the candidate's triangles, larger ids the old faces in id order.
/// `near` finds those faces without a scan of the whole mesh; without it, every face's box is
/// tested.
pub fn certify_candidate_embedded(
    work: &WorkingMesh,
    topo: &Topology,
    near: Option<&NearFaces>,
    patch_faces: &[FaceId],
    r: &Replacement,
) -> Result<(), InvariantError> {
    let base = work.mesh.n_vertices() as u32;
    let position = |v: VertexId| match v.0.checked_sub(base) {
        Some(i) => r.new_positions[i as usize],
        None => work.mesh.positions[v.idx()],
    };
    let new_tris = numbered_triangles(r, base);
    let Some((lo, hi)) = bbox_of(new_tris.iter().flatten().map(|&v| position(v))) else {
        return Ok(());
    };
    let mut in_patch = patch_faces.to_vec();
    in_patch.sort_unstable();
    let meets = |f: usize| {
        let t = work.mesh.triangles[f];
        bbox_of(t.iter().map(|v| work.mesh.positions[v.idx()])).is_some_and(|(a, b)| {
            (0..3).all(|k| a[k] <= hi[k] && b[k] >= lo[k])
                && in_patch.binary_search(&FaceId::new(f)).is_err()
        })
    };
    let scan = || -> Vec<usize> { (0..work.mesh.n_faces()).filter(|&f| meets(f)).collect() };
    let old: Vec<usize> = match near.and_then(|n| n.faces_meeting(&work.mesh, topo, &lo, &hi)) {
        Some(listed) => {
            let found: Vec<usize> = listed.into_iter().filter(|&f| meets(f)).collect();
            debug_assert_eq!(found, scan(), "the face index missed faces");
            found
        }
        None => scan(),
    };
    let n_new = new_tris.len();
    let mut tris = new_tris;
    tris.extend(old.iter().map(|&f| work.mesh.triangles[f]));
    let mut local_id: HashMap<VertexId, VertexId> = HashMap::new();
    let mut positions = Vec::new();
    for t in &mut tris {
        for v in t.iter_mut() {
            *v = *local_id.entry(*v).or_insert_with(|| {
                positions.push(position(*v));
                VertexId::new(positions.len() - 1)
            });
        }
    }
    let local = TriMesh {
        positions,
        triangles: tris,
    };
    let pairs: Vec<FacePair> = super::self_intersections(&local)
        .into_iter()
        .filter(|(a, b)| a.idx() < n_new || b.idx() < n_new)
        .map(|(a, b)| FacePair(a, b))
        .collect();
    if pairs.is_empty() {
        Ok(())
    } else {
        Err(InvariantError::SelfIntersections(Offenders(pairs)))
    }
}

/// Where the working mesh's triangles lie, for [`certify_candidate_embedded`] in Algorithm 1's
/// loop: a uniform grid of triangle boxes, keyed by the triangles themselves (face ids shift
/// at every stitch; a vertex never moves while patches are stitched, so a listed triangle that
/// still exists is listed in every cell its box overlaps). Stitched faces are added
/// ([`NearFaces::insert`]); removed ones stay listed and are dropped at the query, which finds
/// each listed triangle's current face through the topology. Built again whenever vertices
/// may have moved (before each pass of patches).
pub struct NearFaces {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<[VertexId; 3]>>,
    /// Triangles whose box spans more than [`NearFaces::MAX_CELLS`] cells: always returned.
    large: Vec<[VertexId; 3]>,
    listed: usize,
}

impl NearFaces {
    /// A triangle spanning more cells than this is kept in one list instead.
    const MAX_CELLS: i64 = 64;

    /// Index every face of `mesh`, with cells of twice its mean edge length.
    pub fn new(mesh: &TriMesh) -> NearFaces {
        let mut n = NearFaces {
            cell: (2.0 * mesh.mean_edge_length()).max(1e-12),
            cells: HashMap::new(),
            large: Vec::new(),
            listed: 0,
        };
        n.insert(mesh, (0..mesh.n_faces()).map(FaceId::new));
        n
    }

    fn key(&self, p: &Point3<f64>) -> [i64; 3] {
        [0, 1, 2].map(|k| (p[k] / self.cell).floor() as i64)
    }

    /// List the faces `faces` of `mesh` (just stitched).
    pub fn insert(&mut self, mesh: &TriMesh, faces: impl Iterator<Item = FaceId>) {
        for f in faces {
            let t = mesh.triangles[f.idx()];
            let Some((lo, hi)) = bbox_of(t.iter().map(|v| mesh.positions[v.idx()])) else {
                continue;
            };
            let (a, b) = (self.key(&lo), self.key(&hi));
            let span = (0..3).map(|k| b[k] - a[k] + 1).product::<i64>();
            self.listed += 1;
            if span > Self::MAX_CELLS {
                self.large.push(t);
                continue;
            }
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        self.cells.entry([i, j, k]).or_default().push(t);
                    }
                }
            }
        }
    }

    /// The current faces whose listed box may meet `lo..hi`, sorted; `None` when the box spans
    /// so many cells that a scan of the faces is cheaper.
    pub fn faces_meeting(
        &self,
        mesh: &TriMesh,
        topo: &Topology,
        lo: &Point3<f64>,
        hi: &Point3<f64>,
    ) -> Option<Vec<usize>> {
        let (a, b) = (self.key(lo), self.key(hi));
        let span = (0..3).map(|k| (b[k] - a[k] + 1) as f64).product::<f64>();
        if span > (self.listed.max(mesh.n_faces()) / 4) as f64 {
            return None;
        }
        let mut out = Vec::new();
        let mut add = |t: &[VertexId; 3]| {
            if let Some(f) = topo
                .vertex_faces(t[0])
                .iter()
                .find(|f| mesh.triangles[f.idx()] == *t)
            {
                out.push(f.idx());
            }
        };
        for t in &self.large {
            add(t);
        }
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    for t in self.cells.get(&[i, j, k]).into_iter().flatten() {
                        add(t);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        Some(out)
    }
}

/// A uniform grid over face bounding boxes, for the local self-intersection checks of the
/// post-loop passes (a linear scan per flip or move made them O(F) each: 17 s of armadillo's
/// run). A face is listed in every cell its box overlaps; boxes that grow (a moved vertex, a
/// flipped pair) are added again without removing the old entries, so a query returns a
/// superset of the faces whose current box overlaps, which the caller filters exactly.
pub struct FaceGrid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl FaceGrid {
    /// Index every face of `mesh`.
    pub fn new(mesh: &TriMesh) -> FaceGrid {
        let cell = (2.0 * mesh.mean_edge_length()).max(1e-12);
        let mut g = FaceGrid {
            cell,
            cells: HashMap::new(),
        };
        for (f, t) in mesh.triangles.iter().enumerate() {
            if let Some((lo, hi)) = bbox_of(t.iter().map(|v| mesh.positions[v.idx()])) {
                g.insert(f, &lo, &hi);
            }
        }
        g
    }

    fn key(&self, p: &Point3<f64>) -> [i64; 3] {
        [0, 1, 2].map(|k| (p[k] / self.cell).floor() as i64)
    }

    /// List face `f` in every cell the box `lo..hi` overlaps.
    pub fn insert(&mut self, f: usize, lo: &Point3<f64>, hi: &Point3<f64>) {
        let (a, b) = (self.key(lo), self.key(hi));
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    self.cells.entry([i, j, k]).or_default().push(f as u32);
                }
            }
        }
    }

    /// Faces listed in the cells the box overlaps, sorted, without repeats.
    pub fn query(&self, lo: &Point3<f64>, hi: &Point3<f64>) -> Vec<usize> {
        let (a, b) = (self.key(lo), self.key(hi));
        let mut out = Vec::new();
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    if let Some(fs) = self.cells.get(&[i, j, k]) {
                        out.extend(fs.iter().map(|f| *f as usize));
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// [`certify_candidate_embedded`] for a replacement without new vertices (a flip or a move,
/// with the working mesh already holding the moved positions), with the faces near the
/// candidate taken from `grid`: the same faces in the same order, so the same verdict.
pub fn candidate_embedded_local(
    mesh: &TriMesh,
    grid: &FaceGrid,
    replaced: &[FaceId],
    new_tris: &[[VertexId; 3]],
) -> bool {
    let p = |v: &VertexId| mesh.positions[v.idx()];
    let Some((lo, hi)) = bbox_of(new_tris.iter().flatten().map(p)) else {
        return true;
    };
    let mut tris: Vec<[VertexId; 3]> = new_tris.to_vec();
    for f in grid.query(&lo, &hi) {
        if f >= mesh.n_faces() || replaced.contains(&FaceId::new(f)) {
            continue;
        }
        let t = mesh.triangles[f];
        if let Some((a, b)) = bbox_of(t.iter().map(p)) {
            if (0..3).all(|k| a[k] <= hi[k] && b[k] >= lo[k]) {
                tris.push(t);
            }
        }
    }
    // Compact the vertices (ids only matter by equality in the exact test).
    let mut local: HashMap<VertexId, VertexId> = HashMap::new();
    let mut positions = Vec::new();
    let triangles = tris
        .iter()
        .map(|t| {
            t.map(|v| {
                *local.entry(v).or_insert_with(|| {
                    positions.push(p(&v));
                    VertexId::new(positions.len() - 1)
                })
            })
        })
        .collect();
    let n_new = new_tris.len();
    super::self_intersections(&TriMesh {
        positions,
        triangles,
    })
    .into_iter()
    .all(|(a, b)| a.idx() >= n_new && b.idx() >= n_new)
}

/// The working mesh's positions followed by the candidate's new vertices, and the candidate's
/// triangles in those ids (new vertex `i` is `n_vertices + i`).
pub fn candidate_arrays(
    work: &WorkingMesh,
    r: &Replacement,
) -> (Vec<Point3<f64>>, Vec<[VertexId; 3]>) {
    let mut positions = work.mesh.positions.clone();
    let base = positions.len() as u32;
    positions.extend_from_slice(&r.new_positions);
    (positions, numbered_triangles(r, base))
}

/// The replacement's triangles with its new vertices numbered from `base` on (as stitching
/// numbers them).
fn numbered_triangles(r: &Replacement, base: u32) -> Vec<[VertexId; 3]> {
    r.triangles
        .iter()
        .map(|t| {
            t.map(|v| match v {
                PatchVertex::Existing(g) => g,
                PatchVertex::New(i) => VertexId(base + i),
            })
        })
        .collect()
}

/// Pairs `(j, k)`, `j < k`, of candidates (replacements of vertex-disjoint patches of the same
/// working mesh, in batch order) whose new faces intersect (exact). Each candidate was certified
/// against the working mesh it was made on ([`certify_candidate_embedded`]); what that could
/// not see is another candidate of the same batch. The patches share no vertex, so any contact
/// between their new faces is an intersection.
pub fn crossing_candidates(work: &WorkingMesh, candidates: &[&Replacement]) -> Vec<(usize, usize)> {
    if candidates.len() < 2 {
        return Vec::new();
    }
    // A small mesh of the candidates' new faces only, with its own vertex numbering.
    let mut local: HashMap<VertexId, VertexId> = HashMap::new();
    let mut positions: Vec<Point3<f64>> = Vec::new();
    let mut triangles = Vec::new();
    let mut owner = Vec::new();
    for (k, r) in candidates.iter().enumerate() {
        let base = positions.len() as u32;
        positions.extend_from_slice(&r.new_positions);
        for t in &r.triangles {
            let tri = t.map(|v| match v {
                PatchVertex::New(i) => VertexId(base + i),
                PatchVertex::Existing(g) => *local.entry(g).or_insert_with(|| {
                    positions.push(work.mesh.positions[g.idx()]);
                    VertexId::new(positions.len() - 1)
                }),
            });
            triangles.push(tri);
            owner.push(k);
        }
    }
    let mesh = TriMesh {
        positions,
        triangles,
    };
    let mut pairs: Vec<(usize, usize)> = super::self_intersections(&mesh)
        .into_iter()
        .map(|(a, b)| (owner[a.idx()], owner[b.idx()]))
        .filter(|(j, k)| j != k)
        .map(|(j, k)| (j.min(k), j.max(k)))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// The grid-based local check gives the same verdict as the full scan, on moves that
    /// push a torus vertex through the opposite side of the tube (intersecting) and on small
    /// moves (not intersecting).
    #[test]
    fn local_embedding_check_agrees_with_the_full_scan() {
        let torus = crate::mesh::generators::torus(1.0, 0.3, 24, 12);
        let mut work = WorkingMesh::from_reference(&torus);
        let topo = Topology::build(&work.mesh);
        let grid = FaceGrid::new(&work.mesh);
        let (mut hits, mut misses) = (0, 0);
        for vi in (0..work.mesh.n_vertices()).step_by(7) {
            let v = VertexId::new(vi);
            let fan = topo.vertex_faces(v).to_vec();
            let old = work.mesh.positions[vi];
            // Towards the tube's centre line: 2.5 pierces the far wall, 0.05 stays near.
            let centre = Point3::from(Vector3::new(old.x, old.y, 0.0).normalize());
            for t in [0.05, 2.5] {
                work.mesh.positions[vi] = old + (centre - old) * t;
                let new_tris: Vec<[VertexId; 3]> =
                    fan.iter().map(|f| work.mesh.triangles[f.idx()]).collect();
                let r = Replacement {
                    triangles: new_tris
                        .iter()
                        .map(|t| t.map(PatchVertex::Existing))
                        .collect(),
                    ..Replacement::default()
                };
                let full = certify_candidate_embedded(&work, &topo, None, &fan, &r).is_ok();
                let local = candidate_embedded_local(&work.mesh, &grid, &fan, &new_tris);
                assert_eq!(full, local, "v{vi} t {t}");
                if full {
                    misses += 1
                } else {
                    hits += 1
                }
            }
            work.mesh.positions[vi] = old;
        }
        assert!(
            hits > 0 && misses > 0,
            "both verdicts exercised: {hits} / {misses}"
        );
    }

    /// With the face index the candidate certificate gives the scan's verdict, naming the same
    /// pairs: a torus vertex's fan around a new vertex pushed through the far wall of the tube
    /// (intersecting) or moved a little (not).
    #[test]
    fn the_face_index_finds_what_the_scan_finds() {
        let torus = crate::mesh::generators::torus(1.0, 0.3, 24, 12);
        let work = WorkingMesh::from_reference(&torus);
        let topo = Topology::build(&work.mesh);
        let near = NearFaces::new(&work.mesh);
        let (mut hits, mut misses) = (0, 0);
        for vi in (0..work.mesh.n_vertices()).step_by(5) {
            let v = VertexId::new(vi);
            let fan = topo.vertex_faces(v).to_vec();
            let old = work.mesh.positions[vi];
            let centre = Point3::from(Vector3::new(old.x, old.y, 0.0).normalize());
            for t in [0.05, 2.5] {
                let r = Replacement {
                    new_positions: vec![old + (centre - old) * t],
                    new_locations: vec![work.locations[v]],
                    new_curve: Vec::new(),
                    triangles: fan
                        .iter()
                        .map(|f| {
                            work.mesh.triangles[f.idx()].map(|u| match u == v {
                                true => PatchVertex::New(0),
                                false => PatchVertex::Existing(u),
                            })
                        })
                        .collect(),
                };
                let scan = certify_candidate_embedded(&work, &topo, None, &fan, &r);
                let indexed = certify_candidate_embedded(&work, &topo, Some(&near), &fan, &r);
                assert_eq!(scan, indexed, "v{vi} t {t}");
                match scan {
                    Ok(()) => misses += 1,
                    Err(_) => hits += 1,
                }
            }
        }
        assert!(hits > 0 && misses > 0, "{hits} / {misses}");
    }
}
