//! Approximation error (two-sided sampled Hausdorff / RMS) and flips against the input.
//! Closest points come from parry's BVH over the triangles and its point-triangle
//! projection (exact Euclidean distance to the triangle, not to its vertices).

use crate::ids::FaceId;
use crate::invariants::FlipTest;
use crate::mesh::{SurfaceProjector, TriMesh};
use nalgebra::Point3;
use rand::Rng as _;
use rayon::prelude::*;
use serde::Serialize;

/// Two-sided approximation error between two surfaces.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Distance {
    /// Sampled Hausdorff distance max(d(a→b), d(b→a)), in mesh units.
    pub hausdorff: f64,
    /// Root mean square distance over the area-weighted samples of both sides (the mean of
    /// the two one-sided mean squares, then the root), mesh units.
    pub rms: f64,
    /// `hausdorff` / bbox diagonal of `a`.
    pub hausdorff_rel: f64,
    /// `rms` / bbox diagonal of `a`.
    pub rms_rel: f64,
    /// One-sided max distance from samples of `a` to surface `b`.
    pub hausdorff_a_to_b: f64,
    /// One-sided max distance from samples of `b` to surface `a`.
    pub hausdorff_b_to_a: f64,
    /// Vertex and random samples measured (both sides; the refinement's are not counted).
    pub samples: usize,
}

/// Referenced vertices of `m` plus `n_random` area-weighted uniform random points on its
/// triangles. Returns (points, the face of each random point; the random points come last).
fn sample_surface(
    m: &TriMesh,
    n_random: usize,
    rng: &mut crate::Rng,
) -> (Vec<Point3<f64>>, Vec<FaceId>) {
    // Only vertices some face uses: unreferenced vertices (raw scans have them) are not on
    // the surface.
    let mut used = vec![false; m.n_vertices()];
    for t in &m.triangles {
        for v in t {
            used[v.idx()] = true;
        }
    }
    let mut pts: Vec<Point3<f64>> = m
        .positions
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(p, _)| *p)
        .collect();
    // Cumulative area, for choosing a face with probability proportional to its area.
    let mut cdf = Vec::with_capacity(m.n_faces());
    let mut acc = 0.0;
    for f in m.faces() {
        acc += m.face_area(f);
        cdf.push(acc);
    }
    if !(acc > 0.0 && acc.is_finite()) {
        return (pts, Vec::new());
    }
    pts.reserve(n_random);
    let mut faces = Vec::with_capacity(n_random);
    for _ in 0..n_random {
        let u: f64 = rng.random::<f64>() * acc;
        let fi = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
        pts.push(point_in_face(m, FaceId::new(fi), rng));
        faces.push(FaceId::new(fi));
    }
    (pts, faces)
}

/// A uniform random point of face `f`: barycentric (1-√r1, √r1(1-r2), √r1·r2).
fn point_in_face(m: &TriMesh, f: FaceId, rng: &mut crate::Rng) -> Point3<f64> {
    let (r1, r2): (f64, f64) = (rng.random(), rng.random());
    let s = r1.sqrt();
    let [a, b, c] = m.face_points(f);
    let w = [1.0 - s, s * (1.0 - r2), s * r2];
    Point3::from(a.coords * w[0] + b.coords * w[1] + c.coords * w[2])
}

/// Faces whose random samples came closest to the one-sided maximum are sampled again this
/// densely: the distance to a piecewise-flat surface peaks in small regions (over a crease or
/// a tip of the other surface) that area-weighted samples can miss by a few percent.
const REFINE_FACES: usize = 32;
/// Samples per refined face.
const REFINE_SAMPLES: usize = 512;

/// The one-sided maximum, refined in the faces of the largest random samples (module docs:
/// [`REFINE_FACES`]); `d` holds the distances of `pts`, whose random samples (last) lie on
/// `faces` of `m`.
fn refined_max(
    m: &TriMesh,
    faces: &[FaceId],
    d: &[f64],
    target: &SurfaceProjector,
    rng: &mut crate::Rng,
) -> f64 {
    let max = d.iter().copied().fold(0.0, f64::max);
    let tail = &d[d.len() - faces.len()..];
    let mut order: Vec<usize> = (0..tail.len()).collect();
    order.sort_by(|&i, &j| tail[j].total_cmp(&tail[i]).then(i.cmp(&j)));
    let mut chosen: Vec<FaceId> = Vec::new();
    for i in order {
        if chosen.len() == REFINE_FACES {
            break;
        }
        if !chosen.contains(&faces[i]) {
            chosen.push(faces[i]);
        }
    }
    let extra: Vec<Point3<f64>> = chosen
        .iter()
        .flat_map(|&f| (0..REFINE_SAMPLES).map(move |_| f))
        .map(|f| point_in_face(m, f, rng))
        .collect();
    extra
        .par_iter()
        .map(|p| target.closest(p).map_or(f64::INFINITY, |(_, _, d)| d))
        .collect::<Vec<f64>>()
        .into_iter()
        .fold(max, f64::max)
}

/// (the distance of every sample, mean squared distance over the random samples) from the
/// points to the surface.
fn one_side(pts: &[Point3<f64>], n_random: usize, target: &SurfaceProjector) -> (Vec<f64>, f64) {
    let d: Vec<f64> = pts
        .par_iter()
        .map(|p| target.closest(p).map_or(f64::INFINITY, |(_, _, d)| d))
        .collect();
    // The RMS uses only the area-weighted random samples, so that it estimates the surface
    // integral (vertex samples are denser where triangles are small and would bias it).
    let tail = &d[d.len() - n_random..];
    let ms = if tail.is_empty() {
        d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64
    } else {
        tail.iter().map(|x| x * x).sum::<f64>() / tail.len() as f64
    };
    (d, ms)
}

/// Two-sided sampled approximation error between surfaces `a` (the input) and `b`.
///
/// Each surface is sampled at all its vertices used by a face, plus `min_samples` area-weighted random
/// points (seeded by `rng`; first `a`'s, then `b`'s), and every sample is measured to the
/// other surface by the exact point-triangle distance (parry BVH); then the faces of the
/// largest random samples of each side are sampled again densely (32 faces × 512 points,
/// drawn after all the others), so a peak in a small region is
/// not missed. Hausdorff is the larger
/// of the two one-sided maxima; RMS is over the random samples of both sides; relative
/// values divide by the bounding-box diagonal of `a`. The distance queries run in parallel
/// and do not consume randomness, so the result depends only on the seed.
pub fn approximation_error(
    a: &TriMesh,
    b: &TriMesh,
    min_samples: usize,
    rng: &mut crate::Rng,
) -> Distance {
    let (pa, fa) = sample_surface(a, min_samples, rng);
    let (pb, fb) = sample_surface(b, min_samples, rng);
    let (proj_a, proj_b) = (SurfaceProjector::new(a), SurfaceProjector::new(b));
    let (da, msa) = one_side(&pa, fa.len(), &proj_b);
    let (db, msb) = one_side(&pb, fb.len(), &proj_a);
    let ha = refined_max(a, &fa, &da, &proj_b, rng);
    let hb = refined_max(b, &fb, &db, &proj_a, rng);
    let hausdorff = ha.max(hb);
    let rms = (0.5 * (msa + msb)).sqrt();
    let diag = a.bbox_diagonal();
    let rel = |x: f64| if diag > 0.0 { x / diag } else { f64::NAN };
    Distance {
        hausdorff,
        rms,
        hausdorff_rel: rel(hausdorff),
        rms_rel: rel(rms),
        hausdorff_a_to_b: ha,
        hausdorff_b_to_a: hb,
        samples: pa.len() + pb.len(),
    }
}

/// Output faces flipped against the input ([`FlipTest`]).
pub fn flips(input: &TriMesh, output: &TriMesh) -> Vec<FaceId> {
    let test = FlipTest::new(input);
    let flagged: Vec<bool> = (0..output.n_faces())
        .into_par_iter()
        .map(|i| test.is_flipped(&output.face_points(FaceId::new(i))))
        .collect();
    flagged
        .iter()
        .enumerate()
        .filter(|(_, &b)| b)
        .map(|(i, _)| FaceId::new(i))
        .collect()
}
