//! The registry of improvers (Sec. 3.4): name → constructor and options. A new improver is a
//! new file in `improve/` plus one row here (or, outside the crate, one row given to a
//! [`crate::registry::Registry`]). Unlike the other extension points a run takes a list of
//! them, in order ([`crate::pipeline::Stages::improvers`]); the default list is every row of
//! [`IMPROVERS`], in order.

use super::{Algorithm2, Bottom, FlipRule, ImproveOptions, Improver, SurfacePasses, Target};
use crate::registry::{optional, BadValue, Entry, MetricSizes, OptionDoc, Params, RegistryError};

impl crate::registry::Stage for dyn Improver {
    const KIND: &'static str = "improver";
    fn builtin() -> &'static [Entry<Self>] {
        IMPROVERS
    }
    fn stage_name(&self) -> &'static str {
        self.name()
    }
}

/// Every built-in improver, in the order the default list runs them.
pub static IMPROVERS: &[Entry<dyn Improver>] = &[
    Entry {
        name: "surface",
        summary: "the connectivity and vertex position updates on the surface, certified, within --hausd (ours, Sec. 3.4)",
        options: &[
            OptionDoc {
                name: "flips",
                doc: "the connectivity update (edge flips by max-min q)",
                default: |_| SurfacePasses::default().flips.to_string(),
            },
            OptionDoc {
                name: "relocate",
                doc: "the vertex position update, then flips again",
                default: |_| SurfacePasses::default().relocate.to_string(),
            },
            OptionDoc {
                name: "sweep",
                doc: "a sliding boundary vertex also tries 7 evenly spaced places between its neighbours",
                default: |_| SurfacePasses::default().sweep.to_string(),
            },
        ],
        build: surface,
    },
    Entry {
        name: "eq5",
        summary: "Algorithm 2: patches of the run's strategy around the faces below q, the run's parameterizer, Eq. 5-6 updates in the plane (Sec. 3.4)",
        options: &[
            OptionDoc {
                name: "q",
                doc: "improve the faces whose metric quality is below this, in (0, 1]",
                default: |_| ImproveOptions::default().q_threshold.to_string(),
            },
            OptionDoc {
                name: "angle",
                doc: "and those whose smallest angle is below this (degrees, [0, 60))",
                default: |_| ImproveOptions::default().angle_threshold.to_string(),
            },
            OptionDoc {
                name: "passes",
                doc: "passes over the faces below q, each only if the last lowered their count or raised θ_min",
                default: |_| ImproveOptions::default().passes.to_string(),
            },
            OptionDoc {
                name: "rings",
                doc: "rings around a bad face in the first pass, one more per pass",
                default: |_| ImproveOptions::default().rings.to_string(),
            },
            OptionDoc {
                name: "max_patches",
                doc: "at most this many patches in all (then Ok with a warning; none: no bound)",
                default: |_| optional(ImproveOptions::default().max_patches),
            },
            OptionDoc {
                name: "w",
                doc: "the weight w of Eq. 5, > 0",
                default: |_| ImproveOptions::default().planar.w.to_string(),
            },
            OptionDoc {
                name: "flips",
                doc: "the flip rule: energy (Eq. 5) or max-min (q)",
                default: |_| flip_rule_name(ImproveOptions::default().planar.flip_rule).to_string(),
            },
            OptionDoc {
                name: "target",
                doc: "Eq. 5's equilateral triangle: own-area (shape only) or length (side L_tar, the paper's)",
                default: |_| target_name(ImproveOptions::default().planar.target).to_string(),
            },
            OptionDoc {
                name: "rounds",
                doc: "rounds of (vertex update, flips) per patch",
                default: |_| ImproveOptions::default().planar.rounds.to_string(),
            },
            OptionDoc {
                name: "steps",
                doc: "gradient steps per vertex and round",
                default: |_| ImproveOptions::default().planar.steps.to_string(),
            },
            OptionDoc {
                name: "line_search",
                doc: "halvings of a step's line search",
                default: |_| ImproveOptions::default().planar.line_search.to_string(),
            },
            OptionDoc {
                name: "collapse",
                doc: "collapse the shortest edge of a triangle whose smallest angle is below this (degrees, [0, 60); 0: none) when that raises the smallest angle around it",
                default: |_| ImproveOptions::default().planar.collapse_below_deg.to_string(),
            },
            OptionDoc {
                name: "bottom",
                doc: "what a patch must not lower: q-angles (q_min and θ_min) or angles (θ_min only)",
                default: |_| bottom_name(ImproveOptions::default().bottom).to_string(),
            },
        ],
        build: eq5,
    },
];

/// The improver of row `name` with `params` (see [`IMPROVERS`]).
pub fn improver(name: &str, params: Params) -> Result<Box<dyn Improver>, RegistryError> {
    crate::registry::build(IMPROVERS, name, params, MetricSizes::Relative)
}

/// The option value of a flip rule.
fn bottom_name(b: Bottom) -> &'static str {
    match b {
        Bottom::QualityAndAngles => "q-angles",
        Bottom::Angles => "angles",
    }
}

fn flip_rule_name(r: FlipRule) -> &'static str {
    match r {
        FlipRule::Energy => "energy",
        FlipRule::MaxMin => "max-min",
    }
}

/// The option value of an Eq. 5 target.
fn target_name(t: Target) -> &'static str {
    match t {
        Target::OwnArea => "own-area",
        Target::Length => "length",
    }
}

fn surface(p: &mut Params, _: MetricSizes) -> Result<Box<dyn Improver>, BadValue> {
    let mut s = SurfacePasses::default();
    if let Some(b) = p.take("flips", "true or false")? {
        s.flips = b;
    }
    if let Some(b) = p.take("relocate", "true or false")? {
        s.relocate = b;
    }
    if let Some(b) = p.take("sweep", "true or false")? {
        s.sweep = b;
    }
    Ok(Box::new(s))
}

fn eq5(p: &mut Params, _: MetricSizes) -> Result<Box<dyn Improver>, BadValue> {
    let mut o = ImproveOptions::default();
    if let Some(q) = p.take_checked("q", "a number in (0, 1]", |q: f64| q > 0.0 && q <= 1.0)? {
        o.q_threshold = q;
    }
    if let Some(a) = p.take_checked("angle", "an angle in [0, 60) degrees", |a: f64| {
        (0.0..60.0).contains(&a)
    })? {
        o.angle_threshold = a;
    }
    if let Some(n) = p.take("passes", "a number of passes")? {
        o.passes = n;
    }
    if let Some(r) = p.take_checked("rings", "a number of rings ≥ 1", |r: usize| r >= 1)? {
        o.rings = r;
    }
    if let Some(m) = p.take_optional("max_patches", "a number of patches or none", |_: usize| {
        true
    })? {
        o.max_patches = m;
    }
    if let Some(w) = p.take_checked("w", "a positive number", |w: f64| w.is_finite() && w > 0.0)? {
        o.planar.w = w;
    }
    if let Some(r) = p.take::<String>("flips", "energy or max-min")? {
        o.planar.flip_rule = [FlipRule::Energy, FlipRule::MaxMin]
            .into_iter()
            .find(|x| flip_rule_name(*x) == r)
            .ok_or_else(|| BadValue::new("flips", &r, "energy or max-min"))?;
    }
    if let Some(b) = p.take::<String>("bottom", "q-angles or angles")? {
        o.bottom = [Bottom::QualityAndAngles, Bottom::Angles]
            .into_iter()
            .find(|x| bottom_name(*x) == b)
            .ok_or_else(|| BadValue::new("bottom", &b, "q-angles or angles"))?;
    }
    if let Some(t) = p.take::<String>("target", "own-area or length")? {
        o.planar.target = [Target::OwnArea, Target::Length]
            .into_iter()
            .find(|x| target_name(*x) == t)
            .ok_or_else(|| BadValue::new("target", &t, "own-area or length"))?;
    }
    if let Some(n) = p.take("rounds", "a number of rounds")? {
        o.planar.rounds = n;
    }
    if let Some(n) = p.take("steps", "a number of steps")? {
        o.planar.steps = n;
    }
    if let Some(n) = p.take("line_search", "a number of halvings")? {
        o.planar.line_search = n;
    }
    if let Some(a) = p.take_checked("collapse", "an angle in [0, 60) degrees", |a: f64| {
        (0.0..60.0).contains(&a)
    })? {
        o.planar.collapse_below_deg = a;
    }
    Ok(Box::new(Algorithm2 { options: o }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_row_builds_with_its_defaults_and_refuses_bad_values_by_name() {
        for e in IMPROVERS {
            let built = improver(e.name, Params::default()).expect("defaults build");
            assert_eq!(built.name(), e.name);
            assert!(built.validate().is_ok(), "{}", e.name);
        }
        let p = |s: &[&str]| Params::parse(s).expect("parses");
        for bad in [
            "q=0",
            "q=1.5",
            "q=nan",
            "rings=0",
            "w=0",
            "w=inf",
            "flips=best",
            "target=big",
            "bottom=q",
        ] {
            let option = bad.split('=').next().unwrap_or_default().to_string();
            assert!(
                matches!(improver("eq5", p(&[bad])),
                    Err(RegistryError::BadValue { option: o, .. }) if o == option),
                "{bad}"
            );
        }
        assert!(matches!(
            improver("surface", p(&["q=0.7"])),
            Err(RegistryError::UnknownOption { .. })
        ));
        assert!(matches!(
            improver("laplace", Params::default()),
            Err(RegistryError::UnknownName { .. })
        ));
    }
}
