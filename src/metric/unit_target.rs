//! A surface metric in the convention of MMG's `-ltar 1`: scaled so that an edge on target
//! has metric length 1, and positive definite in 3D, so that another remesher can be given
//! the very metric a run remeshes to (`conemesh remesh --write-input-metric`).

use crate::mesh::TriMesh;
use nalgebra::Matrix3;

/// The tensors `metrics` (one per vertex of `mesh`, any units as long as both agree) over
/// `l_tar²`, so that an edge of metric length `l_tar` in `metrics` has length 1 in the result,
/// restricted to each vertex's tangent plane (`P M P` with `P = I − n nᵀ`, `n` the vertex
/// normal of [`TriMesh::vertex_normals`], the plane [`super::MetricField`] checks and restricts
/// to) and completed along the normal by the tangent block's largest eigenvalue.
///
/// On the tangent plane the result is exactly `M / l_tar²`, whatever `M` did along the
/// normal: the curvature metric (Sec. 4.1) is zero along its fitted normal, a user's `.sol` has
/// its own normal part, and neither moves an edge on the surface. The normal part makes each
/// tensor SPD in 3D, which MMG requires of every tensor it reads; its size there is the finer
/// of the two tangent sizes, as in the analytic suite (`conemesh::suite`). A vertex without a
/// normal (no face of positive area) keeps `M / l_tar²`.
pub fn unit_target_metric(
    mesh: &TriMesh,
    metrics: &[Matrix3<f64>],
    l_tar: f64,
) -> Vec<Matrix3<f64>> {
    let inv = 1.0 / (l_tar * l_tar);
    metrics
        .iter()
        .zip(mesh.vertex_normals())
        .map(|(m, n)| {
            if n.norm() < 0.5 {
                return m * inv;
            }
            let p = Matrix3::identity() - n * n.transpose();
            let t = p * m * p * inv;
            let t = (t + t.transpose()) * 0.5;
            let lmax = t.symmetric_eigenvalues().max();
            t + n * n.transpose() * lmax
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use nalgebra::Vector3;

    /// On a sphere, a rank-2 tensor of the tangent plane at each vertex (sizes 0.1 and 0.3
    /// along two tangents) comes back over L_tar² on that plane, SPD in 3D, with the normal
    /// eigenvalue the larger tangent one.
    #[test]
    fn tangent_block_over_ltar_squared_and_spd() {
        let mesh = generators::icosphere(2.0, 2);
        let normals = mesh.vertex_normals();
        let metrics: Vec<Matrix3<f64>> = normals
            .iter()
            .map(|n| {
                let (t1, t2) = crate::metric::tangent_frame(n);
                t1 * t1.transpose() / 0.01 + t2 * t2.transpose() / 0.09
            })
            .collect();
        let l_tar = 2.0;
        let out = unit_target_metric(&mesh, &metrics, l_tar);
        assert_eq!(out.len(), mesh.n_vertices());
        for ((w, m), n) in out.iter().zip(&metrics).zip(&normals) {
            let (t1, t2) = crate::metric::tangent_frame(n);
            for (a, b) in [(t1, t1), (t1, t2), (t2, t2)] {
                let got = a.dot(&(w * b));
                let want = a.dot(&(m * b)) / (l_tar * l_tar);
                assert!((got - want).abs() < 1e-12 * 100.0, "{got} vs {want}");
            }
            let eig = w.symmetric_eigenvalues();
            assert!(eig.min() > 0.0, "SPD: {eig:?}");
            let along: f64 = n.dot(&(w * n));
            assert!((along - 100.0 / 4.0).abs() < 1e-9, "normal part {along}");
            let off: Vector3<f64> = w * n - n * along;
            assert!(off.norm() < 1e-9, "the normal is an eigenvector");
        }
    }
}
