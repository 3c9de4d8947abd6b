//! Geometric fidelity of a remeshed patch (our addition to Algorithm 1; paper-notes.md,
//! "Fidelity control").
//!
//! The curvature metric of Sec. 3.1 bounds the chord error only where the estimated curvature
//! is right: with `M = diag(|k₁|, |k₂|)` an edge of metric length `L` has physical length
//! `L/√|k|` and sagitta `|k|·ℓ²/8 = L²/8`, the same everywhere. At sharp tips, rims and
//! creases the quadric fit over a few rings underestimates `|k|` and the remeshed patch cuts
//! them off. This module measures, for a lifted candidate patch, how far it is from the
//! reference surface in both directions, triangle by triangle, and scales the transferred
//! metric up where a triangle deviates by more than the tolerance, so that the planar
//! remesher makes smaller triangles there. The scaling is isotropic (a scalar factor on the
//! tensor), so the triangles keep the metric's anisotropy and their shape quality in it.

//!
//! Files: `measure.rs` (the deviation of a lifted patch and the metric scaling around it),
//! `apriori.rs` (the scaling before the loop, from the input's geometry), `rounds.rs` (the
//! rounds loop of one patch, the metric a patch starts from, and the per-vertex factors kept
//! between patches).

mod apriori;
mod measure;
mod rounds;
#[cfg(test)]
mod tests;

pub use apriori::a_priori_scale;
pub use measure::{deviations, patch_vertex_factors, scale_metric, LiftedPatch, ScaleLimits};
pub use rounds::{
    patch_metrics, refine, PatchFactors, PatchVertices, Refined, RoundOutput, RoundsSetup,
    VertexFactors,
};

use serde::Serialize;

/// Options of the fidelity control.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FidelityOptions {
    /// Largest accepted distance between a patch and the reference surface, in unit space
    /// (i.e. relative to the input's bounding-box diagonal). `0` disables the control.
    pub max_deviation: f64,
    /// Remeshing rounds after the first one, at most.
    pub rounds: usize,
    /// Largest factor by which one round scales a vertex tensor.
    pub max_factor: f64,
    /// No scaling makes the metric's shortest edge shorter than this fraction of the input's
    /// mean edge length: the input is piecewise linear, and triangles much finer than its
    /// own follow it no better (on a flat plate with sharp rims they only multiply).
    pub min_edge_ratio: f64,
    /// Keep, per working-mesh vertex, the factor a patch's extra rounds scaled the metric by,
    /// so a later patch over the same area (its overlap rings, a further sweep) starts from
    /// that refinement instead of the a-priori metric. Default `false` (each patch starts
    /// afresh); the coarse-input profile turns it on.
    pub persist: bool,
}

impl Default for FidelityOptions {
    fn default() -> Self {
        FidelityOptions {
            max_deviation: 0.0035,
            rounds: 2,
            max_factor: 16.0,
            min_edge_ratio: 0.5,
            persist: false,
        }
    }
}
