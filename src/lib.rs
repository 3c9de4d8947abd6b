#![forbid(unsafe_code)]
#![doc = include_str!("../README.md")]
//!
//! # Module map (paper order)
//! - [`mesh`], [`ids`], [`io`], [`predicates`], [`invariants`]: foundation.
//! - [`metric`]: Sec. 3.1 / 4.1, the Riemannian metric field.
//! - [`patches`]: Sec. 3.2, cone patches (Eq. 1-3).
//! - [`param`]: Sec. 3.3, bijective parameterization.
//! - [`remesh2d`]: Sec. 3.3, metric transfer (Eq. 4) and LCT remeshing.
//! - [`lift`], [`stitch`]: Sec. 3.3 "Mapping back", patch replacement.
//! - [`pipeline`]: Algorithm 1.
//! - [`quality`], [`report`]: Sec. 4.1, the yardstick.
//! - [`suite`]: the analytic benchmark cases (surfaces with user-style metrics).

pub mod check;
pub mod error;
pub mod features;
pub mod fidelity;
pub mod ids;
pub mod invariants;
pub mod io;
pub mod lift;
pub mod mesh;
pub mod metric;
pub mod param;
pub mod patches;
pub mod pipeline;
pub mod predicates;
pub mod quality;
pub mod remesh2d;
pub mod report;
pub mod stitch;
pub mod suite;

pub use error::{Error, Result};
pub use ids::{EdgeKey, FaceId, HalfedgeId, PatchId, VertexId};
pub use mesh::{SurfaceLocation, Topology, TriMesh};

/// The seeded random number generator used everywhere (randomness flows from one seed).
pub type Rng = rand_chacha::ChaCha8Rng;
