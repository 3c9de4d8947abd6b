//! The boundary certificate: the output's boundary lies on the input's boundary curves
//! ([`crate::boundary`]), each loop once around its curve, every corner kept.

use super::{CurvesDefect, InvariantError, Offenders};
use crate::boundary::{BoundaryCurves, CurvePoint};
use crate::ids::VertexId;
use crate::mesh::{Topology, TriMesh};

fn broken(defect: CurvesDefect) -> InvariantError {
    InvariantError::BoundaryCurves(defect)
}

/// The boundary of `mesh` (topology `topo`) lies on the boundary curves of `reference`, with
/// `points[v]` the curve point of vertex `v`:
/// 1. every boundary vertex has a curve point and sits exactly at it (the position recomputed
///    from (loop, edge, t) equals the vertex's, bit for bit);
/// 2. each boundary loop of `mesh` lies on one curve, a different one for each loop, and
///    there are as many loops as curves;
/// 3. along each loop the points go once around their curve in its direction: rotated to
///    start at the first point, they strictly increase in (edge, t) (an exact comparison);
/// 4. every corner of every curve is a vertex of the loop on it.
///
/// Errors name the offending vertices of `mesh` (or, for a lost corner, of `reference`).
pub fn certify_boundary_on_curves(
    curves: &BoundaryCurves,
    reference: &TriMesh,
    mesh: &TriMesh,
    topo: &Topology,
    points: &[Option<CurvePoint>],
) -> Result<(), InvariantError> {
    let loops = topo.boundary_loops();
    let point = |v: VertexId| points.get(v.idx()).copied().flatten();
    let off: Vec<VertexId> = loops
        .iter()
        .flatten()
        .copied()
        .filter(|&v| match point(v) {
            Some(p) => {
                p.curve as usize >= curves.len()
                    || p.edge as usize >= curves.curve(p.curve as usize).len()
                    || !(p.t >= 0.0 && p.t < 1.0)
                    || curves.position(reference, &p) != mesh.positions[v.idx()]
            }
            None => true,
        })
        .collect();
    if !off.is_empty() {
        return Err(InvariantError::BoundaryOffCurve(Offenders(off)));
    }
    if loops.len() != curves.len() {
        return Err(broken(CurvesDefect::LoopCount {
            loops: loops.len(),
            curves: curves.len(),
        }));
    }
    let mut seen = vec![false; curves.len()];
    let mut lost = Vec::new();
    for l in loops {
        let ps: Vec<CurvePoint> = l.iter().filter_map(|&v| point(v)).collect();
        let c = ps[0].curve;
        if let Some(i) = ps.iter().position(|p| p.curve != c) {
            return Err(broken(CurvesDefect::TwoCurves {
                first: l[0],
                other: l[i],
                curves: (c, ps[i].curve),
            }));
        }
        if std::mem::replace(&mut seen[c as usize], true) {
            return Err(broken(CurvesDefect::SharedCurve {
                curve: c,
                through: l[0],
            }));
        }
        // Once around: exactly one descent in the cyclic sequence (where it passes the
        // curve's first vertex), every other step strictly forward.
        let n = ps.len();
        let descents: Vec<usize> = (0..n)
            .filter(|&i| !ps[i].precedes(&ps[(i + 1) % n]))
            .collect();
        if n < 3 || descents.len() != 1 {
            let at = descents.get(1).or(descents.first()).map_or(l[0], |&i| l[i]);
            return Err(broken(CurvesDefect::NotOnceAround {
                at,
                curve: c,
                backward: descents.len(),
                vertices: n,
            }));
        }
        let on_loop: Vec<(u32, f64)> = ps.iter().map(|p| (p.edge, p.t)).collect();
        for (i, &v) in curves.curve(c as usize).iter().enumerate() {
            if curves.is_corner(v) && !on_loop.contains(&(i as u32, 0.0)) {
                lost.push(v);
            }
        }
    }
    if !lost.is_empty() {
        return Err(InvariantError::BoundaryCornersLost(Offenders(lost)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    fn disk() -> (TriMesh, Topology, BoundaryCurves) {
        let d = generators::disk(1.0, 3, 8);
        let t = Topology::build(&d);
        let c = BoundaryCurves::new(&d, &t, 30.0, None);
        (d, t, c)
    }

    fn points(d: &TriMesh, c: &BoundaryCurves) -> Vec<Option<CurvePoint>> {
        d.vertices().map(|v| c.point_at_vertex(v)).collect()
    }

    #[test]
    fn the_input_itself_passes_and_every_breach_is_named() {
        let (d, t, c) = disk();
        let pts = points(&d, &c);
        certify_boundary_on_curves(&c, &d, &d, &t, &pts).expect("the input");
        let l = t.boundary_loops()[0].clone();
        // A vertex moved off its point.
        let mut moved = d.clone();
        moved.positions[l[2].idx()].x += 1e-12;
        assert_eq!(
            certify_boundary_on_curves(&c, &d, &moved, &t, &pts),
            Err(InvariantError::BoundaryOffCurve(Offenders(vec![l[2]])))
        );
        // A vertex without a point.
        let mut missing = pts.clone();
        missing[l[1].idx()] = None;
        assert!(matches!(
            certify_boundary_on_curves(&c, &d, &d, &t, &missing),
            Err(InvariantError::BoundaryOffCurve(_))
        ));
        // Two vertices' points exchanged (with positions to match): the loop runs backwards
        // there.
        let mut swapped = d.clone();
        let mut sp = pts.clone();
        swapped.positions.swap(l[1].idx(), l[2].idx());
        sp.swap(l[1].idx(), l[2].idx());
        assert!(matches!(
            certify_boundary_on_curves(&c, &d, &swapped, &t, &sp),
            Err(InvariantError::BoundaryCurves(_))
        ));
        // A point moved along the curve (still on it) keeps the certificate.
        let mut slid = d.clone();
        let mut sl = pts.clone();
        let p = CurvePoint {
            t: 0.25,
            ..pts[l[3].idx()].expect("on the curve")
        };
        slid.positions[l[3].idx()] = c.position(&d, &p);
        sl[l[3].idx()] = Some(p);
        certify_boundary_on_curves(&c, &d, &slid, &t, &sl).expect("slid along the curve");
    }

    #[test]
    fn a_corner_that_slides_is_lost() {
        let (d, t, _) = disk();
        // Every rim vertex of the 24-gon turns by 15°: corners at 10°.
        let c = BoundaryCurves::new(&d, &t, 10.0, None);
        assert_eq!(c.corners().count(), 24);
        let pts = points(&d, &c);
        let l = t.boundary_loops()[0].clone();
        let mut slid = d.clone();
        let mut sl = pts.clone();
        let p = CurvePoint {
            t: 0.5,
            ..pts[l[0].idx()].expect("on the curve")
        };
        slid.positions[l[0].idx()] = c.position(&d, &p);
        sl[l[0].idx()] = Some(p);
        assert!(matches!(
            certify_boundary_on_curves(&c, &d, &slid, &t, &sl),
            Err(InvariantError::BoundaryCornersLost(Offenders(v))) if v == vec![l[0]]
        ));
    }
}
