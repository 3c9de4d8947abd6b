//! The registry of planar remeshers: name → constructor and options. A new remesher is a
//! new file in `remesh2d/` plus one row here (or, outside the crate, one row given to a
//! [`crate::registry::Registry`]).

use super::{Lct, LctOptions, PlanarRemesher};
use crate::registry::{optional, BadValue, Entry, MetricSizes, OptionDoc, Params, RegistryError};

impl crate::registry::Stage for dyn PlanarRemesher {
    const KIND: &'static str = "planar remesher";
    fn builtin() -> &'static [Entry<Self>] {
        REMESHERS
    }
    fn stage_name(&self) -> &'static str {
        self.name()
    }
}

/// Every built-in planar remesher, the default first.
pub static REMESHERS: &[Entry<dyn PlanarRemesher>] = &[Entry {
    name: "lct",
    summary: "anisotropic meshing with local convex functions (ref. [5], Sec. 3.3), the paper's",
    options: &[
        OptionDoc {
            name: "rounds",
            doc: "outer rounds of split/collapse, flips and smoothing",
            default: |s| lct_defaults(s).rounds.to_string(),
        },
        OptionDoc {
            name: "split_ratio",
            doc: "split interior edges longer than this times L_tar",
            default: |s| lct_defaults(s).split_ratio.to_string(),
        },
        OptionDoc {
            name: "collapse_ratio",
            doc: "collapse interior edges shorter than this times L_tar",
            default: |s| lct_defaults(s).collapse_ratio.to_string(),
        },
        OptionDoc {
            name: "collapse_guard",
            doc: "refuse a collapse that makes an edge longer than this times L_tar (none: split_ratio)",
            default: |s| optional(lct_defaults(s).collapse_guard),
        },
        OptionDoc {
            name: "rebuild",
            doc: "start from the triangulated boundary polygon, not the domain's mesh",
            default: |s| lct_defaults(s).rebuild.to_string(),
        },
        OptionDoc {
            name: "start_spacing",
            doc: "with rebuild, keep the domain's interior vertices this far apart (times L_tar)",
            default: |s| lct_defaults(s).start_spacing.to_string(),
        },
        OptionDoc {
            name: "density",
            doc: "bring the vertex count to an ideal mesh's, so edges are L_tar on average",
            default: |s| lct_defaults(s).density.to_string(),
        },
        OptionDoc {
            name: "smoothing_iters",
            doc: "smoothing passes per round, each followed by flips",
            default: |s| lct_defaults(s).smoothing_iters.to_string(),
        },
        OptionDoc {
            name: "final_smoothing",
            doc: "final polish passes (equilateral-apex smoothing + flips)",
            default: |s| lct_defaults(s).final_smoothing.to_string(),
        },
    ],
    build: lct,
}];

/// The planar remesher of row `name` with `params`, for a curvature metric (see
/// [`REMESHERS`]; [`crate::registry::Registry`] builds for either kind of sizes).
pub fn planar_remesher(
    name: &str,
    params: Params,
) -> Result<Box<dyn PlanarRemesher>, RegistryError> {
    crate::registry::build(REMESHERS, name, params, MetricSizes::Relative)
}

/// LCT's options for a metric with `sizes` ([`LctOptions::for_absolute_sizes`] for absolute
/// ones).
fn lct_defaults(sizes: MetricSizes) -> LctOptions {
    match sizes {
        MetricSizes::Relative => LctOptions::default(),
        MetricSizes::Absolute => LctOptions::for_absolute_sizes(),
    }
}

fn lct(p: &mut Params, sizes: MetricSizes) -> Result<Box<dyn PlanarRemesher>, BadValue> {
    let mut o = lct_defaults(sizes);
    let ratio = |x: f64| x.is_finite() && x > 0.0;
    if let Some(r) = p.take("rounds", "a number of rounds")? {
        o.rounds = r;
    }
    if let Some(r) = p.take_checked("split_ratio", "a number above 1", |x: f64| {
        ratio(x) && x > 1.0
    })? {
        o.split_ratio = r;
    }
    if let Some(r) = p.take_checked("collapse_ratio", "a number in (0, 1)", |x: f64| {
        ratio(x) && x < 1.0
    })? {
        o.collapse_ratio = r;
    }
    if let Some(g) = p.take_optional("collapse_guard", "a number above 1 or none", |x: f64| {
        ratio(x) && x > 1.0
    })? {
        o.collapse_guard = g;
    }
    if let Some(b) = p.take("rebuild", "true or false")? {
        o.rebuild = b;
    }
    if let Some(x) = p.take_checked("start_spacing", "a number ≥ 0", |x: f64| {
        x.is_finite() && x >= 0.0
    })? {
        o.start_spacing = x;
    }
    if let Some(b) = p.take("density", "true or false")? {
        o.density = b;
    }
    if let Some(n) = p.take("smoothing_iters", "a number of passes")? {
        o.smoothing_iters = n;
    }
    if let Some(n) = p.take("final_smoothing", "a number of passes")? {
        o.final_smoothing = n;
    }
    Ok(Box::new(Lct { options: o }))
}
