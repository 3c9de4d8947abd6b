#![forbid(unsafe_code)]
#![doc = include_str!("../README.md")]
//!
//! # Module map (paper order)
//! - [`ids`], [`mesh`], [`io`], [`predicates`], [`invariants`], [`check`]: foundation (typed
//!   ids, the triangle mesh and its topology, file formats, exact predicates, certificates).
//! - [`repair`]: an almost-manifold input made an oriented manifold, every change listed (ours).
//! - [`metric`]: Sec. 3.1 / 4.1, the Riemannian metric field (curvature or user `.sol`).
//! - [`features`]: feature lines kept as patch boundaries (ours).
//! - [`patches`]: Sec. 3.2, cone patches (Eq. 1-3) and the [`patches::PatchStrategy`] registry.
//! - [`param`]: Sec. 3.3, bijective parameterization and the [`param::Parameterizer`] registry.
//! - [`remesh2d`]: Sec. 3.3, metric transfer (Eq. 4), LCT and the
//!   [`remesh2d::PlanarRemesher`] registry.
//! - [`lift`], [`stitch`]: Sec. 3.3 "Mapping back", replacing a patch.
//! - [`fidelity`]: the distance control of a patch (ours).
//! - [`pipeline`]: Algorithm 1, and [`pipeline::Remesher`], the same from file units.
//! - [`job`]: the whole job of `conemesh remesh` and the Python package: repair, Algorithm 1,
//!   the yardstick, the report and the files; the arguments both front ends parse.
//! - [`improve`]: Sec. 3.4, connectivity and vertex position updates on the surface, and
//!   Algorithm 2's planar updates (Eq. 5-6).
//! - [`quality`], [`report`]: Sec. 4.1, the yardstick; JSON and plots.
//! - [`render`]: pictures of a surface coloured by q, angle, patch or distance (Fig. 3, 6).
//! - [`registry`], [`contract`]: the extension points' tables and their contract checks.
//! - [`option_error`]: an option value no run can use, named with its value and range.
//! - [`boundary`]: the input's boundary curves the output's boundary lies on (ours).
//! - [`suite`]: the analytic benchmark cases (surfaces with user-style metrics).
//! - [`compare`]: comparisons of configurations over inputs × seeds, their statistics and
//!   snapshots (ours).

pub mod boundary;
pub mod check;
pub mod compare;
pub mod contract;
pub mod error;
pub mod features;
pub mod fidelity;
pub mod ids;
pub mod improve;
pub mod invariants;
pub mod io;
pub mod job;
pub mod lift;
pub mod mesh;
pub mod metric;
pub mod option_error;
pub mod param;
pub mod patches;
pub mod pipeline;
pub mod predicates;
pub mod quality;
pub mod registry;
pub mod remesh2d;
pub mod render;
pub mod repair;
pub mod report;
pub mod stitch;
pub mod suite;

pub use error::{Error, Result};
pub use ids::{EdgeKey, FaceId, HalfedgeId, PatchId, VertexId};
pub use mesh::{SurfaceLocation, Topology, TriMesh};

/// The seeded random number generator used everywhere (randomness flows from one seed).
pub type Rng = rand_chacha::ChaCha8Rng;
