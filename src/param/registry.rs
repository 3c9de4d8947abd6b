//! The registry of parameterizers: name → constructor and options. A new parameterizer is a
//! new file in `param/` plus one row here.

use super::{Parameterizer, SdOptions, SymmetricDirichlet, Tutte, TutteWeights};
use crate::registry::{BadValue, Entry, OptionDoc, Params, RegistryError};

/// Every built-in parameterizer, the default first.
pub static PARAMETERIZERS: &[Entry<dyn Parameterizer>] = &[
    Entry {
        name: "sd",
        summary: "symmetric Dirichlet energy with the boundary barrier of ref. [30], by projected Newton (Sec. 3.3), the paper's",
        options: &[OptionDoc {
            name: "max_iters",
            doc: "Newton iteration budget; running out is reported, not an error [100]",
        }],
        build: sd,
    },
    Entry {
        name: "tutte",
        summary: "Tutte's embedding onto a circle (bijective, not low-distortion), a baseline",
        options: &[OptionDoc {
            name: "weights",
            doc: "Laplacian weights: uniform, cotan or mean_value [mean_value]",
        }],
        build: tutte,
    },
];

/// The parameterizer of row `name` with `params` (see [`PARAMETERIZERS`]).
pub fn parameterizer(name: &str, params: Params) -> Result<Box<dyn Parameterizer>, RegistryError> {
    crate::registry::build("parameterizer", PARAMETERIZERS, name, params)
}

fn sd(p: &mut Params) -> Result<Box<dyn Parameterizer>, BadValue> {
    let mut options = SdOptions::default();
    if let Some(n) = p.take("max_iters", "a number of iterations")? {
        options.max_iters = n;
    }
    Ok(Box::new(SymmetricDirichlet { options }))
}

fn tutte(p: &mut Params) -> Result<Box<dyn Parameterizer>, BadValue> {
    const EXPECTED: &str = "uniform, cotan or mean_value";
    let weights = match p.take::<String>("weights", EXPECTED)?.as_deref() {
        None => TutteWeights::default(),
        Some("uniform") => TutteWeights::Uniform,
        Some("cotan") => TutteWeights::Cotan,
        Some("mean_value") => TutteWeights::MeanValue,
        Some(other) => return Err(BadValue::new("weights", other, EXPECTED)),
    };
    Ok(Box::new(Tutte { weights }))
}
