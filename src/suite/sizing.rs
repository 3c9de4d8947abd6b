//! The metric kinds of the analytic suite: a size across and a size along a tangent direction
//! at every surface point, turned into a 3×3 tensor by [`Frame::tensor`].

use crate::mesh::generators::Hole;
use nalgebra::{Matrix3, Point3, Vector3};
use std::f64::consts::PI;

/// The metric at a surface point: size `h_across` along the unit tangent `across`, `h_along`
/// along the unit tangent `along` (orthogonal to `across`), and the surface's unit `normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Unit tangent across the anisotropy (the fine direction of a boundary layer or shock).
    pub across: Vector3<f64>,
    /// Target edge length across, in file units.
    pub h_across: f64,
    /// Unit tangent along the anisotropy (`normal × across`).
    pub along: Vector3<f64>,
    /// Target edge length along, in file units.
    pub h_along: f64,
    /// Unit surface normal.
    pub normal: Vector3<f64>,
}

impl Frame {
    /// `M = across acrossᵀ/h_across² + along alongᵀ/h_along² + n nᵀ/h_n²` with
    /// `h_n = min(h_across, h_along)`: an edge of length h_across across (h_along along) has
    /// metric length 1. The normal part makes M SPD in 3D, which MMG requires; conemesh uses
    /// the metric on the tangent plane only.
    pub fn tensor(&self) -> Matrix3<f64> {
        let h_n = self.h_across.min(self.h_along);
        self.across * self.across.transpose() / (self.h_across * self.h_across)
            + self.along * self.along.transpose() / (self.h_along * self.h_along)
            + self.normal * self.normal.transpose() / (h_n * h_n)
    }

    /// `h_along / h_across`.
    pub fn ratio(&self) -> f64 {
        self.h_along / self.h_across
    }
}

/// A tangent direction field (the "along" direction of [`Sizing::Aligned`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Along {
    /// A fixed direction of space, projected on the tangent plane.
    Fixed([f64; 3]),
    /// The circles around the line through `centre` along the unit `axis` (on a surface of
    /// revolution about it: the parallels), turned by `tilt` radians in the tangent plane
    /// towards `normal × circle` (on the cylinder, whose axis it is, a helix of angle `tilt`).
    /// Undefined on the axis itself.
    AroundAxis {
        /// A point of the axis.
        centre: [f64; 3],
        /// Unit direction of the axis.
        axis: [f64; 3],
        /// Angle to the circles, radians.
        tilt: f64,
    },
}

/// A curve of the surface that a boundary layer or a shock follows, given by a distance
/// function whose gradient is the direction across the curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Curve {
    /// Where the surface meets the plane through `point` with unit `normal`: distance
    /// `|(p − point)·normal|` (the height above the plane), across = the plane's normal.
    Plane {
        /// A point of the plane.
        point: [f64; 3],
        /// Unit normal of the plane.
        normal: [f64; 3],
    },
    /// Circles of the xy plane, the nearest one: distance `| |p − c| − r |` (p projected on the
    /// xy plane), across = radial from the nearest circle's centre.
    Circles(&'static [Hole]),
    /// The sine line `y = y0 + amplitude·sin(2πx / wavelength)` of the xy plane: distance
    /// `|φ| / |∇φ|` with `φ = y − y0 − amplitude·sin(2πx / wavelength)` (the first-order
    /// distance, exact on the line), across = `∇φ / |∇φ|`.
    Sine {
        /// Mean height of the line.
        y0: f64,
        /// Amplitude.
        amplitude: f64,
        /// Wavelength along x.
        wavelength: f64,
    },
}

/// A metric of the kind simulation users bring, as sizes in file units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sizing {
    /// `M = I / h²`.
    Isotropic {
        /// Edge length.
        h: f64,
    },
    /// Constant sizes `h_across × h_along` along a direction field (constant anisotropy when
    /// the field is [`Along::Fixed`], turning directions otherwise). Within `core` of an
    /// [`Along::AroundAxis`] field's axis, where the circles shrink to a point, the ratio blends
    /// smoothly to 1: `h_along = h_across·(h_along/h_across)^s(ρ/core)`, ρ the distance to the
    /// axis, s the smoothstep `3t² − 2t³` (0 = no blend).
    Aligned {
        /// The along direction.
        along: Along,
        /// Size across.
        h_across: f64,
        /// Size along.
        h_along: f64,
        /// Blend radius around the axis (0 = none).
        core: f64,
    },
    /// A boundary layer on a wall: across, `h0 + growth·d` (d the distance to the wall) up to
    /// `h_far`; along, `h_far`. Isotropic at `h_far` from `d = (h_far − h0)/growth` on.
    BoundaryLayer {
        /// The wall.
        wall: Curve,
        /// Size across at the wall.
        h0: f64,
        /// Growth of the size across per unit distance.
        growth: f64,
        /// Size along the wall, and everywhere far from it.
        h_far: f64,
    },
    /// A shock: across, `h_coarse − (h_coarse − h_fine)·exp(−(d/width)²)` (d the distance to
    /// the front: `h_fine` on it, smoothly back to `h_coarse`); along, `h_coarse`.
    Shock {
        /// The front.
        front: Curve,
        /// Size across on the front.
        h_fine: f64,
        /// Size along the front, and everywhere far from it.
        h_coarse: f64,
        /// Width of the transition.
        width: f64,
    },
}

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// `v` projected on the plane orthogonal to the unit `n`, normalized; any unit tangent when
/// `v` is (nearly) parallel to `n`. The only callers are where such a `v` comes with an
/// isotropic size (on an axis, at a pole), so the choice does not change the tensor.
fn tangent(v: &Vector3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
    let t = v - n * v.dot(n);
    if t.norm() > 1e-9 * v.norm() && t.norm() > 0.0 {
        return t.normalize();
    }
    // The coordinate axis least aligned with n, projected.
    let e = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        Vector3::x()
    } else if n.y.abs() <= n.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    (e - n * e.dot(n)).normalize()
}

fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Along {
    /// The unit along direction at `p` (unit normal `n`) and the distance to the field's axis
    /// (infinite for a fixed direction).
    pub fn at(&self, p: &Point3<f64>, n: &Vector3<f64>) -> (Vector3<f64>, f64) {
        match *self {
            Along::Fixed(d) => (tangent(&v3(d), n), f64::INFINITY),
            Along::AroundAxis { centre, axis, tilt } => {
                let c = v3(axis).cross(&(p.coords - v3(centre)));
                let rho = c.norm();
                let circle = tangent(&c, n);
                let turned = circle * tilt.cos() + n.cross(&circle) * tilt.sin();
                (tangent(&turned, n), rho)
            }
        }
    }
}

impl Curve {
    /// The distance from `p` to the curve and the (not yet tangent) direction across it.
    pub fn distance(&self, p: &Point3<f64>) -> (f64, Vector3<f64>) {
        match *self {
            Curve::Plane { point, normal } => {
                let n = v3(normal);
                ((p.coords - v3(point)).dot(&n).abs(), n)
            }
            Curve::Circles(circles) => circles
                .iter()
                .map(|h| {
                    let r = Vector3::new(p.x - h.centre[0], p.y - h.centre[1], 0.0);
                    let dir = if r.norm() > 0.0 {
                        r / r.norm()
                    } else {
                        Vector3::x()
                    };
                    ((r.norm() - h.radius).abs(), dir)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap_or((f64::INFINITY, Vector3::x())),
            Curve::Sine {
                y0,
                amplitude,
                wavelength,
            } => {
                let k = 2.0 * PI / wavelength;
                let phi = p.y - y0 - amplitude * (k * p.x).sin();
                let grad = Vector3::new(-amplitude * k * (k * p.x).cos(), 1.0, 0.0);
                (phi.abs() / grad.norm(), grad / grad.norm())
            }
        }
    }
}

impl Sizing {
    /// The metric's frame at the surface point `p` with unit normal `n`.
    pub fn frame(&self, p: &Point3<f64>, n: &Vector3<f64>) -> Frame {
        let with_across = |across: Vector3<f64>, h_across: f64, h_along: f64| {
            let across = tangent(&across, n);
            Frame {
                across,
                h_across,
                along: n.cross(&across),
                h_along,
                normal: *n,
            }
        };
        match *self {
            Sizing::Isotropic { h } => with_across(Vector3::x(), h, h),
            Sizing::Aligned {
                along,
                h_across,
                h_along,
                core,
            } => {
                let (dir, rho) = along.at(p, n);
                let s = if core > 0.0 {
                    smoothstep(rho / core)
                } else {
                    1.0
                };
                let h_along = h_across * (h_along / h_across).powf(s);
                Frame {
                    across: n.cross(&dir),
                    h_across,
                    along: dir,
                    h_along,
                    normal: *n,
                }
            }
            Sizing::BoundaryLayer {
                wall,
                h0,
                growth,
                h_far,
            } => {
                let (d, across) = wall.distance(p);
                with_across(across, (h0 + growth * d).min(h_far), h_far)
            }
            Sizing::Shock {
                front,
                h_fine,
                h_coarse,
                width,
            } => {
                let (d, across) = front.distance(p);
                let h = h_coarse - (h_coarse - h_fine) * (-(d / width).powi(2)).exp();
                with_across(across, h, h_coarse)
            }
        }
    }

    /// One line for a table: kind, sizes and ratio.
    pub fn describe(&self) -> String {
        match *self {
            Sizing::Isotropic { h } => format!("isotropic h = {h}"),
            Sizing::Aligned {
                along,
                h_across,
                h_along,
                core,
            } => {
                let field = match along {
                    Along::Fixed(d) => format!("along {d:?}"),
                    Along::AroundAxis { tilt, .. } if tilt != 0.0 => {
                        format!("along circles turned {:.0}°", tilt.to_degrees())
                    }
                    Along::AroundAxis { .. } => "along circles around an axis".to_string(),
                };
                let blend = if core > 0.0 {
                    format!(", isotropic blend within {core} of the axis")
                } else {
                    String::new()
                };
                format!(
                    "{h_across} across × {h_along} {field} (ratio {:.0}){blend}",
                    h_along / h_across
                )
            }
            Sizing::BoundaryLayer {
                h0, growth, h_far, ..
            } => format!(
                "boundary layer: across min({h0} + {growth}·d, {h_far}), along {h_far} (ratio {:.0} at the wall)",
                h_far / h0
            ),
            Sizing::Shock {
                h_fine,
                h_coarse,
                width,
                ..
            } => format!(
                "shock: across {h_coarse} − {}·exp(−(d/{width})²), along {h_coarse} (ratio {:.0} on the front)",
                h_coarse - h_fine,
                h_coarse / h_fine
            ),
        }
    }
}
