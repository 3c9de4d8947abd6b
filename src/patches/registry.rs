//! The registry of patch strategies: name → constructor and options. A new strategy is a
//! new file in `patches/` plus one row here (or, outside the crate, one row given to a
//! [`crate::registry::Registry`]).

use super::{ConeOptions, ConePatches, KRingDisks, PatchStrategy};
use crate::registry::{optional, BadValue, Entry, MetricSizes, OptionDoc, Params, RegistryError};

impl crate::registry::Stage for dyn PatchStrategy {
    const KIND: &'static str = "patch strategy";
    fn builtin() -> &'static [Entry<Self>] {
        STRATEGIES
    }
    fn stage_name(&self) -> &'static str {
        self.name()
    }
}

/// Every built-in patch strategy, the default first.
pub static STRATEGIES: &[Entry<dyn PatchStrategy>] = &[
    Entry {
        name: "cone",
        summary: "cone patches grown by the developability cost of Eq. 1-3 (Sec. 3.2), the paper's",
        options: &[
            OptionDoc {
                name: "beta",
                doc: "exponent β of the path length in Eq. 3",
                default: |s| cone_defaults(s).beta.to_string(),
            },
            OptionDoc {
                name: "c_max",
                doc: "growth threshold C_max of Eq. 3",
                default: |s| cone_defaults(s).c_max.to_string(),
            },
            OptionDoc {
                name: "expand_rings",
                doc: "rings of processed faces added after growth (Sec. 4.2)",
                default: |s| cone_defaults(s).expand_rings.to_string(),
            },
            OptionDoc {
                name: "refit_rounds",
                doc: "refits of the cone to the grown patch, each followed by more growth",
                default: |s| cone_defaults(s).refit_rounds.to_string(),
            },
            OptionDoc {
                name: "max_faces",
                doc: "largest number of faces added by growth (none: no limit)",
                default: |s| optional(cone_defaults(s).max_faces),
            },
            OptionDoc {
                name: "trim_ragged",
                doc: "trim expansions through needle faces (for absolute sizes, whose earlier patches leave needles)",
                default: |s| cone_defaults(s).trim_ragged.to_string(),
            },
        ],
        build: cone,
    },
    Entry {
        name: "kring",
        summary: "geodesic k-ring disks without geometry, a baseline for the cone criterion",
        options: &[
            OptionDoc {
                name: "rings",
                doc: "rings of faces grown around the seed triangle",
                default: |_| KRingDisks::default().rings.to_string(),
            },
            OptionDoc {
                name: "max_faces",
                doc: "cap on the faces added by growth",
                default: |_| KRingDisks::default().max_faces.to_string(),
            },
            OptionDoc {
                name: "expand_rings",
                doc: "rings of processed faces added afterwards",
                default: |_| KRingDisks::default().expand_rings.to_string(),
            },
        ],
        build: kring,
    },
];

/// The strategy of row `name` with `params`, for a curvature metric (see [`STRATEGIES`];
/// [`crate::registry::Registry`] builds for either kind of sizes).
pub fn strategy(name: &str, params: Params) -> Result<Box<dyn PatchStrategy>, RegistryError> {
    crate::registry::build(STRATEGIES, name, params, MetricSizes::Relative)
}

fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// The cone options for a metric with `sizes`: with absolute sizes, ragged expansions are
/// trimmed (paper-notes "Ragged expansions").
fn cone_defaults(sizes: MetricSizes) -> ConeOptions {
    ConeOptions {
        trim_ragged: sizes == MetricSizes::Absolute,
        ..ConeOptions::default()
    }
}

fn cone(p: &mut Params, sizes: MetricSizes) -> Result<Box<dyn PatchStrategy>, BadValue> {
    let mut o = cone_defaults(sizes);
    if let Some(b) = p.take_checked("beta", "a finite number ≥ 0", |b: f64| {
        b.is_finite() && b >= 0.0
    })? {
        o.beta = b;
    }
    if let Some(c) = p.take_checked("c_max", "a positive number", positive)? {
        o.c_max = c;
    }
    if let Some(r) = p.take("expand_rings", "a number of rings")? {
        o.expand_rings = r;
    }
    if let Some(r) = p.take("refit_rounds", "a number of rounds")? {
        o.refit_rounds = r;
    }
    if let Some(m) = p.take_optional(
        "max_faces",
        "a positive number of faces or none",
        |m: usize| m > 0,
    )? {
        o.max_faces = m;
    }
    if let Some(t) = p.take("trim_ragged", "true or false")? {
        o.trim_ragged = t;
    }
    Ok(Box::new(ConePatches { options: o }))
}

fn kring(p: &mut Params, _: MetricSizes) -> Result<Box<dyn PatchStrategy>, BadValue> {
    let mut k = KRingDisks::default();
    if let Some(r) = p.take_checked("rings", "a positive number of rings", |r: usize| r > 0)? {
        k.rings = r;
    }
    if let Some(m) = p.take_checked("max_faces", "a positive number of faces", |m: usize| m > 0)? {
        k.max_faces = m;
    }
    if let Some(r) = p.take("expand_rings", "a number of rings")? {
        k.expand_rings = r;
    }
    Ok(Box::new(k))
}
