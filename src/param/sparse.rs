//! The sparse linear algebra of Sec. 3.3, all through faer and all sequential (`Par::Seq`,
//! and faer is built without `rayon`): the map, and so the output bytes, must not depend on
//! the thread count.
//!
//! * [`VertexSystem`]: matrices over the `2n` dofs `2v + c` of a disk's map whose pattern
//!   is the vertex 1-rings with full 2×2 blocks — the LSCM normal matrix and the Newton
//!   Hessian of the symmetric Dirichlet optimisation. The pattern and one symbolic Cholesky
//!   factorisation (AMD ordering) are built once per disk and reused by the LSCM solve, the
//!   overlap repair and every Newton iteration ([`Llt`]).
//! * [`solve_triplets`]: a system assembled from triplets, solved once (the Tutte map).

use super::SolveFailure;
use crate::ids::VertexId;
use crate::mesh::TriMesh;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMatRef, Triplet};
use faer::{Conj, Mat, Par, Side};
use std::cell::OnceCell;

/// Dimension (2 × vertices) from which the supernodal Cholesky kernel is forced: faer's
/// automatic choice picks the simplicial kernel for these 2D-mesh matrices, measured
/// ~25–50% slower per numeric factorisation on 5k–15k-face cover patches (the 2×2 vertex
/// blocks make dense supernodes). Below it the automatic choice is kept.
const SUPERNODAL_MIN_DIM: usize = 2000;

/// The fixed sparsity pattern over dofs `2v + c` (full symmetric storage, sorted rows) and
/// the value slot of every triangle-local and vertex-diagonal entry.
pub(super) struct Pattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// 36 slots per triangle, row-major over local dofs `2k + c`.
    tri_slots: Vec<[u32; 36]>,
    /// Slots of the 2×2 diagonal block of each vertex, `[(x,x), (y,x), (x,y), (y,y)]`.
    diag_slots: Vec<[u32; 4]>,
}

impl Pattern {
    fn new(n: usize, tris: &[[VertexId; 3]]) -> Pattern {
        let mut adj: Vec<Vec<usize>> = (0..n).map(|v| vec![v]).collect();
        for t in tris {
            for a in t {
                for b in t {
                    adj[a.idx()].push(b.idx());
                }
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        let mut col_ptr = Vec::with_capacity(2 * n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for a in &adj {
            for _c in 0..2 {
                for &w in a {
                    row_idx.push(2 * w);
                    row_idx.push(2 * w + 1);
                }
                col_ptr.push(row_idx.len());
            }
        }
        let slot = |row: usize, col: usize| -> u32 {
            let (s, e) = (col_ptr[col], col_ptr[col + 1]);
            // The pattern contains every (row, col) asked for by construction.
            let k = row_idx[s..e].binary_search(&row).unwrap_or(0);
            (s + k) as u32
        };
        // Column `2a + c` lists rows `2w, 2w + 1` for the sorted neighbours `w` of `a`, so the
        // slot of row `2b + r` is `col_ptr[2a + c] + 2·(position of b in adj[a]) + r`: one
        // search per vertex pair instead of one per entry.
        let tri_slots = tris
            .iter()
            .map(|t| {
                let mut s = [0u32; 36];
                for k1 in 0..3 {
                    let a = t[k1].idx();
                    for k2 in 0..3 {
                        let b = t[k2].idx();
                        // By construction b is in adj[a].
                        let pos = adj[a].binary_search(&b).unwrap_or(0);
                        for c in 0..2 {
                            let base = col_ptr[2 * a + c] + 2 * pos;
                            for r in 0..2 {
                                // Entry (row 2b + r, column 2a + c) at local (2k2 + r, 2k1 + c).
                                s[(2 * k2 + r) * 6 + 2 * k1 + c] = (base + r) as u32;
                            }
                        }
                    }
                }
                s
            })
            .collect();
        let diag_slots = (0..n)
            .map(|v| {
                [
                    slot(2 * v, 2 * v),
                    slot(2 * v + 1, 2 * v),
                    slot(2 * v, 2 * v + 1),
                    slot(2 * v + 1, 2 * v + 1),
                ]
            })
            .collect();
        Pattern {
            col_ptr,
            row_idx,
            tri_slots,
            diag_slots,
        }
    }

    /// Number of stored entries (the length of a value array).
    pub(super) fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Matrix dimension (2 × vertices).
    pub(super) fn dim(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// Value slot of local entry `(l1, l2)` (local dofs `2k + c`) of triangle `t`.
    #[inline]
    pub(super) fn tri_slot(&self, t: usize, l1: usize, l2: usize) -> usize {
        self.tri_slots[t][l1 * 6 + l2] as usize
    }

    /// Value slot of the diagonal entry of dof `d`.
    #[inline]
    pub(super) fn diag_slot(&self, d: usize) -> usize {
        self.diag_slots[d / 2][if d % 2 == 0 { 0 } else { 3 }] as usize
    }

    /// Add `c · g gᵀ` to the 2×2 diagonal block of vertex `v` (the Gauss–Newton blocks of
    /// the boundary terms, which keep the pattern fixed).
    #[inline]
    pub(super) fn add_diag_outer(&self, vals: &mut [f64], v: usize, c: f64, g: [f64; 2]) {
        let s = &self.diag_slots[v];
        vals[s[0] as usize] += c * g[0] * g[0];
        vals[s[1] as usize] += c * g[1] * g[0];
        vals[s[2] as usize] += c * g[0] * g[1];
        vals[s[3] as usize] += c * g[1] * g[1];
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        let dim = self.dim();
        SymbolicSparseColMatRef::new_checked(dim, dim, &self.col_ptr, None, &self.row_idx)
    }

    /// The matrix with this pattern and the values `vals`.
    fn matrix<'a>(&'a self, vals: &'a [f64]) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(self.symbolic(), vals)
    }
}

/// The [`Pattern`] of one disk and its symbolic Cholesky factorisation (~3.5 ms on a
/// 5,000-face patch, so built once per disk).
pub(super) struct VertexSystem {
    /// The sparsity pattern.
    pub(super) pattern: Pattern,
    symbolic: SymbolicCholesky<usize>,
}

impl VertexSystem {
    /// The pattern of `disk`'s vertex 1-rings and its symbolic factorisation.
    pub(super) fn new(disk: &TriMesh) -> Result<VertexSystem, SolveFailure> {
        let pattern = Pattern::new(disk.n_vertices(), &disk.triangles);
        let mut params = CholeskySymbolicParams::default();
        if pattern.dim() >= SUPERNODAL_MIN_DIM {
            params.supernodal_flop_ratio_threshold = SupernodalThreshold::FORCE_SUPERNODAL;
        }
        let symbolic = factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Lower,
            Default::default(),
            params,
        )
        .map_err(|_| SolveFailure::Symbolic)?;
        Ok(VertexSystem { pattern, symbolic })
    }

    /// The system of `disk` kept in `cell`, built on first use (the LSCM start, the overlap
    /// repair and the certified optimisation of one disk share it).
    pub(super) fn get<'a>(
        cell: &'a OnceCell<VertexSystem>,
        disk: &TriMesh,
    ) -> Result<&'a VertexSystem, SolveFailure> {
        if let Some(s) = cell.get() {
            return Ok(s);
        }
        let s = VertexSystem::new(disk)?;
        Ok(cell.get_or_init(|| s))
    }
}

/// Numeric Cholesky factorisations on a [`VertexSystem`]'s symbolic factorisation, with
/// their storage kept from one to the next.
pub(super) struct Llt<'a> {
    system: &'a VertexSystem,
    l_values: Vec<f64>,
    mem: MemBuffer,
}

impl<'a> Llt<'a> {
    /// Storage for the factors of `system`'s matrices.
    pub(super) fn new(system: &'a VertexSystem) -> Llt<'a> {
        let symbolic = &system.symbolic;
        Llt {
            system,
            l_values: vec![0.0; symbolic.len_val()],
            mem: MemBuffer::new(
                symbolic
                    .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
                    .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq)),
            ),
        }
    }

    /// Factorise the matrix with values `vals` (in pattern order) and overwrite `rhs` with
    /// its solution. Errors (leaving `rhs` unchanged) when the matrix is not numerically
    /// positive definite.
    pub(super) fn solve(&mut self, vals: &[f64], rhs: &mut Mat<f64>) -> Result<(), SolveFailure> {
        let a = self.system.pattern.matrix(vals);
        let llt = self
            .system
            .symbolic
            .factorize_numeric_llt::<f64>(
                &mut self.l_values,
                a,
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .map_err(|_| SolveFailure::NotPositiveDefinite)?;
        llt.solve_in_place_with_conj(
            Conj::No,
            rhs.as_mut(),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
        Ok(())
    }
}

/// How [`solve_triplets`] factorises its matrix.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum Factorization {
    /// Sparse Cholesky (symmetric positive definite).
    Cholesky,
    /// Sparse LU with partial pivoting (general).
    Lu,
}

/// Solve `a x = rhs` for the `n × n` matrix `a` given by `triplets` (duplicates summed),
/// with faer's automatic symbolic choices. Errors name the failing step.
pub(super) fn solve_triplets(
    n: usize,
    triplets: &[Triplet<usize, usize, f64>],
    rhs: &Mat<f64>,
    how: Factorization,
) -> Result<Mat<f64>, SolveFailure> {
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, triplets)
        .map_err(|_| SolveFailure::Assembly)?;
    // faer's high-level solvers use its global parallelism, which is sequential because faer
    // is built without its `rayon` feature (Cargo.toml); enabling that feature would need
    // explicit `Par::Seq` factorisations here, as in `Llt`.
    Ok(match how {
        Factorization::Lu => a.sp_lu().map_err(|_| SolveFailure::Lu)?.solve(rhs),
        Factorization::Cholesky => a
            .sp_cholesky(Side::Lower)
            .map_err(|_| SolveFailure::NotPositiveDefinite)?
            .solve(rhs),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_slots_address_their_entries() {
        let disk = crate::mesh::generators::disk(1.0, 5, 5);
        let pat = Pattern::new(disk.n_vertices(), &disk.triangles);
        for (ti, t) in disk.triangles.iter().enumerate() {
            for l1 in 0..6 {
                for l2 in 0..6 {
                    let row = 2 * t[l1 / 2].idx() + l1 % 2;
                    let col = 2 * t[l2 / 2].idx() + l2 % 2;
                    let k = pat.tri_slot(ti, l1, l2);
                    assert!(pat.col_ptr[col] <= k && k < pat.col_ptr[col + 1]);
                    assert_eq!(pat.row_idx[k], row);
                }
            }
        }
        for d in 0..pat.dim() {
            assert_eq!(pat.row_idx[pat.diag_slot(d)], d);
            assert!(pat.col_ptr[d] <= pat.diag_slot(d) && pat.diag_slot(d) < pat.col_ptr[d + 1]);
        }
    }

    #[test]
    fn llt_solves_a_system_on_the_pattern() {
        // A symmetric, diagonally dominant matrix on the pattern of a small disk (4 on the
        // diagonal, −0.05 elsewhere): the solution of A x = A·1 is 1.
        let disk = crate::mesh::generators::disk(1.0, 4, 4);
        let sys = VertexSystem::new(&disk).unwrap();
        let pat = &sys.pattern;
        let mut vals = vec![-0.05; pat.nnz()];
        for d in 0..pat.dim() {
            vals[pat.diag_slot(d)] = 4.0;
        }
        let mut rhs = Mat::<f64>::zeros(pat.dim(), 1);
        for c in 0..pat.dim() {
            for k in pat.col_ptr[c]..pat.col_ptr[c + 1] {
                rhs[(pat.row_idx[k], 0)] += vals[k];
            }
        }
        Llt::new(&sys).solve(&vals, &mut rhs).unwrap();
        for d in 0..pat.dim() {
            assert!((rhs[(d, 0)] - 1.0).abs() < 1e-12, "{d}: {}", rhs[(d, 0)]);
        }
    }
}
