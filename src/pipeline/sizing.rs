//! Sizing, resolved once into a [`Plan`] before the loop: L_avg and L_tar, the fidelity
//! tolerance and its a-priori metric scaling, the expected output size, and whether the
//! coarse-input profile runs.

use super::error::PipelineError;
use super::options::{CoarseInput, RemeshOptions, TargetLength, COARSE_RATIO, DENSE_INPUT_RATIO};
use crate::fidelity;
use crate::ids::VertexId;
use crate::mesh::{Topology, TriMesh};
use crate::metric::{apply_sizes, MetricField};
use nalgebra::Matrix3;

/// Largest expected output ([`expected_faces`] in the metric at L_tar) a run accepts.
pub const MAX_EXPECTED_FACES: f64 = 1e8;

/// The floor of [`Plan::patch_face_cap`]'s base, so that a tiny input's patches are never
/// capped near their legitimate size (LCT meshes a patch of this size in milliseconds).
pub const MIN_PATCH_FACE_CAP: f64 = 1000.0;

/// Everything a run derives from the input and the options before its first patch.
pub struct Plan {
    /// The options the run uses: the caller's, or [`RemeshOptions::coarse_profile`] of them.
    pub options: RemeshOptions,
    /// The input's face count.
    pub faces_in: usize,
    /// Mean metric edge length of the input.
    pub l_avg: f64,
    /// Target metric edge length.
    pub l_tar: f64,
    /// Fidelity tolerance (unit space; 0 = off).
    pub eps: f64,
    /// The fidelity control's refinement floor (unit-space length).
    pub min_edge: f64,
    /// The a-priori fidelity factor per reference vertex (empty when the control is off).
    pub fid_scale: Vec<f64>,
    /// [`expected_faces`] in the metric alone.
    pub expected: f64,
    /// The same with the a-priori scaling of the caller's options (decides the profile).
    pub expected_fidelity: f64,
    /// The coarse-input profile runs.
    pub coarse: bool,
    /// The input edges that are feature lines ([`crate::features::FeatureRule::edges`]).
    pub feature_edges: Vec<crate::ids::EdgeKey>,
    /// The metric with the size controls applied ([`RemeshOptions::sizes`]), when they are on:
    /// the run's metric, for the remeshing and every measure.
    sized: Option<MetricField>,
    /// The run's metric with the a-priori scaling applied, when there is one.
    scaled: Option<MetricField>,
}

impl Plan {
    /// Resolve the sizes of a run on `field`'s reference mesh (whose topology is `topo`).
    /// Errors for an empty input, option values no run can use, and a target length that is
    /// not a finite positive number or would give more than [`MAX_EXPECTED_FACES`] faces.
    pub fn resolve(
        field: &MetricField,
        topo: &Topology,
        options: &RemeshOptions,
    ) -> Result<Plan, PipelineError> {
        let reference = field.reference();
        if reference.n_faces() == 0 {
            return Err(PipelineError::EmptyInput);
        }
        options.validate()?;
        let (l_avg, l_tar) = target_length(field, options)?;
        let sized = sized_metric(field, l_tar, options)?;
        let field = sized.as_ref().unwrap_or(field);
        let expected = expected_faces(reference, field.vertex_metrics(), &[], l_tar);
        // A target far below the input's size would run for hours and exhaust memory: refuse
        // it up front, naming the count.
        if expected.is_nan() || expected > MAX_EXPECTED_FACES {
            return Err(PipelineError::TargetTooSmall {
                l_tar,
                expected,
                max: MAX_EXPECTED_FACES,
            });
        }
        let (mut min_edge, mut fid_scale) = a_priori(field, topo, options, l_tar);
        let expected_fidelity =
            expected_faces(reference, field.vertex_metrics(), &fid_scale, l_tar);
        // An input where the distance tolerance, not the metric, sets the output's size runs
        // the coarse-input profile (paper-notes "Coarse inputs"), unless it is already finer
        // than that output: then its edges, the first sweep's seams, are shorter than the
        // output's, which is what the profile's sweeps are for. Its finer floor needs the
        // a-priori scaling again.
        let coarse = match options.coarse_input {
            CoarseInput::On => true,
            CoarseInput::Off => false,
            CoarseInput::Auto => is_coarse(reference.n_faces(), expected, expected_fidelity),
        };
        let options = if coarse {
            let profile = options.coarse_profile();
            (min_edge, fid_scale) = a_priori(field, topo, &profile, l_tar);
            profile
        } else {
            options.clone()
        };
        let feature_edges =
            refine_beside_features(field, topo, &options, (l_tar, min_edge), &mut fid_scale);
        let scaled = scaled_metric(field, &fid_scale)?;
        Ok(Plan {
            faces_in: reference.n_faces(),
            eps: options.fidelity.max_deviation,
            options,
            l_avg,
            l_tar,
            min_edge,
            fid_scale,
            expected,
            expected_fidelity,
            coarse,
            feature_edges,
            sized,
            scaled,
        })
    }

    /// The most faces one patch's remesh may have: the whole run's face budget
    /// ([`RemeshOptions::face_budget`] times the largest of the expected output with the
    /// fidelity scaling, the input's face count and [`MIN_PATCH_FACE_CAP`]). No patch of a sane
    /// run comes near it; a patch whose metric is many orders off for its domain stops there.
    pub fn patch_face_cap(&self) -> f64 {
        let faces_in = self.faces_in as f64;
        let base = self.expected_fidelity.max(faces_in).max(MIN_PATCH_FACE_CAP);
        self.options.face_budget * base
    }

    /// The run's metric: `input` with the size controls applied, when they are on.
    pub fn quality_field<'a>(&'a self, input: &'a MetricField) -> &'a MetricField {
        self.sized.as_ref().unwrap_or(input)
    }

    /// The metric the patches are remeshed in: the run's metric with the a-priori fidelity
    /// scaling, when there is one. Every quality measure uses the run's metric.
    pub fn remesh_field<'a>(&'a self, input: &'a MetricField) -> &'a MetricField {
        self.scaled.as_ref().unwrap_or(self.quality_field(input))
    }
}

/// The input's mean metric edge length `L_avg` and the target `L_tar` (Sec. 3.1): the factor
/// times `L_avg`, or the absolute length. An error names where a target that is not a finite
/// positive number came from.
fn target_length(
    field: &MetricField,
    options: &RemeshOptions,
) -> Result<(f64, f64), PipelineError> {
    let reference = field.reference();
    let l_avg = crate::quality::edge_length_average(reference, field.vertex_metrics());
    let l_tar = match options.target {
        TargetLength::Factor(f) => f * l_avg,
        TargetLength::Absolute(l) => l,
    };
    if !(l_tar.is_finite() && l_tar > 0.0) {
        // Name where the value came from: the option, or the input's own edge lengths
        // (a mesh whose size over- or underflows, or a metric that vanishes).
        return Err(PipelineError::BadTarget {
            l_tar,
            target: options.target,
            l_avg,
        });
    }
    Ok((l_avg, l_tar))
}

/// The metric with the size controls ([`RemeshOptions::sizes`]) applied, when they are on.
fn sized_metric(
    field: &MetricField,
    l_tar: f64,
    options: &RemeshOptions,
) -> Result<Option<MetricField>, PipelineError> {
    let reference = field.reference();
    let sized = match options.sizes.any() {
        true => {
            let m = apply_sizes(
                reference,
                field.vertex_metrics(),
                l_tar,
                1.0,
                &options.sizes,
            );
            Some(field.with_metrics(m).map_err(PipelineError::SizedMetric)?)
        }
        false => None,
    };
    Ok(sized)
}

/// Curved feature lines refine the faces beside them (the a-priori scaling stops at
/// creases), after the profile is chosen: a part's creases are no sign of a coarse input.
/// Raises `fid_scale` (when there is one) to the crease scaling; the feature edges.
fn refine_beside_features(
    field: &MetricField,
    topo: &Topology,
    options: &RemeshOptions,
    (l_tar, min_edge): (f64, f64),
    fid_scale: &mut [f64],
) -> Vec<crate::ids::EdgeKey> {
    let reference = field.reference();
    let feature_edges = options.features.edges(reference, topo);
    if !fid_scale.is_empty() && !feature_edges.is_empty() {
        let crease = crate::features::crease_scale(
            reference,
            &feature_edges,
            field.vertex_metrics(),
            l_tar,
            options.fidelity.max_deviation,
            min_edge,
        );
        for (f, c) in fid_scale.iter_mut().zip(crease) {
            *f = f.max(c);
        }
    }
    feature_edges
}

/// The metric with the a-priori scaling `fid_scale` applied, when there is one.
fn scaled_metric(
    field: &MetricField,
    fid_scale: &[f64],
) -> Result<Option<MetricField>, PipelineError> {
    let scaled = if fid_scale.is_empty() {
        None
    } else {
        let metrics = field
            .vertex_metrics()
            .iter()
            .zip(fid_scale)
            .map(|(m, f)| m * *f)
            .collect();
        Some(
            field
                .with_metrics(metrics)
                .map_err(PipelineError::FidelityMetric)?,
        )
    };
    Ok(scaled)
}

/// A-priori fidelity scaling (our addition, [`fidelity::a_priori_scale`]): the metric is
/// scaled up isotropically where a triangle of the target size would cut off more of the
/// reference than the tolerance allows. L_tar is from the unscaled metric, as is every
/// quality measure. Returns the refinement floor and the factor per reference vertex (empty
/// when the control is off).
fn a_priori(
    field: &MetricField,
    topo: &Topology,
    o: &RemeshOptions,
    l_tar: f64,
) -> (f64, Vec<f64>) {
    let reference = field.reference();
    // The mean input edge, summed edge by edge: `TriMesh::mean_edge_length` sums per face,
    // which rounds differently, and one ulp here moves every later patch (measured: the
    // bunny's Hausdorff 0.71 → 1.00 % with the per-face sum).
    let (sum, n) = reference
        .face_edge_lengths()
        .fold((0.0, 0usize), |(s, n), l| (s + l[0] + l[1] + l[2], n + 3));
    let mean_edge = if n == 0 { 0.0 } else { sum / n as f64 };
    let min_edge = o.fidelity.min_edge_ratio * mean_edge;
    let eps = o.fidelity.max_deviation;
    let fid_scale = if eps > 0.0 {
        fidelity::a_priori_scale(
            reference,
            topo,
            field.vertex_metrics(),
            l_tar,
            eps,
            min_edge,
        )
    } else {
        Vec::new()
    };
    (min_edge, fid_scale)
}

/// The number of faces an output of `reference` should have: its area in the metric (the
/// mean of the vertex tensors `metrics[v]·scale[v]` per face; `scale` empty = 1) over the area
/// √3/4·L_tar² of an equilateral triangle of side `l_tar`.
pub fn expected_faces(
    reference: &TriMesh,
    metrics: &[Matrix3<f64>],
    scale: &[f64],
    l_tar: f64,
) -> f64 {
    let s = |v: VertexId| scale.get(v.idx()).copied().unwrap_or(1.0);
    let area: f64 = reference
        .faces()
        .map(|f| {
            let t = reference.face(f);
            let m = t
                .iter()
                .map(|v| metrics[v.idx()] * s(*v))
                .sum::<Matrix3<f64>>()
                / 3.0;
            metric_area(reference.face_points(f), &m)
        })
        .sum();
    area / (3f64.sqrt() / 4.0 * l_tar * l_tar)
}

/// The area of the triangle `[a, b, c]` in the constant metric `m`.
pub fn metric_area([a, b, c]: [nalgebra::Point3<f64>; 3], m: &Matrix3<f64>) -> f64 {
    let q = crate::quality::metric_sqrt(m);
    0.5 * (q * (b - a)).cross(&(q * (c - a))).norm()
}

/// The expected output face counts of a run with `options` ([`expected_faces`] at its L_tar,
/// in the metric alone and with the a-priori fidelity scaling) and whether
/// [`CoarseInput::Auto`]'s rule: the a-priori fidelity scaling multiplies the expected output
/// by at least [`COARSE_RATIO`], and the input has at most [`DENSE_INPUT_RATIO`] times the
/// faces of that output.
fn is_coarse(faces_in: usize, expected: f64, expected_fidelity: f64) -> bool {
    expected_fidelity >= COARSE_RATIO * expected
        && faces_in as f64 <= DENSE_INPUT_RATIO * expected_fidelity
}

/// [`CoarseInput::Auto`] would run the coarse-input profile.
pub fn coarse_input_estimate(
    field: &MetricField,
    options: &RemeshOptions,
) -> Result<(f64, f64, bool), PipelineError> {
    let topo = Topology::build(field.reference());
    let auto = RemeshOptions {
        coarse_input: CoarseInput::Auto,
        ..options.clone()
    };
    let plan = Plan::resolve(field, &topo, &auto)?;
    Ok((plan.expected, plan.expected_fidelity, plan.coarse))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    /// The rule on measured counts (faces in, expected, expected with the a-priori scaling):
    /// decimated-knight and the coarse CAD parts run the profile; CGAL's cheese, whose
    /// input is 3.5 times finer than the output, and a smooth scan do not.
    #[test]
    fn the_coarse_rule_on_measured_counts() {
        assert!(is_coarse(1_000, 339.0, 888.0), "decimated-knight");
        assert!(is_coarse(3_714, 1_066.0, 3_060.0), "couplingdown");
        assert!(is_coarse(4_800, 1_257.0, 3_457.0), "rotor_small");
        assert!(!is_coarse(17_786, 2_411.0, 5_115.0), "cheese");
        assert!(
            !is_coarse(5_000, 8_000.0, 9_200.0),
            "a smooth scan (ratio 1.15)"
        );
        // The ratio alone is not enough, and neither is the density alone.
        assert!(!is_coarse(1_000, 2_000.0, 3_999.0));
        assert!(!is_coarse(8_001, 1_000.0, 4_000.0));
        assert!(is_coarse(8_000, 1_000.0, 4_000.0));
    }

    /// A flat unit square in the identity metric (restricted to the plane): its area over
    /// that of an equilateral triangle of side L; a scale of 4 everywhere quadruples it.
    #[test]
    fn expected_faces_of_a_flat_square() {
        let m = TriMesh {
            positions: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            triangles: vec![
                [VertexId(0), VertexId(1), VertexId(2)],
                [VertexId(0), VertexId(2), VertexId(3)],
            ],
        };
        let id = vec![Matrix3::identity(); 4];
        let l = 0.1;
        let want = 1.0 / (3f64.sqrt() / 4.0 * l * l);
        let got = expected_faces(&m, &id, &[], l);
        assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
        let got4 = expected_faces(&m, &id, &[4.0; 4], l);
        assert!((got4 - 4.0 * want).abs() < 1e-9 * want, "{got4}");
    }
}
