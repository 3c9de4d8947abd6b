//! Least-squares conformal map (Lévy et al. 2002) as a free-boundary initial map for the
//! symmetric Dirichlet optimisation of Sec. 3.3. The Tutte map pins the boundary to a
//! circle, which squeezes triangles near strongly curved boundary stretches to ~1e-7 of
//! their area (initial energy ~1e5–1e15); LSCM has no such squeeze, so far fewer Newton
//! iterations remain. It is not bijective by construction: the caller certifies it exactly
//! and falls back to the Tutte map otherwise.

use super::distortion::triangle_frames;
use super::sparse::{Llt, VertexSystem};
use super::{LinearSystem, ParamError};
use crate::ids::VertexId;
use crate::invariants::{DiskDefect, InvariantError};
use crate::mesh::TriMesh;
use faer::Mat;
use nalgebra::Point2;

/// The two pinned vertices of [`lscm`] and their 3D distance: a boundary vertex and the
/// boundary vertex farthest from it, then the one farthest from that (two sweeps of the
/// diameter heuristic).
fn pins(disk: &TriMesh, boundary: &[VertexId]) -> Result<(VertexId, VertexId, f64), ParamError> {
    if boundary.len() < 3 {
        return Err(InvariantError::NotADisk(DiskDefect::ShortBoundary(boundary.len())).into());
    }
    let far = |from: VertexId| -> VertexId {
        let p = disk.position(from);
        *boundary
            .iter()
            .max_by(|a, b| {
                (disk.position(**a) - p)
                    .norm_squared()
                    .total_cmp(&(disk.position(**b) - p).norm_squared())
            })
            .unwrap_or(&from)
    };
    let p0 = far(boundary[0]);
    let p1 = far(p0);
    if p0 == p1 {
        return Err(ParamError::CoincidentPins { vertex: p0 });
    }
    Ok((p0, p1, (disk.position(p1) - disk.position(p0)).norm()))
}

/// The rows of `a − d` and `b + c` of a triangle's Jacobian over its local dofs `2k + c`
/// (`F_ij = Σ_k u_{k,i} g_k[j]`): the LSCM energy of the triangle is
/// `A_t ((r1·u)² + (r2·u)²)`.
fn conformal_rows(g: &[[f64; 2]; 3]) -> ([f64; 6], [f64; 6]) {
    let mut r1 = [0.0; 6];
    let mut r2 = [0.0; 6];
    for k in 0..3 {
        r1[2 * k] = g[k][0];
        r1[2 * k + 1] = -g[k][1];
        r2[2 * k] = g[k][1];
        r2[2 * k + 1] = g[k][0];
    }
    (r1, r2)
}

/// LSCM of `disk`: minimises `Σ_t A_t ((a − d)² + (b + c)²)` over the Jacobians
/// `F = [[a, b], [c, d]]` (`= Σ_t A_t (‖F‖² − 2 det F)`, zero exactly for a similarity),
/// with the two boundary vertices farthest apart in 3D pinned at their 3D distance.
/// Solved by faer's sparse Cholesky. No certification, no area scaling.
pub fn lscm(disk: &TriMesh, boundary: &[VertexId]) -> Result<Vec<Point2<f64>>, ParamError> {
    let pinned = pins(disk, boundary)?;
    let system = VertexSystem::new(disk).map_err(|failure| ParamError::Solver {
        system: LinearSystem::VertexPattern,
        failure,
    })?;
    solve_pinned(disk, pinned, &system)
}

/// [`lscm`] on the [`VertexSystem`] of `disk` that the symmetric Dirichlet optimisation
/// reuses afterwards: the LSCM normal matrix has the Newton Hessian's pattern, so it costs
/// one numeric factorisation and no second ordering.
pub(super) fn lscm_on(
    disk: &TriMesh,
    boundary: &[VertexId],
    system: &VertexSystem,
) -> Result<Vec<Point2<f64>>, ParamError> {
    solve_pinned(disk, pins(disk, boundary)?, system)
}

/// The LSCM normal equations assembled into the slots of `system`'s pattern, the pinned
/// dofs as identity rows (their couplings moved to the right-hand side), so that the
/// matrix keeps the full pattern and its symbolic factorisation applies.
fn solve_pinned(
    disk: &TriMesh,
    (p0, p1, dist): (VertexId, VertexId, f64),
    system: &VertexSystem,
) -> Result<Vec<Point2<f64>>, ParamError> {
    let n = disk.n_vertices();
    let dim = 2 * n;
    let pat = &system.pattern;
    let mut fixed = vec![None; dim];
    fixed[2 * p0.idx()] = Some(0.0);
    fixed[2 * p0.idx() + 1] = Some(0.0);
    fixed[2 * p1.idx()] = Some(dist);
    fixed[2 * p1.idx() + 1] = Some(0.0);
    let mut vals = vec![0.0; pat.nnz()];
    let mut sol = Mat::<f64>::zeros(dim, 1);
    for (ti, (t, fr)) in disk.triangles.iter().zip(triangle_frames(disk)).enumerate() {
        if fr.area <= 0.0 {
            continue;
        }
        let (r1, r2) = conformal_rows(&fr.grad);
        let dof = |l: usize| 2 * t[l / 2].idx() + l % 2;
        for l1 in 0..6 {
            if fixed[dof(l1)].is_some() {
                continue;
            }
            for l2 in 0..6 {
                let w = fr.area * (r1[l1] * r1[l2] + r2[l1] * r2[l2]);
                match fixed[dof(l2)] {
                    Some(x) => sol[(dof(l1), 0)] -= w * x,
                    None => vals[pat.tri_slot(ti, l1, l2)] += w,
                }
            }
        }
    }
    for (d, x) in fixed.iter().enumerate() {
        if let Some(x) = x {
            vals[pat.diag_slot(d)] = 1.0;
            sol[(d, 0)] = *x;
        }
    }
    Llt::new(system)
        .solve(&vals, &mut sol)
        .map_err(|failure| ParamError::Solver {
            system: LinearSystem::Lscm,
            failure,
        })?;
    let uv: Vec<Point2<f64>> = (0..n)
        .map(|v| Point2::new(sol[(2 * v, 0)], sol[(2 * v + 1, 0)]))
        .collect();
    finite(uv)
}

/// `uv` if every position is finite, else an error naming the first vertex that is not.
fn finite(uv: Vec<Point2<f64>>) -> Result<Vec<Point2<f64>>, ParamError> {
    match uv
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        Some(v) => Err(ParamError::NonFinite {
            system: LinearSystem::Lscm,
            vertex: VertexId::new(v),
        }),
        None => Ok(uv),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::invariants::certify_bijective;
    use crate::mesh::generators;
    use crate::param::{disk_boundary, distortion, scale_to_area};

    #[test]
    fn lscm_of_a_developable_piece_is_an_isometry_after_scaling() {
        // A cone piece unrolls isometrically, and LSCM is exact on similarities: after the
        // area rescale every triangle must be (numerically) isometric and the map certified.
        let m = generators::cone_piece(0.6, 2.5, 0.4, 2.0, 20, 10);
        let b = disk_boundary(&m).unwrap();
        let mut uv = lscm(&m, &b).unwrap();
        scale_to_area(&m, &mut uv);
        certify_bijective(&uv, &m.triangles, &b).unwrap();
        let r = distortion(&m, &uv);
        assert!(r.max_conformal < 1.0 + 1e-6, "{r:?}");
        assert!(r.max_area_distortion < 1e-6, "{r:?}");
    }

    #[test]
    fn lscm_solves_the_normal_equations_with_the_pins_fixed() {
        // A bent (non-developable) cylinder piece, so the minimum is not a similarity: the
        // energy's gradient must vanish at every free dof, and the pins sit where placed.
        let mut m = generators::cylinder_piece(1.0, 2.0, 1.0, 8, 3);
        for p in &mut m.positions {
            p.z += 0.1 * p.x * p.y;
        }
        let b = disk_boundary(&m).unwrap();
        let uv = lscm(&m, &b).unwrap();
        let (p0, p1, dist) = pins(&m, &b).unwrap();
        assert_eq!(uv[p0.idx()], Point2::new(0.0, 0.0));
        assert_eq!(uv[p1.idx()], Point2::new(dist, 0.0));
        let mut grad = vec![0.0; 2 * m.n_vertices()];
        let mut scale = 0.0f64;
        for (t, fr) in m.triangles.iter().zip(triangle_frames(&m)) {
            let (r1, r2) = conformal_rows(&fr.grad);
            let u = |l: usize| uv[t[l / 2].idx()][l % 2];
            let (s1, s2) =
                (0..6).fold((0.0, 0.0), |(a, b), l| (a + r1[l] * u(l), b + r2[l] * u(l)));
            for l in 0..6 {
                let g = 2.0 * fr.area * (r1[l] * s1 + r2[l] * s2);
                grad[2 * t[l / 2].idx() + l % 2] += g;
                scale = scale.max((2.0 * fr.area * (r1[l].abs() + r2[l].abs())).abs());
            }
        }
        let pinned = [
            2 * p0.idx(),
            2 * p0.idx() + 1,
            2 * p1.idx(),
            2 * p1.idx() + 1,
        ];
        for (d, g) in grad.iter().enumerate() {
            if !pinned.contains(&d) {
                assert!(g.abs() < 1e-10 * scale * dist, "dof {d}: {g}");
            }
        }
    }
}
