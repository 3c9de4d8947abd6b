//! Algorithm 2, minimum-angle improvement (Sec. 3.4), after the loop of Algorithm 1.
//!
//! ```text
//! while a face has q below the threshold and the budget is not spent:
//!     P  = a cone patch over `rings` rings around it          // through the PatchStrategy
//!     uv = parameterize P (certified bijective); M2 = Eq. 4
//!     vertex position and connectivity updates in the plane    // Eq. 5-6, improve::eq5
//!     map back, certify and replace P                          // as a patch of Algorithm 1
//! ```
//!
//! It reuses Algorithm 1's patch step with other stages ([`ImproveRun::patch_pass`]): a pass
//! marks the faces at or above the threshold as processed, so the cone strategy seeds only at
//! bad faces and its ring expansion takes their neighbourhood; the planar stage is
//! [`Eq5Improver`], which keeps the patch's vertices and boundary; the patch's boundary
//! chains are not resampled. Every replaced patch is certified as in Algorithm 1.
//! Termination: within a pass every patch marks at least one unprocessed face processed
//! (Algorithm 1's argument); a further pass runs only when the previous one strictly lowered
//! the count of faces below the threshold, and there are at most `passes` of them. Each pass
//! takes one ring more around the bad faces than the last.

use super::{Bottom, Eq5Improver, Eq5Options, ImproveRun, Improver, ImproverCounts};
use super::{LoopStages, RunError};
use crate::param::SymmetricDirichlet;
use crate::patches::{ConeOptions, ConePatches};
use serde::Serialize;

/// Options of Algorithm 2 (Sec. 3.4), with their defaults.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImproveOptions {
    /// A face whose metric quality q is below this is improved (default 0.5).
    pub q_threshold: f64,
    /// So is a face whose smallest angle in the metric is below this many degrees (default
    /// 30; paper-notes.md Sec. 3.4: selecting by q alone takes many faces that are merely
    /// stretched, at several times the cost).
    pub angle_threshold: f64,
    /// Passes over the faces below the threshold (default 3); a pass runs only while the
    /// previous one strictly lowered their count.
    pub passes: usize,
    /// Rings of faces around a bad face that its patch takes in the first pass, one more in
    /// each further pass (default 2).
    pub rings: usize,
    /// At most this many patches over all passes (default: no bound beyond the passes).
    pub max_patches: Option<usize>,
    /// The planar updates (Eq. 5-6); their defaults, but 12 halvings of the line search
    /// (30 cost 20 % more for the same result on the shared meshes).
    pub planar: Eq5Options,
}

impl Default for ImproveOptions {
    fn default() -> Self {
        ImproveOptions {
            q_threshold: 0.5,
            angle_threshold: 30.0,
            passes: 3,
            rings: 2,
            max_patches: None,
            planar: Eq5Options {
                line_search: 12,
                ..Eq5Options::default()
            },
        }
    }
}

impl ImproveOptions {
    /// Errors for values no run can use, naming the option.
    pub fn validate(&self) -> Result<(), String> {
        let q = self.q_threshold;
        if !(q.is_finite() && q > 0.0 && q <= 1.0) {
            return Err(format!("improvement threshold must be in (0, 1], got {q}"));
        }
        let a = self.angle_threshold;
        if !(a.is_finite() && (0.0..60.0).contains(&a)) {
            return Err(format!(
                "improvement angle threshold must be in [0°, 60°), got {a}"
            ));
        }
        let w = self.planar.w;
        if !(w.is_finite() && w > 0.0) {
            return Err(format!("Eq. 5 weight w must be a positive number, got {w}"));
        }
        if self.rings == 0 {
            return Err("improvement rings must be at least 1".into());
        }
        Ok(())
    }
}

impl ImproveOptions {
    /// The face is to be improved: q or its smallest angle below its threshold.
    pub fn is_bad(&self, t: &crate::quality::TriangleQuality) -> bool {
        t.q < self.q_threshold || t.min_angle() < self.angle_threshold
    }
}

/// Algorithm 2 as an [`Improver`] (row `eq5`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Algorithm2 {
    /// Options.
    pub options: ImproveOptions,
}

impl Improver for Algorithm2 {
    fn name(&self) -> &'static str {
        "eq5"
    }

    fn validate(&self) -> Result<(), String> {
        self.options.validate()
    }

    fn improve(
        &self,
        run: &mut dyn ImproveRun,
        rng: &mut crate::Rng,
    ) -> Result<ImproverCounts, RunError> {
        let o = &self.options;
        let mut counts = ImproverCounts::default();
        let mut bad_before = usize::MAX;
        while counts.passes < o.passes {
            let bad: Vec<bool> = run.face_qualities().iter().map(|t| o.is_bad(t)).collect();
            let n_bad = bad.iter().filter(|b| **b).count();
            if n_bad == 0 || n_bad >= bad_before {
                break;
            }
            bad_before = n_bad;
            // Each pass reaches one ring farther: the faces still bad after a pass are those
            // whose patch was too small to move their vertices (they sat on its boundary).
            let stages = PassStages::new(o, o.rings + counts.passes);
            counts.passes += 1;
            let budget = o.max_patches.map(|m| m.saturating_sub(counts.patches));
            let pass = run.patch_pass(stages.borrowed(), &bad, budget, &raises_the_bottom, rng)?;
            counts.patches += pass.patches;
            counts.rejected += pass.rejected;
            if pass.budget_exhausted {
                counts.budget_exhausted = true;
                break;
            }
        }
        Ok(counts)
    }
}

/// Algorithm 2's stages: cone patches expanded by `rings` rings, SD, the planar updates.
struct PassStages {
    patches: ConePatches,
    parameterizer: SymmetricDirichlet,
    remesher: Eq5Improver,
}

impl PassStages {
    fn new(o: &ImproveOptions, rings: usize) -> PassStages {
        PassStages {
            patches: ConePatches {
                options: ConeOptions {
                    expand_rings: rings,
                    ..ConeOptions::default()
                },
            },
            parameterizer: SymmetricDirichlet::default(),
            remesher: Eq5Improver {
                options: o.planar.clone(),
            },
        }
    }

    fn borrowed(&self) -> LoopStages<'_> {
        LoopStages {
            patches: &self.patches,
            parameterizer: &self.parameterizer,
            remesher: &self.remesher,
        }
    }
}

/// The candidate is better at the bottom than the faces it replaces: neither its smallest
/// metric quality nor its smallest angle is lower, and one of them is higher. (The planar
/// updates lower the energy in the plane; lifted across a crease or a strongly curved part a
/// move can still make a worse triangle on the surface, which is refused.)
fn raises_the_bottom(old: Bottom, new: Bottom) -> bool {
    new.q_min >= old.q_min
        && new.theta_min >= old.theta_min
        && (new.q_min > old.q_min || new.theta_min > old.theta_min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_no_run_can_use_are_named() {
        let bad = |f: fn(&mut ImproveOptions)| {
            let mut o = ImproveOptions::default();
            f(&mut o);
            o.validate().expect_err("refused")
        };
        assert!(bad(|i| i.q_threshold = 0.0).contains("threshold"));
        assert!(bad(|i| i.q_threshold = f64::NAN).contains("threshold"));
        assert!(bad(|i| i.q_threshold = 1.5).contains("threshold"));
        assert!(bad(|i| i.planar.w = -1.0).contains("weight w"));
        assert!(bad(|i| i.planar.w = f64::INFINITY).contains("weight w"));
        assert!(bad(|i| i.rings = 0).contains("rings"));
        assert!(ImproveOptions::default().validate().is_ok());
    }

    #[test]
    fn the_acceptance_test_wants_a_higher_bottom_and_nothing_lower() {
        let b = |q_min, theta_min| Bottom { q_min, theta_min };
        assert!(raises_the_bottom(b(0.3, 10.0), b(0.4, 10.0)));
        assert!(raises_the_bottom(b(0.3, 10.0), b(0.3, 12.0)));
        assert!(!raises_the_bottom(b(0.3, 10.0), b(0.3, 10.0)));
        assert!(!raises_the_bottom(b(0.3, 10.0), b(0.5, 9.0)));
        assert!(!raises_the_bottom(b(0.3, 10.0), b(0.2, 20.0)));
    }
}
