//! `Topology` and the mesh certificates against brute-force oracles: every derived quantity
//! recomputed from the face list by its definition (quadratic loops, breadth-first search),
//! on seeded random triangle soups over a handful of vertices (non-manifold edges, flipped
//! faces, pinch vertices, several components, unreferenced vertices) and on random face
//! subsets of closed oriented surfaces (boundary loops, genus).
//!
//! Written for mutation testing (TESTING.md "Mutation testing"): the oracles share no code
//! with `src/mesh/topology.rs` or `src/invariants/mesh.rs`.

use conemesh::invariants::{
    certify_manifold, certify_manifold_at, certify_oriented, certify_same_topology,
    non_manifold_vertices, InvariantError, Offenders, TopologyChange,
};
use conemesh::mesh::generators;
use conemesh::{EdgeKey, FaceId, HalfedgeId, Rng, Topology, TriMesh, VertexId};
use nalgebra::Point3;
use rand::{Rng as _, SeedableRng};
use std::collections::{BTreeMap, BTreeSet};

/// A random soup: `nf` faces with three distinct corners among `nv` vertices, random order
/// (so random orientation); vertices get distinct random positions.
fn soup(rng: &mut Rng, nv: usize, nf: usize) -> TriMesh {
    let positions = (0..nv)
        .map(|_| {
            Point3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        })
        .collect();
    let mut faces = Vec::with_capacity(nf);
    while faces.len() < nf {
        let t = [
            rng.random_range(0..nv),
            rng.random_range(0..nv),
            rng.random_range(0..nv),
        ];
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            faces.push(t);
        }
    }
    TriMesh::from_indices(positions, &faces).expect("distinct in-range corners")
}

/// A random subset (each face kept with probability `keep`) of `m`'s faces, vertex ids kept.
fn subset(rng: &mut Rng, m: &TriMesh, keep: f64) -> TriMesh {
    let mut out = m.clone();
    out.triangles.retain(|_| rng.random_bool(keep));
    if out.triangles.is_empty() {
        out.triangles.push(m.triangles[0]);
    }
    out
}

/// Directed half-edges `(from, to, halfedge)` of the face list.
fn halfedges(m: &TriMesh) -> Vec<(VertexId, VertexId, HalfedgeId)> {
    let mut out = Vec::new();
    for (f, t) in m.triangles.iter().enumerate() {
        for i in 0..3 {
            out.push((t[i], t[(i + 1) % 3], HalfedgeId::of(FaceId::new(f), i)));
        }
    }
    out
}

/// Faces at `v` linked when they share an edge at `v` accepted by `link`; number of groups.
fn fans(m: &TriMesh, v: VertexId, link: &dyn Fn(EdgeKey) -> bool) -> usize {
    let faces: Vec<usize> = (0..m.n_faces())
        .filter(|&f| m.triangles[f].contains(&v))
        .collect();
    let mut group = vec![usize::MAX; faces.len()];
    let mut groups = 0;
    for s in 0..faces.len() {
        if group[s] != usize::MAX {
            continue;
        }
        group[s] = groups;
        let mut stack = vec![s];
        while let Some(a) = stack.pop() {
            for b in 0..faces.len() {
                if group[b] != usize::MAX {
                    continue;
                }
                let shared: Vec<VertexId> = m.triangles[faces[a]]
                    .iter()
                    .copied()
                    .filter(|w| *w != v && m.triangles[faces[b]].contains(w))
                    .collect();
                if shared.iter().any(|&w| link(EdgeKey::new(v, w))) {
                    group[b] = groups;
                    stack.push(b);
                }
            }
        }
        groups += 1;
    }
    groups
}

/// Compare every query of `Topology` (and `invariants::non_manifold_vertices`) with the
/// brute-force definitions; returns the topology for further checks.
fn check_against_oracle(m: &TriMesh, what: &str) -> Topology {
    let t = Topology::build(m);
    assert_eq!(t.n_vertices(), m.n_vertices(), "{what}");
    assert_eq!(t.n_faces(), m.n_faces(), "{what}");
    let hes = halfedges(m);

    // Undirected edges: sorted unique keys, face counts, per-half-edge index.
    let mut count: BTreeMap<EdgeKey, usize> = BTreeMap::new();
    for &(a, b, _) in &hes {
        *count.entry(EdgeKey::new(a, b)).or_default() += 1;
    }
    let keys: Vec<EdgeKey> = count.keys().copied().collect();
    assert_eq!(t.edges(), &keys[..], "{what}: edges");
    let counts: Vec<u32> = count.values().map(|&c| c as u32).collect();
    assert_eq!(
        t.edge_face_counts(),
        &counts[..],
        "{what}: edge face counts"
    );

    let same_dir = |k: EdgeKey| {
        let dirs: Vec<(VertexId, VertexId)> = hes
            .iter()
            .filter(|&&(a, b, _)| EdgeKey::new(a, b) == k)
            .map(|&(a, b, _)| (a, b))
            .collect();
        dirs.len() == 2 && dirs[0] == dirs[1]
    };
    let manifold_edge = |k: EdgeKey| count[&k] == 2 && !same_dir(k);

    for &(a, b, h) in &hes {
        let k = EdgeKey::new(a, b);
        assert_eq!(t.from(h), a, "{what}: from({h:?})");
        assert_eq!(t.to(h), b, "{what}: to({h:?})");
        assert_eq!(t.edges()[t.edge_index(h)], k, "{what}: edge_index({h:?})");
        assert_eq!(t.is_boundary_halfedge(h), count[&k] == 1, "{what}: {h:?}");
        // The opposite: the other half-edge of a two-face edge, if it runs the other way.
        let expect = if manifold_edge(k) {
            hes.iter()
                .find(|&&(c, d, g)| g != h && c == b && d == a)
                .map(|&(_, _, g)| g)
        } else {
            None
        };
        assert_eq!(t.opposite(h), expect, "{what}: opposite({h:?})");
        assert_eq!(
            t.neighbor(h.face(), h.local()),
            expect.map(HalfedgeId::face),
            "{what}: neighbor of {h:?}"
        );
    }

    let nm_edges: Vec<(EdgeKey, usize)> = count
        .iter()
        .filter(|(_, &c)| c >= 3)
        .map(|(&k, &c)| (k, c))
        .collect();
    assert_eq!(t.non_manifold_edges(), &nm_edges[..], "{what}");
    let inconsistent: Vec<EdgeKey> = keys.iter().copied().filter(|&k| same_dir(k)).collect();
    assert_eq!(t.inconsistent_edges(), &inconsistent[..], "{what}");

    // Per vertex: faces, neighbours, boundary, fans.
    let mut pinch_topo = Vec::new();
    let mut pinch_any = Vec::new();
    for v in m.vertices() {
        let mut vf: Vec<FaceId> = t.vertex_faces(v).to_vec();
        vf.sort_unstable();
        let expect: Vec<FaceId> = m.faces().filter(|&f| m.face(f).contains(&v)).collect();
        assert_eq!(vf, expect, "{what}: faces at {v:?}");
        let nb: BTreeSet<VertexId> = hes
            .iter()
            .filter(|&&(a, b, _)| a == v || b == v)
            .map(|&(a, b, _)| if a == v { b } else { a })
            .collect();
        assert_eq!(
            t.vertex_neighbors(v),
            nb.into_iter().collect::<Vec<_>>(),
            "{what}: neighbours of {v:?}"
        );
        let on_boundary = hes
            .iter()
            .any(|&(a, b, _)| (a == v || b == v) && count[&EdgeKey::new(a, b)] == 1);
        assert_eq!(t.is_boundary_vertex(v), on_boundary, "{what}: {v:?}");
        if fans(m, v, &manifold_edge) > 1 {
            pinch_topo.push(v);
        }
        if fans(m, v, &|_| true) > 1 {
            pinch_any.push(v);
        }
    }
    assert_eq!(t.non_manifold_vertices(), &pinch_topo[..], "{what}");
    assert_eq!(non_manifold_vertices(m, &t), pinch_any, "{what}");
    assert_eq!(
        t.is_oriented_manifold(),
        nm_edges.is_empty() && inconsistent.is_empty() && pinch_topo.is_empty(),
        "{what}"
    );

    // Components: faces linked through any shared edge, labelled in order of first face.
    let nf = m.n_faces();
    let mut label = vec![u32::MAX; nf];
    let mut n_comp = 0u32;
    for s in 0..nf {
        if label[s] != u32::MAX {
            continue;
        }
        label[s] = n_comp;
        let mut stack = vec![s];
        while let Some(f) = stack.pop() {
            #[allow(clippy::needless_range_loop)]
            for g in 0..nf {
                let shares_edge = m.triangles[f]
                    .iter()
                    .filter(|v| m.triangles[g].contains(v))
                    .count()
                    >= 2;
                if label[g] == u32::MAX && shares_edge {
                    label[g] = n_comp;
                    stack.push(g);
                }
            }
        }
        n_comp += 1;
    }
    assert_eq!(t.face_components(), &label[..], "{what}: labels");
    assert_eq!(t.components().len(), n_comp as usize, "{what}");
    // A vertex shared by two components (a pinch between them) belongs to both: each
    // component counts every vertex its faces touch; the mesh's χ is V − E + F of the whole.
    let mut vertex_components: BTreeMap<VertexId, BTreeSet<u32>> = BTreeMap::new();
    for (f, tri) in m.triangles.iter().enumerate() {
        for &v in tri {
            vertex_components.entry(v).or_default().insert(label[f]);
        }
    }
    for (c, info) in t.components().iter().enumerate() {
        let c = c as u32;
        let faces = (0..nf).filter(|&f| label[f] == c).count();
        let touching = vertex_components
            .values()
            .filter(|cs| cs.contains(&c))
            .count();
        let edges: BTreeSet<EdgeKey> = hes
            .iter()
            .filter(|&&(_, _, h)| label[h.face().idx()] == c)
            .map(|&(a, b, _)| EdgeKey::new(a, b))
            .collect();
        assert_eq!(info.faces, faces, "{what}: component {c}");
        assert_eq!(info.vertices, touching, "{what}: component {c}");
        assert_eq!(info.edges, edges.len(), "{what}: component {c}");
        let chi = info.vertices as i64 - edges.len() as i64 + faces as i64;
        assert_eq!(info.euler, chi, "{what}: component {c}");
    }
    let sum = |g: &dyn Fn(&conemesh::mesh::ComponentInfo) -> usize| -> usize {
        t.components().iter().map(g).sum()
    };
    let memberships: usize = vertex_components.values().map(|cs| cs.len()).sum();
    assert_eq!(sum(&|c| c.vertices), memberships, "{what}");
    assert_eq!(sum(&|c| c.edges), count.len(), "{what}");
    assert_eq!(sum(&|c| c.faces), nf, "{what}");
    let chi = vertex_components.len() as i64 - count.len() as i64 + nf as i64;
    assert_eq!(t.euler_characteristic(), chi, "{what}");
    t
}

#[test]
fn topology_of_random_soups_matches_brute_force() {
    let mut rng = Rng::seed_from_u64(0x70b0);
    for case in 0..400 {
        let nv = rng.random_range(3..9);
        let nf = rng.random_range(1..14);
        let m = soup(&mut rng, nv, nf);
        check_against_oracle(&m, &format!("soup {case}: {:?}", m.triangles));
    }
}

/// Random face subsets of an oriented closed sphere, and disjoint pairs of them: every edge
/// has one or two consistently oriented faces, so the boundary half-edges form closed loops.
/// Where no vertex has two outgoing boundary half-edges (no pinch), the loops are the cycles
/// of "next boundary half-edge", and every component is a sphere with holes: genus 0 and
/// χ = 2 − (its loops).
#[test]
fn boundary_loops_and_genus_of_sphere_pieces_match_brute_force() {
    let mut rng = Rng::seed_from_u64(0xb0d1);
    let spheres = [generators::icosphere(1.0, 0), generators::icosphere(1.0, 1)];
    let mut checked_no_pinch = 0;
    for case in 0..160 {
        let s = &spheres[case % 2];
        let keep = rng.random_range(0.75..0.99);
        let mut m = subset(&mut rng, s, keep);
        if case % 3 == 0 {
            // A second, disjoint piece: more components and loops.
            let keep = rng.random_range(0.75..0.99);
            let other = subset(&mut rng, s, keep);
            let n = m.positions.len() as u32;
            m.positions.extend(
                other
                    .positions
                    .iter()
                    .map(|p| p + nalgebra::Vector3::new(3.0, 0.0, 0.0)),
            );
            m.triangles
                .extend(other.triangles.iter().map(|t| t.map(|v| VertexId(v.0 + n))));
        }
        let what = format!("piece {case}");
        let t = check_against_oracle(&m, &what);
        assert!(t.non_manifold_edges().is_empty() && t.inconsistent_edges().is_empty());

        let boundary: Vec<(VertexId, VertexId, HalfedgeId)> = halfedges(&m)
            .into_iter()
            .filter(|&(_, _, h)| t.is_boundary_halfedge(h))
            .collect();
        // Every loop is closed and the loops use each boundary half-edge exactly once.
        let mut used: Vec<(VertexId, VertexId)> = t
            .boundary_loops()
            .iter()
            .flat_map(|l| (0..l.len()).map(move |k| (l[k], l[(k + 1) % l.len()])))
            .collect();
        let mut expect: Vec<(VertexId, VertexId)> =
            boundary.iter().map(|&(a, b, _)| (a, b)).collect();
        used.sort_unstable();
        expect.sort_unstable();
        assert_eq!(used, expect, "{what}: loops cover the boundary half-edges");

        let mut outgoing: BTreeMap<VertexId, Vec<VertexId>> = BTreeMap::new();
        for &(a, b, _) in &boundary {
            outgoing.entry(a).or_default().push(b);
        }
        if outgoing.values().any(|o| o.len() > 1) {
            assert!(!t.non_manifold_vertices().is_empty(), "{what}: pinch");
            continue;
        }
        checked_no_pinch += 1;
        // Cycles of v → next(v).
        let mut seen = BTreeSet::new();
        let mut cycles_per_component: BTreeMap<u32, usize> = BTreeMap::new();
        for &(a, _, h) in &boundary {
            if seen.contains(&a) {
                continue;
            }
            let mut v = a;
            while seen.insert(v) {
                v = outgoing[&v][0];
            }
            *cycles_per_component
                .entry(t.face_components()[h.face().idx()])
                .or_default() += 1;
        }
        assert_eq!(
            t.boundary_loops().len(),
            cycles_per_component.values().sum::<usize>(),
            "{what}"
        );
        for (c, info) in t.components().iter().enumerate() {
            let b = cycles_per_component.get(&(c as u32)).copied().unwrap_or(0);
            assert_eq!(info.boundary_loops, b, "{what}: component {c}");
            assert_eq!(info.euler, 2 - b as i64, "{what}: component {c}");
            assert_eq!(info.genus, Some(0), "{what}: component {c}");
        }
        // The surface lies to the left of each loop: a loop's first step is a half-edge of
        // one of the faces.
        for l in t.boundary_loops() {
            let step = (l[0], l[1 % l.len()]);
            assert!(boundary.iter().any(|&(a, b, _)| (a, b) == step), "{what}");
        }
    }
    assert!(checked_no_pinch >= 30, "{checked_no_pinch}");
}

/// Genus from χ = 2 − 2g − b on closed surfaces built by the generators (known genus) and on
/// a single triangle (a disk).
#[test]
fn genus_of_closed_surfaces_and_a_disk() {
    for g in 0..4 {
        let m = generators::genus_plate(g, 1);
        let t = check_against_oracle(&m, &format!("genus plate {g}"));
        assert_eq!(t.components().len(), 1);
        assert_eq!(t.components()[0].genus, Some(g as u32));
        assert_eq!(t.components()[0].boundary_loops, 0);
        assert_eq!(t.euler_characteristic(), 2 - 2 * g as i64);
    }
    // One triangle: χ = 1, b = 1 → g = 0.
    let p = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
    ];
    let one = TriMesh::from_indices(p, &[[0, 1, 2]]).expect("triangle");
    let t = check_against_oracle(&one, "one triangle");
    assert_eq!(t.components()[0].genus, Some(0));
    assert_eq!(t.boundary_loops().len(), 1);
}

/// χ = 2 − 2g − b has no non-negative integer solution g for a closed non-orientable
/// surface (the 6-vertex projective plane: χ = 1, b = 0, so 2g = 1) nor for three closed
/// tetrahedra hinged on one edge (χ = 8 − 16 + 12 = 4, b = 0, so 2g = −2): the genus is
/// `None`, not a rounded or wrapped number.
#[test]
fn genus_is_none_when_two_minus_chi_minus_b_is_odd_or_negative() {
    let pts = |n: usize| -> Vec<Point3<f64>> {
        (0..n)
            .map(|i| {
                let a = i as f64;
                Point3::new(a.cos(), a.sin(), 0.1 * a)
            })
            .collect()
    };
    let rp2 = TriMesh::from_indices(
        pts(6),
        &[
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4],
            [0, 4, 5],
            [0, 5, 1],
            [1, 2, 4],
            [2, 3, 5],
            [3, 4, 1],
            [4, 5, 2],
            [5, 1, 3],
        ],
    )
    .expect("RP2");
    let t = check_against_oracle(&rp2, "projective plane");
    assert!(t.edge_face_counts().iter().all(|&c| c == 2));
    assert!(t.boundary_loops().is_empty());
    assert!(!t.inconsistent_edges().is_empty(), "non-orientable");
    assert_eq!(t.components().len(), 1);
    assert_eq!(t.components()[0].euler, 1);
    assert_eq!(t.components()[0].genus, None);

    // Tetrahedra (0, 1, a, b) for (a, b) = (2, 3), (4, 5), (6, 7), all on the edge (0, 1).
    let mut faces = Vec::new();
    for (a, b) in [(2, 3), (4, 5), (6, 7)] {
        faces.extend([[0, 1, a], [1, 0, b], [0, a, b], [1, b, a]]);
    }
    let hinge = TriMesh::from_indices(pts(8), &faces).expect("hinge");
    let t = check_against_oracle(&hinge, "three tetrahedra on an edge");
    assert_eq!(t.non_manifold_edges().len(), 1);
    assert!(t.boundary_loops().is_empty());
    assert_eq!(t.components().len(), 1);
    assert_eq!(t.components()[0].euler, 4);
    assert_eq!(t.components()[0].genus, None);
}

/// The certificates report exactly what the oracle finds, on the random soups.
#[test]
fn certificates_agree_with_the_oracle_on_soups() {
    let mut rng = Rng::seed_from_u64(0xce57);
    for case in 0..200 {
        let nv = rng.random_range(3..8);
        let nf = rng.random_range(1..10);
        let m = soup(&mut rng, nv, nf);
        let t = check_against_oracle(&m, &format!("soup {case}"));
        let manifold = certify_manifold(&m, &t);
        if !t.non_manifold_edges().is_empty() {
            assert!(matches!(manifold, Err(InvariantError::NonManifoldEdges(_))));
        } else if !non_manifold_vertices(&m, &t).is_empty() {
            assert!(matches!(
                manifold,
                Err(InvariantError::NonManifoldVertices(_))
            ));
        } else {
            assert_eq!(manifold, Ok(()));
        }
        // The local certificate over every vertex is the whole one; over a random subset
        // it reports exactly the subset's pinch vertices.
        let all: Vec<VertexId> = (0..m.n_vertices()).map(VertexId::new).collect();
        assert_eq!(certify_manifold_at(&m, &t, &all), manifold, "soup {case}");
        let some: Vec<VertexId> = all
            .iter()
            .copied()
            .filter(|_| rng.random_bool(0.5))
            .collect();
        let expect: Vec<VertexId> = non_manifold_vertices(&m, &t)
            .into_iter()
            .filter(|v| some.contains(v))
            .collect();
        match certify_manifold_at(&m, &t, &some) {
            Err(InvariantError::NonManifoldEdges(_)) => {
                assert!(!t.non_manifold_edges().is_empty())
            }
            Err(InvariantError::NonManifoldVertices(Offenders(v))) => {
                assert!(t.non_manifold_edges().is_empty());
                assert_eq!(v, expect, "soup {case}")
            }
            Ok(()) => assert!(t.non_manifold_edges().is_empty() && expect.is_empty()),
            Err(e) => panic!("soup {case}: unexpected {e}"),
        }
        assert_eq!(
            certify_oriented(&m, &t).is_ok(),
            t.inconsistent_edges().is_empty()
        );
        assert_eq!(certify_same_topology(&m, &m), Ok(()));
    }
}

/// Exact zero-area test on small integer coordinates: the cross product is exact in i64.
fn zero_area(m: &TriMesh, f: FaceId) -> bool {
    let p = m.face_points(f).map(|p| p.coords.map(|x| x as i64));
    let (u, v) = (p[1] - p[0], p[2] - p[0]);
    u.cross(&v) == nalgebra::Vector3::zeros()
}

/// Soups over a 3×3×3 integer grid (many collinear corners, touching and coplanar faces):
/// the degenerate faces are exactly the integer zero-area ones; `self_intersections` reports
/// each of them as `(f, f)` only, and otherwise every pair `f < g` of non-degenerate faces
/// for which `faces_intersect` holds (all-pairs, no broad phase).
#[test]
fn self_intersections_with_degenerate_faces_equal_all_pairs() {
    use conemesh::invariants::{
        certify_no_degenerate_faces, certify_no_self_intersections, degenerate_faces,
        faces_intersect, is_degenerate, self_intersections,
    };
    let mut rng = Rng::seed_from_u64(0xdead);
    let mut degenerate_seen = 0;
    for case in 0..60 {
        let nv = rng.random_range(4..10);
        let nf = rng.random_range(2..16);
        let positions: Vec<Point3<f64>> = (0..nv)
            .map(|_| {
                Point3::new(
                    rng.random_range(0..3) as f64,
                    rng.random_range(0..3) as f64,
                    rng.random_range(0..3) as f64,
                )
            })
            .collect();
        let mut m = soup(&mut rng, nv, nf);
        m.positions = positions;
        let deg: Vec<FaceId> = m.faces().filter(|&f| zero_area(&m, f)).collect();
        degenerate_seen += deg.len();
        for f in m.faces() {
            assert_eq!(is_degenerate(&m, f), deg.contains(&f), "case {case} {f:?}");
        }
        assert_eq!(degenerate_faces(&m), deg, "case {case}");
        assert_eq!(certify_no_degenerate_faces(&m).is_ok(), deg.is_empty());
        let mut expect = Vec::new();
        for f in m.faces() {
            if deg.contains(&f) {
                expect.push((f, f));
                continue;
            }
            for g in m.faces().filter(|&g| g > f && !deg.contains(&g)) {
                if faces_intersect(&m, f, g) {
                    expect.push((f, g));
                }
            }
        }
        expect.sort_unstable();
        let got = self_intersections(&m);
        assert_eq!(
            got, expect,
            "case {case}: {:?} {:?}",
            m.positions, m.triangles
        );
        assert_eq!(certify_no_self_intersections(&m).is_ok(), expect.is_empty());
    }
    assert!(degenerate_seen > 20, "{degenerate_seen}");
}

/// `faces_intersect` is symmetric and invariant under rotating the corners of either face
/// (the shared-vertex bookkeeping must not depend on where the shared corners sit).
#[test]
fn faces_intersect_ignores_corner_rotation_and_order() {
    use conemesh::invariants::{faces_intersect, is_degenerate};
    let mut rng = Rng::seed_from_u64(0xfa11);
    let mut hits = [0usize; 4];
    for _ in 0..40 {
        let nv = rng.random_range(4..8);
        let mut m = soup(&mut rng, nv, 12);
        for p in &mut m.positions {
            *p = Point3::new(
                rng.random_range(0..3) as f64,
                rng.random_range(0..3) as f64,
                rng.random_range(0..2) as f64,
            );
        }
        for f in m.faces() {
            for g in m.faces().filter(|&g| g != f) {
                if is_degenerate(&m, f) || is_degenerate(&m, g) {
                    continue;
                }
                let r = faces_intersect(&m, f, g);
                assert_eq!(faces_intersect(&m, g, f), r);
                let shared = m.face(f).iter().filter(|v| m.face(g).contains(v)).count();
                hits[shared] += usize::from(r);
                for k in 1..3 {
                    let mut rot = m.clone();
                    rot.triangles[f.idx()].rotate_left(k);
                    assert_eq!(faces_intersect(&rot, f, g), r, "rotate f by {k}");
                    let mut rot = m.clone();
                    rot.triangles[g.idx()].rotate_left(k);
                    assert_eq!(faces_intersect(&rot, f, g), r, "rotate g by {k}");
                }
            }
        }
    }
    // Every sharing case occurs with an intersection.
    assert!(hits.iter().all(|&h| h > 0), "{hits:?}");
}

/// The topology certificate names the first quantity that differs, in the order
/// components, boundary loops, per-component (genus, loops); renumbered components compare
/// equal.
#[test]
fn same_topology_names_the_first_difference() {
    let shift = |m: &TriMesh, dx: f64| {
        let mut m = m.clone();
        for p in &mut m.positions {
            p.x += dx;
        }
        m
    };
    let union = |a: &TriMesh, b: &TriMesh| {
        let mut m = a.clone();
        let n = m.positions.len() as u32;
        m.positions.extend(b.positions.iter().copied());
        m.triangles
            .extend(b.triangles.iter().map(|t| t.map(|v| VertexId(v.0 + n))));
        m
    };
    let what = |a: &TriMesh, b: &TriMesh| match certify_same_topology(a, b) {
        Ok(()) => "same".to_string(),
        Err(InvariantError::TopologyChanged(c)) => match c {
            TopologyChange::Components { .. } => "components",
            TopologyChange::BoundaryLoops { .. } => "boundary loops",
            TopologyChange::PerComponent { .. } => "per-component genus and boundary loops",
        }
        .to_string(),
        Err(e) => panic!("{e}"),
    };
    let sphere = generators::icosphere(1.0, 1);
    let torus = generators::torus(1.0, 0.3, 12, 6);
    let disk = generators::disk(1.0, 2, 8);
    let sphere_torus = union(&sphere, &shift(&torus, 4.0));
    let torus_sphere = union(&torus, &shift(&sphere, 4.0));
    assert_eq!(what(&sphere_torus, &torus_sphere), "same");
    assert_eq!(what(&sphere, &sphere_torus), "components");
    assert_eq!(what(&sphere_torus, &sphere), "components");
    // Same component count, different loop count.
    assert_eq!(what(&sphere, &disk), "boundary loops");
    assert_eq!(what(&disk, &sphere), "boundary loops");
    // Same counts, different genus.
    assert_eq!(
        what(&sphere, &torus),
        "per-component genus and boundary loops"
    );
    // Same totals (2 components, 1 loop), loops on different components:
    // {disk, torus} vs {sphere, disk}: (genus, loops) pair up differently.
    let a = union(&disk, &shift(&torus, 4.0));
    let b = union(&sphere, &shift(&disk, 4.0));
    assert_eq!(what(&a, &b), "per-component genus and boundary loops");
}

/// The certificate's error shows both sides: counts, or the sorted per-component
/// `(genus, loops)` lists, with `?` for a genus that is not a non-negative integer.
#[test]
fn same_topology_error_shows_both_sides() {
    let sides = |a: &TriMesh, b: &TriMesh| match certify_same_topology(a, b) {
        Err(InvariantError::TopologyChanged(c)) => match c {
            TopologyChange::Components { before, after }
            | TopologyChange::BoundaryLoops { before, after } => {
                (before.to_string(), after.to_string())
            }
            TopologyChange::PerComponent { before, after } => {
                (before.to_string(), after.to_string())
            }
        },
        other => panic!("{other:?}"),
    };
    let sphere = generators::icosphere(1.0, 1);
    let torus = generators::torus(1.0, 0.3, 12, 6);
    assert_eq!(
        sides(&sphere, &torus),
        (
            "[(genus 0, 0 loops)]".to_string(),
            "[(genus 1, 0 loops)]".to_string()
        )
    );
    let disk = generators::disk(1.0, 2, 8);
    assert_eq!(sides(&sphere, &disk), ("0".to_string(), "1".to_string()));
    // A Möbius band: χ = 0 and one boundary curve, so 2 − χ − b is odd and its genus is not
    // an integer (`?`). Against a sphere with as many holes (one component, the same loop
    // count) the error prints both per-component signatures.
    let n = 6;
    let mut p = Vec::new();
    for i in 0..n {
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        p.push(Point3::new(2.0 * a.cos(), 2.0 * a.sin(), 0.5));
        p.push(Point3::new(2.0 * a.cos(), 2.0 * a.sin(), -0.5));
    }
    let mut f = Vec::new();
    for i in 0..n {
        let (t0, b0) = (2 * i, 2 * i + 1);
        let (t1, b1) = if i + 1 < n {
            (2 * i + 2, 2 * i + 3)
        } else {
            (1, 0)
        };
        f.push([t0, b0, b1]);
        f.push([t0, b1, t1]);
    }
    let band = TriMesh::from_indices(p, &f).expect("band");
    let c = Topology::build(&band).components()[0].clone();
    let b = c.boundary_loops;
    let mut holes = generators::icosphere(1.0, 1);
    let mut removed: Vec<[VertexId; 3]> = Vec::new();
    holes.triangles.retain(|t| {
        let far = removed.iter().all(|r| !r.iter().any(|v| t.contains(v)));
        if removed.len() < b && far {
            removed.push(*t);
            false
        } else {
            true
        }
    });
    let g = c.genus.map_or("?".to_string(), |g| g.to_string());
    assert_eq!(
        sides(&band, &holes),
        (
            format!("[(genus {g}, {b} loops)]"),
            format!("[(genus 0, {b} loops)]")
        )
    );
    assert!(c.genus.is_none(), "{c:?}");
}

/// Boundary positions are compared as points: −0.0 and +0.0 are the same coordinate.
#[test]
fn boundary_preserved_identifies_signed_zeros() {
    use conemesh::invariants::certify_boundary_preserved;
    let disk = generators::disk(1.0, 2, 8);
    let t = Topology::build(&disk);
    let mut before = disk.clone();
    let mut after = disk.clone();
    // Move a boundary vertex to the origin, written with a different sign of zero on every
    // axis before and after.
    let b = t.boundary_loops()[0][0];
    before.positions[b.idx()].x = 0.0;
    after.positions[b.idx()].x = -0.0;
    before.positions[b.idx()].y = -0.0;
    after.positions[b.idx()].y = 0.0;
    before.positions[b.idx()].z = -0.0;
    after.positions[b.idx()].z = 0.0;
    assert_eq!(certify_boundary_preserved(&before, &after), Ok(()));
    assert_eq!(certify_boundary_preserved(&after, &before), Ok(()));
    // A real move along any single axis is still caught.
    for axis in 0..3 {
        let mut moved = before.clone();
        moved.positions[b.idx()][axis] += 1e-3;
        assert!(
            certify_boundary_preserved(&before, &moved).is_err(),
            "moved along axis {axis}"
        );
    }
}
