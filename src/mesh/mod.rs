//! The triangle mesh: positions + triangles are the source of truth (parry habit); all
//! topology ([`Topology`]) is derived from them and can be rebuilt at any time.

pub mod closest;
pub mod generators;
pub mod location;
pub mod planar;
pub mod topology;
mod union_find;

pub use closest::{parry_trimesh, SurfaceProjector};
pub use location::SurfaceLocation;
pub use planar::{PlanarDomain, PlanarMesh};
pub use topology::{ComponentInfo, Topology};
pub use union_find::UnionFind;

use crate::ids::{FaceId, VertexId};
use nalgebra::{Point3, Vector3};
use thiserror::Error;

/// Axis-aligned bounding box `(min, max)` of `points`; `None` when there are none.
pub fn bbox_of(
    mut points: impl Iterator<Item = Point3<f64>>,
) -> Option<(Point3<f64>, Point3<f64>)> {
    let first = points.next()?;
    Some(points.fold((first, first), |(lo, hi), p| (lo.inf(&p), hi.sup(&p))))
}

/// Errors raised when constructing a mesh from raw arrays.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshError {
    /// The mesh has no faces.
    #[error("empty mesh: no triangles")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteCoordinate {
        /// the vertex
        vertex: VertexId,
        /// x
        x: f64,
        /// y
        y: f64,
        /// z
        z: f64,
    },
    /// A triangle references a vertex that does not exist.
    #[error("face {face} references vertex index {index}, but the mesh has {n_vertices} vertices")]
    IndexOutOfRange {
        /// the face
        face: FaceId,
        /// the bad index
        index: u64,
        /// number of vertices
        n_vertices: usize,
    },
    /// A triangle uses the same vertex twice.
    #[error("face {face} repeats vertex {vertex}")]
    RepeatedVertex {
        /// the face
        face: FaceId,
        /// the repeated vertex
        vertex: VertexId,
    },
    /// More elements than a `u32` id can name.
    #[error("mesh too large: {what} count {count} exceeds u32 ids")]
    TooLarge {
        /// "vertex" or "face"
        what: &'static str,
        /// the count
        count: usize,
    },
}

/// An indexed triangle mesh. Triangles are oriented: `[a, b, c]` has the normal
/// `(b − a) × (c − a)`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions (file units).
    pub positions: Vec<Point3<f64>>,
    /// Triangles as vertex ids, counter-clockwise seen from the outside.
    pub triangles: Vec<[VertexId; 3]>,
}

impl TriMesh {
    /// Build and validate a mesh: finite coordinates, in-range indices, no face repeating a
    /// vertex, at least one face. Topological validity (manifoldness, orientation) is checked
    /// separately by [`crate::invariants`], so that `check` can report on broken meshes.
    pub fn new(
        positions: Vec<Point3<f64>>,
        triangles: Vec<[VertexId; 3]>,
    ) -> Result<Self, MeshError> {
        let m = TriMesh {
            positions,
            triangles,
        };
        m.validate()?;
        Ok(m)
    }

    /// Build a mesh from `usize` indices (validated like [`TriMesh::new`]).
    pub fn from_indices(
        positions: Vec<Point3<f64>>,
        tris: &[[usize; 3]],
    ) -> Result<Self, MeshError> {
        if positions.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "vertex",
                count: positions.len(),
            });
        }
        if tris.len() > u32::MAX as usize / 3 {
            return Err(MeshError::TooLarge {
                what: "face",
                count: tris.len(),
            });
        }
        let n = positions.len();
        let mut triangles = Vec::with_capacity(tris.len());
        for (fi, t) in tris.iter().enumerate() {
            for &i in t {
                if i >= n {
                    return Err(MeshError::IndexOutOfRange {
                        face: FaceId::new(fi),
                        index: i as u64,
                        n_vertices: n,
                    });
                }
            }
            triangles.push([
                VertexId::new(t[0]),
                VertexId::new(t[1]),
                VertexId::new(t[2]),
            ]);
        }
        TriMesh::new(positions, triangles)
    }

    /// Check the array-level rules of [`TriMesh::new`].
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.positions.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "vertex",
                count: self.positions.len(),
            });
        }
        if self.triangles.len() > u32::MAX as usize / 3 {
            return Err(MeshError::TooLarge {
                what: "face",
                count: self.triangles.len(),
            });
        }
        if self.triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        for (i, p) in self.positions.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(MeshError::NonFiniteCoordinate {
                    vertex: VertexId::new(i),
                    x: p.x,
                    y: p.y,
                    z: p.z,
                });
            }
        }
        let n = self.positions.len();
        for (fi, t) in self.triangles.iter().enumerate() {
            for v in t {
                if v.idx() >= n {
                    return Err(MeshError::IndexOutOfRange {
                        face: FaceId::new(fi),
                        index: v.0 as u64,
                        n_vertices: n,
                    });
                }
            }
            if t[0] == t[1] || t[0] == t[2] {
                return Err(MeshError::RepeatedVertex {
                    face: FaceId::new(fi),
                    vertex: t[0],
                });
            }
            if t[1] == t[2] {
                return Err(MeshError::RepeatedVertex {
                    face: FaceId::new(fi),
                    vertex: t[1],
                });
            }
        }
        Ok(())
    }

    /// Number of vertices (including unreferenced ones).
    #[inline]
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    #[inline]
    pub fn n_faces(&self) -> usize {
        self.triangles.len()
    }

    /// Iterator over all face ids.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = FaceId> + '_ {
        (0..self.triangles.len()).map(FaceId::new)
    }

    /// Iterator over all vertex ids.
    pub fn vertices(&self) -> impl ExactSizeIterator<Item = VertexId> + '_ {
        (0..self.positions.len()).map(VertexId::new)
    }

    /// Position of a vertex.
    #[inline]
    pub fn position(&self, v: VertexId) -> &Point3<f64> {
        &self.positions[v.idx()]
    }

    /// The three vertex ids of a face.
    #[inline]
    pub fn face(&self, f: FaceId) -> [VertexId; 3] {
        self.triangles[f.idx()]
    }

    /// The faces as raw index triples (what parry, spade and the planar domains take).
    pub fn index_triangles(&self) -> Vec<[u32; 3]> {
        self.triangles
            .iter()
            .map(|t| [t[0].0, t[1].0, t[2].0])
            .collect()
    }

    /// The three corner positions of a face.
    #[inline]
    pub fn face_points(&self, f: FaceId) -> [Point3<f64>; 3] {
        let t = self.triangles[f.idx()];
        [
            self.positions[t[0].idx()],
            self.positions[t[1].idx()],
            self.positions[t[2].idx()],
        ]
    }

    /// Unnormalised face normal `(b − a) × (c − a)` (length = twice the area).
    #[inline]
    pub fn face_normal_raw(&self, f: FaceId) -> Vector3<f64> {
        let [a, b, c] = self.face_points(f);
        (b - a).cross(&(c - a))
    }

    /// Unit face normal; the zero vector for a face of zero area.
    pub fn face_normal(&self, f: FaceId) -> Vector3<f64> {
        let n = self.face_normal_raw(f);
        let l = n.norm();
        if l > 0.0 {
            n / l
        } else {
            Vector3::zeros()
        }
    }

    /// Face area.
    #[inline]
    pub fn face_area(&self, f: FaceId) -> f64 {
        0.5 * self.face_normal_raw(f).norm()
    }

    /// Face centroid.
    pub fn face_centroid(&self, f: FaceId) -> Point3<f64> {
        let [a, b, c] = self.face_points(f);
        Point3::from((a.coords + b.coords + c.coords) / 3.0)
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        self.faces().map(|f| self.face_area(f)).sum()
    }

    /// Axis-aligned bounding box `(min, max)` of the referenced and unreferenced vertices.
    /// Returns `None` for a mesh with no vertices.
    pub fn bbox(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        bbox_of(self.positions.iter().copied())
    }

    /// The mesh scaled by a power of two so that its largest absolute coordinate lies in
    /// `[1, 2)` (itself when it has no non-zero coordinate). Multiplying by a power of two is
    /// exact for every coordinate that stays a normal float, so every orientation and
    /// intersection verdict on the scaled mesh is the verdict on this one; at extreme scales
    /// (1e±300) the predicates' products would underflow or overflow on the mesh as it is.
    pub fn scaled_by_power_of_two(&self) -> TriMesh {
        let max = self
            .positions
            .iter()
            .flat_map(|p| p.iter().map(|x| x.abs()))
            .fold(0.0f64, f64::max);
        if !(max.is_finite() && max > 0.0) {
            return self.clone();
        }
        // floor(log2(max)) from the float's exponent bits (exact, unlike log2 near powers of
        // two); subnormal maxima are first brought into the normal range.
        let (max, pre) = match max < f64::MIN_POSITIVE {
            true => (max * 2f64.powi(64), 64),
            false => (max, 0),
        };
        let e = ((max.to_bits() >> 52) & 0x7ff) as i32 - 1023;
        let k = -(e - pre);
        // 2^k may not be representable at once (|k| up to 1074): apply it in two halves.
        let (a, b) = (2f64.powi(k / 2), 2f64.powi(k - k / 2));
        TriMesh {
            positions: self.positions.iter().map(|p| (p * a) * b).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Length of the bounding-box diagonal (0 for an empty mesh).
    pub fn bbox_diagonal(&self) -> f64 {
        self.bbox().map(|(lo, hi)| (hi - lo).norm()).unwrap_or(0.0)
    }

    /// The unnormalised face normals summed at each vertex (twice the area-weighted normal;
    /// zero on isolated vertices).
    pub fn area_weighted_normals(&self) -> Vec<Vector3<f64>> {
        let mut n = vec![Vector3::zeros(); self.n_vertices()];
        for f in self.faces() {
            let fnrm = self.face_normal_raw(f);
            for v in self.face(f) {
                n[v.idx()] += fnrm;
            }
        }
        n
    }

    /// Vertex normals: area-weighted (unnormalised face normals summed), normalised.
    pub fn vertex_normals(&self) -> Vec<Vector3<f64>> {
        let mut n = self.area_weighted_normals();
        for x in &mut n {
            let l = x.norm();
            if l > 0.0 {
                *x /= l;
            }
        }
        n
    }

    /// Sum of the face corner angles at each vertex (radians). The angle defect of an interior
    /// vertex is `2π − angle_sums[v]`: the discrete Gaussian curvature concentrated there.
    pub fn angle_sums(&self) -> Vec<f64> {
        let mut s = vec![0.0; self.n_vertices()];
        for t in &self.triangles {
            for k in 0..3 {
                let p = self.positions[t[k].idx()];
                let a = self.positions[t[(k + 1) % 3].idx()] - p;
                let b = self.positions[t[(k + 2) % 3].idx()] - p;
                // atan2 of cross and dot: accurate for angles near 0 and π too.
                s[t[k].idx()] += a.cross(&b).norm().atan2(a.dot(&b));
            }
        }
        s
    }

    /// Mean edge length over all half-edges (each interior edge counted twice).
    pub fn mean_edge_length(&self) -> f64 {
        let mut s = 0.0;
        for l in self.face_edge_lengths() {
            s += l[0] + l[1] + l[2];
        }
        s / (3 * self.n_faces()).max(1) as f64
    }

    /// The lengths of each face's three edges (`|p1 − p0|`, `|p2 − p1|`, `|p0 − p2|`), in face
    /// order.
    pub fn face_edge_lengths(&self) -> impl Iterator<Item = [f64; 3]> + '_ {
        self.faces().map(|f| {
            let [a, b, c] = self.face_points(f);
            [(b - a).norm(), (c - b).norm(), (a - c).norm()]
        })
    }

    /// The mesh with every face's orientation reversed.
    pub fn flipped(&self) -> TriMesh {
        TriMesh {
            positions: self.positions.clone(),
            triangles: self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        }
    }

    /// A copy without vertices that no triangle references, and the map old → new id. The
    /// kept vertices keep their relative order (so per-vertex data given in file order, such
    /// as a `.sol` metric, follows them through the map; a mesh without unreferenced
    /// vertices comes back unchanged).
    pub fn without_unreferenced_vertices(&self) -> (TriMesh, Vec<Option<VertexId>>) {
        let mut used = vec![false; self.n_vertices()];
        for t in &self.triangles {
            for v in t {
                used[v.idx()] = true;
            }
        }
        let mut map = vec![None; self.n_vertices()];
        let mut positions = Vec::new();
        for (old, u) in used.iter().enumerate() {
            if *u {
                map[old] = Some(VertexId::new(positions.len()));
                positions.push(self.positions[old]);
            }
        }
        let triangles: Vec<[VertexId; 3]> = self
            .triangles
            .iter()
            .map(|t| t.map(|v| map[v.idx()].unwrap_or(VertexId(0))))
            .collect();
        (
            TriMesh {
                positions,
                triangles,
            },
            map,
        )
    }

    /// Indices of vertices referenced by no triangle.
    pub fn unreferenced_vertices(&self) -> Vec<VertexId> {
        let mut used = vec![false; self.n_vertices()];
        for t in &self.triangles {
            for v in t {
                used[v.idx()] = true;
            }
        }
        used.iter()
            .enumerate()
            .filter(|(_, u)| !**u)
            .map(|(i, _)| VertexId::new(i))
            .collect()
    }
}

/// Raise per-vertex factors `s` so that within every face of `mesh` none exceeds another by
/// more than `ratio`, in at most `passes` Jacobi passes over the faces (so the result does not
/// depend on the vertex order); factors never fall below 1.
pub fn grade_factors(mesh: &TriMesh, s: &mut [f64], ratio: f64, passes: usize) {
    for _ in 0..passes {
        let prev = s.to_vec();
        let mut changed = false;
        for t in &mesh.triangles {
            let m = t.iter().map(|v| prev[v.idx()]).fold(1.0, f64::max) / ratio;
            for v in t {
                if s[v.idx()] < m {
                    s[v.idx()] = m;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> TriMesh {
        TriMesh::from_indices(
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            &[[0, 1, 2]],
        )
        .expect("valid triangle")
    }

    #[test]
    fn area_normal_and_bbox_of_unit_right_triangle() {
        let m = tri();
        assert_eq!(m.face_area(FaceId(0)), 0.5);
        assert_eq!(m.face_normal(FaceId(0)), Vector3::new(0.0, 0.0, 1.0));
        assert_eq!(
            m.flipped().face_normal(FaceId(0)),
            Vector3::new(0.0, 0.0, -1.0)
        );
        assert!((m.bbox_diagonal() - 2f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn constructor_rejects_bad_arrays_by_element() {
        let p = vec![
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, f64::NAN, 0.0),
        ];
        let e = TriMesh::from_indices(p.clone(), &[[0, 1, 2]]).unwrap_err();
        assert!(
            matches!(
                e,
                MeshError::NonFiniteCoordinate {
                    vertex: VertexId(2),
                    ..
                }
            ),
            "{e}"
        );
        let e = TriMesh::from_indices(p.clone(), &[[0, 1, 5]]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "face f0 references vertex index 5, but the mesh has 3 vertices"
        );
        let mut ok = p;
        ok[2].y = 1.0;
        let e = TriMesh::from_indices(ok.clone(), &[[0, 1, 1]]).unwrap_err();
        assert!(matches!(
            e,
            MeshError::RepeatedVertex {
                face: FaceId(0),
                vertex: VertexId(1)
            }
        ));
        assert_eq!(
            TriMesh::from_indices(ok, &[]).unwrap_err(),
            MeshError::Empty
        );
    }

    #[test]
    fn unreferenced_vertices_are_dropped_and_mapped() {
        let mut m = tri();
        m.positions.insert(0, Point3::new(5.0, 5.0, 5.0));
        for t in &mut m.triangles {
            for v in t.iter_mut() {
                v.0 += 1;
            }
        }
        assert_eq!(m.unreferenced_vertices(), vec![VertexId(0)]);
        let (c, map) = m.without_unreferenced_vertices();
        assert_eq!(c.n_vertices(), 3);
        assert_eq!(map[0], None);
        assert_eq!(map[1], Some(VertexId(0)));
        assert_eq!(c.face_area(FaceId(0)), 0.5);
    }
}
