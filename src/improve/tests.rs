//! Unit tests of the surface passes.
use super::geometry::{metric_optimal_point, point_triangle_distance, segment_distance};
use super::*;
use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::mesh::{Topology, TriMesh};
use nalgebra::{Matrix3, Point3, Vector3};

fn ctx<'a>(
    field: &'a MetricField,
    flip_test: &'a FlipTest,
    tol: f64,
    feature_edges: Option<&'a HashSet<EdgeKey>>,
) -> SurfaceContext<'a> {
    SurfaceContext {
        field,
        flip_test,
        embedded_input: true,
        tol,
        l_tar: f64::NAN,
        slide_sweep: false,
        feature_edges,
        pinned: &[],
        curves: None,
        slide_boundary: false,
        scope: None,
    }
}

/// Two skinny triangles over the long diagonal of a flat rhombus, or of a ridge folded
/// `lift` up along the short diagonal.
fn rhombus(lift: f64) -> (MetricField, WorkingMesh, FlipTest) {
    let reference = TriMesh {
        positions: vec![
            Point3::new(-1.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 0.3, lift),
            Point3::new(0.0, -0.3, lift),
        ],
        triangles: vec![
            [VertexId(0), VertexId(1), VertexId(2)],
            [VertexId(1), VertexId(0), VertexId(3)],
        ],
    };
    let field =
        MetricField::new(reference.clone(), vec![Matrix3::identity(); 4]).expect("identity metric");
    let work = WorkingMesh::from_reference(&reference);
    let flip_test = FlipTest::new(&reference);
    (field, work, flip_test)
}

/// A hexagon fan that is regular in the metric diag(4, 1, 0) (so squashed in x): with the
/// centre displaced, the metric-optimal point is the centre again, while the plain
/// centroid of a non-symmetric fan would not be.
#[test]
fn metric_optimal_point_recentres_an_anisotropic_fan() {
    let m = Matrix3::from_diagonal(&Vector3::new(4.0, 1.0, 0.0));
    let mut positions = vec![Point3::new(0.1, -0.2, 0.0)];
    for k in 0..6 {
        let a = std::f64::consts::FRAC_PI_3 * k as f64;
        positions.push(Point3::new(0.5 * a.cos(), a.sin(), 0.0));
    }
    let triangles = (0..6)
        .map(|k| [VertexId(0), VertexId(1 + k), VertexId(1 + (k + 1) % 6)])
        .collect();
    let mesh = TriMesh {
        positions,
        triangles,
    };
    let fan: Vec<FaceId> = (0..6).map(FaceId::new).collect();
    let p = metric_optimal_point(&mesh, &fan, VertexId(0), &m).expect("point");
    assert!(p.coords.norm() < 1e-12, "{p}");
    // A degenerate tangent metric gives no point.
    assert!(metric_optimal_point(&mesh, &fan, VertexId(0), &Matrix3::zeros()).is_none());
}

/// The skinny pair is flipped to the short diagonal (q rises from 0.29 to 0.65) and the
/// result is still an oriented disk over the same four vertices.
#[test]
fn connectivity_update_flips_a_skinny_pair_on_a_flat_rhombus() {
    let (field, mut work, flip_test) = rhombus(0.0);
    let q_min = |w: &WorkingMesh| {
        crate::quality::face_qualities(&w.mesh, &[Matrix3::identity(); 4])
            .iter()
            .map(|q| q.q)
            .fold(f64::INFINITY, f64::min)
    };
    let before = q_min(&work);
    assert_eq!(
        connectivity_update(&ctx(&field, &flip_test, 0.01, None), &mut work),
        1
    );
    let after = q_min(&work);
    assert!(after > before + 0.3, "q_min {before} -> {after}");
    let edges: HashSet<EdgeKey> = work
        .mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| EdgeKey::new(t[k], t[(k + 1) % 3])))
        .collect();
    assert!(edges.contains(&EdgeKey::new(VertexId(2), VertexId(3))));
    assert!(!edges.contains(&EdgeKey::new(VertexId(0), VertexId(1))));
    let topo = Topology::build(&work.mesh);
    assert!(topo.is_oriented_manifold());
    assert_eq!(topo.boundary_loops().len(), 1);
    // Nothing left to improve.
    assert_eq!(
        connectivity_update(&ctx(&field, &flip_test, 0.01, None), &mut work),
        0
    );
}

/// The same skinny pair is not flipped when its diagonal is a feature-line edge.
#[test]
fn connectivity_update_never_flips_a_feature_edge() {
    let (field, mut work, flip_test) = rhombus(0.0);
    let before = work.mesh.triangles.clone();
    let feature: HashSet<EdgeKey> = [EdgeKey::new(VertexId(0), VertexId(1))].into();
    assert_eq!(
        connectivity_update(&ctx(&field, &flip_test, 0.01, Some(&feature)), &mut work),
        0
    );
    assert_eq!(work.mesh.triangles, before);
}

/// On a ridge the flip would cut the surface by the ridge height (0.05 > tol 0.01): kept.
#[test]
fn connectivity_update_keeps_a_ridge_beyond_the_tolerance() {
    let (field, mut work, flip_test) = rhombus(0.05);
    let before = work.mesh.triangles.clone();
    assert_eq!(
        connectivity_update(&ctx(&field, &flip_test, 0.01, None), &mut work),
        0
    );
    assert_eq!(work.mesh.triangles, before);
    // With a tolerance above the ridge height the same flip is made.
    assert_eq!(
        connectivity_update(&ctx(&field, &flip_test, 0.1, None), &mut work),
        1
    );
}

/// A flat hexagonal fan whose centre sits near one corner: relocation moves it towards
/// the middle and the worst triangle improves; on a pyramid whose apex is off-centre the
/// apex may move only while the old apex stays within `tol` of the surface.
fn hexagon(apex: Point3<f64>) -> TriMesh {
    let mut positions = vec![apex];
    let mut triangles = Vec::new();
    for i in 0..6 {
        let a = i as f64 * std::f64::consts::PI / 3.0;
        positions.push(Point3::new(a.cos(), a.sin(), 0.0));
        triangles.push([VertexId(0), VertexId(1 + i), VertexId(1 + (i + 1) % 6)]);
    }
    TriMesh {
        positions,
        triangles,
    }
}

#[test]
fn vertex_position_update_centres_a_fan_and_keeps_a_tip() {
    let q_min = |m: &TriMesh| {
        crate::quality::face_qualities(m, &vec![Matrix3::identity(); m.n_vertices()])
            .iter()
            .map(|q| q.q)
            .fold(f64::INFINITY, f64::min)
    };
    for (apex, tol) in [
        (Point3::new(0.6, 0.1, 0.0), 0.01),
        (Point3::new(0.3, 0.0, 0.4), 0.01),
    ] {
        let reference = hexagon(apex);
        let field = MetricField::new(reference.clone(), vec![Matrix3::identity(); 7])
            .expect("identity metric");
        let flip_test = FlipTest::new(&reference);
        let mut work = WorkingMesh::from_reference(&reference);
        let before = q_min(&work.mesh);
        let moves = vertex_position_update(&ctx(&field, &flip_test, tol, None), &mut work);
        let p = work.mesh.positions[0];
        let d = work
            .mesh
            .faces()
            .map(|f| point_triangle_distance(&apex, &work.mesh.face_points(f)))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d <= tol,
            "apex {apex}: the old apex is {d} from the surface"
        );
        if apex.z == 0.0 {
            assert!(moves > 0 && p.coords.norm() < 0.3, "centre at {p}");
            assert!(q_min(&work.mesh) > before + 0.2);
        } else {
            // Any move of a sharp apex cuts it: kept.
            assert_eq!(p, apex);
        }
    }
}

#[test]
fn segment_distance_of_crossing_and_skew_segments() {
    let p = |x, y, z| Point3::new(x, y, z);
    let d = segment_distance(
        p(-1., 0., 0.),
        p(1., 0., 0.),
        p(0., -1., 0.5),
        p(0., 1., 0.5),
    );
    assert!((d - 0.5).abs() < 1e-15);
    let d = segment_distance(p(0., 0., 0.), p(1., 0., 0.), p(2., 1., 0.), p(3., 1., 0.));
    assert!((d - 2f64.sqrt()).abs() < 1e-15);
}
