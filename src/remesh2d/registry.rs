//! The registry of planar remeshers: name → constructor and options. A new remesher is a
//! new file in `remesh2d/` plus one row here.

use super::{Lct, LctOptions, PlanarRemesher};
use crate::registry::{BadValue, Entry, OptionDoc, Params, RegistryError};

/// Every built-in planar remesher, the default first.
pub static REMESHERS: &[Entry<dyn PlanarRemesher>] = &[Entry {
    name: "lct",
    summary: "anisotropic meshing with local convex functions (ref. [5], Sec. 3.3), the paper's",
    options: &[
        OptionDoc {
            name: "sizes",
            doc: "the settings for absolute sizes (a user metric): start from the boundary, density control, split at 1.5 [true with --metric, else false]",
        },
        OptionDoc {
            name: "rounds",
            doc: "outer rounds of split/collapse, flips and smoothing [8]",
        },
        OptionDoc {
            name: "split_ratio",
            doc: "split interior edges longer than this times L_tar [4/3; 1.5 with sizes]",
        },
        OptionDoc {
            name: "collapse_ratio",
            doc: "collapse interior edges shorter than this times L_tar [4/5]",
        },
        OptionDoc {
            name: "collapse_guard",
            doc: "refuse a collapse that makes an edge longer than this times L_tar [split_ratio]",
        },
        OptionDoc {
            name: "rebuild",
            doc: "start from the triangulated boundary polygon, not the domain's mesh [false; true with sizes]",
        },
        OptionDoc {
            name: "start_spacing",
            doc: "with rebuild, keep the domain's interior vertices this far apart (times L_tar) [0.8]",
        },
        OptionDoc {
            name: "density",
            doc: "bring the vertex count to an ideal mesh's, so edges are L_tar on average [false; true with sizes]",
        },
        OptionDoc {
            name: "smoothing_iters",
            doc: "smoothing passes per round, each followed by flips [3]",
        },
        OptionDoc {
            name: "final_smoothing",
            doc: "final polish passes (equilateral-apex smoothing + flips) [6]",
        },
    ],
    build: lct,
}];

/// The planar remesher of row `name` with `params` (see [`REMESHERS`]).
pub fn planar_remesher(
    name: &str,
    params: Params,
) -> Result<Box<dyn PlanarRemesher>, RegistryError> {
    crate::registry::build("planar remesher", REMESHERS, name, params)
}

fn lct(p: &mut Params) -> Result<Box<dyn PlanarRemesher>, BadValue> {
    let mut o = match p.take("sizes", "true or false")? {
        Some(true) => LctOptions::for_absolute_sizes(),
        _ => LctOptions::default(),
    };
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
    if let Some(g) = p.take_checked("collapse_guard", "a number above 1", |x: f64| {
        ratio(x) && x > 1.0
    })? {
        o.collapse_guard = Some(g);
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
