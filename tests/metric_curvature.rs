//! Sec. 3.1 / 4.1: principal curvatures on analytic surfaces, the curvature metric, and the
//! metric field's evaluation and projection.

use conemesh::mesh::generators;
use conemesh::metric::{
    curvature_metric, principal_curvatures, CurvatureOptions, MetricError, MetricField,
    MetricOptions, Normalization, SpdDefect,
};
use conemesh::{FaceId, SurfaceLocation, TriMesh};
use nalgebra::{Matrix3, Point3, Vector3};

type R = Result<(), Box<dyn std::error::Error>>;

#[test]
fn icosphere_has_k1_eq_k2_eq_inverse_radius_at_every_vertex() -> R {
    for r in [0.5, 2.0] {
        let m = generators::icosphere(r, 5);
        let pc = principal_curvatures(&m, &CurvatureOptions::default())?;
        for (v, c) in pc.iter().enumerate() {
            for k in [c.k1, c.k2] {
                assert!(
                    (k * r - 1.0).abs() < 0.02,
                    "v{v}: k = {k}, expected 1/r = {}",
                    1.0 / r
                );
            }
            let outward = m.positions[v].coords.normalize();
            assert!(
                c.normal.dot(&outward) > 0.999,
                "v{v}: normal {:?}",
                c.normal
            );
        }
    }
    Ok(())
}

#[test]
fn cylinder_has_k1_inverse_radius_along_the_circumference() -> R {
    let r = 0.3;
    // Fine enough that 5 rings span a small angle: the quadric fit of a circle over an
    // angle θ overestimates 1/r by O(θ²) (5.5 % at 64 segments, ~1 % at 160).
    let (nu, nv) = (160, 100);
    let m = generators::cylinder(r, 1.0, nu, nv);
    let pc = principal_curvatures(&m, &CurvatureOptions::default())?;
    let mut checked = 0;
    for (v, c) in pc.iter().enumerate() {
        let p = m.positions[v];
        // Interior: 5 rings away from both boundary loops.
        if p.z < 6.0 / nv as f64 || p.z > 1.0 - 6.0 / nv as f64 {
            continue;
        }
        checked += 1;
        assert!((c.k1 * r - 1.0).abs() < 0.02, "v{v}: k1 = {}", c.k1);
        assert!(c.k2.abs() * r < 0.02, "v{v}: k2 = {}", c.k2);
        let circumferential = Vector3::new(-p.y, p.x, 0.0).normalize();
        assert!(
            c.d1.dot(&circumferential).abs() > 0.999,
            "v{v}: d1 {:?}",
            c.d1
        );
        assert!(c.d2.z.abs() > 0.999, "v{v}: d2 {:?}", c.d2);
    }
    assert!(checked > 1000);
    Ok(())
}

#[test]
fn flat_disk_gets_the_floor_metric_and_a_valid_frame() -> R {
    let m = generators::disk(0.5, 12, 6);
    let opts = MetricOptions::default();
    let pc = principal_curvatures(&m, &opts.curvature)?;
    let metrics = curvature_metric(&m, &opts)?;
    let floor_metric = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0) * opts.floor;
    for (v, (c, mm)) in pc.iter().zip(&metrics).enumerate() {
        assert_eq!((c.k1, c.k2), (0.0, 0.0), "v{v}");
        assert!(
            (c.normal - Vector3::z()).norm() < 1e-12,
            "v{v}: {:?}",
            c.normal
        );
        assert!((c.d1.norm() - 1.0).abs() < 1e-12 && (c.d2.norm() - 1.0).abs() < 1e-12);
        assert!(c.d1.dot(&c.d2).abs() < 1e-12 && c.d1.dot(&c.normal).abs() < 1e-12);
        assert!((c.d1.cross(&c.d2) - c.normal).norm() < 1e-12);
        assert!((mm - floor_metric).norm() < 1e-16, "v{v}: {mm}");
    }
    // Planar frames are deterministic: the same for every vertex with the same normal.
    assert!(pc.windows(2).all(|w| w[0].d1 == w[1].d1));
    Ok(())
}

#[test]
fn curvature_metric_is_rank_two_with_the_floor() -> R {
    let m = generators::cylinder(0.3, 1.0, 64, 40);
    let opts = MetricOptions::default();
    let pc = principal_curvatures(&m, &opts.curvature)?;
    let metrics = curvature_metric(&m, &opts)?;
    for (c, mm) in pc.iter().zip(&metrics) {
        assert!((mm * c.normal).norm() < 1e-12 * mm.norm());
        let e1 = c.d1.dot(&(mm * c.d1));
        let e2 = c.d2.dot(&(mm * c.d2));
        assert!((e1 - c.k1.abs().max(opts.floor)).abs() < 1e-12 * e1);
        assert!((e2 - c.k2.abs().max(opts.floor)).abs() < 1e-12 * e1);
        assert_eq!(*mm, mm.transpose());
    }
    Ok(())
}

#[test]
fn principal_curvatures_are_rigid_motion_invariant_and_scale_as_inverse_length() -> R {
    let m = generators::torus(1.0, 0.4, 48, 24);
    let rot = nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 2.0);
    let s = 2.5;
    let moved = TriMesh {
        positions: m
            .positions
            .iter()
            .map(|p| Point3::from(rot * p.coords * s + Vector3::new(3.0, -1.0, 0.5)))
            .collect(),
        triangles: m.triangles.clone(),
    };
    let a = principal_curvatures(&m, &CurvatureOptions::default())?;
    let b = principal_curvatures(&moved, &CurvatureOptions::default())?;
    for (v, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!((x.k1 - s * y.k1).abs() < 1e-9 * x.k1.abs().max(1.0), "v{v}");
        assert!((x.k2 - s * y.k2).abs() < 1e-9 * x.k1.abs().max(1.0), "v{v}");
        assert!((rot * x.d1).dot(&y.d1).abs() > 1.0 - 1e-9, "v{v}");
    }
    Ok(())
}

fn field_on_sphere() -> Result<MetricField, MetricError> {
    let m = Normalization::of(&generators::icosphere(1.0, 3)).apply(&generators::icosphere(1.0, 3));
    MetricField::from_curvature(m, &MetricOptions::default())
}

#[test]
fn field_evaluates_vertex_tensors_exactly_and_interpolates_at_face_centres() -> R {
    // A field with distinct, deliberately different tensors per vertex.
    let m = generators::icosphere(1.0, 2);
    let normals = m.vertex_normals();
    let metrics: Vec<Matrix3<f64>> = normals
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let (t1, t2) = conemesh::metric::tangent_frame(n);
            let a = 1.0 + i as f64 * 0.01;
            t1 * t1.transpose() * a + t2 * t2.transpose() * (2.0 * a) + n * n.transpose() * 0.5
        })
        .map(|x: Matrix3<f64>| (x + x.transpose()) * 0.5)
        .collect();
    let field = MetricField::new(m.clone(), metrics.clone())?;
    for f in m.faces() {
        for (k, v) in m.face(f).iter().enumerate() {
            let mut bary = [0.0; 3];
            bary[k] = 1.0;
            assert_eq!(
                field.eval_at(&SurfaceLocation { face: f, bary }),
                metrics[v.idx()]
            );
        }
        let centre = field.eval_at(&SurfaceLocation {
            face: f,
            bary: [1.0 / 3.0; 3],
        });
        let t = m.face(f);
        let mean = (metrics[t[0].idx()] + metrics[t[1].idx()] + metrics[t[2].idx()]) / 3.0;
        assert!((centre - mean).norm() < 1e-14 * mean.norm());
    }
    // eval at a vertex position projects onto that vertex.
    for v in [0usize, 17, 100] {
        let got = field.eval(&m.positions[v]);
        assert!((got - metrics[v]).norm() < 1e-9 * metrics[v].norm(), "v{v}");
    }
    Ok(())
}

#[test]
fn project_returns_the_closest_face_and_point() -> R {
    let field = field_on_sphere()?;
    let m = field.reference();
    for f in [FaceId(0), FaceId(77), FaceId(500)] {
        let c = m.face_centroid(f);
        let off = c + field.face_normal(f) * 0.01;
        let (loc, q) = field.project(&off);
        assert_eq!(loc.face, f);
        assert!((q - c).norm() < 1e-9, "{q} vs {c}");
        assert!(loc.bary.iter().all(|b| (b - 1.0 / 3.0).abs() < 1e-9));
        // Brute force: no face is closer.
        let d = (q - off).norm();
        for g in m.faces() {
            let [a, b, cc] = m.face_points(g);
            assert!(
                (a - off).norm() >= d - 1e-12
                    && (b - off).norm() >= d - 1e-12
                    && (cc - off).norm() >= d - 1e-12
            );
        }
    }
    // A point far outside projects onto the surface with barycentrics summing to 1.
    let (loc, q) = field.project(&Point3::new(3.0, -2.0, 1.0));
    assert!((loc.bary.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    assert!(loc.bary.iter().all(|b| *b >= 0.0));
    assert!((q - loc.position(m)).norm() == 0.0);
    // A NaN query does not panic.
    let _ = field.eval(&Point3::new(f64::NAN, 0.0, 0.0));
    Ok(())
}

#[test]
fn field_rejects_bad_tensors_by_vertex() -> R {
    let m = generators::icosphere(1.0, 1);
    let n = m.n_vertices();
    let good = curvature_metric(&m, &MetricOptions::default())?;
    let e = MetricField::new(m.clone(), good[..n - 1].to_vec()).unwrap_err();
    assert_eq!(
        e,
        MetricError::CountMismatch {
            expected: n,
            found: n - 1
        }
    );
    let mut bad = good.clone();
    bad[5][(1, 1)] = f64::NAN;
    assert_eq!(
        MetricField::new(m.clone(), bad).unwrap_err(),
        MetricError::NonFinite { vertex: 5 }
    );
    let mut bad = good.clone();
    bad[7] = -bad[7];
    assert!(matches!(
        MetricField::new(m.clone(), bad).unwrap_err(),
        MetricError::NotSpd {
            vertex: 7,
            defect: SpdDefect::NegativeEigenvalue { .. }
        }
    ));
    // PSD but zero on the tangent plane: only the normal direction is stretched.
    let mut bad = good.clone();
    let nrm = m.positions[9].coords.normalize();
    bad[9] = nrm * nrm.transpose();
    let e = MetricField::new(m.clone(), bad).unwrap_err();
    assert!(
        matches!(
            e,
            MetricError::NotSpd {
                vertex: 9,
                defect: SpdDefect::TangentIndefinite { .. }
            }
        ),
        "{e}"
    );
    let mut bad = good;
    bad[3][(0, 1)] += 1.0;
    assert!(matches!(
        MetricField::new(m, bad).unwrap_err(),
        MetricError::NotSpd {
            vertex: 3,
            defect: SpdDefect::NotSymmetric { .. }
        }
    ));
    Ok(())
}

#[test]
fn unreferenced_vertices_do_not_break_curvature_or_field() -> R {
    let mut m = generators::icosphere(1.0, 2);
    m.positions.push(Point3::new(5.0, 5.0, 5.0));
    let field = MetricField::from_curvature(m.clone(), &MetricOptions::default())?;
    let last = field.vertex_metrics()[m.n_vertices() - 1];
    assert!(last.iter().all(|x| x.is_finite()));
    Ok(())
}

#[test]
fn principal_curvatures_are_deterministic() -> R {
    let m = generators::torus(1.0, 0.4, 40, 20);
    let bits = |v: &[conemesh::metric::PrincipalCurvature]| -> Vec<u64> {
        v.iter()
            .flat_map(|c| {
                [c.k1, c.k2, c.d1.x, c.d1.y, c.d1.z, c.normal.x]
                    .map(f64::to_bits)
                    .to_vec()
            })
            .collect()
    };
    let a = principal_curvatures(&m, &CurvatureOptions::default())?;
    let b = principal_curvatures(&m, &CurvatureOptions::default())?;
    assert_eq!(bits(&a), bits(&b));
    Ok(())
}

#[test]
fn tiny_components_get_zero_curvature_and_a_valid_field() -> R {
    // One triangle: two neighbours per vertex, too few for the 5-parameter fit.
    let m = TriMesh::from_indices(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.2),
        ],
        &[[0, 1, 2]],
    )?;
    let pc = principal_curvatures(&m, &CurvatureOptions::default())?;
    let n = m.face_normal(FaceId(0));
    for c in &pc {
        assert_eq!((c.k1, c.k2), (0.0, 0.0));
        assert!((c.normal - n).norm() < 1e-12);
    }
    let field = MetricField::from_curvature(m, &MetricOptions::default())?;
    let at = field.eval(&Point3::new(0.2, 0.2, 1.0));
    assert!((at * n).norm() < 1e-15);
    Ok(())
}
