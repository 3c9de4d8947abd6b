//! Input repair (ours; `conemesh remesh --repair`): make a triangle soup that is *almost* an
//! oriented 2-manifold into one, and say what was changed, element by element.
//!
//! Algorithm 1 needs an oriented manifold (every edge with one or two faces traversing it in
//! opposite directions, one fan per vertex). Real files break that in four common ways, and
//! each has one repair that does not move a single coordinate:
//! 1. **weld**: vertices with bit-identical positions (−0 = +0) become one (STL-style soups,
//!    split UV seams), the lowest id kept;
//! 2. **drop**: faces that welding collapsed, repeated faces (the same three vertices, in
//!    either orientation) and faces of exactly zero area (`collinear3d`, exact) — except that a
//!    zero-area face whose middle corner lies on an edge shared with one other face is first
//!    removed by flipping that edge, which keeps the surface closed (a T-junction's sliver);
//! 3. **orient**: each edge-connected component is oriented consistently by a breadth-first
//!    walk over its manifold edges, keeping the orientation most of its faces already had
//!    (ties: that of its first face); a component that cannot be oriented (a Möbius band) is
//!    refused, naming the edge where the walk met itself reversed;
//! 4. **split**: edges with three or more faces are cut (each face keeps its side as a
//!    boundary edge), and every vertex whose faces form several fans gets one vertex per
//!    fan (the first fan, in face order, keeps the id).
//!
//! The result is certified like every stage's: manifold, oriented, no zero-area face; a
//! mesh the four repairs cannot make valid is an error naming the elements, never a
//! silently wrong mesh. Output vertices are the referenced input vertices in input order,
//! then the copies made by splitting; output faces are the kept input faces in input order.

use crate::ids::{EdgeKey, FaceId, VertexId};
use crate::invariants::{self, InvariantError};
use crate::mesh::{Topology, TriMesh};
use serde::Serialize;
use thiserror::Error;

mod drop;
mod orient;
mod split;
mod weld;

use drop::kept_faces;
use orient::orient;
use split::{compact, split_fans};
use weld::weld;

/// Which repairs run (all by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct RepairOptions {
    /// Weld vertices with bit-identical positions.
    pub weld: bool,
    /// Drop collapsed, zero-area and repeated faces.
    pub drop_degenerate: bool,
    /// Orient each component consistently.
    pub orient: bool,
    /// Cut non-manifold edges and split non-manifold vertices.
    pub split: bool,
}

impl Default for RepairOptions {
    fn default() -> Self {
        RepairOptions {
            weld: true,
            drop_degenerate: true,
            orient: true,
            split: true,
        }
    }
}

/// Why a face was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "reason", content = "of")]
pub enum DropReason {
    /// Welding made two of its corners one vertex.
    Collapsed,
    /// Its corners are collinear (exactly).
    ZeroArea,
    /// It has the same three vertices as this earlier face.
    Duplicate(FaceId),
}

/// A dropped input face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct DroppedFace {
    /// the input face
    pub face: FaceId,
    /// why
    #[serde(flatten)]
    pub reason: DropReason,
}

/// A zero-area face `face`, whose middle corner lies on the edge it shares with `across`: the
/// edge was flipped, so the two faces became two of positive area over `across`'s triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ZeroAreaFlip {
    /// the zero-area input face
    pub face: FaceId,
    /// the input face across its longest edge
    pub across: FaceId,
}

/// An input vertex welded into an earlier one at the same position.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Weld {
    /// the input vertex that is gone
    pub vertex: VertexId,
    /// the input vertex that stands for it
    pub into: VertexId,
}

/// An input vertex split into one output vertex per fan.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Split {
    /// the input vertex
    pub vertex: VertexId,
    /// its output vertices, the one keeping its place first
    pub into: Vec<VertexId>,
}

/// Every change a repair made, in input ids unless said otherwise.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RepairLog {
    /// Vertices welded into an earlier one.
    pub welded: Vec<Weld>,
    /// Faces dropped, with the reason.
    pub dropped_faces: Vec<DroppedFace>,
    /// Faces whose orientation was reversed.
    pub flipped_faces: Vec<FaceId>,
    /// Zero-area faces removed by flipping the edge their middle corner lies on, with the face
    /// across it (the two faces are replaced by two that tile the same surface).
    pub zero_area_flips: Vec<ZeroAreaFlip>,
    /// Edges (after welding) that had three or more faces and were cut.
    pub cut_edges: Vec<EdgeKey>,
    /// Vertices split into one per fan (output ids).
    pub split_vertices: Vec<Split>,
    /// Vertices no kept face references (not in the output).
    pub unreferenced_vertices: Vec<VertexId>,
    /// File faces that use a vertex twice, left out when the file was read
    /// ([`crate::io::ReadOptions::drop_repeated_indices`]; file face numbers, not mesh ids).
    pub repeated_index_faces: Vec<crate::io::RepeatedIndexFace>,
}

impl RepairLog {
    /// True when the repair changed nothing but dropping unreferenced vertices.
    pub fn is_empty(&self) -> bool {
        self.welded.is_empty()
            && self.repeated_index_faces.is_empty()
            && self.dropped_faces.is_empty()
            && self.zero_area_flips.is_empty()
            && self.flipped_faces.is_empty()
            && self.cut_edges.is_empty()
            && self.split_vertices.is_empty()
    }

    /// One line: the count of each kind of change.
    pub fn summary(&self) -> String {
        let count =
            |r: fn(&DropReason) -> bool| self.dropped_faces.iter().filter(|d| r(&d.reason)).count();
        format!(
            "{}welded {} vertices; dropped {} faces ({} collapsed, {} zero-area, {} repeated); \
             flipped {} zero-area faces away; flipped {} faces; cut {} non-manifold edges; split {} vertices; \
             left out {} unreferenced vertices",
            match self.repeated_index_faces.len() {
                0 => String::new(),
                n => format!("left out {n} file faces that use a vertex twice; "),
            },
            self.welded.len(),
            self.dropped_faces.len(),
            count(|r| *r == DropReason::Collapsed),
            count(|r| *r == DropReason::ZeroArea),
            count(|r| matches!(r, DropReason::Duplicate(_))),
            self.zero_area_flips.len(),
            self.flipped_faces.len(),
            self.cut_edges.len(),
            self.split_vertices.len(),
            self.unreferenced_vertices.len(),
        )
    }
}

/// A repaired mesh and where its elements came from.
#[derive(Clone, Debug)]
pub struct Repaired {
    /// The repaired, certified mesh.
    pub mesh: TriMesh,
    /// What was changed.
    pub log: RepairLog,
    /// The input vertex of each output vertex (for a welded group, its lowest id).
    pub source_vertex: Vec<VertexId>,
    /// The input face of each output face.
    pub source_face: Vec<FaceId>,
}

impl Repaired {
    /// Per-vertex data of the input (a user's metric tensors, say) carried to the output
    /// vertices: each takes its source vertex's value.
    pub fn vertex_values<T: Clone>(&self, per_input_vertex: &[T]) -> Vec<T> {
        self.source_vertex
            .iter()
            .map(|v| per_input_vertex[v.idx()].clone())
            .collect()
    }
}

/// What the repairs cannot fix.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RepairError {
    /// A component is not orientable.
    #[error(
        "the component of face {face} is not orientable (a Möbius band): orienting it \
         consistently meets edge {edge} from both sides in the same direction"
    )]
    NonOrientable {
        /// an input face of the component
        face: FaceId,
        /// the edge (input ids, after welding) where the orientation contradicts itself
        edge: EdgeKey,
    },
    /// Every face was dropped.
    #[error("no face is left after dropping collapsed, zero-area and repeated faces")]
    NoFaces,
    /// The result still fails a certificate (e.g. a repair left out by the options).
    #[error("the repaired mesh is still invalid: {0}")]
    Unrepaired(#[source] InvariantError),
}

/// Repair `mesh` (see the module documentation for what each step does); the result is a
/// certified oriented manifold without zero-area faces, or an error naming what is left.
pub fn repair(mesh: &TriMesh, options: &RepairOptions) -> Result<Repaired, RepairError> {
    let mut log = RepairLog::default();
    let rep = if options.weld {
        weld(mesh, &mut log)
    } else {
        mesh.vertices().collect()
    };
    let (faces, tris) = kept_faces(mesh, &rep, options.drop_degenerate, &mut log);
    if faces.is_empty() {
        return Err(RepairError::NoFaces);
    }
    let adjacency = glued_edges(&tris, options.split, &mut log);
    // Fans do not depend on orientation: split first, on the corners `adjacency` indexes,
    // then reverse the faces the orientation walk chose.
    let flips = match options.orient {
        true => orient(&faces, &tris, &adjacency, &mut log)?,
        false => vec![],
    };
    let (positions, source_vertex, mut tris) = if options.split {
        split_fans(mesh, &rep, &tris, &adjacency, &mut log)
    } else {
        compact(mesh, &tris, &mut log)
    };
    for &k in &flips {
        tris[k].swap(1, 2);
    }
    let out = TriMesh::new(positions, tris).map_err(|_| RepairError::NoFaces)?;
    let topo = Topology::build(&out);
    invariants::certify_manifold(&out, &topo)
        .and_then(|()| invariants::certify_oriented(&out, &topo))
        .and_then(|()| invariants::certify_no_degenerate_faces(&out))
        .map_err(RepairError::Unrepaired)?;
    Ok(Repaired {
        mesh: out,
        log,
        source_vertex,
        source_face: faces,
    })
}

/// Across edge `i` of each kept face (from corner `i` to corner `i + 1`): the other face's
/// half-edge on it (`3·face + corner`) and whether it traverses the edge in the same
/// direction, for edges with exactly two faces. With `cut`, edges of three or more faces are recorded in the log and glue
/// nothing; without, they are left for the final certificate to name.
fn glued_edges(
    tris: &[[VertexId; 3]],
    cut: bool,
    log: &mut RepairLog,
) -> Vec<[Option<(u32, bool)>; 3]> {
    let mut hes: Vec<(VertexId, VertexId, u32)> = Vec::with_capacity(3 * tris.len());
    for (k, t) in tris.iter().enumerate() {
        for i in 0..3 {
            let EdgeKey(a, b) = EdgeKey::new(t[i], t[(i + 1) % 3]);
            hes.push((a, b, (3 * k + i) as u32));
        }
    }
    hes.sort_unstable();
    let mut adjacency = vec![[None; 3]; tris.len()];
    let from = |h: u32| tris[(h / 3) as usize][(h % 3) as usize];
    let mut i = 0;
    while i < hes.len() {
        let mut j = i + 1;
        while j < hes.len() && (hes[j].0, hes[j].1) == (hes[i].0, hes[i].1) {
            j += 1;
        }
        match j - i {
            2 => {
                let (h, g) = (hes[i].2, hes[i + 1].2);
                let same = from(h) == from(g);
                adjacency[(h / 3) as usize][(h % 3) as usize] = Some((g, same));
                adjacency[(g / 3) as usize][(g % 3) as usize] = Some((h, same));
            }
            1 => {}
            _ if cut => log.cut_edges.push(EdgeKey(hes[i].0, hes[i].1)),
            _ => {}
        }
        i = j;
    }
    adjacency
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use nalgebra::Point3;

    fn tri(a: u32, b: u32, c: u32) -> [VertexId; 3] {
        [VertexId(a), VertexId(b), VertexId(c)]
    }

    fn certified(m: &TriMesh) -> bool {
        Topology::build(m).is_oriented_manifold()
    }

    #[test]
    fn a_valid_mesh_is_returned_unchanged() {
        let m = generators::torus(1.0, 0.4, 12, 8);
        let r = repair(&m, &RepairOptions::default()).expect("repairs");
        assert!(r.log.is_empty(), "{}", r.log.summary());
        assert_eq!(r.mesh, m);
    }

    #[test]
    fn shuffled_orientation_is_made_consistent_keeping_the_majority() {
        let m = generators::torus(1.0, 0.4, 12, 8);
        let mut shuffled = m.clone();
        let flipped: Vec<usize> = (0..m.n_faces()).filter(|f| f % 3 == 1).collect();
        for &f in &flipped {
            shuffled.triangles[f].swap(0, 1);
        }
        assert!(!certified(&shuffled));
        let r = repair(&shuffled, &RepairOptions::default()).expect("repairs");
        // A third of the faces were reversed, so the other two thirds' orientation wins:
        // exactly the reversed faces are flipped back, and the mesh is the original's
        // (up to the rotation of each flipped triangle's corners).
        assert_eq!(
            r.log.flipped_faces,
            flipped.iter().map(|&f| FaceId::new(f)).collect::<Vec<_>>()
        );
        assert!(certified(&r.mesh));
        for f in m.faces() {
            let (a, b) = (m.face(f), r.mesh.face(f));
            let rotations = [[0, 1, 2], [1, 2, 0], [2, 0, 1]];
            assert!(
                rotations.iter().any(|p| p.map(|i| b[i]) == a),
                "{f}: {a:?} vs {b:?}"
            );
        }
    }

    #[test]
    fn a_soup_is_welded_into_the_surface() {
        // Every face with its own three vertices (an STL soup), one face reversed.
        let m = generators::torus(1.0, 0.4, 10, 6);
        let mut soup = generators::triangle_soup(&m);
        soup.triangles[5].swap(1, 2);
        let r = repair(&soup, &RepairOptions::default()).expect("repairs");
        assert_eq!(r.mesh.n_vertices(), m.n_vertices());
        assert_eq!(r.mesh.n_faces(), m.n_faces());
        assert_eq!(r.log.welded.len(), soup.n_vertices() - m.n_vertices());
        assert_eq!(r.log.flipped_faces, vec![FaceId(5)]);
        assert!(certified(&r.mesh));
        assert_eq!(Topology::build(&r.mesh).components()[0].genus, Some(1));
        // Every output vertex sits where its source did.
        for v in r.mesh.vertices() {
            assert_eq!(r.mesh.position(v), soup.position(r.source_vertex[v.idx()]));
        }
    }

    #[test]
    fn two_squares_touching_at_a_corner_are_split_there() {
        // A bowtie: two squares (two triangles each) sharing only vertex 2.
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let positions = vec![
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(1.0, 1.0),
            p(0.0, 1.0),
            p(2.0, 1.0),
            p(2.0, 2.0),
            p(1.0, 2.0),
        ];
        let tris = vec![tri(0, 1, 2), tri(0, 2, 3), tri(2, 4, 5), tri(2, 5, 6)];
        let m = TriMesh::new(positions, tris).expect("valid arrays");
        assert!(!certified(&m));
        let r = repair(&m, &RepairOptions::default()).expect("repairs");
        assert_eq!(
            r.log.split_vertices,
            vec![Split {
                vertex: VertexId(2),
                into: vec![VertexId(2), VertexId(7)]
            }]
        );
        assert_eq!(r.mesh.triangles[2], tri(7, 4, 5));
        assert_eq!(r.source_vertex[7], VertexId(2));
        assert!(certified(&r.mesh));
        assert_eq!(Topology::build(&r.mesh).components().len(), 2);
    }

    #[test]
    fn an_edge_with_three_faces_is_cut_into_three_sheets() {
        // Three triangles on the edge (0, 1), fanned around it like book pages.
        let positions = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.5, 1.0, 0.0),
            Point3::new(0.5, -0.5, 0.8),
            Point3::new(0.5, -0.5, -0.8),
        ];
        let tris = vec![tri(0, 1, 2), tri(1, 0, 3), tri(0, 1, 4)];
        let m = TriMesh::new(positions, tris).expect("valid arrays");
        let r = repair(&m, &RepairOptions::default()).expect("repairs");
        assert_eq!(r.log.cut_edges, vec![EdgeKey(VertexId(0), VertexId(1))]);
        assert!(certified(&r.mesh));
        let topo = Topology::build(&r.mesh);
        assert_eq!(topo.components().len(), 3);
        assert_eq!(r.mesh.n_vertices(), 5 + 4);
    }

    #[test]
    fn degenerate_and_repeated_faces_are_dropped_by_name() {
        let mut m = generators::torus(1.0, 0.4, 8, 6);
        let n = m.n_faces() as u32;
        // A repeated face (reversed), a zero-area face on three collinear new vertices, and a
        // face on a duplicate of vertex 0 that welding collapses.
        let dup = m.triangles[3];
        m.triangles.push([dup[0], dup[2], dup[1]]);
        let base = m.positions.len() as u32;
        m.positions.extend([
            Point3::new(5.0, 0.0, 0.0),
            Point3::new(6.0, 0.0, 0.0),
            Point3::new(7.0, 0.0, 0.0),
            m.positions[0],
        ]);
        m.triangles.push(tri(base, base + 1, base + 2));
        let t1 = m.triangles[1];
        m.triangles.push([t1[0], VertexId(0), VertexId(base + 3)]);
        let r = repair(&m, &RepairOptions::default()).expect("repairs");
        let reasons: Vec<(FaceId, DropReason)> = r
            .log
            .dropped_faces
            .iter()
            .map(|d| (d.face, d.reason))
            .collect();
        assert_eq!(reasons[0], (FaceId(n), DropReason::Duplicate(FaceId(3))));
        assert_eq!(reasons[1], (FaceId(n + 1), DropReason::ZeroArea));
        assert_eq!(reasons[2].0, FaceId(n + 2));
        assert!(certified(&r.mesh));
        assert_eq!(r.mesh.n_faces(), n as usize);
        assert_eq!(r.log.unreferenced_vertices.len(), 3, "{:?}", r.log);
    }

    /// A T-junction sealed by a zero-area face, as exporters leave them: the cube's edge `a`–`b`
    /// has the midpoint `m` on one side only, with the sliver `(a, b, m)`. The repair flips the
    /// sliver away instead of dropping it: the cube stays closed, of area 6, and nothing is
    /// dropped. The sliver alone, with no face across its long edge, is dropped.
    #[test]
    fn a_zero_area_sliver_is_flipped_away_keeping_the_surface_closed() {
        let mut m = generators::cube(2);
        let topo = Topology::build(&m);
        // An axis-aligned edge (its midpoint is exact) with faces on both sides.
        let (f1, i) = m
            .faces()
            .flat_map(|f| (0..3).map(move |i| (f, i)))
            .find(|&(f, i)| {
                let t = m.face(f);
                let d = m.position(t[(i + 1) % 3]) - m.position(t[i]);
                d.iter().filter(|x| **x != 0.0).count() == 1 && topo.neighbor(f, i).is_some()
            })
            .expect("an axis-aligned edge");
        let t = m.face(f1);
        let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
        let mid = VertexId(m.positions.len() as u32);
        m.positions.push(Point3::from(
            (m.position(a).coords + m.position(b).coords) * 0.5,
        ));
        m.triangles[f1.idx()] = [a, mid, c];
        m.triangles.push([mid, b, c]);
        m.triangles.push([a, b, mid]);
        let sliver = FaceId(m.n_faces() as u32 - 1);
        assert!(Topology::build(&m).is_oriented_manifold());
        let r = repair(&m, &RepairOptions::default()).expect("repairs");
        assert!(r.log.dropped_faces.is_empty(), "{:?}", r.log.dropped_faces);
        assert_eq!(r.log.zero_area_flips.len(), 1);
        assert_eq!(r.log.zero_area_flips[0].face, sliver);
        assert_eq!(
            r.log.zero_area_flips[0].across,
            topo.neighbor(f1, i).expect("across")
        );
        assert!(certified(&r.mesh));
        let t2 = Topology::build(&r.mesh);
        assert!(t2.boundary_loops().is_empty(), "still closed");
        assert_eq!(t2.euler_characteristic(), 2);
        assert!((r.mesh.area() - 6.0).abs() < 1e-12);
        assert!(r.log.summary().contains("flipped 1 zero-area faces away"));
    }

    #[test]
    fn a_moebius_band_is_refused_naming_an_edge() {
        let m = generators::moebius_band(8);
        match repair(&m, &RepairOptions::default()) {
            Err(RepairError::NonOrientable { .. }) => {}
            other => panic!("expected a refusal, got {other:?}"),
        }
    }

    #[test]
    fn a_repair_left_out_is_named_by_the_certificate() {
        let mut m = generators::torus(1.0, 0.4, 8, 6);
        m.triangles[0].swap(1, 2);
        let options = RepairOptions {
            orient: false,
            ..Default::default()
        };
        assert!(matches!(
            repair(&m, &options),
            Err(RepairError::Unrepaired(
                InvariantError::InconsistentOrientation(_)
            ))
        ));
        assert!(repair(&m, &RepairOptions::default()).is_ok());
    }

    #[test]
    fn metric_values_follow_their_vertices() {
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let positions = vec![p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0), p(1.0, 0.0)];
        let m = TriMesh::new(positions, vec![tri(0, 3, 2)]).expect("valid arrays");
        let r = repair(&m, &RepairOptions::default()).expect("repairs");
        // v3 is welded into v1 (same point): v1's value is the one carried.
        assert_eq!(r.vertex_values(&[10, 11, 12, 13]), vec![10, 11, 12]);
        assert_eq!(
            r.log.welded,
            vec![Weld {
                vertex: VertexId(3),
                into: VertexId(1)
            }]
        );
    }
}
