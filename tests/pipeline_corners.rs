//! Corner vertices (`RemeshOptions::corner_defect`, `patches::corner_vertices`, paper-notes
//! "Corners"): input vertices with a large angle defect stay vertices of the output, no
//! patch may contain one in its interior (a strategy that breaks this is stopped by name),
//! and a bad threshold is refused.

use conemesh::ids::{FaceId, VertexId};
use conemesh::metric::{MetricField, MetricOptions, Normalization};
use conemesh::patches::{Patch, PatchContext, PatchError, PatchStrategy};
use conemesh::pipeline::{remesh, PipelineError, RemeshOptions, Stages};
use conemesh::quality::approximation_error;
use conemesh::{mesh::generators, TriMesh};
use rand::SeedableRng;

mod common;

/// A unit-diagonal icosphere with vertex 0 pulled out into a spike (angle defect ≈ 4 rad).
fn spiky_sphere() -> TriMesh {
    let mut m = generators::icosphere(1.0, 3);
    m.positions[0] *= 1.8;
    Normalization::of(&m).apply(&m)
}

fn field(m: &TriMesh) -> MetricField {
    MetricField::from_curvature(m.clone(), &MetricOptions::default()).expect("metric")
}

fn has_vertex_at(m: &TriMesh, p: &nalgebra::Point3<f64>) -> bool {
    let used: std::collections::HashSet<usize> =
        m.triangles.iter().flatten().map(|v| v.idx()).collect();
    used.iter().any(|&v| m.positions[v] == *p)
}

#[test]
fn the_spike_is_a_corner_and_stays_in_the_output() {
    let m = spiky_sphere();
    let topo = conemesh::Topology::build(&m);
    let corners = conemesh::patches::corner_vertices(&m, &topo, 1.0);
    assert!(corners[0], "the spike's defect is large");
    // The spike and its 1-ring, where the spike's flank meets the sphere in a saddle.
    let mut expected = vec![false; m.n_vertices()];
    expected[0] = true;
    for v in topo.vertex_neighbors(VertexId(0)) {
        expected[v.idx()] = true;
    }
    assert_eq!(corners, expected);
    let f = field(&m);
    let on = remesh(&f, &Stages::default(), &RemeshOptions::default(), |_| {}).expect("run");
    assert_eq!(on.report.corners, 6);
    assert!(
        has_vertex_at(&on.mesh, &m.positions[0]),
        "the spike's tip is an output vertex"
    );
    // The corners are certified by the run itself: `report.corners` counts vertices the
    // pipeline checked to be in the output at their input positions.
    assert!(on.report.certificate.disk >= on.report.patches);
}

#[test]
fn a_bad_corner_threshold_is_refused() {
    let m = spiky_sphere();
    let f = field(&m);
    for bad in [f64::NAN, -1.0, 0.0] {
        let opts = RemeshOptions {
            corner_defect: Some(bad),
            ..RemeshOptions::default()
        };
        match remesh(&f, &Stages::default(), &opts, |_| {}) {
            Err(PipelineError::Option(conemesh::option_error::OptionError::OutOfRange {
                option,
                ..
            })) => assert_eq!(option, "corner angle defect"),
            other => panic!(
                "{bad}: expected an input error, got {:?}",
                other.map(|_| ())
            ),
        }
    }
}

/// A strategy that ignores the corners: its first patch is the whole 1-ring of vertex 0.
struct OneRingOfSpike;

impl PatchStrategy for OneRingOfSpike {
    fn name(&self) -> &'static str {
        "one-ring"
    }
    fn next_patch(
        &self,
        ctx: &PatchContext<'_>,
        _rng: &mut conemesh::Rng,
    ) -> Result<Option<Patch>, PatchError> {
        let mut faces: Vec<FaceId> = ctx.topology.vertex_faces(VertexId(0)).to_vec();
        faces.sort_unstable();
        let boundary = conemesh::invariants::certify_disk(ctx.mesh, &faces)?;
        Ok(Some(Patch {
            seed_face: faces[0],
            faces,
            boundary,
            seed_vertex: VertexId(0),
            cone: None,
            max_growth_cost: None,
        }))
    }
}

#[test]
fn a_strategy_that_swallows_a_corner_is_stopped_by_name() {
    let m = spiky_sphere();
    let f = field(&m);
    let stages = Stages {
        patches: Box::new(OneRingOfSpike),
        ..Stages::default()
    };
    match remesh(&f, &stages, &RemeshOptions::default(), |_| {}) {
        Err(e @ PipelineError::CornerInterior { vertex, .. }) => {
            assert_eq!(vertex, VertexId(0));
            assert!(e.to_string().contains("v0"), "{e}");
        }
        other => panic!("expected CornerInterior, got {:?}", other.map(|_| ())),
    }
}

/// decimated-knight: its spikes are single vertices with defects of 3-4 rad; keeping them
/// roughly halves the Hausdorff distance, and every corner is an output vertex.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn knight_spikes_are_kept() {
    let mesh = common::load("decimated-knight.off");
    let unit = Normalization::of(&mesh).apply(&mesh);
    let f = field(&unit);
    let topo = conemesh::Topology::build(&unit);
    let corners = conemesh::patches::corner_vertices(&unit, &topo, 1.0);
    let on = remesh(&f, &Stages::default(), &RemeshOptions::default(), |_| {}).expect("run");
    assert_eq!(on.report.corners, corners.iter().filter(|c| **c).count());
    assert!(on.report.corners > 20);
    for (v, _) in corners.iter().enumerate().filter(|(_, c)| **c) {
        assert!(has_vertex_at(&on.mesh, &unit.positions[v]), "corner v{v}");
    }
    let off_opts = RemeshOptions {
        corner_defect: None,
        ..RemeshOptions::default()
    };
    let off = remesh(&f, &Stages::default(), &off_opts, |_| {}).expect("run");
    let mut rng = conemesh::Rng::seed_from_u64(1);
    let d_on = approximation_error(&unit, &on.mesh, 100_000, &mut rng).hausdorff_rel;
    let d_off = approximation_error(&unit, &off.mesh, 100_000, &mut rng).hausdorff_rel;
    assert!(d_on < 0.8 * d_off, "with corners {d_on}, without {d_off}");
}
