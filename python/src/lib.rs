//! `conemesh._conemesh`, the extension module of the Python package (issue 21). The public
//! functions, their numpydoc and the keyword handling are in `conemesh/__init__.py`; this
//! module takes checked numpy arrays and CLI-style argument lists and calls the library.
//!
//! `remesh` keywords become `conemesh remesh` flags, parsed by the library's one clap
//! definition of them ([`conemesh::job::RemeshArgs`], which the CLI parses too) and run as
//! the library's job ([`conemesh::job`]), so a keyword's default is the flag's default and
//! the output is the CLI's by construction. Work runs with the GIL released; Ctrl-C is seen
//! after each patch and stops the run through [`conemesh::pipeline::Cancel`].

use clap::{ArgAction, CommandFactory, Parser};
use conemesh::job::{JobError, JobInput, ProgressBar, RemeshArgs, Source};
use conemesh::pipeline::{PipelineError, Progress};
use conemesh::quality::{EvalOptions, TargetLength};
use conemesh::{TriMesh, VertexId};
use errors::{Attr, Failure};
use nalgebra::{Matrix3, Point3};
use numpy::ndarray::{Array1, Array2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::time::Instant;

mod errors;

/// `conemesh remesh`'s arguments as their own command, as `src/main.rs` declares it.
#[derive(Parser, Debug)]
#[command(name = "conemesh remesh", allow_negative_numbers = true)]
struct RemeshCli {
    #[command(flatten)]
    args: RemeshArgs,
}

type PyResultOf<T> = Result<T, Failure>;

/// `(V, F)` as numpy arrays: `(n, 3)` float64 and `(m, 3)` int64.
type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

fn raise<T>(py: Python<'_>, r: PyResultOf<T>) -> PyResult<T> {
    r.map_err(|f| f.into_pyerr(py))
}

// ---------------------------------------------------------------- arrays

/// `(n, 3)` float64 and `(m, 3)` int64 arrays (dtypes already coerced by the Python layer)
/// as a [`TriMesh`], or an `InputError` naming the face or vertex.
fn mesh_of(v: &PyReadonlyArray2<'_, f64>, f: &PyReadonlyArray2<'_, i64>) -> PyResultOf<TriMesh> {
    let (v, f) = (v.as_array(), f.as_array());
    if v.ncols() != 3 {
        return Err(Failure::input(format!(
            "V must have shape (n, 3), got {:?}",
            v.shape()
        )));
    }
    if f.ncols() != 3 {
        return Err(Failure::input(format!(
            "F must have shape (m, 3), got {:?}",
            f.shape()
        )));
    }
    let positions: Vec<Point3<f64>> = v
        .rows()
        .into_iter()
        .map(|r| Point3::new(r[0], r[1], r[2]))
        .collect();
    let mut tris = Vec::with_capacity(f.nrows());
    for (i, r) in f.rows().into_iter().enumerate() {
        let mut t = [0usize; 3];
        for k in 0..3 {
            t[k] = usize::try_from(r[k]).map_err(|_| {
                Failure::input(format!(
                    "face f{i} references vertex index {}, which is negative",
                    r[k]
                ))
                .with("faces", Attr::Ints(vec![i as i64]))
                .with("index", Attr::Int(r[k]))
            })?;
        }
        tris.push(t);
    }
    TriMesh::from_indices(positions, &tris).map_err(|e| errors::from_mesh(&e))
}

fn positions_array<'py>(py: Python<'py>, pts: &[Point3<f64>]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = pts.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    // The shape is the vector's length by construction.
    Array2::from_shape_vec((pts.len(), 3), flat)
        .unwrap_or_else(|_| Array2::zeros((0, 3)))
        .into_pyarray(py)
}

fn faces_array<'py>(py: Python<'py>, tris: &[[VertexId; 3]]) -> Bound<'py, PyArray2<i64>> {
    let flat: Vec<i64> = tris.iter().flat_map(|t| t.map(|v| v.0 as i64)).collect();
    Array2::from_shape_vec((tris.len(), 3), flat)
        .unwrap_or_else(|_| Array2::zeros((0, 3)))
        .into_pyarray(py)
}

/// A user metric: an `(n, 3, 3)` array of symmetric tensors (file units), or a `.sol` path.
fn metric_of(
    array: Option<PyReadonlyArray3<'_, f64>>,
    path: Option<PathBuf>,
    n_vertices: usize,
) -> PyResultOf<Option<Vec<Matrix3<f64>>>> {
    if let Some(p) = path {
        return conemesh::io::sol::read_sol(&p, n_vertices)
            .map(Some)
            .map_err(|e| errors::from_sol(&e));
    }
    let Some(a) = array else { return Ok(None) };
    let a = a.as_array();
    if a.shape() != [n_vertices, 3, 3] {
        return Err(Failure::new(
            "MetricError",
            format!(
                "metric must have shape ({n_vertices}, 3, 3), one tensor per vertex, got {:?}",
                a.shape()
            ),
        ));
    }
    let mut out = Vec::with_capacity(n_vertices);
    for v in 0..n_vertices {
        let m = Matrix3::from_fn(|i, j| a[[v, i, j]]);
        let bad = |what: &str| {
            Failure::new("MetricError", format!("metric at vertex v{v} {what}"))
                .with("vertices", Attr::Ints(vec![v as i64]))
        };
        if m.iter().any(|x| !x.is_finite()) {
            return Err(bad("has a NaN or infinite entry"));
        }
        // Relative: a metric in file units may have any scale.
        let scale = m.abs().max().max(f64::MIN_POSITIVE);
        if (m - m.transpose()).abs().max() > 1e-12 * scale {
            return Err(bad("is not symmetric"));
        }
        out.push(m);
    }
    Ok(Some(out))
}

// ---------------------------------------------------------------- files

/// `read(path) -> ((V, F), warnings)`.
#[pyfunction]
fn read<'py>(py: Python<'py>, path: PathBuf) -> PyResult<(MeshArrays<'py>, Vec<String>)> {
    let loaded = raise(
        py,
        py.detach(|| conemesh::io::read_mesh(&path).map_err(|e| errors::from_io(&e))),
    )?;
    let warnings = loaded.warnings.iter().map(|w| w.to_string()).collect();
    Ok((
        (
            positions_array(py, &loaded.mesh.positions),
            faces_array(py, &loaded.mesh.triangles),
        ),
        warnings,
    ))
}

/// `write(path, V, F)`: the format by extension, written atomically.
#[pyfunction]
fn write(
    py: Python<'_>,
    path: PathBuf,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
) -> PyResult<()> {
    let mesh = raise(py, mesh_of(&v, &f))?;
    raise(
        py,
        py.detach(|| conemesh::io::write_mesh(&path, &mesh).map_err(|e| errors::from_io(&e))),
    )
}

// ---------------------------------------------------------------- remesh

/// The keywords of `remesh`: every option of `conemesh remesh` but the input and `-o`, with
/// its flag, kind (`flag`, `value`, `list`), value type (`bool`, `int`, `float`, `str`),
/// default (as the CLI prints it), choices and help.
#[pyfunction]
fn remesh_options(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let cmd = RemeshCli::command();
    let mut out = Vec::new();
    for a in cmd.get_arguments() {
        let (Some(long), false) = (a.get_long(), a.is_positional()) else {
            continue;
        };
        let kind = match a.get_action() {
            ArgAction::SetTrue => "flag",
            ArgAction::Append => "list",
            ArgAction::Set => "value",
            _ => continue, // --help
        };
        let id = a.get_id().as_str();
        if id == "output" {
            continue; // the arrays are returned
        }
        let d = PyDict::new(py);
        d.set_item("name", id)?;
        d.set_item("flag", format!("--{long}"))?;
        d.set_item("kind", kind)?;
        let default: Option<String> = a
            .get_default_values()
            .first()
            .map(|s| s.to_string_lossy().into_owned());
        d.set_item("default", default.clone())?;
        let choices: Vec<String> = a
            .get_possible_values()
            .iter()
            .map(|p| p.get_name().to_string())
            .collect();
        // The value's type, asked of the option's own parser: a probe value it accepts.
        // A default that is not a number (`--feature-angle off`, which also takes degrees)
        // makes it a string option.
        let accepts = |v: &str| parse_args(&[format!("--{long}={v}")]).is_ok();
        let word_default = default
            .as_deref()
            .is_some_and(|d| d.parse::<f64>().is_err());
        let ty = match kind {
            "flag" => "bool",
            _ if !choices.is_empty() || accepts("x") || word_default => "str",
            _ if accepts("1") && !accepts("0.5") => "int",
            _ => "float",
        };
        d.set_item("type", ty)?;
        d.set_item("choices", choices)?;
        d.set_item(
            "help",
            a.get_long_help()
                .or(a.get_help())
                .map(|h| h.to_string())
                .unwrap_or_default(),
        )?;
        out.push(d);
    }
    Ok(out)
}

/// clap's verdict on an argument list, in the keywords' words (`ltar_factor`, not
/// `--ltar-factor <LTAR_FACTOR>`).
fn parse_args(args: &[String]) -> PyResultOf<RemeshArgs> {
    let argv = std::iter::once("conemesh remesh".to_string()).chain(args.iter().cloned());
    RemeshCli::try_parse_from(argv)
        .map(|c| c.args)
        .map_err(|e| {
            let rendered = e.render().to_string();
            let first = rendered
                .lines()
                .find(|l| l.starts_with("error:"))
                .unwrap_or(rendered.as_str())
                .trim_start_matches("error:")
                .trim();
            Failure::option(keywordify(first))
        })
}

/// `'--ltar-factor <LTAR_FACTOR>'` → `'ltar_factor'`.
fn keywordify(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(i) = rest.find("--") {
        out.push_str(&rest[..i]);
        let tail = &rest[i + 2..];
        let end = tail
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .unwrap_or(tail.len());
        out.push_str(&tail[..end].replace('-', "_"));
        let mut after = &tail[end..];
        if let Some(v) = after.strip_prefix(" <") {
            if let Some(j) = v.find('>') {
                after = &v[j + 1..];
            }
        }
        rest = after;
    }
    out.push_str(rest);
    out
}

/// Check an argument list without running anything (`conemesh.batch` does so before it
/// submits a task).
#[pyfunction]
fn check_remesh_args(py: Python<'_>, args: Vec<String>) -> PyResult<()> {
    raise(py, parse_args(&args).map(|_| ()))
}

/// What a remesh returns across the GIL boundary.
struct Remeshed {
    mesh: TriMesh,
    report: String,
}

/// An error and its sources, as `anyhow`'s `{:#}` prints them (`a: b: c`).
fn chain(e: &dyn std::error::Error) -> String {
    let mut out = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        out.push_str(": ");
        out.push_str(&s.to_string());
        source = s.source();
    }
    out
}

/// The whole of `conemesh remesh` on arrays: the library's job with the same arguments, so
/// that the output mesh is the CLI's byte for byte for the same seed.
fn remesh_job(
    args: &RemeshArgs,
    mesh: TriMesh,
    metric: Option<Vec<Matrix3<f64>>>,
    mut on_progress: impl FnMut(Progress) -> bool,
) -> PyResultOf<Remeshed> {
    let started = Instant::now();
    if let Some(n) = args.threads {
        // The CLI sizes the process's one rayon pool at start; a Python process may already
        // have used it.
        return Err(Failure::option(format!(
            "threads={n}: set RAYON_NUM_THREADS before the first remesh instead (the package uses the process's thread pool; the output is the same for every count)"
        )));
    }
    // The output paths first, as the CLI checks them: a bad path costs no remesh.
    args.check_output_paths(false)
        .map_err(|e| Failure::new("FileError", keywordify(&e.to_string())))?;
    let input = JobInput {
        mesh,
        metric,
        repeated_index_faces: Vec::new(),
        started,
    };
    let prepared = input.prepare(args.repair_options().as_ref()).map_err(|e| {
        let message = format!("repairing the input: {}", chain(&e));
        match &e {
            conemesh::repair::RepairError::Unrepaired(v) => {
                errors::with_invariant(Failure::input(message), v)
            }
            _ => Failure::input(message),
        }
    })?;
    if let Some(log) = &prepared.repair {
        eprintln!("repair: {}", log.summary());
    }
    // The pipeline refuses a non-manifold input with a message; certify it here first so
    // that the exception names the elements, in the caller's numbering.
    let topo = conemesh::Topology::build(&prepared.mesh);
    conemesh::invariants::certify_manifold(&prepared.mesh, &topo)
        .and_then(|()| conemesh::invariants::certify_oriented(&prepared.mesh, &topo))
        .map_err(|e| {
            errors::with_invariant(
                Failure::input(format!(
                    "the input mesh is not an oriented manifold: {e} (repair=True orients it and cuts non-manifold edges and vertices)"
                )),
                &e,
            )
        })?;
    let mut job = args
        .job(prepared.metric.is_some())
        .map_err(|e| Failure::option(chain(&e)))?;
    // The CLI writes offending patches beside its output; an array has no such folder.
    job.remesher.options.debug_dir = args.debug_dir.clone();
    let cancel = job.remesher.options.cancel.clone();
    let bar = ProgressBar::new(args.quiet, prepared.mesh.n_faces());
    let result = job.remesh(prepared, |p: Progress| {
        bar.show(p);
        if !on_progress(p) {
            cancel.cancel();
        }
    });
    bar.finish();
    let outcome = result.map_err(|e| match e {
        JobError::Remesh(PipelineError::Cancelled { patches }) => Failure::new(
            "KeyboardInterrupt",
            format!("remesh cancelled after {patches} patches"),
        ),
        JobError::Remesh(e) => errors::from_pipeline(&e),
        e => Failure::new("RemeshError", e.to_string()),
    })?;
    // The files asked for, as one transaction (the CLI's): all or none. The report is the
    // CLI's `--report` document, with the Table-1 line added.
    let mut outputs = conemesh::io::Outputs::new();
    let json = outcome
        .stage_files(&mut outputs, &args.files(false), &Source::Arrays)
        .map_err(|e| Failure::new("FileError", chain(&e)))?;
    conemesh::io::paths::commit(outputs).map_err(|e| Failure::new("FileError", chain(&e)))?;
    let report =
        serde_json::to_string(&json).map_err(|e| Failure::new("RemeshError", e.to_string()))?;
    Ok(Remeshed {
        mesh: outcome.remeshed.mesh,
        report,
    })
}

/// `remesh(V, F, metric_array, metric_path, args) -> ((V, F), report_json)`.
#[pyfunction]
#[pyo3(signature = (v, f, metric_array, metric_path, args))]
fn remesh<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    metric_array: Option<PyReadonlyArray3<'py, f64>>,
    metric_path: Option<PathBuf>,
    args: Vec<String>,
) -> PyResult<(MeshArrays<'py>, String)> {
    let parsed = raise(py, parse_args(&args))?;
    let mesh = raise(py, mesh_of(&v, &f))?;
    let metric = raise(py, metric_of(metric_array, metric_path, mesh.n_vertices()))?;
    let mut interrupt: Option<PyErr> = None;
    let result = py.detach(|| {
        remesh_job(&parsed, mesh, metric, |_| {
            // Signals are Python's to deliver: take the GIL for a moment after each patch.
            match Python::attach(|py| py.check_signals()) {
                Ok(()) => true,
                Err(e) => {
                    interrupt = Some(e);
                    false
                }
            }
        })
    });
    match result {
        Ok(out) => Ok((
            (
                positions_array(py, &out.mesh.positions),
                faces_array(py, &out.mesh.triangles),
            ),
            out.report,
        )),
        Err(failure) => match (failure.class, interrupt) {
            ("KeyboardInterrupt", Some(e)) => Err(e),
            ("KeyboardInterrupt", None) => Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(
                failure.message,
            )),
            _ => Err(failure.into_pyerr(py)),
        },
    }
}

// ---------------------------------------------------------------- eval, check, patches, param

/// `conemesh eval` on arrays: the JSON report, with the Table-1 line.
#[pyfunction]
#[pyo3(signature = (v_in, f_in, v_out, f_out, metric_array, metric_path, ltar_factor, ltar, samples, seed, self_intersections, name))]
#[allow(clippy::too_many_arguments)]
fn evaluate(
    py: Python<'_>,
    v_in: PyReadonlyArray2<'_, f64>,
    f_in: PyReadonlyArray2<'_, i64>,
    v_out: PyReadonlyArray2<'_, f64>,
    f_out: PyReadonlyArray2<'_, i64>,
    metric_array: Option<PyReadonlyArray3<'_, f64>>,
    metric_path: Option<PathBuf>,
    ltar_factor: Option<f64>,
    ltar: Option<f64>,
    samples: usize,
    seed: u64,
    self_intersections: bool,
    name: String,
) -> PyResult<String> {
    let input = raise(py, mesh_of(&v_in, &f_in))?;
    let output = raise(py, mesh_of(&v_out, &f_out))?;
    let metric = raise(py, metric_of(metric_array, metric_path, input.n_vertices()))?;
    // The checks of `conemesh eval`, in the keywords' words.
    let target = raise(
        py,
        match (ltar, ltar_factor) {
            (Some(_), Some(_)) => Err(Failure::option(
                "ltar and ltar_factor cannot be given together",
            )),
            (Some(l), None) if !(l > 0.0 && l.is_finite()) => {
                Err(Failure::option(format!("ltar must be positive, got {l}")))
            }
            (Some(l), None) => Ok(TargetLength::Absolute(l)),
            (None, f) => {
                let f = f.unwrap_or(1.5);
                match f > 0.0 && f.is_finite() {
                    true => Ok(TargetLength::Factor(f)),
                    false => Err(Failure::option(format!(
                        "ltar_factor must be positive, got {f}"
                    ))),
                }
            }
        },
    )?;
    let opts = EvalOptions {
        target,
        samples,
        seed,
        self_intersections,
        ..EvalOptions::default()
    };
    let report = py.detach(|| {
        conemesh::quality::evaluate(&input, &output, metric.as_deref(), &opts).map_err(|e| match &e
        {
            conemesh::quality::EvalError::Metric(m) => errors::from_metric(m),
            _ => Failure::option(e.to_string()),
        })
    });
    let report = raise(py, report)?;
    let json = serde_json::json!({
        "report": report,
        "table_header": conemesh::quality::EvalReport::table_header(),
        "table_row": report.table_row(&name),
    });
    Ok(json.to_string())
}

/// `conemesh check --json` on arrays.
#[pyfunction]
fn check(
    py: Python<'_>,
    v: PyReadonlyArray2<'_, f64>,
    f: PyReadonlyArray2<'_, i64>,
    self_intersections: bool,
) -> PyResult<String> {
    let mesh = raise(py, mesh_of(&v, &f))?;
    let opts = conemesh::check::CheckOptions { self_intersections };
    let report = py.detach(|| conemesh::check::check_mesh(&mesh, &opts));
    serde_json::to_string(&report)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

/// `conemesh patches` on arrays: per-face patch ids and the per-patch statistics (JSON).
#[pyfunction]
fn patches<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    seed: u64,
    strategy: String,
    strategy_opt: Vec<String>,
) -> PyResult<(Bound<'py, PyArray1<i64>>, String)> {
    use rand::SeedableRng;
    let mesh = raise(py, mesh_of(&v, &f))?;
    let run = py.detach(|| {
        // Built here: a strategy need not be `Sync`.
        let params = conemesh::registry::Params::parse(&strategy_opt)
            .map_err(|e| Failure::option(e.to_string()))?;
        let strat = conemesh::patches::strategy(&strategy, params)
            .map_err(|e| Failure::option(e.to_string()))?;
        // The pipeline's working units (bounding-box diagonal 1), as `conemesh patches`.
        let work = conemesh::metric::Normalization::of(&mesh).apply(&mesh);
        let mut rng = conemesh::Rng::seed_from_u64(seed);
        conemesh::patches::cover(
            &work,
            strat.as_ref(),
            &conemesh::patches::CoverOptions::default(),
            &mut rng,
        )
        .map_err(|e| Failure::new("RemeshError", e.to_string()))
    });
    let run = raise(py, run)?;
    if !run.complete {
        return Err(Failure::new(
            "RemeshError",
            format!(
                "the `{}` strategy stopped after {} patches with faces still uncovered",
                run.strategy,
                run.patches.len()
            ),
        )
        .into_pyerr(py));
    }
    let ids: Vec<i64> = run
        .patch_of_face
        .iter()
        .map(|p| p.map_or(-1, |p| p.0 as i64))
        .collect();
    let stats = serde_json::json!({"strategy": run.strategy, "seed": seed, "stats": run.stats});
    Ok((Array1::from(ids).into_pyarray(py), stats.to_string()))
}

/// `conemesh param` on arrays: uv per vertex (NaN for vertices no face uses) and the
/// distortion report (JSON).
#[pyfunction]
fn param<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    method: String,
) -> PyResult<(Bound<'py, PyArray2<f64>>, String)> {
    use conemesh::param::{disk_boundary, Parameterizer, SymmetricDirichlet, Tutte};
    let full = raise(py, mesh_of(&v, &f))?;
    let result = py.detach(|| {
        // Built here: a parameterizer need not be `Sync`.
        let p: Box<dyn Parameterizer> = match method.as_str() {
            "sd" => Box::new(SymmetricDirichlet::default()),
            "tutte" => Box::new(Tutte::default()),
            other => {
                return Err(Failure::option(format!(
                    "method must be \"sd\" or \"tutte\", got {other:?}"
                )))
            }
        };
        let (mesh, map) = full.without_unreferenced_vertices();
        let boundary = disk_boundary(&mesh).map_err(|e| Failure::input(e.to_string()))?;
        let out = p
            .parameterize(&mesh, &boundary)
            .map_err(|e| Failure::new("RemeshError", e.to_string()))?;
        // Re-check independently of the parameterizer, as `conemesh param` does.
        conemesh::invariants::certify_bijective(&out.uv, &mesh.triangles, &boundary).map_err(
            |e| errors::with_invariant(Failure::new("CertificateError", e.to_string()), &e),
        )?;
        let mut uv = vec![[f64::NAN; 2]; full.n_vertices()];
        for (old, new) in map.iter().enumerate() {
            if let Some(n) = new {
                let q = out.uv[n.idx()];
                uv[old] = [q.x, q.y];
            }
        }
        let report = serde_json::json!({"method": p.name(), "distortion": out.report});
        Ok::<_, Failure>((uv, report.to_string()))
    });
    let (uv, report) = raise(py, result)?;
    let n = uv.len();
    let arr = Array2::from_shape_vec((n, 2), uv.into_iter().flatten().collect())
        .unwrap_or_else(|_| Array2::zeros((0, 2)));
    Ok((arr.into_pyarray(py), report))
}

// ---------------------------------------------------------------- render

/// The metric of `render`: per vertex of the mesh drawn when its count matches, else per
/// vertex of the reference (as `conemesh render --metric`); `true` for the mesh's.
fn render_metric(
    array: Option<PyReadonlyArray3<'_, f64>>,
    path: Option<PathBuf>,
    n_mesh: usize,
    n_reference: Option<usize>,
) -> PyResultOf<Option<(Vec<Matrix3<f64>>, bool)>> {
    let count = match (&array, &path) {
        (Some(a), _) => a.as_array().shape()[0],
        (None, Some(p)) => match conemesh::io::sol::read_sol(p, n_mesh) {
            Ok(m) => return Ok(Some((m, true))),
            Err(conemesh::io::sol::SolError::CountMismatch { found, .. }) => found,
            Err(e) => return Err(errors::from_sol(&e)),
        },
        (None, None) => return Ok(None),
    };
    let on_mesh = count == n_mesh || n_reference != Some(count);
    let n = if on_mesh { n_mesh } else { count };
    Ok(metric_of(array, path, n)?.map(|m| (m, on_mesh)))
}

/// `conemesh render` on arrays: the picture as an `(H, W, 3)` uint8 array.
#[pyfunction]
#[pyo3(signature = (v, f, color, metric_array, metric_path, v_ref, f_ref, patches, width, height, wireframe))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    v: PyReadonlyArray2<'py, f64>,
    f: PyReadonlyArray2<'py, i64>,
    color: String,
    metric_array: Option<PyReadonlyArray3<'py, f64>>,
    metric_path: Option<PathBuf>,
    v_ref: Option<PyReadonlyArray2<'py, f64>>,
    f_ref: Option<PyReadonlyArray2<'py, i64>>,
    patches: Option<PyReadonlyArray1<'py, i64>>,
    width: u32,
    height: u32,
    wireframe: String,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    use conemesh::render::{ColorBy, RenderError, RenderOptions, Sources, VertexMetric, Wireframe};
    let mesh = raise(py, mesh_of(&v, &f))?;
    let reference = match (&v_ref, &f_ref) {
        (Some(rv), Some(rf)) => Some(raise(py, mesh_of(rv, rf))?),
        _ => None,
    };
    let color = raise(
        py,
        ColorBy::parse(&color).map_err(|e| Failure::option(e.to_string())),
    )?;
    let wireframe = raise(
        py,
        match wireframe.as_str() {
            "auto" => Ok(Wireframe::Auto),
            "on" => Ok(Wireframe::On),
            "off" => Ok(Wireframe::Off),
            w => Err(Failure::option(format!(
                "wireframe: expected auto, on or off, got {w:?}"
            ))),
        },
    )?;
    let n_ref = reference.as_ref().map(|r| r.n_vertices());
    let metric = raise(
        py,
        render_metric(metric_array, metric_path, mesh.n_vertices(), n_ref),
    )?;
    let patches: Option<Vec<Option<conemesh::PatchId>>> = patches.map(|p| {
        p.as_array()
            .iter()
            .map(|&i| u32::try_from(i).ok().map(conemesh::PatchId))
            .collect()
    });
    let opts = RenderOptions {
        width,
        height,
        wireframe,
        ..Default::default()
    };
    let img = py.detach(|| {
        let sources = Sources {
            metric: (metric.as_ref()).map(|(m, on_mesh)| VertexMetric::new(m, *on_mesh)),
            reference: reference.as_ref(),
            patches: patches.as_deref(),
            ..Default::default()
        };
        let drawn = conemesh::render::face_colors(&mesh, color, &sources)
            .and_then(|c| conemesh::render::render(&mesh, &c, &opts));
        drawn.map(|(img, _)| img).map_err(|e| match &e {
            RenderError::Metric(m) => errors::from_metric(m),
            RenderError::EmptyMesh | RenderError::NonFinite { .. } => Failure::input(e.to_string()),
            _ => Failure::option(e.to_string()),
        })
    });
    let img = raise(py, img)?;
    let shape = (img.height as usize, img.width as usize, 3);
    let arr = numpy::ndarray::Array3::from_shape_vec(shape, img.rgb)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("picture buffer: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// The `conemesh remesh` arguments `conemesh compare` sets for every run (a configuration may
/// not set them), from the library's one list.
#[pyfunction]
fn compare_own_args() -> Vec<&'static str> {
    conemesh::compare::config::OWN_ARGS.to_vec()
}

/// `conemesh compare`'s statistics of configuration `config` (grid index, the first being 0)
/// against the first on measure `measure` (index in its measure list), over `(first, other)`
/// pairs: the same bootstrap stream, interval and sign test as the CLI's `compare.json`.
#[pyfunction]
fn paired_stats(
    pairs: Vec<(f64, f64)>,
    higher_is_better: bool,
    config: usize,
    measure: usize,
) -> PyResult<String> {
    use conemesh::compare::stats::{paired, Better};
    let better = match higher_is_better {
        true => Better::Higher,
        false => Better::Lower,
    };
    let seed = conemesh::compare::paired_seed(config, measure);
    serde_json::to_string(&paired(&pairs, better, seed))
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

#[pymodule]
fn _conemesh(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(paired_stats, m)?)?;
    m.add_function(wrap_pyfunction!(compare_own_args, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(remesh_options, m)?)?;
    m.add_function(wrap_pyfunction!(check_remesh_args, m)?)?;
    m.add_function(wrap_pyfunction!(remesh, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(patches, m)?)?;
    m.add_function(wrap_pyfunction!(param, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
