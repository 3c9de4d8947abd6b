//! Quality improvement after the loop of Algorithm 1 (Sec. 3.4).
//!
//! Algorithm 2 of the paper improves the triangles of poor quality by the two updates of
//! Sec. 3.4, the *connectivity update* (edge flips) and the *vertex position update*. Here
//! they run on the surface itself, directly on the working mesh after the loop:
//! [`connectivity_update`] flips edges where the smaller metric quality of their two faces
//! rises, [`vertex_position_update`] moves vertices along the reference surface where the
//! worst face around them improves. The seams between patches are where they matter most:
//! their vertices and edges were fixed patch-boundary elements while the patches were
//! remeshed. Every change is a candidate certified like a patch's new faces (not degenerate,
//! not flipped, locally embedded) and keeps the surface within the distance tolerance.
//! Algorithm 2 proper, which re-parameterizes a cone patch around each bad triangle and runs
//! the two updates in its plane on the energy of Eq. 5-6, is `eq5.rs` (the planar updates, a
//! [`crate::remesh2d::PlanarRemesher`]) driven by `pipeline/algorithm2.rs` (opt-in,
//! `--improve`); how the two differ and what each measured: paper-notes.md, Sec. 3.4.
//!
//! Files: `flips.rs` (connectivity update), `relocate.rs` (vertex position update),
//! `geometry.rs` (the helpers they share), `eq5.rs` (Algorithm 2's planar updates).

pub mod eq5;
mod flips;
mod geometry;
mod relocate;

pub use eq5::{Eq5Improver, Eq5Options, FlipRule, Target};
pub use flips::connectivity_update;
pub use relocate::vertex_position_update;

use crate::ids::EdgeKey;
use crate::invariants::FlipTest;
use crate::metric::MetricField;
use crate::stitch::WorkingMesh;
use std::collections::HashSet;

/// What the surface passes read: the metric, the flip certificate, the tolerance, and the
/// elements they must leave alone.
#[derive(Clone, Copy)]
pub struct SurfaceContext<'a> {
    /// The metric every quality is measured in (the unscaled one, as `conemesh eval`).
    pub field: &'a MetricField,
    /// The flip certificate against the reference.
    pub flip_test: &'a FlipTest,
    /// Check candidates for local self-intersections (only for an embedded input).
    pub embedded_input: bool,
    /// How far a change may move the surface (unit space); `f64::INFINITY` when the distance
    /// control is off.
    pub tol: f64,
    /// Edges no flip may remove (feature lines).
    pub feature_edges: Option<&'a HashSet<EdgeKey>>,
    /// `pinned[v]`: vertex `v` may not move (corners and feature-line vertices).
    pub pinned: &'a [bool],
    /// The input's boundary curves, along which boundary vertices may slide.
    pub curves: Option<&'a crate::boundary::BoundaryCurves>,
    /// Slide boundary vertices along the input's boundary curves (not with the input's
    /// boundary kept bit for bit).
    pub slide_boundary: bool,
}

/// What [`finishing_passes`] did.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct PassCounts {
    /// Edges flipped.
    pub flips: usize,
    /// Vertices moved.
    pub moves: usize,
}

/// The passes after the loop: the connectivity update (with `flips`), then the vertex
/// position update followed by the connectivity update again (with `relocate`).
pub fn finishing_passes(
    ctx: &SurfaceContext<'_>,
    work: &mut WorkingMesh,
    flips: bool,
    relocate: bool,
) -> PassCounts {
    let mut counts = PassCounts::default();
    if flips {
        counts.flips = connectivity_update(ctx, work);
    }
    if relocate {
        counts.moves = vertex_position_update(ctx, work);
        counts.flips += connectivity_update(ctx, work);
    }
    counts
}

#[cfg(test)]
mod tests;
