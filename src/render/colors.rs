//! Per-face colours of a picture: the face's q or smallest angle in the metric (Sec. 4.1),
//! with the faces below [`FLAG_ANGLE`] in magenta (Fig. 6); its patch (Fig. 3), in colours
//! that differ between neighbouring patches; or its distance to a reference surface.

use super::{RenderError, MAGENTA};
use crate::ids::PatchId;
use crate::mesh::{SurfaceProjector, TriMesh};
use crate::metric::{validate_vertex_metric, MetricField, MetricOptions, Normalization};
use crate::option_error::OptionError;
use crate::quality::face_qualities;
use nalgebra::{Matrix3, Point3};
use rustc_hash::FxHashMap;
use std::collections::BTreeSet;

/// Faces whose smallest angle in the metric is below this many degrees are drawn in
/// magenta when colouring by q or by angle (Fig. 6).
pub const FLAG_ANGLE: f64 = 20.0;

/// What the faces are coloured by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorBy {
    /// q = 2√3·a/(p·h) in the metric (Sec. 4.1 (1)), on [0, 1].
    Q,
    /// The smallest angle θ(t) in the metric (Sec. 4.1 (2)), on [0°, 60°].
    MinAngle,
    /// The patch that made the face (Fig. 3).
    Patch,
    /// The distance to the reference surface, in % of its bounding-box diagonal.
    Distance,
    /// One plain colour.
    None,
}

impl ColorBy {
    /// The names `q`, `min-angle`, `patch`, `distance`, `none`, in this order.
    pub const NAMES: [&'static str; 5] = ["q", "min-angle", "patch", "distance", "none"];

    /// Reads one of [`ColorBy::NAMES`].
    pub fn parse(s: &str) -> Result<ColorBy, OptionError> {
        match s.trim() {
            "q" => Ok(ColorBy::Q),
            "min-angle" => Ok(ColorBy::MinAngle),
            "patch" => Ok(ColorBy::Patch),
            "distance" => Ok(ColorBy::Distance),
            "none" => Ok(ColorBy::None),
            t => Err(OptionError::Unparsed {
                option: "color",
                value: t.to_string(),
                expected: "one of q, min-angle, patch, distance, none",
            }),
        }
    }

    /// The name [`ColorBy::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            ColorBy::Q => "q",
            ColorBy::MinAngle => "min-angle",
            ColorBy::Patch => "patch",
            ColorBy::Distance => "distance",
            ColorBy::None => "none",
        }
    }
}

/// Metric tensors for [`ColorBy::Q`] and [`ColorBy::MinAngle`] (any units: q and angles do
/// not change when the metric is scaled).
#[derive(Clone, Copy, Debug)]
pub enum VertexMetric<'a> {
    /// One tensor per vertex of the mesh drawn (e.g. `remesh --write-metric`).
    OnMesh(&'a [Matrix3<f64>]),
    /// One tensor per vertex of the reference surface (e.g. the user metric of a run); each
    /// vertex drawn takes the tensor at its closest point on the reference (Sec. 4.1).
    OnReference(&'a [Matrix3<f64>]),
}

impl<'a> VertexMetric<'a> {
    /// `tensors` on the mesh drawn (`on_mesh`) or on the reference surface.
    pub fn new(tensors: &'a [Matrix3<f64>], on_mesh: bool) -> Self {
        match on_mesh {
            true => VertexMetric::OnMesh(tensors),
            false => VertexMetric::OnReference(tensors),
        }
    }
}

/// The data a colouring may need, besides the mesh.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sources<'a> {
    /// The metric; `None`: the curvature metric (Sec. 4.1) of the reference, or of the mesh
    /// itself without a reference.
    pub metric: Option<VertexMetric<'a>>,
    /// The reference (input) surface, same units as the mesh.
    pub reference: Option<&'a TriMesh>,
    /// The patch of each face (`None`: a face no patch made).
    pub patches: Option<&'a [Option<PatchId>]>,
    /// Options of the curvature metric (default: the yardstick's, as `conemesh eval`).
    pub curvature: MetricOptions,
}

/// What the colour bar of a picture shows.
#[derive(Clone, Debug, PartialEq)]
pub enum Legend {
    /// A continuous scale: `stops` spread evenly from `min` to `max`.
    Scale {
        /// what is measured, with its unit
        title: String,
        /// the value at the first stop
        min: f64,
        /// the value at the last stop
        max: f64,
        /// decimals of the labels
        decimals: usize,
        /// the colour map
        stops: &'static [[u8; 3]],
        /// faces drawn in magenta instead (smallest angle below [`FLAG_ANGLE`]), when flagged
        flagged: Option<usize>,
    },
    /// Patches in distinct colours.
    Patches {
        /// patches drawn
        patches: usize,
        /// faces of no patch (drawn grey)
        kept: usize,
    },
    /// No colour bar.
    None,
}

/// One colour per face, and the legend that explains them.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceColors {
    /// RGB per face, in face order.
    pub colors: Vec<[u8; 3]>,
    /// The colour bar.
    pub legend: Legend,
}

/// Low q / small angles red, high blue (ColorBrewer RdYlBu): no magenta in it, so the
/// flagged faces stand out.
pub const QUALITY_MAP: [[u8; 3]; 11] = [
    [165, 0, 38],
    [215, 48, 39],
    [244, 109, 67],
    [253, 174, 97],
    [254, 224, 144],
    [255, 255, 191],
    [224, 243, 248],
    [171, 217, 233],
    [116, 173, 209],
    [69, 117, 180],
    [49, 54, 149],
];

/// Near pale yellow, far dark red (ColorBrewer YlOrRd).
pub const DISTANCE_MAP: [[u8; 3]; 9] = [
    [255, 255, 204],
    [255, 237, 160],
    [254, 217, 118],
    [254, 178, 76],
    [253, 141, 60],
    [252, 78, 42],
    [227, 26, 28],
    [189, 0, 38],
    [128, 0, 38],
];

/// Patch colours (ColorBrewer / Tableau, no magenta), given to patches so that neighbours
/// differ (greedy colouring of the patch adjacency).
pub const PATCH_PALETTE: [[u8; 3]; 20] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [188, 189, 34],
    [23, 190, 207],
    [174, 199, 232],
    [255, 187, 120],
    [152, 223, 138],
    [255, 152, 150],
    [196, 156, 148],
    [219, 219, 141],
    [158, 218, 229],
    [0, 90, 50],
    [120, 60, 0],
    [0, 60, 120],
    [250, 220, 0],
    [90, 170, 140],
];

/// Faces that no patch made (kept input faces).
pub const KEPT_GREY: [u8; 3] = [190, 190, 190];
/// The colour of [`ColorBy::None`].
pub const PLAIN: [u8; 3] = [190, 200, 215];

/// The colour of `t ∈ [0, 1]` on a piecewise-linear map.
pub fn map_color(stops: &[[u8; 3]], t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    [0, 1, 2].map(|k| (f64::from(a[k]) + f * (f64::from(b[k]) - f64::from(a[k]))).round() as u8)
}

/// The colour of every face of `mesh` by `color`, from `sources`.
pub fn face_colors(
    mesh: &TriMesh,
    color: ColorBy,
    sources: &Sources,
) -> Result<FaceColors, RenderError> {
    match color {
        ColorBy::Q | ColorBy::MinAngle => quality_colors(mesh, color, sources),
        ColorBy::Patch => {
            let p = sources.patches.ok_or(RenderError::Missing {
                color: "patch",
                needs: "the patch of each face",
            })?;
            patch_colors(mesh, p)
        }
        ColorBy::Distance => {
            let r = sources.reference.ok_or(RenderError::Missing {
                color: "distance",
                needs: "a reference surface",
            })?;
            distance_colors(mesh, r)
        }
        ColorBy::None => Ok(FaceColors {
            colors: vec![PLAIN; mesh.n_faces()],
            legend: Legend::None,
        }),
    }
}

/// The metric at every vertex of `mesh` ([`Sources::metric`]).
fn vertex_metrics(mesh: &TriMesh, sources: &Sources) -> Result<Vec<Matrix3<f64>>, RenderError> {
    match (sources.metric, sources.reference) {
        (Some(VertexMetric::OnMesh(m)), _) => {
            if m.len() != mesh.n_vertices() {
                return Err(RenderError::CountMismatch {
                    what: "metric tensors (one per vertex)",
                    expected: mesh.n_vertices(),
                    found: m.len(),
                });
            }
            let normals = mesh.vertex_normals();
            for (v, (t, n)) in m.iter().zip(&normals).enumerate() {
                validate_vertex_metric(v, t, n)?;
            }
            Ok(m.to_vec())
        }
        (Some(VertexMetric::OnReference(m)), Some(r)) => {
            let norm = Normalization::of(r);
            let unit: Vec<Matrix3<f64>> = m.iter().map(|x| norm.metric_to_unit(x)).collect();
            let field = MetricField::from_surface_tensors(norm.apply(r), unit)?;
            Ok(eval_at(&field, &norm, &mesh.positions))
        }
        (Some(VertexMetric::OnReference(_)), None) => Err(RenderError::Missing {
            color: "q or angle in a metric given on the reference",
            needs: "the reference surface",
        }),
        (None, Some(r)) => {
            let norm = Normalization::of(r);
            let field = MetricField::from_curvature(norm.apply(r), &sources.curvature)?;
            Ok(eval_at(&field, &norm, &mesh.positions))
        }
        (None, None) => {
            let norm = Normalization::of(mesh);
            let field = MetricField::from_curvature(norm.apply(mesh), &sources.curvature)?;
            Ok(field.vertex_metrics().to_vec())
        }
    }
}

/// The field at points given in file units.
fn eval_at(field: &MetricField, norm: &Normalization, pts: &[Point3<f64>]) -> Vec<Matrix3<f64>> {
    use rayon::prelude::*;
    pts.par_iter()
        .map(|p| field.eval(&norm.to_unit(p)))
        .collect()
}

fn quality_colors(
    mesh: &TriMesh,
    color: ColorBy,
    sources: &Sources,
) -> Result<FaceColors, RenderError> {
    let metrics = vertex_metrics(mesh, sources)?;
    Ok(quality_face_colors(mesh, &metrics, color))
}

/// The colours of [`ColorBy::Q`] (or, for any other `color`, [`ColorBy::MinAngle`]) in
/// metrics already known to be usable, one per vertex of `mesh` (e.g. a run's own metric at
/// its output vertices), without the checks [`face_colors`] makes of a given metric.
///
/// Panics if `metrics` is shorter than the vertex count (a caller bug).
pub fn quality_face_colors(mesh: &TriMesh, metrics: &[Matrix3<f64>], color: ColorBy) -> FaceColors {
    let qs = face_qualities(mesh, metrics);
    let (title, max, decimals) = match color {
        ColorBy::Q => ("q = 2√3·a/(p·h) in the metric", 1.0, 1),
        _ => ("smallest angle in the metric (°)", 60.0, 0),
    };
    let mut flagged = 0;
    let colors = qs
        .iter()
        .map(|t| {
            if t.min_angle() < FLAG_ANGLE {
                flagged += 1;
                return MAGENTA;
            }
            let x = match color {
                ColorBy::Q => t.q,
                _ => t.min_angle(),
            };
            map_color(&QUALITY_MAP, x / max)
        })
        .collect();
    FaceColors {
        colors,
        legend: Legend::Scale {
            title: title.to_string(),
            min: 0.0,
            max,
            decimals,
            stops: &QUALITY_MAP,
            flagged: Some(flagged),
        },
    }
}

fn distance_colors(mesh: &TriMesh, reference: &TriMesh) -> Result<FaceColors, RenderError> {
    if reference.n_faces() == 0 {
        return Err(RenderError::Missing {
            color: "distance",
            needs: "a reference surface with faces",
        });
    }
    let scale = Normalization::of(reference).scale;
    let projector = SurfaceProjector::new(reference);
    let dist = |p: &Point3<f64>| projector.closest(p).map_or(0.0, |c| c.2) * scale * 100.0;
    let vertex: Vec<f64> = {
        use rayon::prelude::*;
        mesh.positions.par_iter().map(dist).collect()
    };
    // A face is as far as its farthest corner or its centroid (a flat face can bridge a
    // concave part of the reference with all three corners on it).
    let face: Vec<f64> = {
        use rayon::prelude::*;
        (0..mesh.n_faces())
            .into_par_iter()
            .map(|f| {
                let t = mesh.triangles[f];
                let [a, b, c] = t.map(|v| mesh.positions[v.idx()]);
                let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
                t.iter()
                    .map(|v| vertex[v.idx()])
                    .fold(dist(&centroid), f64::max)
            })
            .collect()
    };
    // The scale runs to the largest distance, but not below round-off (10⁻⁶ % of the
    // diagonal): a mesh on its reference is drawn pale, not in the noise's full range.
    let max = face.iter().copied().fold(0.0, f64::max);
    let top = max.max(1e-6);
    Ok(FaceColors {
        colors: face
            .iter()
            .map(|d| map_color(&DISTANCE_MAP, d / top))
            .collect(),
        legend: Legend::Scale {
            title: "distance to the reference (% of its bounding-box diagonal)".into(),
            min: 0.0,
            max: top,
            decimals: ((-top.log10()).ceil().max(0.0) as usize + 2).min(8),
            stops: &DISTANCE_MAP,
            flagged: None,
        },
    })
}

/// Patches coloured greedily in order of their ids, each with the first palette colour none
/// of its already-coloured neighbours (patches sharing an edge) has. A patch with more than
/// 19 neighbours could exhaust the palette; it then reuses colours in turn.
fn patch_colors(mesh: &TriMesh, patches: &[Option<PatchId>]) -> Result<FaceColors, RenderError> {
    if patches.len() != mesh.n_faces() {
        return Err(RenderError::CountMismatch {
            what: "patch ids (one per face)",
            expected: mesh.n_faces(),
            found: patches.len(),
        });
    }
    let ids: Vec<PatchId> = patches
        .iter()
        .flatten()
        .copied()
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let dense = |p: PatchId| ids.binary_search(&p).unwrap_or(0);
    let mut neighbours = vec![BTreeSet::new(); ids.len()];
    let mut edge_patch: FxHashMap<(u32, u32), usize> = FxHashMap::default();
    for (t, p) in mesh.triangles.iter().zip(patches) {
        let Some(p) = p.map(dense) else { continue };
        for i in 0..3 {
            let (a, b) = (t[i].0, t[(i + 1) % 3].0);
            let key = (a.min(b), a.max(b));
            match edge_patch.get(&key) {
                Some(&q) if q != p => {
                    neighbours[p].insert(q);
                    neighbours[q].insert(p);
                }
                Some(_) => {}
                None => {
                    edge_patch.insert(key, p);
                }
            }
        }
    }
    let mut slot = vec![usize::MAX; ids.len()];
    for p in 0..ids.len() {
        let taken: BTreeSet<usize> = neighbours[p].iter().map(|&q| slot[q]).collect();
        slot[p] = (0..PATCH_PALETTE.len())
            .find(|c| !taken.contains(c))
            .unwrap_or(p % PATCH_PALETTE.len());
    }
    let colors = patches
        .iter()
        .map(|p| p.map_or(KEPT_GREY, |p| PATCH_PALETTE[slot[dense(p)]]))
        .collect();
    Ok(FaceColors {
        colors,
        legend: Legend::Patches {
            patches: ids.len(),
            kept: patches.iter().filter(|p| p.is_none()).count(),
        },
    })
}
