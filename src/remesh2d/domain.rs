//! Building planar domains for the standalone 2D mesher: resample a polygon's sides to a
//! metric length, triangulate it (spade's constrained Delaunay triangulation).

use super::{Metric2d, PlanarDomain, Remesh2dError};
use crate::invariants::PolygonSlabs;
use nalgebra::Point2;
use spade::{ConstrainedDelaunayTriangulation, Triangulation};
use std::collections::HashMap;

/// Metric length of the segment `[a, b]`, integrated with `n` midpoint samples.
pub fn metric_length(metric: &dyn Metric2d, a: &Point2<f64>, b: &Point2<f64>, n: usize) -> f64 {
    let e = b - a;
    let n = n.max(1);
    (0..n)
        .map(|i| {
            let t = (i as f64 + 0.5) / n as f64;
            let m = metric.metric(&(a + e * t));
            (e.dot(&(m * e))).max(0.0).sqrt() / n as f64
        })
        .sum()
}

/// Subdivide every side of the closed polygon `corners` so that its pieces have metric length
/// close to `target_length` (each side gets `max(1, round(len / target_length))` pieces at
/// equal metric-length spacing, 64 samples per side; at most 2^20 pieces). Corners are kept
/// bit for bit, in order.
pub fn resample_polygon(
    corners: &[Point2<f64>],
    metric: &dyn Metric2d,
    target_length: f64,
) -> Vec<Point2<f64>> {
    const SAMPLES: usize = 64;
    const MAX_PIECES: usize = 1 << 20;
    let mut out = Vec::new();
    let n = corners.len();
    for i in 0..n {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        out.push(a);
        let e = b - a;
        // Cumulative metric length at the sample boundaries.
        let mut cum = vec![0.0];
        for k in 0..SAMPLES {
            let t0 = k as f64 / SAMPLES as f64;
            let t1 = (k + 1) as f64 / SAMPLES as f64;
            let l = metric_length(metric, &(a + e * t0), &(a + e * t1), 1);
            cum.push(cum[k] + l);
        }
        let total = cum[SAMPLES];
        if !(total.is_finite() && target_length > 0.0) {
            continue;
        }
        // Capped: a target many orders below the edge would exhaust memory.
        let pieces = ((total / target_length).round() as usize).clamp(1, MAX_PIECES);
        for j in 1..pieces {
            let s = total * j as f64 / pieces as f64;
            let k = cum.partition_point(|&c| c < s).clamp(1, SAMPLES);
            let (c0, c1) = (cum[k - 1], cum[k]);
            let f = if c1 > c0 { (s - c0) / (c1 - c0) } else { 0.5 };
            let t = ((k - 1) as f64 + f) / SAMPLES as f64;
            out.push(a + e * t);
        }
    }
    out
}

/// Triangulate the simple polygon `boundary` (counter-clockwise, no repeated points) with the
/// extra `interior` points (those not strictly inside the polygon are dropped), by spade's
/// constrained Delaunay triangulation. The domain's points are `boundary` then the kept
/// interior points; its boundary loop is `0..boundary.len()`.
pub fn triangulate_polygon(
    boundary: &[Point2<f64>],
    interior: &[Point2<f64>],
) -> Result<PlanarDomain, Remesh2dError> {
    triangulate_polygon_with(boundary, interior).map(|(d, _)| d)
}

/// [`triangulate_polygon`], also returning which `interior` points were kept (their indices
/// into `interior`, in order: the domain's points after the boundary).
pub fn triangulate_polygon_with(
    boundary: &[Point2<f64>],
    interior: &[Point2<f64>],
) -> Result<(PlanarDomain, Vec<usize>), Remesh2dError> {
    let nb = boundary.len();
    if nb < 3 {
        return Err(Remesh2dError::ShortPolygon(nb));
    }
    let area2: f64 = (0..nb)
        .map(|i| boundary[i].coords.perp(&boundary[(i + 1) % nb].coords))
        .sum();
    if area2.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(Remesh2dError::Clockwise);
    }
    let mut points: Vec<Point2<f64>> = boundary.to_vec();
    let inside = PolygonSlabs::new(boundary);
    let kept: Vec<usize> = (0..interior.len())
        .filter(|&i| inside.contains(&interior[i]) == Some(true))
        .collect();
    points.extend(kept.iter().map(|&i| interior[i]));
    let verts: Vec<spade::Point2<f64>> = points
        .iter()
        .map(|p| spade::Point2::new(p.x, p.y))
        .collect();
    let edges: Vec<[usize; 2]> = (0..nb).map(|i| [i, (i + 1) % nb]).collect();
    let mut conflict = false;
    let cdt: ConstrainedDelaunayTriangulation<spade::Point2<f64>> =
        ConstrainedDelaunayTriangulation::try_bulk_load_cdt(verts, edges, |_| conflict = true)
            .map_err(Remesh2dError::Triangulation)?;
    if conflict || cdt.num_vertices() != points.len() {
        return Err(Remesh2dError::SelfIntersecting);
    }
    let all: Vec<[u32; 3]> = cdt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    // Keep the faces inside the polygon (the CDT covers the convex hull), exactly: a face with
    // a polygon side traversed i → i+1 is inside (faces are CCW, the polygon is CCW), one with
    // a side traversed i+1 → i is outside, and the status floods across non-polygon edges.
    let nbu = nb as u32;
    let is_side = |a: u32, b: u32| a < nbu && b < nbu && ((a + 1) % nbu == b || (b + 1) % nbu == a);
    let mut he: HashMap<(u32, u32), usize> = HashMap::new();
    for (f, t) in all.iter().enumerate() {
        for k in 0..3 {
            he.insert((t[k], t[(k + 1) % 3]), f);
        }
    }
    let mut inside: Vec<Option<bool>> = vec![None; all.len()];
    let mut stack = Vec::new();
    for (f, t) in all.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if is_side(a, b) {
                inside[f] = Some(a < nbu && (a + 1) % nbu == b);
                stack.push(f);
                break;
            }
        }
    }
    while let Some(f) = stack.pop() {
        let t = all[f];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if is_side(a, b) {
                continue;
            }
            if let Some(&g) = he.get(&(b, a)) {
                if inside[g].is_none() {
                    inside[g] = inside[f];
                    stack.push(g);
                }
            }
        }
    }
    let triangles: Vec<[u32; 3]> = all
        .iter()
        .zip(&inside)
        .filter(|(_, s)| **s == Some(true))
        .map(|(t, _)| *t)
        .collect();
    let dom = PlanarDomain {
        points,
        triangles,
        boundary: (0..nb as u32).collect(),
        constrained_edges: Vec::new(),
    };
    // Collinear-looking sides can make spade split a side at a point: check the result.
    let identity = super::PlanarMesh {
        points: dom.points.clone(),
        triangles: dom.triangles.clone(),
        origin: (0..dom.points.len() as u32).map(Some).collect(),
    };
    crate::invariants::certify_planar(&dom, &identity).map_err(Remesh2dError::InvalidDomain)?;
    Ok((dom, kept))
}
