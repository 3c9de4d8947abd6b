//! Tutte's embedding (the initial map of Sec. 3.3): the boundary is fixed on a convex
//! polygon (a circle, by arc length) and every interior vertex is a weighted average of its
//! neighbours. With positive weights and a convex boundary the map is bijective (Tutte 1963,
//! Floater 2003); in floating point it is certified by `certify_bijective` anyway.

use super::sparse::{solve_triplets, Factorization};
use super::{
    certify, distortion, validate_disk, LinearSystem, ParamError, Parameterization, Parameterizer,
};
use crate::ids::VertexId;
use crate::invariants::{DiskDefect, InvariantError};
use crate::mesh::TriMesh;
use faer::sparse::Triplet;
use faer::Mat;
use nalgebra::Point2;
use std::f64::consts::PI;

/// Edge weights of the Tutte Laplacian.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum TutteWeights {
    /// `w_ij = 1` (Tutte's barycentric map; libigl's uniform Laplacian).
    Uniform,
    /// `w_ij = (cot α_ij + cot β_ij) / 2` (harmonic map; libigl's `cotmatrix`), clamped to a
    /// small positive value where the mesh is not Delaunay so the map stays bijective.
    Cotan,
    /// Floater's mean-value weights `w_ij = (tan(γ/2) + tan(δ/2)) / |x_i − x_j|`, always
    /// positive (not symmetric: solved by LU). The default.
    #[default]
    MeanValue,
}

/// Tutte's embedding as a [`Parameterizer`] (name `"tutte"`): boundary on a circle by arc
/// length, scaled so the 2D area equals the 3D area. If the map with `weights` fails the
/// exact certificate, uniform weights are tried before giving up with `NotCertified`.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct Tutte {
    /// Laplacian weights.
    pub weights: TutteWeights,
}

/// Positions of the boundary loop on a circle of radius `radius` centred at the origin,
/// counter-clockwise, spaced by 3D arc length, `boundary[0]` at angle 0 (the placement of
/// libigl's `map_vertices_to_circle`).
pub fn circle_boundary(disk: &TriMesh, boundary: &[VertexId], radius: f64) -> Vec<Point2<f64>> {
    let m = boundary.len();
    let len: Vec<f64> = (0..m)
        .map(|i| (disk.position(boundary[(i + 1) % m]) - disk.position(boundary[i])).norm())
        .collect();
    let total: f64 = len.iter().sum();
    let mut s = 0.0;
    (0..m)
        .map(|i| {
            let a = if total > 0.0 {
                2.0 * PI * s / total
            } else {
                2.0 * PI * i as f64 / m as f64
            };
            s += len[i];
            Point2::new(radius * a.cos(), radius * a.sin())
        })
        .collect()
}

/// Scale `uv` about the origin so that its total (signed) triangle area equals the 3D area
/// of `disk` ("isometric in the mean"). Leaves `uv` unchanged if either area is not positive.
pub fn scale_to_area(disk: &TriMesh, uv: &mut [Point2<f64>]) {
    let a3 = disk.area();
    let a2: f64 = disk
        .triangles
        .iter()
        .map(|t| {
            let (a, b, c) = (uv[t[0].idx()], uv[t[1].idx()], uv[t[2].idx()]);
            0.5 * (b - a).perp(&(c - a))
        })
        .sum();
    if a3 > 0.0 && a2 > 0.0 {
        let k = (a3 / a2).sqrt();
        for p in uv.iter_mut() {
            p.coords *= k;
        }
    }
}

/// Half-edge weights `w[i → j]` of every triangle corner contribution, as triplets
/// `(i, j, w)` (both directions listed; duplicates summed by the assembly).
fn weights(disk: &TriMesh, kind: TutteWeights) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::with_capacity(6 * disk.n_faces());
    for t in &disk.triangles {
        let p = [
            disk.position(t[0]),
            disk.position(t[1]),
            disk.position(t[2]),
        ];
        for k in 0..3 {
            let (i, j, o) = (k, (k + 1) % 3, (k + 2) % 3);
            let (vi, vj, vo) = (t[i].idx(), t[j].idx(), t[o].idx());
            match kind {
                TutteWeights::Uniform => {
                    // Each interior edge is seen from two faces: 1/2 each.
                    out.push((vi, vj, 0.5));
                    out.push((vj, vi, 0.5));
                }
                TutteWeights::Cotan => {
                    // Corner o is opposite edge ij.
                    let (a, b) = (p[i] - p[o], p[j] - p[o]);
                    let cr = a.cross(&b).norm();
                    let w = if cr > 0.0 { 0.5 * a.dot(&b) / cr } else { 0.0 };
                    out.push((vi, vj, w));
                    out.push((vj, vi, w));
                }
                TutteWeights::MeanValue => {
                    // Corner i between edges ij and io: tan(θ/2) = |a×b| / (|a||b| + a·b).
                    let (a, b) = (p[j] - p[i], p[o] - p[i]);
                    let (la, lb) = (a.norm(), b.norm());
                    let den = la * lb + a.dot(&b);
                    let tan_half = if den > 0.0 {
                        a.cross(&b).norm() / den
                    } else {
                        0.0
                    };
                    if la > 0.0 {
                        out.push((vi, vj, tan_half / la));
                    }
                    if lb > 0.0 {
                        out.push((vi, vo, tan_half / lb));
                    }
                }
            }
        }
    }
    if kind == TutteWeights::Cotan {
        // Clamp non-positive (non-Delaunay) weights to a small positive floor, per edge sum.
        out.sort_unstable_by_key(|x| (x.0, x.1));
        let mut merged: Vec<(usize, usize, f64)> = Vec::with_capacity(out.len() / 2);
        for (i, j, w) in out {
            match merged.last_mut() {
                Some(l) if l.0 == i && l.1 == j => l.2 += w,
                _ => merged.push((i, j, w)),
            }
        }
        let mean = merged.iter().map(|x| x.2.abs()).sum::<f64>() / merged.len().max(1) as f64;
        let floor = 1e-6 * mean;
        for x in &mut merged {
            x.2 = x.2.max(floor);
        }
        return merged;
    }
    out
}

/// Tutte's embedding of `disk` with `boundary[i]` fixed at `boundary_uv[i]`: solves
/// `Σ_j w_ij (u_i − u_j) = 0` for the interior vertices with faer's sparse Cholesky
/// (symmetric weights) or LU (mean-value weights). No certification, no scaling.
pub fn tutte_embedding(
    disk: &TriMesh,
    boundary: &[VertexId],
    boundary_uv: &[Point2<f64>],
    weights_kind: TutteWeights,
) -> Result<Vec<Point2<f64>>, ParamError> {
    let n = disk.n_vertices();
    if boundary.len() != boundary_uv.len() {
        return Err(ParamError::BoundaryCount {
            vertices: boundary.len(),
            positions: boundary_uv.len(),
        });
    }
    const FIXED: usize = usize::MAX;
    let mut uv = vec![Point2::origin(); n];
    let mut index = vec![0usize; n];
    for (v, p) in boundary.iter().zip(boundary_uv) {
        if v.idx() >= n {
            return Err(InvariantError::NotADisk(DiskDefect::VertexOutOfRange {
                vertex: *v,
                vertices: n,
            })
            .into());
        }
        index[v.idx()] = FIXED;
        uv[v.idx()] = *p;
    }
    let mut n_free = 0;
    for x in index.iter_mut() {
        if *x != FIXED {
            *x = n_free;
            n_free += 1;
        }
    }
    if n_free == 0 {
        return Ok(uv);
    }
    let mut trips = Vec::new();
    let mut rhs = Mat::<f64>::zeros(n_free, 2);
    for (i, j, w) in weights(disk, weights_kind) {
        let ii = index[i];
        if ii == FIXED {
            continue;
        }
        trips.push(Triplet::new(ii, ii, w));
        match index[j] {
            FIXED => {
                rhs[(ii, 0)] += w * uv[j].x;
                rhs[(ii, 1)] += w * uv[j].y;
            }
            jj => trips.push(Triplet::new(ii, jj, -w)),
        }
    }
    let how = if weights_kind == TutteWeights::MeanValue {
        Factorization::Lu
    } else {
        Factorization::Cholesky
    };
    let sol = solve_triplets(n_free, &trips, &rhs, how).map_err(|failure| ParamError::Solver {
        system: LinearSystem::Tutte,
        failure,
    })?;
    for v in 0..n {
        let i = index[v];
        if i != FIXED {
            uv[v] = Point2::new(sol[(i, 0)], sol[(i, 1)]);
        }
    }
    if let Some(v) = uv
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(ParamError::NonFinite {
            system: LinearSystem::Tutte,
            vertex: VertexId::new(v),
        });
    }
    Ok(uv)
}

/// Certified Tutte map with area scaling: `weights` first, then uniform weights.
pub(crate) fn certified_tutte(
    disk: &TriMesh,
    boundary: &[VertexId],
    weights: TutteWeights,
) -> Result<(Vec<Point2<f64>>, TutteWeights), ParamError> {
    let circle = circle_boundary(disk, boundary, 1.0);
    let mut uv = tutte_embedding(disk, boundary, &circle, weights)?;
    scale_to_area(disk, &mut uv);
    match certify(disk, &uv, boundary) {
        Ok(()) => return Ok((uv, weights)),
        Err(e) if weights == TutteWeights::Uniform => return Err(e),
        Err(_) => {}
    }
    let mut uv = tutte_embedding(disk, boundary, &circle, TutteWeights::Uniform)?;
    scale_to_area(disk, &mut uv);
    certify(disk, &uv, boundary)?;
    Ok((uv, TutteWeights::Uniform))
}

impl Parameterizer for Tutte {
    fn name(&self) -> &'static str {
        "tutte"
    }

    fn parameterize(
        &self,
        disk: &TriMesh,
        boundary: &[VertexId],
    ) -> Result<Parameterization, ParamError> {
        validate_disk(disk, boundary)?;
        let (uv, _) = certified_tutte(disk, boundary, self.weights)?;
        let report = distortion(disk, &uv);
        Ok(Parameterization { uv, report })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::invariants::certify_bijective;
    use crate::mesh::generators;
    use crate::param::disk_boundary;

    #[test]
    fn tutte_of_generated_disks_is_certified_for_all_weights() {
        let meshes = [
            generators::disk(1.0, 6, 6),
            generators::cylinder_piece(1.0, 2.5, 1.5, 20, 8),
            generators::cone_piece(0.6, 2.0, 0.3, 2.0, 16, 10),
        ];
        for m in &meshes {
            let b = disk_boundary(m).unwrap();
            for w in [
                TutteWeights::Uniform,
                TutteWeights::Cotan,
                TutteWeights::MeanValue,
            ] {
                let p = Tutte { weights: w }.parameterize(m, &b).unwrap();
                certify_bijective(&p.uv, &m.triangles, &b).unwrap();
                // Isometric in the mean: 2D area = 3D area.
                let a2: f64 = m
                    .triangles
                    .iter()
                    .map(|t| {
                        let (a, b, c) = (p.uv[t[0].idx()], p.uv[t[1].idx()], p.uv[t[2].idx()]);
                        0.5 * (b - a).perp(&(c - a))
                    })
                    .sum();
                assert!((a2 - m.area()).abs() < 1e-9 * m.area(), "{w:?}");
            }
        }
    }

    #[test]
    fn flat_disk_with_its_own_boundary_is_reproduced() {
        // A planar disk with the boundary at its true positions: mean-value weights reproduce
        // linear functions (Floater 2003), so the map is the identity. (The cotan weights of
        // this generator are clamped on its non-Delaunay edges, so they do not.)
        let m = generators::disk(1.0, 5, 6);
        let b = disk_boundary(&m).unwrap();
        let buv: Vec<_> = b
            .iter()
            .map(|v| Point2::new(m.position(*v).x, m.position(*v).y))
            .collect();
        for w in [TutteWeights::MeanValue] {
            let uv = tutte_embedding(&m, &b, &buv, w).unwrap();
            for (p, q) in uv.iter().zip(&m.positions) {
                assert!(
                    (p.x - q.x).abs() < 1e-10 && (p.y - q.y).abs() < 1e-10,
                    "{w:?} {p} {q}"
                );
            }
        }
    }
}
