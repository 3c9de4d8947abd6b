//! The library's typed errors as Python exceptions (`conemesh.Error` and its subclasses,
//! defined in `conemesh/_errors.py` so that they can also derive from `ValueError` or
//! `OSError`), with the element ids as attributes.
//!
//! Work runs without the GIL, so an error is first a [`Failure`] (plain data, `Send`) and
//! becomes a Python exception only once the GIL is held again.

use conemesh::invariants::InvariantError;
use conemesh::io::sol::SolError;
use conemesh::io::IoError;
use conemesh::mesh::MeshError;
use conemesh::metric::MetricError;
use conemesh::pipeline::{PipelineError, StageError};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// An attribute value of an exception.
#[derive(Debug, Clone)]
pub enum Attr {
    Int(i64),
    Str(String),
    Ints(Vec<i64>),
    Pairs(Vec<(i64, i64)>),
}

/// An error on its way to Python: the class name in `conemesh._errors`, the message and the
/// attributes (element ids, patch, path, ...).
#[derive(Debug, Clone)]
pub struct Failure {
    pub class: &'static str,
    pub message: String,
    pub attrs: Vec<(&'static str, Attr)>,
}

impl Failure {
    pub fn new(class: &'static str, message: impl Into<String>) -> Failure {
        Failure {
            class,
            message: message.into(),
            attrs: Vec::new(),
        }
    }

    pub fn with(mut self, name: &'static str, value: Attr) -> Failure {
        self.attrs.push((name, value));
        self
    }

    pub fn input(message: impl Into<String>) -> Failure {
        Failure::new("InputError", message)
    }

    pub fn option(message: impl Into<String>) -> Failure {
        Failure::new("OptionError", message)
    }

    /// The Python exception. Should the class not be found (a broken install), a
    /// `RuntimeError` with the same message, rather than losing the error.
    pub fn into_pyerr(self, py: Python<'_>) -> PyErr {
        let build = || -> PyResult<PyErr> {
            let class = py.import("conemesh._errors")?.getattr(self.class)?;
            let value = class.call1((self.message.clone(),))?;
            for (name, attr) in &self.attrs {
                match attr {
                    Attr::Int(i) => value.setattr(*name, *i)?,
                    Attr::Str(s) => value.setattr(*name, s.as_str())?,
                    Attr::Ints(v) => value.setattr(*name, v.clone())?,
                    Attr::Pairs(v) => value.setattr(*name, v.clone())?,
                }
            }
            Ok(PyErr::from_value(value))
        };
        build().unwrap_or_else(|_| PyRuntimeError::new_err(self.message))
    }
}

fn ids<T>(v: &[T], f: impl Fn(&T) -> i64) -> Attr {
    Attr::Ints(v.iter().map(f).collect())
}

/// A mesh given as arrays that is not one (empty, NaN, bad index, repeated vertex).
pub fn from_mesh(e: &MeshError) -> Failure {
    let f = Failure::input(e.to_string());
    match e {
        MeshError::NonFiniteCoordinate { vertex, .. } => {
            f.with("vertices", Attr::Ints(vec![vertex.0 as i64]))
        }
        MeshError::IndexOutOfRange { face, index, .. } => f
            .with("faces", Attr::Ints(vec![face.0 as i64]))
            .with("index", Attr::Int(*index as i64)),
        MeshError::RepeatedVertex { face, vertex } => f
            .with("faces", Attr::Ints(vec![face.0 as i64]))
            .with("vertices", Attr::Ints(vec![vertex.0 as i64])),
        _ => f,
    }
}

/// The offending elements of an invariant as attributes of `f`, and its name as
/// `invariant`.
pub fn with_invariant(f: Failure, e: &InvariantError) -> Failure {
    use InvariantError as I;
    let edge = |k: &conemesh::EdgeKey| (k.0 .0 as i64, k.1 .0 as i64);
    let (name, f) = match e {
        I::NonManifoldEdges(o) => (
            "non_manifold_edges",
            f.with(
                "edges",
                Attr::Pairs(o.0.iter().map(|x| edge(&x.0)).collect()),
            ),
        ),
        I::NonManifoldVertices(o) => (
            "non_manifold_vertices",
            f.with("vertices", ids(&o.0, |v| v.0 as i64)),
        ),
        I::InconsistentOrientation(o) => (
            "inconsistent_orientation",
            f.with("edges", Attr::Pairs(o.0.iter().map(edge).collect())),
        ),
        I::DegenerateFaces(o) => (
            "degenerate_faces",
            f.with("faces", ids(&o.0, |x| x.0 as i64)),
        ),
        I::SelfIntersections(o) => (
            "self_intersections",
            f.with(
                "face_pairs",
                Attr::Pairs(o.0.iter().map(|p| (p.0 .0 as i64, p.1 .0 as i64)).collect()),
            ),
        ),
        I::TopologyChanged(c) => {
            use conemesh::invariants::TopologyChange as T;
            let f = match c {
                T::Components { before, after } => f
                    .with("quantity", Attr::Str("components".into()))
                    .with("before", Attr::Int(*before as i64))
                    .with("after", Attr::Int(*after as i64)),
                T::BoundaryLoops { before, after } => f
                    .with("quantity", Attr::Str("boundary_loops".into()))
                    .with("before", Attr::Int(*before as i64))
                    .with("after", Attr::Int(*after as i64)),
                T::PerComponent { .. } => f.with("quantity", Attr::Str("per_component".into())),
            };
            ("topology_changed", f)
        }
        I::BoundaryVerticesMoved(o) => (
            "boundary_vertices_moved",
            f.with("vertices", ids(&o.0, |v| v.0 as i64)),
        ),
        I::BoundaryEdgesMissing(o) => (
            "boundary_edges_missing",
            f.with("edges", Attr::Pairs(o.0.iter().map(edge).collect())),
        ),
        I::BoundaryOffCurve(o) => (
            "boundary_off_curve",
            f.with("vertices", ids(&o.0, |v| v.0 as i64)),
        ),
        I::BoundaryCurves(d) => ("boundary_curves", elements(f, &d.vertices(), &[], &[])),
        I::BoundaryCornersLost(o) => (
            "boundary_corners_lost",
            f.with("vertices", ids(&o.0, |v| v.0 as i64)),
        ),
        I::NotADisk(d) => {
            let f = match d.vertices().as_slice() {
                [] => f,
                v => f.with("vertices", ids(v, |x| x.0 as i64)),
            };
            let f = match d.faces().as_slice() {
                [] => f,
                v => f.with("faces", ids(v, |x| x.0 as i64)),
            };
            let f = match d.edges().as_slice() {
                [] => f,
                v => f.with("edges", Attr::Pairs(v.iter().map(edge).collect())),
            };
            ("not_a_disk", f)
        }
        I::NotBijective(d) => (
            "not_bijective",
            elements(f, &d.vertices(), &d.faces(), &d.edges()),
        ),
        I::FlippedFaces(o) => ("flipped_faces", f.with("faces", ids(&o.0, |x| x.0 as i64))),
        I::PlanarInvalid(d) => (
            "planar_invalid",
            elements(f, &d.vertices(), &d.faces(), &d.edges()),
        ),
    };
    f.with("invariant", Attr::Str(name.into()))
}

/// The named vertices, faces and directed edges as attributes of `f`, each only when there
/// are some.
fn elements(
    f: Failure,
    vertices: &[conemesh::VertexId],
    faces: &[conemesh::FaceId],
    edges: &[(conemesh::VertexId, conemesh::VertexId)],
) -> Failure {
    let f = match vertices {
        [] => f,
        v => f.with("vertices", ids(v, |x| x.0 as i64)),
    };
    let f = match faces {
        [] => f,
        v => f.with("faces", ids(v, |x| x.0 as i64)),
    };
    match edges {
        [] => f,
        v => f.with(
            "edges",
            Attr::Pairs(v.iter().map(|(a, b)| (a.0 as i64, b.0 as i64)).collect()),
        ),
    }
}

pub fn from_metric(e: &MetricError) -> Failure {
    let f = Failure::new("MetricError", e.to_string());
    match e {
        MetricError::NotSpd { vertex, .. } | MetricError::NonFinite { vertex } => {
            f.with("vertices", Attr::Ints(vec![*vertex as i64]))
        }
        MetricError::Mesh(m) => from_mesh(m),
        _ => f,
    }
}

pub fn from_io(e: &IoError) -> Failure {
    let f = match e {
        IoError::Mesh { source, .. } => Failure {
            class: "FileError",
            ..from_mesh(source)
        },
        _ => Failure::new("FileError", e.to_string()),
    };
    // Every variant names its file first (`{path}: ...`).
    let f = f.with("kind", Attr::Str(e.kind().into()));
    Failure {
        message: e.to_string(),
        ..f
    }
}

pub fn from_sol(e: &SolError) -> Failure {
    match e {
        SolError::Io { .. } => Failure::new("FileError", e.to_string()),
        SolError::NaN { vertex, .. } | SolError::InvalidSize { vertex, .. } => {
            Failure::new("MetricError", e.to_string())
                .with("vertices", Attr::Ints(vec![*vertex as i64]))
        }
        _ => Failure::new("MetricError", e.to_string()),
    }
}

/// Algorithm 1's errors: certificates, metric, input, stages, and Ctrl-C.
pub fn from_pipeline(e: &PipelineError) -> Failure {
    let msg = e.to_string();
    let located = |f: Failure, patch: &conemesh::PatchId, seed: &Option<conemesh::VertexId>| {
        let f = f.with("patch", Attr::Int(patch.0 as i64));
        match seed {
            Some(s) => f.with("seed", Attr::Int(s.0 as i64)),
            None => f,
        }
    };
    match e {
        PipelineError::Stage {
            patch,
            seed,
            stage,
            source,
        } => {
            let f = match source {
                StageError::Certificate(inv) => {
                    with_invariant(Failure::new("CertificateError", msg), inv)
                }
                _ => Failure::new("RemeshError", msg),
            };
            located(f, patch, seed).with("stage", Attr::Str(stage.to_string()))
        }
        PipelineError::Certificate {
            patch,
            seed,
            violation,
            ..
        } => located(
            with_invariant(Failure::new("CertificateError", msg), violation),
            patch,
            seed,
        ),
        PipelineError::Final(inv)
        | PipelineError::FileUnits(inv)
        | PipelineError::FeatureLines(inv) => {
            with_invariant(Failure::new("CertificateError", msg), inv)
        }
        PipelineError::CornerLost(v) => {
            Failure::new("CertificateError", msg).with("vertices", Attr::Ints(vec![v.0 as i64]))
        }
        PipelineError::FeatureLost(k) => Failure::new("CertificateError", msg)
            .with("edges", Attr::Pairs(vec![(k.0 .0 as i64, k.1 .0 as i64)])),
        PipelineError::Metric(m) => Failure {
            message: msg,
            ..from_metric(m)
        },
        PipelineError::NotManifold(inv) => with_invariant(Failure::input(msg), inv),
        PipelineError::SizedMetric(m) | PipelineError::FidelityMetric(m) => Failure {
            message: msg,
            ..from_metric(m)
        },
        PipelineError::MetricCount { .. } => Failure::new("MetricError", msg),
        PipelineError::Option(_) | PipelineError::ImproverOption { .. } => Failure::option(msg),
        PipelineError::EmptyInput
        | PipelineError::BadTarget { .. }
        | PipelineError::TargetTooSmall { .. }
        | PipelineError::Features(_) => Failure::input(msg),
        PipelineError::CrowdedVertex { vertex, .. } => {
            Failure::input(msg).with("vertices", Attr::Ints(vec![vertex.0 as i64]))
        }
        // The piece's failure decides the class; its ids are the piece's own, so they are
        // in the message only, with the piece's place.
        PipelineError::Region {
            level,
            index,
            source,
            ..
        } => Failure::new(from_pipeline(source).class, msg)
            .with("region_level", Attr::Str(level.to_string()))
            .with("region", Attr::Int(*index as i64)),
        _ => Failure::new("RemeshError", msg),
    }
}
