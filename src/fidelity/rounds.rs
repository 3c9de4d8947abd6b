//! The fidelity control's share of one patch of Algorithm 1: the metric the patch starts
//! from ([`patch_metrics`]), the rounds loop that remeshes it again with the metric scaled up
//! where the lifted patch deviates from the reference ([`refine`]), and the per-vertex factors
//! kept between patches ([`VertexFactors`]).

use super::measure::{deviations, patch_vertex_factors, scale_metric, LiftedPatch, ScaleLimits};
use super::FidelityOptions;
use crate::ids::{VertexId, VertexMap};
use crate::mesh::{PlanarMesh, SurfaceLocation, TriMesh};
use crate::metric::MetricField;
use crate::remesh2d::PlanarMetricField;
use crate::stitch::Replacement;
use nalgebra::{Matrix2, Matrix3, Point3, Vector3};
use std::time::Instant;

/// The fidelity factor of every working-mesh vertex: by how much earlier patches' rounds
/// scaled the metric there (1 where they did not, and always 1 unless
/// [`FidelityOptions::persist`]).
#[derive(Clone, Debug)]
pub struct VertexFactors(Vec<f64>);

impl VertexFactors {
    /// Factor 1 at `n` vertices.
    pub fn ones(n: usize) -> VertexFactors {
        VertexFactors(vec![1.0; n])
    }

    /// The factor at `v` (1 past the end).
    pub fn get(&self, v: VertexId) -> f64 {
        self.0.get(v.idx()).copied().unwrap_or(1.0)
    }

    /// Cover one more vertex, with factor `f` (a region's new vertex as the regions are
    /// merged).
    pub fn push(&mut self, f: f64) {
        self.0.push(f);
    }

    /// Keep the larger of the factor at `v` and `f` (a region's factor at one of the whole
    /// mesh's vertices).
    pub fn raise(&mut self, v: VertexId, f: f64) {
        if let Some(x) = self.0.get_mut(v.idx()) {
            *x = x.max(f);
        }
    }

    /// Number of vertices covered.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when no vertex is covered.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// After a patch was stitched into a working mesh of `n_vertices`: keep the larger factor
    /// at the patch's vertices and append those of its new vertices (with `persist`), or just
    /// follow the vertex count. Errors with (factors, vertices) when the counts disagree.
    pub fn absorb(
        &mut self,
        factors: PatchFactors,
        persist: bool,
        n_vertices: usize,
    ) -> Result<(), (usize, usize)> {
        if persist {
            for (v, f) in factors.existing {
                self.0[v.idx()] = self.0[v.idx()].max(f);
            }
            self.0.extend(factors.new);
        } else {
            self.0.resize(n_vertices, 1.0);
        }
        if self.0.len() == n_vertices {
            Ok(())
        } else {
            Err((self.0.len(), n_vertices))
        }
    }
}

/// The fidelity control's metric factors after a patch: at the patch's vertices
/// (working-mesh ids) and at its new vertices (in [`Replacement::new_positions`] order). Kept
/// per working-mesh vertex ([`VertexFactors`]), so a later patch over the same area (the
/// overlap rings, a further sweep) starts from the refinement this one needed instead of from
/// the a-priori metric. Empty unless [`FidelityOptions::persist`].
#[derive(Clone, Debug, Default)]
pub struct PatchFactors {
    /// At the patch's existing vertices.
    pub existing: Vec<(VertexId, f64)>,
    /// At its new vertices.
    pub new: Vec<f64>,
}

/// The 3D metric at every vertex of a patch (`to_global`: the patch's vertices in the working
/// mesh, whose reference locations are `locations`): `field` (already carrying the a-priori
/// scaling `fid_scale` interpolated) at the vertex's location, times what earlier patches'
/// rounds needed there, raised to the largest a-priori factor of the reference vertices under
/// the patch's faces ([`patch_vertex_factors`]).
pub fn patch_metrics(
    field: &MetricField,
    fid_scale: &[f64],
    carried: &VertexFactors,
    patch: &TriMesh,
    to_global: &[VertexId],
    locations: &VertexMap<SurfaceLocation>,
) -> Vec<Matrix3<f64>> {
    let reference = field.reference();
    let boost = if fid_scale.is_empty() {
        Vec::new()
    } else {
        patch_vertex_factors(field, fid_scale, patch)
    };
    to_global
        .iter()
        .enumerate()
        .map(|(i, g)| {
            let loc = &locations[*g];
            let m = field.eval_at(loc) * carried.get(*g).max(1.0);
            match boost.get(i) {
                Some(&b) if b > 1.0 => {
                    let t = reference.face(loc.face);
                    let here: f64 = (0..3).map(|k| loc.bary[k] * fid_scale[t[k].idx()]).sum();
                    m * (b / here).max(1.0)
                }
                _ => m,
            }
        })
        .collect()
}

/// What [`refine`] needs besides the patch.
pub struct RoundsSetup<'a> {
    /// The control's options (tolerance, rounds, factor cap, persistence).
    pub options: &'a FidelityOptions,
    /// The metric the patch is remeshed in (with the a-priori scaling).
    pub field: &'a MetricField,
    /// Area-weighted vertex normals of the reference.
    pub normals: &'a [Vector3<f64>],
    /// Target metric edge length.
    pub l_tar: f64,
    /// The refinement floor (no scaling makes the metric's shortest edge shorter).
    pub min_edge: f64,
}

/// One round's planar remesh, the planar metric field it was made in, and its lift.
pub struct RoundOutput {
    /// The 3D position of every planar vertex (in the planar mesh's order).
    pub lifted: Vec<Point3<f64>>,
    /// The plane position of every new vertex of the replacement (in its order).
    pub new_uv: Vec<nalgebra::Point2<f64>>,
    /// The certified planar remesh.
    pub planar: PlanarMesh,
    /// Which of its vertices are kept domain-boundary (or constrained) vertices: those that no
    /// round can change. An interior vertex the remesher left in place is not one of them.
    pub kept: Vec<bool>,
    /// The planar metric field (on the initial 2D mesh) of this round.
    pub field: PlanarMetricField,
    /// The lifted candidate.
    pub replacement: Replacement,
}

/// The outcome of [`refine`].
pub struct Refined {
    /// The last round's lifted candidate.
    pub replacement: Replacement,
    /// Rounds after the first.
    pub rounds: usize,
    /// The factors to keep ([`VertexFactors::absorb`]).
    pub factors: PatchFactors,
}

/// The vertices of a patch's initial 2D mesh (the parameterization's): their working-mesh
/// ids.
#[derive(Copy, Clone)]
pub struct PatchVertices<'a> {
    /// Working-mesh id of each.
    pub to_global: &'a [VertexId],
}

/// The fidelity rounds of one patch (our addition; paper-notes.md "Fidelity control"):
/// `round(metrics, k)` remeshes the patch in the plane in `metrics` (one tensor per vertex of
/// the initial 2D mesh, `vertices`)
/// and lifts it; while the lifted candidate deviates from the reference by more than the
/// tolerance (at most [`FidelityOptions::rounds`] times), the metric is scaled up around the
/// deviating triangles ([`scale_metric`]) and the patch remeshed again. `clock` accumulates
/// the time of the measurements.
pub fn refine<E>(
    setup: &RoundsSetup<'_>,
    vertices: PatchVertices<'_>,
    carried: &VertexFactors,
    mut metrics: Vec<Matrix2<f64>>,
    clock: &mut f64,
    mut round: impl FnMut(&[Matrix2<f64>], usize) -> Result<RoundOutput, E>,
) -> Result<Refined, E> {
    let o = setup.options;
    let PatchVertices { to_global } = vertices;
    let base_trace: Vec<f64> = metrics.iter().map(|m| m.trace()).collect();
    let mut rounds = 0usize;
    loop {
        let out = round(&metrics, rounds)?;
        let eps = o.max_deviation;
        let finish = |out: RoundOutput, metrics: &[Matrix2<f64>]| {
            let factors = factors_after(&out, metrics, &base_trace, carried, to_global);
            Refined {
                replacement: out.replacement,
                rounds,
                factors,
            }
        };
        if eps.is_nan() || eps <= 0.0 || rounds >= o.rounds {
            return Ok(finish(out, &metrics));
        }
        let t0 = Instant::now();
        let lifted = &out.lifted;
        let patch = LiftedPatch {
            positions: lifted,
            fixed: &out.kept,
            triangles: &out.planar.triangles,
        };
        let deviating = deviations(setup.field, setup.normals, &patch, eps);
        let scaled = match deviating.is_empty() {
            true => 0,
            false => scale_metric(
                &mut metrics,
                &out.field,
                &out.planar,
                &deviating,
                &ScaleLimits {
                    eps,
                    max_factor: o.max_factor,
                    l_tar: setup.l_tar,
                    min_edge: setup.min_edge,
                },
            ),
        };
        *clock += t0.elapsed().as_secs_f64();
        if scaled == 0 {
            return Ok(finish(out, &metrics));
        }
        rounds += 1;
    }
}

/// The factor by which the rounds so far scaled the metric (the ratio of traces to the
/// first round's), times what the patch carried in, at every vertex of the initial mesh and,
/// interpolated in it, at every new vertex.
fn factors_after(
    out: &RoundOutput,
    metrics: &[Matrix2<f64>],
    base_trace: &[f64],
    carried: &VertexFactors,
    to_global: &[VertexId],
) -> PatchFactors {
    let total: Vec<f64> = (0..metrics.len())
        .map(|i| {
            let r = if base_trace[i] > 0.0 {
                metrics[i].trace() / base_trace[i]
            } else {
                1.0
            };
            r.max(1.0) * carried.get(to_global[i]).max(1.0)
        })
        .collect();
    let tris = out.field.triangles();
    let new: Vec<f64> = out
        .new_uv
        .iter()
        .map(|p| match out.field.locate(p) {
            Some((t, b)) => (0..3)
                .map(|k| b[k] * total[tris[t][k] as usize])
                .sum::<f64>()
                .max(1.0),
            None => 1.0,
        })
        .collect();
    PatchFactors {
        existing: to_global.iter().copied().zip(total).collect(),
        new,
    }
}
