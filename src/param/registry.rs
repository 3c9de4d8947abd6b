//! The registry of parameterizers: name → constructor and options. A new parameterizer is a
//! new file in `param/` plus one row here (or, outside the crate, one row given to a
//! [`crate::registry::Registry`]).

use super::{Parameterizer, SdOptions, SymmetricDirichlet, Tutte, TutteWeights};
use crate::registry::{BadValue, Entry, MetricSizes, OptionDoc, Params, RegistryError};

impl crate::registry::Stage for dyn Parameterizer {
    const KIND: &'static str = "parameterizer";
    fn builtin() -> &'static [Entry<Self>] {
        PARAMETERIZERS
    }
    fn stage_name(&self) -> &'static str {
        self.name()
    }
}

/// Every built-in parameterizer, the default first.
pub static PARAMETERIZERS: &[Entry<dyn Parameterizer>] = &[
    Entry {
        name: "sd",
        summary: "symmetric Dirichlet energy with the boundary barrier of ref. [30], by projected Newton (Sec. 3.3), the paper's",
        options: &[OptionDoc {
            name: "max_iters",
            doc: "Newton iteration budget; running out is reported, not an error",
            default: |_| SdOptions::default().max_iters.to_string(),
        }],
        build: sd,
    },
    Entry {
        name: "tutte",
        summary: "Tutte's embedding onto a circle (bijective, not low-distortion), a baseline",
        options: &[OptionDoc {
            name: "weights",
            doc: "Laplacian weights: uniform, cotan or mean_value",
            default: |_| weights_name(TutteWeights::default()).to_string(),
        }],
        build: tutte,
    },
];

/// The parameterizer of row `name` with `params` (see [`PARAMETERIZERS`]).
pub fn parameterizer(name: &str, params: Params) -> Result<Box<dyn Parameterizer>, RegistryError> {
    crate::registry::build(PARAMETERIZERS, name, params, MetricSizes::Relative)
}

fn sd(p: &mut Params, _: MetricSizes) -> Result<Box<dyn Parameterizer>, BadValue> {
    let mut options = SdOptions::default();
    if let Some(n) = p.take("max_iters", "a number of iterations")? {
        options.max_iters = n;
    }
    Ok(Box::new(SymmetricDirichlet { options }))
}

/// The option value of `w`.
fn weights_name(w: TutteWeights) -> &'static str {
    match w {
        TutteWeights::Uniform => "uniform",
        TutteWeights::Cotan => "cotan",
        TutteWeights::MeanValue => "mean_value",
    }
}

fn tutte(p: &mut Params, _: MetricSizes) -> Result<Box<dyn Parameterizer>, BadValue> {
    const EXPECTED: &str = "uniform, cotan or mean_value";
    let weights = match p.take::<String>("weights", EXPECTED)? {
        None => TutteWeights::default(),
        Some(name) => [
            TutteWeights::Uniform,
            TutteWeights::Cotan,
            TutteWeights::MeanValue,
        ]
        .into_iter()
        .find(|w| weights_name(*w) == name)
        .ok_or_else(|| BadValue::new("weights", &name, EXPECTED))?,
    };
    Ok(Box::new(Tutte { weights }))
}
