//! Metric transfer (Sec. 3.3, Eq. 4) on a curved isometric patch, then the planar remesh of
//! its parameter domain under the transferred field: the path the pipeline takes.

use conemesh::invariants::certify_planar;
use conemesh::mesh::generators;
use conemesh::remesh2d::{
    planar_quality, transfer_metric, Lct, PlanarDomain, PlanarMetricField, PlanarRemesher,
    Remesh2dError, TransferMethod,
};
use nalgebra::{Matrix2, Matrix3, Point2, Vector3};
use rand::SeedableRng;

/// A cylinder piece (r = 1, angle 1, height 1) unrolled by arc length: an isometry.
/// The 3D metric: k_u along the circle's tangent, k_z along the axis, k_n along the normal.
fn unrolled_cylinder(
    nu: usize,
    nv: usize,
    k: [f64; 3],
) -> (conemesh::TriMesh, Vec<Point2<f64>>, Vec<Matrix3<f64>>) {
    let m = generators::cylinder_piece(1.0, 1.0, 1.0, nu, nv);
    let uv: Vec<Point2<f64>> = m
        .positions
        .iter()
        .map(|p| Point2::new(p.y.atan2(p.x), p.z))
        .collect();
    let metrics = m
        .positions
        .iter()
        .map(|p| {
            let u = p.y.atan2(p.x);
            let t = Vector3::new(-u.sin(), u.cos(), 0.0);
            let z = Vector3::z();
            let n = Vector3::new(u.cos(), u.sin(), 0.0);
            t * t.transpose() * k[0] + z * z.transpose() * k[1] + n * n.transpose() * k[2]
        })
        .collect();
    (m, uv, metrics)
}

#[test]
fn both_transfers_restrict_the_metric_on_an_unrolled_cylinder() -> Result<(), Remesh2dError> {
    let (m, uv, metrics) = unrolled_cylinder(64, 16, [100.0, 4.0, 9.0]);
    let expect = Matrix2::new(100.0, 0.0, 0.0, 4.0);
    for method in [
        TransferMethod::Eq4PrincipalFit,
        TransferMethod::JacobianPullback,
    ] {
        let out = transfer_metric(&m, &uv, &metrics, method)?;
        for (i, t) in out.iter().enumerate() {
            // Chords vs arcs: O(Δu²) relative error.
            assert!(
                (t - expect).norm() < 1e-2 * expect.norm(),
                "{method:?} v{i}: {t}"
            );
        }
    }
    Ok(())
}

#[test]
fn remesh_under_transferred_field_is_certified() -> Result<(), Remesh2dError> {
    // Boundary spacing of metric length 0.25 both ways: 10/40 along u, 2/8 along z.
    let (nu, nv) = (40usize, 8usize);
    let (m, uv, metrics) = unrolled_cylinder(nu, nv, [100.0, 4.0, 9.0]);
    let m2 = transfer_metric(&m, &uv, &metrics, TransferMethod::default())?;
    let tris: Vec<[u32; 3]> = m.triangles.iter().map(|t| t.map(|v| v.0)).collect();
    let field = PlanarMetricField::new(uv.clone(), tris.clone(), m2)?;
    let id = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
    let mut boundary: Vec<u32> = (0..nu).map(|i| id(i, 0)).collect();
    boundary.extend((0..nv).map(|j| id(nu, j)));
    boundary.extend((1..=nu).rev().map(|i| id(i, nv)));
    boundary.extend((1..=nv).rev().map(|j| id(0, j)));
    let dom = PlanarDomain {
        points: uv,
        triangles: tris,
        boundary,
        constrained_edges: vec![],
    };
    let l = 0.25;
    let out = Lct::default().remesh(
        &dom,
        &field,
        l,
        &mut rand_chacha::ChaCha8Rng::seed_from_u64(11),
    )?;
    certify_planar(&dom, &out)?;
    let q = planar_quality(&out, &field, l);
    assert!(q.q_avg >= 0.88 && q.edges_in_range >= 0.9, "{q:?}");
    Ok(())
}
