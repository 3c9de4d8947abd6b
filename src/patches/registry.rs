//! The registry of patch strategies: name → constructor and options. A new strategy is a
//! new file in `patches/` plus one row here.

use super::{ConeOptions, ConePatches, KRingDisks, PatchStrategy};
use crate::registry::{BadValue, Entry, OptionDoc, Params, RegistryError};

/// Every built-in patch strategy, the default first.
pub static STRATEGIES: &[Entry<dyn PatchStrategy>] = &[
    Entry {
        name: "cone",
        summary: "cone patches grown by the developability cost of Eq. 1-3 (Sec. 3.2), the paper's",
        options: &[
            OptionDoc {
                name: "beta",
                doc: "exponent β of the path length in Eq. 3 [0.7]",
            },
            OptionDoc {
                name: "c_max",
                doc: "growth threshold C_max of Eq. 3 [0.1]",
            },
            OptionDoc {
                name: "expand_rings",
                doc: "rings of processed faces added after growth (Sec. 4.2) [2]",
            },
            OptionDoc {
                name: "refit_rounds",
                doc: "refits of the cone to the grown patch, each followed by more growth [1]",
            },
            OptionDoc {
                name: "max_faces",
                doc: "largest number of faces added by growth [no limit]",
            },
            OptionDoc {
                name: "sizes",
                doc: "absolute sizes (a user metric): trim expansions through needle faces [true with --metric, else false]",
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
                doc: "rings of faces grown around the seed triangle [6]",
            },
            OptionDoc {
                name: "max_faces",
                doc: "cap on the faces added by growth [200]",
            },
            OptionDoc {
                name: "expand_rings",
                doc: "rings of processed faces added afterwards [1]",
            },
        ],
        build: kring,
    },
];

/// The strategy of row `name` with `params` (see [`STRATEGIES`]).
pub fn strategy(name: &str, params: Params) -> Result<Box<dyn PatchStrategy>, RegistryError> {
    crate::registry::build("patch strategy", STRATEGIES, name, params)
}

fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

fn cone(p: &mut Params) -> Result<Box<dyn PatchStrategy>, BadValue> {
    let mut o = ConeOptions::default();
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
    if let Some(m) = p.take_checked("max_faces", "a positive number of faces", |m: usize| m > 0)? {
        o.max_faces = Some(m);
    }
    if let Some(t) = p.take("sizes", "true or false")? {
        o.trim_ragged = t;
    }
    Ok(Box::new(ConePatches { options: o }))
}

fn kring(p: &mut Params) -> Result<Box<dyn PatchStrategy>, BadValue> {
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
