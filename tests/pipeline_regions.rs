//! Region-parallel Algorithm 1 (issue 32): a mesh larger than `region_faces` is split into
//! regions that run at the same time with their cuts frozen, then the bands around the cuts
//! are remeshed. The output is certified like any run's, depends on the seed and the region
//! size and never on the thread count, and the faces where the cuts were are as good as the
//! rest.

use conemesh::mesh::{generators, TriMesh};
use conemesh::pipeline::{RemeshOptions, Remeshed, Remesher, TargetLength};
use nalgebra::Matrix3;

fn run_in_pool(
    mesh: &TriMesh,
    metric: Option<&[Matrix3<f64>]>,
    threads: usize,
    region_faces: usize,
) -> Remeshed {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let options = RemeshOptions {
        seed: 4,
        region_faces,
        // A user metric gives the sizes: edges of metric length 1.
        target: match metric {
            Some(_) => TargetLength::Absolute(1.0),
            None => RemeshOptions::default().target,
        },
        ..RemeshOptions::default()
    };
    pool.install(|| Remesher::new(options).run_with(mesh, metric, |_| {}))
        .unwrap_or_else(|e| panic!("remesh with regions of {region_faces} faces: {e}"))
}

/// The faces a run at the defaults makes of `mesh` (one region).
fn expected_output(mesh: &TriMesh) -> usize {
    run_in_pool(mesh, None, 2, 0).unit.report.faces_out
}

fn bits(r: &Remeshed) -> (Vec<u64>, Vec<[u32; 3]>) {
    (
        r.mesh
            .positions
            .iter()
            .flat_map(|p| p.iter().map(|x| x.to_bits()))
            .collect(),
        r.mesh.triangles.iter().map(|t| t.map(|v| v.0)).collect(),
    )
}

/// Several regions really ran, every certificate held (the run returns `Ok` only then, and
/// the report counts them), and 1, 2 and 7 threads give the same bits: on a closed surface, a
/// surface with boundary and genus, a noisy open scan and a CAD part with feature lines.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn regions_give_the_same_bits_for_every_thread_count() {
    let meshes = [
        ("torus", generators::torus(1.0, 0.35, 80, 30)),
        ("genus plate", generators::genus_plate(2, 8)),
        ("noisy scan", generators::noisy_scan(4, 7)),
        ("cube", generators::cube(24)),
    ];
    for (name, mesh) in &meshes {
        // Regions of about a sixth of the output each.
        let region_faces = expected_output(mesh) / 6;
        let one = run_in_pool(mesh, None, 1, region_faces);
        let report = &one.unit.report;
        assert!(
            report.regions.count >= 4,
            "{name}: {} faces in regions of {region_faces} output faces gave {} regions \
             (declined at a cut edge of {:?} L_tar)",
            mesh.n_faces(),
            report.regions.count,
            report.regions.declined_cut_edge
        );
        assert!(report.certificate.manifold > 0 && report.certificate.boundary_preserved > 0);
        let cuts = report.regions.cuts.expect("the band's faces are reported");
        assert!(cuts.seam.faces > 0, "{name}: the band's loop made no face");
        for threads in [2, 7] {
            let other = run_in_pool(mesh, None, threads, region_faces);
            assert!(
                bits(&one) == bits(&other),
                "{name}: 1 and {threads} threads differ"
            );
        }
    }
}

/// With one region (`region_faces` 0, or a mesh no larger than it) the run is the paper's loop
/// on the whole mesh: no band, and the same bits whether the option is 0 or above the size.
#[test]
fn one_region_is_the_loop_on_the_whole_mesh() {
    let mesh = generators::torus(1.0, 0.35, 40, 16);
    let off = run_in_pool(&mesh, None, 2, 0);
    let large = run_in_pool(&mesh, None, 2, mesh.n_faces());
    assert_eq!(off.unit.report.regions.count, 1);
    assert!(off.unit.report.regions.cuts.is_none());
    assert!(bits(&off) == bits(&large));
    let split = run_in_pool(&mesh, None, 2, expected_output(&mesh) / 3);
    assert!(split.unit.report.regions.count > 1);
    assert!(bits(&split) != bits(&off), "regions changed nothing");
}

/// The faces where the cuts were are as good as the rest, and the whole run as good as the
/// one without regions: on the bumpy sphere and on a noisy open scan, in their curvature
/// metrics.
#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn faces_on_former_cuts_are_as_good_as_the_rest() {
    let cases = [
        ("bumpy sphere", generators::bumpy_sphere(4)),
        ("noisy scan", generators::noisy_scan(5, 3)),
    ];
    for (name, mesh) in &cases {
        let whole = run_in_pool(mesh, None, 2, 0);
        let split = run_in_pool(mesh, None, 2, whole.unit.report.faces_out / 4);
        let s = &split.unit.report;
        let cuts = s.regions.cuts.expect("several regions");
        eprintln!(
            "{name}: {} regions; q_avg {:.4} whole, {:.4} regions; cut faces {} q_avg {:.4}, rest {:.4}",
            s.regions.count,
            q_avg(&whole),
            q_avg(&split),
            cuts.seam.faces,
            cuts.seam.q_avg,
            cuts.rest.q_avg
        );
        assert!(s.regions.count > 2, "{name}");
        // The regions' own faces come out better than the paper's loop makes them (smaller
        // patches); the faces on former cuts are as good as the paper's loop, and near the rest.
        assert!(
            cuts.seam.q_avg > cuts.rest.q_avg - 0.015,
            "{name}: faces on former cuts q_avg {:.4}, the rest {:.4}",
            cuts.seam.q_avg,
            cuts.rest.q_avg
        );
        assert!(
            cuts.seam.q_avg > q_avg(&whole) - 0.005,
            "{name}: faces on former cuts q_avg {:.4}, the run without regions {:.4}",
            cuts.seam.q_avg,
            q_avg(&whole)
        );
        assert!(
            q_avg(&split) > q_avg(&whole) - 0.005,
            "{name}: q_avg {:.4} with regions, {:.4} without",
            q_avg(&split),
            q_avg(&whole)
        );
    }
}

/// Where the input is coarser than the output along the cuts (a plate under a user metric of
/// 100 : 1 whose grid edges are twice the target across the fine direction), frozen cuts would
/// keep edges too long for the output: the run keeps one region, says why, and gives the
/// one-region run's bytes.
#[test]
fn a_coarse_anisotropic_input_keeps_one_region() {
    let plate = generators::plate(1.0, 90);
    // Edges of 1/200 across x and 1/20 along y (eigenvalues 100 : 1), the same everywhere.
    let aniso: Vec<Matrix3<f64>> = plate
        .positions
        .iter()
        .map(|_| Matrix3::from_diagonal(&nalgebra::Vector3::new(40000.0, 400.0, 400.0)))
        .collect();
    let whole = run_in_pool(&plate, Some(&aniso), 2, 0);
    let asked = run_in_pool(&plate, Some(&aniso), 2, whole.unit.report.faces_out / 4);
    let r = &asked.unit.report.regions;
    assert_eq!(r.count, 1);
    let declined = r.declined_cut_edge.expect("the regions were declined");
    assert!(declined > conemesh::pipeline::MAX_CUT_EDGE, "{declined}");
    assert!(bits(&whole) == bits(&asked));
}

fn q_avg(r: &Remeshed) -> f64 {
    let s = &r.unit.report.seams;
    let n = (s.seam.faces + s.rest.faces) as f64;
    (s.seam.q_avg * s.seam.faces as f64 + s.rest.q_avg * s.rest.faces as f64) / n
}
