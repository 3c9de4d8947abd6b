//! The registry of improvers (Sec. 3.4): name → constructor and options. A new improver is a
//! new file in `improve/` plus one row here. Unlike the other extension points a run takes a
//! list of them, in order ([`crate::pipeline::Stages::improvers`]).

use super::{Algorithm2, FlipRule, ImproveOptions, Improver, SurfacePasses, Target};
use crate::registry::{BadValue, Entry, OptionDoc, Params, RegistryError};

/// Every built-in improver, in the order the default list runs them.
pub static IMPROVERS: &[Entry<dyn Improver>] = &[
    Entry {
        name: "surface",
        summary: "the connectivity and vertex position updates on the surface, certified, within --hausd (ours, Sec. 3.4)",
        options: &[
            OptionDoc {
                name: "flips",
                doc: "the connectivity update (edge flips by max-min q) [true]",
            },
            OptionDoc {
                name: "relocate",
                doc: "the vertex position update, then flips again [true]",
            },
        ],
        build: surface,
    },
    Entry {
        name: "eq5",
        summary: "Algorithm 2: cone patches around the faces below q, Eq. 5-6 updates in the plane (Sec. 3.4)",
        options: &[
            OptionDoc {
                name: "q",
                doc: "improve the faces whose metric quality is below this, in (0, 1] [0.5]",
            },
            OptionDoc {
                name: "angle",
                doc: "and those whose smallest angle is below this (degrees, [0, 60)) [30]",
            },
            OptionDoc {
                name: "passes",
                doc: "passes over the faces below q, each only if the last lowered their count [3]",
            },
            OptionDoc {
                name: "rings",
                doc: "rings around a bad face in the first pass, one more per pass [2]",
            },
            OptionDoc {
                name: "max_patches",
                doc: "at most this many patches in all (then Ok with a warning) [no bound]",
            },
            OptionDoc {
                name: "w",
                doc: "the weight w of Eq. 5, > 0 [1]",
            },
            OptionDoc {
                name: "flips",
                doc: "the flip rule: energy (Eq. 5) or max-min (q) [energy]",
            },
            OptionDoc {
                name: "target",
                doc: "Eq. 5's equilateral triangle: own-area (shape only) or length (side L_tar, the paper's) [own-area]",
            },
            OptionDoc {
                name: "rounds",
                doc: "rounds of (vertex update, flips) per patch [10]",
            },
            OptionDoc {
                name: "steps",
                doc: "gradient steps per vertex and round [4]",
            },
            OptionDoc {
                name: "line_search",
                doc: "halvings of a step's line search [12]",
            },
            OptionDoc {
                name: "collapse",
                doc: "collapse the shortest edge of a triangle whose smallest angle is below this (degrees, [0, 60); 0: none) when that raises the smallest angle around it [30]",
            },
        ],
        build: eq5,
    },
];

/// The improver of row `name` with `params` (see [`IMPROVERS`]).
pub fn improver(name: &str, params: Params) -> Result<Box<dyn Improver>, RegistryError> {
    crate::registry::build("improver", IMPROVERS, name, params)
}

fn surface(p: &mut Params) -> Result<Box<dyn Improver>, BadValue> {
    let mut s = SurfacePasses::default();
    if let Some(b) = p.take("flips", "true or false")? {
        s.flips = b;
    }
    if let Some(b) = p.take("relocate", "true or false")? {
        s.relocate = b;
    }
    Ok(Box::new(s))
}

fn eq5(p: &mut Params) -> Result<Box<dyn Improver>, BadValue> {
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
    if let Some(m) = p.take("max_patches", "a number of patches")? {
        o.max_patches = Some(m);
    }
    if let Some(w) = p.take_checked("w", "a positive number", |w: f64| w.is_finite() && w > 0.0)? {
        o.planar.w = w;
    }
    if let Some(r) = p.take::<String>("flips", "energy or max-min")? {
        o.planar.flip_rule = match r.as_str() {
            "energy" => FlipRule::Energy,
            "max-min" => FlipRule::MaxMin,
            _ => return Err(BadValue::new("flips", &r, "energy or max-min")),
        };
    }
    if let Some(t) = p.take::<String>("target", "own-area or length")? {
        o.planar.target = match t.as_str() {
            "own-area" => Target::OwnArea,
            "length" => Target::Length,
            _ => return Err(BadValue::new("target", &t, "own-area or length")),
        };
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
