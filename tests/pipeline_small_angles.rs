//! The report's faces below 20° (issue 36): exactly the output faces whose smallest angle in
//! the metric is below 20°, smallest first, each with the most held kind among its vertices
//! (a kept corner, a feature line, the boundary, or none), recomputed here from positions
//! alone: kept corners from the input's angle defects and the boundary's turns, feature lines
//! from the input's feature edges, the boundary from the output's topology.

use conemesh::features::FeatureRule;
use conemesh::mesh::{Topology, TriMesh};
use conemesh::pipeline::{
    RemeshOptions, Remeshed, Remesher, Stages, TargetLength, VertexKind, SMALL_ANGLE_DEG,
};
use conemesh::quality::face_qualities;
use conemesh::suite::ANALYTIC;
use nalgebra::{Matrix3, Point3};

mod common;

fn run(mesh: &TriMesh, metric: Option<&[Matrix3<f64>]>) -> Remeshed {
    let options = RemeshOptions {
        target: match metric {
            Some(_) => TargetLength::Absolute(1.0),
            None => RemeshOptions::default().target,
        },
        ..RemeshOptions::default()
    };
    let stages = match metric {
        Some(_) => Stages::for_sizes(conemesh::registry::MetricSizes::Absolute),
        None => Stages::default(),
    };
    Remesher::new(options)
        .with_stages(stages)
        .run_with(mesh, metric, |_| {})
        .unwrap_or_else(|e| panic!("remesh: {e}"))
}

/// The kind of output vertex `v` (of the run's unit-space mesh, as the field's reference),
/// from positions: on a kept corner of the input (angle
/// defect ≥ 1 rad, the default, or a boundary turn ≥ the default corner angle), on a feature
/// edge of the input, on the output's boundary, or inside.
fn kind_of(out: &Remeshed, v: conemesh::VertexId, out_topo: &Topology) -> VertexKind {
    let reference = out.field.reference();
    let ref_topo = Topology::build(reference);
    let p = out.unit.mesh.position(v);
    let corner_defect = conemesh::patches::corner_vertices(reference, &ref_topo, 1.0);
    let curves = conemesh::boundary::BoundaryCurves::new(
        reference,
        &ref_topo,
        conemesh::boundary::BoundaryOptions::default().corner_angle,
        Some(1.0),
    );
    let is_corner = reference
        .vertices()
        .filter(|w| corner_defect[w.idx()] || curves.is_corner(*w))
        .any(|w| reference.position(w) == p);
    if is_corner {
        return VertexKind::Corner;
    }
    let on_segment = |a: &Point3<f64>, b: &Point3<f64>| {
        let ab = b - a;
        let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
        (p - (a + ab * t)).norm() <= 1e-12 * (1.0 + a.coords.norm())
    };
    let on_feature = FeatureRule::default()
        .edges(reference, &ref_topo)
        .iter()
        .any(|e| on_segment(reference.position(e.0), reference.position(e.1)));
    if on_feature {
        VertexKind::Feature
    } else if out_topo.is_boundary_vertex(v) {
        VertexKind::Boundary
    } else {
        VertexKind::Interior
    }
}

/// Checks the report of `out` against the faces and kinds recomputed here; returns how many
/// faces of each cause it lists.
fn check_small_angles(name: &str, out: &Remeshed) -> [usize; 4] {
    let s = &out.unit.report.small_angles;
    assert_eq!(s.threshold_deg, SMALL_ANGLE_DEG);
    let metrics: Vec<_> = (out.unit.locations.iter())
        .map(|l| out.field.eval_at(l))
        .collect();
    let qs = face_qualities(&out.unit.mesh, &metrics);
    let mut below: Vec<usize> = (0..qs.len())
        .filter(|&f| qs[f].min_angle() < SMALL_ANGLE_DEG)
        .collect();
    below.sort_by(|&a, &b| qs[a].min_angle().total_cmp(&qs[b].min_angle()));
    let listed: Vec<usize> = s.faces.iter().map(|f| f.face.idx()).collect();
    assert_eq!(listed, below, "{name}: the faces below 20°, smallest first");
    let out_topo = Topology::build(&out.unit.mesh);
    let mut counts = [0; 4];
    for f in &s.faces {
        let angle = qs[f.face.idx()].min_angle();
        assert!((f.angle_deg - angle).abs() < 1e-9, "{name}: {}", f.face);
        let kinds = out
            .unit
            .mesh
            .face(f.face)
            .map(|v| kind_of(out, v, &out_topo));
        let cause = *kinds.iter().min().expect("three vertices");
        assert_eq!(f.cause, cause, "{name}: face {} {kinds:?}", f.face);
        assert_eq!(
            f.all_corners,
            kinds.iter().all(|k| *k == VertexKind::Corner)
        );
        counts[cause as usize] += 1;
    }
    assert_eq!(
        [s.corner, s.feature, s.boundary, s.interior],
        counts,
        "{name}: counts by cause"
    );
    counts
}

/// fandisk (a CAD part with feature lines) and plate-turning10 (a plate with four corners
/// under a user metric whose directions turn): the report lists what the recount finds, and
/// between them both a feature line and a kept corner are named as causes.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn the_report_names_every_face_below_20_degrees_and_its_cause() {
    let fandisk = common::load("fandisk.off");
    let fandisk_counts = check_small_angles("fandisk", &run(&fandisk, None));
    let case = ANALYTIC
        .iter()
        .find(|c| c.name == "plate-turning10")
        .expect("plate-turning10");
    let plate = case.mesh().expect("plate");
    let metric = case.metric(&plate);
    let plate_counts = check_small_angles(case.name, &run(&plate, Some(&metric)));
    let cause = |k: VertexKind| fandisk_counts[k as usize] + plate_counts[k as usize];
    assert!(
        cause(VertexKind::Feature) > 0 && cause(VertexKind::Corner) > 0,
        "fandisk {fandisk_counts:?}, plate-turning10 {plate_counts:?}"
    );
}

/// The surface passes' boundary sweep (`surface.sweep`): a boundary vertex that slides along
/// the input's boundary also tries evenly spaced places between its neighbours. On a plate
/// with a boundary-layer metric it opens the smallest angles, which sit at the boundary,
/// and the boundary stays on the input's curve and resampled to the metric (measured: θ_min
/// 27.2° → 34.1°).
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn the_boundary_sweep_opens_the_smallest_angles_and_keeps_the_boundary_on_target() {
    let case = ANALYTIC
        .iter()
        .find(|c| c.name == "plate-blayer")
        .expect("the suite has plate-blayer");
    let mesh = case.mesh().expect("generated");
    let metric = case.metric(&mesh);
    let remesh = |sweep: bool| {
        let mut stages = Stages::for_sizes(conemesh::registry::MetricSizes::Absolute);
        let params = conemesh::registry::Params::parse(&[format!("sweep={sweep}").as_str()])
            .expect("parses");
        let i = stages
            .improvers
            .iter()
            .position(|s| s.name() == "surface")
            .expect("the surface passes run by default");
        stages.improvers[i] = conemesh::improve::improver("surface", params).expect("builds");
        let options = RemeshOptions {
            target: TargetLength::Absolute(1.0),
            ..RemeshOptions::default()
        };
        Remesher::new(options)
            .with_stages(stages)
            .run_with(&mesh, Some(&metric), |_| {})
            .unwrap_or_else(|e| panic!("remesh: {e}"))
    };
    let (without, with) = (remesh(false), remesh(true));
    let after = |r: &Remeshed| {
        r.unit
            .report
            .improvement
            .as_ref()
            .expect("the improvers ran")
            .after
    };
    let (a, b) = (after(&without), after(&with));
    assert!(
        b.theta_min > a.theta_min + 2.0,
        "θ_min {} → {}",
        a.theta_min,
        b.theta_min
    );
    assert!(
        b.q_avg >= a.q_avg - 0.001,
        "q_avg {} → {}",
        a.q_avg,
        b.q_avg
    );
    let topo = Topology::build(&with.unit.mesh);
    conemesh::invariants::certify_boundary_on_curves(
        &with.unit.curves,
        &with.input,
        &with.mesh,
        &topo,
        &with.unit.curve,
    )
    .expect("the boundary on the input's curve");
    // The boundary's pieces stay resampled to the metric: their metric lengths, over their
    // mean, within [0.6, 1.45] but for a few.
    let off_target = |r: &Remeshed| {
        let m = &r.unit.mesh;
        let t = Topology::build(m);
        let lengths: Vec<f64> = t
            .boundary_loops()
            .iter()
            .flat_map(|l| (0..l.len()).map(move |i| (l[i], l[(i + 1) % l.len()])))
            .map(|(u, v)| {
                let (a, b) = (m.positions[u.idx()], m.positions[v.idx()]);
                let tensor = r.field.eval(&Point3::from((a.coords + b.coords) / 2.0));
                let d = b - a;
                d.dot(&(tensor * d)).max(0.0).sqrt()
            })
            .collect();
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        let off = lengths
            .iter()
            .filter(|l| !(0.6..=1.45).contains(&(**l / mean)))
            .count();
        off as f64 / lengths.len() as f64
    };
    let (off_without, off_with) = (off_target(&without), off_target(&with));
    assert!(
        off_with <= off_without.max(0.05),
        "{off_without} → {off_with}"
    );
}
