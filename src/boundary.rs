//! Boundary curves (ours; the paper keeps patch boundaries fixed and says nothing of the
//! input's boundary): the input's boundary loops as polylines that the output's boundary
//! must lie on.
//!
//! The output's boundary vertices are not the input's: each lies *on* the input's boundary
//! polyline, located exactly as a [`CurvePoint`] (loop, edge, parameter `t`), and its position
//! is that point ([`BoundaryCurves::position`], recomputed bit for bit by the certificate).
//! Corners of a loop stay where they are: vertices where the curve turns by more than
//! [`BoundaryOptions::corner_angle`] in 3D, or where the surface's angle sum differs from π by
//! at least the corner defect (the boundary form of the interior corner rule). Between
//! corners the pipeline resamples the curve to the metric length L_tar (`pipeline/chains.rs`).

use crate::ids::{FaceId, VertexId};
use crate::mesh::{SurfaceLocation, Topology, TriMesh};
use nalgebra::Point3;
use serde::Serialize;

/// How the boundary is treated.
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct BoundaryOptions {
    /// Resample the boundary to the metric (true, default) or keep the input's boundary
    /// vertices and edges bit for bit (false, the earlier behaviour).
    pub resample: bool,
    /// A boundary vertex where the curve turns by at least this many degrees (the angle
    /// between its two boundary edges' directions) is a corner and stays. Default 45°
    /// (MMG's ridge angle).
    pub corner_angle: f64,
}

impl Default for BoundaryOptions {
    fn default() -> Self {
        BoundaryOptions {
            resample: true,
            corner_angle: 45.0,
        }
    }
}

/// A point on a boundary curve: loop `curve`, on its edge `edge` (from vertex `edge` of the
/// loop to the next), at parameter `t ∈ [0, 1)` (`t = 0`: the loop's vertex itself).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Which boundary loop of the input.
    pub curve: u32,
    /// Which edge of the loop.
    pub edge: u32,
    /// Where on the edge.
    pub t: f64,
}

impl CurvePoint {
    /// Strict order along a loop (edge, then `t`): exact, no arc lengths involved.
    pub fn precedes(&self, other: &CurvePoint) -> bool {
        (self.edge, self.t) < (other.edge, other.t)
    }
}

/// The boundary loops of the reference mesh as polylines (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct BoundaryCurves {
    /// The loops (reference vertex ids, surface on the left, as [`Topology::boundary_loops`]).
    loops: Vec<Vec<VertexId>>,
    /// Arc length at each loop vertex; one more entry at the end: the loop's length.
    arc: Vec<Vec<f64>>,
    /// Per loop edge: the reference face on it and the index in that face of the edge's start.
    faces: Vec<Vec<(FaceId, usize)>>,
    /// Per reference vertex: its loop and index there.
    on: Vec<Option<(u32, u32)>>,
    /// Per reference vertex: a corner of its loop.
    corner: Vec<bool>,
}

impl BoundaryCurves {
    /// The boundary curves of `reference` (whose topology is `topo`): corners where the 3D
    /// turning angle is at least `corner_angle` degrees or, with `corner_defect`, where
    /// `|π − Σθ| ≥ corner_defect` radians.
    pub fn new(
        reference: &TriMesh,
        topo: &Topology,
        corner_angle: f64,
        corner_defect: Option<f64>,
    ) -> BoundaryCurves {
        let n = reference.n_vertices();
        let mut c = BoundaryCurves {
            on: vec![None; n],
            corner: vec![false; n],
            ..BoundaryCurves::default()
        };
        let sums = reference.angle_sums();
        let cos_max = corner_angle.to_radians().cos();
        let p = |v: VertexId| reference.positions[v.idx()];
        for (l, lp) in topo.boundary_loops().iter().enumerate() {
            let m = lp.len();
            let mut arc = Vec::with_capacity(m + 1);
            let mut faces = Vec::with_capacity(m);
            let mut s = 0.0;
            for i in 0..m {
                let (a, b) = (lp[i], lp[(i + 1) % m]);
                arc.push(s);
                s += (p(b) - p(a)).norm();
                faces.push(boundary_face(reference, topo, a, b));
                c.on[a.idx()] = Some((l as u32, i as u32));
                let prev = lp[(i + m - 1) % m];
                let (d0, d1) = (p(a) - p(prev), p(b) - p(a));
                let turn = d0.dot(&d1) < cos_max * d0.norm() * d1.norm();
                let defect = corner_defect
                    .is_some_and(|d| (std::f64::consts::PI - sums[a.idx()]).abs() >= d);
                c.corner[a.idx()] = turn || defect;
            }
            arc.push(s);
            c.loops.push(lp.clone());
            c.arc.push(arc);
            c.faces.push(faces);
        }
        c
    }

    /// Number of loops.
    pub fn len(&self) -> usize {
        self.loops.len()
    }

    /// True when the reference has no boundary.
    pub fn is_empty(&self) -> bool {
        self.loops.is_empty()
    }

    /// The vertices of loop `l`.
    pub fn curve(&self, l: usize) -> &[VertexId] {
        &self.loops[l]
    }

    /// The length of loop `l`.
    pub fn length(&self, l: usize) -> f64 {
        *self.arc[l].last().unwrap_or(&0.0)
    }

    /// The corner vertices (reference ids), in loop order.
    pub fn corners(&self) -> impl Iterator<Item = VertexId> + '_ {
        self.loops
            .iter()
            .flatten()
            .copied()
            .filter(|v| self.corner[v.idx()])
    }

    /// True when reference vertex `v` is a corner of its loop.
    pub fn is_corner(&self, v: VertexId) -> bool {
        self.corner.get(v.idx()).copied().unwrap_or(false)
    }

    /// Reference vertex `v` as a point of its loop, if it is on one.
    pub fn point_at_vertex(&self, v: VertexId) -> Option<CurvePoint> {
        let (l, i) = self.on.get(v.idx()).copied().flatten()?;
        Some(CurvePoint {
            curve: l,
            edge: i,
            t: 0.0,
        })
    }

    /// True when `p` is a corner vertex of its loop.
    pub fn is_corner_point(&self, p: &CurvePoint) -> bool {
        p.t == 0.0 && self.is_corner(self.loops[p.curve as usize][p.edge as usize])
    }

    /// The endpoints of the edge `p` lies on.
    fn edge_ends(&self, p: &CurvePoint) -> (VertexId, VertexId) {
        let lp = &self.loops[p.curve as usize];
        let i = p.edge as usize;
        (lp[i], lp[(i + 1) % lp.len()])
    }

    /// The position of `p`: `a + (b − a)·t` on its edge `ab` (exactly `a` at `t = 0`). The
    /// certificate recomputes it, so the output's boundary vertices are on the curve by a
    /// bit-for-bit check, not a tolerance.
    pub fn position(&self, reference: &TriMesh, p: &CurvePoint) -> Point3<f64> {
        let (a, b) = self.edge_ends(p);
        let (pa, pb) = (reference.positions[a.idx()], reference.positions[b.idx()]);
        if p.t == 0.0 {
            pa
        } else {
            pa + (pb - pa) * p.t
        }
    }

    /// `p` as a point of the reference surface (on the face of its edge).
    pub fn location(&self, p: &CurvePoint) -> SurfaceLocation {
        let (face, k) = self.faces[p.curve as usize][p.edge as usize];
        let mut bary = [0.0; 3];
        bary[k] = 1.0 - p.t;
        bary[(k + 1) % 3] = p.t;
        SurfaceLocation { face, bary }
    }

    /// The arc length of `p` along its loop from the loop's first vertex.
    pub fn arc(&self, p: &CurvePoint) -> f64 {
        let a = &self.arc[p.curve as usize];
        let i = p.edge as usize;
        a[i] + (a[i + 1] - a[i]) * p.t
    }

    /// The vertices of loop `l` whose arc length lies strictly between `a` and `b` (`a ≤ b`,
    /// both possibly beyond the loop's length: taken around the loop).
    pub fn vertices_between(
        &self,
        l: usize,
        a: f64,
        b: f64,
    ) -> impl Iterator<Item = VertexId> + '_ {
        let arc = &self.arc[l];
        let lp = &self.loops[l];
        let total = *arc.last().unwrap_or(&0.0);
        let m = lp.len();
        // Whole turns of the loop the interval may cover, each vertex at arc[i] + k·total.
        let turns = if total > 0.0 {
            (b / total).floor() as i64 + 1
        } else {
            0
        };
        let first = if total > 0.0 {
            (a / total).floor() as i64
        } else {
            0
        };
        (first..turns.max(first))
            .flat_map(move |k| (0..m).map(move |i| (k, i)))
            .filter(move |&(k, i)| {
                let s = arc[i] + k as f64 * total;
                s > a && s < b
            })
            .map(move |(_, i)| lp[i])
    }

    /// The point of loop `l` at arc length `s` (taken modulo the loop's length).
    pub fn at_arc(&self, l: usize, s: f64) -> CurvePoint {
        let a = &self.arc[l];
        let total = *a.last().unwrap_or(&0.0);
        let m = self.loops[l].len();
        let s = if total > 0.0 {
            s.rem_euclid(total)
        } else {
            0.0
        };
        // The last edge whose start is at or before s.
        let i = a[..m].partition_point(|&x| x <= s).saturating_sub(1);
        let len = a[i + 1] - a[i];
        let t = if len > 0.0 { (s - a[i]) / len } else { 0.0 };
        let (edge, t) = if t >= 1.0 {
            ((i + 1) % m, 0.0)
        } else {
            (i, t.max(0.0))
        };
        CurvePoint {
            curve: l as u32,
            edge: edge as u32,
            t,
        }
    }
}

/// The face of the boundary half-edge `a → b` and the index of `a` in it.
fn boundary_face(
    reference: &TriMesh,
    topo: &Topology,
    a: VertexId,
    b: VertexId,
) -> (FaceId, usize) {
    topo.vertex_faces(a)
        .iter()
        .find_map(|&f| {
            let t = reference.face(f);
            (0..3)
                .find(|&k| t[k] == a && t[(k + 1) % 3] == b)
                .map(|k| (f, k))
        })
        .unwrap_or((FaceId(0), 0))
}

/// One-sided distances between the input's boundary curves and the output's boundary
/// polylines (unit space): the largest distance of a sample of the input curve to the
/// output's boundary, and of a sample of the output's boundary to the input curve.
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize)]
pub struct CurveDistance {
    /// max over the input curve of the distance to the output boundary.
    pub input_to_output: f64,
    /// max over the output boundary of the distance to the input curve.
    pub output_to_input: f64,
}

/// [`CurveDistance`] between the boundary edges of two meshes, by sampling each edge at 8
/// points and measuring to the nearest edge of the other side (brute force over edges
/// within a grid cell; boundaries are short).
pub fn curve_distance(
    input: &TriMesh,
    input_topo: &Topology,
    output: &TriMesh,
    output_topo: &Topology,
) -> CurveDistance {
    let segs = |m: &TriMesh, t: &Topology| -> Vec<(Point3<f64>, Point3<f64>)> {
        t.boundary_loops()
            .iter()
            .flat_map(|l| (0..l.len()).map(move |i| (l[i], l[(i + 1) % l.len()])))
            .map(|(a, b)| (m.positions[a.idx()], m.positions[b.idx()]))
            .collect()
    };
    let (si, so) = (segs(input, input_topo), segs(output, output_topo));
    CurveDistance {
        input_to_output: one_side(&si, &so),
        output_to_input: one_side(&so, &si),
    }
}

/// Distance from `p` to the segment `[a, b]` (to `a` when the segment is a point).
pub(crate) fn point_segment_distance(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    let e = b - a;
    let l2 = e.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&e) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + e * t)).norm()
}

fn one_side(from: &[(Point3<f64>, Point3<f64>)], to: &[(Point3<f64>, Point3<f64>)]) -> f64 {
    use rayon::prelude::*;
    if from.is_empty() || to.is_empty() {
        return 0.0;
    }
    from.par_iter()
        .map(|(a, b)| {
            (0..=8)
                .map(|k| {
                    let p = a + (b - a) * (k as f64 / 8.0);
                    to.iter()
                        .map(|(c, d)| point_segment_distance(&p, c, d))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    /// A flat square plate, 4×4 quads of the unit square.
    fn plate() -> TriMesh {
        generators::plate(1.0, 4)
    }

    #[test]
    fn a_plate_has_one_loop_with_four_corners() {
        let m = plate();
        let topo = Topology::build(&m);
        let c = BoundaryCurves::new(&m, &topo, 45.0, Some(1.0));
        assert_eq!(c.len(), 1);
        assert_eq!(c.curve(0).len(), 16);
        assert!((c.length(0) - 4.0).abs() < 1e-12);
        let corners: Vec<Point3<f64>> = c.corners().map(|v| m.positions[v.idx()]).collect();
        assert_eq!(corners.len(), 4, "{corners:?}");
        // With only the angle sum rule the same four (Σθ = 90° there, 180° elsewhere).
        let d = BoundaryCurves::new(&m, &topo, 179.0, Some(1.0));
        assert_eq!(d.corners().count(), 4);
        let none = BoundaryCurves::new(&m, &topo, 179.0, None);
        assert_eq!(none.corners().count(), 0);
    }

    #[test]
    fn points_round_trip_through_arc_length_and_lie_on_their_edge() {
        let m = plate();
        let topo = Topology::build(&m);
        let c = BoundaryCurves::new(&m, &topo, 45.0, None);
        for k in 0..40 {
            let s = k as f64 * 0.1 + 0.013;
            let p = c.at_arc(0, s);
            assert!(p.t >= 0.0 && p.t < 1.0);
            assert!((c.arc(&p) - s.rem_euclid(4.0)).abs() < 1e-12, "{s} → {p:?}");
            let x = c.position(&m, &p);
            let loc = c.location(&p);
            assert!((loc.position(&m) - x).norm() < 1e-15);
            // On the unit square's boundary.
            let on = [x.x, x.y].iter().any(|v| *v == 0.0 || *v == 1.0);
            assert!(on && x.z == 0.0, "{x}");
        }
        // Vertices are exactly their points.
        for &v in c.curve(0) {
            let p = c.point_at_vertex(v).expect("on the loop");
            assert_eq!(c.position(&m, &p), m.positions[v.idx()]);
        }
        // A closed surface has no curves.
        let s = generators::icosphere(1.0, 1);
        assert!(BoundaryCurves::new(&s, &Topology::build(&s), 45.0, None).is_empty());
    }

    #[test]
    fn curve_distance_sees_a_cut_corner() {
        let m = plate();
        let topo = Topology::build(&m);
        assert_eq!(
            curve_distance(&m, &topo, &m, &topo),
            CurveDistance::default()
        );
        // Move the corner (0,0) in along the diagonal: the input corner is 0.1·√2 away.
        let mut cut = m.clone();
        cut.positions[0] = Point3::new(0.1, 0.1, 0.0);
        let d = curve_distance(&m, &topo, &cut, &Topology::build(&cut));
        assert!(
            d.input_to_output > 0.05 && d.output_to_input > 0.05,
            "{d:?}"
        );
    }
}
