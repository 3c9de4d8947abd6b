//! The standalone 2D mesher's demonstration cases (`examples/remesh2d.rs`, snapshot test):
//! two domains × three analytic metrics.

use super::{
    planar_quality, resample_polygon, triangulate_polygon, Lct, Metric2d, PlanarMesh,
    PlanarQuality, PlanarRemesher, Remesh2dError,
};
use nalgebra::{Matrix2, Point2};
use rand::SeedableRng;

/// An analytic metric of the demonstration.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum DemoMetric {
    /// `M = I`.
    UniformIsotropic,
    /// `M = diag(1, 100)`: edges 10× shorter along y.
    ConstantAnisotropic,
    /// A boundary layer at `y = 0`: `M = diag(1/hx², 1/hy(y)²)` with `hx = 0.1` and
    /// `hy = 0.01 + 0.09·(1 − e^{−y/0.3})` (anisotropy 10 at the wall, 1 far away).
    BoundaryLayer,
}

impl Metric2d for DemoMetric {
    fn metric(&self, p: &Point2<f64>) -> Matrix2<f64> {
        match self {
            DemoMetric::UniformIsotropic => Matrix2::identity(),
            DemoMetric::ConstantAnisotropic => Matrix2::new(1.0, 0.0, 0.0, 100.0),
            DemoMetric::BoundaryLayer => {
                let hx = 0.1;
                let hy = 0.01 + 0.09 * (1.0 - (-p.y.max(0.0) / 0.3).exp());
                Matrix2::new(1.0 / (hx * hx), 0.0, 0.0, 1.0 / (hy * hy))
            }
        }
    }
}

impl DemoMetric {
    /// Short name.
    pub fn name(&self) -> &'static str {
        match self {
            DemoMetric::UniformIsotropic => "uniform",
            DemoMetric::ConstantAnisotropic => "aniso(1,100)",
            DemoMetric::BoundaryLayer => "boundary-layer",
        }
    }
    /// The target metric length used for this metric in the demonstration.
    pub fn target_length(&self) -> f64 {
        match self {
            DemoMetric::UniformIsotropic => 0.05,
            DemoMetric::ConstantAnisotropic => 0.25,
            DemoMetric::BoundaryLayer => 0.5,
        }
    }
}

/// A demonstration domain.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum DemoDomain {
    /// The unit square.
    Square,
    /// The unit square minus its upper-right quarter.
    LShape,
}

impl DemoDomain {
    /// Short name.
    pub fn name(&self) -> &'static str {
        match self {
            DemoDomain::Square => "square",
            DemoDomain::LShape => "L-shape",
        }
    }
    /// Counter-clockwise corners.
    pub fn corners(&self) -> Vec<Point2<f64>> {
        let p = Point2::new;
        match self {
            DemoDomain::Square => vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
            DemoDomain::LShape => vec![
                p(0.0, 0.0),
                p(1.0, 0.0),
                p(1.0, 0.5),
                p(0.5, 0.5),
                p(0.5, 1.0),
                p(0.0, 1.0),
            ],
        }
    }
}

/// All six cases, in table order.
pub fn demo_cases() -> Vec<(DemoDomain, DemoMetric)> {
    let mut v = Vec::new();
    for d in [DemoDomain::Square, DemoDomain::LShape] {
        for m in [
            DemoMetric::UniformIsotropic,
            DemoMetric::ConstantAnisotropic,
            DemoMetric::BoundaryLayer,
        ] {
            v.push((d, m));
        }
    }
    v
}

/// Build the initial domain (sides resampled to the target metric length, the constrained
/// Delaunay triangulation of that polygon with no interior points), remesh it with the default
/// [`Lct`] (seed 7) and measure it. (A regular grid of interior points is a worse start: the
/// right-triangle lattice is close to a stationary point of the LCT energy, paper-notes.md.)
pub fn run_demo_case(
    domain: DemoDomain,
    metric: DemoMetric,
    target_length: f64,
) -> Result<(PlanarMesh, PlanarQuality), Remesh2dError> {
    let boundary = resample_polygon(&domain.corners(), &metric, target_length);
    let dom = triangulate_polygon(&boundary, &[])?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let out = Lct::default().remesh(&dom, &metric, target_length, &mut rng)?;
    let q = planar_quality(&out, &metric, target_length);
    Ok((out, q))
}
