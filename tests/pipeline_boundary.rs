//! Boundaries are curves to keep, not vertices (the metric-conformity issue): the output's
//! boundary vertices lie exactly on the input's boundary polyline, resampled to the metric,
//! corners kept, loops kept; `--keep-boundary` keeps the input's boundary bit for bit.

use conemesh::boundary::BoundaryOptions;
use conemesh::invariants::{
    certify_boundary_on_curves, certify_boundary_preserved, certify_same_topology,
};
use conemesh::mesh::{generators, Topology, TriMesh};
use conemesh::pipeline::{RemeshOptions, Remesher, TargetLength};
use nalgebra::Matrix3;

/// The unit square plate, `n × n` grid cells.
fn plate(n: usize) -> TriMesh {
    generators::plate(1.0, n)
}

/// Sizes `hx` along x and `hy` along y, SPD in 3D (the normal size the smaller), as a user's
/// `.sol` would give them.
fn constant(mesh: &TriMesh, hx: f64, hy: f64) -> Vec<Matrix3<f64>> {
    let hn = hx.min(hy);
    let m = Matrix3::from_diagonal(&nalgebra::Vector3::new(
        1.0 / (hx * hx),
        1.0 / (hy * hy),
        1.0 / (hn * hn),
    ));
    vec![m; mesh.n_vertices()]
}

fn run(
    mesh: &TriMesh,
    metric: &[Matrix3<f64>],
    boundary: BoundaryOptions,
) -> conemesh::pipeline::Remeshed {
    Remesher::new(RemeshOptions {
        target: TargetLength::Absolute(1.0),
        boundary,
        ..RemeshOptions::default()
    })
    .run_with_metric(mesh, metric)
    .expect("remeshes, every certificate held")
}

/// The metric lengths of the output's boundary edges.
fn boundary_lengths(out: &TriMesh, metric: &Matrix3<f64>) -> Vec<f64> {
    let t = Topology::build(out);
    t.boundary_loops()
        .iter()
        .flat_map(|l| (0..l.len()).map(move |i| (l[i], l[(i + 1) % l.len()])))
        .map(|(a, b)| {
            let d = out.positions[b.idx()] - out.positions[a.idx()];
            d.dot(&(metric * d)).sqrt()
        })
        .collect()
}

/// 100:1 on a 20 × 20 plate: the input's boundary edges are 0.05 long, 10 L_tar along x and
/// 0.1 L_tar along y. The output's boundary has edges of about L_tar, lies on the input's
/// boundary, and keeps the four corners.
#[test]
fn a_plate_boundary_is_resampled_to_a_strongly_anisotropic_metric() {
    let input = plate(20);
    let metric = constant(&input, 0.005, 0.5);
    let out = run(&input, &metric, BoundaryOptions::default());
    let m = &out.mesh;
    let topo = Topology::build(m);
    certify_same_topology(&input, m).expect("a disk");
    certify_boundary_on_curves(&out.unit.curves, &out.input, m, &topo, &out.unit.curve)
        .expect("on the input's boundary, in file units");
    // Exactly on the unit square's sides.
    for l in topo.boundary_loops() {
        for v in l {
            let p = m.positions[v.idx()];
            let on = p.x == 0.0 || p.x == 1.0 || p.y == 0.0 || p.y == 1.0;
            assert!(on && p.z == 0.0, "{v} at {p} is off the plate's boundary");
        }
    }
    for c in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        assert!(
            m.positions.iter().any(|p| p.x == c.0 && p.y == c.1),
            "corner {c:?} kept"
        );
    }
    let lengths = boundary_lengths(m, &metric[0]);
    let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
    let in_range =
        lengths.iter().filter(|l| (0.7..=1.42).contains(*l)).count() as f64 / lengths.len() as f64;
    assert!(
        (0.9..1.1).contains(&mean),
        "boundary edges {mean} L_tar on average"
    );
    assert!(in_range > 0.95, "{in_range}");
    // About 1/0.005 = 200 pieces on each side along x, 2 along y.
    assert!(
        (390..430).contains(&lengths.len()),
        "{} boundary edges",
        lengths.len()
    );
    let r = &out.unit.report;
    assert!(r.certificate.chains > 0);
    assert!(r.boundary_distance.input_to_output < 1e-12);
}

/// A disk with a hole (an annulus) in an isotropic metric coarser than the input: both
/// circles are resampled (no corners), the loops stay, and the chords stay within the
/// tolerance of the input circles.
#[test]
fn curved_boundaries_are_coarsened_within_the_tolerance() {
    // The annulus: a disk's outer rings.
    let disk = generators::disk(1.0, 8, 12);
    let keep: Vec<[usize; 3]> = disk
        .triangles
        .iter()
        .filter(|t| {
            t.iter()
                .all(|v| disk.positions[v.idx()].coords.norm() > 0.3)
        })
        .map(|t| t.map(|v| v.idx()))
        .collect();
    let annulus = TriMesh::from_indices(disk.positions.clone(), &keep)
        .expect("annulus")
        .without_unreferenced_vertices()
        .0;
    assert_eq!(Topology::build(&annulus).boundary_loops().len(), 2);
    let metric = constant(&annulus, 0.2, 0.2);
    let out = run(&annulus, &metric, BoundaryOptions::default());
    let topo = Topology::build(&out.mesh);
    assert_eq!(topo.boundary_loops().len(), 2);
    certify_boundary_on_curves(
        &out.unit.curves,
        &out.input,
        &out.mesh,
        &topo,
        &out.unit.curve,
    )
    .expect("on the input's circles");
    let input_boundary = Topology::build(&annulus)
        .boundary_loops()
        .iter()
        .map(Vec::len)
        .sum::<usize>();
    let output_boundary = topo.boundary_loops().iter().map(Vec::len).sum::<usize>();
    assert!(
        output_boundary < input_boundary,
        "coarsened: {output_boundary} boundary vertices for {input_boundary}"
    );
    // The chords stay within the default tolerance of the input circles (unit space: 0.0035
    // of the diagonal; the curve distance samples the edges, so allow 1 %).
    let d = out.unit.report.boundary_distance;
    assert!(
        d.input_to_output > 0.0,
        "coarsened chords cut the circles a little"
    );
    assert!(d.input_to_output <= 0.0035 * 1.01, "{d:?}");
    assert!(d.output_to_input <= 0.0035 * 1.01, "{d:?}");
}

/// `--keep-boundary`: the input's boundary vertices and edges, bit for bit.
#[test]
fn keep_boundary_keeps_the_input_boundary() {
    let input = plate(12);
    let metric = constant(&input, 0.02, 0.2);
    let out = run(
        &input,
        &metric,
        BoundaryOptions {
            resample: false,
            ..BoundaryOptions::default()
        },
    );
    certify_boundary_preserved(&input, &out.mesh).expect("kept bit for bit");
    assert_eq!(out.unit.report.certificate.chains, 0);
}
