//! The transferred metric as a field on the parameter domain: the *initial* 2D patch mesh
//! with a 2×2 tensor per vertex, exact point location and barycentric interpolation
//! (Sec. 3.3: "any point of the 2D domain gets its metric by locating it in the initial 2D
//! patch mesh").

use super::{transfer::clamp_spd, Metric2d, Remesh2dError};
use crate::ids::{FaceId, VertexId};
use crate::predicates::{orient2d, Sign};
use nalgebra::{Matrix2, Point2};

/// A piecewise-linear metric field on a planar triangulation (the initial patch mesh).
///
/// Point location is exact ([`orient2d`]) with a uniform bucket grid over the triangles'
/// bounding boxes; interpolation is linear in the tensor entries (a convex combination of
/// SPD tensors is SPD; log-Euclidean interpolation would keep determinants better under
/// strong variation, at several times the cost, and is not needed for the smooth
/// transferred fields).
#[derive(Clone, Debug)]
pub struct PlanarMetricField {
    points: Vec<Point2<f64>>,
    triangles: Vec<[u32; 3]>,
    metrics: Vec<Matrix2<f64>>,
    /// Optional per-triangle corner tensors (see [`PlanarMetricField::with_corner_metrics`]);
    /// when present they replace `metrics` in the interpolation.
    corners: Option<Vec<[Matrix2<f64>; 3]>>,
    lo: Point2<f64>,
    cell: f64,
    nx: usize,
    ny: usize,
    /// For each grid cell, the triangles whose bounding box meets it, ascending.
    buckets: Vec<Vec<u32>>,
}

impl PlanarMetricField {
    /// Build the field. `points`: vertex positions; `triangles`: positively oriented (CCW)
    /// triangles over them; `metrics`: one SPD tensor per point (clamped with
    /// [`clamp_spd`]). Errors name the first bad triangle or point.
    pub fn new(
        points: Vec<Point2<f64>>,
        triangles: Vec<[u32; 3]>,
        metrics: Vec<Matrix2<f64>>,
    ) -> Result<Self, Remesh2dError> {
        if metrics.len() != points.len() {
            return Err(Remesh2dError::CountMismatch {
                elements: points.len(),
                of: "points",
                found: metrics.len(),
                data: "metrics",
            });
        }
        if triangles.is_empty() {
            return Err(Remesh2dError::NoTriangles);
        }
        if let Some(i) = points
            .iter()
            .position(|p| !p.x.is_finite() || !p.y.is_finite())
        {
            return Err(Remesh2dError::NonFinitePoint(VertexId::new(i)));
        }
        for (f, t) in triangles.iter().enumerate() {
            if t.iter().any(|&i| i as usize >= points.len()) {
                return Err(Remesh2dError::VertexOutOfRange(FaceId::new(f)));
            }
            let [a, b, c] = t.map(|i| points[i as usize]);
            if orient2d(&a, &b, &c) != Sign::Positive {
                return Err(Remesh2dError::NotPositive(FaceId::new(f)));
            }
        }
        let metrics = metrics
            .iter()
            .zip(&points)
            .map(|(m, p)| clamp_spd(m).ok_or(Remesh2dError::MetricNotSpd { x: p.x, y: p.y }))
            .collect::<Result<Vec<_>, _>>()?;
        let (mut lo, mut hi) = (points[0], points[0]);
        for p in &points {
            lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        // About one triangle per cell.
        let (w, h) = (
            (hi.x - lo.x).max(f64::MIN_POSITIVE),
            (hi.y - lo.y).max(f64::MIN_POSITIVE),
        );
        let cell = ((w * h) / triangles.len() as f64)
            .sqrt()
            .max(w.max(h) / 4096.0);
        let nx = ((w / cell).floor() as usize + 1).max(1);
        let ny = ((h / cell).floor() as usize + 1).max(1);
        let mut buckets = vec![Vec::new(); nx * ny];
        let mut field = PlanarMetricField {
            points,
            triangles,
            metrics,
            corners: None,
            lo,
            cell,
            nx,
            ny,
            buckets: Vec::new(),
        };
        for (f, t) in field.triangles.iter().enumerate() {
            let ps = t.map(|i| field.points[i as usize]);
            let (x0, y0) = field.cell_of(&Point2::new(
                ps[0].x.min(ps[1].x).min(ps[2].x),
                ps[0].y.min(ps[1].y).min(ps[2].y),
            ));
            let (x1, y1) = field.cell_of(&Point2::new(
                ps[0].x.max(ps[1].x).max(ps[2].x),
                ps[0].y.max(ps[1].y).max(ps[2].y),
            ));
            for cy in y0..=y1 {
                for cx in x0..=x1 {
                    buckets[cy * nx + cx].push(f as u32);
                }
            }
        }
        field.buckets = buckets;
        Ok(field)
    }

    /// Interpolate per-triangle corner tensors instead of the shared vertex tensors: triangle
    /// `f`'s metric at barycentric `l` is `Σ l_k corners[f][k]`. The field is then piecewise
    /// linear and discontinuous across the initial edges. Used for the exact pullback
    /// `J_tᵀ M(v) J_t` of the 3D metric through the parameterization's per-triangle Jacobian
    /// `J_t` (Eq. 4 without averaging the Jacobians of the triangles around a vertex, which
    /// is wrong where they differ much: coarse, strongly curved inputs). Tensors are
    /// clamped with [`clamp_spd`]; errors name the first bad corner.
    pub fn with_corner_metrics(
        mut self,
        corners: Vec<[Matrix2<f64>; 3]>,
    ) -> Result<Self, Remesh2dError> {
        if corners.len() != self.triangles.len() {
            return Err(Remesh2dError::CountMismatch {
                elements: self.triangles.len(),
                of: "triangles",
                found: corners.len(),
                data: "corner metric triples",
            });
        }
        let mut clamped = Vec::with_capacity(corners.len());
        for (t, c) in self.triangles.iter().zip(&corners) {
            let mut out = [Matrix2::zeros(); 3];
            for k in 0..3 {
                let p = self.points[t[k] as usize];
                out[k] = clamp_spd(&c[k]).ok_or(Remesh2dError::MetricNotSpd { x: p.x, y: p.y })?;
            }
            clamped.push(out);
        }
        self.corners = Some(clamped);
        Ok(self)
    }

    /// The grid cell of `p`, clamped to the grid (so that bounding-box corners map inside).
    fn cell_of(&self, p: &Point2<f64>) -> (usize, usize) {
        let fx = ((p.x - self.lo.x) / self.cell).floor();
        let fy = ((p.y - self.lo.y) / self.cell).floor();
        let cx = if fx > 0.0 {
            (fx as usize).min(self.nx - 1)
        } else {
            0
        };
        let cy = if fy > 0.0 {
            (fy as usize).min(self.ny - 1)
        } else {
            0
        };
        (cx, cy)
    }

    /// The triangles (CCW vertex indices) of the initial mesh.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The vertex positions of the initial mesh.
    pub fn points(&self) -> &[Point2<f64>] {
        &self.points
    }

    /// The (clamped) vertex tensors.
    pub fn vertex_metrics(&self) -> &[Matrix2<f64>] {
        &self.metrics
    }

    /// Exact point location: the triangle containing `p` (closed triangle, by `orient2d`) and
    /// the barycentric coordinates of `p` in it (floating point, clamped to `[0, 1]`, summing
    /// to 1). A point on a shared edge or vertex belongs to the lowest-index triangle that
    /// contains it. `None` when `p` is outside the mesh.
    pub fn locate(&self, p: &Point2<f64>) -> Option<(usize, [f64; 3])> {
        if !p.x.is_finite() || !p.y.is_finite() {
            return None;
        }
        let fx = (p.x - self.lo.x) / self.cell;
        let fy = (p.y - self.lo.y) / self.cell;
        // Points outside the grid are outside every triangle's bounding box... except for
        // rounding in the division, so look at the clamped cell anyway.
        if fx < -1.0 || fy < -1.0 || fx > self.nx as f64 + 1.0 || fy > self.ny as f64 + 1.0 {
            return None;
        }
        // The cell index is monotone in the coordinates (rounded subtraction and division are
        // monotone), so a triangle containing p was registered in p's own cell.
        let (cx, cy) = self.cell_of(p);
        let best = self.buckets[cy * self.nx + cx]
            .iter()
            .copied()
            .find(|&f| self.contains(f as usize, p));
        best.map(|f| (f as usize, self.barycentric(f as usize, p)))
    }

    /// [`PlanarMetricField::locate`], or outside the mesh the nearest triangle and the
    /// clamped barycentric coordinates of `p` in it (the nearest point of the mesh).
    pub fn locate_or_nearest(&self, p: &Point2<f64>) -> (usize, [f64; 3]) {
        self.locate(p).unwrap_or_else(|| {
            let f = self.nearest_triangle(p);
            (f, self.barycentric(f, p))
        })
    }

    /// `true` when `p` lies in the closed triangle `f` (exact).
    fn contains(&self, f: usize, p: &Point2<f64>) -> bool {
        let [a, b, c] = self.triangles[f].map(|i| self.points[i as usize]);
        orient2d(&a, &b, p) != Sign::Negative
            && orient2d(&b, &c, p) != Sign::Negative
            && orient2d(&c, &a, p) != Sign::Negative
    }

    /// Barycentric coordinates of `p` in triangle `f`, clamped to `[0, 1]` and normalised.
    pub fn barycentric(&self, f: usize, p: &Point2<f64>) -> [f64; 3] {
        let [a, b, c] = self.triangles[f].map(|i| self.points[i as usize]);
        let area = (b - a).perp(&(c - a));
        let l0 = (b - p).perp(&(c - p)) / area;
        let l1 = (c - p).perp(&(a - p)) / area;
        let l2 = (a - p).perp(&(b - p)) / area;
        let l = [l0, l1, l2].map(|x| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                0.0
            }
        });
        let s = l[0] + l[1] + l[2];
        if s > 0.0 {
            l.map(|x| x / s)
        } else {
            [1.0 / 3.0; 3]
        }
    }

    /// The triangle nearest to `p` (Euclidean distance), by a scan; used only when `p` is
    /// outside the mesh through rounding.
    fn nearest_triangle(&self, p: &Point2<f64>) -> usize {
        // The triangles registered in the cells around p's (clamped) cell first: a point
        // just outside the mesh has its nearest triangle there; the full scan only when those
        // cells are empty.
        let (cx, cy) = self.cell_of(p);
        let mut near: Vec<u32> = Vec::new();
        for y in cy.saturating_sub(1)..(cy + 2).min(self.ny) {
            for x in cx.saturating_sub(1)..(cx + 2).min(self.nx) {
                near.extend_from_slice(&self.buckets[y * self.nx + x]);
            }
        }
        let dist = |f: usize| {
            let [a, b, c] = self.triangles[f].map(|i| self.points[i as usize]);
            [(a, b), (b, c), (c, a)]
                .iter()
                .map(|(u, v)| seg_dist2(p, u, v))
                .fold(f64::INFINITY, f64::min)
        };
        if let Some(f) = near
            .iter()
            .map(|&f| f as usize)
            .min_by(|&f, &g| dist(f).total_cmp(&dist(g)).then(f.cmp(&g)))
        {
            return f;
        }
        let mut best = (f64::INFINITY, 0usize);
        for (f, t) in self.triangles.iter().enumerate() {
            let [a, b, c] = t.map(|i| self.points[i as usize]);
            let d = [(a, b), (b, c), (c, a)]
                .iter()
                .map(|(u, v)| seg_dist2(p, u, v))
                .fold(f64::INFINITY, f64::min);
            if d < best.0 {
                best = (d, f);
            }
        }
        best.1
    }

    /// The interpolated tensor in triangle `f` at barycentric `l`.
    fn interpolate(&self, f: usize, l: [f64; 3]) -> Matrix2<f64> {
        if let Some(c) = self.corners.as_ref().and_then(|c| c.get(f)) {
            return c[0] * l[0] + c[1] * l[1] + c[2] * l[2];
        }
        let t = self.triangles[f];
        self.metrics[t[0] as usize] * l[0]
            + self.metrics[t[1] as usize] * l[1]
            + self.metrics[t[2] as usize] * l[2]
    }
}

/// Squared distance from `p` to the segment `[a, b]`.
fn seg_dist2(p: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).norm_squared()
}

impl Metric2d for PlanarMetricField {
    /// Locate `p` and interpolate the vertex tensors linearly; a point outside the mesh
    /// (only possible through rounding for certified interior points) takes the value at the
    /// closest point of the nearest triangle.
    fn metric(&self, p: &Point2<f64>) -> Matrix2<f64> {
        match self.locate(p) {
            Some((f, l)) => self.interpolate(f, l),
            None => {
                let f = self.nearest_triangle(p);
                let l = self.barycentric(f, p);
                self.interpolate(f, l)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2×2 grid of squares, each split in two.
    fn grid() -> Result<PlanarMetricField, Remesh2dError> {
        let mut pts = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                pts.push(Point2::new(i as f64, j as f64));
            }
        }
        let mut tris = Vec::new();
        for j in 0..2u32 {
            for i in 0..2u32 {
                let a = j * 3 + i;
                tris.push([a, a + 1, a + 4]);
                tris.push([a, a + 4, a + 3]);
            }
        }
        let metrics = pts
            .iter()
            .map(|p| Matrix2::new(1.0 + p.x, 0.0, 0.0, 1.0 + p.y))
            .collect();
        PlanarMetricField::new(pts, tris, metrics)
    }

    #[test]
    fn locate_is_exact_on_vertices_and_edges() -> Result<(), Remesh2dError> {
        let f = grid()?;
        // Every vertex and every edge midpoint (exact in binary) is located, in a triangle
        // that contains it, and the lowest such triangle.
        for (i, p) in f.points().iter().enumerate() {
            let (t, l) = f.locate(p).unwrap_or_else(|| panic!("v{i} is not located"));
            let first = (0..f.triangles().len()).find(|&k| f.contains(k, p));
            assert_eq!(Some(t), first, "v{i}");
            let k = f.triangles()[t].iter().position(|&v| v as usize == i);
            assert!(k.is_some_and(|k| l[k] == 1.0), "v{i} barycentric {l:?}");
        }
        for t in f.triangles().to_vec() {
            for k in 0..3 {
                let (a, b) = (
                    f.points()[t[k] as usize],
                    f.points()[t[(k + 1) % 3] as usize],
                );
                let m = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
                let (tri, l) = f.locate(&m).expect("an edge midpoint is located");
                assert!(f.contains(tri, &m));
                assert_eq!(
                    Some(tri),
                    (0..f.triangles().len()).find(|&q| f.contains(q, &m))
                );
                assert!(l.contains(&0.0), "edge point has a zero coordinate");
            }
        }
        // Outside.
        assert_eq!(f.locate(&Point2::new(2.0 + 1e-15, 1.0)), None);
        assert_eq!(f.locate(&Point2::new(-1e-300, 0.5)), None);
        Ok(())
    }

    #[test]
    fn metric_interpolates_linearly() -> Result<(), Remesh2dError> {
        let f = grid()?;
        let m = f.metric(&Point2::new(0.25, 1.5));
        assert!((m - Matrix2::new(1.25, 0.0, 0.0, 2.5)).norm() < 1e-12);
        // Outside by rounding: the nearest value.
        let m = f.metric(&Point2::new(2.0 + 1e-12, 1.0));
        assert!((m - Matrix2::new(3.0, 0.0, 0.0, 2.0)).norm() < 1e-9);
        Ok(())
    }

    /// Corner tensors replace the vertex tensors: the field is linear in each triangle
    /// between its own corners and jumps across a shared edge.
    #[test]
    fn corner_metrics_interpolate_per_triangle() -> Result<(), Remesh2dError> {
        let points = vec![
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(0.0, 1.0),
            Point2::new(1.0, 1.0),
        ];
        let triangles = vec![[0, 1, 2], [1, 3, 2]];
        let id = Matrix2::identity();
        let f = PlanarMetricField::new(points, triangles, vec![id; 4])?;
        let a = Matrix2::new(4.0, 0.0, 0.0, 1.0);
        let b = Matrix2::new(1.0, 0.0, 0.0, 9.0);
        let f = f.with_corner_metrics(vec![[a, a, a], [b, b * 2.0, b]])?;
        assert!((f.metric(&Point2::new(0.2, 0.2)) - a).norm() < 1e-12);
        // Centroid of the second triangle: the mean of its corners.
        let c = f.metric(&Point2::new(2.0 / 3.0, 2.0 / 3.0));
        assert!((c - b * (4.0 / 3.0)).norm() < 1e-12, "{c}");
        assert!(f.clone().with_corner_metrics(vec![[a; 3]]).is_err());
        Ok(())
    }

    #[test]
    fn field_is_send_sync() {
        fn check<T: Send + Sync>() {}
        check::<PlanarMetricField>();
        check::<crate::remesh2d::Lct>();
    }

    #[test]
    fn rejects_clockwise_triangles() {
        let pts = vec![
            Point2::new(0.0, 0.0),
            Point2::new(0.0, 1.0),
            Point2::new(1.0, 0.0),
        ];
        let r = PlanarMetricField::new(pts, vec![[0, 1, 2]], vec![Matrix2::identity(); 3]);
        assert!(matches!(r, Err(Remesh2dError::NotPositive(FaceId(0)))));
    }
}
