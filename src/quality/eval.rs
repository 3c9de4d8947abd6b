//! Scoring a remeshed surface against its input (Sec. 4.1, Table 1): the library half of
//! `conemesh eval`, so that tests, benchmarks and the CLI measure identically.
//!
//! Both meshes are mapped to the input's unit space (bounding-box diagonal 1, see
//! [`Normalization`]); the reference metric field lives on the input (the curvature metric of
//! Sec. 4.1, or tensors supplied by the user); every output vertex takes the metric of its
//! closest point on the input (barycentric interpolation, Sec. 4.1).

use super::{
    approximation_error, edge_conformity, edge_length_average, flips, quality_stats, Conformity,
    Distance, QualityStats,
};
use crate::ids::FaceId;
use crate::invariants::{certify_same_topology, self_intersections};
use crate::mesh::TriMesh;
use crate::metric::{MetricField, MetricOptions, Normalization};
use nalgebra::Matrix3;
use rand::SeedableRng;
use serde::Serialize;
use std::time::Instant;

/// How the target edge length L_tar is given.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum TargetLength {
    /// L_tar = factor · L_avg of the input (Table 1's "1.5 L_avg").
    Factor(f64),
    /// L_tar as a metric length in the input file's units.
    Absolute(f64),
}

/// Options of [`evaluate`], with their defaults.
#[derive(Clone, Debug)]
pub struct EvalOptions {
    /// Target edge length (default `Factor(1.5)`, the paper's usual choice).
    pub target: TargetLength,
    /// Curvature metric options, used when no per-vertex metric is supplied.
    pub metric: MetricOptions,
    /// Random samples per surface for the approximation error, on top of the vertices
    /// (default 100 000).
    pub samples: usize,
    /// Seed of the sampling (default 0).
    pub seed: u64,
    /// Search for self-intersections of the output (exact; default on).
    pub self_intersections: bool,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            target: TargetLength::Factor(1.5),
            metric: MetricOptions::default(),
            samples: 100_000,
            seed: 0,
            self_intersections: true,
        }
    }
}

/// Vertex and face counts of a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MeshSize {
    /// Vertices referenced by at least one face.
    pub vertices: usize,
    /// Faces.
    pub faces: usize,
}

impl MeshSize {
    fn of(m: &TriMesh) -> Self {
        MeshSize {
            vertices: m.n_vertices() - m.unreferenced_vertices().len(),
            faces: m.n_faces(),
        }
    }
}

/// Wall-clock seconds of the parts of [`evaluate`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EvalTimings {
    /// Building the metric field (curvature estimation + BVH).
    pub metric: f64,
    /// Evaluating the field at the output vertices and the quality statistics.
    pub quality: f64,
    /// Approximation error.
    pub distance: f64,
    /// Flips, self-intersections and topology.
    pub validity: f64,
}

/// Everything `conemesh eval` measures (written to JSON as is).
#[derive(Clone, Debug, Serialize)]
pub struct EvalReport {
    /// Input size.
    pub input: MeshSize,
    /// Output size.
    pub output: MeshSize,
    /// Where the metric came from: `"curvature"` or `"user"`.
    pub metric_source: String,
    /// Scale from file units to unit space (1 / input bbox diagonal).
    pub unit_scale: f64,
    /// L_avg of the input, in unit space.
    pub l_avg: f64,
    /// L_tar in unit space.
    pub l_tar: f64,
    /// How L_tar was given.
    pub target: TargetLength,
    /// Table-1 statistics of the input in the metric.
    pub input_quality: QualityStats,
    /// Table-1 statistics of the output in the metric.
    pub output_quality: QualityStats,
    /// Input edges / L_tar.
    pub input_conformity: Conformity,
    /// Output edges / L_tar.
    pub output_conformity: Conformity,
    /// Approximation error in unit space (absolute = relative to the input's diagonal).
    pub distance: Distance,
    /// Hausdorff distance in the input file's units.
    pub hausdorff_file_units: f64,
    /// Output faces flipped against the input ([`flips`]).
    pub flips: Vec<FaceId>,
    /// Intersecting output face pairs (empty when not searched).
    pub self_intersections: Vec<(FaceId, FaceId)>,
    /// Whether self-intersections were searched.
    pub self_intersections_checked: bool,
    /// Same components, genus and boundary loops as the input.
    pub topology_kept: bool,
    /// What changed, when the topology is not kept.
    pub topology_detail: Option<String>,
    /// Timings.
    pub timings: EvalTimings,
}

/// Errors of [`evaluate`].
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// The metric (a user metric that is not SPD on the input, or the curvature estimate).
    #[error(transparent)]
    Metric(#[from] crate::metric::MetricError),
    /// More random samples than [`MAX_SAMPLES`] were asked for (refused before any
    /// allocation).
    #[error("{0} random samples per surface asked for; at most {MAX_SAMPLES} are taken")]
    TooManySamples(usize),
}

/// The most random samples per surface [`evaluate`] takes (each costs 24 bytes and a
/// closest-point query; 10⁸ is already minutes of work).
pub const MAX_SAMPLES: usize = 100_000_000;

/// Score `output` against `input` (both in file units).
///
/// `input_metric`: per-input-vertex tensors in file units (e.g. read from a `.sol` file);
/// `None` computes the curvature metric of Sec. 4.1 on the unit-space input.
pub fn evaluate(
    input: &TriMesh,
    output: &TriMesh,
    input_metric: Option<&[Matrix3<f64>]>,
    opts: &EvalOptions,
) -> Result<EvalReport, EvalError> {
    if opts.samples > MAX_SAMPLES {
        return Err(EvalError::TooManySamples(opts.samples));
    }
    let norm = Normalization::of(input);
    let (unit_in, unit_out) = (norm.apply(input), norm.apply(output));

    let t0 = Instant::now();
    let (field, source) = match input_metric {
        Some(m) => (
            MetricField::from_surface_tensors(
                unit_in.clone(),
                m.iter().map(|x| norm.metric_to_unit(x)).collect(),
            )?,
            "user",
        ),
        None => (
            MetricField::from_curvature(unit_in.clone(), &opts.metric)?,
            "curvature",
        ),
    };
    let t_metric = t0.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let in_metrics = field.vertex_metrics();
    let out_metrics: Vec<Matrix3<f64>> = {
        use rayon::prelude::*;
        unit_out
            .positions
            .par_iter()
            .map(|p| field.eval(p))
            .collect()
    };
    let l_avg = edge_length_average(&unit_in, in_metrics);
    let l_tar = match opts.target {
        TargetLength::Factor(f) => f * l_avg,
        // A metric length does not depend on the scale: a vector scales by `scale` and the
        // metric by 1/scale² (`metric_to_unit`), so √(eᵀMe) is unchanged.
        TargetLength::Absolute(l) => l,
    };
    let input_quality = quality_stats(&unit_in, in_metrics);
    let output_quality = quality_stats(&unit_out, &out_metrics);
    let input_conformity = edge_conformity(&unit_in, in_metrics, l_tar);
    let output_conformity = edge_conformity(&unit_out, &out_metrics, l_tar);
    let t_quality = t0.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let mut rng = crate::Rng::seed_from_u64(opts.seed);
    let distance = approximation_error(&unit_in, &unit_out, opts.samples, &mut rng);
    let t_distance = t0.elapsed().as_secs_f64();

    let t0 = Instant::now();
    let flipped = flips(&unit_in, &unit_out);
    // Exact predicates: the unit-space copy may round differently from the file's
    // coordinates, so self-intersections are searched on the file-unit output.
    let si = if opts.self_intersections {
        self_intersections(output)
    } else {
        Vec::new()
    };
    let topo = certify_same_topology(input, output);
    let t_validity = t0.elapsed().as_secs_f64();

    Ok(EvalReport {
        input: MeshSize::of(input),
        output: MeshSize::of(output),
        metric_source: source.to_string(),
        unit_scale: norm.scale,
        l_avg,
        l_tar,
        target: opts.target,
        input_quality,
        output_quality,
        input_conformity,
        output_conformity,
        hausdorff_file_units: distance.hausdorff / norm.scale,
        distance,
        flips: flipped,
        self_intersections: si,
        self_intersections_checked: opts.self_intersections,
        topology_kept: topo.is_ok(),
        topology_detail: topo.err().map(|e| e.to_string()),
        timings: EvalTimings {
            metric: t_metric,
            quality: t_quality,
            distance: t_distance,
            validity: t_validity,
        },
    })
}

impl EvalReport {
    /// The column header of [`EvalReport::table_row`].
    pub fn table_header() -> String {
        format!(
            "{:<16} {:>7} {:>7}  {:<19}  {:<25}  {:>6} {:>6} {:>6} {:>6}  {:<11} {:>7}  {:>9} {:>9}  {:>5} {:>8} {:>8}",
            "mesh", "V", "F", "q_min/q_max/q_avg", "θ_min/θ_max/θ_avg", "<10°", "<20°", "<30°",
            ">120°", "L/L_tar", "inrange", "Hausd.%", "RMS%", "flips", "self-int", "topology"
        )
    }

    /// One line in the spirit of the paper's Table 1, for the output: sizes, q and θ
    /// statistics, % of small / large angles, mean±std of L/L_tar and the % in
    /// [1/√2, √2], Hausdorff and RMS in % of the input's diagonal, flips, self-intersections
    /// (`-` when not searched) and whether the topology is kept.
    pub fn table_row(&self, name: &str) -> String {
        let q = &self.output_quality;
        let c = &self.output_conformity;
        let si = if self.self_intersections_checked {
            self.self_intersections.len().to_string()
        } else {
            "-".to_string()
        };
        format!(
            "{:<16} {:>7} {:>7}  {:<19}  {:<25}  {:>6.2} {:>6.2} {:>6.2} {:>6.2}  {:<11} {:>6.1}%  {:>9.4} {:>9.4}  {:>5} {:>8} {:>8}",
            name,
            self.output.vertices,
            self.output.faces,
            format!("{:.3}/{:.3}/{:.3}", q.q_min, q.q_max, q.q_avg),
            format!("{:.2}°/{:.2}°/{:.2}°", q.theta_min, q.theta_max, q.theta_avg),
            q.pct_min_angle_lt_10,
            q.pct_min_angle_lt_20,
            q.pct_min_angle_lt_30,
            q.pct_max_angle_gt_120,
            format!("{:.2}±{:.2}", c.mean, c.std),
            100.0 * c.fraction_in_range,
            100.0 * self.distance.hausdorff_rel,
            100.0 * self.distance.rms_rel,
            self.flips.len(),
            si,
            if self.topology_kept { "yes" } else { "no" },
        )
    }
}
