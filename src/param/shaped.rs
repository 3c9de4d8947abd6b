//! Convex boundaries shaped after a (non-bijective) LSCM map, for the Tutte initial map of
//! Sec. 3.3. When the free-boundary LSCM self-overlaps the optimiser starts from a Tutte
//! map; Tutte's theorem only needs a convex boundary, and a circle squeezes elongated
//! patches (energy 1e4–1e5 at start). An ellipse with the LSCM boundary's principal axes
//! keeps the bijectivity guarantee (strictly convex) with far less squeeze.

use crate::ids::VertexId;
use crate::mesh::TriMesh;
use nalgebra::{Matrix2, Point2, SymmetricEigen, Vector2};
use std::f64::consts::PI;

/// Boundary positions on the ellipse of the LSCM boundary `lscm_uv` (its principal axes
/// and radii from the second moments of the boundary polygon, weighted by edge length;
/// a uniform point on an ellipse of semi-axis `a` has variance `a²/2` along it), with
/// `boundary[i]` placed by 3D arc length, counter-clockwise, starting at the angle of the
/// first boundary vertex's LSCM position. `None` if the LSCM boundary is degenerate.
pub fn ellipse_boundary(
    disk: &TriMesh,
    boundary: &[VertexId],
    lscm_uv: &[Point2<f64>],
) -> Option<Vec<Point2<f64>>> {
    let m = boundary.len();
    if m < 3 {
        return None;
    }
    let q = |i: usize| lscm_uv[boundary[i % m].idx()];
    // Edge-length-weighted moments of the boundary polygon (edge midpoints).
    let (mut w_sum, mut c) = (0.0, Vector2::zeros());
    for i in 0..m {
        let l = (q(i + 1) - q(i)).norm();
        w_sum += l;
        c += (q(i).coords + q(i + 1).coords) * (0.5 * l);
    }
    if w_sum.is_nan() || w_sum <= 0.0 {
        return None;
    }
    c /= w_sum;
    let mut cov = Matrix2::zeros();
    for i in 0..m {
        let l = (q(i + 1) - q(i)).norm();
        let d = (q(i).coords + q(i + 1).coords) * 0.5 - c;
        cov += d * d.transpose() * (l / w_sum);
    }
    let eig = SymmetricEigen::new(cov);
    let (k1, k2) = if eig.eigenvalues[0] >= eig.eigenvalues[1] {
        (0, 1)
    } else {
        (1, 0)
    };
    let e1: Vector2<f64> = eig.eigenvectors.column(k1).into();
    let e2 = Vector2::new(-e1.y, e1.x);
    let (a, b) = (
        (2.0 * eig.eigenvalues[k1]).max(0.0).sqrt(),
        (2.0 * eig.eigenvalues[k2]).max(0.0).sqrt(),
    );
    if !(b > 0.0 && a.is_finite()) || a / b > 1e6 {
        return None;
    }
    // Arc length of the ellipse (a, b) by a fine polygon, to invert.
    const N: usize = 2048;
    let pt = |th: f64| Vector2::new(a * th.cos(), b * th.sin());
    let mut cum = Vec::with_capacity(N + 1);
    cum.push(0.0);
    for k in 0..N {
        let (t0, t1) = (
            2.0 * PI * k as f64 / N as f64,
            2.0 * PI * (k + 1) as f64 / N as f64,
        );
        let last = cum[k];
        cum.push(last + (pt(t1) - pt(t0)).norm());
    }
    let perim = cum[N];
    // θ of the ellipse point at arc length s (mod perimeter), linear within a piece.
    let theta_at = |s: f64| -> f64 {
        let s = s.rem_euclid(perim);
        let k = cum.partition_point(|&x| x <= s).clamp(1, N) - 1;
        let f = (s - cum[k]) / (cum[k + 1] - cum[k]).max(f64::MIN_POSITIVE);
        2.0 * PI * (k as f64 + f) / N as f64
    };
    // Start: the ellipse angle of the first vertex's LSCM position.
    let d0 = q(0).coords - c;
    let th0 = (d0.dot(&e2) / b)
        .atan2(d0.dot(&e1) / a)
        .rem_euclid(2.0 * PI);
    let s0 = {
        let x = th0 / (2.0 * PI) * N as f64;
        let k = (x.floor() as usize).min(N - 1);
        cum[k] + (x - k as f64) * (cum[k + 1] - cum[k])
    };
    let len: Vec<f64> = (0..m)
        .map(|i| (disk.position(boundary[(i + 1) % m]) - disk.position(boundary[i])).norm())
        .collect();
    let total: f64 = len.iter().sum();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let mut s = 0.0;
    let out = (0..m)
        .map(|i| {
            let th = theta_at(s0 + perim * s / total);
            s += len[i];
            let p = pt(th);
            Point2::from(c + e1 * p.x + e2 * p.y)
        })
        .collect();
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use crate::param::{disk_boundary, lscm};
    use crate::predicates::{orient2d, Sign};

    #[test]
    fn ellipse_boundary_is_strictly_convex_and_counter_clockwise() {
        let m = generators::cone_piece(0.6, 2.5, 0.4, 2.0, 20, 10);
        let b = disk_boundary(&m).unwrap();
        let uv = lscm(&m, &b).unwrap();
        let e = ellipse_boundary(&m, &b, &uv).unwrap();
        let k = e.len();
        for i in 0..k {
            let (p, q, r) = (&e[i], &e[(i + 1) % k], &e[(i + 2) % k]);
            assert_eq!(orient2d(p, q, r), Sign::Positive, "corner {i}");
        }
        // Winding number one: the turning angles sum to 2π.
        let turn: f64 = (0..k)
            .map(|i| {
                let (a, b2) = (e[(i + 1) % k] - e[i], e[(i + 2) % k] - e[(i + 1) % k]);
                a.perp(&b2).atan2(a.dot(&b2))
            })
            .sum();
        assert!((turn - 2.0 * PI).abs() < 1e-9, "{turn}");
    }
}
