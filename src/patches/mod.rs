//! Patch generation (Sec. 3.2): cone patches and the [`PatchStrategy`] extension point.
//!
//! Files: `cone_fit.rs` (Eq. 1-2), `growth_cost.rs` (Eq. 3), `grow.rs` (greedy growth with
//! the exact disk rule), `expand.rs` (1-2 ring expansion), `cone.rs` (the paper's strategy),
//! `kring.rs` (a second strategy), `shrink.rs` (the retry ladder's smaller disk),
//! `registry.rs` (name → strategy), `extract.rs` (a patch as its own mesh), `cover.rs` (the
//! covering run of `conemesh patches`).
//!
//! A new strategy: a file with a type implementing [`PatchStrategy`] (`kring.rs` is the
//! template; the helpers it uses are public: [`pick_seed_vertex`], [`unprocessed_ring`],
//! [`DiskPatch`], [`expand::expand_rings`], [`finish_patch`]), one row in [`STRATEGIES`], and
//! `cargo test` runs its contract ([`crate::contract::patch_strategy`]). Outside the crate the
//! row goes to a [`crate::registry::Registry`] instead.

pub mod cone;
pub mod cone_fit;
pub mod cover;
pub mod expand;
pub mod extract;
pub mod grow;
pub mod growth_cost;
pub mod kring;
mod registry;
mod shrink;

pub use cone::{finish_patch, pick_seed_vertex, unprocessed_ring, ConePatches};
pub use cone_fit::{cone_error, cone_objective, fit_cone, fit_cone_normals};
pub use cover::{cover, CoverOptions, CoverRun, PatchStats};
pub use extract::{extract_patch, PatchMesh};
pub use grow::{grow_patch, DiskPatch, Grown, Refusal};
pub use growth_cost::{growth_cost, ConeOptions};
pub use kring::KRingDisks;
pub use registry::{strategy, STRATEGIES};
pub use shrink::shrink_breadth_first;

use crate::ids::{EdgeKey, FaceId, PatchId, VertexId};
use crate::mesh::{Topology, TriMesh};
use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use std::collections::{HashMap, HashSet};
use thiserror::Error;

/// Errors of patch generation.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PatchError {
    /// The mesh handed to the cover is not a valid mesh.
    #[error("patch generation: {0}")]
    Mesh(#[from] crate::mesh::MeshError),
    /// The seed vertex a strategy picked has no unprocessed face (its context is not one the
    /// strategy can grow from).
    #[error("patch generation: seed vertex {seed} has no unprocessed face")]
    SeedWithoutFace {
        /// the seed vertex
        seed: VertexId,
    },
    /// A produced patch failed its certificate.
    #[error("patch{} (seed {seed}): {source}", patch.map(|p| format!(" {p}")).unwrap_or_default())]
    NotCertified {
        /// the patch, when the caller numbers them
        patch: Option<PatchId>,
        /// its seed vertex
        seed: VertexId,
        /// the violated invariant
        source: crate::invariants::InvariantError,
    },
    /// A face set handed to [`extract_patch`] failed its certificate (not a disk:
    /// [`crate::invariants::InvariantError::NotADisk`]).
    #[error(transparent)]
    Invariant(#[from] crate::invariants::InvariantError),
    /// A strategy returned a patch without unprocessed faces (the loop would not progress).
    #[error("patch {patch} (seed {seed}) contains no unprocessed face")]
    NoProgress {
        /// the patch
        patch: PatchId,
        /// its seed vertex
        seed: VertexId,
    },
    /// A strategy returned faces that are not in the mesh.
    #[error("patch {patch}: face {face} is not in the mesh")]
    FaceOutOfRange {
        /// the patch
        patch: PatchId,
        /// the face
        face: FaceId,
    },
}

/// A fitted cone (Eq. 1-2): unit axis `n_P` and angle `α_P` between axis and face normals.
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct Cone {
    /// Unit axis n_P.
    pub axis: Vector3<f64>,
    /// Angle α_P in radians.
    pub angle: f64,
}

/// A patch: faces of the working mesh forming a topological disk.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Patch {
    /// Faces, sorted by id.
    pub faces: Vec<FaceId>,
    /// The boundary as an ordered vertex loop, oriented so that the patch lies to its left
    /// (it follows the patch faces' half-edge direction).
    pub boundary: Vec<VertexId>,
    /// The seed vertex the patch was started from.
    pub seed_vertex: VertexId,
    /// The seed triangle s_P.
    pub seed_face: FaceId,
    /// The fitted cone, for strategies that fit one.
    pub cone: Option<Cone>,
    /// Largest Eq. 3 cost of a face added by growth (seed and expansion excluded), for
    /// strategies that grow by cost; always below `c_max`.
    pub max_growth_cost: Option<f64>,
}

/// What a strategy sees: the working mesh, its topology, which faces are processed, and
/// optionally edges no patch may cross (feature lines).
#[derive(Clone, Copy)]
pub struct PatchContext<'a> {
    /// The working mesh.
    pub mesh: &'a TriMesh,
    /// Its topology (built from `mesh`).
    pub topology: &'a Topology,
    /// `processed[f]` for every face of `mesh`.
    pub processed: &'a [bool],
    /// Edges patches must not cross (their interior may not contain them).
    pub feature_edges: Option<&'a HashSet<EdgeKey>>,
    /// `corners[v]`: vertex `v` may not become an interior vertex of a patch (a cone point of
    /// the input, see [`corner_vertices`]); vertices past the end are not corners.
    pub corners: Option<&'a [bool]>,
    /// `blocked[f]`: face `f` is reserved by another patch of the same batch (it shares a
    /// vertex with one), so this patch may neither contain it nor grow from it; faces past
    /// the end are not blocked. The pipeline checks the result: a patch with a blocked face
    /// ends its batch and waits for the next (see `pipeline` module docs).
    pub blocked: Option<&'a [bool]>,
}

impl PatchContext<'_> {
    /// True when `f` is marked in [`PatchContext::blocked`].
    pub fn is_blocked(&self, f: FaceId) -> bool {
        self.blocked
            .is_some_and(|b| b.get(f.idx()).copied().unwrap_or(false))
    }

    /// True when `v` is marked in [`PatchContext::corners`].
    pub fn is_corner(&self, v: VertexId) -> bool {
        self.corners
            .is_some_and(|c| c.get(v.idx()).copied().unwrap_or(false))
    }
}

/// Cone points of a piecewise-flat surface: interior vertices whose angle defect
/// `|2π − Σθ|` is at least `min_defect` radians. The Gaussian curvature of the whole
/// neighbourhood is concentrated at such a vertex, so no patch containing it in its interior
/// can be flattened isometrically (Sec. 3.3), and the planar remesher would replace the tip
/// by a flat fan, cutting it off (decimated-knight: spikes with defects of 3-4 rad, 2-5 % of
/// the diagonal high). Patches keep them on their boundary, so they stay in the output.
/// Boundary vertices are never interior to a patch and are not marked.
pub fn corner_vertices(mesh: &TriMesh, topology: &Topology, min_defect: f64) -> Vec<bool> {
    let sums = mesh.angle_sums();
    mesh.vertices()
        .map(|v| {
            !topology.vertex_faces(v).is_empty()
                && !topology.is_boundary_vertex(v)
                && (std::f64::consts::TAU - sums[v.idx()]).abs() >= min_defect
        })
        .collect()
}

/// The research extension point of Sec. 3.2: produce the next patch to remesh.
///
/// Contract: a returned patch is a topological disk (certified by the caller with
/// `invariants::certify_disk`) containing at least one unprocessed face, does not cross
/// feature edges, has no [`PatchContext::corners`] vertex in its interior, and its boundary loop is oriented as documented on [`Patch`]. `Ok(None)`
/// means there is no unprocessed face left.
pub trait PatchStrategy: Send + Sync {
    /// Short name (`cone`, …) used in reports and on the command line.
    fn name(&self) -> &'static str;
    /// The next patch, drawing randomness only from `rng`.
    fn next_patch(
        &self,
        ctx: &PatchContext<'_>,
        rng: &mut ChaCha8Rng,
    ) -> Result<Option<Patch>, PatchError>;
    /// A smaller disk inside `faces` (a patch whose attempt failed), of about `target`
    /// faces, containing an unprocessed face (`seed_face` when it is one). The same
    /// contract as [`PatchStrategy::next_patch`]. Default: breadth first from the seed face
    /// under the exact disk rule ([`shrink_breadth_first`]).
    fn shrink(
        &self,
        ctx: &PatchContext<'_>,
        faces: &[FaceId],
        seed_face: FaceId,
        target: usize,
    ) -> Vec<FaceId> {
        shrink_breadth_first(ctx, faces, seed_face, target)
    }
    /// The same strategy with its patches expanded by `rings` rings of processed faces after
    /// growth: Algorithm 2 (Sec. 3.4) marks the good faces processed, so its patches are the
    /// bad faces and `rings` rings around them, one ring more each pass. Default `None`: the
    /// strategy has no such setting, and Algorithm 2 uses it as it is.
    fn widened(&self, rings: usize) -> Option<Box<dyn PatchStrategy>> {
        let _ = rings;
        None
    }
}
/// A corner vertex all of whose faces are in `faces` (interior to the patch), if any.
pub fn interior_corner(
    mesh: &TriMesh,
    topo: &Topology,
    faces: &[FaceId],
    corners: &[bool],
) -> Option<VertexId> {
    let mut count: HashMap<VertexId, usize> = HashMap::new();
    for &f in faces {
        for v in mesh.face(f) {
            if corners.get(v.idx()).copied().unwrap_or(false) {
                *count.entry(v).or_default() += 1;
            }
        }
    }
    let mut inside: Vec<VertexId> = count
        .into_iter()
        .filter(|(v, n)| !topo.is_boundary_vertex(*v) && *n == topo.vertex_faces(*v).len())
        .map(|(v, _)| v)
        .collect();
    inside.sort_unstable();
    inside.first().copied()
}

/// A feature edge shared by two faces of the patch (so inside it), the smallest if several.
pub fn interior_feature(
    mesh: &TriMesh,
    faces: &[FaceId],
    feature_edges: &HashSet<EdgeKey>,
) -> Option<EdgeKey> {
    let mut count: HashMap<EdgeKey, u32> = HashMap::new();
    for f in faces {
        let t = mesh.triangles[f.idx()];
        for k in 0..3 {
            *count.entry(EdgeKey::new(t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    count
        .into_iter()
        .filter(|(e, c)| *c >= 2 && feature_edges.contains(e))
        .map(|(e, _)| e)
        .min()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;

    /// The regular octahedron: every vertex has angle sum 4·60° and defect 2π/3.
    fn octahedron() -> TriMesh {
        let p = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let t = [
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        TriMesh::from_indices(
            p.iter()
                .map(|x| nalgebra::Point3::new(x[0], x[1], x[2]))
                .collect(),
            &t,
        )
        .expect("octahedron")
    }

    #[test]
    fn corner_vertices_by_angle_defect() {
        let o = octahedron();
        let topo = Topology::build(&o);
        let sums = o.angle_sums();
        assert!(sums
            .iter()
            .all(|s| (s - 4.0 * std::f64::consts::FRAC_PI_3).abs() < 1e-12));
        assert!(corner_vertices(&o, &topo, 2.0).iter().all(|c| *c));
        assert!(corner_vertices(&o, &topo, 2.2).iter().all(|c| !*c));
        // A finely sampled sphere has no cone points; a disk's rim vertices are never corners
        // (boundary), and its flat centre has no defect.
        let s = generators::icosphere(1.0, 3);
        let ts = Topology::build(&s);
        assert!(corner_vertices(&s, &ts, 0.2).iter().all(|c| !*c));
        let d = generators::disk(1.0, 3, 6);
        let td = Topology::build(&d);
        assert!(corner_vertices(&d, &td, 1e-9).iter().all(|c| !*c));
    }

    #[test]
    fn growth_never_closes_the_fan_of_a_corner() {
        let o = octahedron();
        let topo = Topology::build(&o);
        let processed = vec![false; o.n_faces()];
        let corners = vec![false, false, false, false, true, false];
        let ctx = PatchContext {
            mesh: &o,
            topology: &topo,
            processed: &processed,
            feature_edges: None,
            corners: Some(&corners),
            blocked: None,
        };
        // The four faces around vertex 4 in fan order: the last one would close its fan.
        let fan = [FaceId(0), FaceId(1), FaceId(2), FaceId(3)];
        let mut p = DiskPatch::new(&ctx, fan[0]);
        assert_eq!(p.try_add(fan[1]), Ok(()));
        assert_eq!(p.try_add(fan[2]), Ok(()));
        assert_eq!(p.try_add(fan[3]), Err(Refusal::Corner(VertexId(4))));
        // Without the mark the same face is accepted (k = 2 closes the fan: a disk).
        let free = PatchContext {
            corners: None,
            ..ctx
        };
        let mut q = DiskPatch::new(&free, fan[0]);
        for f in &fan[1..] {
            assert_eq!(q.try_add(*f), Ok(()));
        }
        assert!(!ctx.is_corner(VertexId(99)), "past the end is not a corner");
    }
}
