//! Mapping a remeshed patch back to the surface (Sec. 3.3, "Mapping back to the source").
//!
//! Boundary vertices keep their identity and position (the planar remesher returns them with
//! `origin`). Every other vertex is located in the *initial* 2D patch mesh (exact point
//! location), its barycentric coordinates there give a point on the patch in 3D
//! (`p = b0·p0 + b1·p1 + b2·p2`, as in the paper), and that point is then placed on the
//! reference surface by closest-point projection, which also gives its reference location
//! (face + barycentric). The paper maps onto the current mesh; we add the projection so that
//! every vertex lies on the *input* surface even after several patches have replaced chords
//! of it (see paper-notes.md, "Mapping back").

use crate::boundary::CurvePoint;
use crate::ids::VertexId;
use crate::mesh::{SurfaceLocation, TriMesh};
use crate::remesh2d::PlanarMesh;
use crate::stitch::{PatchVertex, Replacement};
use nalgebra::{Point2, Point3};
use thiserror::Error;

/// Errors of lifting.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LiftError {
    /// A planar output vertex lies outside the initial 2D patch mesh.
    #[error("remeshed vertex {index} at ({x}, {y}) is outside the parameterized patch")]
    OutsideDomain {
        /// index in the planar mesh
        index: usize,
        /// u
        x: f64,
        /// v
        y: f64,
    },
    /// An output vertex claims an origin that is not a patch vertex.
    #[error("remeshed vertex {index} claims origin {origin}, but the patch has {n} vertices")]
    BadOrigin {
        /// index in the planar mesh
        index: usize,
        /// claimed origin
        origin: u32,
        /// patch vertex count
        n: usize,
    },
}

/// How a vertex of the planar domain maps back: a vertex of the patch (its local id), or a
/// new point on the input's boundary curves, placed there exactly
/// ([`crate::boundary::BoundaryCurves::position`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum DomainVertex {
    /// A vertex of the patch.
    Patch(u32),
    /// A new point on a boundary curve.
    Curve {
        /// Its position (on the curve, exactly).
        position: Point3<f64>,
        /// Its location on the reference surface.
        location: SurfaceLocation,
        /// Its point on the curve.
        point: CurvePoint,
    },
}

/// The patch as the lifting step sees it: its initial 2D mesh and the 3D positions of the
/// same vertices, and what each vertex of the planar domain is.
pub struct PatchFrame<'a> {
    /// Local triangles (indices into `positions` / the parameterization).
    pub triangles: &'a [[VertexId; 3]],
    /// 3D positions of the local vertices (working mesh, unit-diagonal space).
    pub positions: &'a [Point3<f64>],
    /// Local → working-mesh vertex id.
    pub to_global: &'a [VertexId],
    /// Planar-domain vertex → what it is (the planar remesher's `origin` indexes these).
    pub domain: &'a [DomainVertex],
}

/// Lift `planar` to 3D: boundary (origin) vertices become [`PatchVertex::Existing`], new
/// vertices are located with `locate` (initial 2D mesh: triangle index and barycentric
/// coordinates) and placed on the reference surface by `project`.
pub fn lift(
    planar: &PlanarMesh,
    frame: &PatchFrame<'_>,
    locate: impl Fn(&Point2<f64>) -> Option<(usize, [f64; 3])>,
    project: impl Fn(&Point3<f64>) -> SurfaceLocation,
    reference: &TriMesh,
) -> Result<Replacement, LiftError> {
    let n_local = frame.positions.len();
    let mut map = Vec::with_capacity(planar.points.len());
    let mut repl = Replacement::default();
    for (i, p) in planar.points.iter().enumerate() {
        match planar.origin.get(i).copied().flatten() {
            Some(o) => match frame.domain.get(o as usize) {
                Some(DomainVertex::Patch(l)) => {
                    let g = frame
                        .to_global
                        .get(*l as usize)
                        .ok_or(LiftError::BadOrigin {
                            index: i,
                            origin: o,
                            n: n_local,
                        })?;
                    map.push(PatchVertex::Existing(*g));
                }
                Some(DomainVertex::Curve {
                    position,
                    location,
                    point,
                }) => {
                    repl.new_positions.push(*position);
                    repl.new_locations.push(*location);
                    repl.new_curve.push(Some(*point));
                    map.push(PatchVertex::New((repl.new_positions.len() - 1) as u32));
                }
                None => {
                    return Err(LiftError::BadOrigin {
                        index: i,
                        origin: o,
                        n: frame.domain.len(),
                    })
                }
            },
            None => {
                let (t, b) = locate(p).ok_or(LiftError::OutsideDomain {
                    index: i,
                    x: p.x,
                    y: p.y,
                })?;
                let tri = frame.triangles[t];
                let q = frame.positions[tri[0].idx()].coords * b[0]
                    + frame.positions[tri[1].idx()].coords * b[1]
                    + frame.positions[tri[2].idx()].coords * b[2];
                let loc = project(&Point3::from(q));
                repl.new_positions.push(loc.position(reference));
                repl.new_locations.push(loc);
                repl.new_curve.push(None);
                map.push(PatchVertex::New((repl.new_positions.len() - 1) as u32));
            }
        }
    }
    repl.triangles = planar
        .triangles
        .iter()
        .map(|t| [map[t[0] as usize], map[t[1] as usize], map[t[2] as usize]])
        .collect();
    Ok(repl)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ids::FaceId;

    #[test]
    fn lift_keeps_origins_and_interpolates_new_vertices() {
        // One reference triangle in the plane z = 0; its 2D map is the identity on (x, y).
        let reference = TriMesh::from_indices(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            &[[0, 1, 2]],
        )
        .expect("valid");
        let to_global = [VertexId(0), VertexId(1), VertexId(2)];
        let domain: Vec<DomainVertex> = (0..3).map(DomainVertex::Patch).collect();
        let frame = PatchFrame {
            triangles: &reference.triangles,
            positions: &reference.positions,
            to_global: &to_global,
            domain: &domain,
        };
        // Planar output: the three corners plus a centre vertex, fanned.
        let planar = PlanarMesh {
            points: vec![
                Point2::new(0.0, 0.0),
                Point2::new(1.0, 0.0),
                Point2::new(0.0, 1.0),
                Point2::new(0.25, 0.25),
            ],
            triangles: vec![[0, 1, 3], [1, 2, 3], [2, 0, 3]],
            origin: vec![Some(0), Some(1), Some(2), None],
        };
        let locate = |p: &Point2<f64>| Some((0usize, [1.0 - p.x - p.y, p.x, p.y]));
        let project = |p: &Point3<f64>| SurfaceLocation {
            face: FaceId(0),
            bary: [1.0 - p.x - p.y, p.x, p.y],
        };
        let r = lift(&planar, &frame, locate, project, &reference).expect("lifts");
        assert_eq!(r.new_positions, vec![Point3::new(0.25, 0.25, 0.0)]);
        assert_eq!(
            r.triangles[0],
            [
                PatchVertex::Existing(VertexId(0)),
                PatchVertex::Existing(VertexId(1)),
                PatchVertex::New(0)
            ]
        );
        // A vertex outside the domain is an error naming it.
        let mut bad = planar.clone();
        bad.points[3] = Point2::new(2.0, 2.0);
        let outside =
            |p: &Point2<f64>| (p.x + p.y <= 1.0).then(|| (0usize, [1.0 - p.x - p.y, p.x, p.y]));
        assert_eq!(
            lift(&bad, &frame, outside, project, &reference).unwrap_err(),
            LiftError::OutsideDomain {
                index: 3,
                x: 2.0,
                y: 2.0
            }
        );
    }
}
