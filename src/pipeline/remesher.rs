//! Algorithm 1 in one call: a mesh in file units (and optionally a user metric in file
//! units) in, a certified remeshed mesh in file units, its report and typed warnings out.
//! The whole job around it (the repair of the input, the yardstick, the report document and
//! the files) is `crate::job`'s.
//!
//! ```no_run
//! use conemesh::pipeline::{RemeshOptions, Remesher};
//! let loaded = conemesh::io::read_mesh(std::path::Path::new("bunny.off"))?;
//! let out = Remesher::new(RemeshOptions::default()).run(&loaded.mesh)?;
//! conemesh::io::write_mesh(std::path::Path::new("bunny-remeshed.obj"), &out.mesh)?;
//! for w in &out.warnings {
//!     eprintln!("warning: {w}");
//! }
//! # Ok::<(), conemesh::Error>(())
//! ```

use super::error::PipelineError;
use super::options::{RemeshOptions, Stages};
use super::records::{Progress, RemeshResult, Warning};
use crate::ids::VertexId;
use crate::invariants;
use crate::mesh::TriMesh;
use crate::metric::{unit_target_metric, MetricError, MetricField, MetricOptions, Normalization};
use nalgebra::Matrix3;

/// The most faces one input vertex may be a corner of ([`PipelineError::CrowdedVertex`]).
/// Scanned and CAD meshes stay far below it (a pole of a UV sphere, or the cap of a finely
/// tessellated cylinder cut into a fan, has hundreds to a few thousand). The cost of a fan
/// grows faster than its faces: one at this bound takes about half a minute, one of 100,000
/// faces more than five.
pub const MAX_FACES_AT_VERTEX: usize = 16_384;

/// Algorithm 1 from a mesh in file units: [`Remesher::run`] drops unreferenced vertices,
/// scales the input to unit bounding-box diagonal, builds the metric (the curvature metric
/// of Sec. 3.1, or the user's), runs [`super::remesh`], maps the result back to file units
/// (surviving input vertices bit for bit) and re-certifies that mesh exactly.
pub struct Remesher {
    /// Options of Algorithm 1.
    pub options: RemeshOptions,
    /// The extension points; `None`: the paper's methods, set for absolute sizes when a user
    /// metric is given ([`Stages::for_sizes`]).
    pub stages: Option<Stages>,
    /// How the curvature metric is estimated (when no user metric is given).
    pub metric: MetricOptions,
}

/// The result of [`Remesher::run`].
pub struct Remeshed {
    /// The output in file units.
    pub mesh: TriMesh,
    /// The unit-space result: mesh, reference locations, provenance and report.
    pub unit: RemeshResult,
    /// The input after dropping unreferenced vertices (the reference, in file units).
    pub input: TriMesh,
    /// Where each vertex of the mesh as given went in `input` (`None`: unreferenced, dropped).
    pub input_vertices: Vec<Option<VertexId>>,
    /// The user metric at the vertices of `input` (file units), when one was given.
    pub input_metric: Option<Vec<Matrix3<f64>>>,
    /// The scaling between file units and unit space.
    pub normalization: Normalization,
    /// The metric field on the unit-space input.
    pub field: MetricField,
    /// What the user should know (also in `unit.report.warnings`).
    pub warnings: Vec<Warning>,
}

impl Remeshed {
    /// The metric at every output vertex, in file units (what `--write-metric` writes).
    pub fn output_metric(&self) -> Vec<Matrix3<f64>> {
        self.unit
            .locations
            .iter()
            .map(|l| self.normalization.metric_from_unit(&self.field.eval_at(l)))
            .collect()
    }

    /// The metric the run remeshes to, at every vertex of the mesh as given (unreferenced
    /// ones too), in file units and scaled so that an edge on target has metric length 1
    /// (MMG's `-ltar 1`): the curvature or user metric with the size controls and the
    /// a-priori fidelity factors of the run ([`RemeshResult::remesh_metric`]), over L_tar²,
    /// completed along the normal to be SPD ([`unit_target_metric`]). What
    /// `--write-input-metric` writes, so that MMG can be given the same metric as conemesh.
    ///
    /// An unreferenced vertex carries no surface; it gets the mean of the other tensors, so
    /// that the file has an SPD tensor at every vertex of the mesh (MMG reads one per vertex).
    pub fn input_metric_unit_target(&self) -> Vec<Matrix3<f64>> {
        let file_units: Vec<Matrix3<f64>> = self
            .unit
            .remesh_metric
            .iter()
            .map(|m| self.normalization.metric_from_unit(m))
            .collect();
        let kept = unit_target_metric(&self.input, &file_units, self.unit.report.l_tar);
        let mean = kept.iter().sum::<Matrix3<f64>>() / kept.len().max(1) as f64;
        self.input_vertices
            .iter()
            .map(|v| v.map_or(mean, |v| kept[v.idx()]))
            .collect()
    }
}

impl Remesher {
    /// A remesher with `options` and the paper's stages.
    pub fn new(options: RemeshOptions) -> Remesher {
        Remesher {
            options,
            stages: None,
            metric: MetricOptions::default(),
        }
    }

    /// The same with other extension points.
    pub fn with_stages(self, stages: Stages) -> Remesher {
        Remesher {
            stages: Some(stages),
            ..self
        }
    }

    /// Remesh `input` (file units) in its curvature metric.
    pub fn run(&self, input: &TriMesh) -> Result<Remeshed, PipelineError> {
        self.run_with(input, None, |_| {})
    }

    /// Remesh `input` in a user metric: one symmetric tensor per input vertex, in file
    /// units, positive definite on the surface's tangent plane.
    pub fn run_with_metric(
        &self,
        input: &TriMesh,
        metric: &[Matrix3<f64>],
    ) -> Result<Remeshed, PipelineError> {
        self.run_with(input, Some(metric), |_| {})
    }

    /// [`Remesher::run`] or [`Remesher::run_with_metric`], reporting progress after every
    /// patch.
    pub fn run_with(
        &self,
        input: &TriMesh,
        metric: Option<&[Matrix3<f64>]>,
        on_progress: impl FnMut(Progress),
    ) -> Result<Remeshed, PipelineError> {
        if let Some(m) = metric {
            if m.len() != input.n_vertices() {
                return Err(PipelineError::MetricCount {
                    tensors: m.len(),
                    vertices: input.n_vertices(),
                });
            }
        }
        certify_faces_at_vertices(input)?;
        // Unreferenced vertices carry no surface; drop them. The compaction keeps the order of
        // the other vertices, and the user metric follows them through the map.
        let (file_mesh, map) = input.without_unreferenced_vertices();
        let norm = Normalization::of(&file_mesh);
        let reference = norm.apply(&file_mesh);
        let input_metric = metric.map(|m| {
            let mut kept = vec![Matrix3::zeros(); file_mesh.n_vertices()];
            for (old, new) in map.iter().enumerate() {
                if let Some(n) = new {
                    kept[n.idx()] = m[old];
                }
            }
            kept
        });
        let field = match &input_metric {
            Some(m) => {
                let unit = m.iter().map(|m| norm.metric_to_unit(m)).collect();
                MetricField::from_surface_tensors(reference, unit)
                    .map_err(|e| in_file_numbering(e, &map))?
            }
            None => {
                let opts = match self.options.crease_metric {
                    true => MetricOptions {
                        features: self.options.features,
                        ..self.metric
                    },
                    false => self.metric,
                };
                MetricField::from_curvature(reference, &opts)?
            }
        };
        // The size controls are given in file units; the run is in unit space.
        let mut options = self.options.clone();
        options.sizes.hmin = options.sizes.hmin.map(|h| h * norm.scale);
        options.sizes.hmax = options.sizes.hmax.map(|h| h * norm.scale);
        let defaults;
        let stages = match &self.stages {
            Some(s) => s,
            None => {
                let sizes = crate::registry::MetricSizes::of_user_metric(metric.is_some());
                defaults = Stages::for_sizes(sizes);
                &defaults
            }
        };
        let unit = super::remesh(&field, stages, &options, on_progress)?;
        let mesh = to_file_units(&unit, field.reference(), &file_mesh, &norm);
        // The certificates were taken in unit space; mapping back to file units rounds the new
        // vertices, so the mesh that is returned is certified again (exact): no degenerate
        // face, and no self-intersection where the unit-space output had none.
        // On the mesh scaled by a power of two (exact), so the verdicts hold at any scale.
        let scaled = mesh.scaled_by_power_of_two();
        invariants::certify_no_degenerate_faces(&scaled).map_err(PipelineError::FileUnits)?;
        invariants::certify_boundary_on_curves(
            &unit.curves,
            &file_mesh,
            &mesh,
            &crate::mesh::Topology::build(&mesh),
            &unit.curve,
        )
        .map_err(PipelineError::FileUnits)?;
        if unit.report.certificate.no_self_intersections == 1 {
            invariants::certify_no_self_intersections(&scaled).map_err(PipelineError::FileUnits)?;
        }
        Ok(Remeshed {
            mesh,
            warnings: unit.report.warnings.clone(),
            unit,
            input: file_mesh,
            input_vertices: map,
            input_metric,
            normalization: norm,
            field,
        })
    }
}

/// A metric error names the vertex in the compacted input; name it as in the file.
fn in_file_numbering(e: MetricError, map: &[Option<VertexId>]) -> MetricError {
    let file_id = |v: usize| {
        map.iter()
            .position(|n| n.is_some_and(|n| n.idx() == v))
            .unwrap_or(v)
    };
    match e {
        MetricError::NotSpd { vertex, defect } => MetricError::NotSpd {
            vertex: file_id(vertex),
            defect,
        },
        MetricError::NonFinite { vertex } => MetricError::NonFinite {
            vertex: file_id(vertex),
        },
        other => other,
    }
}

/// Map the unit-space result back to file units. A vertex on a boundary curve is that curve
/// point computed from the file's positions (so it lies on the file's boundary polyline by
/// the same exact rule); a vertex that sits exactly on an input vertex (one-hot barycentric
/// location, bit-identical unit position) gets that vertex's file coordinates bit for bit;
/// every other vertex is mapped by the inverse normalization.
fn to_file_units(
    unit: &RemeshResult,
    reference: &TriMesh,
    file_mesh: &TriMesh,
    norm: &Normalization,
) -> TriMesh {
    let out = &unit.mesh;
    let positions = out
        .positions
        .iter()
        .zip(&unit.locations)
        .enumerate()
        .map(|(i, (p, loc))| {
            if let Some(c) = unit.curve.get(i).copied().flatten() {
                return unit.curves.position(file_mesh, &c);
            }
            for k in 0..3 {
                if loc.bary[k] == 1.0 {
                    let v = reference.triangles[loc.face.idx()][k];
                    if reference.positions[v.idx()] == *p {
                        return file_mesh.positions[v.idx()];
                    }
                }
            }
            norm.from_unit(p)
        })
        .collect();
    TriMesh {
        positions,
        triangles: out.triangles.clone(),
    }
}

/// Refuse an input vertex that is a corner of more than [`MAX_FACES_AT_VERTEX`] faces,
/// before any work ([`PipelineError::CrowdedVertex`]).
fn certify_faces_at_vertices(input: &TriMesh) -> Result<(), PipelineError> {
    let mut faces = vec![0usize; input.n_vertices()];
    for t in &input.triangles {
        for v in t {
            faces[v.idx()] += 1;
        }
    }
    match faces
        .iter()
        .enumerate()
        .max_by_key(|&(i, n)| (*n, std::cmp::Reverse(i)))
    {
        Some((v, &n)) if n > MAX_FACES_AT_VERTEX => Err(PipelineError::CrowdedVertex {
            vertex: VertexId::new(v),
            faces: n,
            max: MAX_FACES_AT_VERTEX,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    /// A planar fan of `n` faces around vertex 0.
    fn fan(n: usize) -> TriMesh {
        let mut positions = vec![Point3::origin()];
        positions.extend((0..=n).map(|i| {
            let a = 1.5 * std::f64::consts::PI * i as f64 / n as f64;
            Point3::new(a.cos(), a.sin(), 0.0)
        }));
        let tris: Vec<[usize; 3]> = (1..=n).map(|i| [0, i, i + 1]).collect();
        TriMesh::from_indices(positions, &tris).expect("fan")
    }

    #[test]
    fn a_vertex_at_the_bound_is_taken_and_one_past_it_is_refused_by_id() {
        assert!(certify_faces_at_vertices(&fan(MAX_FACES_AT_VERTEX)).is_ok());
        let refused = certify_faces_at_vertices(&fan(MAX_FACES_AT_VERTEX + 1));
        assert!(
            matches!(
                refused,
                Err(PipelineError::CrowdedVertex { vertex, faces, max })
                    if vertex == VertexId::new(0)
                        && faces == MAX_FACES_AT_VERTEX + 1
                        && max == MAX_FACES_AT_VERTEX
            ),
            "{refused:?}"
        );
    }
}
