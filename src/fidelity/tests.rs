//! Unit tests of the fidelity control.

use super::*;
use crate::ids::VertexId;
use crate::mesh::{generators, Topology, TriMesh};
use crate::metric::{MetricField, MetricOptions, Normalization};

/// A flat disk of radius 0.5 in z = 0 with its centre vertex raised to `height`: a tent
/// whose apex a coarse remesh would cut off.
fn tent(height: f64) -> TriMesh {
    let mut m = generators::disk(0.5, 8, 24);
    let c = (0..m.n_vertices())
        .min_by(|&a, &b| {
            m.positions[a]
                .coords
                .norm()
                .total_cmp(&m.positions[b].coords.norm())
        })
        .expect("vertices");
    m.positions[c].z = height;
    m
}

fn field(m: &TriMesh) -> MetricField {
    MetricField::from_curvature(Normalization::of(m).apply(m), &MetricOptions::default())
        .expect("metric")
}

#[test]
fn smooth_sphere_needs_no_scaling_unless_the_target_is_too_coarse() {
    let sphere = generators::icosphere(1.0, 4);
    let m = Normalization::of(&sphere).apply(&sphere);
    let f = field(&m);
    let topo = Topology::build(&m);
    // Unit space: r = 1/(2√3) (the bbox diagonal of the unit sphere is 2√3), k = 1/r.
    // Over the ball of radius ℓ = L/√k (< 0.05, the cap) the sphere rises k ℓ²/2 = L²/2
    // above a tangent plane: with L = 0.09 that is 0.00405, below 4·eps for eps = 0.002
    // and above it for eps = 0.0008.
    let fine = a_priori_scale(&m, &topo, f.vertex_metrics(), 0.09, 0.002, 1e-6);
    assert!(fine.iter().all(|&s| s == 1.0));
    let coarse = a_priori_scale(&m, &topo, f.vertex_metrics(), 0.09, 0.0008, 1e-6);
    assert!(coarse.iter().all(|&s| s > 1.0));
}

#[test]
fn a_tent_apex_is_refined_and_the_far_plane_is_not() {
    let m = Normalization::of(&tent(0.3)).apply(&tent(0.3));
    let f = field(&m);
    let topo = Topology::build(&m);
    let s = a_priori_scale(&m, &topo, f.vertex_metrics(), 0.3, 0.005, 1e-6);
    let apex = (0..m.n_vertices())
        .max_by(|&a, &b| m.positions[a].z.total_cmp(&m.positions[b].z))
        .expect("vertices");
    assert!(s[apex] > 4.0, "apex factor {}", s[apex]);
    // Vertices on the outer ring lie in the plane far from the apex.
    let far: Vec<usize> = (0..m.n_vertices())
        .filter(|&v| (m.positions[v] - m.positions[apex]).xy().norm() > 0.3)
        .collect();
    assert!(!far.is_empty());
    assert!(far.iter().all(|&v| s[v] < s[apex]));
    // Gradation: neighbours differ by at most 1.2² (Jacobi passes may stop early only
    // when nothing changes).
    for t in &m.triangles {
        for a in t {
            for b in t {
                assert!(s[a.idx()] <= s[b.idx()] * 1.44 + 1e-12);
            }
        }
    }
}

#[test]
fn deviations_see_a_cut_off_apex_and_nothing_on_the_reference_itself() {
    // Apex height (unit space 0.035) below the spoke length (0.044): the cut-off apex is
    // closer to the patch than the patch's longest edge, so it counts.
    let reference = tent(0.05);
    let f = field(&reference);
    let unit = f.reference().clone();
    let normals = unit.area_weighted_normals();
    let boundary: std::collections::HashSet<VertexId> = Topology::build(&unit)
        .boundary_loops()
        .iter()
        .flatten()
        .copied()
        .collect();
    let fixed: Vec<bool> = (0..unit.n_vertices())
        .map(|v| boundary.contains(&VertexId::new(v)))
        .collect();
    let tris: Vec<[u32; 3]> = unit.index_triangles();
    let same = deviations(
        &f,
        &normals,
        &LiftedPatch {
            positions: &unit.positions,
            fixed: &fixed,
            triangles: &tris,
        },
        1e-9,
    );
    assert!(same.is_empty(), "{same:?}");
    // The same connectivity with the apex pushed down into the plane: the apex is cut off
    // by the full tent height (in unit space).
    let mut cut = unit.positions.clone();
    let apex = (0..cut.len())
        .max_by(|&a, &b| cut[a].z.total_cmp(&cut[b].z))
        .expect("vertices");
    let h = cut[apex].z - cut[(apex + 1) % cut.len()].z;
    cut[apex].z -= h;
    let dev = deviations(
        &f,
        &normals,
        &LiftedPatch {
            positions: &cut,
            fixed: &fixed,
            triangles: &tris,
        },
        0.01,
    );
    assert!(!dev.is_empty());
    let worst = dev.iter().map(|d| d.1).fold(0.0, f64::max);
    assert!(
        (worst - h).abs() < 1e-9 * h.max(1.0) || worst <= h,
        "worst {worst}, h {h}"
    );
    assert!(worst > 0.5 * h, "worst {worst}, h {h}");
    // Every deviating triangle touches the apex's neighbourhood.
    for (t, _) in &dev {
        let near = tris[*t]
            .iter()
            .any(|&v| (cut[v as usize] - cut[apex]).xy().norm() < 0.2);
        assert!(near, "triangle {t} far from the apex");
    }
}

#[test]
fn patch_vertices_take_the_factor_of_the_reference_vertex_beneath() {
    let reference = tent(0.0); // flat
    let f = field(&reference);
    let unit = f.reference().clone();
    let mut scale = vec![1.0; unit.n_vertices()];
    let hot = 5;
    scale[hot] = 9.0;
    let out = patch_vertex_factors(&f, &scale, &unit);
    // On the reference itself the hot vertex projects onto one of its own faces.
    assert_eq!(out[hot], 9.0);
    let touched = out.iter().filter(|&&s| s == 9.0).count();
    assert!((1..=3).contains(&touched) || touched == 3, "{touched}");
    assert!(out.iter().all(|&s| s == 1.0 || s == 9.0));
}
