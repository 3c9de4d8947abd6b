//! Invariants of a whole triangle mesh: manifold, oriented, no degenerate faces, no
//! self-intersections, topology kept, boundary kept. Every geometric decision is an exact
//! predicate from [`crate::predicates`].

use super::{ComponentTopologies, EdgeFaces, FacePair, InvariantError, Offenders, TopologyChange};
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::{Topology, TriMesh};
use crate::predicates::{
    collinear3d, edge_adjacent_triangles_overlap, triangles_intersect,
    vertex_adjacent_triangles_intersect,
};
use nalgebra::Point3;
use std::collections::HashSet;

/// Vertices whose incident faces do not form a single fan: the faces around `v`, linked when
/// they share an edge incident to `v`, fall into two or more groups (a pinch point).
///
/// Unlike [`Topology::non_manifold_vertices`], faces are linked through *any* shared edge,
/// whatever its face count or orientation, so a flipped face or a non-manifold edge is
/// reported once, as what it is, and does not also turn its vertices into pinch points.
/// Sorted.
pub fn non_manifold_vertices(mesh: &TriMesh, topo: &Topology) -> Vec<VertexId> {
    non_manifold_vertices_among(mesh, topo, (0..topo.n_vertices()).map(VertexId::new))
}

/// [`non_manifold_vertices`] restricted to `vertices` (in their order; ids out of range are
/// skipped), for a mesh that changed only around them.
pub fn non_manifold_vertices_among(
    mesh: &TriMesh,
    topo: &Topology,
    vertices: impl IntoIterator<Item = VertexId>,
) -> Vec<VertexId> {
    let vertices = vertices.into_iter().filter(|v| v.idx() < topo.n_vertices());
    let mut out = Vec::new();
    let tris = |f: FaceId| mesh.face(f);
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    // Buffers reused across vertices (this runs after every patch of Algorithm 1).
    let mut parent: Vec<usize> = Vec::new();
    let mut spokes: Vec<(VertexId, usize)> = Vec::new();
    for v in vertices {
        let faces = topo.vertex_faces(v);
        if faces.len() <= 1 {
            continue;
        }
        // Each face at v has two edges at v, named by their other endpoint; faces sharing an
        // other endpoint share that edge. Union–find over the (small) fan.
        parent.clear();
        parent.extend(0..faces.len());
        spokes.clear();
        for (k, &f) in faces.iter().enumerate() {
            for w in tris(f) {
                if w != v {
                    spokes.push((w, k));
                }
            }
        }
        spokes.sort_unstable();
        for s in spokes.windows(2) {
            if s[0].0 == s[1].0 {
                let (a, b) = (find(&mut parent, s[0].1), find(&mut parent, s[1].1));
                parent[a.max(b)] = a.min(b);
            }
        }
        let r0 = find(&mut parent, 0);
        if (1..faces.len()).any(|k| find(&mut parent, k) != r0) {
            out.push(v);
        }
    }
    out
}

/// Every edge has one or two faces, and every vertex's faces form one fan
/// ([`non_manifold_vertices`]). Non-manifold edges are reported first.
pub fn certify_manifold(mesh: &TriMesh, topo: &Topology) -> Result<(), InvariantError> {
    debug_assert_eq!(mesh.n_faces(), topo.n_faces());
    let edges = topo.non_manifold_edges();
    if !edges.is_empty() {
        return Err(InvariantError::NonManifoldEdges(Offenders(
            edges.iter().map(|&(e, k)| EdgeFaces(e, k)).collect(),
        )));
    }
    let verts = non_manifold_vertices(mesh, topo);
    if !verts.is_empty() {
        return Err(InvariantError::NonManifoldVertices(Offenders(verts)));
    }
    Ok(())
}

/// [`certify_manifold`] for a mesh that was manifold and then changed only in faces around
/// `touched` (the vertices of the faces removed and added): every edge still has one or two
/// faces (checked everywhere; the topology lists them), and every touched vertex's faces form
/// one fan. A vertex not touched has the same faces as before, so this certifies the whole
/// mesh by induction — Algorithm 1 certifies the input with [`certify_manifold`] and every
/// patch replacement with this, at the cost of the patch instead of the mesh. Offending
/// vertices are reported sorted.
pub fn certify_manifold_at(
    mesh: &TriMesh,
    topo: &Topology,
    touched: &[VertexId],
) -> Result<(), InvariantError> {
    debug_assert_eq!(mesh.n_faces(), topo.n_faces());
    let edges = topo.non_manifold_edges();
    if !edges.is_empty() {
        return Err(InvariantError::NonManifoldEdges(Offenders(
            edges.iter().map(|&(e, k)| EdgeFaces(e, k)).collect(),
        )));
    }
    let mut verts = non_manifold_vertices_among(mesh, topo, touched.iter().copied());
    verts.sort_unstable();
    verts.dedup();
    if !verts.is_empty() {
        return Err(InvariantError::NonManifoldVertices(Offenders(verts)));
    }
    Ok(())
}

/// Every edge with two faces is traversed in opposite directions by them (consistent
/// orientation). Offenders: the edges traversed twice in the same direction.
pub fn certify_oriented(mesh: &TriMesh, topo: &Topology) -> Result<(), InvariantError> {
    debug_assert_eq!(mesh.n_faces(), topo.n_faces());
    let bad = topo.inconsistent_edges();
    if bad.is_empty() {
        Ok(())
    } else {
        Err(InvariantError::InconsistentOrientation(Offenders(
            bad.to_vec(),
        )))
    }
}

/// `true` when face `f` has exactly zero area: its corners are collinear (or coincide),
/// decided exactly as the projections on the xy, yz and zx planes all having zero
/// `orient2d` (they are the three components of the normal `(b − a) × (c − a)`).
pub fn is_degenerate(mesh: &TriMesh, f: FaceId) -> bool {
    let [a, b, c] = mesh.face_points(f);
    collinear3d(&a, &b, &c)
}

/// All faces of exactly zero area ([`is_degenerate`]), in id order.
pub fn degenerate_faces(mesh: &TriMesh) -> Vec<FaceId> {
    mesh.faces().filter(|&f| is_degenerate(mesh, f)).collect()
}

/// No face has exactly zero area.
pub fn certify_no_degenerate_faces(mesh: &TriMesh) -> Result<(), InvariantError> {
    let bad = degenerate_faces(mesh);
    if bad.is_empty() {
        Ok(())
    } else {
        Err(InvariantError::DegenerateFaces(Offenders(bad)))
    }
}

/// Whether the non-degenerate faces `f` and `g` (`f ≠ g`) intersect in more than the
/// elements they share by vertex id (CGAL `Polygon_mesh_processing::self_intersections`
/// semantics, decided exactly):
/// - three shared vertices (a duplicated face): they intersect;
/// - two shared vertices (a shared edge, in either direction): only if the faces are coplanar
///   and on the same side of the edge (folded over);
/// - one shared vertex: only if the edge opposite it in one face meets the other face;
/// - none: if the closed triangles have any common point (touching counts).
pub fn faces_intersect(mesh: &TriMesh, f: FaceId, g: FaceId) -> bool {
    let (tf, tg) = (mesh.face(f), mesh.face(g));
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| tf[i] == tg[j])
        .collect();
    let pf = mesh.face_points(f);
    let pg = mesh.face_points(g);
    match shared.len() {
        0 => triangles_intersect(&pf, &pg),
        1 => {
            let (i, j) = shared[0];
            vertex_adjacent_triangles_intersect(
                &pf[i],
                &pf[(i + 1) % 3],
                &pf[(i + 2) % 3],
                &pg[(j + 1) % 3],
                &pg[(j + 2) % 3],
            )
        }
        2 => {
            let (i0, _) = shared[0];
            let (i1, _) = shared[1];
            let r = 3 - i0 - i1;
            let s = (0..3)
                .find(|&j| shared.iter().all(|&(_, sj)| sj != j))
                .unwrap_or(0);
            edge_adjacent_triangles_overlap(&pf[i0], &pf[i1], &pf[r], &pg[s])
        }
        _ => true,
    }
}

/// Self-intersecting face pairs `(f, g)`, `f < g`, sorted; a degenerate face `f` is reported
/// as the pair `(f, f)` and takes no further part (CGAL's convention: a zero-area face is a
/// self-intersection by itself, and it has no plane to test against). The verdict of every
/// other pair is [`faces_intersect`]'s.
///
/// The search (`invariants/pairs.rs`) runs one exact query per edge of the mesh against a
/// hierarchy of exact face boxes that prunes the faces sharing an endpoint of the edge, so
/// fans of long thin faces cost about linear time, and it is parallel (rayon) from 1,024
/// faces on. The output is sorted, hence independent of thread scheduling.
pub fn self_intersections(mesh: &TriMesh) -> Vec<(FaceId, FaceId)> {
    super::pairs::self_intersections_with_stats(mesh).0
}

/// No two faces intersect other than in their shared vertices and edges, and no face is
/// degenerate (see [`self_intersections`]).
pub fn certify_no_self_intersections(mesh: &TriMesh) -> Result<(), InvariantError> {
    let pairs = self_intersections(mesh);
    if pairs.is_empty() {
        Ok(())
    } else {
        Err(InvariantError::SelfIntersections(Offenders(
            pairs.into_iter().map(|(f, g)| FacePair(f, g)).collect(),
        )))
    }
}

/// The topology a run must keep: the number of components and boundary loops and the
/// per-component `(genus, boundary loops)`, sorted so that renumbered components compare
/// equal. A genus that is not a non-negative integer prints as `?`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopologySignature {
    components: usize,
    boundary_loops: usize,
    per_component: Vec<(Option<u32>, usize)>,
}

impl TopologySignature {
    /// The signature of a mesh's topology.
    pub fn of(topo: &Topology) -> TopologySignature {
        let mut per_component: Vec<(Option<u32>, usize)> = topo
            .components()
            .iter()
            .map(|c| (c.genus, c.boundary_loops))
            .collect();
        per_component.sort_unstable();
        TopologySignature {
            components: topo.components().len(),
            boundary_loops: topo.boundary_loops().len(),
            per_component,
        }
    }

    /// `Ok` when `after` equals `self`, else the first difference: components, boundary
    /// loops, then the per-component genus and loops.
    pub fn certify_same(&self, after: &TopologySignature) -> Result<(), InvariantError> {
        if self.components != after.components {
            return Err(InvariantError::TopologyChanged(
                TopologyChange::Components {
                    before: self.components,
                    after: after.components,
                },
            ));
        }
        if self.boundary_loops != after.boundary_loops {
            return Err(InvariantError::TopologyChanged(
                TopologyChange::BoundaryLoops {
                    before: self.boundary_loops,
                    after: after.boundary_loops,
                },
            ));
        }
        if self.per_component != after.per_component {
            return Err(InvariantError::TopologyChanged(
                TopologyChange::PerComponent {
                    before: ComponentTopologies(self.per_component.clone()),
                    after: ComponentTopologies(after.per_component.clone()),
                },
            ));
        }
        Ok(())
    }
}

/// `after` has the topology of `before`: the same number of connected components, the same
/// number of boundary loops, and the same multiset of per-component (genus, boundary loops)
/// (components may be renumbered).
pub fn certify_same_topology(before: &TriMesh, after: &TriMesh) -> Result<(), InvariantError> {
    let (tb, ta) = (Topology::build(before), Topology::build(after));
    TopologySignature::of(&tb).certify_same(&TopologySignature::of(&ta))
}

/// A position as bits, with `-0.0` identified with `0.0` (the same point).
fn key(p: &Point3<f64>) -> [u64; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// The boundary edges of `mesh` (edges with one face), by vertex ids.
pub fn boundary_edges(topo: &Topology) -> Vec<EdgeKey> {
    topo.edges()
        .iter()
        .zip(topo.edge_face_counts())
        .filter(|(_, &n)| n == 1)
        .map(|(e, _)| *e)
        .collect()
}

/// Every boundary vertex of `before` is, bit for bit, the position of a vertex of `after`,
/// and every boundary edge of `before` (an edge with one face) joins two positions that are
/// joined by a boundary edge of `after`. Offenders are named by their ids in `before`;
/// vertices are checked first.
pub fn certify_boundary_preserved(before: &TriMesh, after: &TriMesh) -> Result<(), InvariantError> {
    let (tb, ta) = (Topology::build(before), Topology::build(after));
    certify_boundary_kept(before, &boundary_edges(&tb), after, &boundary_edges(&ta))
}

/// [`certify_boundary_preserved`] with the boundary edges of both meshes given (the pipeline
/// keeps the input's and computes the working mesh's after every patch).
pub fn certify_boundary_kept(
    before: &TriMesh,
    before_boundary: &[EdgeKey],
    after: &TriMesh,
    after_boundary: &[EdgeKey],
) -> Result<(), InvariantError> {
    if before_boundary.is_empty() {
        return Ok(());
    }
    let after_positions: HashSet<[u64; 3]> = after_boundary
        .iter()
        .flat_map(|e| [e.0, e.1])
        .map(|v| key(after.position(v)))
        .collect();
    let mut moved: Vec<VertexId> = before_boundary
        .iter()
        .flat_map(|e| [e.0, e.1])
        .filter(|v| !after_positions.contains(&key(before.position(*v))))
        .collect();
    moved.sort_unstable();
    moved.dedup();
    if !moved.is_empty() {
        return Err(InvariantError::BoundaryVerticesMoved(Offenders(moved)));
    }
    let unordered = |a: [u64; 3], b: [u64; 3]| if a <= b { (a, b) } else { (b, a) };
    let after_edges: HashSet<([u64; 3], [u64; 3])> = after_boundary
        .iter()
        .map(|e| unordered(key(after.position(e.0)), key(after.position(e.1))))
        .collect();
    let missing: Vec<EdgeKey> = before_boundary
        .iter()
        .filter(|e| {
            !after_edges.contains(&unordered(
                key(before.position(e.0)),
                key(before.position(e.1)),
            ))
        })
        .copied()
        .collect();
    if !missing.is_empty() {
        return Err(InvariantError::BoundaryEdgesMissing(Offenders(missing)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    fn mesh(p: &[(f64, f64, f64)], t: &[[usize; 3]]) -> TriMesh {
        TriMesh::from_indices(p.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect(), t)
            .expect("valid test mesh")
    }

    #[test]
    fn generated_surfaces_pass_every_certificate() {
        for m in [
            generators::icosphere(1.0, 2),
            generators::torus(1.0, 0.3, 24, 12),
            generators::genus_plate(2, 2),
            generators::disk(1.0, 4, 12),
        ] {
            let t = Topology::build(&m);
            certify_manifold(&m, &t).unwrap();
            certify_oriented(&m, &t).unwrap();
            certify_no_degenerate_faces(&m).unwrap();
            certify_no_self_intersections(&m).unwrap();
            certify_same_topology(&m, &m).unwrap();
            certify_boundary_preserved(&m, &m).unwrap();
        }
    }

    /// Corners for the small non-manifold cases below (fans meeting at v0 and v5).
    const PINCH_POINTS: [(f64, f64, f64); 8] = [
        (0., 0., 0.),
        (1., 0., 0.),
        (0.5, 1., 0.),
        (0.5, -1., 0.),
        (0.5, 0., 1.),
        (-1., 0.5, 0.),
        (-1., -0.5, 0.),
        (-1., -0.5, 1.),
    ];

    #[test]
    fn manifold_failures_name_the_elements() {
        let p = &PINCH_POINTS[..7];
        let m = mesh(p, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        let e = certify_manifold(&m, &Topology::build(&m)).unwrap_err();
        assert_eq!(
            e,
            InvariantError::NonManifoldEdges(Offenders(vec![EdgeFaces(
                EdgeKey(VertexId(0), VertexId(1)),
                3
            )]))
        );
        let m = mesh(p, &[[0, 1, 2], [0, 5, 6]]);
        let e = certify_manifold(&m, &Topology::build(&m)).unwrap_err();
        assert_eq!(
            e,
            InvariantError::NonManifoldVertices(Offenders(vec![VertexId(0)]))
        );
        // A flipped neighbour is an orientation problem, not a pinch point.
        let m = mesh(p, &[[0, 1, 2], [0, 1, 3]]);
        let t = Topology::build(&m);
        certify_manifold(&m, &t).unwrap();
        assert_eq!(
            certify_oriented(&m, &t).unwrap_err(),
            InvariantError::InconsistentOrientation(Offenders(vec![EdgeKey(
                VertexId(0),
                VertexId(1)
            )]))
        );
    }

    /// The local certificate checks the vertices it is given (in any order, with repeats and
    /// out-of-range ids ignored) and every edge; it agrees with the whole-mesh certificate
    /// whenever the offending vertex is among them.
    #[test]
    fn local_manifold_certificate_checks_the_touched_vertices_and_every_edge() {
        let p = &PINCH_POINTS;
        // Two fans pinched at v0, and a second pinch at v5 (faces 1 and 2 meet only there).
        let m = mesh(p, &[[0, 1, 2], [0, 5, 6], [5, 3, 7]]);
        let t = Topology::build(&m);
        let whole = certify_manifold(&m, &t).unwrap_err();
        assert_eq!(
            whole,
            InvariantError::NonManifoldVertices(Offenders(vec![VertexId(0), VertexId(5)]))
        );
        let at = |vs: &[u32]| {
            let vs: Vec<VertexId> = vs.iter().map(|&v| VertexId(v)).collect();
            certify_manifold_at(&m, &t, &vs)
        };
        assert_eq!(at(&[5, 0, 5, 99]).unwrap_err(), whole);
        assert_eq!(
            at(&[2, 5]).unwrap_err(),
            InvariantError::NonManifoldVertices(Offenders(vec![VertexId(5)]))
        );
        // Untouched pinches are the caller's induction hypothesis, not checked.
        at(&[1, 2, 6]).unwrap();
        at(&[]).unwrap();
        assert_eq!(
            non_manifold_vertices_among(&m, &t, [VertexId(5), VertexId(77), VertexId(0)]),
            vec![VertexId(5), VertexId(0)]
        );
        // A non-manifold edge is found whatever the touched vertices.
        let m = mesh(p, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        let t = Topology::build(&m);
        assert_eq!(
            certify_manifold_at(&m, &t, &[]).unwrap_err(),
            InvariantError::NonManifoldEdges(Offenders(vec![EdgeFaces(
                EdgeKey(VertexId(0), VertexId(1)),
                3
            )]))
        );
    }

    #[test]
    fn degenerate_faces_are_exactly_zero_area() {
        // Collinear along a direction that is not an axis; and a nearly collinear face one
        // ulp off the line, which is not degenerate.
        let m = mesh(
            &[
                (0., 0., 0.),
                (1., 2., 3.),
                (2., 4., 6.),
                (3., 6., 9. + 8.0 * f64::EPSILON),
                (1., 0., 0.),
            ],
            &[[0, 1, 2], [0, 1, 3], [0, 1, 4]],
        );
        assert!(is_degenerate(&m, FaceId(0)));
        assert!(!is_degenerate(&m, FaceId(1)));
        assert!(!is_degenerate(&m, FaceId(2)));
        assert_eq!(
            certify_no_degenerate_faces(&m).unwrap_err(),
            InvariantError::DegenerateFaces(Offenders(vec![FaceId(0)]))
        );
        assert_eq!(self_intersections(&m)[0], (FaceId(0), FaceId(0)));
    }

    #[test]
    fn self_intersections_follow_shared_element_rules() {
        // Two triangles in the plane sharing edge (0,1): flat → fine; folded over → pair.
        let p = [
            (0., 0., 0.),
            (2., 0., 0.),
            (1., 1., 0.),
            (1., -1., 0.),
            (1.5, 2., 0.),
        ];
        let flat = mesh(&p, &[[0, 1, 2], [1, 0, 3]]);
        assert!(self_intersections(&flat).is_empty());
        let folded = mesh(&p, &[[0, 1, 2], [1, 0, 4]]);
        assert_eq!(self_intersections(&folded), vec![(FaceId(0), FaceId(1))]);
        // Sharing one vertex: a fan neighbour is fine, one crossing the other is not.
        let q = [
            (0., 0., 0.),
            (2., 0., 0.),
            (0., 2., 0.),
            (-2., 0., 0.),
            (0., -2., 0.),
            (1., 1., 1.),
            (1., 0.2, -1.),
        ];
        assert!(self_intersections(&mesh(&q, &[[0, 1, 2], [0, 3, 4]])).is_empty());
        assert_eq!(
            self_intersections(&mesh(&q, &[[0, 1, 2], [0, 5, 6]])),
            vec![(FaceId(0), FaceId(1))]
        );
        // No shared vertex, touching at a point: counts.
        let r = [
            (0., 0., 0.),
            (2., 0., 0.),
            (0., 2., 0.),
            (0.5, 0.5, 0.),
            (0.5, 0.5, 1.),
            (1., 0.5, 1.),
        ];
        assert_eq!(
            self_intersections(&mesh(&r, &[[0, 1, 2], [3, 4, 5]])),
            vec![(FaceId(0), FaceId(1))]
        );
        // Duplicated face.
        assert_eq!(
            self_intersections(&mesh(&r, &[[0, 1, 2], [0, 2, 1]])),
            vec![(FaceId(0), FaceId(1))]
        );
    }

    #[test]
    fn pushing_a_vertex_through_the_surface_is_caught() {
        let mut m = generators::icosphere(1.0, 2);
        certify_no_self_intersections(&m).unwrap();
        // Push v0 through the sphere, out past the antipode: its fan must cross the far side.
        m.positions[0] = Point3::from(-m.positions[0].coords * 1.5);
        let pairs = self_intersections(&m);
        assert!(!pairs.is_empty());
        assert!(pairs.windows(2).all(|w| w[0] < w[1]), "sorted and unique");
        let fan: Vec<FaceId> = Topology::build(&m).vertex_faces(VertexId(0)).to_vec();
        assert!(pairs
            .iter()
            .all(|(f, g)| fan.contains(f) || fan.contains(g)));
    }

    #[test]
    fn broad_phase_loses_no_pair() {
        // Two overlapping spheres, one rotated so that their faces cross in general position,
        // plus a coplanar touching case: the BVH result equals the all-pairs brute force, on
        // the calling thread (640 faces) and with rayon (1,600 faces).
        for (level_a, parallel) in [(2, false), (3, true)] {
            let a = generators::icosphere(1.0, level_a);
            let b = generators::icosphere(0.8, 2);
            let mut m = a.clone();
            let n = m.positions.len() as u32;
            let rot = nalgebra::Rotation3::from_euler_angles(0.3, 0.2, 0.1);
            m.positions.extend(
                b.positions
                    .iter()
                    .map(|p| rot * p + nalgebra::Vector3::new(0.5, 0.25, 0.0)),
            );
            m.triangles
                .extend(b.triangles.iter().map(|t| t.map(|v| VertexId(v.0 + n))));
            assert_eq!(
                m.n_faces() >= super::super::pairs::PARALLEL_MIN_FACES,
                parallel
            );
            let fast = self_intersections(&m);
            let mut slow = Vec::new();
            for i in 0..m.n_faces() {
                for j in i + 1..m.n_faces() {
                    if faces_intersect(&m, FaceId::new(i), FaceId::new(j)) {
                        slow.push((FaceId::new(i), FaceId::new(j)));
                    }
                }
            }
            assert!(slow.len() > 20, "{}", slow.len());
            assert_eq!(fast, slow);
        }
    }

    #[test]
    fn topology_and_boundary_changes_are_named() {
        let torus = generators::torus(1.0, 0.3, 16, 8);
        let sphere = generators::icosphere(1.0, 1);
        let e = certify_same_topology(&torus, &sphere).unwrap_err();
        assert!(
            matches!(
                e,
                InvariantError::TopologyChanged(TopologyChange::PerComponent { .. })
            ),
            "{e}"
        );
        let disk = generators::disk(1.0, 3, 8);
        let e = certify_same_topology(&disk, &sphere).unwrap_err();
        assert!(
            matches!(
                e,
                InvariantError::TopologyChanged(TopologyChange::BoundaryLoops {
                    before: 1,
                    after: 0
                })
            ),
            "{e}"
        );
        let mut two = sphere.clone();
        let n = two.positions.len() as u32;
        two.positions.extend(
            sphere
                .positions
                .iter()
                .map(|p| p + nalgebra::Vector3::new(5.0, 0.0, 0.0)),
        );
        two.triangles.extend(
            sphere
                .triangles
                .iter()
                .map(|t| t.map(|v| VertexId(v.0 + n))),
        );
        let e = certify_same_topology(&sphere, &two).unwrap_err();
        assert!(
            matches!(
                e,
                InvariantError::TopologyChanged(TopologyChange::Components {
                    before: 1,
                    after: 2
                })
            ),
            "{e}"
        );

        // Moving an interior vertex keeps the boundary; moving a boundary vertex does not.
        let t = Topology::build(&disk);
        let interior = disk.vertices().find(|&v| !t.is_boundary_vertex(v)).unwrap();
        let boundary = t.boundary_loops()[0][0];
        let mut moved = disk.clone();
        moved.positions[interior.idx()].z += 0.1;
        certify_boundary_preserved(&disk, &moved).unwrap();
        moved.positions[boundary.idx()].z += 1e-300;
        assert_eq!(
            certify_boundary_preserved(&disk, &moved).unwrap_err(),
            InvariantError::BoundaryVerticesMoved(Offenders(vec![boundary]))
        );
        // Splitting a boundary edge keeps every vertex but loses the edge.
        let l = &t.boundary_loops()[0];
        let (a, b) = (l[0], l[1]);
        let mut split = disk.clone();
        let mid = Point3::from((disk.position(a).coords + disk.position(b).coords) / 2.0);
        split.positions.push(mid);
        let m = VertexId::new(split.positions.len() - 1);
        let f = split
            .faces()
            .find(|&f| {
                let tr = split.face(f);
                (0..3).any(|i| tr[i] == a && tr[(i + 1) % 3] == b)
            })
            .unwrap();
        let tr = split.face(f);
        let i = (0..3).find(|&i| tr[i] == a).unwrap();
        let c = tr[(i + 2) % 3];
        split.triangles[f.idx()] = [a, m, c];
        split.triangles.push([m, b, c]);
        assert_eq!(
            certify_boundary_preserved(&disk, &split).unwrap_err(),
            InvariantError::BoundaryEdgesMissing(Offenders(vec![EdgeKey::new(a, b)]))
        );
    }
}
