//! The patch's free boundary chains, resampled on the input's boundary curves (ours; the
//! boundary-curve rule of [`crate::boundary`]).
//!
//! A vertex of the patch boundary is *free* when it lies on an input boundary curve, both its
//! patch-boundary edges are edges of the mesh boundary (so all its faces are in the patch),
//! and it is not a corner. A *chain* is a maximal run of mesh-boundary edges of the patch
//! loop between non-free vertices (its anchors, which stay). Each chain is resampled in the
//! plane to pieces of metric length L_tar, at points placed exactly on the input curve; a
//! piece whose chord passes farther than the fidelity tolerance from the curve is halved. The
//! patch then becomes a new planar domain: the new boundary loop triangulated with the
//! patch's interior vertices (the planar remesher starts from its boundary anyway).

use super::context::RunContext;
use crate::boundary::{BoundaryCurves, CurvePoint};
use crate::ids::VertexId;
use crate::lift::DomainVertex;
use crate::mesh::{PlanarDomain, Topology, TriMesh};
use crate::patches::PatchMesh;
use crate::remesh2d::{triangulate_polygon_with, Metric2d};
use crate::stitch::WorkingMesh;
use nalgebra::{Point2, Point3};

/// Metric-length samples per chain edge.
const SAMPLES: usize = 8;
/// Halvings of one piece at most, for the chord tolerance.
const MAX_HALVINGS: usize = 8;

/// The patch in the plane, ready for the planar remesher.
pub struct PatchDomain {
    /// The polygon and its triangulation.
    pub domain: PlanarDomain,
    /// How each domain point maps back (a patch vertex, or a new point on a curve).
    pub vertices: Vec<DomainVertex>,
    /// The 3D position of each domain point.
    pub positions: Vec<Point3<f64>>,
    /// Chains resampled.
    pub chains: usize,
}

/// The parameterized patch as a planar domain, with its free boundary chains resampled
/// (unchanged when the patch has none, or when resampling is off or the new polygon cannot
/// be triangulated).
pub fn patch_domain(
    ctx: &RunContext<'_>,
    work: &WorkingMesh,
    topo: &Topology,
    disk: &PatchMesh,
    uv: &[Point2<f64>],
    metric: &dyn Metric2d,
) -> PatchDomain {
    let unchanged = || PatchDomain {
        domain: PlanarDomain {
            points: uv.to_vec(),
            triangles: disk.mesh.index_triangles(),
            boundary: disk.boundary.iter().map(|v| v.0).collect(),
            constrained_edges: Vec::new(),
        },
        vertices: (0..uv.len() as u32).map(DomainVertex::Patch).collect(),
        positions: disk.mesh.positions.clone(),
        chains: 0,
    };
    if !ctx.plan.options.boundary.resample || ctx.improving || ctx.curves.is_empty() {
        return unchanged();
    }
    let sampler = Sampler {
        curves: &ctx.curves,
        reference: ctx.quality_field.reference(),
        metric,
        l_tar: ctx.plan.l_tar,
        eps: ctx.plan.eps,
        max_pieces: ctx.plan.patch_face_cap(),
    };
    let chains = free_chains(&ctx.curves, ctx.frozen.as_deref(), work, topo, disk);
    if chains.is_empty() {
        return unchanged();
    }
    // The new loop: anchors and untouched vertices as they are, chains' insides replaced.
    let g = |l: VertexId| disk.to_global[l.idx()];
    let point_of = |l: VertexId| work.curve.get(g(l)).copied().flatten();
    let mut loop_vertices: Vec<DomainVertex> = Vec::new();
    let mut loop_uv: Vec<Point2<f64>> = Vec::new();
    let mut loop_pos: Vec<Point3<f64>> = Vec::new();
    let b = &disk.boundary;
    let n = b.len();
    let chain_at: std::collections::HashMap<usize, &Chain> =
        chains.iter().map(|c| (c.start, c)).collect();
    let mut i = chains[0].start;
    for _ in 0..n {
        let l = b[i];
        loop_vertices.push(DomainVertex::Patch(l.0));
        loop_uv.push(uv[l.idx()]);
        loop_pos.push(disk.mesh.positions[l.idx()]);
        match chain_at.get(&i) {
            Some(c) => {
                let pts: Option<Vec<(CurvePoint, Point2<f64>)>> = c
                    .vertices
                    .iter()
                    .map(|&v| point_of(v).map(|p| (p, uv[v.idx()])))
                    .collect();
                let Some(new) = pts.and_then(|pts| sampler.resample(&pts)) else {
                    // Not resampled: the chain's own vertices stay.
                    for &v in &c.vertices[1..c.vertices.len() - 1] {
                        loop_vertices.push(DomainVertex::Patch(v.0));
                        loop_uv.push(uv[v.idx()]);
                        loop_pos.push(disk.mesh.positions[v.idx()]);
                    }
                    i = c.end;
                    if i == chains[0].start {
                        break;
                    }
                    continue;
                };
                for (p, q) in new {
                    loop_vertices.push(DomainVertex::Curve {
                        position: ctx.curves.position(sampler.reference, &p),
                        location: ctx.curves.location(&p),
                        point: p,
                    });
                    loop_uv.push(q);
                    loop_pos.push(ctx.curves.position(sampler.reference, &p));
                }
                i = c.end;
                if i == chains[0].start {
                    break;
                }
            }
            None => i = (i + 1) % n,
        }
        if i == chains[0].start {
            break;
        }
    }
    let on_loop: std::collections::HashSet<VertexId> = b.iter().copied().collect();
    let interior: Vec<VertexId> = (0..uv.len())
        .map(VertexId::new)
        .filter(|v| !on_loop.contains(v))
        .collect();
    let interior_uv: Vec<Point2<f64>> = interior.iter().map(|v| uv[v.idx()]).collect();
    let Ok((domain, kept)) = triangulate_polygon_with(&loop_uv, &interior_uv) else {
        return unchanged();
    };
    let mut vertices = loop_vertices;
    let mut positions = loop_pos;
    for k in kept {
        vertices.push(DomainVertex::Patch(interior[k].0));
        positions.push(disk.mesh.positions[interior[k].idx()]);
    }
    PatchDomain {
        domain,
        vertices,
        positions,
        chains: chains.len(),
    }
}

/// A chain of the patch loop: positions `start` to `end` of the loop (cyclically), its
/// vertices (local ids) from anchor to anchor.
struct Chain {
    start: usize,
    end: usize,
    vertices: Vec<VertexId>,
}

/// The edge `a → b` of the working mesh has one face (a boundary edge of the mesh).
fn is_mesh_boundary_edge(mesh: &TriMesh, topo: &Topology, a: VertexId, b: VertexId) -> bool {
    let has = |v: VertexId, w: VertexId| {
        topo.vertex_faces(v).iter().any(|f| {
            let t = mesh.triangles[f.idx()];
            (0..3).any(|k| t[k] == v && t[(k + 1) % 3] == w)
        })
    };
    has(a, b) && !has(b, a)
}

/// The free chains of the patch loop (module docs). In a region's run its cut edges are no
/// chain's and its cut vertices anchors: the cuts stay as they are.
fn free_chains(
    curves: &BoundaryCurves,
    frozen: Option<&super::context::FrozenCut>,
    work: &WorkingMesh,
    topo: &Topology,
    disk: &PatchMesh,
) -> Vec<Chain> {
    let b = &disk.boundary;
    let n = b.len();
    let g = |i: usize| disk.to_global[b[i % n].idx()];
    let boundary_edge: Vec<bool> = (0..n)
        .map(|i| {
            is_mesh_boundary_edge(&work.mesh, topo, g(i), g(i + 1))
                && !frozen.is_some_and(|c| c.is_cut_edge(g(i), g(i + 1)))
        })
        .collect();
    if !boundary_edge.iter().any(|e| *e) {
        return Vec::new();
    }
    let free = |i: usize| {
        let i = i % n;
        boundary_edge[i]
            && boundary_edge[(i + n - 1) % n]
            && !frozen.is_some_and(|c| c.is_cut_vertex(g(i)))
            && work
                .curve
                .get(g(i))
                .copied()
                .flatten()
                .is_some_and(|p| !curves.is_corner_point(&p))
    };
    // Start at an anchor; a loop that is all free (one patch over a whole boundary loop
    // without corners) is anchored at its smallest vertex id.
    let start = (0..n)
        .find(|&i| !free(i))
        .unwrap_or_else(|| (0..n).min_by_key(|&i| g(i)).unwrap_or(0));
    let anchor = |i: usize| i % n == start || !free(i);
    let mut chains = Vec::new();
    let mut k = 0;
    while k < n {
        let i = (start + k) % n;
        if !boundary_edge[i] {
            k += 1;
            continue;
        }
        let mut vertices = vec![b[i]];
        let mut j = k + 1;
        loop {
            vertices.push(b[(start + j) % n]);
            if anchor(start + j) || j >= n {
                break;
            }
            j += 1;
        }
        chains.push(Chain {
            start: i,
            end: (start + j) % n,
            vertices,
        });
        k = j;
    }
    chains
}

/// Resamples one chain (see the module docs).
struct Sampler<'a> {
    curves: &'a BoundaryCurves,
    reference: &'a TriMesh,
    metric: &'a dyn Metric2d,
    l_tar: f64,
    eps: f64,
    /// More pieces than this (the patch face cap: a patch whose metric is many orders off for
    /// its size) and the chain is not resampled.
    max_pieces: f64,
}

impl Sampler<'_> {
    /// The new inner points of a chain given as (curve point, uv) from anchor to anchor: a
    /// piecewise-linear correspondence between arc length on the curve and the uv polyline,
    /// equal metric length in the plane, chords within the tolerance of the curve.
    fn resample(
        &self,
        chain: &[(CurvePoint, Point2<f64>)],
    ) -> Option<Vec<(CurvePoint, Point2<f64>)>> {
        if chain.len() < 2 || chain.iter().any(|(p, _)| p.curve != chain[0].0.curve) {
            return None;
        }
        let curve = chain[0].0.curve as usize;
        let total_arc = self.curves.length(curve);
        // Arc length of each chain vertex, unwrapped to increase along the chain.
        let mut arc = vec![self.curves.arc(&chain[0].0)];
        for w in chain.windows(2) {
            let d = (self.curves.arc(&w[1].0) - self.curves.arc(&w[0].0)).rem_euclid(total_arc);
            let d = if d == 0.0 && w[1].0 == chain[0].0 {
                total_arc
            } else {
                d
            };
            arc.push(arc.last().copied().unwrap_or(0.0) + d);
        }
        // Cumulative metric length over SAMPLES sub-segments of every chain edge.
        let mut cum = vec![0.0];
        for w in chain.windows(2) {
            let (a, b) = (w[0].1, w[1].1);
            for k in 0..SAMPLES {
                let (t0, t1) = (k as f64 / SAMPLES as f64, (k + 1) as f64 / SAMPLES as f64);
                let (p, q) = (a + (b - a) * t0, b + (a - b) * (1.0 - t1));
                let m = self
                    .metric
                    .metric(&Point2::from((p.coords + q.coords) * 0.5));
                let e = q - p;
                let l = e.dot(&(m * e)).max(0.0).sqrt();
                cum.push(cum.last().copied().unwrap_or(0.0) + l);
            }
        }
        let total = cum.last().copied().unwrap_or(0.0);
        if !(total.is_finite() && total > 0.0 && total_arc > 0.0) {
            return None;
        }
        let closed = chain[0].0 == chain[chain.len() - 1].0;
        if total / self.l_tar > self.max_pieces {
            return None;
        }
        let pieces = ((total / self.l_tar).round() as usize).max(if closed { 3 } else { 1 });
        // Arc length (and uv) at a metric length s along the chain.
        let at_metric = |s: f64| -> f64 {
            let k = cum.partition_point(|&c| c < s).clamp(1, cum.len() - 1);
            let (c0, c1) = (cum[k - 1], cum[k]);
            let f = if c1 > c0 { (s - c0) / (c1 - c0) } else { 0.5 };
            let sub = (k - 1) as f64 + f;
            let (e, t) = (
                (sub / SAMPLES as f64).floor() as usize,
                sub / SAMPLES as f64,
            );
            let e = e.min(chain.len() - 2);
            let t = (t - e as f64).clamp(0.0, 1.0);
            arc[e] + (arc[e + 1] - arc[e]) * t
        };
        let mut arcs: Vec<f64> = vec![arc[0]];
        arcs.extend((1..pieces).map(|j| at_metric(total * j as f64 / pieces as f64)));
        arcs.push(arc[arc.len() - 1]);
        if self.eps > 0.0 {
            arcs = self.within_tolerance(curve, arcs);
        }
        Some(
            arcs[1..arcs.len() - 1]
                .iter()
                .map(|&s| (self.curves.at_arc(curve, s), uv_at(chain, &arc, s)))
                .collect(),
        )
    }

    /// Halve every piece whose chord passes farther than the tolerance from the curve
    /// vertices under it.
    fn within_tolerance(&self, curve: usize, arcs: Vec<f64>) -> Vec<f64> {
        let mut out = vec![arcs[0]];
        for w in arcs.windows(2) {
            let mut stack = vec![(w[0], w[1], 0usize)];
            let mut pieces = Vec::new();
            while let Some((a, b, depth)) = stack.pop() {
                if depth < MAX_HALVINGS && self.chord_error(curve, a, b) > self.eps {
                    let m = 0.5 * (a + b);
                    stack.push((m, b, depth + 1));
                    stack.push((a, m, depth + 1));
                } else {
                    pieces.push(b);
                }
            }
            out.extend(pieces);
        }
        out
    }

    /// The largest distance of the curve's vertices strictly between arc lengths `a` and `b`
    /// to the chord between the curve points there.
    fn chord_error(&self, curve: usize, a: f64, b: f64) -> f64 {
        let (pa, pb) = (
            self.curves
                .position(self.reference, &self.curves.at_arc(curve, a)),
            self.curves
                .position(self.reference, &self.curves.at_arc(curve, b)),
        );
        let e = pb - pa;
        let l2 = e.norm_squared();
        self.curves
            .vertices_between(curve, a, b)
            .map(|v| {
                let p = self.reference.positions[v.idx()];
                let t = if l2 > 0.0 {
                    ((p - pa).dot(&e) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (p - (pa + e * t)).norm()
            })
            .fold(0.0, f64::max)
    }
}

/// The uv point at arc length `s` of a chain whose vertices are at arc lengths `arc`.
fn uv_at(chain: &[(CurvePoint, Point2<f64>)], arc: &[f64], s: f64) -> Point2<f64> {
    let k = arc.partition_point(|&x| x <= s).clamp(1, arc.len() - 1);
    let (a0, a1) = (arc[k - 1], arc[k]);
    let t = if a1 > a0 {
        ((s - a0) / (a1 - a0)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (p, q) = (chain[k - 1].1, chain[k].1);
    p + (q - p) * t
}
