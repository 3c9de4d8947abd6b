//! Least-squares conformal map (Lévy et al. 2002) as a free-boundary initial map for the
//! symmetric Dirichlet optimisation of Sec. 3.3. The Tutte map pins the boundary to a
//! circle, which squeezes triangles near strongly curved boundary stretches to ~1e-7 of
//! their area (initial energy ~1e5–1e15); LSCM has no such squeeze, so far fewer Newton
//! iterations remain. It is not bijective by construction: the caller certifies it exactly
//! and falls back to the Tutte map otherwise.

use super::distortion::triangle_frames;
use super::ParamError;
use crate::ids::VertexId;
use crate::mesh::TriMesh;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SparseColMatRef, Triplet};
use faer::{Conj, Mat, Par, Side};
use nalgebra::Point2;

/// The two pinned vertices of [`lscm`] and their 3D distance: a boundary vertex and the
/// boundary vertex farthest from it, then the one farthest from that (two sweeps of the
/// diameter heuristic).
pub(super) fn pins(
    disk: &TriMesh,
    boundary: &[VertexId],
) -> Result<(VertexId, VertexId, f64), ParamError> {
    if boundary.len() < 3 {
        return Err(ParamError::NotADisk(format!(
            "boundary of {} vertices",
            boundary.len()
        )));
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
        return Err(ParamError::Solver("LSCM: coincident pins".to_string()));
    }
    Ok((p0, p1, (disk.position(p1) - disk.position(p0)).norm()))
}

/// The rows of `a − d` and `b + c` of a triangle's Jacobian over its local dofs `2k + c`
/// (`F_ij = Σ_k u_{k,i} g_k[j]`): the LSCM energy of the triangle is
/// `A_t ((r1·u)² + (r2·u)²)`.
pub(super) fn conformal_rows(g: &[[f64; 2]; 3]) -> ([f64; 6], [f64; 6]) {
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
    let n = disk.n_vertices();
    if boundary.len() < 3 {
        return Err(ParamError::NotADisk(format!(
            "boundary of {} vertices",
            boundary.len()
        )));
    }
    let (p0, p1, dist) = pins(disk, boundary)?;
    const FIXED: usize = usize::MAX;
    let mut uv = vec![Point2::origin(); n];
    uv[p1.idx()] = Point2::new(dist, 0.0);
    // Dof 2v + c; pinned dofs are moved to the right-hand side.
    let mut index = vec![0usize; 2 * n];
    index[2 * p0.idx()] = FIXED;
    index[2 * p0.idx() + 1] = FIXED;
    index[2 * p1.idx()] = FIXED;
    index[2 * p1.idx() + 1] = FIXED;
    let mut m = 0;
    for x in index.iter_mut() {
        if *x != FIXED {
            *x = m;
            m += 1;
        }
    }
    let fixed_value = |dof: usize| -> f64 {
        let p = uv[dof / 2];
        if dof % 2 == 0 {
            p.x
        } else {
            p.y
        }
    };
    let mut trips = Vec::with_capacity(36 * disk.n_faces());
    let mut rhs = Mat::<f64>::zeros(m, 1);
    for (t, fr) in disk.triangles.iter().zip(triangle_frames(disk)) {
        if fr.area <= 0.0 {
            continue;
        }
        let (r1, r2) = conformal_rows(&fr.grad);
        let dof = |l: usize| 2 * t[l / 2].idx() + l % 2;
        for l1 in 0..6 {
            let i = index[dof(l1)];
            if i == FIXED {
                continue;
            }
            for l2 in 0..6 {
                let w = fr.area * (r1[l1] * r1[l2] + r2[l1] * r2[l2]);
                match index[dof(l2)] {
                    FIXED => rhs[(i, 0)] -= w * fixed_value(dof(l2)),
                    j => trips.push(Triplet::new(i, j, w)),
                }
            }
        }
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &trips)
        .map_err(|e| ParamError::Solver(format!("assembling LSCM: {e:?}")))?;
    let sol = cholesky_solve(a.as_ref(), rhs)?;
    for v in 0..n {
        for c in 0..2 {
            let i = index[2 * v + c];
            if i != FIXED {
                uv[v][c] = sol[(i, 0)];
            }
        }
    }
    finite_lscm(uv)
}

/// `uv` if every position is finite, else an error naming the first vertex that is not.
pub(crate) fn finite_lscm(uv: Vec<Point2<f64>>) -> Result<Vec<Point2<f64>>, ParamError> {
    match uv
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        Some(v) => Err(ParamError::Solver(format!(
            "LSCM gave a non-finite position for v{v}"
        ))),
        None => Ok(uv),
    }
}

/// Solve `a x = rhs` (symmetric positive definite, full storage) by sparse Cholesky; the
/// supernodal kernel is forced from the size where it wins for the 2D-mesh matrices of
/// Sec. 3.3 (as for the Newton Hessian, `super::sdirichlet`).
fn cholesky_solve(
    a: SparseColMatRef<'_, usize, f64>,
    mut rhs: Mat<f64>,
) -> Result<Mat<f64>, ParamError> {
    let err =
        |what: &str, e: &dyn std::fmt::Debug| ParamError::Solver(format!("LSCM {what}: {e:?}"));
    let mut params = CholeskySymbolicParams::default();
    if a.nrows() >= super::sdirichlet::SUPERNODAL_MIN_DIM {
        params.supernodal_flop_ratio_threshold = SupernodalThreshold::FORCE_SUPERNODAL;
    }
    let symbolic =
        factorize_symbolic_cholesky(a.symbolic(), Side::Lower, Default::default(), params)
            .map_err(|e| err("symbolic Cholesky", &e))?;
    llt_solve(&symbolic, a, &mut rhs)?;
    Ok(rhs)
}

/// Numeric Cholesky of `a` on its symbolic factorisation, then `rhs ← a⁻¹ rhs` (the LSCM
/// solve; also used by the symmetric Dirichlet setup, which keeps one symbolic factorisation).
pub(crate) fn llt_solve(
    symbolic: &SymbolicCholesky<usize>,
    a: SparseColMatRef<'_, usize, f64>,
    rhs: &mut Mat<f64>,
) -> Result<(), ParamError> {
    let mut l_values = vec![0.0; symbolic.len_val()];
    let mut mem = MemBuffer::new(
        symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
    );
    let llt = symbolic
        .factorize_numeric_llt::<f64>(
            &mut l_values,
            a,
            Side::Lower,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .map_err(|e| ParamError::Solver(format!("LSCM Cholesky: {e:?}")))?;
    llt.solve_in_place_with_conj(Conj::No, rhs.as_mut(), Par::Seq, MemStack::new(&mut mem));
    Ok(())
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
}
