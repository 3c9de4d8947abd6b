//! Principal curvatures and directions per vertex by a local quadric fit (Sec. 4.1: "the
//! Riemannian metric of M_ref is obtained by curvature"; the fit follows libigl's
//! `principal_curvature`, see `paper-notes.md` § 3.1).
//!
//! For every vertex `v`:
//! 1. the neighbourhood is the set of vertices within `radius` edge rings of `v` (grown further
//!    if it has fewer than 5 other vertices, libigl's minimum of 6 points; cut at
//!    `MAX_NEIGHBOURS` in breadth-first order);
//! 2. the frame normal `n₀` is the vertex's area-weighted normal, with a tangent pair
//!    `(t₁, t₂)`; neighbours whose normal faces away from `n₀` (more than 90°, e.g. across a
//!    sharp feature line) are dropped when at least 5 remain (libigl's defaults: `localMode`,
//!    `AVERAGE` normal, `projectionPlaneCheck`);
//! 3. the height function `z = a u² + b uv + c v² + d u + e v` (libigl's quadric: no constant
//!    term, the surface passes through `v`) is fitted to the neighbours' frame coordinates by
//!    least squares (SVD, coordinates scaled by the neighbourhood size for conditioning);
//! 4. the principal curvatures are (minus) the eigenvalues of the fitted surface's shape operator
//!    `I⁻¹ II` at `v` (libigl uses a symmetrised approximation, see `paper-notes.md`), and `d₁`
//!    is its eigenvector for `k₁` mapped to 3D and projected on the tangent plane of `n₀`, as libigl
//!    reports directions; `d₂ = n₀ × d₁`.
//!
//! Sign: `k > 0` where the surface bends away from its normal (a sphere with outward normals has
//! `k₁ = k₂ = +1/r`), as in libigl.

use super::MetricError;
use crate::mesh::TriMesh;
use nalgebra::{DMatrix, DVector, Matrix2, SymmetricEigen, Vector3};
use rayon::prelude::*;

/// Options of [`principal_curvatures`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CurvatureOptions {
    /// Neighbourhood size in edge rings around each vertex (default 5, libigl's default).
    pub radius: usize,
}

impl Default for CurvatureOptions {
    fn default() -> Self {
        CurvatureOptions { radius: 5 }
    }
}

/// Principal curvatures and the principal frame at one vertex.
///
/// Convention: `|k1| ≥ |k2|` (ties: `k1 ≥ k2`), i.e. `d1` is the direction of largest curvature
/// *magnitude*, the one along which the curvature metric asks for the shortest edges.
/// `(d1, d2, normal)` is a right-handed orthonormal frame: `d1 × d2 = normal`.
/// Where both curvatures vanish (planar regions, directions undefined) `k1 = k2 = 0` and
/// `(d1, d2)` is a deterministic tangent pair built from the normal alone
/// ([`tangent_frame`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipalCurvature {
    /// Curvature of largest magnitude (1/length; positive = bending away from `normal`).
    pub k1: f64,
    /// The other principal curvature.
    pub k2: f64,
    /// Unit principal direction of `k1`.
    pub d1: Vector3<f64>,
    /// Unit principal direction of `k2` (`normal × d1`).
    pub d2: Vector3<f64>,
    /// Unit normal at the vertex: the area-weighted vertex normal (the fit's frame normal), so
    /// that the curvature metric is degenerate exactly along the mesh's vertex normal.
    pub normal: Vector3<f64>,
}

/// Curvature magnitudes below `PLANAR_RELATIVE / h` (h = neighbourhood size) are numerical noise
/// of the fit: such vertices are planar, their directions undefined.
const PLANAR_RELATIVE: f64 = 1e-9;

/// A neighbour "faces" the vertex when the cosine between their normals exceeds this.
const FACING_MIN_COS: f64 = 1e-9;

/// Minimum number of neighbours (besides the vertex) for a fit; libigl asks for 6 points
/// including the vertex itself.
pub(super) const MIN_NEIGHBOURS: usize = 5;

/// Largest neighbourhood a fit uses: the rings stop growing, in breadth-first order, once they
/// hold this many vertices, so a vertex next to a hub (a polygon cut into a fan, a CAD disk
/// face: one vertex of 100,000 faces) costs a bounded fit instead of one over the whole mesh.
/// The 5-rings of the shared meshes hold at most 211 vertices, so their fits are unchanged.
pub(super) const MAX_NEIGHBOURS: usize = 512;

/// A deterministic orthonormal tangent pair `(t1, t2)` with `t1 × t2 = n` for a unit normal
/// `n`: `t1` is the coordinate axis least aligned with `n` (lowest index on ties), projected.
/// A zero `n` gives `(x, y)`.
pub fn tangent_frame(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let l = n.norm();
    if !l.is_finite() || l <= 0.0 {
        return (Vector3::x(), Vector3::y());
    }
    let n = n / l;
    let mut k = 0;
    for i in 1..3 {
        if n[i].abs() < n[k].abs() {
            k = i;
        }
    }
    let mut a = Vector3::zeros();
    a[k] = 1.0;
    let t1 = (a - n * n.dot(&a)).normalize();
    let t2 = n.cross(&t1);
    (t1, t2)
}

fn planar(normal: Vector3<f64>) -> PrincipalCurvature {
    let normal = if normal.norm() > 0.0 {
        normal.normalize()
    } else {
        Vector3::z()
    };
    let (d1, d2) = tangent_frame(&normal);
    PrincipalCurvature {
        k1: 0.0,
        k2: 0.0,
        d1,
        d2,
        normal,
    }
}

/// Vertex adjacency (CSR, neighbours sorted), derived from the triangles.
struct Adjacency {
    offsets: Vec<usize>,
    neighbours: Vec<u32>,
}

impl Adjacency {
    fn build(mesh: &TriMesh) -> Adjacency {
        let n = mesh.n_vertices();
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(mesh.n_faces() * 6);
        for t in &mesh.triangles {
            for i in 0..3 {
                let (a, b) = (t[i].0, t[(i + 1) % 3].0);
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0usize; n + 1];
        for &(a, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        Adjacency {
            offsets,
            neighbours: pairs.into_iter().map(|(_, b)| b).collect(),
        }
    }

    fn of(&self, v: usize) -> &[u32] {
        &self.neighbours[self.offsets[v]..self.offsets[v + 1]]
    }
}

/// Per-thread BFS scratch: a generation stamp per vertex avoids clearing between vertices.
struct Scratch {
    stamp: Vec<u32>,
    generation: u32,
    ring: Vec<u32>,
}

impl Scratch {
    fn new(n: usize) -> Scratch {
        Scratch {
            stamp: vec![0; n],
            generation: 0,
            ring: Vec::new(),
        }
    }

    /// Vertices within `radius` rings of `v` (excluding `v`), grown ring by ring beyond
    /// `radius` until there are [`MIN_NEIGHBOURS`] or the component is exhausted.
    fn k_ring(&mut self, adj: &Adjacency, v: usize, radius: usize) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.generation = 1;
        }
        let g = self.generation;
        self.ring.clear();
        self.stamp[v] = g;
        // Ring 1 is grown from v itself.
        let mut current: Vec<u32> = vec![v as u32];
        let mut depth = 0usize;
        loop {
            if depth >= radius && self.ring.len() >= MIN_NEIGHBOURS {
                break;
            }
            let room = MAX_NEIGHBOURS - self.ring.len();
            let mut next = Vec::new();
            'ring: for &w in &current {
                for &u in adj.of(w as usize) {
                    if self.stamp[u as usize] != g {
                        self.stamp[u as usize] = g;
                        next.push(u);
                        if next.len() == room {
                            break 'ring;
                        }
                    }
                }
            }
            if next.is_empty() {
                break;
            }
            self.ring.extend_from_slice(&next);
            if self.ring.len() == MAX_NEIGHBOURS {
                break;
            }
            current = next;
            depth += 1;
        }
    }
}

/// Fit at one vertex; `ring` excludes the vertex itself.
/// `n0` is the frame normal: the vertex's own area-weighted normal (libigl's default,
/// `localMode` with `AVERAGE` normals), or one side's normal at a crease ([`super::creases`]).
pub(super) fn fit_vertex(
    positions: &[nalgebra::Point3<f64>],
    normals: &[Vector3<f64>],
    n0: Vector3<f64>,
    v: usize,
    ring: &[u32],
) -> PrincipalCurvature {
    if !n0.norm().is_finite() || n0.norm() <= 0.0 || ring.len() < MIN_NEIGHBOURS {
        return planar(n0);
    }
    let n0 = n0.normalize();
    // libigl's `projectionPlaneCheck`: drop neighbours facing away (normal more than 90° from
    // n₀), e.g. across a sharp feature line, when enough remain and some were dropped. libigl's
    // test is `> 0`; we ask for `> FACING_MIN_COS` so that neighbours at exactly 90° (common on
    // symmetric meshes: a torus's equator seen from its top circle) are dropped whatever the
    // round-off, instead of flipping in and out with the mesh's placement and scale.
    let facing: Vec<u32> = ring
        .iter()
        .copied()
        .filter(|&w| normals[w as usize].dot(&n0) > FACING_MIN_COS)
        .collect();
    let ring: &[u32] = if facing.len() >= MIN_NEIGHBOURS && facing.len() < ring.len() {
        &facing
    } else {
        ring
    };
    let (t1, t2) = tangent_frame(&n0);
    let p = positions[v];
    let local: Vec<Vector3<f64>> = ring
        .iter()
        .map(|&w| {
            let q = positions[w as usize] - p;
            Vector3::new(q.dot(&t1), q.dot(&t2), q.dot(&n0))
        })
        .collect();
    let h = local
        .iter()
        .map(|q| (q.x * q.x + q.y * q.y).sqrt())
        .fold(0.0f64, f64::max);
    if !h.is_finite() || h <= 0.0 {
        return planar(n0);
    }
    let Some((a, b, c, d, e)) = fit_quadric(&local, h) else {
        return planar(n0);
    };
    let Some(pairs) = principal_pairs((a, b, c, d, e), t1, t2) else {
        return planar(n0);
    };
    let (k1, k2) = (pairs[0].0, pairs[1].0);
    if !(k1.is_finite() && k2.is_finite()) {
        return planar(n0);
    }
    if k1.abs() * h <= PLANAR_RELATIVE {
        return planar(n0);
    }
    let normal = n0;
    let d1 = pairs[0].1;
    let l = d1.norm();
    if !l.is_finite() || l <= 0.0 {
        return planar(normal);
    }
    let d1 = d1 / l;
    let d2 = normal.cross(&d1);
    PrincipalCurvature {
        k1,
        k2,
        d1,
        d2,
        normal,
    }
}

/// The quadric `z = a u² + b uv + c v² + d u + e v` through the ring's local coordinates
/// (least squares), `h` their largest tangential distance; `None` when it has no finite fit.
fn fit_quadric(local: &[Vector3<f64>], h: f64) -> Option<(f64, f64, f64, f64, f64)> {
    // Least squares z = a u² + b uv + c v² + d u + e v on coordinates scaled by 1/h, so that
    // all five columns have comparable size (the solution is the same up to the rescaling).
    let m = local.len();
    let mut a_mat = DMatrix::<f64>::zeros(m, 5);
    let mut rhs = DVector::<f64>::zeros(m);
    for (r, q) in local.iter().enumerate() {
        let (u, w, z) = (q.x / h, q.y / h, q.z / h);
        a_mat[(r, 0)] = u * u;
        a_mat[(r, 1)] = u * w;
        a_mat[(r, 2)] = w * w;
        a_mat[(r, 3)] = u;
        a_mat[(r, 4)] = w;
        rhs[r] = z;
    }
    let svd = a_mat.svd(true, true);
    let smax = svd.singular_values.max();
    let sol = svd.solve(&rhs, smax * 1e-12).ok()?;
    // Undo the scaling: z/h = a'(u/h)² + … ⇒ a = a'/h (second order), d = d' (first order).
    let (a, b, c, d, e) = (sol[0] / h, sol[1] / h, sol[2] / h, sol[3], sol[4]);
    if ![a, b, c, d, e].iter().all(|x| x.is_finite()) {
        return None;
    }
    Some((a, b, c, d, e))
}

/// The fitted graph's principal curvatures with their directions in the tangent plane of
/// `n₀` (frame `t1`, `t2`), largest magnitude first; `None` when the first fundamental form
/// has no Cholesky inverse.
fn principal_pairs(
    (a, b, c, d, e): (f64, f64, f64, f64, f64),
    t1: Vector3<f64>,
    t2: Vector3<f64>,
) -> Option<Vec<(f64, Vector3<f64>)>> {
    // Fundamental forms of the graph (u, v, f(u, v)) at the origin: I = [[E, F], [F, G]],
    // II = [[L, M], [M, N]] with the fitted surface's unit normal (−d, −e, 1)/w.
    let w = (1.0 + d * d + e * e).sqrt();
    let (ee, ff, gg) = (1.0 + d * d, d * e, 1.0 + e * e);
    let (l, m_, nn) = (2.0 * a / w, b / w, 2.0 * c / w);
    // Principal curvatures: eigenvalues of the shape operator I⁻¹ II (the generalised symmetric
    // problem II x = λ I x, solved through the Cholesky factor I = R Rᵀ: S = R⁻¹ II R⁻ᵀ,
    // x = R⁻ᵀ y). libigl symmetrises I⁻¹ II instead (its off-diagonal M E − L F on both sides),
    // which is exact only when d = e = 0 and then depends on the frame's tangent axis; the exact
    // operator does not, so the result is independent of how (t₁, t₂) is chosen.
    let r11 = ee.sqrt();
    let r21 = ff / r11;
    let r22 = (gg - r21 * r21).sqrt();
    let r_inv = Matrix2::new(r11, 0.0, r21, r22).try_inverse()?;
    let second = Matrix2::new(l, m_, m_, nn);
    let s = r_inv * second * r_inv.transpose();
    let eig = SymmetricEigen::new((s + s.transpose()) * 0.5);
    // k = −λ: the graph of a sphere seen from its outward normal has f = −(u²+v²)/2r, λ = −1/r.
    // Directions: the 3D tangent x_u x¹ + x_v x² = (t₁ + d n₀) x¹ + (t₂ + e n₀) x², projected on
    // the tangent plane of n₀ (as libigl reports them), where the metric lives (Sec. 4.1 builds
    // M from (d₁, d₂, d₁ × d₂); Eq. 4 projects onto the plane of d₁, d₂).
    let mut pairs: Vec<(f64, Vector3<f64>)> = (0..2)
        .map(|i| {
            let x = r_inv.transpose() * eig.eigenvectors.column(i);
            (-eig.eigenvalues[i], t1 * x[0] + t2 * x[1])
        })
        .collect();
    pairs.sort_by(|p, q| {
        q.0.abs()
            .total_cmp(&p.0.abs())
            .then_with(|| q.0.total_cmp(&p.0))
    });
    Some(pairs)
}

/// Principal curvatures and directions at every vertex of `mesh` (quadric fit over
/// `opts.radius` rings, see the module doc). Shapes: one entry per vertex, in vertex order.
/// Units: curvature in 1/(mesh units); callers pass the unit-space mesh (Sec. 3.1 notes).
///
/// Unreferenced vertices and vertices whose neighbourhood cannot be fitted (fewer than 5
/// neighbours in their whole component, degenerate geometry) get `k1 = k2 = 0` and a frame from
/// their normal.
/// Deterministic; parallel over vertices.
///
/// Errors: [`MetricError::Mesh`] if the mesh is empty or a coordinate is not finite.
pub fn principal_curvatures(
    mesh: &TriMesh,
    opts: &CurvatureOptions,
) -> Result<Vec<PrincipalCurvature>, MetricError> {
    mesh.validate()?;
    let adj = Adjacency::build(mesh);
    let normals = mesh.vertex_normals();
    let n = mesh.n_vertices();
    let radius = opts.radius.max(1);
    let out = (0..n)
        .into_par_iter()
        .map_init(
            || Scratch::new(n),
            |s, v| {
                s.k_ring(&adj, v, radius);
                fit_vertex(&mesh.positions, &normals, normals[v], v, &s.ring)
            },
        )
        .collect();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_frame_is_right_handed_orthonormal() {
        for n in [
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(1.0, 2.0, -3.0).normalize(),
            Vector3::new(-1.0, 0.0, 0.0),
        ] {
            let (a, b) = tangent_frame(&n);
            assert!((a.norm() - 1.0).abs() < 1e-14 && (b.norm() - 1.0).abs() < 1e-14);
            assert!(a.dot(&n).abs() < 1e-14 && b.dot(&n).abs() < 1e-14);
            assert!((a.cross(&b) - n).norm() < 1e-14);
        }
    }

    #[test]
    fn paraboloid_vertex_has_the_analytic_curvatures() -> Result<(), MetricError> {
        // z = −(x²/2r1 + y²/2r2) on a grid: at the apex k1 = 1/r1 along x, k2 = 1/r2 along y
        // (normal +z, surface bending away from it).
        let (r1, r2) = (0.5, 2.0);
        let nx = 21;
        let mut pos = Vec::new();
        for j in 0..nx {
            for i in 0..nx {
                let x = (i as f64 - 10.0) * 0.01;
                let y = (j as f64 - 10.0) * 0.01;
                pos.push(nalgebra::Point3::new(
                    x,
                    y,
                    -(x * x / (2.0 * r1) + y * y / (2.0 * r2)),
                ));
            }
        }
        let mut tris = Vec::new();
        for j in 0..nx - 1 {
            for i in 0..nx - 1 {
                let a = j * nx + i;
                tris.push([a, a + 1, a + nx + 1]);
                tris.push([a, a + nx + 1, a + nx]);
            }
        }
        let m = TriMesh::from_indices(pos, &tris)?;
        let pc = principal_curvatures(&m, &CurvatureOptions::default())?;
        let apex = &pc[10 * nx + 10];
        assert!((apex.k1 - 1.0 / r1).abs() < 0.01 / r1, "{apex:?}");
        assert!((apex.k2 - 1.0 / r2).abs() < 0.01 / r2, "{apex:?}");
        assert!(apex.d1.x.abs() > 0.999, "{apex:?}");
        assert!(apex.normal.z > 0.999, "{apex:?}");
        Ok(())
    }

    fn wedge(angle: f64) -> Result<TriMesh, MetricError> {
        // A crease z = −0.3x (x > 0), z = 1.2x (x < 0), plus a y² bend: at the crease the vertex
        // normal is far from the fitted surface's normal (d, e ≠ 0 in the frame).
        let (c, s) = (angle.cos(), angle.sin());
        let nx = 21;
        let mut pos = Vec::new();
        for j in 0..nx {
            for i in 0..nx {
                let x = (i as f64 - 10.0) * 0.01;
                let y = (j as f64 - 10.0) * 0.01;
                let z = if x > 0.0 { -0.3 * x } else { 1.2 * x } - y * y;
                pos.push(nalgebra::Point3::new(c * x - s * y, s * x + c * y, z));
            }
        }
        let mut tris = Vec::new();
        for j in 0..nx - 1 {
            for i in 0..nx - 1 {
                let a = j * nx + i;
                tris.push([a, a + 1, a + nx + 1]);
                tris.push([a, a + nx + 1, a + nx]);
            }
        }
        Ok(TriMesh::from_indices(pos, &tris)?)
    }

    #[test]
    fn curvatures_do_not_depend_on_the_frame_tangent_axis_at_a_crease() -> Result<(), MetricError> {
        // Deliberate difference to libigl (paper-notes § 3.1): the exact shape operator is
        // independent of the tangent axis of the fitting frame; libigl's symmetrised one is not
        // when the vertex normal differs from the fitted normal. Rotating the mesh about z changes
        // which axis `tangent_frame` picks relative to the surface.
        let centre = 10 * 21 + 10;
        let a = principal_curvatures(&wedge(0.0)?, &CurvatureOptions::default())?[centre];
        let b = principal_curvatures(&wedge(0.5)?, &CurvatureOptions::default())?[centre];
        assert!(a.k1.abs() > 1.0, "{a:?}");
        assert!((a.k1 - b.k1).abs() < 1e-9 * a.k1.abs(), "{a:?} {b:?}");
        assert!((a.k2 - b.k2).abs() < 1e-9 * a.k1.abs(), "{a:?} {b:?}");
        Ok(())
    }

    #[test]
    fn a_hub_vertex_bounds_every_neighbourhood_and_a_flat_fan_stays_flat() -> Result<(), MetricError>
    {
        // A disk cut as one fan of 20,000 slices: every vertex's 2-ring holds the whole
        // circle. The rings stop at MAX_NEIGHBOURS (the fit was quadratic in the mesh).
        let fan = crate::mesh::generators::disk(1.0, 1, 20_000);
        let adj = Adjacency::build(&fan);
        let mut scratch = Scratch::new(fan.n_vertices());
        let hubs_neighbour = (0..fan.n_vertices())
            .find(|&v| adj.of(v).len() == 3)
            .expect("a circle vertex");
        scratch.k_ring(&adj, hubs_neighbour, 5);
        assert_eq!(scratch.ring.len(), MAX_NEIGHBOURS);
        let pcs = principal_curvatures(&fan, &CurvatureOptions::default())?;
        assert!(pcs.iter().all(|p| p.k1.abs() < 1e-9 && p.k2.abs() < 1e-9));
        Ok(())
    }
}
