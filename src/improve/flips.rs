//! The connectivity update on the surface: edge flips that raise the smaller metric quality
//! of the two faces, each a certified candidate.

use super::geometry::segment_distance;
use super::SurfaceContext;
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::invariants::{candidate_embedded_local, is_degenerate_triangle, FaceGrid};
use crate::mesh::{bbox_of, TriMesh};
use crate::stitch::WorkingMesh;
use nalgebra::Matrix3;
use std::collections::{HashMap, HashSet};

/// The connectivity update (Sec. 3.4) on the surface: metric edge flips after the loop. The patches' boundaries are fixed while
/// they are remeshed, so the triangles along the seams between patches are the worst of the
/// output (decimated-knight and cow: q ≈ 0.65-0.76 on seam faces against 0.84-0.85 inside
/// patches). An interior edge `ab` with faces `abc`, `bad` is replaced by `cd` when the
/// smaller quality (Sec. 4.1, metric of the reference at the vertices' locations, as `eval`)
/// of the two faces strictly increases, `cd` is not an edge yet, the new faces are neither
/// degenerate (exact) nor flipped against the reference (conservative test), do not intersect
/// the faces around them (exact, embedded input only), and the two diagonals pass within
/// `tol` of each other (the flip moves the surface by at most that much). Passes repeat
/// until nothing flips (at most 8). Returns the number of flips.
pub fn connectivity_update(ctx: &SurfaceContext<'_>, work: &mut WorkingMesh) -> usize {
    let SurfaceContext {
        field,
        flip_test,
        embedded_input,
        tol,
        feature_edges,
        ..
    } = *ctx;
    use crate::quality::{face_metric, triangle_quality};
    let metrics: Vec<Matrix3<f64>> = work.locations.iter().map(|l| field.eval_at(l)).collect();
    let q = |mesh: &TriMesh, t: [VertexId; 3]| {
        triangle_quality(
            t.map(|v| mesh.positions[v.idx()]),
            &face_metric(&metrics, t),
        )
        .q
    };
    let mut total = 0;
    let mut grid = FaceGrid::new(&work.mesh);
    for _pass in 0..8 {
        let mut edge_faces: HashMap<EdgeKey, Vec<usize>> =
            HashMap::new();
        for (f, t) in work.mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                edge_faces
                    .entry(EdgeKey::new(t[k], t[(k + 1) % 3]))
                    .or_default()
                    .push(f);
            }
        }
        let mut edges: Vec<EdgeKey> = edge_faces
            .iter()
            .filter(|(e, fs)| fs.len() == 2 && !feature_edges.is_some_and(|fe| fe.contains(e)))
            .map(|(e, _)| *e)
            .collect();
        edges.sort();
        let mut touched = vec![false; work.mesh.n_faces()];
        // Quality of each face, computed once per pass (a face is looked at from each of its
        // three edges; a flipped face is `touched` and not looked at again in this pass).
        let mut face_q: Vec<Option<f64>> = vec![None; work.mesh.n_faces()];
        let mut new_edges: HashSet<EdgeKey> = HashSet::new();
        let mut flipped = 0;
        for e in edges {
            let fs = &edge_faces[&e];
            let (f1, f2) = (fs[0], fs[1]);
            if touched[f1] || touched[f2] {
                continue;
            }
            // Orient: f1 = (a, b, c) with the directed edge a→b, f2 = (b, a, d).
            let t1 = work.mesh.triangles[f1];
            let t2 = work.mesh.triangles[f2];
            let Some(k) = (0..3).find(|&k| EdgeKey::new(t1[k], t1[(k + 1) % 3]) == e) else {
                continue;
            };
            let (a, b, c) = (t1[k], t1[(k + 1) % 3], t1[(k + 2) % 3]);
            let Some(d) = t2.iter().copied().find(|v| *v != a && *v != b) else {
                continue;
            };
            if c == d || !(0..3).any(|j| t2[j] == b && t2[(j + 1) % 3] == a) {
                continue;
            }
            let cd = EdgeKey::new(c, d);
            if edge_faces.contains_key(&cd) || new_edges.contains(&cd) {
                continue;
            }
            let mut cached =
                |f: usize, t: [VertexId; 3]| *face_q[f].get_or_insert_with(|| q(&work.mesh, t));
            let (q1, q2) = (cached(f1, t1), cached(f2, t2));
            let n1 = [a, d, c];
            let n2 = [d, b, c];
            let (r1, r2) = (q(&work.mesh, n1), q(&work.mesh, n2));
            // The smaller quality must rise (maximising the sum instead gave +0.002 q_avg on
            // cow and knight but lower q_min).
            if r1.min(r2).partial_cmp(&q1.min(q2)) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let p = |v: VertexId| work.mesh.positions[v.idx()];
            if segment_distance(p(a), p(b), p(c), p(d)) > tol {
                continue;
            }
            let tris = [n1.map(p), n2.map(p)];
            if tris
                .iter()
                .any(|t| is_degenerate_triangle(t) || flip_test.is_flipped_anywhere(t))
            {
                continue;
            }
            if embedded_input
                && !candidate_embedded_local(
                    &work.mesh,
                    &grid,
                    &[FaceId::new(f1), FaceId::new(f2)],
                    &[n1, n2],
                )
            {
                continue;
            }
            work.mesh.triangles[f1] = n1;
            work.mesh.triangles[f2] = n2;
            if let Some((lo, hi)) = bbox_of([a, b, c, d].iter().map(|v| p(*v))) {
                grid.insert(f1, &lo, &hi);
                grid.insert(f2, &lo, &hi);
            }
            touched[f1] = true;
            touched[f2] = true;
            new_edges.insert(cd);
            flipped += 1;
        }
        total += flipped;
        if flipped == 0 {
            break;
        }
    }
    total
}
